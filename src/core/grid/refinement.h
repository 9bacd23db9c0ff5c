// Refinement by evaluation: the B-spline blocks evaluated on stretched, point-matched grids.
// Point counts are shared by every block direction that a connected face links (so opposite edges
// of a block and shared edges of neighbours agree); distributions are computed from the physical
// grid lines themselves (block edges, wall-normal lines), which neighbours share, so both sides
// of a shared face place the same points; shared points are then made identical bit for bit.
#pragma once

#include <optional>
#include <vector>

#include "core/grid/structured_grid.h"
#include "core/volume/block_mesh.h"
#include "core/volume/domain.h"

namespace bvmesh::grid {

enum class WallDistribution { Geometric, Tanh };

// A wall feature (a wing's leading or trailing edge, its tip) as a polyline, and the tangential
// spacing asked next to it. Every wall edge of a block that ends on the line (its end within
// `tolerance` of it; 0: 1e-3 of the wall's size) and leaves it (more than 45 degrees off the
// line's direction there) gets a first spacing there of at most `spacing`: the longest of them
// exactly (in arc length), the others the same fraction of their length.
struct FeatureSpacing {
  RowMatrixX3d points;  // at least two, consecutive ones apart
  double spacing = 0.0;
  double tolerance = 0.0;
};

// The most points a block edge takes (edge_points, or counts from a spacing).
constexpr int kMaxEdgePoints = 100000;

struct RefinementOptions {
  // Wall-normal lines (the direction whose end face is a wall, and every direction a connected
  // face links to it): `normalPoints` points (0: the fewest that keep the growth ratio at most
  // `growth` with the first cell height asked).
  int normalPoints = 49;
  // First cell height at the wall: absolute if > 0; else from yPlus (> 0) with reynoldsNumber and
  // referenceLength by the flat-plate estimate; else none, and every wall-normal line grows by
  // exactly `growth` (the Euler grid: no clustering beyond the far field's own growth).
  double firstCellHeight = 0.0;
  double yPlus = 0.0;
  double reynoldsNumber = 0.0;
  double referenceLength = 0.0;
  // Maximum growth ratio of wall-normal spacings (with a first cell height), or the growth itself.
  double growth = 1.2;
  WallDistribution distribution = WallDistribution::Geometric;
  // Tangential lines: `edgePoints` points on every block edge, or, if tangentialSpacing > 0, as
  // many as that spacing needs on the longest wall edge of each linked set (a wall resolution:
  // the far field takes what its blocks fan out to; sets without a wall edge count all their
  // edges); if targetCells > 0, the spacing that gives about that many cells in all.
  int edgePoints = 17;
  double tangentialSpacing = 0.0;
  long long targetCells = 0;
  // Spacing at both ends of every tangential block edge (0: uniform in arc length); block edges
  // run along the wing's leading and trailing edges and tip, where clustering pays.
  double edgeEndSpacing = 0.0;
  // Largest turning of a wall edge's tangent over one cell, in degrees (0: none). With a spacing
  // (tangentialSpacing or targetCells) a set's count is what its wall edges (and the middle
  // lines of its wall faces) need to keep every cell within the spacing and its turning within
  // this: each asks for length / spacing + turning / maxTurningDegrees cells; with edgePoints the
  // count stays as asked. Either way the points go at equal steps of that measure, shared by the
  // set, so they gather where the wall bends (a wing's nose). Lines inside a face take their
  // parameters blended from its edges' and can turn somewhat more (a sphere at 10 degrees: 12.4).
  double maxTurningDegrees = 0.0;
  // Largest ratio between a set's spacing at its end and that of the wall edges continuing its
  // wall edges there, across a block corner within 45 degrees of straight on (0: no limit). A set
  // whose continuation is finer than that is clustered at that end (Vinokur's law, all its edges
  // alike) to this many times the finest continuation's mean spacing: a wing's span towards a
  // small tip cap. OpenFOAM reads neighbours 20 times apart as small interpolation weights and 100
  // times apart in volume as a failed check. The presets of bvmesh.grid use 4.
  double maxSpacingJump = 0.0;
  // Spacings asked at wall features: the linked sets of the edges on them are clustered at those
  // ends (Vinokur's law, one-sided or two-sided), the clustering fading by a square root per
  // block away from the feature's edges; with a spacing or cell target a set takes the cells
  // its longest feature edge needs to grow back to its spacing by at most `growth`. Where a
  // spacing-jump limit clusters the same end, the finer of the two.
  std::vector<FeatureSpacing> featureSpacings;
  // The far field's wall-normal lines slide, from a tenth of the wall's size out, towards the
  // lines through points uniform in arc length on the outer boundary's block edges (all the way
  // at the outer boundary): the marching carries the wall's clustering out and fans the front out
  // at convex ends (a wing's tip), which reach the outer boundary as neighbouring cells up to a
  // hundred times apart in width, read by OpenFOAM as small determinants. Only for layouts whose
  // every block stands on the wall (off otherwise); where the slid lines would fold a cell, the
  // grid is refined without (RefinedGrid::evenFarFieldUsed).
  bool evenFarField = false;
  // The flow domain the blocks were marched to: a box's or cylinder's outer faces are then tagged
  // quad by quad (grid::tagOuterQuads), not by their middle alone.
  std::optional<volume::Domain> outerDomain;
  // At most this many points (0: no limit), checked when the sizes are planned, before any point
  // is computed: a memory budget, so that a count beyond the machine is refused instead of
  // exhausting its memory (bvmesh.grid.refine sets it from the free memory).
  long long maxPoints = 0;
};

struct RefinedGrid {
  StructuredGrid grid;
  int normalPoints = 0;
  double firstCellHeightAsked = 0.0;  // 0 when the growth was fixed instead
  // Measured over every wall-normal line: the first point's distance from the wall, the largest
  // ratio of consecutive spacings.
  double firstCellHeightMin = 0.0;
  double firstCellHeightMax = 0.0;
  double growthMax = 0.0;
  int outerFacesSplit = 0;  // outer block faces whose quads lie on more than one part of the domain
  bool evenFarFieldUsed = false;  // the far field's lines slid (RefinementOptions::evenFarField)
  // Where a cell folded: the blocks a fold was in took 2^foldRefinements times their tangential
  // cells (refineBlockMesh); 0 where none folded or no finer grid folded less.
  int foldRefinements = 0;
};

// Each wall-normal line runs in one block from the wall to the outer boundary (blocks stacked on
// a wall block along its wall-normal direction are refused, naming them). Throws
// InvalidInputError for bad options (naming them) or a first cell height the lines cannot take
// with the points and growth allowed (saying how many points would).
RefinedGrid refineBlockMesh(const volume::BlockMesh& blocks, const RefinementOptions& options);

}  // namespace bvmesh::grid

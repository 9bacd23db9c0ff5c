// Marching a closed (or symmetry-bounded) quad surface grid outward, layer by layer: the
// boundary layer along the wall normals (straight, orthogonal grid lines), then the far field with
// marching directions and point positions smoothed more and more with distance, and finally the
// outer layers blended onto the domain boundary. Every layer's cells are checked; a layer that
// would fold is marched again with more smoothing and, failing that, stops the marching with an
// error that says where.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/common/types.h"
#include "core/volume/boundary_planes.h"
#include "core/volume/domain.h"
#include "core/volume/hyperbolic_step.h"

namespace bvmesh::volume {

// A point of a fan round a knife edge of the wall (edge_fans.h): it lies on the edge, and its
// grid line turns from the line of the edge's copy `from` to that of its copy `to` by `fraction`,
// round the outside of the edge's wedge (`outside`, a unit direction off the edge between its
// faces: the way round where the faces' normals are opposite, a cusp).
struct FanPoint {
  int point = -1;
  int from = -1;
  int to = -1;
  double fraction = 0.0;
  Eigen::Vector3d outside = Eigen::Vector3d::Zero();
};

// The two copies of a knife edge's point: the edge's faces see one each, a fan lies between them.
struct KnifeCopies {
  int first = -1;
  int second = -1;
};

// A point where fans close (their knife edge ends inside the wall, the copies joined again), and
// the widest angle between the copies' normals along those fans.
struct FanClosing {
  int point = -1;
  double widestAngle = 0.0;
};

// The surface to march: points, quads (counter-clockwise seen from outside, i.e. the side to march
// to) and, per point, the unit wall normal and the boundary planes it lies on. A quad may
// repeat a corner (a triangle: a fan closing at the end of its edge), and a fan's quads have no
// area on the wall itself.
struct MarchingFront {
  RowMatrixX3d points;
  std::vector<std::array<int, 4>> quads;
  RowMatrixX3d normals;
  std::vector<unsigned char> onPlanes;  // per point, BoundaryPlanes bits; may be empty (none)
  std::vector<std::string> quadNames;  // per quad, where it is (for error messages), may be empty
  std::vector<FanPoint> fanPoints;
  std::vector<KnifeCopies> knifeCopies;
  std::vector<FanClosing> fanClosings;

  // The BoundaryPlanes bits of point p (0: on none).
  unsigned planesAt(Eigen::Index p) const { return onPlanes.empty() ? 0u : onPlanes[static_cast<size_t>(p)]; }
};

// Per point its neighbours along the front's quads' edges (a quad's repeated corner is no edge);
// with `withoutFans`, the wall's points alone, connected as if the knife edges' fans were not
// there (a fan's points have none, and an edge's two copies are apart).
std::vector<std::vector<int>> frontNeighbours(const MarchingFront& front, bool withoutFans = false);

// A knife edge's fan: its points' lines turn from one copy's line to the other's (kept in the
// boundary planes a point lies on).
void turnFans(const MarchingFront& front, const BoundaryPlanes& planes, RowMatrixX3d& lines);

// How the far field is marched: `Hyperbolic` solves Chan & Steger's orthogonality and cell-volume
// equations per step (hyperbolic_step.h), whose smoothed volumes open concave corners; a layer it
// would fold is marched by the smoothed step. `Smoothed` steps along directions blended from the
// previous layer's, the front's normal and the domain's radial, smoothed implicitly, with the
// points smoothed in the front.
enum class FarfieldScheme { Smoothed, Hyperbolic };
FarfieldScheme farfieldSchemeOf(const std::string& name);  // "smoothed", "hyperbolic"

struct MarchingOptions {
  // Boundary layer: total thickness and number of layers (geometric growth).
  double boundaryLayerThickness = 0.0;
  int boundaryLayerLayers = 4;
  double boundaryLayerGrowth = 1.2;
  // Width, in boundary-layer thicknesses, of the band around sharp convex wall edges over which the
  // boundary-layer grid lines fan out from one side's normal to the other's (0: no band).
  double sharpEdgeSplay = 2.0;
  // Far field: the distance from the domain centre the layers are marched to (the sphere's radius,
  // the box's or cylinder's half size), the growth of the layer thickness from one layer to the
  // next, and the outer boundary the last layer is projected onto.
  double farfieldDistance = 0.0;
  double farfieldGrowth = 1.3;
  Domain domain;
  // The symmetry and outflow planes (used when some points are on them).
  BoundaryPlanes planes;
  // Far-field smoothing: direction smoothing (implicit, grows with the layer) and point smoothing
  // in the front's tangent plane (the cell-size equaliser), both scaled by this factor (0: none).
  double smoothing = 1.0;
  FarfieldScheme farfieldScheme = FarfieldScheme::Hyperbolic;
  HyperbolicOptions hyperbolic;     // its explicit and implicit smoothing are scaled by `smoothing`
  double minScaledJacobian = 0.05;  // a layer with a cell below this is marched again with more smoothing
  int maxLayers = 400;
  // Layers times front points at most (0: no limit), checked once the layer count is known, before
  // the far field is marched: a memory budget (about 220 bytes a layer point with the blocks).
  long long maxLayerPoints = 0;
};

struct MarchingResult {
  std::vector<RowMatrixX3d> layers;         // layer 0 = the wall
  std::vector<double> layerDistance;        // mean marched distance of each layer
  std::vector<double> layerMinScaledJacobian;  // per layer k >= 1: worst cell between layers k-1 and k
  // With the hyperbolic scheme: far-field layers it would have folded (after the local repair),
  // marched by the smoothed scheme's step instead (or, where that folds too, by the hyperbolic
  // step with the smoothed one round its folded cells).
  int farfieldLayersSmoothed = 0;
};

MarchingResult marchLayers(const MarchingFront& front, const MarchingOptions& options);

}  // namespace bvmesh::volume

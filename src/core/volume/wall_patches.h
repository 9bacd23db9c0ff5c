// The wall of the volume mesh as conforming patches: the limit surface's B-spline charts, split
// where a chart side meets more than one neighbouring side, so that every patch side is shared
// with exactly one other patch side (or lies on the mesh boundary). Each patch becomes the wall
// face of one block; splitting a chart is knot insertion, so the patches are exactly the charts'
// surfaces.
#pragma once

#include <array>
#include <utility>
#include <vector>

#include "core/surface/limit_bsplines.h"
#include "core/volume/block_mesh.h"

namespace bvmesh::volume {

// A bicubic patch with clamped knot vectors over [0, m] x [0, n] (one span per control-mesh quad).
struct PatchSurface {
  std::vector<double> uKnots;         // full knot vectors
  std::vector<double> vKnots;
  int uPoles = 0;
  int vPoles = 0;
  std::vector<Eigen::Vector3d> poles;  // pole (i, j) at i * vPoles + j

  const Eigen::Vector3d& pole(int i, int j) const { return poles[static_cast<size_t>(i * vPoles + j)]; }
  // Point and unit normal (du x dv) at (u, v).
  Eigen::Vector3d point(double u, double v, Eigen::Vector3d* normal = nullptr) const;
};

// A patch side in the chart's terms: VMin / VMax run along u, UMin / UMax along v.
using surface::ChartSide;

struct PatchSideLink {
  int patch = -1;  // -1: the side lies on the mesh boundary
  ChartSide side = ChartSide::VMin;
  bool reversed = false;  // the neighbour runs along the shared side in the opposite direction
};

struct WallPatch {
  int chart = -1;
  std::array<int, 2> uRange{0, 0};  // chart cells [first, last) along u
  std::array<int, 2> vRange{0, 0};
  PatchSurface surface;  // empty from conformingPatchLayout
  std::array<std::vector<int>, 4> sideVertices;  // control-mesh vertices along each side, by increasing parameter
  std::array<PatchSideLink, 4> sides;             // per ChartSide
  std::array<bool, 4> creaseSide{false, false, false, false};  // side on a crease of the control mesh
  // A fan round a knife edge of the wall (edge_fans.h): no wall of its own, its surface the edge
  // repeated across it (u along the edge, v round it), its block's wall face collapsed.
  bool fan = false;
  // Where a knife edge's vertex chain is cut open: which copy of it each side and corner lies on
  // (0: the chain itself; 1 and 2: the edge's two faces, the fan between them seeing both), and
  // the sides collapsed to one point (a fan's end inside the wall).
  std::array<int, 4> sideCopy{0, 0, 0, 0};
  std::array<int, 4> cornerCopy{0, 0, 0, 0};  // corners (0, 0), (U, 0), (0, V), (U, V)
  std::array<bool, 4> collapsedSide{false, false, false, false};
};

// Position (i, j) in a patch's pole grid of entry t along a side, and the side's number of poles.
std::pair<int, int> sidePolePosition(const WallPatch& patch, ChartSide side, int t);
int sidePoleCount(const WallPatch& patch, ChartSide side);

// A patch's corners are numbered 0: (0, 0), 1: (U, 0), 2: (0, V), 3: (U, V). The control vertex
// at one, and the corner at entry `end` (0: first, 1: last) along a side.
int cornerVertex(const WallPatch& patch, int corner);
int sideEndCorner(ChartSide side, int end);

// The patch surface's point, and its normal (not unit), at the Greville abscissae of pole (i, j).
Eigen::Vector3d polePoint(const WallPatch& patch, int i, int j, Eigen::Vector3d* normal = nullptr);

// The unit direction in which the patch's surface leaves through entry t of `side`: from the
// point (polePoint) of the pole one row inside to the side's.
Eigen::Vector3d sideOutward(const WallPatch& patch, ChartSide side, int t);

// Splits the charts of `layout` (of `mesh`) into conforming patches and links their sides, without
// surfaces: the patches as rectangles of control-mesh faces. Throws TopologyError when a side has
// more than one neighbour after splitting.
std::vector<WallPatch> conformingPatchLayout(const surface::ChartLayout& layout, const surface::QuadControlMesh& mesh);

// The same with each patch's surface: its piece of its chart's B-spline surface in `bsplines`
// (built from `mesh`).
std::vector<WallPatch> conformingWallPatches(const surface::LimitBSplines& bsplines,
                                             const surface::QuadControlMesh& mesh);

// The lateral faces (u_min ... v_max) of the block standing on `patch` (block numbers = patch
// numbers): connected to the block on the neighbouring patch, collapsed where the side is, or,
// where it is open, the condition of the plane it lies on (`openSides`, per ChartSide).
void setLateralFaces(const WallPatch& patch, const std::array<BoundaryCondition, 4>& openSides,
                     std::array<BlockFace, 6>& faces);

}  // namespace bvmesh::volume

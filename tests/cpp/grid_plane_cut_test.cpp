// Plane cuts through a grid: the lattice lines of an affine box, a plane the grid touches from one
// side, collapsed faces and touched corners.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <vector>

#include "block_fixtures.h"
#include "core/common/errors.h"
#include "core/grid/hex_topology.h"
#include "core/grid/plane_cut.h"
#include "core/grid/refinement.h"
#include "grid_fixtures.h"

namespace bvmesh::grid {
namespace {

using Eigen::Vector3d;

// [0, 2] x [0, 2] x [0, 1] as 2 x 2 unwarped blocks (turned and mirrored), 5 points per edge
// and 9 along z: the lattice the plane-cut tests cut.
StructuredGrid affineBoxGrid() {
  return refineBlockMesh(test::boxBlocks(0.0, true, 1).mesh, test::affineBoxOptions()).grid;
}

TEST(GridPlaneCut, AffineBoxCutAcrossXHasTheLatticeLines) {
  // [0, 2] x [0, 2] x [0, 1] as 2 x 2 blocks (turned and mirrored), 5 points per edge: the plane
  // x = 0.6 crosses the faces normal to y (5 per block, 1 long in z; y = 1 is in both blocks at
  // x < 1) and normal to z (9 levels, 2 long in y): 28 in all, every point at x = 0.6, and each
  // segment's cell straddles the plane.
  const StructuredGrid grid = affineBoxGrid();
  const PlaneCut cut = cutByPlane(grid, Vector3d(0.6, 7.0, -3.0), Vector3d(2.0, 0.0, 0.0));
  ASSERT_GT(cut.cell.size(), 0u);
  double length = 0.0;
  const HexTopology topology(grid);
  for (Eigen::Index s = 0; s < cut.start.rows(); ++s) {
    EXPECT_NEAR(cut.start(s, 0), 0.6, 1e-12);
    EXPECT_NEAR(cut.end(s, 0), 0.6, 1e-12);
    length += (cut.end.row(s) - cut.start.row(s)).norm();
    double low = 1e9, high = -1e9;
    for (Eigen::Index corner : topology.cellCorners(cut.cell[static_cast<size_t>(s)])) {
      low = std::min(low, topology.points().points(corner, 0));
      high = std::max(high, topology.points().points(corner, 0));
    }
    EXPECT_LE(low, 0.6);
    EXPECT_GE(high, 0.6);
  }
  EXPECT_NEAR(length, 28.0, 1e-9);
  EXPECT_EQ(cut.start.rows(), 2 * 5 * 8 + 9 * 8);
  EXPECT_THROW(cutByPlane(grid, Vector3d::Zero(), Vector3d::Zero()), InvalidInputError);
  EXPECT_THROW(cutByPlane(grid, Vector3d::Zero(), Vector3d(0.0, std::nan(""), 1.0)), InvalidInputError);
}

TEST(GridPlaneCut, APlaneTheGridTouchesFromOneSideDrawsTheGridLinesInIt) {
  // The box's face x = 0 (as a half model's symmetry plane) cut with the normal pointing into the
  // grid and away from it: the same lines either way, the face's lattice: in each of the two blocks
  // on it (y 0..1 and 1..2) 5 lines along z of length 1 and 9 along y of length 1 in 4 steps, each
  // step a segment on its own (the line y = 1 once per block).
  const StructuredGrid grid = affineBoxGrid();
  for (const double side : {1.0, -1.0}) {
    const PlaneCut cut = cutByPlane(grid, Vector3d(0.0, 0.3, 0.4), Vector3d(side, 0.0, 0.0));
    ASSERT_EQ(cut.start.rows(), 2 * (5 * 8 + 9 * 4)) << side;
    double length = 0.0;
    for (Eigen::Index s = 0; s < cut.start.rows(); ++s) {
      EXPECT_EQ(cut.start(s, 0), 0.0);
      EXPECT_EQ(cut.end(s, 0), 0.0);
      length += (cut.end.row(s) - cut.start.row(s)).norm();
    }
    EXPECT_NEAR(length, 2.0 * (5.0 + 9.0), 1e-12) << side;
  }
  // A plane beyond the grid still cuts nothing.
  EXPECT_EQ(cutByPlane(grid, Vector3d(-0.1, 0.0, 0.0), Vector3d(1.0, 0.0, 0.0)).start.rows(), 0);
}

TEST(GridPlaneCut, ACollapsedFaceOrATouchedCornerDrawsNoSegment) {
  // Two unit cells along x, the second a prism: its far face (x = 2) merged into the edge y = 0.
  // The plane z = 0.5 crosses the faces normal to x at x = 0 and 1 and those normal to y, one
  // unit segment each (the prism's slanted face sqrt(2)); the merged face's crossings are one
  // point, no segment (a CAD line through it would fail: the GridCut feature of a grid with fans).
  std::vector<GridBlock> prism = test::twoCellRow({2, 1, 0}, Vector3d(0.0, -1.0, 0.0));
  prism[0].points.row(prism[0].index(2, 1, 1)) << 2.0, 0.0, 1.0;
  const StructuredGrid grid(prism);
  const PlaneCut cut = cutByPlane(grid, Vector3d(0.0, 0.0, 0.5), Vector3d(0.0, 0.0, 1.0));
  ASSERT_EQ(cut.start.rows(), 6);
  double length = 0.0;
  for (Eigen::Index s = 0; s < cut.start.rows(); ++s) {
    EXPECT_GT((cut.end.row(s) - cut.start.row(s)).norm(), 0.99);
    length += (cut.end.row(s) - cut.start.row(s)).norm();
  }
  EXPECT_NEAR(length, 5.0 + std::sqrt(2.0), 1e-12);
  // A plane through the corner (0, 0, 0) alone touches three faces there and cuts none.
  EXPECT_EQ(cutByPlane(grid, Vector3d::Zero(), Vector3d(-1.0, -1.0, -1.0)).start.rows(), 0);
}

}  // namespace
}  // namespace bvmesh::grid

// Collapsed block faces: a block fanning round a sharp edge (block_fixtures.h, fanWedgeBlocks)
// whose wall face is the edge itself. Validation, the merged points, the refinement's count round
// the fan (its spacing taken off the wall at either end of the block), the cells there as prisms
// (their faces, their scaled Jacobian against the sine of the angle between their lines) and the
// block file; checkMesh on them: openfoam_writer_test.cpp.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "block_fixtures.h"
#include "core/common/errors.h"
#include "core/grid/hex_topology.h"
#include "core/grid/refinement.h"
#include "core/grid/subdivision_refinement.h"
#include "core/quality/cell_quality.h"
#include "core/volume/block_mesh_io.h"
#include "core/volume/hex_scaled_jacobian.h"

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

constexpr double kHalfWedge = 10.0 * M_PI / 180.0;

grid::RefinedGrid refinedFan(double spacing = 0.5) {
  grid::RefinementOptions options;
  options.normalPoints = 9;
  options.tangentialSpacing = spacing;
  return grid::refineBlockMesh(test::fanWedgeBlocks(kHalfWedge), options);
}

TEST(CollapsedFace, TheFanTakesItsSpacingRoundTheEdgeFromItsFirstKnotOffTheWallAtEitherEnd) {
  // The same volume parametrised from the wall out and from the far field in: the same grid, point
  // for point (the fan's spacing from the line at the first knot off the wall; taken at the first
  // knot from w = 0 in both, the second would take it from the far field's side).
  grid::RefinementOptions options;
  options.normalPoints = 9;
  options.tangentialSpacing = 0.25;
  // Three knot spans off the wall, the fan's lines gathering towards its upper side farther out.
  test::FanWedgeShape shape{3, 2.0, false};
  const grid::RefinedGrid out = grid::refineBlockMesh(test::fanWedgeBlocks(kHalfWedge, shape), options);
  shape.wallAtEnd = true;
  const grid::RefinedGrid in = grid::refineBlockMesh(test::fanWedgeBlocks(kHalfWedge, shape), options);
  const grid::GridBlock& a = out.grid.blocks()[2];
  const grid::GridBlock& b = in.grid.blocks()[2];
  ASSERT_EQ(a.size, b.size);
  EXPECT_GE(a.size[1], 6);  // round the fan: 160 degrees at most 30 each
  double largest = 0.0;
  for (int k = 0; k < a.size[2]; ++k) {
    for (int j = 0; j < a.size[1]; ++j) {
      for (int i = 0; i < a.size[0]; ++i) {
        largest = std::max(
            largest,
            (a.points.row(a.index(i, j, k)) - b.points.row(b.index(i, j, a.size[2] - 1 - k))).norm());
      }
    }
  }
  EXPECT_LT(largest, 1e-12);
}

TEST(CollapsedFace, TheFanBlocksFaceOnTheEdgeIsOneCurveAlongItsAngle) {
  const BlockMesh mesh = test::fanWedgeBlocks(kHalfWedge);
  const BlockFace& edge = mesh.blocks()[2].faces[static_cast<size_t>(BlockFaceSide::WMin)];
  EXPECT_EQ(edge.condition, BoundaryCondition::Collapsed);
  EXPECT_FALSE(edge.collapsedAlong[0]);  // along u: the edge itself
  EXPECT_TRUE(edge.collapsedAlong[1]);   // along v: round the fan
  // The control mesh merges the edge's poles: 5 along the span, shared by all three blocks.
  const VolumeControlMesh control = volumeControlMesh(mesh);
  std::set<int> edgePoints;
  for (int j = 0; j < 5; ++j) {
    for (int i = 0; i < 5; ++i) {
      edgePoints.insert(control.pointOfPole[static_cast<size_t>(control.blockPointOffset[2] + mesh.blocks()[2].volume.poleIndex(i, j, 0))]);
    }
  }
  EXPECT_EQ(edgePoints.size(), 5u);
  for (BoundaryCondition condition : control.boundaryConditions) EXPECT_NE(condition, BoundaryCondition::Collapsed);
}

TEST(CollapsedFace, AFaceCalledCollapsedThatIsNotIsRefusedByName) {
  std::vector<Block> blocks = test::fanWedgeBlocks(kHalfWedge).blocks();
  blocks[0].faces[static_cast<size_t>(BlockFaceSide::WMax)].condition = BoundaryCondition::Collapsed;
  try {
    BlockMesh mesh(std::move(blocks));
    FAIL() << "accepted a collapsed face whose poles differ";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("block 0 face w_max is collapsed, but its poles differ"), std::string::npos)
        << error.what();
  }
}

TEST(CollapsedFace, TheFanTakesOneCellPerThirtyDegreesAndItsPointsOnTheEdgeAreOne) {
  const grid::RefinedGrid refined = refinedFan();
  const grid::GridBlock& fan = refined.grid.blocks()[2];
  // The fan turns 180 - 2 * 10 degrees: 160 / 30 -> 6 cells, 7 points along v.
  EXPECT_EQ(fan.size[1], 7);
  for (int i = 0; i < fan.size[0]; ++i) {
    for (int j = 1; j < fan.size[1]; ++j) EXPECT_TRUE(fan.points.row(fan.index(i, j, 0)) == fan.points.row(fan.index(i, 0, 0)));
    EXPECT_NEAR(fan.points(fan.index(i, 0, 0), 0), 0.0, 1e-15);
    EXPECT_NEAR(fan.points(fan.index(i, 0, 0), 2), 0.0, 1e-15);
  }
}

TEST(CollapsedFace, CellsOnTheEdgeArePrismsThatCloseAndMeasureTheSineOfTheirStep) {
  const grid::RefinedGrid refined = refinedFan();
  const grid::HexTopology topology(refined.grid);
  const RowMatrixX3d& points = topology.points().points;
  // Per cell the sum of its faces' area vectors (outward from the owner) vanishes: every cell closes.
  std::vector<Vector3d> closure(static_cast<size_t>(topology.cellCount()), Vector3d::Zero());
  std::map<int, int> faceSizes;
  auto area = [&](const grid::HexFace& face) {
    Vector3d sum = Vector3d::Zero();
    const Vector3d a = points.row(face.points[0]).transpose();
    for (int v = 1; v + 1 < face.size; ++v) {
      sum += 0.5 * (points.row(face.points[static_cast<size_t>(v)]).transpose() - a)
                       .cross(points.row(face.points[static_cast<size_t>(v + 1)]).transpose() - a);
    }
    return sum;
  };
  Eigen::Index internal = 0;
  topology.forEachInternalFace([&](const grid::HexFace& face) {
    ++internal;
    ++faceSizes[face.size];
    closure[static_cast<size_t>(face.owner)] += area(face);
    closure[static_cast<size_t>(face.neighbour)] -= area(face);
  });
  EXPECT_EQ(internal, topology.internalFaceCount());
  Eigen::Index boundary = 0;
  topology.forEachBoundaryFace([&](size_t, const grid::HexFace& face) {
    ++boundary;
    ++faceSizes[face.size];
    closure[static_cast<size_t>(face.owner)] += area(face);
  });
  Eigen::Index patchFaces = 0;
  for (const grid::BoundaryPatch& patch : topology.patches()) {
    EXPECT_NE(patch.condition, BoundaryCondition::Collapsed);
    patchFaces += patch.size;
  }
  EXPECT_EQ(boundary, patchFaces);
  for (const Vector3d& sum : closure) EXPECT_LT(sum.norm(), 1e-12);
  // Triangles: the fan's first cells' span faces (i-min, i-max: inside and on both symmetry planes).
  const grid::GridBlock& fan = refined.grid.blocks()[2];
  const int fanCells = fan.size[1] - 1;
  EXPECT_EQ(faceSizes[3], fan.size[0] * fanCells);
  // Every internal face of the blocks as hexahedra is there (the fan's first cells are prisms,
  // their faces triangles or quads), and no boundary face lies on the edge itself.
  Eigen::Index hexInternal = 0, hexBoundary = 0;
  for (const grid::GridBlock& block : refined.grid.blocks()) {
    const Eigen::Index ni = block.size[0] - 1, nj = block.size[1] - 1, nk = block.size[2] - 1;
    hexInternal += (ni - 1) * nj * nk + ni * (nj - 1) * nk + ni * nj * (nk - 1);
    hexBoundary += 2 * (ni * nj + nj * nk + ni * nk);
  }
  const Eigen::Index blockFaces = 2 * (fan.size[0] - 1) * (fan.size[2] - 1);  // the fan's two connected faces
  EXPECT_EQ(internal, hexInternal + blockFaces);
  EXPECT_EQ(boundary, hexBoundary - 2 * blockFaces - (fan.size[0] - 1) * fanCells);
  // The prisms' corner at the edge: the span direction is square to both lines there, so a first
  // cell's scaled Jacobian is the sine of the angle between its two lines (its other corners are
  // near right angles in a thin first layer).
  const quality::CellQuality measured = quality::measureCellQuality(topology);
  for (int j = 0; j < fanCells; ++j) {
    for (int i = 0; i + 1 < fan.size[0]; ++i) {
      const Vector3d edge = fan.points.row(fan.index(i, j, 0)).transpose();
      const Vector3d first = fan.points.row(fan.index(i, j, 1)).transpose() - edge;
      const Vector3d second = fan.points.row(fan.index(i, j + 1, 1)).transpose() - edge;
      const double expected = first.cross(second).norm() / (first.norm() * second.norm());
      const Eigen::Index cell = topology.cellOffset(2) + i + (fan.size[0] - 1) * j;
      EXPECT_NEAR(measured.scaledJacobian[static_cast<size_t>(cell)], expected, 1e-9) << "cell " << i << ", " << j;
    }
  }
  for (Eigen::Index c = topology.cellOffset(2); c < topology.cellOffset(3); ++c) {
    EXPECT_GT(measured.volume[static_cast<size_t>(c)], 0.0);
    EXPECT_GT(measured.scaledJacobian[static_cast<size_t>(c)], 0.3);  // about sin(160 / 6 degrees) = 0.45
  }
  quality::requirePositiveCells(topology);
}

TEST(CollapsedFace, HexCellsWithAMergedCornerAreMeasuredAsPrismsAndInvertedOnesStayNegative) {
  // A wedge with its edge along x: corners 000 and 010 one point, 100 and 110 one point.
  const double angle = 40.0 * M_PI / 180.0;
  const Vector3d a = Vector3d::Zero();
  auto top = [&](double x, double side) { return Vector3d(x, std::sin(side * angle / 2), std::cos(side * angle / 2)); };
  std::array<Vector3d, 8> wedge{a, Vector3d(1, 0, 0), Vector3d(1, 0, 0), a,
                                top(0, -1), top(1, -1), top(1, 1), top(0, 1)};
  EXPECT_NEAR(hexScaledJacobian(wedge), std::sin(angle), 1e-12);
  std::swap(wedge[4], wedge[7]);
  std::swap(wedge[5], wedge[6]);
  EXPECT_LT(hexScaledJacobian(wedge), -std::sin(angle) + 1e-12);
  // The same wedge with its edge on top (corners 001 and 011 one point, 101 and 111 one point):
  // the merged corners' differing edges point into them.
  std::array<Vector3d, 8> upsideDown{top(0, -1), top(1, -1),        top(1, 1),         top(0, 1),
                                     a,          Vector3d(1, 0, 0), Vector3d(1, 0, 0), a};
  for (Vector3d& x : upsideDown) x.z() = -x.z();
  EXPECT_NEAR(hexScaledJacobian(upsideDown), std::sin(angle), 1e-12);
  // Merged along two directions at once (all four bottom corners one point): a pyramid, whose
  // apex is no corner of its own; measured by its base.
  std::array<Vector3d, 8> pyramid{a, a, a, a, Vector3d(-1, -1, 1), Vector3d(1, -1, 1), Vector3d(1, 1, 1), Vector3d(-1, 1, 1)};
  EXPECT_GT(hexScaledJacobian(pyramid), 0.0);
  // All eight corners one point: nothing to measure, not a cell.
  std::array<Vector3d, 8> point{};
  point.fill(Vector3d(1, 2, 3));
  EXPECT_EQ(hexScaledJacobian(point), -1.0);
}

TEST(CollapsedFace, AnEdgeOfZeroLengthOnNoCollapsedFaceIsRefusedByName) {
  // The fan's edge face called a wall: its edges along v have no length, and nothing says which
  // line they would take their points from.
  std::vector<Block> blocks = test::fanWedgeBlocks(kHalfWedge).blocks();
  blocks[2].faces[static_cast<size_t>(BlockFaceSide::WMin)].condition = BoundaryCondition::Wall;
  grid::RefinementOptions options;
  options.normalPoints = 9;
  options.tangentialSpacing = 0.5;
  try {
    grid::refineBlockMesh(BlockMesh(std::move(blocks)), options);
    FAIL() << "refined an edge of zero length on a wall face";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(
        std::string(error.what()).find("block 2 has an edge of zero length along v on no collapsed face"),
        std::string::npos)
        << error.what();
  }
}

TEST(CollapsedFace, CellsPinchedWithoutACollapsedFaceAreNoCells) {
  // The refined fan with its edge face called a wall: its points there coincide but are distinct
  // points (each cell face on the edge a quad of no area), so its cells there are no prisms.
  std::vector<grid::GridBlock> blocks = refinedFan().grid.blocks();
  volume::BlockFace& edge = blocks[2].faces[static_cast<size_t>(BlockFaceSide::WMin)];
  edge.condition = BoundaryCondition::Wall;
  const grid::StructuredGrid pinched(blocks, false);
  const grid::HexTopology topology(pinched);
  const std::vector<double> jacobians = quality::cellScaledJacobians(topology);
  const grid::GridBlock& fan = blocks[2];
  const Eigen::Index fanCells =
      static_cast<Eigen::Index>(fan.size[0] - 1) * (fan.size[1] - 1) * (fan.size[2] - 1);
  const Eigen::Index firstFanCell = topology.cellCount() - fanCells;
  int onEdge = 0;
  for (Eigen::Index c = firstFanCell; c < topology.cellCount(); ++c)
    onEdge += jacobians[static_cast<size_t>(c)] == -1.0;
  EXPECT_EQ(onEdge, (fan.size[0] - 1) * (fan.size[1] - 1));
  EXPECT_THROW(quality::requirePositiveCells(topology), InvalidInputError);
}

TEST(CollapsedFace, QuadConditionsNeitherNameNorLieOnACollapsedFace) {
  const std::vector<grid::GridBlock> refined = refinedFan().grid.blocks();
  // The fan block with every quad of one face given `condition`: refused, or "accepted".
  auto refusal = [&](BlockFaceSide side, BoundaryCondition condition) -> std::string {
    std::vector<grid::GridBlock> blocks = refined;
    const std::array<int, 2> counts = faceGridCounts(blocks[2].size, static_cast<int>(side));
    blocks[2].quadConditions[static_cast<size_t>(side)].assign(
        static_cast<size_t>((counts[0] - 1) * (counts[1] - 1)), condition);
    try {
      grid::StructuredGrid grid(std::move(blocks), false);
    } catch (const InvalidInputError& error) {
      return error.what();
    }
    return "accepted";
  };
  // Quads of a far-field face marked collapsed, and quad conditions on the collapsed face.
  EXPECT_NE(refusal(BlockFaceSide::WMax, BoundaryCondition::Collapsed)
                .find("grid block 2 face w_max (farfield) has"),
            std::string::npos);
  EXPECT_NE(
      refusal(BlockFaceSide::WMin, BoundaryCondition::Wall).find("grid block 2 face w_min (collapsed) has"),
      std::string::npos);
  EXPECT_EQ(refusal(BlockFaceSide::WMax, BoundaryCondition::Farfield), "accepted");
}

TEST(CollapsedFace, VolumetricSubdivisionRefusesItByName) {
  try {
    grid::subdivideBlockMesh(test::fanWedgeBlocks(kHalfWedge), 1);
    FAIL() << "subdivided a collapsed block";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("block 2 face w_min is collapsed"), std::string::npos) << error.what();
  }
}

TEST(CollapsedFace, TheBlockFileKeepsTheCollapsedFace) {
  std::stringstream file;
  writeBlockMesh(test::fanWedgeBlocks(kHalfWedge), file);
  EXPECT_NE(file.str().find("face w_min collapsed"), std::string::npos);
  const BlockMesh read = readBlockMesh(file, "the fan");
  EXPECT_TRUE(read.blocks()[2].faces[static_cast<size_t>(BlockFaceSide::WMin)].collapsedAlong[1]);
  EXPECT_TRUE(read.blocks()[2].volume.poles() == test::fanWedgeBlocks(kHalfWedge).blocks()[2].volume.poles());
}

}  // namespace
}  // namespace bvmesh::volume

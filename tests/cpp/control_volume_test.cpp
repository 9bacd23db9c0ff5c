// The control volume marched from a wall's own Catmull-Clark control mesh, against independent
// truths: its wall refined by volumetric subdivision equals the surface stage's subdivision of the
// wall (creases included), its grid's wall points are the wall's limit points, its blocks cover
// every cell once with right-handed cells, and its symmetry faces stay in the plane.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/common/errors.h"
#include "core/grid/subdivision_refinement.h"
#include "core/subdiv/limit_samples.h"
#include "core/volume/control_volume.h"
#include "surface_test_meshes.h"

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

// The largest distance from a point of `a` to the nearest point of `b`, both ways: zero when the
// two are the same point set in any order.
double setDistance(const RowMatrixX3d& a, const RowMatrixX3d& b) {
  auto oneWay = [](const RowMatrixX3d& from, const RowMatrixX3d& to) {
    double worst = 0.0;
    for (Eigen::Index r = 0; r < from.rows(); ++r) worst = std::max(worst, std::sqrt((to.rowwise() - from.row(r)).rowwise().squaredNorm().minCoeff()));
    return worst;
  };
  return std::max(oneWay(a, b), oneWay(b, a));
}

// A boundary layer of 0.2 in 4 layers on walls about 2 across: thinner control cells (0.1) next to
// the creased equator turn over in the first step, where the wall follows the crease rule and the
// points above it the smooth interior rule (docs/volume.md).
VolumeMeshOptions smallDomain() {
  VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.2;
  options.farfieldDistance = 20.0;
  return options;
}

TEST(ControlVolume, WallRefinesAsTheSurfaceStageRefinesTheWall) {
  // A cube with a creased equator: the crease must reach the volume's wall, else the smooth rules
  // round it and the refined wall differs from the surface's.
  const surface::QuadControlMesh wall = surface::testing::subdivide(surface::testing::cubeWithCreasedEquator(), 1);
  ASSERT_GT(wall.creases.rows(), 0);
  const ControlVolume volume = controlVolumeMesh(wall, smallDomain());
  EXPECT_EQ(volume.mesh.creases.rows(), wall.creases.rows());
  HexMesh refined = volume.mesh;
  for (int step = 0; step < 2; ++step) refined = subdivideHexMesh(refined).mesh;
  const WallControlMesh refinedWall = wallControlMesh(refined);
  const surface::QuadControlMesh surface = surface::testing::subdivide(wall, 2);
  ASSERT_EQ(refinedWall.mesh.numVertices(), surface.vertices.rows());
  EXPECT_LT(setDistance(refinedWall.mesh.vertices(), surface.vertices), 1e-13);

  // Without the crease tags one step already rounds the equator off.
  HexMesh smooth = volume.mesh;
  smooth.creases.resize(0, 2);
  smooth = subdivideHexMesh(smooth).mesh;
  EXPECT_GT(setDistance(wallControlMesh(smooth).mesh.vertices(), surface::testing::subdivide(wall, 1).vertices), 1e-3);
}

TEST(ControlVolume, BlocksCoverEveryCellOnceAndTheHalfModelStaysOnItsPlane) {
  const surface::QuadControlMesh half = surface::testing::upperHalfOfRefinedCube();
  VolumeMeshOptions options = smallDomain();
  try {
    controlVolumeMesh(half, options);
    ADD_FAILURE() << "an open wall without a symmetry plane was accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("the wall is open at control vertex"), std::string::npos) << error.what();
  }
  options.hasSymmetryPlane = true;
  options.planeNormal = Vector3d::UnitZ();
  const ControlVolume volume = controlVolumeMesh(half, options);

  std::vector<int> cellUses(volume.mesh.cells.size(), 0);
  for (const HexBlock& block : volume.blocks) {
    ASSERT_EQ(block.size[2], static_cast<int>(volume.layerDistance.size()));
    for (int k = 0; k + 1 < block.size[2]; ++k) {
      for (int j = 0; j + 1 < block.size[1]; ++j) {
        for (int i = 0; i + 1 < block.size[0]; ++i) {
          const int c = block.cellAt[block.cell(i, j, k)];
          ++cellUses[static_cast<size_t>(c)];
          for (size_t q = 0; q < 8; ++q) {
            const auto& bits = kHexCornerBits[q];
            EXPECT_EQ(volume.mesh.cells[static_cast<size_t>(c)][q], block.pointAt[block.point(i + bits[0], j + bits[1], k + bits[2])]);
          }
        }
      }
    }
  }
  EXPECT_TRUE(std::all_of(cellUses.begin(), cellUses.end(), [](int uses) { return uses == 1; }));
  for (const auto& cell : volume.mesh.cells) {
    for (double jacobian : cornerJacobians(volume.mesh.points, cell, true)) EXPECT_GT(jacobian, 0.1);
  }
  int symmetryFaces = 0;
  for (size_t f = 0; f < volume.mesh.boundaryFaces.size(); ++f) {
    if (volume.mesh.boundaryConditions[f] != BoundaryCondition::Symmetry) continue;
    ++symmetryFaces;
    for (int p : volume.mesh.boundaryFaces[f]) EXPECT_LT(std::abs(volume.mesh.points(p, 2)), 1e-12 * 20.0);
  }
  EXPECT_GT(symmetryFaces, 0);

  // The grid of one step: point-matched blocks (the StructuredGrid checks it), its wall points
  // the wall's limit points at its vertices, edge midpoints and face centres, its symmetry points
  // on the plane.
  const grid::StructuredGrid grid = grid::subdivideControlVolume(volume, 1);
  EXPECT_EQ(grid.blockCount(), static_cast<int>(volume.blocks.size()));
  std::vector<Vector3d> wallPoints;
  for (const grid::GridBlock& block : grid.blocks()) {
    for (int j = 0; j < block.size[1]; ++j) {
      for (int i = 0; i < block.size[0]; ++i) wallPoints.emplace_back(block.points.row(block.index(i, j, 0)));
    }
  }
  RowMatrixX3d gridWall(static_cast<Eigen::Index>(wallPoints.size()), 3);
  for (size_t r = 0; r < wallPoints.size(); ++r) gridWall.row(static_cast<Eigen::Index>(r)) = wallPoints[r].transpose();
  const RowMatrixX3d limit = LimitSamples(surface::toControlMesh(half)).positions(half.vertices);
  EXPECT_LT(setDistance(gridWall, limit), 1e-12);
}

TEST(ControlVolume, InwardWallGetsAClearError) {
  surface::QuadControlMesh inward = surface::testing::subdivide(surface::testing::cube(), 1);
  for (Eigen::Index f = 0; f < inward.faces.rows(); ++f) std::swap(inward.faces(f, 1), inward.faces(f, 3));
  try {
    controlVolumeMesh(inward, smallDomain());
    ADD_FAILURE() << "an inward wall was accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("oriented inwards"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace bvmesh::volume

// Refinement of hand-made block meshes (every connection orientation, a mirrored block) against
// the affine map they represent: point matching, counts, clustering, the even far field and folds.
// Distributions: grid_distribution_test.cpp; cell quality: quality_test.cpp; the OpenFOAM writer:
// openfoam_writer_test.cpp.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "block_fixtures.h"
#include "core/common/errors.h"
#include "core/grid/distribution.h"
#include "core/grid/folded_cells.h"
#include "core/grid/refinement.h"
#include "grid_fixtures.h"

namespace bvmesh::grid {
namespace {

using Eigen::Vector3d;

TEST(GridRefinement, AffineBoxGivesTheExactLattice) {
  // Unwarped, every block is an affine map: uniform arc length along x and y is a uniform
  // lattice, and the wall-normal lines from the wall at z = 0 follow the geometric law exactly.
  const test::BoxBlocks box = test::boxBlocks(0.0, true, 1);
  RefinementOptions options = test::affineBoxOptions();
  options.firstCellHeight = 0.01;
  options.growth = 1.8;
  const RefinedGrid refined = refineBlockMesh(box.mesh, options);
  const StructuredGrid& grid = refined.grid;
  ASSERT_EQ(grid.blockCount(), 4);
  EXPECT_TRUE(grid.viscousWall());
  EXPECT_EQ(grid.cellCount(), 4 * 4 * 4 * 8);
  const double growth = geometricGrowth(9, 0.01, 1.0);
  const std::vector<double> law = geometricDistances(9, 0.01, growth, 1.0);
  for (const GridBlock& block : grid.blocks()) {
    for (Eigen::Index r = 0; r < block.points.rows(); ++r) {
      const Vector3d x = block.points.row(r).transpose();
      for (int axis = 0; axis < 2; ++axis)
        EXPECT_NEAR(std::remainder(x[axis] * 4.0, 1.0), 0.0, 1e-9) << x.transpose();
      EXPECT_TRUE(std::any_of(law.begin(), law.end(), [&](double d) { return std::abs(d - x.z()) < 1e-9; }))
          << x.transpose();
    }
  }
  EXPECT_NEAR(refined.firstCellHeightMin, 0.01, 1e-12);
  EXPECT_NEAR(refined.firstCellHeightMax, 0.01, 1e-12);
  EXPECT_NEAR(refined.growthMax, growth, 1e-9);
}

TEST(GridRefinement, APointBudgetRefusesALargerGridByItsPlannedSize) {
  // 4 blocks of 5 x 5 x 9 points: allowed at exactly that many, refused one below, and a count
  // far beyond any machine (100 000 points per edge) refused before a point is computed.
  const test::BoxBlocks box = test::boxBlocks(0.0, true, 1);
  RefinementOptions options = test::affineBoxOptions();
  options.maxPoints = 4 * 5 * 5 * 9;
  EXPECT_EQ(refineBlockMesh(box.mesh, options).grid.cellCount(), 4 * 4 * 4 * 8);
  options.maxPoints -= 1;
  try {
    refineBlockMesh(box.mesh, options);
    ADD_FAILURE() << "a grid above its point budget was refined";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("the grid would have 900 points, more than max_points (899"),
              std::string::npos)
        << error.what();
  }
  options.edgePoints = kMaxEdgePoints;
  options.maxPoints = 100000000;
  EXPECT_THROW(refineBlockMesh(box.mesh, options), InvalidInputError);
  options.maxPoints = -1;
  EXPECT_THROW(refineBlockMesh(box.mesh, options), InvalidInputError);
}

TEST(GridRefinement, WarpedBoxIsPointMatchedWithExactWallSpacing) {
  const test::BoxBlocks box = test::boxBlocks(0.08, true, 1);
  RefinementOptions options;
  options.tangentialSpacing = 0.09;
  options.normalPoints = 0;
  options.firstCellHeight = 1e-5;
  options.edgeEndSpacing = 0.02;
  const RefinedGrid refined =
      refineBlockMesh(box.mesh, options);  // the grid's constructor checks matching bit for bit
  EXPECT_GE(refined.grid.blocks()[0].size[0], 13);
  EXPECT_NEAR(refined.firstCellHeightMin / 1e-5, 1.0, 1e-9);
  EXPECT_NEAR(refined.firstCellHeightMax / 1e-5, 1.0, 1e-9);
  EXPECT_LE(refined.growthMax, 1.2 * (1 + 1e-6));
  // One point fewer than chosen would need a larger growth.
  options.normalPoints = refined.normalPoints - 1;
  EXPECT_THROW(refineBlockMesh(box.mesh, options), InvalidInputError);
  // A cell target: within a block's worth of the asked count.
  options.normalPoints = 17;
  options.firstCellHeight = 0.0;
  options.tangentialSpacing = 0.0;
  options.targetCells = 20000;
  const RefinedGrid target = refineBlockMesh(box.mesh, options);
  EXPECT_NEAR(static_cast<double>(target.grid.cellCount()), 20000.0, 0.3 * 20000.0);
}

// The one-layer box of block_fixtures.h with every pole moved by `map` (its wall at z = 0).
template <class Map>
volume::BlockMesh mappedOneLayerBox(Map map) {
  std::vector<volume::Block> blocks = test::boxBlocks(0.0, true, 1).mesh.blocks();
  for (volume::Block& block : blocks) {
    const RowMatrixX3d poles = block.volume.poles();
    for (Eigen::Index row = 0; row < poles.rows(); ++row)
      block.volume.setPole(row, map(Vector3d(poles.row(row).transpose())));
  }
  return volume::BlockMesh(blocks);
}

TEST(GridRefinement, TangentialCountsFollowTheWallNotTheFarField) {
  // The one-layer box flared to four times its width at the top (x and y scaled by 1 + 3 z):
  // every wall edge is 1 long, every top edge 4. The tangential spacing is a wall resolution, so
  // a block that fans out to a large outer face keeps the count its wall edge needs (counting
  // the top edges gave 17 points where the wall asks for 5, and crowded small wall blocks).
  const volume::BlockMesh flared = mappedOneLayerBox([](const Vector3d& x) {
    const double scale = 1.0 + 3.0 * x.z();
    return Vector3d(scale * x.x(), scale * x.y(), x.z());
  });
  RefinementOptions options;
  options.tangentialSpacing = 0.25;
  options.normalPoints = 9;
  const RefinedGrid refined = refineBlockMesh(flared, options);
  for (const auto& block : refined.grid.blocks()) {
    int tangential = 0;
    for (int d = 0; d < 3; ++d) {
      if (block.size[static_cast<size_t>(d)] == 9) continue;  // the wall-normal direction
      EXPECT_EQ(block.size[static_cast<size_t>(d)], 5);
      ++tangential;
    }
    EXPECT_EQ(tangential, 2);
  }
}

// The grid points of `refined` with z within `tolerance` of `height`, by block.
std::vector<std::vector<Vector3d>> pointsAtHeight(const RefinedGrid& refined, double height,
                                                  double tolerance) {
  std::vector<std::vector<Vector3d>> result;
  for (const GridBlock& block : refined.grid.blocks()) {
    result.emplace_back();
    for (Eigen::Index p = 0; p < block.points.rows(); ++p) {
      if (std::abs(block.points(p, 2) - height) <= tolerance)
        result.back().push_back(block.points.row(p).transpose());
    }
  }
  return result;
}

// The steps between the sorted x of the points on the line y = 0 of the layer, over all blocks.
std::vector<double> stepsAlongX(const std::vector<std::vector<Vector3d>>& layer) {
  std::vector<double> x;
  for (const auto& block : layer) {
    for (const Vector3d& point : block) {
      if (std::abs(point.y()) < 1e-12) x.push_back(point.x());
    }
  }
  std::sort(x.begin(), x.end());
  x.erase(std::unique(x.begin(), x.end(), [](double a, double b) { return std::abs(a - b) < 1e-12; }),
          x.end());
  std::vector<double> steps;
  for (size_t i = 1; i < x.size(); ++i) steps.push_back(x[i] - x[i - 1]);
  return steps;
}

// The ratio of the largest to the smallest of steps [first, last).
double stepSpread(const std::vector<double>& steps, size_t first, size_t last) {
  const auto [low, high] = std::minmax_element(steps.begin() + static_cast<std::ptrdiff_t>(first),
                                               steps.begin() + static_cast<std::ptrdiff_t>(last));
  return *high / *low;
}

TEST(GridRefinement, BlocksThatFoldWhereSampledCoarselyTakeTwiceTheCells) {
  // The one-layer box bent round the z axis' parallel through the origin: x -> angle, z -> radius
  // 1 + z, y -> height; each block's x spans `degrees`. The blocks are valid B-spline volumes,
  // but a cell whose corners lie more than 180 degrees apart round the bend is turned inside out:
  // at 200 degrees per block, one cell per edge folds, two do not.
  auto bent = [](double degrees) {
    const double perUnit = degrees * M_PI / 180.0;
    return mappedOneLayerBox([perUnit](const Vector3d& x) {
      const double angle = perUnit * x.x(), radius = 1.0 + x.z();
      return Vector3d(radius * std::cos(angle), radius * std::sin(angle), x.y());
    });
  };
  RefinementOptions options;
  options.edgePoints = 2;
  options.normalPoints = 3;
  const RefinedGrid folding = refineBlockMesh(bent(200.0), options);
  EXPECT_EQ(folding.foldRefinements, 1);
  EXPECT_EQ(folding.grid.cellCount(), 4 * 2 * 2 * 2);
  EXPECT_EQ(foldedBlocks(folding.grid.blocks()), std::vector<char>(4, 0));
  const RefinedGrid valid = refineBlockMesh(bent(150.0), options);
  EXPECT_EQ(valid.foldRefinements, 0);
  EXPECT_EQ(valid.grid.cellCount(), 4 * 1 * 1 * 2);
  // Blocks inside out (the box mirrored) fold however finely sampled: the grid comes back as it was.
  const RefinedGrid inverted = refineBlockMesh(
      mappedOneLayerBox([](const Vector3d& x) { return Vector3d(-x.x(), x.y(), x.z()); }), options);
  EXPECT_EQ(inverted.foldRefinements, 0);
  EXPECT_EQ(inverted.grid.cellCount(), 4 * 1 * 1 * 2);
  // The finer grid (4 blocks of 3 x 3 x 3 points) fits in the point budget beside the folded one
  // (4 of 2 x 2 x 3) it replaces, or the folded one stands.
  options.maxPoints = 48 + 108;
  EXPECT_EQ(refineBlockMesh(bent(200.0), options).foldRefinements, 1);
  options.maxPoints = 48 + 107;
  const RefinedGrid overBudget = refineBlockMesh(bent(200.0), options);
  EXPECT_EQ(overBudget.foldRefinements, 0);
  EXPECT_EQ(foldedBlocks(overBudget.grid.blocks()), std::vector<char>(4, 1));
}

TEST(GridRefinement, AnEvenFarFieldSpreadsTheOuterPointsAndKeepsTheWall) {
  // The one-layer box spread unevenly at the top (x -> x (1 + 1.5 z x), the same in y): the wall
  // (z = 0) keeps its evenly spaced points, and the lines through them reach the top unevenly
  // (the first block's top edge, x = 0 .. 2.5, takes steps growing 2.5 times). With
  // even_far_field the lines slide to points uniform in arc length on the outer edges.
  const volume::BlockMesh spread = mappedOneLayerBox([](const Vector3d& x) {
    return Vector3d(x.x() * (1.0 + 1.5 * x.z() * x.x()), x.y() * (1.0 + 1.5 * x.z() * x.y()), x.z());
  });
  RefinementOptions options;
  options.edgePoints = 9;
  options.firstCellHeight = 0.01;
  options.normalPoints = 0;  // as many as the longest line needs: the slid lines are longer
  const RefinedGrid plain = refineBlockMesh(spread, options);
  EXPECT_FALSE(plain.evenFarFieldUsed);
  options.evenFarField = true;
  const RefinedGrid even = refineBlockMesh(spread, options);  // point-matched (checked) in every orientation
  EXPECT_TRUE(even.evenFarFieldUsed);

  const std::vector<double> plainTop = stepsAlongX(pointsAtHeight(plain, 1.0, 1e-12));
  const std::vector<double> evenTop = stepsAlongX(pointsAtHeight(even, 1.0, 1e-12));
  ASSERT_EQ(plainTop.size(), 16u);
  ASSERT_EQ(evenTop.size(), 16u);
  EXPECT_GT(stepSpread(plainTop, 0, 8), 2.4) << ::testing::PrintToString(plainTop);
  // Block edges from x = 0 to 2.5 and from 2.5 to 8 (the wall's x = 1 at the top), 8 cells each,
  // uniform to the accuracy of the edges' arc-length tables.
  for (size_t i = 0; i < evenTop.size(); ++i)
    EXPECT_NEAR(evenTop[i] / (i < 8 ? 2.5 / 8 : 5.5 / 8), 1.0, 1e-3) << i;

  // The wall and the first cell heights are untouched, the growth stays within its maximum.
  EXPECT_EQ(pointsAtHeight(even, 0.0, 0.0), pointsAtHeight(plain, 0.0, 0.0));
  EXPECT_NEAR(even.firstCellHeightMin, 0.01, 1e-12);
  EXPECT_NEAR(even.firstCellHeightMax, 0.01, 1e-12);
  EXPECT_LE(even.growthMax, 1.2 * (1 + 1e-9));

  // A wall clustered at its block edges' ends (edge_end_spacing 0.02): the outer edges stay even.
  options.edgeEndSpacing = 0.02;
  const RefinedGrid clustered = refineBlockMesh(spread, options);
  EXPECT_NEAR(stepsAlongX(pointsAtHeight(clustered, 0.0, 0.0)).front(), 0.02, 1e-9);
  const std::vector<double> top = stepsAlongX(pointsAtHeight(clustered, 1.0, 1e-12));
  EXPECT_LT(stepSpread(top, 0, 8), 1.01) << ::testing::PrintToString(top);
}

TEST(GridRefinement, WallEdgesThatTurnGetTheirPointsFromTheTurningLimit) {
  // The one-layer box bent round the y axis: x in [0, 2] becomes a quarter circle of radius 1 + z
  // (poles mapped, so the wall is close to the unit cylinder), y stays straight. With a coarse
  // spacing (0.6) alone the x edges get 3 points (60 degrees per cell); a 5-degree turning limit
  // gives each block's 45 degrees of wall at least 9 cells, placed so that no wall cell turns
  // more, while the straight y edges keep the spacing's count.
  const volume::BlockMesh mesh = mappedOneLayerBox([](const Vector3d& x) {
    const double angle = 0.25 * M_PI * x.x(), radius = 1.0 + x.z();
    return Vector3d(radius * std::sin(angle), x.y(), radius * std::cos(angle));
  });
  RefinementOptions options;
  options.tangentialSpacing = 0.6;
  options.normalPoints = 5;
  const RefinedGrid coarse = refineBlockMesh(mesh, options);
  options.maxTurningDegrees = 5.0;
  const RefinedGrid refined = refineBlockMesh(mesh, options);
  int turningEdges = 0;
  for (size_t b = 0; b < refined.grid.blocks().size(); ++b) {
    const GridBlock& block = refined.grid.blocks()[b];
    int wall = -1;
    for (int f = 0; f < 6; ++f) {
      if (block.faces[static_cast<size_t>(f)].condition == volume::BoundaryCondition::Wall) wall = f;
    }
    ASSERT_GE(wall, 0);
    const std::array<int, 2> along = volume::faceDirections(wall);
    for (int axis = 0; axis < 2; ++axis) {
      const int d = along[static_cast<size_t>(axis)];
      const int n = block.size[static_cast<size_t>(d)];
      const int other = block.size[static_cast<size_t>(along[static_cast<size_t>(1 - axis)])];
      auto wallPoint = [&](int i, int j) {
        return Vector3d(
            block.points.row(axis == 0 ? block.facePoint(wall, i, j) : block.facePoint(wall, j, i))
                .transpose());
      };
      // The direction's grid lines on the wall: do they bend (x) or run straight (y)?
      const Vector3d first = wallPoint(1, 0) - wallPoint(0, 0),
                     last = wallPoint(n - 1, 0) - wallPoint(n - 2, 0);
      const bool turns = std::abs(first.normalized().dot(last.normalized())) < 0.99;
      const int coarseCount = coarse.grid.blocks()[b].size[static_cast<size_t>(d)];
      if (!turns) {
        EXPECT_EQ(n, coarseCount);
        continue;
      }
      ++turningEdges;
      EXPECT_EQ(coarseCount, 3);
      EXPECT_GE(n, 10);
      for (int j = 0; j < other; ++j) {
        for (int i = 1; i + 1 < n; ++i) {
          const Vector3d a = wallPoint(i, j) - wallPoint(i - 1, j), c = wallPoint(i + 1, j) - wallPoint(i, j);
          // Consecutive chords turn by the mean of the two cells' turnings.
          EXPECT_LE(std::atan2(a.cross(c).norm(), a.dot(c)) * 180.0 / M_PI, 5.0 * 1.05);
        }
      }
    }
  }
  EXPECT_EQ(turningEdges, 4);
  // With a fixed edge_points count the count stays as asked.
  options.tangentialSpacing = 0.0;
  options.edgePoints = 6;
  const RefinedGrid counted = refineBlockMesh(mesh, options);
  for (const GridBlock& block : counted.grid.blocks()) {
    EXPECT_EQ(std::count(block.size.begin(), block.size.end(), 6), 2);
  }
}

TEST(GridRefinement, EveryOrientationAndAMirroredBlockArePointMatched) {
  // No wall: every direction from its block's edges, blended; the warped 2 x 2 x 2 box with its
  // turned and mirrored blocks comes out point-matched (checked bit for bit by StructuredGrid).
  const test::BoxBlocks box = test::boxBlocks(0.08, false, 2);
  RefinementOptions options;
  options.edgePoints = 7;
  options.edgeEndSpacing = 0.05;
  const RefinedGrid refined = refineBlockMesh(box.mesh, options);
  EXPECT_EQ(refined.grid.cellCount(), 8 * 6 * 6 * 6);
  EXPECT_FALSE(refined.grid.viscousWall());
}

// An unwarped block of [x0, x0 + 1] x [0, 1] x [0, 1] with its wall at z = 1, the upper end of w,
// whose w knots are `wKnots` and whose poles in w are at z = (Greville)^2: straight wall-normal
// lines parameterised unevenly.
volume::Block upperWallBlock(double x0, const std::vector<double>& wKnots) {
  const std::vector<double> knots = uniformClampedKnots(3, 1);
  const std::vector<double> across = grevilleAbscissae(knots, 3);
  const std::vector<double> along = grevilleAbscissae(wKnots, 3);
  RowMatrixX3d poles(static_cast<Eigen::Index>(16 * along.size()), 3);
  Eigen::Index row = 0;
  for (const double w : along) {
    for (const double v : across) {
      for (const double u : across) poles.row(row++) = Vector3d(x0 + u, v, w * w).transpose();
    }
  }
  volume::Block block;
  block.volume = volume::BsplineVolume({3, 3, 3}, {knots, knots, wKnots}, poles);
  block.faces[5].condition = volume::BoundaryCondition::Wall;
  return block;
}

TEST(GridRefinement, UpperEndWallsOnUnevenKnotsFollowTheLawInEveryBlock) {
  // Two blocks with different w knot vectors, refined together (their wall-normal lines share
  // threads and chunks): every line runs down from z = 1 by the geometric law of its own length,
  // placed in point distances (the arc-length inversion alone was ~1e-4 off on the long last
  // span), and its first spacing is exact.
  std::vector<volume::Block> blocks{upperWallBlock(0.0, {0, 0, 0, 0, 0.1, 0.3, 1, 1, 1, 1}),
                                    upperWallBlock(2.0, {0, 0, 0, 0, 0.6, 1, 1, 1, 1})};
  RefinementOptions options;
  options.edgePoints = 7;
  options.normalPoints = 0;
  options.firstCellHeight = 1e-3;
  const RefinedGrid refined = refineBlockMesh(volume::BlockMesh(std::move(blocks)), options);
  const int points = refined.normalPoints;
  const std::vector<double> law = geometricDistances(points, 1e-3, geometricGrowth(points, 1e-3, 1.0), 1.0);
  for (const GridBlock& block : refined.grid.blocks()) {
    ASSERT_EQ(block.size[2], points);
    for (int j = 0; j < block.size[1]; ++j) {
      for (int i = 0; i < block.size[0]; ++i) {
        for (int k = 0; k < points; ++k) {
          const double z = block.points(block.index(i, j, k), 2);
          EXPECT_NEAR(1.0 - z, law[static_cast<size_t>(points - 1 - k)], 1e-12) << i << " " << j << " " << k;
        }
        EXPECT_NEAR(
            block.points(block.index(i, j, points - 1), 2) - block.points(block.index(i, j, points - 2), 2),
            1e-3, 1e-15);
      }
    }
  }
}

// Joins block 0's u_max face to block 1's u_min face, orientations alike.
void connectAlongU(std::vector<volume::Block>& blocks) {
  blocks[0].faces[1].condition = volume::BoundaryCondition::Connected;
  blocks[0].faces[1].neighbour.block = 1;
  blocks[0].faces[1].neighbour.face = 0;
  blocks[1].faces[0].condition = volume::BoundaryCondition::Connected;
  blocks[1].faces[0].neighbour.block = 0;
  blocks[1].faces[0].neighbour.face = 1;
}

// Two blocks side by side over the wall z = 0 ([0, 1] and [1, 2] in x, [0, 1] in y, connected
// at x = 1), whose wall-normal lines rise from the wall, turn by 60 degrees round a circle of
// radius 0.3 + 0.2 y and run on straight: bent in one part, straight in the other, and
// parameterised unevenly (poles at path length ~ g^1.5 of their Greville abscissae g).
std::vector<volume::Block> bentLineBlocks() {
  const std::vector<double> knots = uniformClampedKnots(3, 1);
  const std::vector<double> wKnots{0, 0, 0, 0, 0.05, 0.15, 0.3, 0.5, 0.75, 1, 1, 1, 1};
  const std::vector<double> across = grevilleAbscissae(knots, 3);
  const std::vector<double> along = grevilleAbscissae(wKnots, 3);
  auto path = [](double x, double y, double s) {
    const double radius = 0.3 + 0.2 * y, turn = M_PI / 3.0;
    if (s <= radius * turn)
      return Vector3d(x + radius * (1.0 - std::cos(s / radius)), y, radius * std::sin(s / radius));
    const Vector3d bend(x + radius * (1.0 - std::cos(turn)), y, radius * std::sin(turn));
    return Vector3d(bend + (s - radius * turn) * Vector3d(std::sin(turn), 0.0, std::cos(turn)));
  };
  std::vector<volume::Block> blocks(2);
  for (int b = 0; b < 2; ++b) {
    RowMatrixX3d poles(static_cast<Eigen::Index>(16 * along.size()), 3);
    Eigen::Index row = 0;
    for (const double w : along) {
      for (const double v : across) {
        for (const double u : across) poles.row(row++) = path(b + u, v, 1.5 * std::pow(w, 1.5)).transpose();
      }
    }
    blocks[static_cast<size_t>(b)].volume = volume::BsplineVolume({3, 3, 3}, {knots, knots, wKnots}, poles);
    blocks[static_cast<size_t>(b)].faces[4].condition = volume::BoundaryCondition::Wall;
  }
  connectAlongU(blocks);
  return blocks;
}

// The largest and smallest ratio of consecutive point distances along the k lines of every block,
// measured on the grid's points.
std::pair<double, double> measuredGrowth(const StructuredGrid& grid) {
  double largest = 0.0, smallest = std::numeric_limits<double>::infinity();
  for (const GridBlock& block : grid.blocks()) {
    for (int j = 0; j < block.size[1]; ++j) {
      for (int i = 0; i < block.size[0]; ++i) {
        for (int k = 2; k < block.size[2]; ++k) {
          auto at = [&](int level) {
            return Vector3d(block.points.row(block.index(i, j, level)).transpose());
          };
          const double ratio = (at(k) - at(k - 1)).norm() / (at(k - 1) - at(k - 2)).norm();
          largest = std::max(largest, ratio);
          smallest = std::min(smallest, ratio);
        }
      }
    }
  }
  return {largest, smallest};
}

TEST(GridRefinement, BentWallNormalLinesKeepTheGrowthInPointDistances) {
  // The laws hold in straight point distances, not only in arc length, which on these lines
  // would put consecutive spacings up to ~1 % above the growth asked where the bend ends.
  const volume::BlockMesh mesh(bentLineBlocks());
  RefinementOptions options;
  options.edgePoints = 6;
  options.normalPoints = 0;
  options.firstCellHeight = 1e-3;
  const RefinedGrid clustered = refineBlockMesh(mesh, options);  // point matching checked bit for bit
  const auto [largest, smallest] = measuredGrowth(clustered.grid);
  EXPECT_LE(largest, 1.2 * (1 + 1e-9));
  EXPECT_LE(clustered.growthMax, 1.2 * (1 + 1e-9));
  EXPECT_GT(largest, 1.1);  // the fewest points, so some line grows by about the maximum
  EXPECT_NEAR(clustered.firstCellHeightMin / 1e-3, 1.0, 1e-11);
  EXPECT_NEAR(clustered.firstCellHeightMax / 1e-3, 1.0, 1e-11);
  // Without a first height (the euler preset) every line grows by exactly the growth asked.
  options.normalPoints = 21;
  options.firstCellHeight = 0.0;
  options.growth = 1.15;
  const RefinedGrid fixed = refineBlockMesh(mesh, options);
  const auto [most, least] = measuredGrowth(fixed.grid);
  EXPECT_NEAR(most / 1.15, 1.0, 1e-9);
  EXPECT_NEAR(least / 1.15, 1.0, 1e-9);
  EXPECT_LE(fixed.growthMax, 1.15 * (1 + 1e-9));
}

// A block with its wall at w = 0 over [x0, x0 + 1] x [0, 1], `height` tall; `zigzag` moves its
// inner pole layers sideways by that much, alternately, which lengthens its control polygon
// much more than its lines.
volume::Block wallBlockOfLines(double x0, double height, double zigzag) {
  const std::vector<double> knots = uniformClampedKnots(3, 1);
  const std::vector<double> wKnots = uniformClampedKnots(3, 4);
  const std::vector<double> across = grevilleAbscissae(knots, 3);
  const std::vector<double> along = grevilleAbscissae(wKnots, 3);
  RowMatrixX3d poles(static_cast<Eigen::Index>(16 * along.size()), 3);
  Eigen::Index row = 0;
  for (size_t layer = 0; layer < along.size(); ++layer) {
    const bool inner = layer > 0 && layer + 1 < along.size();
    const double shift = inner ? (layer % 2 == 0 ? zigzag : -zigzag) : 0.0;
    for (const double v : across) {
      for (const double u : across)
        poles.row(row++) = Vector3d(x0 + u + shift, v, height * along[layer] / along.back()).transpose();
    }
  }
  volume::Block block;
  block.volume = volume::BsplineVolume({3, 3, 3}, {knots, knots, wKnots}, poles);
  block.faces[4].condition = volume::BoundaryCondition::Wall;
  return block;
}

TEST(GridRefinement, AutomaticNormalPointsFollowTheLongestLineNotTheLongestPolygon) {
  // The automatic count measures lines in the order of a bound from their control polygons. Here
  // the zigzag block's polygons are the longest (its 81 lines come first, more than one round of
  // measured lines) but the straight block's lines are the longest: the count must come from them.
  const volume::Block zigzag = wallBlockOfLines(0.0, 1.0, 0.3);
  const volume::Block straight = wallBlockOfLines(3.0, 1.8, 0.0);
  double polygon = 0.0;
  const RowMatrixX3d& poles = zigzag.volume.poles();
  for (int k = 0; k + 1 < zigzag.volume.poleCount(2); ++k) {
    polygon += (poles.row(zigzag.volume.poleIndex(0, 0, k + 1)) - poles.row(zigzag.volume.poleIndex(0, 0, k)))
                   .norm();
  }
  RowMatrixX3d along(2001, 3), points;
  const double top = zigzag.volume.knots(2).back();
  for (Eigen::Index s = 0; s < along.rows(); ++s)
    along.row(s) << 0.5, 0.5, top * static_cast<double>(s) / 2000.0;
  zigzag.volume.evaluate(along, points);
  double line = 0.0;
  for (Eigen::Index s = 1; s < points.rows(); ++s) line += (points.row(s) - points.row(s - 1)).norm();
  ASSERT_GT(polygon, 3.0);  // the premise: a polygon far above the straight block's 1.8, a line below
  ASSERT_LT(line, 1.5);
  RefinementOptions options;
  options.edgePoints = 9;
  options.normalPoints = 0;
  options.firstCellHeight = 1e-3;
  const volume::BlockMesh mesh({zigzag, straight});
  const RefinedGrid refined = refineBlockMesh(mesh, options);
  EXPECT_EQ(refined.normalPoints, geometricPointsNeeded(1e-3, 1.2, 1.8));
  EXPECT_GT(refined.normalPoints, geometricPointsNeeded(1e-3, 1.2, line));
  EXPECT_LE(refined.growthMax, 1.2 * (1 + 1e-9));
}

// A block on the box [x0, x1] x [y0, y1] x [0, 1] (poles on the identity map), its wall at z = 0.
volume::Block wallBox(double x0, double x1, double y0 = 0.0, double y1 = 1.0) {
  const std::vector<double> knots = uniformClampedKnots(3, 1);
  const std::vector<double> at = grevilleAbscissae(knots, 3);
  RowMatrixX3d poles(64, 3);
  Eigen::Index row = 0;
  for (const double z : at) {
    for (const double y : at) {
      for (const double x : at)
        poles.row(row++) = Vector3d(x0 + (x1 - x0) * x, y0 + (y1 - y0) * y, z).transpose();
    }
  }
  volume::Block block;
  block.volume = volume::BsplineVolume({3, 3, 3}, {knots, knots, knots}, poles);
  block.faces[4].condition = volume::BoundaryCondition::Wall;
  return block;
}

// Two wall boxes joined at x = x1: [x0, x1] and [x1, x2] in x, [0, 1] in y and z.
volume::BlockMesh wallBoxesAlongX(double x0, double x1, double x2) {
  std::vector<volume::Block> blocks{wallBox(x0, x1), wallBox(x1, x2)};
  connectAlongU(blocks);
  return volume::BlockMesh(std::move(blocks));
}

// Distances between consecutive points of block b along `along`, through the point (1, 1, k).
std::vector<double> gridSteps(const RefinedGrid& refined, size_t b, int along, int k) {
  const GridBlock& block = refined.grid.blocks()[b];
  std::vector<double> steps;
  std::array<int, 3> ijk{1, 1, k};
  for (int i = 1; i < block.size[static_cast<size_t>(along)]; ++i) {
    std::array<int, 3> before = ijk;
    ijk[static_cast<size_t>(along)] = i;
    before[static_cast<size_t>(along)] = i - 1;
    steps.push_back((block.points.row(block.index(ijk[0], ijk[1], ijk[2])) -
                     block.points.row(block.index(before[0], before[1], before[2])))
                        .norm());
  }
  return steps;
}

TEST(GridRefinement, ASpacingJumpToAFinerNeighbourIsLimitedAtThatEnd) {
  // A long block (x 0 .. 10) continued along x by a thin one (10 .. 10.05): at spacing 0.5 the
  // thin block's one cell is 10 times finer. With max_spacing_jump 4 the long block's x lines
  // end at the thin block with 4 x 0.05, and their other end (no neighbour) is left free.
  const volume::BlockMesh mesh = wallBoxesAlongX(0.0, 10.0, 10.05);
  RefinementOptions options;
  options.tangentialSpacing = 0.5;
  options.normalPoints = 5;
  auto xSteps = [](const RefinedGrid& refined) { return gridSteps(refined, 0, 0, 0); };
  const RefinedGrid plain = refineBlockMesh(mesh, options);
  const std::vector<double> uniform = xSteps(plain);
  ASSERT_EQ(uniform.size(), 20u);
  EXPECT_NEAR(uniform.back(), 0.5, 1e-12);
  options.maxSpacingJump = 4.0;
  const RefinedGrid limited = refineBlockMesh(mesh, options);  // point-matched bit for bit (checked)
  const std::vector<double> steps = xSteps(limited);
  ASSERT_EQ(steps.size(), 20u);
  EXPECT_NEAR(steps.back(), 4.0 * 0.05, 1e-9);
  EXPECT_GT(steps.front(), 0.5);  // one-sided: the free end gets what the cluster gives up
  for (size_t i = 1; i < steps.size(); ++i) EXPECT_LT(steps[i], steps[i - 1]);
  // The thin block is not touched (its neighbour is coarser), nor is a jump within the limit.
  EXPECT_EQ(limited.grid.blocks()[1].points, plain.grid.blocks()[1].points);
  options.maxSpacingJump = 10.0;
  EXPECT_EQ(xSteps(refineBlockMesh(mesh, options)), uniform);
  options.maxSpacingJump = 0.5;
  EXPECT_THROW(refineBlockMesh(mesh, options), InvalidInputError);
}

TEST(GridRefinement, FeatureSpacingsClusterTheWallEdgesLeavingTheLine) {
  // Two blocks over the wall z = 0, x in [0, 1] and [1, 3], joined at x = 1 where a feature line
  // runs along y (a wing's leading edge, say): the x edges that end there start with the asked
  // spacing, their counts grow so that their steps grow by about `growth` away from it, and the
  // y edges along the line are left as they were.
  const volume::BlockMesh mesh = wallBoxesAlongX(0.0, 1.0, 3.0);
  RefinementOptions options;
  options.tangentialSpacing = 0.1;
  options.normalPoints = 5;
  const RefinedGrid plain = refineBlockMesh(mesh, options);
  RowMatrixX3d line(2, 3);
  line << 1.0, -1.0, 0.0, 1.0, 2.0, 0.0;
  options.featureSpacings = {FeatureSpacing{line, 0.01, 0.0}};
  const RefinedGrid clustered = refineBlockMesh(mesh, options);  // point-matched bit for bit (checked)
  for (int k : {0, 4}) {  // on the wall and at the far end of the wall-normal lines
    const std::vector<double> before = gridSteps(clustered, 0, 0, k), after = gridSteps(clustered, 1, 0, k);
    EXPECT_NEAR(before.back() / (k == 0 ? 0.01 : before.back()), 1.0, 1e-6);
    EXPECT_NEAR(after.front() / (k == 0 ? 0.01 : after.front()), 1.0, 1e-6);
    for (const std::vector<double>* x : {&before, &after}) {
      double largestRatio = 0.0;
      for (size_t i = 1; i < x->size(); ++i) {
        largestRatio = std::max(largestRatio, std::max((*x)[i] / (*x)[i - 1], (*x)[i - 1] / (*x)[i]));
      }
      EXPECT_LT(largestRatio, 1.25);
    }
    EXPECT_GT(before.front(), 0.05);  // the free end (x = 0) is not clustered
  }
  EXPECT_GT(clustered.grid.blocks()[0].size[0], plain.grid.blocks()[0].size[0]);
  for (double y : gridSteps(clustered, 0, 1, 0)) EXPECT_NEAR(y, 0.1, 1e-12);  // along the line: as before
  // Both ends on features: two-sided.
  RowMatrixX3d start(2, 3);
  start << 0.0, -1.0, 0.0, 0.0, 2.0, 0.0;
  options.featureSpacings.push_back(FeatureSpacing{start, 0.02, 0.0});
  const std::vector<double> twoSided = gridSteps(refineBlockMesh(mesh, options), 0, 0, 0);
  EXPECT_NEAR(twoSided.front() / 0.02, 1.0, 1e-6);
  EXPECT_NEAR(twoSided.back() / 0.01, 1.0, 1e-6);
  // A line through no block corner changes nothing; one along the x edges (y = 0) leaves them
  // and clusters the y edges leaving it.
  RowMatrixX3d across(2, 3);
  across << 0.5, -1.0, 0.0, 0.5, 2.0, 0.0;
  options.featureSpacings = {FeatureSpacing{across, 0.01, 0.0}};
  EXPECT_EQ(refineBlockMesh(mesh, options).grid.blocks()[0].points, plain.grid.blocks()[0].points);
  RowMatrixX3d along(2, 3);
  along << -1.0, 0.0, 0.0, 4.0, 0.0, 0.0;
  options.featureSpacings = {FeatureSpacing{along, 0.01, 0.0}};
  const RefinedGrid alongX = refineBlockMesh(mesh, options);
  for (double x : gridSteps(alongX, 0, 0, 0)) EXPECT_NEAR(x, 0.1, 1e-12);
  EXPECT_NEAR(gridSteps(alongX, 0, 1, 0).front() / 0.01, 1.0, 1e-6);
  // Bad features are named.
  for (const FeatureSpacing& bad :
       {FeatureSpacing{line, 0.0, 0.0}, FeatureSpacing{line.topRows(1), 0.01, 0.0},
        FeatureSpacing{RowMatrixX3d::Zero(2, 3), 0.01, 0.0}, FeatureSpacing{line, 0.01, -1.0}}) {
    options.featureSpacings = {bad};
    EXPECT_THROW(
        {
          try {
            refineBlockMesh(mesh, options);
          } catch (const InvalidInputError& error) {
            EXPECT_NE(std::string(error.what()).find("feature spacing 0"), std::string::npos) << error.what();
            throw;
          }
        },
        InvalidInputError);
  }
}

TEST(GridRefinement, FeatureClusteringFadesBlockByBlockAlongItsSet) {
  // Three blocks in a row along y share their x lines' set; a feature line crosses x = 0 at y = 0
  // only, so it asks its spacing of block 0's x edge at y = 0 alone. The x edges 1, 2 and 3
  // blocks away (y = 1, 2, 3) start at u (f / u)^(1 / 2^k), u the uniform step: the clustering
  // fades instead of running through the whole set.
  std::vector<volume::Block> blocks{wallBox(0.0, 1.0, 0.0, 1.0), wallBox(0.0, 1.0, 1.0, 2.0),
                                    wallBox(0.0, 1.0, 2.0, 3.0)};
  for (int b = 0; b < 2; ++b) {
    blocks[static_cast<size_t>(b)].faces[3].condition = volume::BoundaryCondition::Connected;
    blocks[static_cast<size_t>(b)].faces[3].neighbour.block = b + 1;
    blocks[static_cast<size_t>(b)].faces[3].neighbour.face = 2;
    blocks[static_cast<size_t>(b) + 1].faces[2].condition = volume::BoundaryCondition::Connected;
    blocks[static_cast<size_t>(b) + 1].faces[2].neighbour.block = b;
    blocks[static_cast<size_t>(b) + 1].faces[2].neighbour.face = 3;
  }
  const volume::BlockMesh mesh(std::move(blocks));
  RefinementOptions options;
  options.edgePoints = 11;  // the count as asked: u = 0.1
  options.normalPoints = 3;
  RowMatrixX3d line(2, 3);
  line << 0.0, -1.0, 0.0, 0.0, 0.5, 0.0;
  options.featureSpacings = {FeatureSpacing{line, 0.01, 1e-6}};
  const RefinedGrid refined = refineBlockMesh(mesh, options);
  const double u = 0.1, f = 0.01;
  for (int k = 0; k <= 3; ++k) {
    const GridBlock& block = refined.grid.blocks()[static_cast<size_t>(k == 3 ? 2 : k)];
    const int j = k == 3 ? block.size[1] - 1 : 0;
    const double first = block.points(block.index(1, j, 0), 0) - block.points(block.index(0, j, 0), 0);
    EXPECT_NEAR(first / (u * std::pow(f / u, std::pow(0.5, k))), 1.0, 1e-6) << "edge " << k;
  }
}

TEST(GridRefinement, BlocksStackedOnAWallBlockAreRefused) {
  const test::BoxBlocks box = test::boxBlocks(0.0, true, 2);
  RefinementOptions options;
  options.firstCellHeight = 0.01;
  try {
    refineBlockMesh(box.mesh, options);
    FAIL();
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("stacked along the wall-normal direction"), std::string::npos)
        << error.what();
  }
}

TEST(GridRefinement, BadOptionsAreNamed) {
  const test::BoxBlocks box = test::boxBlocks(0.0);
  RefinementOptions options;
  options.growth = 0.9;
  EXPECT_THROW(refineBlockMesh(box.mesh, options), InvalidInputError);
  options = {};
  options.edgePoints = 1;
  EXPECT_THROW(refineBlockMesh(box.mesh, options), InvalidInputError);
  options = {};
  options.normalPoints = 0;  // automatic needs a first height
  try {
    refineBlockMesh(box.mesh, options);
    FAIL();
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("normal_points"), std::string::npos);
  }
  for (const double angle : {-1.0, 91.0, std::nan("")}) {
    options = {};
    options.maxTurningDegrees = angle;
    try {
      refineBlockMesh(box.mesh, options);
      FAIL();
    } catch (const InvalidInputError& error) {
      EXPECT_NE(std::string(error.what()).find("max_turning_angle"), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace bvmesh::grid

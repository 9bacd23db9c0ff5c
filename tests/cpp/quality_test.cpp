// Cell quality against hand-computed cells: unit and sheared cubes (scaled Jacobian, OpenFOAM's
// non-orthogonality and skewness, aspect ratio, growth, wall angle), OpenFOAM's cell determinant
// on thin and cubic cells, and the refusal of an inverted cell with its place.
#include <gtest/gtest.h>

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "core/common/errors.h"
#include "core/grid/hex_topology.h"
#include "core/quality/cell_quality.h"

namespace bvmesh::grid {
namespace {

using Eigen::Vector3d;

// A single-block grid from corner points (2 x 2 x 2 points, or a stack of cells along k).
StructuredGrid cellGrid(const std::vector<Vector3d>& points, std::array<int, 3> size) {
  GridBlock block;
  block.size = size;
  block.points.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t p = 0; p < points.size(); ++p)
    block.points.row(static_cast<Eigen::Index>(p)) = points[p].transpose();
  for (auto& face : block.faces) face.condition = volume::BoundaryCondition::Farfield;
  block.faces[4].condition = volume::BoundaryCondition::Wall;
  return StructuredGrid({block});
}

// Points i fastest of the unit cells [0,1]^2 x [0, cells] with x += shear * z.
std::vector<Vector3d> shearedStack(double shear, int cells) {
  std::vector<Vector3d> points;
  for (int k = 0; k <= cells; ++k) {
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 2; ++i) points.emplace_back(i + shear * k, j, k);
    }
  }
  return points;
}

TEST(CellQuality, UnitCubesAndShearedCellsAgainstHandValues) {
  const StructuredGrid cubes = cellGrid(shearedStack(0.0, 2), {2, 2, 3});
  const HexTopology cubeTopology(cubes);
  const quality::CellQuality cube = quality::measureCellQuality(cubeTopology);
  for (int c = 0; c < 2; ++c) {
    EXPECT_NEAR(cube.scaledJacobian[static_cast<size_t>(c)], 1.0, 1e-15);
    EXPECT_NEAR(cube.aspectRatio[static_cast<size_t>(c)], 1.0, 1e-15);
    EXPECT_NEAR(cube.nonOrthogonality[static_cast<size_t>(c)], 0.0, 1e-6);
    EXPECT_NEAR(cube.skewness[static_cast<size_t>(c)], 0.0, 1e-12);
    EXPECT_NEAR(cube.volume[static_cast<size_t>(c)], 1.0, 1e-15);
    EXPECT_NEAR(cube.growthRatio[static_cast<size_t>(c)], 1.0, 1e-15);
  }
  ASSERT_EQ(cube.wallAngle.size(), 1u);
  EXPECT_NEAR(cube.wallAngle[0], 0.0, 1e-6);
  for (double h : cube.firstCellHeight) EXPECT_NEAR(h, 1.0, 1e-15);

  // Shear x += s z: every corner's unit edges span 1 / sqrt(1 + s^2); the centres of the two
  // stacked cells are joined by (s, 0, 1), atan(s) off the face normal; the wall cell's edges lean
  // by the same angle.
  const double s = 0.4;
  const StructuredGrid sheared = cellGrid(shearedStack(s, 2), {2, 2, 3});
  const HexTopology shearedTopology(sheared);
  const quality::CellQuality q = quality::measureCellQuality(shearedTopology);
  const double lean = std::atan(s) * 180.0 / M_PI;
  for (int c = 0; c < 2; ++c) {
    EXPECT_NEAR(q.scaledJacobian[static_cast<size_t>(c)], 1.0 / std::sqrt(1.0 + s * s), 1e-14);
    EXPECT_NEAR(q.nonOrthogonality[static_cast<size_t>(c)], lean, 1e-9);
    EXPECT_NEAR(q.aspectRatio[static_cast<size_t>(c)], std::sqrt(1.0 + s * s), 1e-14);
  }
  EXPECT_NEAR(q.wallAngle[0], lean, 1e-9);
  const auto summary = quality::summarizeQuality(shearedTopology, q);
  EXPECT_EQ(summary[0].name, "scaled_jacobian");
  EXPECT_NEAR(summary[1].max, lean, 1e-9);
}

// The summary's percentiles interpolate linearly between order statistics (numpy's default): on
// a stack of 1000 cells whose values are 0..999 shuffled, the q-percentile is 999 q (9.99, 499.5,
// 989.01: each between two values); per block and over all alike, for every metric.
TEST(CellQuality, SummaryPercentilesAreTheInterpolatedOrderStatistics) {
  const int cells = 1000;
  const StructuredGrid stack = cellGrid(shearedStack(0.0, cells), {2, 2, cells + 1});
  const HexTopology topology(stack);
  quality::CellQuality q = quality::measureCellQuality(topology);
  std::vector<double> shuffled(static_cast<size_t>(cells));
  for (int c = 0; c < cells; ++c)
    shuffled[static_cast<size_t>(c)] = (377 * c) % cells;  // 377 is prime to 1000
  for (std::vector<double>* values : {&q.scaledJacobian, &q.nonOrthogonality, &q.skewness, &q.aspectRatio,
                                      &q.growthRatio, &q.determinant}) {
    *values = shuffled;
  }
  for (const int block : {-1, 0}) {
    for (const quality::MetricSummary& s : quality::summarizeQuality(topology, q, block)) {
      if (s.name == "wall_angle" || s.name == "first_cell_height") continue;
      EXPECT_EQ(s.count, cells) << s.name;
      EXPECT_EQ(s.min, 0.0) << s.name;
      EXPECT_NEAR(s.p01, 9.99, 1e-12) << s.name;
      EXPECT_NEAR(s.median, 499.5, 1e-12) << s.name;
      EXPECT_NEAR(s.p99, 989.01, 1e-9) << s.name;
      EXPECT_EQ(s.max, 999.0) << s.name;
    }
  }
  // Between two order statistics: 0, 10, 20, 30 -> the 1 % point lies 0.03 of the way from 0 to 10.
  const StructuredGrid four = cellGrid(shearedStack(0.0, 4), {2, 2, 5});
  const HexTopology fourTopology(four);
  quality::CellQuality few = quality::measureCellQuality(fourTopology);
  few.scaledJacobian = {30.0, 0.0, 20.0, 10.0};
  const quality::MetricSummary s = quality::summarizeQuality(fourTopology, few)[0];
  EXPECT_NEAR(s.p01, 0.3, 1e-12);
  EXPECT_NEAR(s.median, 15.0, 1e-12);
  EXPECT_NEAR(s.p99, 29.7, 1e-12);
}

// OpenFOAM's cell determinant on 3 x 3 x 3 cells of 1 x 1 x h: the middle cell has six internal
// faces, sum of a a^T = diag(2 h^2, 2 h^2, 2) over mean |a| = (2 + 4 h) / 6 squared; a corner cell
// has one internal face per direction (half of that sum); a one-cell stack sees one direction only.
TEST(CellQuality, CellDeterminantIsOpenFoamsOnThinAndCubicCells) {
  for (const double h : {1.0, 0.1}) {
    std::vector<Vector3d> points;
    for (int k = 0; k < 4; ++k) {
      for (int j = 0; j < 4; ++j) {
        for (int i = 0; i < 4; ++i) points.emplace_back(i, j, h * k);
      }
    }
    const StructuredGrid grid = cellGrid(points, {4, 4, 4});
    const HexTopology topology(grid);
    const quality::CellQuality q = quality::measureCellQuality(topology);
    const double mean = (2.0 + 4.0 * h) / 6.0;
    const double middle = std::pow(h, 4) / std::pow(mean, 6);
    EXPECT_NEAR(q.determinant[1 + 3 * (1 + 3 * 1)], middle, 1e-12 * middle);
    EXPECT_NEAR(q.determinant[0], middle / 8.0, 1e-12 * middle);
  }
  const StructuredGrid stack = cellGrid(shearedStack(0.0, 2), {2, 2, 3});
  const HexTopology stackTopology(stack);
  for (double d : quality::measureCellQuality(stackTopology).determinant) EXPECT_NEAR(d, 0.0, 1e-15);
}

TEST(CellQuality, InvertedCellIsRefusedWithItsPlace) {
  std::vector<Vector3d> points = shearedStack(0.0, 2);
  points[9] = Vector3d(0.5, 0.0, -0.5);  // corner (1, 0, 2) pulled down through the first cell's top
  const StructuredGrid grid = cellGrid(points, {2, 2, 3});
  const HexTopology topology(grid);
  try {
    quality::requirePositiveCells(topology);
    FAIL() << "an inverted cell was accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("block 0 at cell (0, 0, 1)"), std::string::npos) << error.what();
  }
  // A consistently mirrored block is not inverted: its cells are taken with i reversed.
  std::vector<Vector3d> mirrored = shearedStack(0.0, 2);
  for (Vector3d& x : mirrored) x.x() = -x.x();
  const StructuredGrid mirror = cellGrid(mirrored, {2, 2, 3});
  const HexTopology mirrorTopology(mirror);
  EXPECT_TRUE(mirrorTopology.mirrored(0));
  EXPECT_NO_THROW(quality::requirePositiveCells(mirrorTopology));
  EXPECT_NEAR(quality::measureCellQuality(mirrorTopology).volume[0], 1.0, 1e-15);
}

}  // namespace
}  // namespace bvmesh::grid

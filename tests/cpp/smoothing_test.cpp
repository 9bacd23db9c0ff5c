#include "core/fit/smoothing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/common/errors.h"

namespace bvmesh::fit {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A closed polygon: each point's neighbours are the previous and the next one.
std::vector<std::vector<int>> ringNeighbours(int count) {
  std::vector<std::vector<int>> neighbours(count);
  for (int i = 0; i < count; ++i) neighbours[i] = {(i + count - 1) % count, (i + 1) % count};
  return neighbours;
}

TEST(TaubinSmoothing, RemovesNoiseWithoutShrinkingACircle) {
  const int count = 200;
  std::mt19937 random(3);
  std::normal_distribution<double> noise(0.0, 0.01);
  RowMatrixX3d noisy(count, 3);
  for (int i = 0; i < count; ++i) {
    const double angle = 2.0 * kPi * i / count;
    noisy.row(i) << std::cos(angle) + noise(random), std::sin(angle) + noise(random), 0.0;
  }
  const RowMatrixX3d smooth = taubinSmooth(noisy, ringNeighbours(count), {});
  auto radiusSpread = [](const RowMatrixX3d& points, double& mean) {
    const Eigen::VectorXd radii = points.rowwise().norm();
    mean = radii.mean();
    return (radii.array() - mean).abs().maxCoeff();
  };
  double noisyMean = 0.0;
  double smoothMean = 0.0;
  const double noisySpread = radiusSpread(noisy, noisyMean);
  const double smoothSpread = radiusSpread(smooth, smoothMean);
  EXPECT_LT(smoothSpread, 0.5 * noisySpread);
  EXPECT_NEAR(smoothMean, 1.0, 2e-3);  // plain Laplacian smoothing (mu = 0) shrinks it visibly

  TaubinOptions laplacian;
  laplacian.mu = 0.0;
  laplacian.iterations = 100;
  double shrunkMean = 0.0;
  radiusSpread(taubinSmooth(noisy, ringNeighbours(count), laplacian), shrunkMean);
  EXPECT_LT(shrunkMean, 0.98);
}

TEST(TaubinSmoothing, PointsWithoutNeighboursStayAndLinesStayStraight) {
  // A crease polyline on the x axis whose inner points only see each other: they stay on the line,
  // and the ends (corners, no neighbours) do not move.
  RowMatrixX3d points(5, 3);
  points << 0, 0, 0, 0.7, 0, 0, 2.5, 0, 0, 2.9, 0, 0, 4, 0, 0;
  const std::vector<std::vector<int>> neighbours = {{}, {0, 2}, {1, 3}, {2, 4}, {}};
  const RowMatrixX3d smooth = taubinSmooth(points, neighbours, {});
  EXPECT_EQ(smooth.row(0), points.row(0));
  EXPECT_EQ(smooth.row(4), points.row(4));
  EXPECT_LT(smooth.col(1).cwiseAbs().maxCoeff() + smooth.col(2).cwiseAbs().maxCoeff(), 1e-15);
  // ... and are spaced more evenly than before.
  auto spacingSpread = [](const RowMatrixX3d& p) {
    Eigen::VectorXd gaps = p.col(0).tail(4) - p.col(0).head(4);
    return gaps.maxCoeff() - gaps.minCoeff();
  };
  EXPECT_LT(spacingSpread(smooth), 0.5 * spacingSpread(points));
}

TEST(TaubinSmoothing, BadInputIsRejected) {
  const RowMatrixX3d points = RowMatrixX3d::Zero(3, 3);
  EXPECT_THROW(taubinSmooth(points, ringNeighbours(2)), InvalidInputError);
  EXPECT_THROW(taubinSmooth(points, {{1}, {5}, {0}}), InvalidInputError);
  TaubinOptions bad;
  bad.lambda = std::nan("");
  EXPECT_THROW(taubinSmooth(points, ringNeighbours(3), bad), InvalidInputError);
}

// The ring's alternating mode has umbrella eigenvalue -2: one iteration scales it by
// (1 - 2 lambda)(1 - 2 mu), the figure the check bounds.
double alternatingModeGain(double lambda, double mu) {
  const int count = 8;
  RowMatrixX3d points = RowMatrixX3d::Zero(count, 3);
  for (int i = 0; i < count; ++i) points(i, 2) = i % 2 == 0 ? 1.0 : -1.0;
  TaubinOptions options;
  options.iterations = 1;
  options.lambda = lambda;
  options.mu = mu;
  return taubinSmooth(points, ringNeighbours(count), options)(0, 2);
}

TEST(TaubinSmoothing, PairsThatAmplifyAWavelengthAreRefusedBeforeMovingAPoint) {
  EXPECT_NEAR(alternatingModeGain(0.6307, -0.6732), (1 - 2 * 0.6307) * (1 + 2 * 0.6732), 1e-14);
  EXPECT_NEAR(alternatingModeGain(0.5, 0.0), 0.0, 1e-14);  // a plain Laplacian step
  EXPECT_NEAR(alternatingModeGain(0.5, -0.5), 0.0, 1e-14);
  const RowMatrixX3d points = RowMatrixX3d::Zero(3, 3);
  TaubinOptions bad;
  for (const auto& [lambda, mu] : {std::pair{2147483648.0, -1.0},  // the fitter's vertices went to 1e27
                                   std::pair{0.9, -0.95},          // the finest mode 2.3 times per iteration
                                   std::pair{0.3, -0.6},           // a middle wavelength 1.125 times
                                   std::pair{-0.5, -0.5}}) {      // growing every wavelength
    bad.lambda = lambda;
    bad.mu = mu;
    EXPECT_THROW(taubinSmooth(points, ringNeighbours(3), bad), InvalidInputError) << lambda << " " << mu;
  }
}

}  // namespace
}  // namespace bvmesh::fit

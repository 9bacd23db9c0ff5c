#include "core/common/closest_point.h"

#include <gtest/gtest.h>

#include <random>

namespace bvmesh {
namespace {

// Brute force: the nearest of many points of the triangle (a dense barycentric grid).
double bruteForceDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                          const Eigen::Vector3d& c) {
  const int steps = 400;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= steps; ++i) {
    for (int j = 0; i + j <= steps; ++j) {
      const double s = static_cast<double>(i) / steps;
      const double t = static_cast<double>(j) / steps;
      best = std::min(best, (a + s * (b - a) + t * (c - a) - p).norm());
    }
  }
  return best;
}

TEST(ClosestPoint, TriangleMatchesBruteForceInEveryRegion) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> coordinate(-2.0, 2.0);
  auto point = [&] { return Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random)); };
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d a = point(), b = point(), c = point(), p = point();
    const Eigen::Vector3d q = closestPointOnTriangle(p, a, b, c);
    const double exact = (q - p).norm();
    // The grid's spacing bounds how much nearer the exact answer may be.
    const double spacing = std::max({(b - a).norm(), (c - a).norm(), (c - b).norm()}) / 400.0;
    EXPECT_LE(exact, bruteForceDistance(p, a, b, c) + 1e-12);
    EXPECT_GE(exact, bruteForceDistance(p, a, b, c) - spacing);
  }
}

TEST(ClosestPoint, TriangleWeightsInterpolateTheFootFromTheCorners) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> coordinate(-2.0, 2.0);
  auto point = [&] { return Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random)); };
  for (int trial = 0; trial < 200; ++trial) {
    // Degenerate triangles too, as tessellations have them at a surface's pole: every fifth with
    // its third corner on the line through the first two, every seventh with two corners at one
    // point (a Voronoi-region walk divides by zero there unless it checks).
    const Eigen::Vector3d a = point(), p = point();
    const Eigen::Vector3d b = trial % 7 == 0 ? a : point();
    const Eigen::Vector3d c = trial % 5 == 0 ? Eigen::Vector3d(a + 0.7 * (b - a)) : point();
    const TriangleFoot foot = closestFootOnTriangle(p, a, b, c);
    EXPECT_NEAR(foot.weights.sum(), 1.0, 1e-14);
    EXPECT_GE(foot.weights.minCoeff(), 0.0);
    EXPECT_LT((foot.weights[0] * a + foot.weights[1] * b + foot.weights[2] * c - foot.point).norm(), 1e-13);
    EXPECT_LE((foot.point - p).norm(), bruteForceDistance(p, a, b, c) + 1e-12);
  }
}

TEST(ClosestPoint, DegenerateTrianglesAndSegments) {
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(2, 0, 0);
  EXPECT_TRUE(closestPointOnTriangle(Eigen::Vector3d(1.5, 1, 0), a, b, c).isApprox(Eigen::Vector3d(1.5, 0, 0)));
  EXPECT_TRUE(closestPointOnTriangle(Eigen::Vector3d(5, 1, 1), a, a, a).isApprox(a));
  EXPECT_TRUE(closestPointOnSegment(Eigen::Vector3d(-1, 2, 0), a, b).isApprox(a));
  EXPECT_TRUE(closestPointOnSegment(Eigen::Vector3d(0.25, 2, 0), a, b).isApprox(Eigen::Vector3d(0.25, 0, 0)));
  // A point above the interior lands on the plane.
  const Eigen::Vector3d q = closestPointOnTriangle(Eigen::Vector3d(0.2, 0.2, 3), a, b, Eigen::Vector3d(0, 1, 0));
  EXPECT_NEAR((q - Eigen::Vector3d(0.2, 0.2, 0)).norm(), 0.0, 1e-15);
}

}  // namespace
}  // namespace bvmesh

// The hyperbolic far-field step (Chan & Steger on an unstructured quad front): radial on a sphere,
// mirrored ghosts on the symmetry plane equal to the whole model, clear errors for fronts it
// cannot march.
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <map>
#include <string>
#include <tuple>

#include "core/common/errors.h"
#include "core/volume/hyperbolic_step.h"

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

struct Front {
  RowMatrixX3d points;
  std::vector<std::array<int, 4>> quads;
};

// The cube's faces, n x n quads each, pushed onto the unit sphere: quads counter-clockwise seen
// from outside. Points are merged by their lattice position on the cube.
Front quadSphere(int n) {
  std::map<std::tuple<int, int, int>, int> index;
  std::vector<Vector3d> points;
  Front front;
  auto point = [&](int axis, int sign, int a, int b) {
    std::array<int, 3> lattice{};
    lattice[static_cast<size_t>(axis)] = sign * n;
    lattice[static_cast<size_t>((axis + 1) % 3)] = 2 * a - n;
    lattice[static_cast<size_t>((axis + 2) % 3)] = 2 * b - n;
    const auto key = std::make_tuple(lattice[0], lattice[1], lattice[2]);
    const auto found = index.find(key);
    if (found != index.end()) return found->second;
    points.push_back(Vector3d(lattice[0], lattice[1], lattice[2]).normalized());
    return index[key] = static_cast<int>(points.size()) - 1;
  };
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {1, -1}) {
      for (int a = 0; a < n; ++a) {
        for (int b = 0; b < n; ++b) {
          std::array<int, 4> quad{point(axis, sign, a, b), point(axis, sign, a + 1, b),
                                  point(axis, sign, a + 1, b + 1), point(axis, sign, a, b + 1)};
          if (sign < 0) std::swap(quad[1], quad[3]);
          front.quads.push_back(quad);
        }
      }
    }
  }
  front.points.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t p = 0; p < points.size(); ++p)
    front.points.row(static_cast<Eigen::Index>(p)) = points[p].transpose();
  return front;
}

TEST(HyperbolicStep, StepsOnASphereAreRadialWhereItsSymmetryFixesThemAndAsLongAsAskedOnAverage) {
  const int n = 8;
  const Front sphere = quadSphere(n);
  HyperbolicStepper stepper(sphere.points.rows(), sphere.quads, {}, Vector3d::Zero(), Vector3d::UnitY(), {});
  const double thickness = 0.1;
  const RowMatrixX3d next = stepper.advance(sphere.points, sphere.points, thickness, 0.1);
  double shortest = 1.0, longest = 0.0, mean = 0.0;
  int symmetric = 0;
  for (Eigen::Index p = 0; p < next.rows(); ++p) {
    const Vector3d move = (next.row(p) - sphere.points.row(p)).transpose();
    const Vector3d radial = sphere.points.row(p).transpose();
    shortest = std::min(shortest, move.norm());
    longest = std::max(longest, move.norm());
    mean += move.norm() / static_cast<double>(next.rows());
    // The cube's corners, edge midpoints and face centres lie on two or three of its mirror
    // planes: their step can only be radial.
    const Vector3d lattice = radial / radial.cwiseAbs().maxCoeff();
    if ((lattice.cwiseAbs().array() < 1e-12 || lattice.cwiseAbs().array() > 1.0 - 1e-12).all()) {
      ++symmetric;
      EXPECT_LT(move.normalized().cross(radial).norm(), 1e-6) << "point " << p;
    }
  }
  EXPECT_EQ(symmetric, 8 + 12 + 6);
  // Elsewhere the explicit smoothing evens out the cells, which are smallest next to the cube's
  // corners: measured up to 8.4 degrees off radial there in this step, steps 0.096 to 0.13 (the
  // corners', whose smoothed volumes are the largest for their area).
  EXPECT_NEAR(mean, thickness, 0.02 * thickness);
  EXPECT_GT(shortest, 0.8 * thickness);
  EXPECT_LT(longest, 1.4 * thickness);
}

TEST(HyperbolicStep, AStepperWarmedByAnEarlierStepMarchesAsAFreshOne) {
  // Each solve starts from the previous step's solution, scaled to its step length; the answer is
  // the system's, not the guess's.
  const Front sphere = quadSphere(6);
  HyperbolicOptions exact;
  exact.solverTolerance = 1e-10;
  HyperbolicStepper fresh(sphere.points.rows(), sphere.quads, {}, Vector3d::Zero(), Vector3d::UnitY(), exact);
  HyperbolicStepper warmed(sphere.points.rows(), sphere.quads, {}, Vector3d::Zero(), Vector3d::UnitY(),
                           exact);
  const RowMatrixX3d earlier = warmed.advance(sphere.points, sphere.points, 0.03, 0.6);
  ASSERT_GT((earlier - sphere.points).rowwise().norm().minCoeff(), 0.02);
  const double thickness = 0.1;
  const RowMatrixX3d expected = fresh.advance(sphere.points, sphere.points, thickness, 0.1);
  const RowMatrixX3d next = warmed.advance(sphere.points, sphere.points, thickness, 0.1);
  EXPECT_LT((next - expected).rowwise().norm().maxCoeff(), 1e-8 * thickness);
}

TEST(HyperbolicStep, MirroredGhostsOnTheSymmetryPlaneGiveTheWholeModelsStep) {
  const Front sphere = quadSphere(8);
  // The half y >= 0, its points on y = 0 kept on the plane.
  std::vector<int> halfIndex(static_cast<size_t>(sphere.points.rows()), -1);
  Front half;
  std::vector<int> wholeIndex;
  for (Eigen::Index p = 0; p < sphere.points.rows(); ++p) {
    if (sphere.points(p, 1) < -1e-12) continue;
    halfIndex[static_cast<size_t>(p)] = static_cast<int>(wholeIndex.size());
    wholeIndex.push_back(static_cast<int>(p));
  }
  half.points.resize(static_cast<Eigen::Index>(wholeIndex.size()), 3);
  std::vector<char> onPlane(wholeIndex.size(), 0);
  for (size_t i = 0; i < wholeIndex.size(); ++i) {
    half.points.row(static_cast<Eigen::Index>(i)) = sphere.points.row(wholeIndex[i]);
    onPlane[i] = std::abs(sphere.points(wholeIndex[i], 1)) < 1e-12 ? 1 : 0;
  }
  for (const auto& quad : sphere.quads) {
    std::array<int, 4> mapped{};
    bool inside = true;
    for (int k = 0; k < 4; ++k) {
      mapped[static_cast<size_t>(k)] = halfIndex[static_cast<size_t>(quad[static_cast<size_t>(k)])];
      inside = inside && mapped[static_cast<size_t>(k)] >= 0;
    }
    if (inside) half.quads.push_back(mapped);
  }
  ASSERT_EQ(half.quads.size(), sphere.quads.size() / 2);
  HyperbolicOptions exact;
  exact.solverTolerance = 1e-10;
  HyperbolicStepper whole(sphere.points.rows(), sphere.quads, {}, Vector3d::Zero(), Vector3d::UnitY(), exact);
  HyperbolicStepper halved(half.points.rows(), half.quads, onPlane, Vector3d::Zero(), Vector3d::UnitY(),
                           exact);
  // Thin enough for one pseudo-step in both (the half's short edges are not the whole's).
  const double thickness = 0.05;
  const RowMatrixX3d wholeNext = whole.advance(sphere.points, sphere.points, thickness, 0.3);
  const RowMatrixX3d halfNext = halved.advance(half.points, half.points, thickness, 0.3);
  for (size_t i = 0; i < wholeIndex.size(); ++i) {
    const auto row = static_cast<Eigen::Index>(i);
    // The steps' linear systems are solved to 1e-10 of their right-hand side.
    EXPECT_LT((halfNext.row(row) - wholeNext.row(wholeIndex[i])).norm(), 1e-8 * thickness) << "point " << i;
    if (onPlane[i] != 0) {
      EXPECT_EQ(halfNext(row, 1), 0.0) << "point " << i;
    }
  }
}

TEST(HyperbolicStep, FrontsItCannotMarchAreNamed) {
  const Front sphere = quadSphere(2);
  // A hole: one quad missing leaves its corners on an open boundary off the symmetry plane.
  std::vector<std::array<int, 4>> open(sphere.quads.begin() + 1, sphere.quads.end());
  try {
    HyperbolicStepper stepper(sphere.points.rows(), open, {}, Vector3d::Zero(), Vector3d::UnitY(), {});
    FAIL() << "an open front was accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("open boundary off the symmetry plane"), std::string::npos)
        << error.what();
  }
  // Two spheres touching at one point: two fans around it.
  std::vector<std::array<int, 4>> pinched = sphere.quads;
  const auto offset = static_cast<int>(sphere.points.rows());
  for (auto quad : sphere.quads) {
    for (int& p : quad) p = p == 0 ? 0 : p + offset;
    pinched.push_back(quad);
  }
  try {
    HyperbolicStepper stepper(2 * offset, pinched, {}, Vector3d::Zero(), Vector3d::UnitY(), {});
    FAIL() << "a pinched front was accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("front point 0 has cells that do not form one fan"),
              std::string::npos)
        << error.what();
  }
  // A front collapsed to a point has no tangent plane to march from.
  HyperbolicStepper stepper(sphere.points.rows(), sphere.quads, {}, Vector3d::Zero(), Vector3d::UnitY(), {});
  const RowMatrixX3d collapsed = RowMatrixX3d::Zero(sphere.points.rows(), 3);
  EXPECT_THROW(stepper.advance(collapsed, collapsed, 0.1, 0.5), SolverError);
}

}  // namespace
}  // namespace bvmesh::volume

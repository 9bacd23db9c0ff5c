// The hyperbolic far-field step (Chan & Steger on an unstructured quad front): radial on a sphere,
// mirrored ghosts on the symmetry plane, and on it and an outflow plane, equal to the whole model,
// clear errors for fronts it cannot march.
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
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
  HyperbolicStepper stepper(sphere.points.rows(), sphere.quads, {}, BoundaryPlanes{}, {});
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
  HyperbolicStepper fresh(sphere.points.rows(), sphere.quads, {}, BoundaryPlanes{}, exact);
  HyperbolicStepper warmed(sphere.points.rows(), sphere.quads, {}, BoundaryPlanes{}, exact);
  const RowMatrixX3d earlier = warmed.advance(sphere.points, sphere.points, 0.03, 0.6);
  ASSERT_GT((earlier - sphere.points).rowwise().norm().minCoeff(), 0.02);
  const double thickness = 0.1;
  const RowMatrixX3d expected = fresh.advance(sphere.points, sphere.points, thickness, 0.1);
  const RowMatrixX3d next = warmed.advance(sphere.points, sphere.points, thickness, 0.1);
  EXPECT_LT((next - expected).rowwise().norm().maxCoeff(), 1e-8 * thickness);
}

// The part of `whole` on the positive side of the coordinate planes x[axis] = 0 given with their
// plane bits, its points on them marked with those bits, and each of its points' index in `whole`.
struct Part {
  Front front;
  std::vector<unsigned char> onPlanes;
  std::vector<int> wholeIndex;
};

Part partOf(const Front& whole, const std::vector<std::pair<int, unsigned char>>& planes) {
  Part part;
  std::vector<int> partIndex(static_cast<size_t>(whole.points.rows()), -1);
  for (Eigen::Index p = 0; p < whole.points.rows(); ++p) {
    bool inside = true;
    unsigned char on = 0;
    for (const auto& [axis, bit] : planes) {
      inside = inside && whole.points(p, axis) > -1e-12;
      if (std::abs(whole.points(p, axis)) < 1e-12) on = static_cast<unsigned char>(on | bit);
    }
    if (!inside) continue;
    partIndex[static_cast<size_t>(p)] = static_cast<int>(part.wholeIndex.size());
    part.wholeIndex.push_back(static_cast<int>(p));
    part.onPlanes.push_back(on);
  }
  part.front.points.resize(static_cast<Eigen::Index>(part.wholeIndex.size()), 3);
  for (size_t i = 0; i < part.wholeIndex.size(); ++i) {
    part.front.points.row(static_cast<Eigen::Index>(i)) = whole.points.row(part.wholeIndex[i]);
  }
  for (const auto& quad : whole.quads) {
    std::array<int, 4> mapped{};
    bool inside = true;
    for (int k = 0; k < 4; ++k) {
      mapped[static_cast<size_t>(k)] = partIndex[static_cast<size_t>(quad[static_cast<size_t>(k)])];
      inside = inside && mapped[static_cast<size_t>(k)] >= 0;
    }
    if (inside) part.front.quads.push_back(mapped);
  }
  return part;
}

// One step of the part with its mirrored ghosts against the whole model's step: equal, and the
// part's points on a plane exactly on it.
void expectTheWholeModelsStep(const Front& whole, const Part& part, const BoundaryPlanes& planes) {
  HyperbolicOptions exact;
  exact.solverTolerance = 1e-10;
  HyperbolicStepper wholeStepper(whole.points.rows(), whole.quads, {}, BoundaryPlanes{}, exact);
  HyperbolicStepper partStepper(part.front.points.rows(), part.front.quads, part.onPlanes, planes, exact);
  // Thin enough for one pseudo-step in both (the part's short edges are not the whole's).
  const double thickness = 0.05;
  const RowMatrixX3d wholeNext = wholeStepper.advance(whole.points, whole.points, thickness, 0.3);
  const RowMatrixX3d partNext = partStepper.advance(part.front.points, part.front.points, thickness, 0.3);
  for (size_t i = 0; i < part.wholeIndex.size(); ++i) {
    const auto row = static_cast<Eigen::Index>(i);
    // The steps' linear systems are solved to 1e-10 of their right-hand side.
    EXPECT_LT((partNext.row(row) - wholeNext.row(part.wholeIndex[i])).norm(), 1e-8 * thickness)
        << "point " << i;
    for (size_t k = 0; k < 2; ++k) {
      if ((part.onPlanes[i] & (1u << k)) != 0) {
        EXPECT_EQ(partNext.row(row).dot(planes.normal[k].transpose()), 0.0)
            << "point " << i << " plane " << k;
      }
    }
  }
}

TEST(HyperbolicStep, MirroredGhostsOnTheSymmetryPlaneGiveTheWholeModelsStep) {
  const Front sphere = quadSphere(8);
  // The half y >= 0, its points on y = 0 kept on the plane.
  const Part half = partOf(sphere, {{1, kSymmetryPlaneBit}});
  ASSERT_EQ(half.front.quads.size(), sphere.quads.size() / 2);
  expectTheWholeModelsStep(sphere, half, BoundaryPlanes{});
}

TEST(HyperbolicStep, GhostsMirroredInTwoPlanesGiveTheWholeModelsStep) {
  // The quarter x >= 0, y >= 0: the symmetry plane y = 0 and an outflow plane x = 0, the poles
  // (0, 0, +-1) on both (a quarter of their ring is the front's, three quarters are images).
  const Front sphere = quadSphere(8);
  const Part quarter = partOf(sphere, {{1, kSymmetryPlaneBit}, {0, kOutflowPlaneBit}});
  ASSERT_EQ(quarter.front.quads.size(), sphere.quads.size() / 4);
  ASSERT_EQ(
      std::count(quarter.onPlanes.begin(), quarter.onPlanes.end(), kSymmetryPlaneBit | kOutflowPlaneBit), 2);
  BoundaryPlanes planes;
  planes.normal = {Vector3d::UnitY(), Vector3d::UnitX()};
  expectTheWholeModelsStep(sphere, quarter, planes);
}

TEST(HyperbolicStep, FrontsItCannotMarchAreNamed) {
  const Front sphere = quadSphere(2);
  // A hole: one quad missing leaves its corners on an open boundary off the symmetry plane.
  std::vector<std::array<int, 4>> open(sphere.quads.begin() + 1, sphere.quads.end());
  try {
    HyperbolicStepper stepper(sphere.points.rows(), open, {}, BoundaryPlanes{}, {});
    FAIL() << "an open front was accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("open boundary off the symmetry and outflow planes"),
              std::string::npos)
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
    HyperbolicStepper stepper(2 * offset, pinched, {}, BoundaryPlanes{}, {});
    FAIL() << "a pinched front was accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("front point 0 has cells that do not form one fan"),
              std::string::npos)
        << error.what();
  }
  // A front collapsed to a point has no tangent plane to march from.
  HyperbolicStepper stepper(sphere.points.rows(), sphere.quads, {}, BoundaryPlanes{}, {});
  const RowMatrixX3d collapsed = RowMatrixX3d::Zero(sphere.points.rows(), 3);
  EXPECT_THROW(stepper.advance(collapsed, collapsed, 0.1, 0.5), SolverError);
}

}  // namespace
}  // namespace bvmesh::volume

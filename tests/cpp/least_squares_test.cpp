#include "core/fit/least_squares.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <limits>
#include <random>

#include "core/common/errors.h"

namespace bvmesh::fit {
namespace {

// A random sparse operator with rows like limit stencils: a few positive weights summing to 1,
// and every control point used by several samples.
RowSparseMatrix randomOperator(int samples, int points, std::mt19937& random) {
  std::uniform_int_distribution<int> pick(0, points - 1);
  std::uniform_real_distribution<double> weight(0.1, 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  for (int row = 0; row < samples; ++row) {
    std::vector<std::pair<int, double>> stencil = {{row % points, weight(random)}};
    for (int k = 0; k < 5; ++k) stencil.emplace_back(pick(random), weight(random));
    double sum = 0.0;
    for (const auto& entry : stencil) sum += entry.second;
    for (const auto& entry : stencil) entries.emplace_back(row, entry.first, entry.second / sum);
  }
  RowSparseMatrix matrix(samples, points);
  matrix.setFromTriplets(entries.begin(), entries.end());
  return matrix;
}

RowMatrixX3d randomPoints(int count, std::mt19937& random) {
  std::normal_distribution<double> normal;
  RowMatrixX3d points(count, 3);
  for (int i = 0; i < count; ++i) points.row(i) << normal(random), normal(random), normal(random);
  return points;
}

// Gradient of sum_i w_i |A_i p - s_i|^2 with respect to every control point (#P x 3).
RowMatrixX3d objectiveGradient(const RowSparseMatrix& a, const Eigen::VectorXd& w, const RowMatrixX3d& p,
                              const RowMatrixX3d& s) {
  const RowMatrixX3d residual = a * p - s;
  return 2.0 * (a.transpose() * (w.asDiagonal() * residual));
}

class LeastSquares : public ::testing::TestWithParam<LeastSquaresMethod> {
protected:
  std::mt19937 random{42};
  // Exactness checks ask CGLS for a tight tolerance.
  LeastSquaresOptions options() const {
    LeastSquaresOptions result;
    result.method = GetParam();
    result.cglsTolerance = 1e-13;
    return result;
  }
};

TEST_P(LeastSquares, RecoversPointsWhoseSamplesAreConsistent) {
  const RowSparseMatrix a = randomOperator(400, 100, random);
  const RowMatrixX3d truth = randomPoints(100, random);
  const ControlPointSolver solver(a, Eigen::VectorXd(), {}, options());
  const RowMatrixX3d result = solver.solve(a * truth, RowMatrixX3d::Zero(100, 3));
  EXPECT_LT((result - truth).cwiseAbs().maxCoeff(), 1e-9);
}

TEST_P(LeastSquares, WeightedSolutionMatchesDenseQr) {
  const RowSparseMatrix a = randomOperator(300, 80, random);
  const RowMatrixX3d targets = randomPoints(300, random);
  Eigen::VectorXd weights = Eigen::VectorXd::Random(300).cwiseAbs() + Eigen::VectorXd::Constant(300, 0.1);
  const ControlPointSolver solver(a, weights, {}, options());
  const RowMatrixX3d result = solver.solve(targets, randomPoints(80, random));

  const Eigen::MatrixXd sqrtW = weights.cwiseSqrt().asDiagonal();
  const Eigen::MatrixXd dense = sqrtW * Eigen::MatrixXd(a);
  const Eigen::MatrixXd expected = dense.colPivHouseholderQr().solve(sqrtW * Eigen::MatrixXd(targets));
  EXPECT_LT((result - expected).cwiseAbs().maxCoeff(), 1e-8);
}

TEST_P(LeastSquares, FixedPointsStayAndTheRestIsOptimal) {
  const RowSparseMatrix a = randomOperator(400, 100, random);
  const RowMatrixX3d targets = randomPoints(400, random);
  const RowMatrixX3d current = randomPoints(100, random);
  ApproximationConstraints constraints;
  constraints.fixedVertices = {0, 17, 99};
  const ControlPointSolver solver(a, Eigen::VectorXd(), constraints, options());
  const RowMatrixX3d result = solver.solve(targets, current);
  for (int id : constraints.fixedVertices) EXPECT_EQ(result.row(id), current.row(id));
  // Optimality of the free points: the objective's gradient vanishes there.
  RowMatrixX3d gradient = objectiveGradient(a, Eigen::VectorXd::Ones(400), result, targets);
  for (int id : constraints.fixedVertices) gradient.row(id).setZero();
  EXPECT_LT(gradient.cwiseAbs().maxCoeff(), 1e-8);
}

TEST_P(LeastSquares, PlanePointsStayOnATiltedPlaneAndAreOptimalWithinIt) {
  const RowSparseMatrix a = randomOperator(400, 100, random);
  const RowMatrixX3d targets = randomPoints(400, random);
  PlaneConstraint plane;
  plane.point = Eigen::Vector3d(0.3, -0.2, 1.0);
  plane.normal = Eigen::Vector3d(1.0, 2.0, -0.5);
  plane.vertices = {3, 4, 5, 50, 60};
  ApproximationConstraints constraints;
  constraints.plane = plane;
  constraints.fixedVertices = {7};
  const RowMatrixX3d current = randomPoints(100, random);
  const ControlPointSolver solver(a, Eigen::VectorXd(), constraints, options());
  const RowMatrixX3d result = solver.solve(targets, current);

  const Eigen::Vector3d n = plane.normal.normalized();
  for (int id : plane.vertices) {
    EXPECT_NEAR((result.row(id).transpose() - plane.point).dot(n), 0.0, 1e-12) << "vertex " << id;
  }
  EXPECT_LT((result.row(7) - current.row(7)).norm(), 1e-14);
  // KKT: free points have zero gradient, plane points have a gradient along the normal only.
  RowMatrixX3d gradient = objectiveGradient(a, Eigen::VectorXd::Ones(400), result, targets);
  gradient.row(7).setZero();
  for (int id : plane.vertices) gradient.row(id) -= gradient.row(id).dot(n) * n.transpose();
  EXPECT_LT(gradient.cwiseAbs().maxCoeff(), 1e-8);
}

INSTANTIATE_TEST_SUITE_P(BothSolvers, LeastSquares,
                         ::testing::Values(LeastSquaresMethod::Cholesky, LeastSquaresMethod::Cgls));

// CGLS solves for the correction: with the default tolerance, points far from the origin (a wing
// in millimetres) close to their solution get an error proportional to the small correction,
// not to their coordinates.
TEST(LeastSquaresCgls, ErrorScalesWithTheCorrectionNotTheCoordinates) {
  std::mt19937 random(5);
  const RowSparseMatrix a = randomOperator(800, 200, random);
  RowMatrixX3d truth = randomPoints(200, random);
  truth.array() += 1000.0;
  const RowMatrixX3d start = truth + 1e-3 * randomPoints(200, random);
  LeastSquaresOptions options;
  options.method = LeastSquaresMethod::Cgls;
  options.cglsTolerance = 1e-8;
  const ControlPointSolver solver(a, Eigen::VectorXd(), {}, options);
  const RowMatrixX3d result = solver.solve(a * truth, start);
  EXPECT_LT((result - truth).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(LeastSquaresErrors, NameTheProblem) {
  std::mt19937 random(7);
  RowSparseMatrix a = randomOperator(40, 10, random);
  EXPECT_THROW(ControlPointSolver(a, Eigen::VectorXd::Ones(39), {}), InvalidInputError);
  ApproximationConstraints outOfRange;
  outOfRange.fixedVertices = {10};
  EXPECT_THROW(ControlPointSolver(a, Eigen::VectorXd(), outOfRange), InvalidInputError);

  // A control point no sample depends on cannot be placed.
  RowSparseMatrix wider(40, 11);
  std::vector<Eigen::Triplet<double>> entries;
  for (int row = 0; row < a.outerSize(); ++row) {
    for (RowSparseMatrix::InnerIterator entry(a, row); entry; ++entry) entries.emplace_back(row, entry.col(), entry.value());
  }
  wider.setFromTriplets(entries.begin(), entries.end());
  try {
    ControlPointSolver solver(wider, Eigen::VectorXd(), {});
    FAIL() << "unsampled control point accepted";
  } catch (const SolverError& error) {
    EXPECT_NE(std::string(error.what()).find("control point 10"), std::string::npos) << error.what();
  }

  const ControlPointSolver solver(a, Eigen::VectorXd(), {});
  RowMatrixX3d targets = RowMatrixX3d::Zero(40, 3);
  targets(5, 1) = std::nan("");
  EXPECT_THROW(solver.solve(targets, RowMatrixX3d::Zero(10, 3)), InvalidInputError);
  RowMatrixX3d current = RowMatrixX3d::Zero(10, 3);
  current(3, 0) = std::numeric_limits<double>::infinity();
  try {
    solver.solve(RowMatrixX3d::Zero(40, 3), current);
    ADD_FAILURE() << "an infinite control point accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("vertex 3 has a non-finite coordinate (inf, 0, 0)"), std::string::npos)
        << error.what();
  }
  EXPECT_THROW(solver.solve(RowMatrixX3d::Zero(39, 3), RowMatrixX3d::Zero(10, 3)), InvalidInputError);
}

}  // namespace
}  // namespace bvmesh::fit

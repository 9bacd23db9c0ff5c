#include "core/fit/least_squares.h"

#include <Eigen/Geometry>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/CholmodSupport>

#include <array>
#include <cmath>
#include <string>

#include "core/common/errors.h"
#include "core/common/parallel.h"
#include "core/common/input_checks.h"

namespace bvmesh::fit {
namespace {

using SparseColMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor>;

// An orthonormal frame whose third axis is `normal`.
Eigen::Matrix3d frameWithNormal(const Eigen::Vector3d& normal) {
  const Eigen::Vector3d n = normal.normalized();
  const Eigen::Vector3d helper = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d t1 = helper.cross(n).normalized();
  const Eigen::Vector3d t2 = n.cross(t1);
  Eigen::Matrix3d rows;
  rows.row(0) = t1;
  rows.row(1) = t2;
  rows.row(2) = n;
  return rows;
}

void checkVertexIds(const std::vector<int>& ids, int count, const char* what) {
  for (int id : ids) {
    if (id < 0 || id >= count) {
      throw InvalidInputError(std::string(what) + " vertex " + std::to_string(id) + " is out of range (" +
                              std::to_string(count) + " control points)");
    }
  }
}

}  // namespace

// The least-squares problem of one coordinate, with its own split of the control points into
// free (unknown) and held (known) ones.
struct FreeColumnSystem {
  std::vector<int> freeOfPoint;   // per control point: its column among the free ones, or -1
  std::vector<int> heldPoints;    // control points whose coordinate is known
  SparseColMatrix weightedFree;   // sqrt(w) A restricted to the free columns
  SparseColMatrix weightedHeld;   // sqrt(w) A restricted to the held columns
  Eigen::CholmodSupernodalLLT<SparseColMatrix> cholesky;
  LeastSquaresOptions cglsOptions;

  FreeColumnSystem(const RowSparseMatrix& operatorA, const Eigen::VectorXd& sqrtWeights,
                   const std::vector<bool>& held, const LeastSquaresOptions& options) {
    const int pointCount = static_cast<int>(operatorA.cols());
    freeOfPoint.assign(pointCount, -1);
    std::vector<int> heldOfPoint(pointCount, -1);
    int freeCount = 0;
    for (int point = 0; point < pointCount; ++point) {
      if (held[point]) {
        heldOfPoint[point] = static_cast<int>(heldPoints.size());
        heldPoints.push_back(point);
      } else {
        freeOfPoint[point] = freeCount++;
      }
    }
    std::vector<Eigen::Triplet<double>> freeEntries;
    std::vector<Eigen::Triplet<double>> heldEntries;
    freeEntries.reserve(static_cast<size_t>(operatorA.nonZeros()));
    for (int row = 0; row < operatorA.rows(); ++row) {
      for (RowSparseMatrix::InnerIterator entry(operatorA, row); entry; ++entry) {
        const int point = static_cast<int>(entry.col());
        const double value = sqrtWeights[row] * entry.value();
        if (freeOfPoint[point] >= 0) {
          freeEntries.emplace_back(row, freeOfPoint[point], value);
        } else {
          heldEntries.emplace_back(row, heldOfPoint[point], value);
        }
      }
    }
    weightedFree.resize(operatorA.rows(), freeCount);
    weightedFree.setFromTriplets(freeEntries.begin(), freeEntries.end());
    weightedHeld.resize(operatorA.rows(), static_cast<Eigen::Index>(heldPoints.size()));
    weightedHeld.setFromTriplets(heldEntries.begin(), heldEntries.end());
    checkEveryFreePointIsSampled();

    if (options.method == LeastSquaresMethod::Cholesky) {
      const SparseColMatrix normal = weightedFree.transpose() * weightedFree;
      cholesky.compute(normal);
      if (cholesky.info() != Eigen::Success) {
        throw SolverError("the normal equations of the approximation could not be factorized: the samples do "
                          "not determine all free control points");
      }
    } else {
      cglsOptions = options;
    }
  }

  // A free control point that no sample depends on would make the system singular.
  void checkEveryFreePointIsSampled() const {
    const Eigen::VectorXd columnNorms =
        Eigen::RowVectorXd::Ones(weightedFree.rows()) * weightedFree.cwiseAbs();
    for (size_t point = 0; point < freeOfPoint.size(); ++point) {
      const int column = freeOfPoint[point];
      if (column >= 0 && !(columnNorms[column] > 0.0)) {
        throw SolverError("control point " + std::to_string(point) +
                          " influences no sample with positive weight, so the approximation cannot place it");
      }
    }
  }

  Eigen::VectorXd solve(const Eigen::VectorXd& weightedTargets, const Eigen::VectorXd& heldValues,
                        const Eigen::VectorXd& guess, LeastSquaresMethod method) const {
    const Eigen::VectorXd rhs = weightedTargets - weightedHeld * heldValues;
    if (method == LeastSquaresMethod::Cholesky) return cholesky.solve(weightedFree.transpose() * rhs);
    // CGLS solves for the correction of the current points, so its relative tolerance measures the
    // error against the size of the correction rather than against the coordinates themselves.
    // A solver per call (setting it up costs one pass over the matrix), so that the coordinates
    // can be solved on separate threads.
    Eigen::LeastSquaresConjugateGradient<SparseColMatrix> cgls;
    cgls.setTolerance(cglsOptions.cglsTolerance);
    cgls.setMaxIterations(cglsOptions.cglsMaxIterations);
    cgls.compute(weightedFree);
    const Eigen::VectorXd correction = cgls.solve(rhs - weightedFree * guess);
    if (cgls.info() == Eigen::NumericalIssue) throw SolverError("CGLS failed on the approximation problem");
    return guess + correction;
  }
};

struct ControlPointSolver::Impl {
  LeastSquaresOptions options;
  Eigen::Matrix3d frame = Eigen::Matrix3d::Identity();  // rows: the axes the problem is solved in
  Eigen::VectorXd sqrtWeights;
  std::vector<bool> fixed;
  std::vector<int> planeVertices;
  double planeOffset = 0.0;                          // the plane's third frame coordinate
  std::unique_ptr<FreeColumnSystem> tangentSystem;   // frame axes 0, 1 (and 2 without a plane)
  std::unique_ptr<FreeColumnSystem> normalSystem;    // frame axis 2 when there is a plane
  int sampleCount = 0;
  int pointCount = 0;
};

ControlPointSolver::ControlPointSolver(const RowSparseMatrix& operatorA, const Eigen::VectorXd& weights,
                                       const ApproximationConstraints& constraints,
                                       const LeastSquaresOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.options = options;
  s.sampleCount = static_cast<int>(operatorA.rows());
  s.pointCount = static_cast<int>(operatorA.cols());
  if (s.sampleCount == 0 || s.pointCount == 0) throw InvalidInputError("the sample operator is empty");
  if (weights.size() != 0 && weights.size() != operatorA.rows()) {
    throw InvalidInputError("got " + std::to_string(weights.size()) + " weights for " +
                            std::to_string(s.sampleCount) + " samples");
  }
  s.sqrtWeights = Eigen::VectorXd::Ones(s.sampleCount);
  for (Eigen::Index i = 0; i < weights.size(); ++i) {
    if (!(weights[i] >= 0.0) || !std::isfinite(weights[i])) {
      throw InvalidInputError("weight of sample " + std::to_string(i) + " must be finite and not negative");
    }
    s.sqrtWeights[i] = std::sqrt(weights[i]);
  }
  checkVertexIds(constraints.fixedVertices, s.pointCount, "fixed");
  s.fixed.assign(s.pointCount, false);
  for (int id : constraints.fixedVertices) s.fixed[id] = true;

  s.tangentSystem = std::make_unique<FreeColumnSystem>(operatorA, s.sqrtWeights, s.fixed, options);
  if (constraints.plane) {
    const PlaneConstraint& plane = *constraints.plane;
    if (!plane.normal.allFinite() || plane.normal.norm() < 1e-300 || !plane.point.allFinite()) {
      throw InvalidInputError("the constraint plane needs a finite point and a non-zero normal");
    }
    checkVertexIds(plane.vertices, s.pointCount, "plane");
    s.frame = frameWithNormal(plane.normal);
    s.planeOffset = s.frame.row(2).dot(plane.point);
    s.planeVertices = plane.vertices;
    std::vector<bool> heldInNormal = s.fixed;
    for (int id : plane.vertices) heldInNormal[id] = true;
    s.normalSystem = std::make_unique<FreeColumnSystem>(operatorA, s.sqrtWeights, heldInNormal, options);
  }
}

ControlPointSolver::~ControlPointSolver() = default;
ControlPointSolver::ControlPointSolver(ControlPointSolver&&) noexcept = default;
ControlPointSolver& ControlPointSolver::operator=(ControlPointSolver&&) noexcept = default;

int ControlPointSolver::sampleCount() const { return impl_->sampleCount; }
int ControlPointSolver::controlPointCount() const { return impl_->pointCount; }

RowMatrixX3d ControlPointSolver::solve(const RowMatrixX3d& targets, const RowMatrixX3d& current) const {
  const Impl& s = *impl_;
  if (targets.rows() != s.sampleCount) {
    throw InvalidInputError("got " + std::to_string(targets.rows()) + " target points for " +
                            std::to_string(s.sampleCount) + " samples");
  }
  if (current.rows() != s.pointCount) {
    throw InvalidInputError("got " + std::to_string(current.rows()) + " current control points, expected " +
                            std::to_string(s.pointCount));
  }
  checkFinitePoints(targets, "target point");
  checkFinitePoints(current);

  // Work in the constraint frame: row-vector points map as p' = p F^T.
  const RowMatrixX3d localTargets = targets * s.frame.transpose();
  RowMatrixX3d local = current * s.frame.transpose();
  for (int id : s.planeVertices) local(id, 2) = s.planeOffset;

  RowMatrixX3d result = local;
  auto solveAxis = [&](int axis) {
    const FreeColumnSystem& system = (axis == 2 && s.normalSystem) ? *s.normalSystem : *s.tangentSystem;
    Eigen::VectorXd held(static_cast<Eigen::Index>(system.heldPoints.size()));
    for (size_t k = 0; k < system.heldPoints.size(); ++k) held[static_cast<Eigen::Index>(k)] = local(system.heldPoints[k], axis);
    Eigen::VectorXd guess(system.weightedFree.cols());
    for (int point = 0; point < s.pointCount; ++point) {
      if (system.freeOfPoint[point] >= 0) guess[system.freeOfPoint[point]] = local(point, axis);
    }
    const Eigen::VectorXd weightedTargets = s.sqrtWeights.cwiseProduct(localTargets.col(axis));
    const Eigen::VectorXd free = system.solve(weightedTargets, held, guess, s.options.method);
    for (int point = 0; point < s.pointCount; ++point) {
      if (system.freeOfPoint[point] >= 0) result(point, axis) = free[system.freeOfPoint[point]];
    }
  };
  if (s.options.method == LeastSquaresMethod::Cgls) {
    // The three coordinates are independent problems: solve them at once (CHOLMOD's solve shares
    // its workspace, so the Cholesky path stays on one thread).
    parallelChunks(3, 1, [&](std::int64_t begin, std::int64_t end) {
      for (std::int64_t axis = begin; axis < end; ++axis) solveAxis(static_cast<int>(axis));
    }, 3);
  } else {
    for (int axis = 0; axis < 3; ++axis) solveAxis(axis);
  }
  if (!result.allFinite()) throw SolverError("the approximation produced non-finite control points");
  return result * s.frame;
}

}  // namespace bvmesh::fit

// Iteration step 4: new control points whose limit samples best match their projections,
//   min_p  sum_i w_i |A_i p - s_i|^2,
// with A the (#samples x #control points) limit-sample operator, s_i the projected samples and
// w_i per-sample weights; one matrix, three right-hand sides (x, y, z).
//
// Hard constraints are eliminated, not penalized:
//   - fixed vertices keep their current position;
//   - plane vertices (e.g. the root of a half model on its symmetry plane) stay on one plane:
//     the problem is solved in a frame whose third axis is the plane normal, where these
//     vertices keep their normal coordinate and move freely in the other two.
//
// The solver is built once per level (A and the weights fixed) and solves many right-hand sides:
// every parameter-correction pass of a level reuses the Cholesky factorization.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <optional>
#include <vector>

#include "core/common/types.h"

namespace bvmesh::fit {


enum class LeastSquaresMethod {
  Cholesky,  // sparse Cholesky of the normal equations, factorized once, reused per right-hand side
  Cgls,      // conjugate gradients on the least-squares problem for the correction of the current points
};

struct PlaneConstraint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();
  std::vector<int> vertices;  // control points that must stay on the plane
};

struct ApproximationConstraints {
  std::vector<int> fixedVertices;      // control points that keep their current position
  std::optional<PlaneConstraint> plane;
};

struct LeastSquaresOptions {
  LeastSquaresMethod method = LeastSquaresMethod::Cgls;
  // CGLS stops when the normal-equation residual of the correction has fallen by this factor.
  // A fitting pass need not solve exactly: the next pass corrects it again. On the M6, 1e-4 reaches
  // the same accuracy as 1e-8 in half the time; the sphere study's orders are unchanged.
  double cglsTolerance = 1e-4;
  int cglsMaxIterations = 2000;
};

class ControlPointSolver {
public:
  // operatorA: #S x #P limit-sample operator; weights: #S positive weights (empty = all 1).
  // Throws InvalidInputError for inconsistent sizes, bad weights or constraint indices out of
  // range, SolverError when the samples do not determine the free control points.
  ControlPointSolver(const RowSparseMatrix& operatorA, const Eigen::VectorXd& weights,
                     const ApproximationConstraints& constraints, const LeastSquaresOptions& options = {});
  ~ControlPointSolver();
  ControlPointSolver(ControlPointSolver&&) noexcept;
  ControlPointSolver& operator=(ControlPointSolver&&) noexcept;

  // targets: #S x 3 projected samples; current: #P x 3 current control points (values of the
  // constrained points, and the warm start of CGLS). Returns the #P x 3 new control points.
  // Plane vertices are put exactly on the plane.
  RowMatrixX3d solve(const RowMatrixX3d& targets, const RowMatrixX3d& current) const;

  int sampleCount() const;
  int controlPointCount() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bvmesh::fit

#include "core/fit/volume_fit.h"

#include <Eigen/IterativeLinearSolvers>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <unordered_set>
#include <utility>

#include "core/common/errors.h"
#include "core/common/number_text.h"

namespace bvmesh::fit {
namespace {

using volume::BoundaryCondition;
using volume::HexMesh;

// Displacements of the points that are not on the boundary: sum over edges w_ij (d_i - d_j) = 0
// at each, with the boundary points' displacements given.
RowMatrixX3d harmonicDisplacement(const HexMesh& mesh, const std::vector<char>& onBoundary, const RowMatrixX3d& boundaryMoves) {
  const auto count = static_cast<size_t>(mesh.points.rows());
  std::vector<int> unknown(count, -1);
  int unknowns = 0;
  for (size_t p = 0; p < count; ++p) {
    if (!onBoundary[p]) unknown[p] = unknowns++;
  }
  RowMatrixX3d moves = boundaryMoves;
  if (unknowns == 0) return moves;
  std::unordered_set<std::uint64_t> seen;
  std::vector<Eigen::Triplet<double>> entries;
  RowMatrixX3d rhs = RowMatrixX3d::Zero(unknowns, 3);
  for (const auto& cell : mesh.cells) {
    for (const auto& edge : volume::kHexCellEdges) {
      const int a = cell[static_cast<size_t>(edge[0])], b = cell[static_cast<size_t>(edge[1])];
      const auto key = static_cast<std::uint64_t>(std::min(a, b)) << 32 | static_cast<std::uint64_t>(std::max(a, b));
      if (!seen.insert(key).second) continue;
      // Short edges couple stronger (weight 1 / length^2): the thin boundary-layer cells then move
      // with the wall nearly rigidly instead of being squashed by its displacement.
      const double weight = 1.0 / (mesh.points.row(a) - mesh.points.row(b)).squaredNorm();
      for (const auto& [from, to] : {std::pair<int, int>{a, b}, std::pair<int, int>{b, a}}) {
        const int row = unknown[static_cast<size_t>(from)];
        if (row < 0) continue;
        entries.emplace_back(row, row, weight);
        const int column = unknown[static_cast<size_t>(to)];
        if (column >= 0) {
          entries.emplace_back(row, column, -weight);
        } else {
          rhs.row(row) += weight * boundaryMoves.row(to);
        }
      }
    }
  }
  Eigen::SparseMatrix<double> laplacian(unknowns, unknowns);
  laplacian.setFromTriplets(entries.begin(), entries.end());
  // Conjugate gradients: a direct factorization of a 3-D mesh Laplacian fills in badly (tens of
  // seconds at 40k unknowns), the iteration costs a few hundred sparse products.
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> solver(laplacian);
  solver.setTolerance(1e-12);
  solver.setMaxIterations(std::max<Eigen::Index>(1000, static_cast<Eigen::Index>(100.0 * std::cbrt(unknowns))));
  Eigen::MatrixXd solved(unknowns, 3);
  for (int d = 0; d < 3; ++d) {
    solved.col(d) = solver.solve(rhs.col(d));
    if (solver.info() != Eigen::Success) {
      throw SolverError("continued fitting: the interior displacement did not converge (" +
                        std::to_string(solver.iterations()) + " iterations, residual " +
                        numberText(solver.error()) + "; an interior region without a boundary point?)");
    }
  }
  for (size_t p = 0; p < count; ++p) {
    if (unknown[p] >= 0) moves.row(static_cast<Eigen::Index>(p)) = solved.row(unknown[p]);
  }
  return moves;
}

}  // namespace

VolumeFitResult subdivideAndFitVolume(const HexMesh& mesh, std::shared_ptr<const target::Target> target,
                                      const FitOptions& options, int passes) {
  if (passes < 1) throw InvalidInputError("continued fitting needs passes >= 1, got " + std::to_string(passes));
  volume::HexSubdivisionResult refined = volume::subdivideHexMesh(mesh, options.subdivision);
  HexMesh& result = refined.mesh;
  volume::WallControlMesh wall = volume::wallControlMesh(result);
  SurfaceFitter fitter(std::move(target), std::move(wall.mesh), {}, options);
  fitter.correctParameters(passes);

  std::vector<char> onBoundary(static_cast<size_t>(result.points.rows()), 0);
  for (const auto& face : result.boundaryFaces) {
    for (int p : face) onBoundary[static_cast<size_t>(p)] = 1;
  }
  RowMatrixX3d boundaryMoves = RowMatrixX3d::Zero(result.points.rows(), 3);
  const RowMatrixX3d& fitted = fitter.mesh().vertices();
  for (size_t v = 0; v < wall.points.size(); ++v) {
    boundaryMoves.row(wall.points[v]) = fitted.row(static_cast<Eigen::Index>(v)) - result.points.row(wall.points[v]);
  }
  result.points += harmonicDisplacement(result, onBoundary, boundaryMoves);

  VolumeFitResult out;
  out.minScaledJacobian = std::numeric_limits<double>::infinity();
  for (size_t c = 0; c < result.cells.size(); ++c) {
    const std::array<double, 8> corners = volume::cornerJacobians(result.points, result.cells[c], true);
    const double scaled = *std::min_element(corners.begin(), corners.end());
    if (!(scaled > 0.0)) {
      Eigen::RowVector3d centre = Eigen::RowVector3d::Zero();
      for (int p : result.cells[c]) centre += result.points.row(p) / 8.0;
      throw SolverError("continued fitting: refined cell " + std::to_string(c) + " (child of cell " +
                        std::to_string(c / 8) + ") at (" + coordinatesText(centre.transpose()) +
                        ") turned over (scaled corner Jacobian " + numberText(scaled) +
                        ") with the fitted wall and the interior following it");
    }
    out.minScaledJacobian = std::min(out.minScaledJacobian, scaled);
  }
  out.wall = fitter.record(false);
  out.mesh = std::move(result);
  out.subdivisionOperator = std::move(refined.subdivisionOperator);
  return out;
}

}  // namespace bvmesh::fit

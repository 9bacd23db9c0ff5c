#include "core/surface/chart_continuity.h"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cstdlib>
#include <utility>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"

namespace bvmesh::surface {
namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

// The poles next to the outer ring: (i, j) with 1 <= i <= m + 1, 1 <= j <= n + 1 on that box's
// outline. The unknowns are their three coordinates, 3 * ring index + coordinate.
class SecondRing {
 public:
  SecondRing(int m, int n) : vPoles_(n + 3), index_(static_cast<size_t>((m + 3) * (n + 3)), -1) {
    for (int i = 1; i <= m + 1; ++i) {
      for (int j = 1; j <= n + 1; ++j) {
        if (i != 1 && i != m + 1 && j != 1 && j != n + 1) continue;
        index_[static_cast<size_t>(i * vPoles_ + j)] = static_cast<int>(poles_.size());
        poles_.push_back({i, j});
      }
    }
  }
  int size() const { return static_cast<int>(poles_.size()); }
  const std::array<int, 2>& pole(int k) const { return poles_[static_cast<size_t>(k)]; }
  // Ring index of pole (i, j), -1 when it is not on the ring.
  int index(int i, int j) const { return index_[static_cast<size_t>(i * vPoles_ + j)]; }

 private:
  int vPoles_;
  std::vector<int> index_;
  std::vector<std::array<int, 2>> poles_;
};

// The 4 x 4 poles that act at (s, t), from (uFirst, vFirst), with their basis values and
// derivatives in u and v.
struct LocalBasis {
  int uFirst = 0, vFirst = 0;
  double u[4], du[4], v[4], dv[4];
};

LocalBasis localBasis(int m, int n, double s, double t) {
  const std::vector<double> uKnots = uniformClampedKnots(3, m);
  const std::vector<double> vKnots = uniformClampedKnots(3, n);
  const int uSpan = findKnotSpan(uKnots, 3, s);
  const int vSpan = findKnotSpan(vKnots, 3, t);
  LocalBasis basis;
  basis.uFirst = uSpan - 3;
  basis.vFirst = vSpan - 3;
  basisFunctions(uKnots, 3, uSpan, s, basis.u, basis.du);
  basisFunctions(vKnots, 3, vSpan, t, basis.v, basis.dv);
  return basis;
}

// d/du and d/dv of the chart at the basis' point.
std::pair<Eigen::Vector3d, Eigen::Vector3d> firstDerivatives(const std::array<Eigen::MatrixXd, 3>& poles,
                                                             const LocalBasis& basis) {
  Eigen::Vector3d alongU = Eigen::Vector3d::Zero();
  Eigen::Vector3d alongV = Eigen::Vector3d::Zero();
  for (int a = 0; a < 4; ++a) {
    for (int b = 0; b < 4; ++b) {
      for (int d = 0; d < 3; ++d) {
        const double pole = poles[static_cast<size_t>(d)](basis.uFirst + a, basis.vFirst + b);
        alongU[d] += basis.du[a] * basis.v[b] * pole;
        alongV[d] += basis.u[a] * basis.dv[b] * pole;
      }
    }
  }
  return {alongU, alongV};
}

int polesAlong(const std::array<Eigen::MatrixXd, 3>& poles, int direction) {
  return static_cast<int>(direction == 0 ? poles[0].rows() : poles[0].cols());
}

}  // namespace

Eigen::Vector3d chartNormal(const std::array<Eigen::MatrixXd, 3>& poles, double s, double t) {
  const LocalBasis basis = localBasis(polesAlong(poles, 0) - 3, polesAlong(poles, 1) - 3, s, t);
  const auto [alongU, alongV] = firstDerivatives(poles, basis);
  const Eigen::Vector3d normal = alongU.cross(alongV);
  return normal.norm() > 0.0 ? Eigen::Vector3d(normal.normalized()) : Eigen::Vector3d::Zero();
}

void alignBorderTangentPlanes(std::array<Eigen::MatrixXd, 3>& poles, const std::vector<BorderNormal>& normals,
                              const Eigen::MatrixXd& uGram, const Eigen::MatrixXd& vGram, double weight) {
  if (normals.empty()) return;
  const int m = polesAlong(poles, 0) - 3;
  const int n = polesAlong(poles, 1) - 3;
  const SecondRing ring(m, n);
  std::vector<Eigen::Triplet<double>> entries;
  // Moving the ring costs what it moves the fitted samples: A^T A on the ring, per coordinate.
  for (int a = 0; a < ring.size(); ++a) {
    const auto [i, j] = ring.pole(a);
    for (int b = 0; b < ring.size(); ++b) {
      const auto [k, l] = ring.pole(b);
      if (std::abs(i - k) > 3 || std::abs(j - l) > 3) continue;
      const double value = uGram(i, k) * vGram(j, l);
      for (int d = 0; d < 3; ++d) entries.emplace_back(3 * a + d, 3 * b + d, value);
    }
  }
  // Per border point: N . (cross derivative) = 0, linear in the ring's moves x (row . x +
  // residual). Scaled by 1 / sin of the angle between the two derivatives, it is the angle
  // between the tangent plane and N times |cross derivative|: near a corner whose sides almost
  // line up the plane turns a lot for a small cross-derivative error.
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(3 * ring.size());
  std::vector<std::pair<int, double>> row;
  for (const BorderNormal& point : normals) {
    const bool alongU = point.side == ChartSide::VMin || point.side == ChartSide::VMax;
    double s = point.position;
    double t = point.position;
    if (alongU) t = point.side == ChartSide::VMin ? 0.0 : n;
    else s = point.side == ChartSide::UMin ? 0.0 : m;
    LocalBasis basis = localBasis(m, n, s, t);
    const auto [du, dv] = firstDerivatives(poles, basis);
    const double sine = du.cross(dv).norm() / (du.norm() * dv.norm());
    if (!(sine > 0.0)) continue;
    // The cross derivative's weights: basis values along the side, derivatives across it.
    if (alongU) std::copy(basis.dv, basis.dv + 4, basis.v);
    else std::copy(basis.du, basis.du + 4, basis.u);
    row.clear();
    double residual = 0.0;
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        const double c = weight / sine * basis.u[a] * basis.v[b];
        const int i = basis.uFirst + a;
        const int j = basis.vFirst + b;
        const int k = ring.index(i, j);
        for (int d = 0; d < 3; ++d) {
          residual += c * point.normal[d] * poles[static_cast<size_t>(d)](i, j);
          if (k >= 0 && c != 0.0) row.emplace_back(3 * k + d, c * point.normal[d]);
        }
      }
    }
    for (const auto& [p, x] : row) {
      rhs[p] -= x * residual;
      for (const auto& [q, y] : row) entries.emplace_back(p, q, x * y);
    }
  }
  SparseMatrix system(3 * ring.size(), 3 * ring.size());
  system.setFromTriplets(entries.begin(), entries.end());
  Eigen::SimplicialLDLT<SparseMatrix> solver(system);
  if (solver.info() != Eigen::Success) throw SolverError("the tangent-plane fit of a chart's border rows is singular");
  Eigen::VectorXd move = solver.solve(rhs);
  move += solver.solve(rhs - system * move);
  for (int a = 0; a < ring.size(); ++a) {
    const auto [i, j] = ring.pole(a);
    for (int d = 0; d < 3; ++d) poles[static_cast<size_t>(d)](i, j) += move[3 * a + d];
  }
}

}  // namespace bvmesh::surface

#include "core/volume/bspline_volume.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"
#include "core/common/number_text.h"
#include "core/common/parallel.h"

namespace bvmesh::volume {
namespace {

// Cell volumes and quality measures multiply up to six lengths: beyond this they overflow a double
// (blocks 1e80 across gave NaN volumes that the writers took).
constexpr double kMaxPoleCoordinate = 1e50;

const char* directionName(int direction) { return direction == 0 ? "u" : direction == 1 ? "v" : "w"; }

constexpr int kMaxOrder = 8;  // degree 7

// The degree + 1 basis functions (and derivatives, unless null) of one direction at x; returns
// the first pole they weight. `entry` names x in the error when it is outside the knot range.
int basisAt(const std::vector<double>& knots, int degree, double x, const char* name, size_t entry, double* values,
            double* derivatives) {
  const double lo = knots.front();
  const double hi = knots.back();
  const double slack = 1e-12 * std::max(1.0, hi - lo);
  if (!std::isfinite(x) || x < lo - slack || x > hi + slack) {
    throw InvalidInputError(std::string("parameter ") + name + " = " + numberText(x) + " (entry " +
                            std::to_string(entry) + ") is outside the knot range [" + numberText(lo) + ", " +
                            numberText(hi) + "]");
  }
  const double clamped = std::min(hi, std::max(lo, x));
  const int span = findKnotSpan(knots, degree, clamped);
  basisFunctions(knots, degree, span, clamped, values, derivatives);
  return span - degree;
}

// Basis functions of one direction at a list of parameters: span start and degree + 1 values
// (and derivatives) per parameter.
struct DirectionBasis {
  int order = 0;
  std::vector<int> first;
  std::vector<double> values;
  std::vector<double> derivatives;
};

DirectionBasis directionBasis(const std::vector<double>& knots, int degree, const std::vector<double>& parameters,
                              const char* name) {
  DirectionBasis basis;
  basis.order = degree + 1;
  basis.first.resize(parameters.size());
  basis.values.resize(parameters.size() * static_cast<size_t>(basis.order));
  basis.derivatives.resize(basis.values.size());
  for (size_t p = 0; p < parameters.size(); ++p) {
    basis.first[p] = basisAt(knots, degree, parameters[p], name, p, &basis.values[p * static_cast<size_t>(basis.order)],
                             &basis.derivatives[p * static_cast<size_t>(basis.order)]);
  }
  return basis;
}

}  // namespace

void validateClampedKnots(const std::vector<double>& knots, int degree, int poleCount, const std::string& what) {
  if (degree < 1 || degree > 7) throw InvalidInputError(what + ": degree " + std::to_string(degree) + " is not in 1..7");
  if (poleCount < degree + 1) {
    throw InvalidInputError(what + ": " + std::to_string(poleCount) + " poles, a degree-" + std::to_string(degree) +
                            " direction needs at least " + std::to_string(degree + 1));
  }
  if (static_cast<int>(knots.size()) != poleCount + degree + 1) {
    throw InvalidInputError(what + ": " + std::to_string(knots.size()) + " knots for " + std::to_string(poleCount) +
                            " poles of degree " + std::to_string(degree) + " (needs " +
                            std::to_string(poleCount + degree + 1) + ")");
  }
  for (size_t k = 0; k < knots.size(); ++k) {
    if (!std::isfinite(knots[k])) throw InvalidInputError(what + ": knot " + std::to_string(k) + " is not finite");
    if (k > 0 && knots[k] < knots[k - 1]) {
      throw InvalidInputError(what + ": knot " + std::to_string(k) + " (" + numberText(knots[k]) +
                              ") is below the one before it");
    }
  }
  const size_t order = static_cast<size_t>(degree + 1);
  for (size_t k = 1; k < order; ++k) {
    if (knots[k] != knots[0] || knots[knots.size() - 1 - k] != knots.back()) {
      throw InvalidInputError(what + ": not clamped (the first and last " + std::to_string(order) +
                              " knots must be equal)");
    }
  }
  if (!(knots.back() > knots.front())) throw InvalidInputError(what + ": empty knot range");
  for (size_t k = order; k + order < knots.size(); ++k) {
    size_t run = 1;
    while (k + run + order <= knots.size() - 1 && knots[k + run] == knots[k]) ++run;
    if (run > static_cast<size_t>(degree)) {
      throw InvalidInputError(what + ": interior knot " + numberText(knots[k]) + " repeated " +
                              std::to_string(run) + " times (at most the degree, " + std::to_string(degree) +
                              ")");
    }
  }
}

BsplineVolume::BsplineVolume(std::array<int, 3> degrees, std::array<std::vector<double>, 3> knots, RowMatrixX3d poles,
                             const std::string& name)
    : degrees_(degrees), knots_(std::move(knots)), poles_(std::move(poles)) {
  for (int d = 0; d < 3; ++d) {
    counts_[static_cast<size_t>(d)] =
        static_cast<int>(knots_[static_cast<size_t>(d)].size()) - degrees_[static_cast<size_t>(d)] - 1;
    validateClampedKnots(knots_[static_cast<size_t>(d)], degrees_[static_cast<size_t>(d)],
                         counts_[static_cast<size_t>(d)], name + ", " + directionName(d) + " knots");
  }
  const Eigen::Index expected = static_cast<Eigen::Index>(counts_[0]) * counts_[1] * counts_[2];
  if (poles_.rows() != expected) {
    throw InvalidInputError(name + ": " + std::to_string(poles_.rows()) + " poles, the knot vectors ask for " +
                            std::to_string(counts_[0]) + " x " + std::to_string(counts_[1]) + " x " +
                            std::to_string(counts_[2]) + " = " + std::to_string(expected));
  }
  for (Eigen::Index r = 0; r < poles_.rows(); ++r) {
    const bool finite = poles_.row(r).allFinite();
    if (!finite || poles_.row(r).cwiseAbs().maxCoeff() > kMaxPoleCoordinate) {
      const int i = static_cast<int>(r % counts_[0]);
      const int j = static_cast<int>((r / counts_[0]) % counts_[1]);
      const int k = static_cast<int>(r / (static_cast<Eigen::Index>(counts_[0]) * counts_[1]));
      const std::string pole =
          name + ": pole (" + std::to_string(i) + ", " + std::to_string(j) + ", " + std::to_string(k) + ")";
      if (!finite) throw InvalidInputError(pole + " is not finite");
      throw InvalidInputError(
          pole + " has a coordinate beyond 1e50 (" + coordinatesText(poles_.row(r).transpose()) +
          "): cell volumes and angles multiply up to six lengths and would overflow; rescale the model");
    }
  }
}

void BsplineVolume::evaluate(const RowMatrixX3d& parameters, RowMatrixX3d& points, RowMatrixX3d* du,
                             RowMatrixX3d* dv, RowMatrixX3d* dw) const {
  const Eigen::Index count = parameters.rows();
  points.resize(count, 3);
  for (RowMatrixX3d* d : {du, dv, dw}) {
    if (d != nullptr) d->resize(count, 3);
  }
  const bool derivatives = du != nullptr || dv != nullptr || dw != nullptr;
  parallelChunks(count, 4096, [&](std::int64_t begin, std::int64_t end) {
    // One point at a time, its basis on the stack: the per-point way that grid evaluation and
    // refinement are measured against (bench_volume, bench_grid).
    double values[3][kMaxOrder];
    double slopes[3][kMaxOrder];
    int first[3];
    const int order[3] = {degree(0) + 1, degree(1) + 1, degree(2) + 1};
    for (Eigen::Index p = begin; p < end; ++p) {
      for (int d = 0; d < 3; ++d) {
        first[d] = basisAt(knots(d), degree(d), parameters(p, d), directionName(d), static_cast<size_t>(p), values[d],
                           derivatives ? slopes[d] : nullptr);
      }
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      Eigen::Vector3d xu = x, xv = x, xw = x;
      for (int c = 0; c < order[2]; ++c) {
        for (int b = 0; b < order[1]; ++b) {
          for (int a = 0; a < order[0]; ++a) {
            const Eigen::Vector3d pole = poles_.row(poleIndex(first[0] + a, first[1] + b, first[2] + c)).transpose();
            const double nu = values[0][a];
            const double nv = values[1][b];
            const double nw = values[2][c];
            x += nu * nv * nw * pole;
            if (derivatives) {
              xu += slopes[0][a] * nv * nw * pole;
              xv += nu * slopes[1][b] * nw * pole;
              xw += nu * nv * slopes[2][c] * pole;
            }
          }
        }
      }
      points.row(p) = x.transpose();
      if (du != nullptr) du->row(p) = xu.transpose();
      if (dv != nullptr) dv->row(p) = xv.transpose();
      if (dw != nullptr) dw->row(p) = xw.transpose();
    }
  });
}

BsplineCurve BsplineVolume::isoCurve(int direction, double a, double b) const {
  BsplineCurve curve;
  curve.degree = degree(direction);
  curve.knots = knots(direction);
  isoCurvePoles(direction, a, b, curve.poles);
  return curve;
}

void BsplineVolume::isoCurvePoles(int direction, double a, double b, RowMatrixX3d& poles) const {
  const int first = direction == 0 ? 1 : 0;
  const int second = direction == 2 ? 1 : 2;
  double na[kMaxOrder];
  double nb[kMaxOrder];
  const int firstA = basisAt(knots(first), degree(first), a, directionName(first), 0, na, nullptr);
  const int firstB = basisAt(knots(second), degree(second), b, directionName(second), 0, nb, nullptr);
  const int orderA = degree(first) + 1;
  const int orderB = degree(second) + 1;
  // The weights of the orderA x orderB pole lines, and where those lines are in poles_, so the
  // sum over each layer along `direction` is a tight loop (every wall-normal grid line makes one).
  double weight[kMaxOrder * kMaxOrder];
  Eigen::Index offset[kMaxOrder * kMaxOrder];
  std::array<int, 3> ijk{};
  for (int y = 0; y < orderB; ++y) {
    for (int x = 0; x < orderA; ++x) {
      ijk[static_cast<size_t>(first)] = firstA + x;
      ijk[static_cast<size_t>(second)] = firstB + y;
      weight[y * orderA + x] = na[x] * nb[y];
      offset[y * orderA + x] = 3 * poleIndex(ijk[0], ijk[1], ijk[2]);
    }
  }
  ijk = {0, 0, 0};
  ijk[static_cast<size_t>(direction)] = 1;
  const Eigen::Index layer = 3 * poleIndex(ijk[0], ijk[1], ijk[2]);
  const int terms = orderA * orderB;
  poles.resize(poleCount(direction), 3);
  for (int along = 0; along < poleCount(direction); ++along) {
    const double* source = poles_.data() + along * layer;
    double sum[3] = {0.0, 0.0, 0.0};
    for (int t = 0; t < terms; ++t) {
      const double* pole = source + offset[t];
      for (int q = 0; q < 3; ++q) sum[q] += weight[t] * pole[q];
    }
    for (int q = 0; q < 3; ++q) poles(along, q) = sum[q];
  }
}

void BsplineVolume::evaluateGrid(const std::vector<double>& u, const std::vector<double>& v,
                                 const std::vector<double>& w, RowMatrixX3d& points, RowMatrixX3d* du,
                                 RowMatrixX3d* dv, RowMatrixX3d* dw) const {
  const DirectionBasis bu = directionBasis(knots(0), degree(0), u, "u");
  const DirectionBasis bv = directionBasis(knots(1), degree(1), v, "v");
  const DirectionBasis bw = directionBasis(knots(2), degree(2), w, "w");
  const bool derivatives = du != nullptr || dv != nullptr || dw != nullptr;
  const Eigen::Index nu = static_cast<Eigen::Index>(u.size());
  const Eigen::Index nv = static_cast<Eigen::Index>(v.size());
  const Eigen::Index nw = static_cast<Eigen::Index>(w.size());
  points.resize(nu * nv * nw, 3);
  for (RowMatrixX3d* d : {du, dv, dw}) {
    if (d != nullptr) d->resize(nu * nv * nw, 3);
  }
  const int poleV = counts_[1];
  const int poleW = counts_[2];
  // Per chunk of u parameters: sums over u (T: value and d/du at (a, pole j, pole k)), then over
  // v (S: value, d/du, d/dv at (a, b, pole k)), then over w into the output.
  parallelChunks(nu, std::max<Eigen::Index>(1, nu / 16), [&](std::int64_t begin, std::int64_t end) {
    const Eigen::Index chunk = end - begin;
    const int fields = derivatives ? 2 : 1;
    std::vector<double> t(static_cast<size_t>(chunk * poleV * poleW * 3 * fields), 0.0);
    auto tAt = [&](int field, Eigen::Index a, int j, int k) {
      return &t[static_cast<size_t>((((field * chunk + a) * poleV + j) * poleW + k) * 3)];
    };
    for (Eigen::Index a = 0; a < chunk; ++a) {
      const size_t pa = static_cast<size_t>(begin + a);
      for (int k = 0; k < poleW; ++k) {
        for (int j = 0; j < poleV; ++j) {
          double* value = tAt(0, a, j, k);
          double* slope = derivatives ? tAt(1, a, j, k) : nullptr;
          for (int r = 0; r < bu.order; ++r) {
            const auto row = poles_.row(poleIndex(bu.first[pa] + r, j, k));
            const double n = bu.values[pa * static_cast<size_t>(bu.order) + static_cast<size_t>(r)];
            for (int x = 0; x < 3; ++x) value[x] += n * row[x];
            if (slope != nullptr) {
              const double dn = bu.derivatives[pa * static_cast<size_t>(bu.order) + static_cast<size_t>(r)];
              for (int x = 0; x < 3; ++x) slope[x] += dn * row[x];
            }
          }
        }
      }
    }
    const int sFields = derivatives ? 3 : 1;
    std::vector<double> s(static_cast<size_t>(chunk * nv * poleW * 3 * sFields), 0.0);
    auto sAt = [&](int field, Eigen::Index a, Eigen::Index b, int k) {
      return &s[static_cast<size_t>((((field * chunk + a) * nv + b) * poleW + k) * 3)];
    };
    for (Eigen::Index a = 0; a < chunk; ++a) {
      for (Eigen::Index b = 0; b < nv; ++b) {
        const size_t pb = static_cast<size_t>(b);
        for (int r = 0; r < bv.order; ++r) {
          const int j = bv.first[pb] + r;
          const double n = bv.values[pb * static_cast<size_t>(bv.order) + static_cast<size_t>(r)];
          const double dn = bv.derivatives[pb * static_cast<size_t>(bv.order) + static_cast<size_t>(r)];
          for (int k = 0; k < poleW; ++k) {
            const double* value = tAt(0, a, j, k);
            double* out = sAt(0, a, b, k);
            for (int x = 0; x < 3; ++x) out[x] += n * value[x];
            if (derivatives) {
              const double* slopeU = tAt(1, a, j, k);
              double* outU = sAt(1, a, b, k);
              double* outV = sAt(2, a, b, k);
              for (int x = 0; x < 3; ++x) {
                outU[x] += n * slopeU[x];
                outV[x] += dn * value[x];
              }
            }
          }
        }
      }
    }
    for (Eigen::Index c = 0; c < nw; ++c) {
      const size_t pc = static_cast<size_t>(c);
      for (Eigen::Index b = 0; b < nv; ++b) {
        for (Eigen::Index a = 0; a < chunk; ++a) {
          double x[3] = {0, 0, 0}, xu[3] = {0, 0, 0}, xv[3] = {0, 0, 0}, xw[3] = {0, 0, 0};
          for (int r = 0; r < bw.order; ++r) {
            const int k = bw.first[pc] + r;
            const double n = bw.values[pc * static_cast<size_t>(bw.order) + static_cast<size_t>(r)];
            const double* value = sAt(0, a, b, k);
            for (int q = 0; q < 3; ++q) x[q] += n * value[q];
            if (derivatives) {
              const double dn = bw.derivatives[pc * static_cast<size_t>(bw.order) + static_cast<size_t>(r)];
              const double* valueU = sAt(1, a, b, k);
              const double* valueV = sAt(2, a, b, k);
              for (int q = 0; q < 3; ++q) {
                xu[q] += n * valueU[q];
                xv[q] += n * valueV[q];
                xw[q] += dn * value[q];
              }
            }
          }
          const Eigen::Index row = (begin + a) + nu * (b + nv * c);
          std::copy(x, x + 3, points.data() + 3 * row);
          if (du != nullptr) std::copy(xu, xu + 3, du->data() + 3 * row);
          if (dv != nullptr) std::copy(xv, xv + 3, dv->data() + 3 * row);
          if (dw != nullptr) std::copy(xw, xw + 3, dw->data() + 3 * row);
        }
      }
    }
  });
}

}  // namespace bvmesh::volume

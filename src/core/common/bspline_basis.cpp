#include "core/common/bspline_basis.h"

#include <algorithm>
#include <string>

#include "core/common/errors.h"

namespace bvmesh {

int findKnotSpan(const std::vector<double>& knots, int degree, double x) {
  const int poleCount = static_cast<int>(knots.size()) - degree - 1;
  if (x >= knots[static_cast<size_t>(poleCount)]) {
    // The last non-empty span: skip the repeated end knots.
    int span = poleCount - 1;
    while (span > degree && knots[static_cast<size_t>(span)] == knots[static_cast<size_t>(span + 1)]) --span;
    return span;
  }
  if (x <= knots[static_cast<size_t>(degree)]) {
    int span = degree;
    while (span < poleCount - 1 && knots[static_cast<size_t>(span)] == knots[static_cast<size_t>(span + 1)]) ++span;
    return span;
  }
  // First knot > x, one back.
  const auto upper = std::upper_bound(knots.begin() + degree, knots.begin() + poleCount + 1, x);
  return static_cast<int>(upper - knots.begin()) - 1;
}

void basisFunctions(const std::vector<double>& knots, int degree, int span, double x, double* values,
                    double* derivatives) {
  // ndu[j][r]: basis values (upper triangle incl. diagonal) and knot differences (lower), A2.3.
  constexpr int maxOrder = 8;
  if (degree + 1 > maxOrder) throw InvalidInputError("B-spline degree " + std::to_string(degree) + " above 7");
  double ndu[maxOrder][maxOrder];
  double left[maxOrder];
  double right[maxOrder];
  ndu[0][0] = 1.0;
  for (int j = 1; j <= degree; ++j) {
    left[j] = x - knots[static_cast<size_t>(span + 1 - j)];
    right[j] = knots[static_cast<size_t>(span + j)] - x;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      ndu[j][r] = right[r + 1] + left[j - r];
      const double temp = ndu[r][j - 1] / ndu[j][r];
      ndu[r][j] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    ndu[j][j] = saved;
  }
  for (int j = 0; j <= degree; ++j) values[j] = ndu[j][degree];
  // Exact unit values at clamped ends: the face of a clamped block is its boundary pole grid.
  if (x <= knots.front() || x >= knots.back()) {
    const int one = x <= knots.front() ? 0 : degree;
    for (int j = 0; j <= degree; ++j) values[j] = j == one ? 1.0 : 0.0;
  }
  if (derivatives == nullptr) return;
  if (degree == 0) {
    derivatives[0] = 0.0;
    return;
  }
  // First derivatives: p * (N_{r, p-1} / (t_{r+p} - t_r) - N_{r+1, p-1} / (t_{r+p+1} - t_{r+1})).
  for (int r = 0; r <= degree; ++r) {
    double d = 0.0;
    if (r >= 1) d += ndu[r - 1][degree - 1] / ndu[degree][r - 1];
    if (r <= degree - 1) d -= ndu[r][degree - 1] / ndu[degree][r];
    derivatives[r] = degree * d;
  }
}

std::vector<double> uniformClampedKnots(int degree, int spans) {
  std::vector<double> knots(static_cast<size_t>(degree), 0.0);
  for (int k = 0; k <= spans; ++k) knots.push_back(k);
  knots.insert(knots.end(), static_cast<size_t>(degree), static_cast<double>(spans));
  return knots;
}

std::vector<double> grevilleAbscissae(const std::vector<double>& knots, int degree) {
  const int poleCount = static_cast<int>(knots.size()) - degree - 1;
  std::vector<double> result(static_cast<size_t>(poleCount));
  for (int i = 0; i < poleCount; ++i) {
    double sum = 0.0;
    for (int k = 1; k <= degree; ++k) sum += knots[static_cast<size_t>(i + k)];
    result[static_cast<size_t>(i)] = sum / degree;
  }
  // Exact ends (the sum of equal knots divided by their count can round).
  result.front() = knots.front();
  result.back() = knots.back();
  return result;
}

void insertKnot(std::vector<double>& knots, int degree, Eigen::MatrixXd& poles, double x) {
  const int k = findKnotSpan(knots, degree, x);
  Eigen::MatrixXd result(poles.rows() + 1, poles.cols());
  for (int i = 0; i < result.rows(); ++i) {
    if (i <= k - degree) {
      result.row(i) = poles.row(i);
    } else if (i > k) {
      result.row(i) = poles.row(i - 1);
    } else {
      const double alpha = (x - knots[static_cast<size_t>(i)]) /
                           (knots[static_cast<size_t>(i + degree)] - knots[static_cast<size_t>(i)]);
      result.row(i) = alpha * poles.row(i) + (1.0 - alpha) * poles.row(i - 1);
    }
  }
  knots.insert(knots.begin() + k + 1, x);
  poles = std::move(result);
}

void restrictToInterval(std::vector<double>& knots, int degree, Eigen::MatrixXd& poles, double a, double b) {
  for (double end : {a, b}) {
    if (end <= knots.front() || end >= knots.back()) continue;
    for (auto r = std::count(knots.begin(), knots.end(), end); r < degree; ++r) insertKnot(knots, degree, poles, end);
  }
  // With a of multiplicity `degree`, the piece's first pole is the one before a's first knot.
  const int first =
      a <= knots.front() ? 0 : static_cast<int>(std::lower_bound(knots.begin(), knots.end(), a) - knots.begin()) - 1;
  std::vector<double> pieceKnots(static_cast<size_t>(degree + 1), a);
  for (double t : knots) {
    if (t > a && t < b) pieceKnots.push_back(t);
  }
  const int count = static_cast<int>(pieceKnots.size());  // interior knots + degree + 1
  pieceKnots.insert(pieceKnots.end(), static_cast<size_t>(degree + 1), b);
  knots = std::move(pieceKnots);
  poles = poles.middleRows(first, count).eval();
}

}  // namespace bvmesh

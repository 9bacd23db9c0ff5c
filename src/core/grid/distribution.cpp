#include "core/grid/distribution.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

#include "core/common/errors.h"
#include "core/common/number_text.h"

namespace bvmesh::grid {
namespace {

// A table sampled at equal steps over [0, 1], linearly interpolated at `fraction` (in [0, 1]).
double sampledAt(const std::vector<double>& table, double fraction) {
  const double at = fraction * static_cast<double>(table.size() - 1);
  const size_t k = std::min(static_cast<size_t>(at), table.size() - 2);
  const double w = at - static_cast<double>(k);
  return (1.0 - w) * table[k] + w * table[k + 1];
}

// The root of an increasing function on [lo, hi] (f(lo) < 0 < f(hi)) by bisection to the last bit.
template <class F>
double increasingRoot(F f, double lo, double hi) {
  for (int iteration = 0; iteration < 200 && hi - lo > 1e-15 * std::max(1.0, std::abs(hi)); ++iteration) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) < 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// delta with sinh(delta) / delta = b (b > 1) or sin(delta) / delta = b (b < 1).
double stretchingParameter(double b) {
  if (b > 1.0) return increasingRoot([b](double d) { return std::sinh(d) / d - b; }, 1e-9, 800.0);
  return increasingRoot([b](double d) { return b - std::sin(d) / d; }, 1e-9, M_PI - 1e-12);
}

void checkPoints(int points, const char* what) {
  if (points < 2) throw InvalidInputError(std::string(what) + ": " + std::to_string(points) + " points (at least 2)");
}

// (r^n - 1) / (r - 1) without cancellation near r = 1, from r - 1 and log r.
double geometricSum(double excess, double logGrowth, int intervals) {
  if (std::abs(excess) < 1e-300) return intervals;
  return std::expm1(intervals * logGrowth) / excess;
}

double geometricSum(double growth, int intervals) {
  return geometricSum(growth - 1.0, std::log1p(growth - 1.0), intervals);
}

// Vinokur's formula as published. Its stretching parameter and ratio are the same for every
// point, so they are solved for once.
std::vector<double> vinokurFormula(int points, double firstSpacing, double lastSpacing) {
  const int intervals = points - 1;
  std::vector<double> x(static_cast<size_t>(points));
  const bool atStart = firstSpacing > 0.0;
  const bool atEnd = lastSpacing > 0.0;
  const bool both = atStart && atEnd;
  const double a = both ? std::sqrt(lastSpacing / firstSpacing) : 1.0;
  const double b = both               ? 1.0 / (intervals * std::sqrt(firstSpacing * lastSpacing))
                   : atStart || atEnd ? 1.0 / (intervals * (atStart ? firstSpacing : lastSpacing))
                                      : 1.0;
  const double d = b != 1.0 ? stretchingParameter(b) : 0.0;
  for (int i = 0; i <= intervals; ++i) {
    const double xi = static_cast<double>(i) / intervals;
    double value = xi;
    if (both) {
      if (b != 1.0) {
        const double u = b > 1.0 ? 0.5 * (1.0 + std::tanh(d * (xi - 0.5)) / std::tanh(0.5 * d))
                                 : 0.5 * (1.0 + std::tan(d * (xi - 0.5)) / std::tan(0.5 * d));
        value = u / (a + (1.0 - a) * u);
      }
    } else if (atStart || atEnd) {
      const double eta = atStart ? xi : 1.0 - xi;
      double clustered = eta;
      if (b != 1.0) {
        clustered = b > 1.0 ? 1.0 + std::tanh(0.5 * d * (eta - 1.0)) / std::tanh(0.5 * d)
                            : 1.0 + std::tan(0.5 * d * (eta - 1.0)) / std::tan(0.5 * d);
      }
      value = atStart ? clustered : 1.0 - clustered;
    }
    x[static_cast<size_t>(i)] = value;
  }
  x.front() = 0.0;
  x.back() = 1.0;
  return x;
}

}  // namespace

std::vector<double> vinokurFractions(int points, double firstSpacing, double lastSpacing) {
  checkPoints(points, "a stretched distribution");
  if (!(firstSpacing >= 0.0 && firstSpacing < 1.0 && lastSpacing >= 0.0 && lastSpacing < 1.0)) {
    throw InvalidInputError("end spacings " + numberText(firstSpacing) + ", " + numberText(lastSpacing) +
                            " are not fractions in [0, 1) of the line's length");
  }
  // The formula meets the end spacings to first order only: rescale its inputs until the
  // spacings it gives are the ones asked (a few fixed-point steps).
  double first = firstSpacing, last = lastSpacing;
  std::vector<double> x = vinokurFormula(points, first, last);
  for (int iteration = 0; iteration < 50; ++iteration) {
    const double gotFirst = x[1], gotLast = 1.0 - x[x.size() - 2];
    const bool firstMet = firstSpacing == 0.0 || std::abs(gotFirst - firstSpacing) <= 1e-10 * firstSpacing;
    const bool lastMet = lastSpacing == 0.0 || std::abs(gotLast - lastSpacing) <= 1e-10 * lastSpacing;
    if (firstMet && lastMet) break;
    if (first > 0.0) first = std::min(0.999, first * firstSpacing / gotFirst);
    if (last > 0.0) last = std::min(0.999, last * lastSpacing / gotLast);
    x = vinokurFormula(points, first, last);
  }
  return x;
}

std::vector<double> tanhWallFractions(int points, double firstSpacing) {
  checkPoints(points, "a wall distribution");
  const int intervals = points - 1;
  if (!(firstSpacing > 0.0 && firstSpacing < 1.0 / intervals)) {
    throw InvalidInputError("a first spacing of " + numberText(firstSpacing) + " of the line's length with " +
                            std::to_string(points) +
                            " points cannot cluster at the wall (it must be below 1/" +
                            std::to_string(intervals) + ")");
  }
  // x(xi) = 1 - tanh(d (1 - xi) / 2) / tanh(d / 2), written without cancellation for large d.
  auto fraction = [](double d, double xi) {
    return std::sinh(0.5 * d * xi) / (std::sinh(0.5 * d) * std::cosh(0.5 * d * (1.0 - xi)));
  };
  const double xi1 = 1.0 / intervals;
  const double d = increasingRoot([&](double delta) { return firstSpacing - fraction(delta, xi1); }, 1e-9, 1400.0);
  std::vector<double> x(static_cast<size_t>(points));
  for (int i = 0; i <= intervals; ++i) x[static_cast<size_t>(i)] = fraction(d, static_cast<double>(i) / intervals);
  x.front() = 0.0;
  x.back() = 1.0;
  return x;
}

double geometricGrowth(int points, double firstSpacing, double length) {
  checkPoints(points, "a geometric distribution");
  const int intervals = points - 1;
  if (!(firstSpacing > 0.0) || !(length > 0.0)) {
    throw InvalidInputError("a geometric distribution needs a positive first spacing and length (got " +
                            numberText(firstSpacing) + " and " + numberText(length) + ")");
  }
  if (firstSpacing * intervals >= length) {
    throw InvalidInputError("a first spacing of " + numberText(firstSpacing) + " times " +
                            std::to_string(intervals) + " intervals already exceeds the line's length " +
                            numberText(length) + ": use fewer points or a smaller first spacing");
  }
  // f(r) = h S(r) - L is increasing and convex for r > 1: Newton from r0 = (L / h)^(1 / (n - 2)),
  // where f > 0 (S(r) > r^(n - 2)), descends monotonically onto the root.
  auto excess = [&](double growth) { return firstSpacing * geometricSum(growth, intervals) - length; };
  if (intervals == 1) return 1.0;
  double r = std::max(1.0 + 1e-3, std::pow(length / firstSpacing, 1.0 / std::max(1, intervals - 1)));
  for (int iteration = 0; iteration < 100; ++iteration) {
    const double f = excess(r);
    const double step = 1e-7 * (r - 1.0);
    const double slope = (excess(r + step) - f) / step;
    const double next = r - f / slope;
    if (!(next > 1.0) || !(slope > 0.0)) break;  // too close to 1 for Newton: bisect instead
    if (std::abs(next - r) <= 1e-15 * r) return next;
    r = next;
  }
  double hi = 2.0;
  while (excess(hi) < 0.0) hi *= 2.0;
  return increasingRoot(excess, 1.0, hi);
}

std::vector<double> geometricDistances(int points, double firstSpacing, double growth, double length) {
  std::vector<double> distance(static_cast<size_t>(points), 0.0);
  const double excess = growth - 1.0;
  const double logGrowth = std::log1p(excess);  // once for every k
  for (int k = 1; k < points; ++k) distance[static_cast<size_t>(k)] = firstSpacing * geometricSum(excess, logGrowth, k);
  distance.back() = length;
  return distance;
}

int geometricPointsNeeded(double firstSpacing, double maxGrowth, double length) {
  if (!(maxGrowth > 1.0)) throw InvalidInputError("the maximum growth ratio must be above 1");
  const double intervals = std::ceil(std::log1p(length * (maxGrowth - 1.0) / firstSpacing) / std::log(maxGrowth));
  return static_cast<int>(intervals) + 1;
}

double flatPlateFirstCellHeight(double yPlus, double reynoldsNumber, double referenceLength) {
  if (!(yPlus > 0.0) || !(reynoldsNumber > 0.0) || !(referenceLength > 0.0)) {
    throw InvalidInputError("a y+ target needs a positive y+, Reynolds number and reference length (got " +
                            numberText(yPlus) + ", " + numberText(reynoldsNumber) + ", " +
                            numberText(referenceLength) + ")");
  }
  const double skinFriction = 0.026 * std::pow(reynoldsNumber, -1.0 / 7.0);
  return yPlus * referenceLength / (reynoldsNumber * std::sqrt(0.5 * skinFriction));
}

double flatPlateYPlus(double firstCellHeight, double reynoldsNumber, double referenceLength) {
  return firstCellHeight / flatPlateFirstCellHeight(1.0, reynoldsNumber, referenceLength);
}

SpanPolynomials::SpanPolynomials(const std::vector<double>& knots, int degree) : order_(degree + 1) {
  const size_t order = static_cast<size_t>(order_);
  const int poleCount = static_cast<int>(knots.size()) - degree - 1;
  upper_ = knots.back();
  // Cox-de Boor on polynomials in tau: N_{i,k} = (t - t_i) / (t_{i+k} - t_i) N_{i,k-1}
  // + (t_{i+k+1} - t) / (t_{i+k+1} - t_{i+1}) N_{i+1,k-1}, with t = t_s + width tau (each factor
  // linear in tau), from N_{s,0} = 1. Exact to rounding, unlike a fit through sampled values.
  std::vector<std::vector<double>> level(order), next(order);
  for (int s = degree; s < poleCount; ++s) {
    const double a = knots[static_cast<size_t>(s)], b = knots[static_cast<size_t>(s + 1)];
    if (!(b > a)) continue;
    const double width = b - a;
    for (auto& polynomial : level) polynomial.assign(order, 0.0);
    level[static_cast<size_t>(degree)][0] = 1.0;  // slot r holds N_{s - degree + r}
    for (int k = 1; k <= degree; ++k) {
      for (auto& polynomial : next) polynomial.assign(order, 0.0);
      for (int r = degree - k; r <= degree; ++r) {
        const int i = s - degree + r;
        auto addScaled = [&](const std::vector<double>& from, double constant, double slope) {
          std::vector<double>& to = next[static_cast<size_t>(r)];
          for (size_t m = 0; m < order; ++m) {
            to[m] += constant * from[m];
            if (m + 1 < order) to[m + 1] += slope * from[m];
          }
        };
        const double left = knots[static_cast<size_t>(i + k)] - knots[static_cast<size_t>(i)];
        if (left > 0.0) addScaled(level[static_cast<size_t>(r)], (a - knots[static_cast<size_t>(i)]) / left, width / left);
        const double right = knots[static_cast<size_t>(i + k + 1)] - knots[static_cast<size_t>(i + 1)];
        if (right > 0.0 && r < degree) {
          addScaled(level[static_cast<size_t>(r + 1)], (knots[static_cast<size_t>(i + k + 1)] - a) / right, -width / right);
        }
      }
      std::swap(level, next);
    }
    start_.push_back(a);
    width_.push_back(width);
    perWidth_.push_back(1.0 / width);
    firstPole_.push_back(s - degree);
    for (size_t m = 0; m < order; ++m) {
      for (size_t r = 0; r < order; ++r) basis_.push_back(level[r][m]);
    }
  }
}

void PolynomialCurve::assign(const RowMatrixX3d& poles, const SpanPolynomials& spans) {
  spans_ = &spans;
  const size_t order = static_cast<size_t>(spans.order_);
  coefficients_.resize(spans.pieceCount() * order * 3);
  const double* pole = poles.data();
  // Per piece, its order x order basis matrix times its order x 3 poles (the cubic case with the
  // sizes known to the compiler).
  auto convert = [&](auto fixedOrder) {
    constexpr size_t fixed = decltype(fixedOrder)::value;
    const size_t size = fixed > 0 ? fixed : order;
    for (size_t piece = 0; piece < spans.pieceCount(); ++piece) {
      const double* first = pole + 3 * spans.firstPole_[piece];
      const double* basis = &spans.basis_[piece * size * size];
      double* out = &coefficients_[piece * size * 3];
      for (size_t m = 0; m < size; ++m) {
        double x = 0.0, y = 0.0, z = 0.0;
        for (size_t r = 0; r < size; ++r) {
          const double n = basis[m * size + r];
          x += n * first[3 * r];
          y += n * first[3 * r + 1];
          z += n * first[3 * r + 2];
        }
        out[3 * m] = x;
        out[3 * m + 1] = y;
        out[3 * m + 2] = z;
      }
    }
  };
  if (order == 4) convert(std::integral_constant<size_t, 4>{});
  else convert(std::integral_constant<size_t, 0>{});
}

namespace {

// Horner on one piece's coefficients (order x 3, tau^0 first): the point and, unless null,
// d/dtau. Order 0: the order given at run time; the blocks' cubic pieces get an unrolled copy.
template <int Order>
inline Eigen::Vector3d horner(const double* c, int order, double tau, Eigen::Vector3d* slope) {
  if constexpr (Order > 0) order = Order;
  auto row = [c](int m) { return Eigen::Vector3d(c[3 * m], c[3 * m + 1], c[3 * m + 2]); };
  Eigen::Vector3d value = row(order - 1);
  Eigen::Vector3d derivative = Eigen::Vector3d::Zero();
  for (int m = order - 2; m >= 0; --m) {
    if (slope != nullptr) derivative = derivative * tau + value;
    value = value * tau + row(m);
  }
  if (slope != nullptr) *slope = derivative;
  return value;
}

}  // namespace

Eigen::Vector3d PolynomialCurve::point(size_t piece, double tau, Eigen::Vector3d* tangent) const {
  const int order = spans_->order_;
  const double* c = &coefficients_[piece * static_cast<size_t>(order) * 3];
  const Eigen::Vector3d value = order == 4 ? horner<4>(c, order, tau, tangent) : horner<0>(c, order, tau, tangent);
  if (tangent != nullptr) *tangent *= spans_->perWidth_[piece];
  return value;
}

Eigen::Vector3d PolynomialCurve::tangent(size_t piece, double tau) const {
  const int order = spans_->order_;
  const double* c = &coefficients_[piece * static_cast<size_t>(order) * 3];
  auto row = [c](int m) { return Eigen::Vector3d(c[3 * m], c[3 * m + 1], c[3 * m + 2]); };
  Eigen::Vector3d slope = (order - 1) * row(order - 1);
  for (int m = order - 2; m >= 1; --m) slope = slope * tau + m * row(m);
  return slope * spans_->perWidth_[piece];
}

void PolynomialCurve::evaluate(const double* t, size_t count, Eigen::Vector3d* points, Eigen::Vector3d* tangents) const {
  if (count == 0) return;
  const int order = spans_->order_;
  const size_t stride = static_cast<size_t>(order) * 3;
  auto walk = [&](auto evaluatePiece) {
    size_t piece = pieceOf(std::min(upper(), std::max(lower(), t[0])), 0);
    for (size_t k = 0; k < count; ++k) {
      const double x = std::min(upper(), std::max(lower(), t[k]));
      piece = pieceOf(x, piece);
      const double tau = (x - spans_->start_[piece]) * spans_->perWidth_[piece];
      points[k] = evaluatePiece(&coefficients_[piece * stride], tau, tangents != nullptr ? &tangents[k] : nullptr);
      if (tangents != nullptr) tangents[k] *= spans_->perWidth_[piece];
    }
  };
  if (order == 4) {
    walk([](const double* c, double tau, Eigen::Vector3d* slope) { return horner<4>(c, 4, tau, slope); });
  } else {
    walk([order](const double* c, double tau, Eigen::Vector3d* slope) { return horner<0>(c, order, tau, slope); });
  }
}

ArcLength::ArcLength(const BsplineCurve& curve, int intervalsPerSpan) {
  const SpanPolynomials spans(curve.knots, curve.degree);
  PolynomialCurve polynomial;
  polynomial.assign(curve.poles, spans);
  tabulate(polynomial, intervalsPerSpan);
}

void ArcLength::tabulate(const PolynomialCurve& curve, int intervalsPerSpan) {
  // Simpson nodes: 2 per interval and the last end; speeds from dC/dtau by Horner.
  const size_t pieces = curve.pieceCount();
  const size_t perPiece = 2 * static_cast<size_t>(intervalsPerSpan);
  const size_t ends = pieces * static_cast<size_t>(intervalsPerSpan) + 1;
  speed_.resize(pieces * perPiece + 1);
  for (size_t piece = 0; piece < pieces; ++piece) {
    for (size_t q = 0; q < perPiece; ++q) {
      speed_[piece * perPiece + q] = curve.tangent(piece, static_cast<double>(q) / static_cast<double>(perPiece)).squaredNorm();
    }
  }
  speed_.back() = curve.tangent(pieces - 1, 1.0).squaredNorm();
  Eigen::Map<Eigen::ArrayXd> speed(speed_.data(), static_cast<Eigen::Index>(speed_.size()));
  speed = speed.sqrt();  // one packed pass
  parameter_.resize(ends);
  arc_.resize(ends);
  for (size_t piece = 0; piece < pieces; ++piece) {
    for (int m = 0; m < intervalsPerSpan; ++m) {
      parameter_[piece * static_cast<size_t>(intervalsPerSpan) + static_cast<size_t>(m)] =
          curve.pieceStart(piece) + curve.pieceWidth(piece) * m / intervalsPerSpan;
    }
  }
  parameter_.back() = curve.upper();
  arc_[0] = 0.0;
  for (size_t m = 1; m < ends; ++m) {
    const double* node = &speed_[2 * (m - 1)];
    arc_[m] = arc_[m - 1] + (parameter_[m] - parameter_[m - 1]) / 6.0 * (node[0] + 4.0 * node[1] + node[2]);
  }
  // Where the curve stops (zero speed), dt/ds is unbounded: fall back to the chord's slope.
  const double meanSpeed = arc_.back() / (parameter_.back() - parameter_.front());
  slope_.resize(ends);
  for (size_t m = 0; m < ends; ++m) {
    const size_t a = m == 0 ? 0 : m - 1;
    const size_t b = m + 1 == ends ? m : m + 1;
    const double chord = arc_[b] - arc_[a];
    const double fallback = chord > 0.0 ? (parameter_[b] - parameter_[a]) / chord : 0.0;
    const double nodeSpeed = speed_[2 * m];
    slope_[m] = nodeSpeed > 1e-9 * meanSpeed ? 1.0 / nodeSpeed : fallback;
  }
}

double ArcLength::interpolate(size_t m, double s) const {
  const double h = arc_[m + 1] - arc_[m];
  if (!(h > 0.0)) return parameter_[m];
  const double tau = (s - arc_[m]) / h;
  const double tau2 = tau * tau, tau3 = tau2 * tau;
  const double t = (2 * tau3 - 3 * tau2 + 1) * parameter_[m] + (tau3 - 2 * tau2 + tau) * h * slope_[m] +
                   (-2 * tau3 + 3 * tau2) * parameter_[m + 1] + (tau3 - tau2) * h * slope_[m + 1];
  return std::min(parameter_[m + 1], std::max(parameter_[m], t));
}

double ArcLength::parameterAt(double s) const {
  if (s <= 0.0) return parameter_.front();
  if (s >= arc_.back()) return parameter_.back();
  return interpolate(static_cast<size_t>(std::upper_bound(arc_.begin(), arc_.end(), s) - arc_.begin()) - 1, s);
}

void ArcLength::parametersAt(const std::vector<double>& s, int end, std::vector<double>& t) const {
  t.resize(s.size());
  const double length = arc_.back();
  size_t m = end == 0 ? 0 : arc_.size() - 2;
  for (size_t k = 0; k < s.size(); ++k) {
    const double along = end == 0 ? s[k] : length - s[k];
    if (along <= 0.0) {
      t[k] = parameter_.front();
    } else if (along >= length) {
      t[k] = parameter_.back();
    } else {
      while (m + 2 < arc_.size() && along >= arc_[m + 1]) ++m;
      while (m > 0 && along < arc_[m]) --m;
      t[k] = interpolate(m, along);
    }
  }
}

TurningTable::TurningTable(const BsplineCurve& curve, const ArcLength& arc, int samples) {
  const size_t steps = static_cast<size_t>(std::max(1, samples));
  arc_.resize(steps + 1);
  turning_.resize(steps + 1);
  std::vector<double> t;
  for (size_t k = 0; k <= steps; ++k) arc_[k] = arc.length() * static_cast<double>(k) / static_cast<double>(steps);
  arc.parametersAt(arc_, 0, t);
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (size_t k = 0; k <= steps; ++k) {
    Eigen::Vector3d tangent;
    curve.point(t[k], &tangent);
    // A point where the curve stops (zero tangent) turns nothing by itself; the next one counts.
    double turned = 0.0;
    if (k > 0 && previous.squaredNorm() > 0.0 && tangent.squaredNorm() > 0.0) {
      turned = std::atan2(previous.cross(tangent).norm(), previous.dot(tangent));
    }
    if (k > 0) turning_[k] = turning_[k - 1] + turned;
    if (tangent.squaredNorm() > 0.0) previous = tangent;
  }
}

double TurningTable::measureAt(double s, double spacing, double maxTurning) const {
  if (!(maxTurning > 0.0)) return s / spacing;
  return s / spacing + sampledAt(turning_, std::clamp(s / length(), 0.0, 1.0)) / maxTurning;
}

SharedMeasure::SharedMeasure(int samples, double spacing, double maxTurning)
    : spacing_(spacing), maxTurning_(maxTurning) {
  if (!uniformInArcLength()) sum_.assign(static_cast<size_t>(std::max(1, samples)) + 1, 0.0);
}

void SharedMeasure::add(const TurningTable& edge, bool reversed) {
  if (uniformInArcLength()) return;  // arc length's fractions need no table
  const double steps = static_cast<double>(sum_.size() - 1);
  const double total = edge.measure(spacing_, maxTurning_);
  for (size_t k = 0; k < sum_.size(); ++k) {
    const double sigma = static_cast<double>(k) / steps;
    sum_[k] += reversed ? total - edge.measureAt((1.0 - sigma) * edge.length(), spacing_, maxTurning_)
                        : edge.measureAt(sigma * edge.length(), spacing_, maxTurning_);
  }
}

double SharedMeasure::at(double sigma) const {
  const double x = std::clamp(sigma, 0.0, 1.0);
  if (uniformInArcLength() || !(sum_.back() > 0.0)) return x;
  return sampledAt(sum_, x) / sum_.back();
}

double SharedMeasure::sigmaAt(double measure) const {
  if (uniformInArcLength() || !(sum_.back() > 0.0)) return std::clamp(measure, 0.0, 1.0);
  const double target = measure * sum_.back();
  if (target <= 0.0) return 0.0;
  if (target >= sum_.back()) return 1.0;
  // The first sample at or above the target; sums never decrease.
  const size_t hi = static_cast<size_t>(std::lower_bound(sum_.begin(), sum_.end(), target) - sum_.begin());
  const size_t lo = hi - 1;
  const double steps = static_cast<double>(sum_.size() - 1);
  const double w = sum_[hi] > sum_[lo] ? (target - sum_[lo]) / (sum_[hi] - sum_[lo]) : 0.0;
  return (static_cast<double>(lo) + w) / steps;
}

std::vector<double> SharedMeasure::fractions(int points, double firstStep, double lastStep) const {
  const double uniform = 1.0 / (points - 1);
  // An end is clustered where its step is shorter than an equal one; the other may stay free.
  const auto clustered = [uniform](double step) { return step > 0.0 && step < uniform ? step : 0.0; };
  std::vector<double> sigma = vinokurFractions(points, clustered(firstStep), clustered(lastStep));
  for (double& x : sigma) x = sigmaAt(x);
  sigma.front() = 0.0;
  sigma.back() = 1.0;
  return sigma;
}

bool ChordPlacer::place(const PolynomialCurve& curve, ChordLaw& law, std::vector<double>& t,
                        std::vector<Eigen::Vector3d>& points) {
  const size_t n = t.size();
  if (n < 3) return true;
  // Along the line t increases (direction 1) or decreases (-1): tangents are taken in the
  // line's own sense, so every derivative below is positive on a line that does not fold.
  const double direction = t[n - 1] > t[0] ? 1.0 : -1.0;
  tangents_.resize(n);
  for (auto* v : {&residual_, &slope_, &alpha_, &beta_, &step_}) v->resize(n);
  double* const residual = residual_.data();
  double* const slope = slope_.data();
  double* const alpha = alpha_.data();
  double* const beta = beta_.data();
  double* const step = step_.data();
  Eigen::Vector3d* const tangent = tangents_.data();
  // The worst relative residual |r_k| / d_k of the chords c_k = x_k - x_{k-1} against the law's
  // distances d_k (r_k = |c_k| - d_k kept).
  auto residuals = [&] {
    double worst = 0.0, distance = law.height, perDistance = 1.0 / law.height;
    const double perGrowth = 1.0 / law.growth;
    for (size_t k = 1; k < n; ++k) {
      residual[k] = (points[k] - points[k - 1]).norm() - distance;
      worst = std::max(worst, std::abs(residual[k]) * perDistance);
      distance *= law.growth;
      perDistance *= perGrowth;
    }
    return worst;
  };
  // What the points' coordinates can resolve, relative to the first distance: far from the origin
  // (a model at 1e8, coordinates 1.5e-8 apart) Newton stalls above 1e-9 (the ends are fixed, so
  // their size bounds every point's).
  const double coordinateScale = std::max(points[0].cwiseAbs().maxCoeff(), points[n - 1].cwiseAbs().maxCoeff());
  const double resolvable = 64.0 * std::numeric_limits<double>::epsilon() * coordinateScale;
  double previous = std::numeric_limits<double>::infinity();
  for (int iteration = 0; iteration < 40; ++iteration) {
    // Once Newton is close (quadratic from 1e-6 on), the next points are most likely the last:
    // they are checked before their tangents are taken.
    bool withTangents = !(previous <= 1e-6);
    curve.evaluate(&t[1], n - 2, &points[1], withTangents ? &tangent[1] : nullptr);
    const double worst = residuals();
    // Done at 1e-11 (growth ratios then hold to 2e-11), or once Newton stops gaining within what
    // the coordinates resolve (first heights ~1e-10 of their distance from the origin).
    const double stalled = std::max(1e-9, resolvable / law.height);
    if (worst <= 1e-11 || (worst <= stalled && worst > 0.25 * previous)) return true;
    previous = worst;
    if (!withTangents) curve.evaluate(&t[1], n - 2, &points[1], &tangent[1]);
    if (direction < 0.0) {
      for (size_t k = 1; k + 1 < n; ++k) tangent[k] = -tangent[k];
    }
    // Newton's step on the residuals: their derivatives in the law's free parameter are d_k / h,
    // or (k - 1) d_k / g; in t the Jacobian is lower bidiagonal (a_k = c_k . x'_k / |c_k| and
    // b_k = c_k . x'_{k-1} / |c_k|, the derivatives of |c_k| in t_k and -t_{k-1}), so
    // dt_k = alpha_k + beta_k dtheta forward, then the last chord (both its ends fixed) gives
    // dtheta.
    double distance = law.height;
    const double perHeight = 1.0 / law.height, perGrowth = 1.0 / law.growth;
    alpha[0] = beta[0] = 0.0;
    double lastB = 0.0;
    for (size_t k = 1; k < n; ++k) {
      const Eigen::Vector3d chord = points[k] - points[k - 1];
      const double length = residual[k] + distance;
      slope[k] = law.heightFixed ? static_cast<double>(k - 1) * distance * perGrowth : distance * perHeight;
      const double previousDot = k > 1 ? chord.dot(tangent[k - 1]) : 0.0;  // b_k |c_k|
      if (k + 1 < n) {
        const double dot = chord.dot(tangent[k]);  // a_k |c_k|
        if (!(dot > 0.0)) return false;
        const double perDot = 1.0 / dot;
        alpha[k] = (previousDot * alpha[k - 1] - residual[k] * length) * perDot;
        beta[k] = (previousDot * beta[k - 1] + slope[k] * length) * perDot;
      } else {
        lastB = previousDot / length;
      }
      distance *= law.growth;
    }
    const double denominator = lastB * beta[n - 2] + slope[n - 1];
    if (!(denominator > 0.0)) return false;
    const double change = (residual[n - 1] - lastB * alpha[n - 2]) / denominator;
    // Damped so that the points stay in order and the law's parameter positive.
    double fraction = 1.0;
    for (int halving = 0;; ++halving) {
      if (halving == 30) return false;
      const double theta = (law.heightFixed ? law.growth : law.height) + fraction * change;
      bool ordered = theta > 0.0;
      for (size_t k = 1; ordered && k + 1 < n; ++k) {
        step[k] = t[k] + direction * fraction * (alpha[k] + beta[k] * change);
        ordered = direction * (step[k] - (k == 1 ? t[0] : step[k - 1])) > 0.0 && direction * (t[n - 1] - step[k]) > 0.0;
      }
      if (ordered) {
        (law.heightFixed ? law.growth : law.height) = theta;
        for (size_t k = 1; k + 1 < n; ++k) t[k] = step[k];
        break;
      }
      fraction *= 0.5;
    }
  }
  return false;
}

double parameterAtDistance(const BsplineCurve& curve, double t0, int direction, double distance, double guess) {
  const Eigen::Vector3d origin = curve.point(t0);
  double lo = std::min(t0, direction > 0 ? curve.upper() : curve.lower());
  double hi = std::max(t0, direction > 0 ? curve.upper() : curve.lower());
  double t = std::min(hi, std::max(lo, guess));
  // g(t) = |C(t) - C(t0)| - distance grows away from t0; keep [lo, hi] bracketing its root.
  for (int iteration = 0; iteration < 60; ++iteration) {
    Eigen::Vector3d tangent;
    const Eigen::Vector3d offset = curve.point(t, &tangent) - origin;
    const double r = offset.norm();
    const double g = r - distance;
    if (std::abs(g) <= 1e-14 * distance) break;
    const bool past = g > 0.0;
    if ((direction > 0) == past) hi = t;
    else lo = t;
    const double slope = r > 0.0 ? offset.dot(tangent) / r : 0.0;
    double next = slope != 0.0 ? t - g / slope : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (next == t) break;
    t = next;
  }
  return t;
}

}  // namespace bvmesh::grid

#include "core/grid/distribution.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"

namespace bvmesh::grid {
namespace {

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

// Vinokur's formula as published.
std::vector<double> vinokurFormula(int points, double firstSpacing, double lastSpacing) {
  const int intervals = points - 1;
  std::vector<double> x(static_cast<size_t>(points));
  const bool atStart = firstSpacing > 0.0;
  const bool atEnd = lastSpacing > 0.0;
  for (int i = 0; i <= intervals; ++i) {
    const double xi = static_cast<double>(i) / intervals;
    double value = xi;
    if (atStart && atEnd) {
      const double a = std::sqrt(lastSpacing / firstSpacing);
      const double b = 1.0 / (intervals * std::sqrt(firstSpacing * lastSpacing));
      if (b != 1.0) {
        const double d = stretchingParameter(b);
        const double u = b > 1.0 ? 0.5 * (1.0 + std::tanh(d * (xi - 0.5)) / std::tanh(0.5 * d))
                                 : 0.5 * (1.0 + std::tan(d * (xi - 0.5)) / std::tan(0.5 * d));
        value = u / (a + (1.0 - a) * u);
      }
    } else if (atStart || atEnd) {
      const double spacing = atStart ? firstSpacing : lastSpacing;
      const double eta = atStart ? xi : 1.0 - xi;
      const double b = 1.0 / (intervals * spacing);
      double clustered = eta;
      if (b != 1.0) {
        const double d = stretchingParameter(b);
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
    throw InvalidInputError("end spacings " + std::to_string(firstSpacing) + ", " + std::to_string(lastSpacing) +
                            " are not fractions in [0, 1) of the line's length");
  }
  // The formula meets the end spacings to first order only: rescale its inputs until the
  // spacings it gives are the ones asked (a few fixed-point steps).
  double first = firstSpacing, last = lastSpacing;
  std::vector<double> x = vinokurFormula(points, first, last);
  for (int iteration = 0; iteration < 50; ++iteration) {
    const double gotFirst = x[1], gotLast = 1.0 - x[x.size() - 2];
    if (std::abs(gotFirst - firstSpacing) <= 1e-10 * firstSpacing && std::abs(gotLast - lastSpacing) <= 1e-10 * lastSpacing) break;
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
    throw InvalidInputError("a first spacing of " + std::to_string(firstSpacing) + " of the line's length with " +
                            std::to_string(points) + " points cannot cluster at the wall (it must be below 1/" +
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
                            std::to_string(firstSpacing) + " and " + std::to_string(length) + ")");
  }
  if (firstSpacing * intervals >= length) {
    throw InvalidInputError("a first spacing of " + std::to_string(firstSpacing) + " times " +
                            std::to_string(intervals) + " intervals already exceeds the line's length " +
                            std::to_string(length) + ": use fewer points or a smaller first spacing");
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
                            std::to_string(yPlus) + ", " + std::to_string(reynoldsNumber) + ", " +
                            std::to_string(referenceLength) + ")");
  }
  const double skinFriction = 0.026 * std::pow(reynoldsNumber, -1.0 / 7.0);
  return yPlus * referenceLength / (reynoldsNumber * std::sqrt(0.5 * skinFriction));
}

double flatPlateYPlus(double firstCellHeight, double reynoldsNumber, double referenceLength) {
  return firstCellHeight / flatPlateFirstCellHeight(1.0, reynoldsNumber, referenceLength);
}

CurveSamples::CurveSamples(const std::vector<double>& knots, int degree, int intervalsPerSpan) : order_(degree + 1) {
  for (size_t k = 0; k + 1 < knots.size(); ++k) {
    const double a = knots[k], b = knots[k + 1];
    if (!(b > a)) continue;
    for (int m = 0; m < intervalsPerSpan; ++m) parameters_.push_back(a + (b - a) * m / intervalsPerSpan);
  }
  parameters_.push_back(knots.back());
  ends_ = parameters_.size();
  for (size_t m = 1; m < ends_; ++m) parameters_.push_back(0.5 * (parameters_[m - 1] + parameters_[m]));
  first_.resize(parameters_.size());
  values_.resize(parameters_.size() * static_cast<size_t>(order_));
  derivatives_.resize(values_.size());
  for (size_t m = 0; m < parameters_.size(); ++m) {
    const int span = findKnotSpan(knots, degree, parameters_[m]);
    first_[m] = span - degree;
    basisFunctions(knots, degree, span, parameters_[m], &values_[m * static_cast<size_t>(order_)],
                   &derivatives_[m * static_cast<size_t>(order_)]);
  }
}

ArcLength::ArcLength(const BsplineCurve& curve, int intervalsPerSpan)
    : ArcLength(curve, CurveSamples(curve.knots, curve.degree, intervalsPerSpan)) {}

void ArcLength::tabulate(const BsplineCurve& curve, const CurveSamples& samples) {
  const size_t ends = samples.ends_;
  const size_t order = static_cast<size_t>(samples.order_);
  // Every wall-normal grid line tabulates its arc length: tight loops over raw rows, the square
  // roots taken as one array (packed instructions).
  speed_.resize(samples.parameters_.size());
  const double* poles = curve.poles.data();
  for (size_t m = 0; m < speed_.size(); ++m) {
    const double* derivative = &samples.derivatives_[m * order];
    const double* pole = poles + 3 * samples.first_[m];
    double x = 0.0, y = 0.0, z = 0.0;
    for (size_t r = 0; r < order; ++r, pole += 3) {
      x += derivative[r] * pole[0];
      y += derivative[r] * pole[1];
      z += derivative[r] * pole[2];
    }
    speed_[m] = x * x + y * y + z * z;
  }
  Eigen::Map<Eigen::ArrayXd> speed(speed_.data(), static_cast<Eigen::Index>(speed_.size()));
  speed = speed.sqrt();
  parameter_.assign(samples.parameters_.begin(), samples.parameters_.begin() + static_cast<std::ptrdiff_t>(ends));
  arc_.assign(ends, 0.0);
  for (size_t m = 1; m < ends; ++m) {
    arc_[m] = arc_[m - 1] + (parameter_[m] - parameter_[m - 1]) / 6.0 * (speed_[m - 1] + 4.0 * speed_[ends + m - 1] + speed_[m]);
  }
  // Where the curve stops (zero speed), dt/ds is unbounded: fall back to the chord's slope.
  const double meanSpeed = arc_.back() / (parameter_.back() - parameter_.front());
  slope_.resize(ends);
  for (size_t m = 0; m < ends; ++m) {
    const size_t a = m == 0 ? 0 : m - 1;
    const size_t b = m + 1 == ends ? m : m + 1;
    const double chord = arc_[b] - arc_[a];
    const double fallback = chord > 0.0 ? (parameter_[b] - parameter_[a]) / chord : 0.0;
    slope_[m] = speed_[m] > 1e-9 * meanSpeed ? 1.0 / speed_[m] : fallback;
  }
}

double ArcLength::parameterAt(double s) const {
  if (s <= 0.0) return parameter_.front();
  if (s >= arc_.back()) return parameter_.back();
  const size_t m = static_cast<size_t>(std::upper_bound(arc_.begin(), arc_.end(), s) - arc_.begin()) - 1;
  const double h = arc_[m + 1] - arc_[m];
  if (!(h > 0.0)) return parameter_[m];
  const double tau = (s - arc_[m]) / h;
  const double tau2 = tau * tau, tau3 = tau2 * tau;
  const double t = (2 * tau3 - 3 * tau2 + 1) * parameter_[m] + (tau3 - 2 * tau2 + tau) * h * slope_[m] +
                   (-2 * tau3 + 3 * tau2) * parameter_[m + 1] + (tau3 - tau2) * h * slope_[m + 1];
  return std::min(parameter_[m + 1], std::max(parameter_[m], t));
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

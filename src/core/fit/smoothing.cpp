#include "core/fit/smoothing.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/common/errors.h"
#include "core/common/number_text.h"

namespace bvmesh::fit {
namespace {

void umbrellaStep(const RowMatrixX3d& from, RowMatrixX3d& to, const std::vector<std::vector<int>>& neighbours,
                  double factor) {
  for (Eigen::Index point = 0; point < from.rows(); ++point) {
    const std::vector<int>& ring = neighbours[static_cast<size_t>(point)];
    if (ring.empty()) {
      to.row(point) = from.row(point);
      continue;
    }
    Eigen::RowVector3d average = Eigen::RowVector3d::Zero();
    for (int neighbour : ring) average += from.row(neighbour);
    average /= static_cast<double>(ring.size());
    to.row(point) = from.row(point) + factor * (average - from.row(point));
  }
}

// The pair of steps scales a mode of the umbrella operator with eigenvalue -k (k in [0, 2]) by
// (1 - lambda k)(1 - mu k): the largest magnitude over k, at an end or at the parabola's vertex.
double largestPairGain(double lambda, double mu) {
  const auto gain = [&](double k) { return std::abs((1.0 - lambda * k) * (1.0 - mu * k)); };
  double largest = std::max(gain(0.0), gain(2.0));
  if (lambda * mu != 0.0) {
    const double vertex = (lambda + mu) / (2.0 * lambda * mu);
    if (vertex > 0.0 && vertex < 2.0) largest = std::max(largest, gain(vertex));
  }
  return largest;
}

}  // namespace

RowMatrixX3d taubinSmooth(const RowMatrixX3d& points, const std::vector<std::vector<int>>& neighbours,
                         const TaubinOptions& options) {
  if (static_cast<Eigen::Index>(neighbours.size()) != points.rows()) {
    throw InvalidInputError("got neighbour lists for " + std::to_string(neighbours.size()) + " points, expected " +
                            std::to_string(points.rows()));
  }
  if (!std::isfinite(options.lambda) || !std::isfinite(options.mu)) {
    throw InvalidInputError("Taubin smoothing needs finite lambda and mu");
  }
  const double gain = largestPairGain(options.lambda, options.mu);
  if (gain > kMaxTaubinPairGain) {
    throw InvalidInputError("Taubin smoothing with lambda " + numberText(options.lambda) + " and mu " +
                            numberText(options.mu) + " amplifies some wavelength " + numberText(gain) +
                            " times per iteration (the points would run away): take 0 < lambda < 1 and "
                            "-1 < mu < -lambda, such as 0.6307 and -0.6732");
  }
  // A count past the bound is a typo that would hold the caller (a workbench's main thread) for days.
  if (options.iterations < 0 || options.iterations > kMaxTaubinIterations) {
    throw InvalidInputError("Taubin smoothing iterations must be 0 .. " +
                            std::to_string(kMaxTaubinIterations) + ", got " +
                            std::to_string(options.iterations));
  }
  for (size_t point = 0; point < neighbours.size(); ++point) {
    for (int neighbour : neighbours[point]) {
      if (neighbour < 0 || neighbour >= points.rows()) {
        throw InvalidInputError("neighbour " + std::to_string(neighbour) + " of point " + std::to_string(point) +
                                " is out of range");
      }
    }
  }
  RowMatrixX3d current = points;
  RowMatrixX3d next(points.rows(), 3);
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    umbrellaStep(current, next, neighbours, options.lambda);
    umbrellaStep(next, current, neighbours, options.mu);
  }
  return current;
}

}  // namespace bvmesh::fit

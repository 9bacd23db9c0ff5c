// Point distributions along grid lines: stretching laws in arc length (geometric growth from a
// first cell height, Vinokur's tanh clustering at one or both ends), the flat-plate estimate of
// the first cell height for a y+ target, and the inversion of a curve's arc length.
#pragma once

#include <vector>

#include "core/common/bspline_curve.h"

namespace bvmesh::grid {

// Fractions 0 = x_0 < ... < x_{n-1} = 1 of Vinokur's two-sided tanh stretching (J. Comput. Phys.
// 50, 1983) with end spacings firstSpacing and lastSpacing as fractions of the length; both 0:
// uniform; one 0: one-sided. The end spacings are met to 1e-10 relative.
std::vector<double> vinokurFractions(int points, double firstSpacing, double lastSpacing);

// One-sided tanh stretching whose first spacing is exactly firstSpacing (fraction of the length).
std::vector<double> tanhWallFractions(int points, double firstSpacing);

// The growth ratio r of a geometric law with `points` points, first spacing h and total length L:
// h (r^(n-1) - 1) / (r - 1) = L. Throws InvalidInputError when h (n - 1) >= L (no r > 1).
double geometricGrowth(int points, double firstSpacing, double length);

// Distances from the start of a geometric law, 0 ... length.
std::vector<double> geometricDistances(int points, double firstSpacing, double growth, double length);

// Smallest point count whose geometric law from firstSpacing reaches `length` with growth <= maxGrowth.
int geometricPointsNeeded(double firstSpacing, double maxGrowth, double length);

// First cell height for a y+ target on a turbulent flat plate of length L at Reynolds number Re:
// Cf = 0.026 Re^(-1/7) (White), u_tau = U sqrt(Cf / 2), y = y+ nu / u_tau = y+ L / (Re sqrt(Cf / 2)).
double flatPlateFirstCellHeight(double yPlus, double reynoldsNumber, double referenceLength);
// The y+ of a first cell height under the same estimate (its inverse).
double flatPlateYPlus(double firstCellHeight, double reynoldsNumber, double referenceLength);

// Sample parameters of curves on one knot vector (`intervalsPerSpan` equal intervals in each
// knot span, and their midpoints), with the basis functions there computed once: every
// wall-normal line of a block shares them, so tabulating a line's arc length costs a few pole
// sums per sample.
class CurveSamples {
 public:
  CurveSamples(const std::vector<double>& knots, int degree, int intervalsPerSpan);
  size_t count() const { return parameters_.size(); }  // interval ends, then the midpoints

 private:
  friend class ArcLength;
  int order_;
  size_t ends_ = 0;  // parameters_[0 .. ends_) are interval ends, the rest midpoints
  std::vector<double> parameters_;
  std::vector<int> first_;                    // first pole of each sample's basis
  std::vector<double> values_, derivatives_;  // order_ per sample
};

// A curve's arc length s(t) tabulated by Simpson's rule on the samples' intervals (polynomial
// pieces, so it keeps its order; dense knots near a wall get dense samples) and inverted by cubic
// Hermite interpolation of t(s) (dt/ds = 1 / |C'(t)|).
class ArcLength {
 public:
  ArcLength() = default;  // no table until tabulate()
  ArcLength(const BsplineCurve& curve, const CurveSamples& samples) { tabulate(curve, samples); }
  ArcLength(const BsplineCurve& curve, int intervalsPerSpan);
  // Tabulates `curve` afresh in the storage of the last table (one ArcLength serves a thread's
  // wall-normal lines one after the other without allocating).
  void tabulate(const BsplineCurve& curve, const CurveSamples& samples);
  double length() const { return arc_.back(); }
  // The parameter at arc length s (0 <= s <= length()) from the curve's start.
  double parameterAt(double s) const;

 private:
  std::vector<double> parameter_, arc_, slope_;  // t_m, s(t_m), dt/ds at t_m
  std::vector<double> speed_;                    // |C'| at the samples (kept for its storage)
};

// The parameter t (from t0 towards the curve's other end, in `direction` +1 or -1) whose point is
// at straight distance `distance` from C(t0), by safeguarded Newton from `guess`.
double parameterAtDistance(const BsplineCurve& curve, double t0, int direction, double distance, double guess);

}  // namespace bvmesh::grid

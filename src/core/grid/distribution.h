// Point distributions along grid lines: stretching laws in arc length (geometric growth from a
// first cell height, Vinokur's tanh clustering at one or both ends), the flat-plate estimate of
// the first cell height for a y+ target, and the inversion of a curve's arc length.
#pragma once

#include <algorithm>
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

// The pieces of the B-spline basis on one knot vector: per non-empty knot span, the polynomial
// of each basis function that is non-zero there, in the span's own parameter
// tau = (t - t_s) / (t_{s+1} - t_s) in [0, 1]. Computed once per block direction, they turn the
// poles of any curve on that knot vector into polynomial pieces (PolynomialCurve).
class SpanPolynomials {
 public:
  SpanPolynomials(const std::vector<double>& knots, int degree);
  size_t pieceCount() const { return start_.size(); }

 private:
  friend class PolynomialCurve;
  int order_;
  std::vector<double> start_, width_, perWidth_;  // per piece: t_s, t_{s+1} - t_s, its inverse
  std::vector<int> firstPole_;         // per piece: s - degree
  std::vector<double> basis_;          // per piece order x order: [m][r] the tau^m coefficient of basis r
  double upper_ = 0.0;                 // the last knot
};

// A curve as polynomial pieces: a point and its tangent at any parameter cost one Horner sum
// instead of basis functions, so a wall-normal line can be evaluated a few times over while its
// points are placed (and its arc length tabulated) at little cost.
class PolynomialCurve {
 public:
  // The curve with these poles on `spans`' knot vector; the storage of the last call is reused
  // (one PolynomialCurve serves a thread's wall-normal lines). `spans` must outlive the curve.
  void assign(const RowMatrixX3d& poles, const SpanPolynomials& spans);
  size_t pieceCount() const { return spans_->pieceCount(); }
  double lower() const { return spans_->start_.front(); }
  double upper() const { return spans_->upper_; }
  double pieceStart(size_t piece) const { return spans_->start_[piece]; }
  double pieceWidth(size_t piece) const { return spans_->width_[piece]; }
  // The piece that holds t, starting the search from `hint` (increasing parameters walk forward).
  size_t pieceOf(double t, size_t hint) const {
    const std::vector<double>& start = spans_->start_;
    size_t piece = std::min(hint, start.size() - 1);
    while (piece > 0 && t < start[piece]) --piece;
    while (piece + 1 < start.size() && t >= start[piece + 1]) ++piece;
    return piece;
  }
  // The point at tau in `piece` and, unless null, dC/dt there (a Horner sum).
  Eigen::Vector3d point(size_t piece, double tau, Eigen::Vector3d* tangent = nullptr) const;
  // dC/dt alone at tau in `piece`.
  Eigen::Vector3d tangent(size_t piece, double tau) const;
  // The point at t (clamped into the curve's range); `piece` is a hint and is updated.
  Eigen::Vector3d pointAt(double t, size_t& piece, Eigen::Vector3d* tangent = nullptr) const {
    const double x = std::min(upper(), std::max(lower(), t));
    piece = pieceOf(x, piece);
    return point(piece, (x - spans_->start_[piece]) * spans_->perWidth_[piece], tangent);
  }
  // The points (and, unless `tangents` is null, dC/dt) at the `count` parameters t, which run
  // along the curve (increasing or decreasing): one walk through the pieces, Horner inlined.
  void evaluate(const double* t, size_t count, Eigen::Vector3d* points, Eigen::Vector3d* tangents) const;

 private:
  const SpanPolynomials* spans_ = nullptr;
  std::vector<double> coefficients_;  // per piece order x 3: the tau^m coefficient of x, y, z
};

// A curve's arc length s(t) tabulated by Simpson's rule on `intervalsPerSpan` intervals of each
// knot span (polynomial pieces, so it keeps its order; dense knots near a wall get dense
// samples) and inverted by cubic Hermite interpolation of t(s) (dt/ds = 1 / |C'(t)|).
class ArcLength {
 public:
  ArcLength() = default;  // no table until tabulate()
  ArcLength(const BsplineCurve& curve, int intervalsPerSpan);
  // Tabulates `curve` afresh in the storage of the last table (one ArcLength serves a thread's
  // wall-normal lines one after the other without allocating).
  void tabulate(const PolynomialCurve& curve, int intervalsPerSpan);
  double length() const { return arc_.back(); }
  // The parameter at arc length s (0 <= s <= length()) from the curve's start.
  double parameterAt(double s) const;
  // The parameters at the increasing arc lengths s, from the curve's end `end` (0: its start,
  // 1: its end, s measured backwards), into t in the same order (one walk through the table).
  void parametersAt(const std::vector<double>& s, int end, std::vector<double>& t) const;

 private:
  double interpolate(size_t m, double s) const;  // Hermite on [arc_[m], arc_[m + 1]]
  std::vector<double> parameter_, arc_, slope_;  // t_m, s(t_m), dt/ds at t_m
  std::vector<double> speed_;                    // |C'| at every Simpson node (kept for its storage)
};

// A curve's arc length s and the cumulative turning theta of its tangent (radians), tabulated at
// equal steps of arc length, and the measure s / spacing + theta / maxTurning: points at equal
// steps of it keep every cell within the spacing and within the turning limit (to the table's
// resolution), so they gather where the curve bends (a wing's nose, a fillet, a rounded tip).
class TurningTable {
 public:
  // `samples` steps of arc length (>= 1) along `curve`, whose table `arc` is.
  TurningTable(const BsplineCurve& curve, const ArcLength& arc, int samples);
  double length() const { return arc_.back(); }
  double turning() const { return turning_.back(); }
  // The measure from the start to arc length s (linear between samples; maxTurning 0: s / spacing).
  double measureAt(double s, double spacing, double maxTurning) const;
  double measure(double spacing, double maxTurning) const { return measureAt(length(), spacing, maxTurning); }

 private:
  std::vector<double> arc_, turning_;
};

// The distribution that linked grid edges share: the sum of their measures as functions of the
// fraction sigma of their arc length (each taken in the shared sense), normalised to 1. Edges that
// face each other across a block then place their points at the same fractions of their length,
// as they do when uniform in arc length; one edge's own measure would shear a thin block whose
// opposite edge bends elsewhere. Edges with more to resolve weigh more.
class SharedMeasure {
 public:
  // The measures of the set's spacing and turning limit, tabulated at `samples` fractions.
  SharedMeasure(int samples, double spacing, double maxTurning);
  // Adds an edge's measure (reversed: the edge runs against the shared sense).
  void add(const TurningTable& edge, bool reversed);
  // Without a turning limit every measure is arc length: the shared fractions are those of arc
  // length itself, exactly (at and the fractions' inverse are the identity, no table, no
  // rounding).
  bool uniformInArcLength() const { return !(maxTurning_ > 0.0); }
  // The normalised measure at fraction sigma of arc length (in the shared sense).
  double at(double sigma) const;
  // Fractions 0 = sigma_0 < ... < sigma_{n-1} = 1 of `points` points at equal steps of the
  // normalised measure, or stretched by Vinokur's law so that the first and last steps are
  // firstStep and lastStep of it: each end whose step is > 0 and shorter than an equal step (one
  // such end alone: the one-sided law, the other end free).
  std::vector<double> fractions(int points, double firstStep, double lastStep) const;

 private:
  double sigmaAt(double measure) const;  // the inverse of at()
  double spacing_, maxTurning_;
  std::vector<double> sum_;  // at sigma = k / (samples); empty when uniform in arc length
};

// A geometric law in straight distances between consecutive points of a line:
// |x_k - x_{k-1}| = height growth^(k-1), k = 1 .. n - 1. With `heightFixed` the growth is what
// the line's ends leave free, else the height is.
struct ChordLaw {
  double height = 0.0;
  double growth = 1.0;
  bool heightFixed = true;
};

// Places points on a curve so that their straight distances follow a ChordLaw (the law in arc
// length lets the measured ratio of consecutive spacings exceed the growth asked where a line
// bends). One placer serves a thread's lines one after the other, reusing its storage.
class ChordPlacer {
 public:
  // n = t.size() points: t[0] and t[n - 1] (the line's ends, points[0] and points[n - 1] given)
  // stay, t[1 .. n - 2] start in order between them (the law placed in arc length) and move by
  // Newton's method on all of them and the law's free parameter at once, until every distance
  // is the law's to 1e-11 relative or to rounding; they fill points[1 .. n - 2]. Returns false
  // if Newton fails (a line that folds back on itself).
  bool place(const PolynomialCurve& curve, ChordLaw& law, std::vector<double>& t, std::vector<Eigen::Vector3d>& points);

 private:
  std::vector<Eigen::Vector3d> tangents_;
  std::vector<double> residual_, slope_, alpha_, beta_, step_;
};

// The parameter t (from t0 towards the curve's other end, in `direction` +1 or -1) whose point is
// at straight distance `distance` from C(t0), by safeguarded Newton from `guess`.
double parameterAtDistance(const BsplineCurve& curve, double t0, int direction, double distance, double guess);

}  // namespace bvmesh::grid

#include "core/surface/limit_bsplines.h"

#include <BRepBuilderAPI_MakeSolid.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepGProp.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <GProp_GProps.hxx>
#include <Geom_BSplineSurface.hxx>
#include <ShapeFix_Solid.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>
#include <TopoDS_Vertex.hxx>
#include <gp_Pnt.hxx>
#include <gp_Vec.hxx>

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <string>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"
#include "core/common/occt_errors.h"
#include "core/surface/chart_continuity.h"

namespace bvmesh::surface {
namespace {

using Eigen::Vector3d;
using SparseMatrix = Eigen::SparseMatrix<double>;

// Weight of the tangent-plane condition at the border samples against the fit to limit samples
// (both lengths): large, so that the rows next to the borders turn into the shared planes and only
// their moves within those planes are left to the fit. 100 keeps the M6's normal jumps below 0.1
// degree; 1000 folded its smallest charts.
constexpr double tangentPlaneWeight = 100.0;

// The clamped cubic B-spline basis with integer knots 0, 1, ..., K (knots 0 and K of
// multiplicity 4): the four functions that are non-zero at x, starting at pole `first`.
struct CubicBasis {
  int first = 0;
  double w[4] = {0, 0, 0, 0};
};

std::vector<double> clampedKnots(int spans) {
  std::vector<double> knots{0, 0, 0};
  for (int k = 0; k <= spans; ++k) knots.push_back(k);
  knots.insert(knots.end(), 3, spans);
  return knots;
}

CubicBasis cubicBasis(const std::vector<double>& knots, int spans, double x) {
  const int span = std::clamp(static_cast<int>(std::floor(x)), 0, spans - 1) + 3;
  CubicBasis basis;
  basis.first = span - 3;
  double left[4];
  double right[4];
  basis.w[0] = 1.0;
  for (int j = 1; j <= 3; ++j) {
    left[j] = x - knots[static_cast<size_t>(span + 1 - j)];
    right[j] = knots[static_cast<size_t>(span + j)] - x;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double temp = basis.w[r] / (right[r + 1] + left[j - r]);
      basis.w[r] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    basis.w[j] = saved;
  }
  return basis;
}

// Sample parameters: `perSpan` points inside each of `spans` unit spans, away from the knots.
std::vector<double> fitParameters(int spans, int perSpan) {
  std::vector<double> x;
  for (int i = 0; i < spans; ++i) {
    for (int q = 0; q < perSpan; ++q) x.push_back(i + (q + 0.5) / perSpan);
  }
  return x;
}

// Check parameters: `perSpan` points per span including both ends.
std::vector<double> checkParameters(int spans, int perSpan) {
  std::vector<double> x;
  for (int i = 0; i < spans; ++i) {
    for (int q = (i == 0 ? 0 : 1); q < perSpan; ++q) x.push_back(i + static_cast<double>(q) / (perSpan - 1));
  }
  return x;
}

// Least squares in one direction with `fixedPerEnd` poles given at either end (the border pole,
// or the border pole and the one next to it): for samples R (rows at fitParameters) returns the
// free poles X minimising |A_free X - R|. The normal equations are banded and well conditioned;
// one refinement step brings the residual to rounding level.
class EndConstrainedFit {
 public:
  EndConstrainedFit(int spans, int perSpan, int fixedPerEnd) : fixedPerEnd_(fixedPerEnd) {
    const std::vector<double> knots = clampedKnots(spans);
    const std::vector<double> x = fitParameters(spans, perSpan);
    full_.resize(static_cast<Eigen::Index>(x.size()), spans + 3);
    std::vector<Eigen::Triplet<double>> entries;
    for (size_t r = 0; r < x.size(); ++r) {
      const CubicBasis b = cubicBasis(knots, spans, x[r]);
      for (int k = 0; k < 4; ++k) entries.emplace_back(static_cast<int>(r), b.first + k, b.w[k]);
    }
    full_.setFromTriplets(entries.begin(), entries.end());
    free_ = full_.middleCols(fixedPerEnd, freeCount());
    freeT_ = free_.transpose();
    if (freeCount() == 0) return;
    solver_.compute(freeT_ * free_);
    if (solver_.info() != Eigen::Success) {
      throw SolverError("the B-spline fit with " + std::to_string(spans) + " spans is singular");
    }
  }
  const SparseMatrix& full() const { return full_; }
  int fixedPerEnd() const { return fixedPerEnd_; }
  int freeCount() const { return static_cast<int>(full_.cols()) - 2 * fixedPerEnd_; }
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const {
    if (freeCount() == 0) return Eigen::MatrixXd(0, rhs.cols());
    Eigen::MatrixXd x = solver_.solve(freeT_ * rhs);
    const Eigen::MatrixXd residual = rhs - free_ * x;
    x += solver_.solve(freeT_ * residual);
    return x;
  }

 private:
  int fixedPerEnd_;
  SparseMatrix full_;
  SparseMatrix free_;
  SparseMatrix freeT_;
  Eigen::SimplicialLDLT<SparseMatrix> solver_;
};

// Least squares for the free poles of a curve with basis matrix `basis` (samples x poles), the
// others fixed at their values in `poles` (#poles x 3); refined once like EndConstrainedFit.
void solveFreePoles(const SparseMatrix& basis, const std::vector<bool>& fixed, Eigen::MatrixXd& poles,
                    const Eigen::MatrixXd& samples) {
  std::vector<int> column(fixed.size(), -1);
  int freeCount = 0;
  for (size_t c = 0; c < fixed.size(); ++c) {
    if (!fixed[c]) column[c] = freeCount++;
  }
  if (freeCount == 0) return;
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::MatrixXd rhs = samples;
  for (int c = 0; c < basis.outerSize(); ++c) {
    for (SparseMatrix::InnerIterator it(basis, c); it; ++it) {
      if (fixed[static_cast<size_t>(c)]) {
        rhs.row(it.row()) -= it.value() * poles.row(c);
      } else {
        entries.emplace_back(static_cast<int>(it.row()), column[static_cast<size_t>(c)], it.value());
      }
    }
  }
  SparseMatrix a(basis.rows(), freeCount);
  a.setFromTriplets(entries.begin(), entries.end());
  const SparseMatrix at = a.transpose();
  Eigen::SimplicialLDLT<SparseMatrix> solver(at * a);
  if (solver.info() != Eigen::Success) throw SolverError("a constrained border-curve fit is singular");
  Eigen::MatrixXd x = solver.solve(at * rhs);
  x += solver.solve(at * (rhs - a * x));
  for (size_t c = 0; c < fixed.size(); ++c) {
    if (!fixed[c]) poles.row(static_cast<Eigen::Index>(c)) = x.row(column[c]);
  }
}

class FitCache {
 public:
  explicit FitCache(int perSpan) : perSpan_(perSpan) {}
  const EndConstrainedFit& get(int spans, int fixedPerEnd = 1) {
    auto it = fits_.find({spans, fixedPerEnd});
    if (it == fits_.end()) {
      it = fits_.emplace(std::make_pair(spans, fixedPerEnd),
                         std::make_unique<EndConstrainedFit>(spans, perSpan_, fixedPerEnd)).first;
    }
    return *it->second;
  }

 private:
  int perSpan_;
  std::map<std::pair<int, int>, std::unique_ptr<EndConstrainedFit>> fits_;
};

// Poles of the piece [a, b] (integers) of a clamped cubic on [0, spans] with integer knots: the
// same curve, clamped at a and b, with the knots in between unchanged.
std::vector<Vector3d> restrictCurve(const std::vector<Vector3d>& poles, int spans, int a, int b) {
  std::vector<double> knots = clampedKnots(spans);
  Eigen::MatrixXd rows(static_cast<Eigen::Index>(poles.size()), 3);
  for (size_t i = 0; i < poles.size(); ++i) rows.row(static_cast<Eigen::Index>(i)) = poles[i].transpose();
  restrictToInterval(knots, 3, rows, a, b);
  std::vector<Vector3d> piece(static_cast<size_t>(rows.rows()));
  for (Eigen::Index i = 0; i < rows.rows(); ++i) piece[static_cast<size_t>(i)] = rows.row(i).transpose();
  return piece;
}

// Mesh face location of chart parameters (s, t) in [0, m] x [0, n].
SurfaceLocation chartLocation(const QuadChart& chart, double s, double t) {
  const int i = std::clamp(static_cast<int>(std::floor(s)), 0, chart.uCells - 1);
  const int j = std::clamp(static_cast<int>(std::floor(t)), 0, chart.vCells - 1);
  const double a = std::clamp(s - i, 0.0, 1.0);
  const double b = std::clamp(t - j, 0.0, 1.0);
  const int face = chart.face(i, j);
  switch (chart.rotation(i, j)) {
    case 1:
      return {face, 1.0 - b, a};
    case 2:
      return {face, 1.0 - a, 1.0 - b};
    case 3:
      return {face, b, 1.0 - a};
    default:
      return {face, a, b};
  }
}

// Chart parameters of a position along one of its sides.
std::pair<double, double> sideParameters(const QuadChart& chart, ChartSide side, double position) {
  switch (side) {
    case ChartSide::VMin:
      return {position, 0.0};
    case ChartSide::UMax:
      return {chart.uCells, position};
    case ChartSide::VMax:
      return {position, chart.vCells};
    case ChartSide::UMin:
      return {0.0, position};
  }
  return {0.0, 0.0};
}

int segmentLength(const BorderSegment& segment) { return static_cast<int>(segment.vertices.size()) - 1; }

double sidePosition(const SegmentUse& use, double y) { return use.reversed ? use.first - y : use.first + y; }

// Where each segment sits in its border line.
struct LinePlace {
  int line = -1;
  int offset = 0;
  bool reversed = false;
};

Vector3d surfacePoint(const cad::BSplineSurfaceData& surface, const std::vector<double>& uKnots,
                      const std::vector<double>& vKnots, double s, double t) {
  const int m = surface.uPoleCount - 3;
  const int n = surface.vPoleCount - 3;
  const CubicBasis bu = cubicBasis(uKnots, m, s);
  const CubicBasis bv = cubicBasis(vKnots, n, t);
  Vector3d p = Vector3d::Zero();
  for (int a = 0; a < 4; ++a) {
    for (int b = 0; b < 4; ++b) {
      const size_t k = 3 * static_cast<size_t>((bu.first + a) * surface.vPoleCount + bv.first + b);
      p += bu.w[a] * bv.w[b] * Vector3d(surface.poles[k], surface.poles[k + 1], surface.poles[k + 2]);
    }
  }
  return p;
}

std::vector<int> clampedMultiplicities(int spans) {
  std::vector<int> mults{4};
  mults.insert(mults.end(), static_cast<size_t>(spans - 1), 1);
  mults.push_back(4);
  return mults;
}

std::vector<double> distinctKnots(int spans) {
  std::vector<double> knots;
  for (int k = 0; k <= spans; ++k) knots.push_back(k);
  return knots;
}

class Fitter {
 public:
  Fitter(ChartLayout layout, const LimitPointsFunction& limit, const LimitBSplineOptions& options)
      : limit_(limit), options_(options), fits_(options.samplesPerSpan) {
    result_.layout = std::move(layout);
  }

  LimitBSplines run() {
    placeSegments();
    fitLines();
    fitCharts();
    check();
    return std::move(result_);
  }

 private:
  const ChartLayout& layout() const { return result_.layout; }

  // Face location of parameter y in [0, #edges] along a segment (seen from its first use).
  SurfaceLocation segmentLocation(int segment, double y) const {
    const BorderSegment& seg = layout().segments[static_cast<size_t>(segment)];
    const SegmentUse& use = seg.uses.front();
    const QuadChart& chart = layout().charts[static_cast<size_t>(use.chart)];
    const auto [s, t] = sideParameters(chart, use.side, sidePosition(use, y));
    return chartLocation(chart, s, t);
  }

  void placeSegments() {
    places_.assign(layout().segments.size(), LinePlace{});
    lineSpans_.clear();
    for (size_t l = 0; l < layout().lines.size(); ++l) {
      const BorderLine& line = layout().lines[l];
      int offset = 0;
      for (size_t k = 0; k < line.segments.size(); ++k) {
        places_[static_cast<size_t>(line.segments[k])] =
            LinePlace{static_cast<int>(l), offset, line.reversed[k]};
        offset += segmentLength(layout().segments[static_cast<size_t>(line.segments[k])]);
      }
      lineSpans_.push_back(offset);
    }
  }

  SurfaceLocation lineLocation(int line, double x) const {
    for (int segment : layout().lines[static_cast<size_t>(line)].segments) {
      const LinePlace& place = places_[static_cast<size_t>(segment)];
      const int length = segmentLength(layout().segments[static_cast<size_t>(segment)]);
      if (x <= place.offset + length) {
        const double local = x - place.offset;
        return segmentLocation(segment, place.reversed ? length - local : local);
      }
    }
    throw SolverError("border line parameter outside its segments");
  }

  // First (end 0) or last (end 1) vertex of a border line.
  int lineEndVertex(size_t line, int end) const {
    const BorderLine& l = layout().lines[line];
    const size_t k = end == 0 ? 0 : l.segments.size() - 1;
    const BorderSegment& segment = layout().segments[static_cast<size_t>(l.segments[k])];
    const bool atFront = (end == 0) != l.reversed[k];
    return atFront ? segment.vertices.front() : segment.vertices.back();
  }

  // One clamped cubic per border line: end poles at the limit points of its end nodes, the rest
  // a least-squares fit to limit samples along the line.
  void fitLines() {
    const size_t lineCount = layout().lines.size();
    std::vector<SurfaceLocation> locations;
    std::vector<size_t> first(lineCount + 1, 0);
    for (size_t l = 0; l < lineCount; ++l) {
      first[l] = locations.size();
      const int spans = lineSpans_[l];
      locations.push_back(lineLocation(static_cast<int>(l), 0.0));
      locations.push_back(lineLocation(static_cast<int>(l), spans));
      for (double x : fitParameters(spans, options_.samplesPerSpan)) {
        locations.push_back(lineLocation(static_cast<int>(l), x));
      }
    }
    RowMatrixX3d points;
    RowMatrixX3d normals;
    limit_(locations, points, &normals);
    checkEvaluated(points, locations.size());
    if (normals.rows() != points.rows()) throw SolverError("the limit evaluator returned no normals");
    // Nodes on boundaries or creases have a tangent plane per side; the others have one.
    std::set<int> sharpNodes;
    for (const BorderSegment& segment : layout().segments) {
      if (segment.kind == BorderKind::Separatrix) continue;
      sharpNodes.insert(segment.vertices.front());
      sharpNodes.insert(segment.vertices.back());
    }
    linePoles_.assign(lineCount, {});
    for (size_t l = 0; l < lineCount; ++l) {
      const int spans = lineSpans_[l];
      const EndConstrainedFit& fit = fits_.get(spans);
      const auto row = static_cast<Eigen::Index>(first[l]);
      const Eigen::MatrixXd samples = points.middleRows(row + 2, fit.full().rows());
      Eigen::MatrixXd poles = Eigen::MatrixXd::Zero(spans + 3, 3);
      poles.row(0) = points.row(row);
      poles.row(spans + 2) = points.row(row + 1);
      Eigen::MatrixXd rhs = samples;
      rhs -= Eigen::VectorXd(fit.full().col(0)) * poles.row(0);
      rhs -= Eigen::VectorXd(fit.full().col(spans + 2)) * poles.row(spans + 2);
      poles.middleRows(1, spans + 1) = fit.solve(rhs);
      // At a smooth node (an extraordinary vertex, say) every curve leaving it must start in the
      // limit tangent plane, so that the chart corners there share that plane: project the
      // pole next to the end onto it and refit the rest. Regular curves already satisfy this.
      const BorderLine& line = layout().lines[l];
      if (layout().segments[static_cast<size_t>(line.segments.front())].kind == BorderKind::Separatrix) {
        std::vector<bool> fixed(static_cast<size_t>(spans + 3), false);
        fixed.front() = fixed.back() = true;
        bool constrained = false;
        for (int end = 0; end < 2; ++end) {
          const Eigen::Index node = end == 0 ? 0 : spans + 2;
          const Eigen::Index next = end == 0 ? 1 : spans + 1;
          const Eigen::RowVector3d normal = normals.row(row + end);
          if (sharpNodes.count(lineEndVertex(l, end)) != 0 || normal.norm() == 0.0) continue;
          const Eigen::RowVector3d tangent = poles.row(next) - poles.row(node);
          poles.row(next) -= tangent.dot(normal) * normal;
          fixed[static_cast<size_t>(next)] = true;
          constrained = true;
        }
        if (constrained) solveFreePoles(fit.full(), fixed, poles, samples);
      }
      for (Eigen::Index k = 0; k < poles.rows(); ++k) linePoles_[l].push_back(poles.row(k).transpose());
    }
    result_.segmentCurves.resize(layout().segments.size());
    for (size_t s = 0; s < layout().segments.size(); ++s) {
      const LinePlace& place = places_[s];
      const int length = segmentLength(layout().segments[s]);
      std::vector<Vector3d> poles =
          restrictCurve(linePoles_[static_cast<size_t>(place.line)],
                        lineSpans_[static_cast<size_t>(place.line)], place.offset, place.offset + length);
      if (place.reversed) std::reverse(poles.begin(), poles.end());
      BSplineCurveData& curve = result_.segmentCurves[s];
      for (const Vector3d& p : poles) curve.poles.insert(curve.poles.end(), {p.x(), p.y(), p.z()});
      curve.knots = distinctKnots(length);
      curve.multiplicities = clampedMultiplicities(length);
    }
  }

  // Boundary poles of a chart side, by increasing side position: a piece of one line's curve.
  std::vector<Vector3d> sidePoles(const QuadChart& chart, int chartIndex, ChartSide side) const {
    const int segment = chart.sideSegments[static_cast<size_t>(side)].front();
    const BorderSegment& seg = layout().segments[static_cast<size_t>(segment)];
    const int length = segmentLength(seg);
    const SegmentUse* use = nullptr;
    for (const SegmentUse& candidate : seg.uses) {
      if (candidate.chart == chartIndex && candidate.side == side &&
          candidate.first == (candidate.reversed ? length : 0)) {
        use = &candidate;
      }
    }
    if (use == nullptr) throw SolverError("chart " + std::to_string(chartIndex) + ": side segment not found");
    const LinePlace& place = places_[static_cast<size_t>(segment)];
    const int sideLength = chart.sideLength(side);
    // Side position 0 is segment parameter y0; the line runs with the side when both or neither
    // of the two orientations are reversed.
    const int y0 = use->reversed ? length : 0;
    const int x0 = place.offset + (place.reversed ? length - y0 : y0);
    const bool along = use->reversed == place.reversed;
    const int a = along ? x0 : x0 - sideLength;
    std::vector<Vector3d> poles =
        restrictCurve(linePoles_[static_cast<size_t>(place.line)],
                      lineSpans_[static_cast<size_t>(place.line)], a, a + sideLength);
    if (!along) std::reverse(poles.begin(), poles.end());
    return poles;
  }

  // The tangent plane neighbours are to share along every shared smooth segment, for each chart
  // side on it (chart_continuity.h): the mean of the two charts' unit normals as fitted on their
  // own (`poles`), each weighted by the other chart's misfit (largest sample residual), so that an
  // exact chart (a regular one) keeps its plane and its neighbour turns to it. Both normals are
  // orthogonal to the shared border curve, and so is the mean. Not the limit surface's normal:
  // next to an extraordinary vertex a chart cannot follow it, and turning both charts to it
  // folded the small charts around the M6's trailing-edge tip.
  std::vector<std::vector<BorderNormal>> borderNormals(const std::vector<std::array<Eigen::MatrixXd, 3>>& poles,
                                                      const std::vector<double>& misfit) const {
    std::vector<std::vector<BorderNormal>> result(layout().charts.size());
    for (const BorderSegment& segment : layout().segments) {
      if (segment.kind != BorderKind::Separatrix || segment.uses.size() < 2) continue;
      for (double y : borderParameters(segmentLength(segment))) {
        if (nextToCorner(segment, y)) continue;
        Vector3d normal[2];
        double weight[2];
        for (size_t k = 0; k < 2; ++k) {
          const SegmentUse& use = segment.uses[k];
          const QuadChart& chart = layout().charts[static_cast<size_t>(use.chart)];
          const auto [s, t] = sideParameters(chart, use.side, sidePosition(use, y));
          normal[k] = chartNormal(poles[static_cast<size_t>(use.chart)], s, t);
          weight[1 - k] = misfit[static_cast<size_t>(use.chart)];
        }
        Vector3d mean = weight[0] * normal[0] + weight[1] * normal[1];
        if (!(mean.norm() > 0.0)) mean = normal[0] + normal[1];  // both exact
        if (!(mean.norm() > 0.0)) continue;
        for (const SegmentUse& use : segment.uses) {
          result[static_cast<size_t>(use.chart)].push_back({use.side, sidePosition(use, y), mean.normalized()});
        }
      }
    }
    return result;
  }

  // Where neighbours are made to share their tangent planes along a segment of `spans` edges:
  // 2 * samplesPerSpan intervals per span, four times as many in the spans next to its ends, where
  // the limit surface of an extraordinary vertex turns fastest against the chart's polynomials.
  std::vector<double> borderParameters(int spans) const {
    const int perSpan = 2 * options_.samplesPerSpan;
    std::vector<double> y{0.0};
    for (int i = 0; i < spans; ++i) {
      const int steps = (i == 0 || i == spans - 1) ? 4 * perSpan : perSpan;
      for (int q = 1; q <= steps; ++q) y.push_back(i + static_cast<double>(q) / steps);
    }
    return y;
  }

  // Within the span next to a corner (a cone point of the limit surface) the charts, whose normals
  // are continuous up to their corners, cannot follow the limit's tangent planes.
  bool nextToCorner(const BorderSegment& segment, double y) const {
    const auto corner = [&](int vertex) {
      return std::binary_search(layout().corners.begin(), layout().corners.end(), vertex);
    };
    return (y < 1.0 && corner(segment.vertices.front())) ||
           (y > segmentLength(segment) - 1.0 && corner(segment.vertices.back()));
  }

  // Least-squares poles inside the outer rings that `fu` and `fv` hold fixed (Kronecker
  // structured: (A_u (x) A_v) P = S separates into two 1D solves), per coordinate. Returns the
  // largest sample residual.
  static double fitFreePoles(std::array<Eigen::MatrixXd, 3>& poles, const std::array<Eigen::MatrixXd, 3>& samples,
                             const EndConstrainedFit& fu, const EndConstrainedFit& fv) {
    const Eigen::MatrixXd av(fv.full());
    const int fixed = fu.fixedPerEnd();
    double misfit = 0.0;
    for (size_t d = 0; d < 3; ++d) {
      if (fu.freeCount() > 0 && fv.freeCount() > 0) {
        poles[d].block(fixed, fixed, fu.freeCount(), fv.freeCount()).setZero();
        const Eigen::MatrixXd residual = samples[d] - fu.full() * poles[d] * av.transpose();
        const Eigen::MatrixXd half = fu.solve(residual);  // free u poles x samples in v
        poles[d].block(fixed, fixed, fu.freeCount(), fv.freeCount()) = fv.solve(half.transpose()).transpose();
      }
      misfit = std::max(misfit, (samples[d] - fu.full() * poles[d] * av.transpose()).cwiseAbs().maxCoeff());
    }
    return misfit;
  }

  // The chart's border curves as its outer pole ring, per coordinate; the other poles zero.
  std::array<Eigen::MatrixXd, 3> borderPoles(int chartIndex) const {
    const QuadChart& chart = layout().charts[static_cast<size_t>(chartIndex)];
    const int m = chart.uCells;
    const int n = chart.vCells;
    std::array<Eigen::MatrixXd, 3> poles;
    poles.fill(Eigen::MatrixXd::Zero(m + 3, n + 3));
    for (ChartSide side : {ChartSide::VMin, ChartSide::UMax, ChartSide::VMax, ChartSide::UMin}) {
      const std::vector<Vector3d> row = sidePoles(chart, chartIndex, side);
      for (size_t k = 0; k < row.size(); ++k) {
        const int q = static_cast<int>(k);
        for (size_t d = 0; d < 3; ++d) {
          switch (side) {
            case ChartSide::VMin:
              poles[d](q, 0) = row[k][static_cast<Eigen::Index>(d)];
              break;
            case ChartSide::UMax:
              poles[d](m + 2, q) = row[k][static_cast<Eigen::Index>(d)];
              break;
            case ChartSide::VMax:
              poles[d](q, n + 2) = row[k][static_cast<Eigen::Index>(d)];
              break;
            case ChartSide::UMin:
              poles[d](0, q) = row[k][static_cast<Eigen::Index>(d)];
              break;
          }
        }
      }
    }
    return poles;
  }

  // Every chart fitted on its own, then the rows next to its smooth borders turned into the
  // tangent planes it should share with its neighbours and the poles inside them refitted.
  void fitCharts() {
    const auto& charts = layout().charts;
    const int perSpan = options_.samplesPerSpan;
    std::vector<SurfaceLocation> locations;
    std::vector<size_t> first(charts.size(), 0);
    for (size_t c = 0; c < charts.size(); ++c) {
      first[c] = locations.size();
      const std::vector<double> su = fitParameters(charts[c].uCells, perSpan);
      const std::vector<double> sv = fitParameters(charts[c].vCells, perSpan);
      for (double s : su) {
        for (double t : sv) locations.push_back(chartLocation(charts[c], s, t));
      }
    }
    RowMatrixX3d points;
    limit_(locations, points, nullptr);
    checkEvaluated(points, locations.size());

    std::vector<std::array<Eigen::MatrixXd, 3>> poles(charts.size());
    std::vector<std::array<Eigen::MatrixXd, 3>> samples(charts.size());  // per coordinate, u x v
    std::vector<double> misfit(charts.size(), 0.0);
    for (size_t c = 0; c < charts.size(); ++c) {
      const int m = charts[c].uCells;
      const int n = charts[c].vCells;
      const Eigen::Index rows = fits_.get(m).full().rows();
      const Eigen::Index cols = fits_.get(n).full().rows();
      for (int d = 0; d < 3; ++d) {
        Eigen::MatrixXd& grid = samples[c][static_cast<size_t>(d)];
        grid.resize(rows, cols);
        for (Eigen::Index r = 0; r < rows; ++r) {
          grid.row(r) = points.col(d).segment(static_cast<Eigen::Index>(first[c]) + r * cols, cols).transpose();
        }
      }
      poles[c] = borderPoles(static_cast<int>(c));
      misfit[c] = fitFreePoles(poles[c], samples[c], fits_.get(m), fits_.get(n));
    }
    const std::vector<std::vector<BorderNormal>> normals =
        options_.tangentContinuity ? borderNormals(poles, misfit) : std::vector<std::vector<BorderNormal>>(charts.size());
    result_.surfaces.resize(charts.size());
    for (size_t c = 0; c < charts.size(); ++c) {
      const int m = charts[c].uCells;
      const int n = charts[c].vCells;
      if (!normals[c].empty()) {
        const SparseMatrix& au = fits_.get(m).full();
        const SparseMatrix& av = fits_.get(n).full();
        alignBorderTangentPlanes(poles[c], normals[c], Eigen::MatrixXd(au.transpose() * au),
                                 Eigen::MatrixXd(av.transpose() * av), tangentPlaneWeight);
        fitFreePoles(poles[c], samples[c], fits_.get(m, 2), fits_.get(n, 2));
      }
      cad::BSplineSurfaceData& surface = result_.surfaces[c];
      surface.uPoleCount = m + 3;
      surface.vPoleCount = n + 3;
      surface.poles.assign(static_cast<size_t>(3 * (m + 3) * (n + 3)), 0.0);
      for (size_t d = 0; d < 3; ++d) {
        for (int i = 0; i < m + 3; ++i) {
          for (int j = 0; j < n + 3; ++j) surface.poles[3 * static_cast<size_t>(i * (n + 3) + j) + d] = poles[c][d](i, j);
        }
      }
      surface.uKnots = distinctKnots(m);
      surface.vKnots = distinctKnots(n);
      surface.uMultiplicities = clampedMultiplicities(m);
      surface.vMultiplicities = clampedMultiplicities(n);
    }
  }

  // Max deviation per chart on a denser grid than the fit, and the gap between neighbours.
  void check() {
    const auto& charts = layout().charts;
    const int perSpan = options_.checkSamplesPerSpan;
    std::vector<SurfaceLocation> locations;
    std::vector<Vector3d> fitted;
    std::vector<size_t> first(charts.size() + 1, 0);
    for (size_t c = 0; c < charts.size(); ++c) {
      first[c] = locations.size();
      const auto& surface = result_.surfaces[c];
      const std::vector<double> uKnots = clampedKnots(charts[c].uCells);
      const std::vector<double> vKnots = clampedKnots(charts[c].vCells);
      for (double s : checkParameters(charts[c].uCells, perSpan)) {
        for (double t : checkParameters(charts[c].vCells, perSpan)) {
          locations.push_back(chartLocation(charts[c], s, t));
          fitted.push_back(surfacePoint(surface, uKnots, vKnots, s, t));
        }
      }
    }
    first[charts.size()] = locations.size();
    RowMatrixX3d points, normals;
    limit_(locations, points, &normals);
    checkEvaluated(points, locations.size());
    result_.maxDeviation.assign(charts.size(), 0.0);
    result_.maxDistance.assign(charts.size(), 0.0);
    for (size_t c = 0; c < charts.size(); ++c) {
      for (size_t k = first[c]; k < first[c + 1]; ++k) {
        const auto row = static_cast<Eigen::Index>(k);
        const Vector3d difference = fitted[k] - points.row(row).transpose();
        result_.maxDeviation[c] = std::max(result_.maxDeviation[c], difference.norm());
        const Vector3d normal = normals.row(row).transpose();
        const double along = normal.norm() > 0.0 ? std::abs(difference.dot(normal.normalized())) : difference.norm();
        result_.maxDistance[c] = std::max(result_.maxDistance[c], along);
      }
    }
    result_.maxBorderGap = 0.0;
    result_.maxKinkDegrees = 0.0;
    std::vector<Handle(Geom_BSplineSurface)> occt(charts.size());
    const double degrees = 180.0 / std::acos(-1.0);
    for (const BorderSegment& segment : layout().segments) {
      if (segment.uses.size() < 2) continue;
      for (double y : checkParameters(segmentLength(segment), perSpan)) {
        const bool smooth = segment.kind != BorderKind::Crease && !nextToCorner(segment, y);
        Vector3d p[2];
        Vector3d normal[2];
        for (int k = 0; k < 2; ++k) {
          const SegmentUse& use = segment.uses[static_cast<size_t>(k)];
          const auto c = static_cast<size_t>(use.chart);
          const QuadChart& chart = charts[c];
          const auto [s, t] = sideParameters(chart, use.side, sidePosition(use, y));
          p[k] =
              surfacePoint(result_.surfaces[c], clampedKnots(chart.uCells), clampedKnots(chart.vCells), s, t);
          if (!smooth) continue;
          if (occt[c].IsNull()) occt[c] = cad::makeBSplineSurface(result_.surfaces[c]);
          translateOcctErrors("surface normal on a chart border", [&] {
            gp_Pnt point;
            gp_Vec du;
            gp_Vec dv;
            occt[c]->D1(s, t, point, du, dv);
            const gp_Vec n = du.Crossed(dv);
            normal[k] = Vector3d(n.X(), n.Y(), n.Z());
          });
        }
        result_.maxBorderGap = std::max(result_.maxBorderGap, (p[0] - p[1]).norm());
        if (smooth && normal[0].norm() > 0.0 && normal[1].norm() > 0.0) {
          // atan2 of sine and cosine stays accurate for tiny angles, unlike acos.
          const double angle = std::atan2(normal[0].cross(normal[1]).norm(), normal[0].dot(normal[1]));
          result_.maxKinkDegrees = std::max(result_.maxKinkDegrees, angle * degrees);
        }
      }
    }
  }

  static void checkEvaluated(const RowMatrixX3d& points, size_t count) {
    if (static_cast<size_t>(points.rows()) != count) {
      throw SolverError("the limit evaluator returned " + std::to_string(points.rows()) + " points for " +
                        std::to_string(count) + " locations");
    }
    if (!points.allFinite()) throw SolverError("the limit evaluator returned non-finite points");
  }

  const LimitPointsFunction& limit_;
  LimitBSplineOptions options_;
  FitCache fits_;
  LimitBSplines result_;
  std::vector<LinePlace> places_;
  std::vector<int> lineSpans_;
  std::vector<std::vector<Vector3d>> linePoles_;
};

}  // namespace

LimitBSplines fitLimitBSplines(ChartLayout layout, const LimitPointsFunction& limit,
                               const LimitBSplineOptions& options) {
  if (options.samplesPerSpan < 4) {
    throw InvalidInputError("samplesPerSpan " + std::to_string(options.samplesPerSpan) +
                            " is too small: a cubic span needs at least 4 samples");
  }
  if (options.checkSamplesPerSpan < 2) {
    throw InvalidInputError("checkSamplesPerSpan " + std::to_string(options.checkSamplesPerSpan) +
                            " must be at least 2 (both span ends)");
  }
  if (!limit) throw InvalidInputError("no limit evaluator given");
  return Fitter(std::move(layout), limit, options).run();
}

LimitBSplines limitSurfaceToBSplines(const QuadControlMesh& mesh, const LimitBSplineOptions& options) {
  ChartLayout layout = buildChartLayout(mesh);
  const ControlMesh controlMesh = toControlMesh(mesh);
  const LimitEvaluator evaluator(controlMesh, SubdivisionOptions{}, options.isolationLevel);
  return fitLimitBSplines(std::move(layout), limitPoints(evaluator, controlMesh.vertices()), options);
}

SewnShape sewBSplineSurfaces(const std::vector<cad::BSplineSurfaceData>& surfaces,
                             const SewingOptions& options) {
  if (surfaces.empty()) throw InvalidInputError("no surfaces to sew");
  if (!(options.relativeTolerance > 0.0)) {
    throw InvalidInputError("the relative sewing tolerance must be positive");
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL);
  Eigen::Vector3d hi = -lo;
  for (const auto& surface : surfaces) {
    for (size_t k = 0; k + 2 < surface.poles.size(); k += 3) {
      const Eigen::Vector3d p(surface.poles[k], surface.poles[k + 1], surface.poles[k + 2]);
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  SewnShape result;
  result.tolerance = options.relativeTolerance * (hi - lo).norm();
  std::vector<TopoDS_Face> faces;
  for (const auto& surface : surfaces) faces.push_back(cad::makeBSplineFace(surface));
  return translateOcctErrors("sewing the B-spline faces", [&] {
    BRepBuilderAPI_Sewing sewing(result.tolerance);
    for (const TopoDS_Face& face : faces) sewing.Add(face);
    sewing.Perform();
    result.shape = sewing.SewedShape();
    result.freeEdges = sewing.NbFreeEdges();
    if (result.shape.ShapeType() == TopAbs_FACE) {
      // A single face (e.g. a torus chart sewn to itself) comes back bare: give it its shell.
      TopoDS_Shell shell;
      BRep_Builder builder;
      builder.MakeShell(shell);
      builder.Add(shell, result.shape);
      result.shape = shell;
    }
    if (result.freeEdges == 0 && options.makeSolid && result.shape.ShapeType() == TopAbs_SHELL) {
      BRepBuilderAPI_MakeSolid maker(TopoDS::Shell(result.shape));
      if (maker.IsDone()) {
        ShapeFix_Solid fix(maker.Solid());
        fix.Perform();
        TopoDS_Shape solid = fix.Solid();
        GProp_GProps props;
        BRepGProp::VolumeProperties(solid, props);
        if (props.Mass() < 0.0) solid.Reverse();
        result.shape = solid;
        result.solid = solid.ShapeType() == TopAbs_SOLID;
      }
    }
    for (TopExp_Explorer it(result.shape, TopAbs_EDGE); it.More(); it.Next()) {
      result.maxEdgeTolerance =
          std::max(result.maxEdgeTolerance, BRep_Tool::Tolerance(TopoDS::Edge(it.Current())));
    }
    for (TopExp_Explorer it(result.shape, TopAbs_VERTEX); it.More(); it.Next()) {
      result.maxEdgeTolerance =
          std::max(result.maxEdgeTolerance, BRep_Tool::Tolerance(TopoDS::Vertex(it.Current())));
    }
    result.valid = BRepCheck_Analyzer(result.shape).IsValid();
    return result;
  });
}

}  // namespace bvmesh::surface

#include "core/grid/wall_lines.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <mutex>
#include <numeric>
#include <optional>
#include <string>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"
#include "core/common/number_text.h"
#include "core/common/parallel.h"
#include "core/grid/distribution.h"

namespace bvmesh::grid {
namespace {

using volume::BsplineVolume;

// Wall-normal lines' arc-length tables sample each knot span once (Simpson + Hermite on polynomial
// pieces): they are only the start of Newton's placement by straight distances, which corrects them.
constexpr int kLineIntervalsPerSpan = 1;

// Where the wall-normal lines start sliding towards the outer boundary's even points, in wall
// sizes.
constexpr double kSlideStart = 0.1;

// A wall-normal line placed by chords: where its points are, for its neighbour's start.
struct PlacedLine {
  size_t block = std::numeric_limits<size_t>::max();
  std::array<int, 3> ijk{0, 0, 0};
  ChordLaw law;
  std::vector<double> parameter;
};

// One wall-normal line at a time: a thread reuses its storage from column to column.
struct WallLine {
  size_t block = std::numeric_limits<size_t>::max();  // whose knots `curve` has
  BsplineCurve curve;                                 // for its exact ends and Newton on the first height
  PolynomialCurve polynomial;                         // the same curve in pieces, for everything else
  ArcLength arc;
  std::vector<double> distance, parameter;
  std::vector<Eigen::Vector3d> points;
  RowMatrixX3d outerPoles;  // a sliding line's: the iso-parametric line it slides towards
  ChordPlacer placer;
  // The last three lines placed in this chunk of columns, newest first: the next line along the
  // same row of columns starts from their parameters extrapolated, which needs no arc-length
  // table and is closer than the law in arc length (Newton mostly takes one step instead of two).
  std::array<PlacedLine, 3> history;
  LineMeasures measured;  // over the thread's lines so far
};

// Whether `next` is the column after `line`'s in the same block along `along`, the other index
// the same.
bool nextInRow(const PlacedLine& line, size_t block, const std::array<int, 3>& next, int along) {
  if (line.block != block) return false;
  for (size_t d = 0; d < 3; ++d) {
    if (next[d] != line.ijk[d] + (static_cast<int>(d) == along ? 1 : 0)) return false;
  }
  return true;
}

// Per wall-normal column (numbered as `columnOffset` counts them), an upper bound of its line's
// arc length: the longest control polygon among the block's pole columns that its tangential
// parameters blend (B-spline weights are non-negative and sum to one, so the line's polygon is no
// longer than the longest of theirs, and a B-spline curve no longer than its polygon), with a
// margin for the arc-length quadrature's rounding.
std::vector<double> columnLengthBounds(const std::vector<volume::Block>& blocks,
                                       const std::vector<BlockPlan>& plans,
                                       const std::vector<std::int64_t>& columnOffset) {
  std::vector<double> bound(static_cast<size_t>(columnOffset.back()), 0.0);
  for (size_t b = 0; b < blocks.size(); ++b) {
    const BlockPlan& plan = plans[b];
    const int n = plan.normalDirection;
    if (n < 0) continue;
    const BsplineVolume& volume = blocks[b].volume;
    const auto [t1, t2] = otherDirections(n);
    const int count1 = volume.poleCount(t1), count2 = volume.poleCount(t2), along = volume.poleCount(n);
    std::vector<double> polygon(static_cast<size_t>(count1) * static_cast<size_t>(count2), 0.0);
    std::array<int, 3> ijk{};
    for (int a2 = 0; a2 < count2; ++a2) {
      for (int a1 = 0; a1 < count1; ++a1) {
        ijk[static_cast<size_t>(t1)] = a1;
        ijk[static_cast<size_t>(t2)] = a2;
        double length = 0.0;
        for (int k = 0; k + 1 < along; ++k) {
          ijk[static_cast<size_t>(n)] = k;
          const Eigen::Index here = volume.poleIndex(ijk[0], ijk[1], ijk[2]);
          ijk[static_cast<size_t>(n)] = k + 1;
          length += (volume.poles().row(volume.poleIndex(ijk[0], ijk[1], ijk[2])) - volume.poles().row(here))
                        .norm();
        }
        polygon[static_cast<size_t>(a2) * static_cast<size_t>(count1) + static_cast<size_t>(a1)] = length;
      }
    }
    const auto firstPole = [&](int direction, double t) {
      const std::vector<double>& knots = volume.knots(direction);
      return findKnotSpan(knots, volume.degree(direction), std::clamp(t, knots.front(), knots.back())) -
             volume.degree(direction);
    };
    const int n1 = plan.size[static_cast<size_t>(t1)];
    for (std::int64_t local = 0; local < columnOffset[b + 1] - columnOffset[b]; ++local) {
      ijk = {0, 0, 0};
      ijk[static_cast<size_t>(t1)] = static_cast<int>(local % n1);
      ijk[static_cast<size_t>(t2)] = static_cast<int>(local / n1);
      const int first1 = firstPole(t1, pointParameter(plan, t1, ijk));
      const int first2 = firstPole(t2, pointParameter(plan, t2, ijk));
      double longest = 0.0;
      for (int a2 = first2; a2 <= first2 + volume.degree(t2); ++a2) {
        for (int a1 = first1; a1 <= first1 + volume.degree(t1); ++a1) {
          longest = std::max(
              longest,
              polygon[static_cast<size_t>(a2) * static_cast<size_t>(count1) + static_cast<size_t>(a1)]);
        }
      }
      bound[static_cast<size_t>(columnOffset[b] + local)] = longest * (1.0 + 1e-6);
    }
  }
  return bound;
}

// A line's arc length, which must not be zero.
void tabulateLine(size_t b, const std::array<int, 3>& ijk, WallLine& line) {
  line.arc.tabulate(line.polynomial, kLineIntervalsPerSpan);
  if (!(line.arc.length() > 0.0)) {
    throw InvalidInputError(blockText(b) + " has a wall-normal line of zero length at (" +
                            std::to_string(ijk[0]) + ", " + std::to_string(ijk[1]) + ", " +
                            std::to_string(ijk[2]) + ")");
  }
}

// The columns of every wall block numbered one block after the other, so that one pool of
// threads shares them all (blocks differ in size by orders of magnitude).
class Columns {
 public:
  Columns(const std::vector<volume::Block>& blocks, const std::vector<BlockPlan>& plans,
          const SlideShares& shares)
      : blocks_(blocks), plans_(plans), shares_(shares), spans_(blocks.size()), offset_{0} {
    for (size_t b = 0; b < blocks.size(); ++b) {
      const int n = plans[b].normalDirection;
      std::int64_t columns = 0;
      if (n >= 0) {
        spans_[b].emplace(blocks[b].volume.knots(n), blocks[b].volume.degree(n));
        const auto [t1, t2] = otherDirections(n);
        columns = static_cast<std::int64_t>(plans[b].size[static_cast<size_t>(t1)]) *
                  plans[b].size[static_cast<size_t>(t2)];
      }
      offset_.push_back(offset_.back() + columns);
    }
  }
  // Where each block's columns start, then their count.
  const std::vector<std::int64_t>& offset() const { return offset_; }

  // Calls work(b, ijk) for the columns [begin, end) (ijk with index 0 along the normal).
  template <class Work>
  void forRange(std::int64_t begin, std::int64_t end, Work&& work) const {
    size_t b =
        static_cast<size_t>(std::upper_bound(offset_.begin(), offset_.end(), begin) - offset_.begin()) - 1;
    for (std::int64_t c = begin; c < end; ++c) {
      while (c >= offset_[b + 1]) ++b;
      const auto [t1, t2] = otherDirections(plans_[b].normalDirection);
      const int n1 = plans_[b].size[static_cast<size_t>(t1)];
      const std::int64_t local = c - offset_[b];
      std::array<int, 3> ijk{0, 0, 0};
      ijk[static_cast<size_t>(t1)] = static_cast<int>(local % n1);
      ijk[static_cast<size_t>(t2)] = static_cast<int>(local / n1);
      work(b, ijk);
    }
  }

  // Sets `line` to the wall-normal line of column (b, ijk).
  void load(size_t b, const std::array<int, 3>& ijk, WallLine& line) const {
    const BlockPlan& plan = plans_[b];
    const BsplineVolume& volume = blocks_[b].volume;
    const int n = plan.normalDirection;
    const auto [t1, t2] = otherDirections(n);
    if (line.block != b) {
      line.block = b;
      line.curve.degree = volume.degree(n);
      line.curve.knots = volume.knots(n);
    }
    if (shares_.empty()) {
      volume.isoCurvePoles(n, pointParameter(plan, t1, ijk), pointParameter(plan, t2, ijk), line.curve.poles);
    } else {
      slide(plan, volume, ijk, line);
    }
    line.polynomial.assign(line.curve.poles, *spans_[b]);
  }

  // Whether the lines slide.
  bool sliding() const { return !shares_.empty(); }

  // Calls work(b, ijk, line) for every column, `line` holding its wall-normal line; returns what
  // the work measured into the lines. Chunks of columns are fixed whatever the threads, and each
  // starts afresh, so the lines come out the same bit for bit.
  template <class Work>
  LineMeasures forEvery(Work&& work) const {
    LineMeasures measured;
    std::mutex guard;
    parallelChunks(offset_.back(), 256, [&](std::int64_t begin, std::int64_t end) {
      WallLine line;
      forRange(begin, end, [&](size_t b, const std::array<int, 3>& ijk) {
        load(b, ijk, line);
        work(b, ijk, line);
      });
      const std::lock_guard<std::mutex> lock(guard);
      measured.add(line.measured);
    });
    return measured;
  }

 private:
  // Instead of the column's iso-parametric line, one whose poles slide from it towards the
  // iso-parametric line through the outer boundary's parameters (outerParameter), pole layer by
  // pole layer by their shares: on the chord between the two lines' poles. The line stays a
  // B-spline curve, so its points are placed by the wall law as before.
  void slide(const BlockPlan& plan, const BsplineVolume& volume, const std::array<int, 3>& ijk,
             WallLine& line) const {
    const int n = plan.normalDirection;
    const auto [t1, t2] = otherDirections(n);
    RowMatrixX3d& poles = line.curve.poles;
    volume.isoCurvePoles(n, pointParameter(plan, t1, ijk), pointParameter(plan, t2, ijk), poles);
    volume.isoCurvePoles(n, outerParameter(plan, t1, ijk), outerParameter(plan, t2, ijk), line.outerPoles);
    const std::vector<double>& share = shares_.at(static_cast<int>(poles.rows()));
    for (Eigen::Index m = 0; m < poles.rows(); ++m) {
      const double s = share[static_cast<size_t>(plan.wallEnd == 0 ? m : poles.rows() - 1 - m)];
      if (s > 0.0) poles.row(m) += s * (line.outerPoles.row(m) - poles.row(m));
    }
  }

  const std::vector<volume::Block>& blocks_;
  const std::vector<BlockPlan>& plans_;
  const SlideShares& shares_;  // empty: iso-parametric lines
  std::vector<std::optional<SpanPolynomials>> spans_;
  std::vector<std::int64_t> offset_;
};

// Per column, its slid line's control polygon length (with the same margin): the bound when the
// lines slide, which the pole columns' own polygons do not give.
std::vector<double> slidLineBounds(const Columns& columns) {
  std::vector<double> bound(static_cast<size_t>(columns.offset().back()), 0.0);
  parallelChunks(columns.offset().back(), 256, [&](std::int64_t begin, std::int64_t end) {
    WallLine line;
    std::int64_t column = begin;
    columns.forRange(begin, end, [&](size_t b, const std::array<int, 3>& ijk) {
      columns.load(b, ijk, line);
      const RowMatrixX3d& poles = line.curve.poles;
      double length = 0.0;
      for (Eigen::Index k = 1; k < poles.rows(); ++k) length += (poles.row(k) - poles.row(k - 1)).norm();
      bound[static_cast<size_t>(column++)] = length * (1.0 + 1e-6);
    });
  });
  return bound;
}

// Every line's `points` points by the options' wall law, from the first cell height (0: the
// growth fixed instead), into the grid blocks.
class LinePlacement {
 public:
  LinePlacement(const std::vector<volume::Block>& blocks, const std::vector<BlockPlan>& plans,
                const RefinementOptions& options, double firstHeight, int points)
      : blocks_(blocks),
        plans_(plans),
        options_(options),
        firstHeight_(firstHeight),
        points_(points),
        // Without a first cell height every line has the same geometric law up to its length: its
        // sums 1 + g + ... + g^(k-1) serve them all.
        unitSums_(firstHeight > 0.0 ? std::vector<double>{}
                                    : geometricDistances(points, 1.0, options.growth, 1.0)),
        byChords_(firstHeight == 0.0 || options.distribution == WallDistribution::Geometric) {}

  // Places the line of column (b, base), loaded in `line`, into `grid`.
  void place(size_t b, const std::array<int, 3>& base, WallLine& line, GridBlock& grid) const {
    const BlockPlan& plan = plans_[b];
    const int n = plan.normalDirection;
    std::vector<Eigen::Vector3d>& x = line.points;
    x.resize(static_cast<size_t>(points_));
    x.front() = line.curve.point(parameterAtEnd(blocks_[b].volume, n, plan.wallEnd));
    x.back() = line.curve.point(parameterAtEnd(blocks_[b].volume, n, 1 - plan.wallEnd));
    if (!byChords_) {
      placeInArcLength(b, base, line);
    } else {
      placeByChords(b, base, line);
    }
    store(plan, base, line, grid);
  }

 private:
  // The law laid out in arc length: the start for lines placed by chords, the tanh law itself.
  void layOutInArcLength(size_t b, const std::array<int, 3>& base, ChordLaw& law, WallLine& line) const {
    const BlockPlan& plan = plans_[b];
    const int n = plan.normalDirection;
    const int points = points_;
    std::vector<double>& t = line.parameter;
    tabulateLine(b, base, line);
    const double length = line.arc.length();
    std::vector<double>& distance = line.distance;
    if (firstHeight_ == 0.0) {
      law.heightFixed = false;
      law.growth = options_.growth;
      law.height = length * (options_.growth - 1.0) / std::expm1((points - 1) * std::log(options_.growth));
      distance.resize(static_cast<size_t>(points));
      for (size_t k = 0; k < distance.size(); ++k) distance[k] = law.height * unitSums_[k];
      distance.back() = length;
    } else if (options_.distribution == WallDistribution::Tanh) {
      distance = tanhWallFractions(points, firstHeight_ / length);
      for (double& d : distance) d *= length;
    } else {
      law.height = firstHeight_;
      law.growth = geometricGrowth(points, firstHeight_, length);
      distance = geometricDistances(points, firstHeight_, law.growth, length);
    }
    line.arc.parametersAt(distance, plan.wallEnd, t);
    t.front() = parameterAtEnd(blocks_[b].volume, n, plan.wallEnd);
    t.back() = parameterAtEnd(blocks_[b].volume, n, 1 - plan.wallEnd);
  }

  // Only the first height is exact here; the rest follows the tanh law in arc length.
  void placeInArcLength(size_t b, const std::array<int, 3>& base, WallLine& line) const {
    const int wallEnd = plans_[b].wallEnd;
    std::vector<double>& t = line.parameter;
    ChordLaw law;
    layOutInArcLength(b, base, law, line);
    if (points_ > 2)
      t[1] = parameterAtDistance(line.curve, t.front(), wallEnd == 0 ? 1 : -1, firstHeight_, t[1]);
    if (points_ > 2) line.polynomial.evaluate(&t[1], t.size() - 2, &line.points[1], nullptr);
  }

  // How many of the last lines lead up to this one along its row (0 .. 3), and the start
  // extrapolated from them (polynomial in the column index), kept if it leaves the points in
  // order and the law's free parameter positive. False if there were none or Newton failed.
  bool placeFromLastLines(size_t b, const std::array<int, 3>& base, ChordLaw& law, WallLine& line) const {
    const int along = otherDirections(plans_[b].normalDirection)[0];
    std::vector<double>& t = line.parameter;
    size_t known = 0;
    while (known < line.history.size() &&
           nextInRow(line.history[known], b, known == 0 ? base : line.history[known - 1].ijk, along)) {
      ++known;
    }
    if (known == 0) return false;
    static constexpr double kWeights[3][3] = {{1.0, 0.0, 0.0}, {2.0, -1.0, 0.0}, {3.0, -3.0, 1.0}};
    const double* weight = kWeights[known - 1];
    auto extrapolate = [&](auto value) {
      double sum = 0.0;
      for (size_t h = 0; h < known; ++h) sum += weight[h] * value(line.history[h]);
      return sum;
    };
    t.resize(line.history[0].parameter.size());
    const double direction =
        line.history[0].parameter.back() > line.history[0].parameter.front() ? 1.0 : -1.0;
    bool ordered = true;
    for (size_t k = 0; k < t.size(); ++k) {
      t[k] = extrapolate([k](const PlacedLine& placedLine) { return placedLine.parameter[k]; });
      ordered = ordered && (k == 0 || direction * (t[k] - t[k - 1]) > 0.0);
    }
    t.front() = line.history[0].parameter.front();
    t.back() = line.history[0].parameter.back();
    ordered = ordered && direction * (t.back() - t[t.size() - 2]) > 0.0 && direction * (t[1] - t[0]) > 0.0;
    law = line.history[0].law;
    double& free = law.heightFixed ? law.growth : law.height;
    free = extrapolate([&law](const PlacedLine& placedLine) {
      return law.heightFixed ? placedLine.law.growth : placedLine.law.height;
    });
    if (!ordered || !(free > 0.0)) {
      t = line.history[0].parameter;
      law = line.history[0].law;
    }
    return line.placer.place(line.polynomial, law, t, line.points);
  }

  // The geometric law in straight distances, started from the last lines along the row or else
  // from the law in arc length; the line joins the history.
  void placeByChords(size_t b, const std::array<int, 3>& base, WallLine& line) const {
    std::vector<double>& t = line.parameter;
    ChordLaw law;
    if (!placeFromLastLines(b, base, law, line)) {
      layOutInArcLength(b, base, law, line);
      if (!line.placer.place(line.polynomial, law, t, line.points)) {
        throw SolverError(blockText(b) + ": the wall-normal line at (" + std::to_string(base[0]) + ", " +
                          std::to_string(base[1]) + ", " + std::to_string(base[2]) +
                          ") takes no geometric law in point distances (does it fold back?)");
      }
    }
    if (firstHeight_ > 0.0 && law.growth > options_.growth * (1.0 + 1e-12)) {
      tabulateLine(b, base, line);
      const double length = line.arc.length();
      throw InvalidInputError(blockText(b) + ": a first cell height of " + numberText(firstHeight_) +
                              " over " + numberText(length) + " with " + std::to_string(points_) +
                              " wall-normal points needs a growth ratio of " + numberText(law.growth) +
                              ", above the maximum " + numberText(options_.growth) + "; at least " +
                              std::to_string(geometricPointsNeeded(firstHeight_, options_.growth, length)) +
                              " points are needed (normal_points = 0 picks them)");
    }
    std::rotate(line.history.begin(), line.history.end() - 1, line.history.end());
    line.history[0].block = b;
    line.history[0].ijk = base;
    line.history[0].law = law;
    line.history[0].parameter.swap(t);  // t's storage is refilled before its next use
  }

  // The line's points into the grid, measured here, where they are at hand (in the grid they lie
  // far apart).
  void store(const BlockPlan& plan, const std::array<int, 3>& base, WallLine& line, GridBlock& grid) const {
    const std::vector<Eigen::Vector3d>& x = line.points;
    std::array<int, 3> ijk = base;
    double previousStep = 0.0;
    for (int k = 0; k < points_; ++k) {
      ijk[static_cast<size_t>(plan.normalDirection)] = plan.wallEnd == 0 ? k : points_ - 1 - k;
      grid.points.row(grid.index(ijk[0], ijk[1], ijk[2])) = x[static_cast<size_t>(k)].transpose();
      if (k > 0) {
        const double gap = (x[static_cast<size_t>(k)] - x[static_cast<size_t>(k - 1)]).norm();
        if (k == 1) {
          line.measured.firstHeightMin = std::min(line.measured.firstHeightMin, gap);
          line.measured.firstHeightMax = std::max(line.measured.firstHeightMax, gap);
        } else {
          line.measured.growthMax = std::max(line.measured.growthMax, gap / previousStep);
        }
        previousStep = gap;
      }
    }
  }

  const std::vector<volume::Block>& blocks_;
  const std::vector<BlockPlan>& plans_;
  const RefinementOptions& options_;
  double firstHeight_;
  int points_;
  std::vector<double> unitSums_;
  bool byChords_;
};

}  // namespace

SlideShares slideShares(const std::vector<volume::Block>& blocks, const std::vector<BlockPlan>& plans,
                        bool on) {
  SlideShares shares;
  if (!on) return shares;
  Eigen::Vector3d lower = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d upper = -lower;
  std::map<int, std::pair<std::vector<double>, long>> distanceSums;  // by pole count: sums, columns
  for (size_t b = 0; b < blocks.size(); ++b) {
    const int n = plans[b].normalDirection;
    if (n < 0) return {};
    const BsplineVolume& volume = blocks[b].volume;
    const int count = volume.poleCount(n);
    const auto [t1, t2] = otherDirections(n);
    auto& [sums, columns] = distanceSums[count];
    sums.resize(static_cast<size_t>(count), 0.0);
    std::array<int, 3> ijk{};
    for (int a2 = 0; a2 < volume.poleCount(t2); ++a2) {
      for (int a1 = 0; a1 < volume.poleCount(t1); ++a1) {
        ijk[static_cast<size_t>(t1)] = a1;
        ijk[static_cast<size_t>(t2)] = a2;
        double distance = 0.0;
        Eigen::Vector3d before;
        for (int q = 0; q < count; ++q) {
          ijk[static_cast<size_t>(n)] = plans[b].wallEnd == 0 ? q : count - 1 - q;
          const Eigen::Vector3d pole =
              volume.poles().row(volume.poleIndex(ijk[0], ijk[1], ijk[2])).transpose();
          if (q == 0) {
            lower = lower.cwiseMin(pole);
            upper = upper.cwiseMax(pole);
          } else {
            distance += (pole - before).norm();
          }
          sums[static_cast<size_t>(q)] += distance;
          before = pole;
        }
        ++columns;
      }
    }
  }
  const double start = kSlideStart * (upper - lower).norm();
  for (auto& [count, sumsAndColumns] : distanceSums) {
    const auto& [sums, columns] = sumsAndColumns;
    const double outer = sums.back() / static_cast<double>(columns);
    std::vector<double>& share = shares[count];
    share.assign(sums.size(), 0.0);
    if (!(outer > start)) continue;
    for (size_t q = 0; q < sums.size(); ++q) {
      const double distance = sums[q] / static_cast<double>(columns);
      const double r =
          distance > start ? std::min(1.0, std::log(distance / start) / std::log(outer / start)) : 0.0;
      share[q] = r * r * (3.0 - 2.0 * r);
    }
    share.back() = 1.0;
  }
  return shares;
}

int fewestWallNormalPoints(const std::vector<volume::Block>& blocks, const std::vector<BlockPlan>& plans,
                           double firstHeight, double growth, const SlideShares& shares) {
  // What the longest line needs. A line is no longer than its control polygon, and that no
  // longer than the longest pole column it is blended from, so each column's need is bounded
  // without its line; lines are measured longest bound first, until no bound left could need
  // more points than the lines measured so far. The count is the same as measuring every line,
  // at a few of them.
  const Columns columns(blocks, plans, shares);
  const std::vector<double> bound =
      columns.sliding() ? slidLineBounds(columns) : columnLengthBounds(blocks, plans, columns.offset());
  std::vector<std::int64_t> order(bound.size());
  std::iota(order.begin(), order.end(), std::int64_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::int64_t a, std::int64_t c) {
    return bound[static_cast<size_t>(a)] > bound[static_cast<size_t>(c)];
  });
  constexpr std::int64_t kLinesPerRound = 64;
  int normalPoints = 2;
  std::mutex guard;
  for (size_t next = 0; next < order.size();) {
    if (geometricPointsNeeded(firstHeight, growth, bound[static_cast<size_t>(order[next])]) <= normalPoints)
      break;
    const std::int64_t round =
        std::min<std::int64_t>(kLinesPerRound, static_cast<std::int64_t>(order.size() - next));
    parallelChunks(round, 8, [&](std::int64_t begin, std::int64_t end) {
      WallLine line;
      for (std::int64_t k = begin; k < end; ++k) {
        const std::int64_t column = order[next + static_cast<size_t>(k)];
        columns.forRange(column, column + 1, [&](size_t b, const std::array<int, 3>& ijk) {
          columns.load(b, ijk, line);
          tabulateLine(b, ijk, line);
          const int needed = geometricPointsNeeded(firstHeight, growth, line.arc.length());
          const std::lock_guard<std::mutex> lock(guard);
          normalPoints = std::max(normalPoints, needed);
        });
      }
    });
    next += static_cast<size_t>(round);
  }
  return normalPoints;
}

LineMeasures placeWallLines(const std::vector<volume::Block>& blocks, const std::vector<BlockPlan>& plans,
                            const RefinementOptions& options, const SlideShares& shares, double firstHeight,
                            int points, std::vector<GridBlock>& grids) {
  const Columns columns(blocks, plans, shares);
  const LinePlacement placement(blocks, plans, options, firstHeight, points);
  LineMeasures measured = columns.forEvery([&](size_t b, const std::array<int, 3>& base, WallLine& line) {
    placement.place(b, base, line, grids[b]);
  });
  if (columns.offset().back() == 0) measured.firstHeightMin = 0.0;  // no wall
  return measured;
}

}  // namespace bvmesh::grid

#include "core/grid/refinement.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <future>
#include <limits>
#include <mutex>
#include <numeric>
#include <optional>
#include <string>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"
#include "core/common/parallel.h"
#include "core/grid/block_plan.h"
#include "core/grid/direction_sets.h"
#include "core/grid/distribution.h"
#include "core/grid/outer_quads.h"

namespace bvmesh::grid {
namespace {

using volume::BlockMesh;
using volume::BsplineVolume;

// Wall-normal lines' arc-length tables sample each knot span once (Simpson + Hermite on polynomial
// pieces): they are only the start of Newton's placement by straight distances, which corrects them.
constexpr int kLineIntervalsPerSpan = 1;

void checkOptions(const RefinementOptions& options) {
  auto positiveOrZero = [](double value, const char* name) {
    if (!std::isfinite(value) || value < 0.0) {
      throw InvalidInputError(std::string(name) + " must be a finite number >= 0 (got " + std::to_string(value) + ")");
    }
  };
  positiveOrZero(options.firstCellHeight, "first_cell_height");
  positiveOrZero(options.yPlus, "y_plus");
  positiveOrZero(options.reynoldsNumber, "reynolds_number");
  positiveOrZero(options.referenceLength, "reference_length");
  positiveOrZero(options.tangentialSpacing, "tangential_spacing");
  positiveOrZero(options.edgeEndSpacing, "edge_end_spacing");
  if (!std::isfinite(options.maxTurningDegrees) || options.maxTurningDegrees < 0.0 || options.maxTurningDegrees > 90.0) {
    throw InvalidInputError("max_turning_angle must be 0 (none) or a number of degrees up to 90 (got " +
                            std::to_string(options.maxTurningDegrees) + ")");
  }
  if (!std::isfinite(options.maxSpacingJump) ||
      (options.maxSpacingJump != 0.0 && options.maxSpacingJump < 1.0)) {
    throw InvalidInputError("max_spacing_jump must be 0 (none) or a ratio >= 1 (got " +
                            std::to_string(options.maxSpacingJump) + ")");
  }
  if (!std::isfinite(options.growth) || options.growth <= 1.0 || options.growth > 3.0) {
    throw InvalidInputError("growth must be in (1, 3] (got " + std::to_string(options.growth) + ")");
  }
  if (options.normalPoints != 0 && (options.normalPoints < 2 || options.normalPoints > 100000)) {
    throw InvalidInputError("normal_points must be 0 (automatic) or 2 .. 100000 (got " +
                            std::to_string(options.normalPoints) + ")");
  }
  if (options.edgePoints < 2 || options.edgePoints > 100000) {
    throw InvalidInputError("edge_points must be 2 .. 100000 (got " + std::to_string(options.edgePoints) + ")");
  }
  // 2e9 cells are 100 GB of points and topology: beyond any machine this runs on.
  if (options.targetCells < 0 || options.targetCells > 2000000000LL) {
    throw InvalidInputError("target_cells must be 0 (none) or up to 2e9, got " + std::to_string(options.targetCells));
  }
  if (options.normalPoints == 0 && options.firstCellHeight == 0.0 && options.yPlus == 0.0) {
    throw InvalidInputError("automatic normal_points (0) needs a first cell height or a y+ target");
  }
}

// Three significant digits at any scale (std::to_string prints 0.000000 below 1e-6).
std::string shortNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

// What the wall-normal lines measure: the first point's distance from the wall, the largest
// ratio of consecutive spacings.
struct LineMeasures {
  double firstHeightMin = std::numeric_limits<double>::infinity();
  double firstHeightMax = 0.0;
  double growthMax = 0.0;

  void add(const LineMeasures& other) {
    firstHeightMin = std::min(firstHeightMin, other.firstHeightMin);
    firstHeightMax = std::max(firstHeightMax, other.firstHeightMax);
    growthMax = std::max(growthMax, other.growthMax);
  }
};

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
  BsplineCurve curve;          // for its exact ends and Newton on the first height
  PolynomialCurve polynomial;  // the same curve in pieces, for everything else
  ArcLength arc;
  std::vector<double> distance, parameter;
  std::vector<Eigen::Vector3d> points;
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

}  // namespace

RefinedGrid refineBlockMesh(const BlockMesh& mesh, const RefinementOptions& options) {
  checkOptions(options);
  const auto& blocks = mesh.blocks();
  const size_t blockCount = blocks.size();
  if (blockCount == 0) throw InvalidInputError("the block mesh has no blocks to refine");

  const double firstHeight = options.firstCellHeight > 0.0 ? options.firstCellHeight
                             : options.yPlus > 0.0
                                 ? flatPlateFirstCellHeight(options.yPlus, options.reynoldsNumber, options.referenceLength)
                                 : 0.0;
  std::vector<BlockPlan> plans = planDirectionSets(blocks, options, firstHeight);

  // Wall-normal lines: per column the line along the normal direction through the tangential
  // parameters blended at the wall end; points at the wall law's distances along its arc length.
  std::vector<GridBlock> gridBlocks(blockCount);
  // Automatic: the edges' estimate served the cell target; the lines themselves decide.
  const bool automaticNormal = options.normalPoints == 0;
  int normalPoints = automaticNormal ? 2 : options.normalPoints;
  std::vector<std::optional<SpanPolynomials>> columnSpans(blockCount);
  // The columns of every wall block numbered one block after the other, so that one pool of
  // threads shares them all (blocks differ in size by orders of magnitude).
  std::vector<std::int64_t> columnOffset{0};
  for (size_t b = 0; b < blockCount; ++b) {
    const int n = plans[b].normalDirection;
    std::int64_t columns = 0;
    if (n >= 0) {
      columnSpans[b].emplace(blocks[b].volume.knots(n), blocks[b].volume.degree(n));
      const auto [t1, t2] = otherDirections(n);
      columns = static_cast<std::int64_t>(plans[b].size[static_cast<size_t>(t1)]) * plans[b].size[static_cast<size_t>(t2)];
    }
    columnOffset.push_back(columnOffset.back() + columns);
  }
  // A line's arc length, which must not be zero.
  auto tabulateLine = [&](size_t b, const std::array<int, 3>& ijk, WallLine& line) {
    line.arc.tabulate(line.polynomial, kLineIntervalsPerSpan);
    if (!(line.arc.length() > 0.0)) {
      throw InvalidInputError(blockText(b) + " has a wall-normal line of zero length at (" + std::to_string(ijk[0]) +
                              ", " + std::to_string(ijk[1]) + ", " + std::to_string(ijk[2]) + ")");
    }
  };
  // Calls work(b, ijk) for the columns [begin, end) (ijk with index 0 along the normal).
  auto forColumns = [&](std::int64_t begin, std::int64_t end, auto&& work) {
    size_t b = static_cast<size_t>(std::upper_bound(columnOffset.begin(), columnOffset.end(), begin) - columnOffset.begin()) - 1;
    for (std::int64_t c = begin; c < end; ++c) {
      while (c >= columnOffset[b + 1]) ++b;
      const auto [t1, t2] = otherDirections(plans[b].normalDirection);
      const int n1 = plans[b].size[static_cast<size_t>(t1)];
      const std::int64_t local = c - columnOffset[b];
      std::array<int, 3> ijk{0, 0, 0};
      ijk[static_cast<size_t>(t1)] = static_cast<int>(local % n1);
      ijk[static_cast<size_t>(t2)] = static_cast<int>(local / n1);
      work(b, ijk);
    }
  };
  // Calls work(b, ijk, line) for every column, `line` holding its wall-normal line; returns what
  // the work measured into the lines. Chunks of columns are fixed whatever the threads, and each
  // starts afresh, so the lines come out the same bit for bit.
  // Sets `line` to the wall-normal line of column (b, ijk).
  auto loadLine = [&](size_t b, const std::array<int, 3>& ijk, WallLine& line) {
    const BlockPlan& plan = plans[b];
    const BsplineVolume& volume = blocks[b].volume;
    const int n = plan.normalDirection;
    const auto [t1, t2] = otherDirections(n);
    if (line.block != b) {
      line.block = b;
      line.curve.degree = volume.degree(n);
      line.curve.knots = volume.knots(n);
    }
    volume.isoCurvePoles(n, pointParameter(plan, t1, ijk), pointParameter(plan, t2, ijk), line.curve.poles);
    line.polynomial.assign(line.curve.poles, *columnSpans[b]);
  };
  auto forEveryColumn = [&](auto&& work) {
    LineMeasures measured;
    std::mutex guard;
    parallelChunks(columnOffset.back(), 256, [&](std::int64_t begin, std::int64_t end) {
      WallLine line;
      forColumns(begin, end, [&](size_t b, const std::array<int, 3>& ijk) {
        loadLine(b, ijk, line);
        work(b, ijk, line);
      });
      const std::lock_guard<std::mutex> lock(guard);
      measured.add(line.measured);
    });
    return measured;
  };
  if (automaticNormal) {
    // The fewest points that keep every line's growth within the maximum: what the longest line
    // needs. A line is no longer than its control polygon, and that no longer than the longest
    // pole column it is blended from, so each column's need is bounded without its line; lines
    // are measured longest bound first, until no bound left could need more points than the
    // lines measured so far. The count is the same as measuring every line, at a few of them.
    const std::vector<double> bound = columnLengthBounds(blocks, plans, columnOffset);
    std::vector<std::int64_t> order(bound.size());
    std::iota(order.begin(), order.end(), std::int64_t{0});
    std::stable_sort(order.begin(), order.end(), [&](std::int64_t a, std::int64_t c) {
      return bound[static_cast<size_t>(a)] > bound[static_cast<size_t>(c)];
    });
    constexpr std::int64_t kLinesPerRound = 64;
    std::mutex guard;
    for (size_t next = 0; next < order.size();) {
      if (geometricPointsNeeded(firstHeight, options.growth, bound[static_cast<size_t>(order[next])]) <=
          normalPoints)
        break;
      const std::int64_t round =
          std::min<std::int64_t>(kLinesPerRound, static_cast<std::int64_t>(order.size() - next));
      parallelChunks(round, 8, [&](std::int64_t begin, std::int64_t end) {
        WallLine line;
        for (std::int64_t k = begin; k < end; ++k) {
          const std::int64_t column = order[next + static_cast<size_t>(k)];
          forColumns(column, column + 1, [&](size_t b, const std::array<int, 3>& ijk) {
            loadLine(b, ijk, line);
            tabulateLine(b, ijk, line);
            const int needed = geometricPointsNeeded(firstHeight, options.growth, line.arc.length());
            const std::lock_guard<std::mutex> lock(guard);
            normalPoints = std::max(normalPoints, needed);
          });
        }
      });
      next += static_cast<size_t>(round);
    }
  }
  for (size_t b = 0; b < blockCount; ++b) {
    BlockPlan& plan = plans[b];
    if (plan.normalDirection >= 0) plan.size[static_cast<size_t>(plan.normalDirection)] = normalPoints;
    GridBlock& grid = gridBlocks[b];
    grid.size = plan.size;
    grid.faces = blocks[b].faces;
    grid.points.resize(grid.pointCount(), 3);
  }
  // Which points are shared follows from the sizes alone: found on a thread of its own while the
  // points are computed.
  std::vector<std::array<volume::BlockFace, 6>> faces;
  std::vector<std::array<int, 3>> sizes;
  std::vector<Eigen::Index> offset{0};
  for (const GridBlock& grid : gridBlocks) {
    faces.push_back(grid.faces);
    sizes.push_back(grid.size);
    offset.push_back(offset.back() + grid.pointCount());
  }
  std::future<std::vector<Eigen::Index>> sharedRoots =
      std::async(std::launch::async, [&faces, &sizes] { return volume::sharedGridRoots(faces, sizes); });
  for (size_t b = 0; b < blockCount; ++b) {
    const BlockPlan& plan = plans[b];
    if (plan.normalDirection >= 0) continue;
    // No wall-normal direction: every parameter blended from the block's edges.
    GridBlock& grid = gridBlocks[b];
    RowMatrixX3d parameters(grid.pointCount(), 3);
    for (int k = 0; k < grid.size[2]; ++k) {
      for (int j = 0; j < grid.size[1]; ++j) {
        for (int i = 0; i < grid.size[0]; ++i) {
          const std::array<int, 3> ijk{i, j, k};
          for (int d = 0; d < 3; ++d) parameters(grid.index(i, j, k), d) = pointParameter(plan, d, ijk);
        }
      }
    }
    blocks[b].volume.evaluate(parameters, grid.points);
  }
  const int points = normalPoints;
  // Without a first cell height every line has the same geometric law up to its length: its
  // sums 1 + g + ... + g^(k-1) serve them all.
  const std::vector<double> unitSums =
      firstHeight > 0.0 ? std::vector<double>{} : geometricDistances(points, 1.0, options.growth, 1.0);
  const bool byChords = firstHeight == 0.0 || options.distribution == WallDistribution::Geometric;
  const LineMeasures measured = forEveryColumn([&](size_t b, const std::array<int, 3>& base, WallLine& line) {
    const BlockPlan& plan = plans[b];
    GridBlock& grid = gridBlocks[b];
    const int n = plan.normalDirection;
    std::vector<double>& t = line.parameter;
    std::vector<Eigen::Vector3d>& x = line.points;
    x.resize(static_cast<size_t>(points));
    x.front() = line.curve.point(parameterAtEnd(blocks[b].volume, n, plan.wallEnd));
    x.back() = line.curve.point(parameterAtEnd(blocks[b].volume, n, 1 - plan.wallEnd));
    // The law laid out in arc length: the start for lines placed by chords, the tanh law itself.
    ChordLaw law;
    auto inArcLength = [&] {
      tabulateLine(b, base, line);
      const double length = line.arc.length();
      std::vector<double>& distance = line.distance;
      if (firstHeight == 0.0) {
        law.heightFixed = false;
        law.growth = options.growth;
        law.height = length * (options.growth - 1.0) / std::expm1((points - 1) * std::log(options.growth));
        distance.resize(static_cast<size_t>(points));
        for (size_t k = 0; k < distance.size(); ++k) distance[k] = law.height * unitSums[k];
        distance.back() = length;
      } else if (options.distribution == WallDistribution::Tanh) {
        distance = tanhWallFractions(points, firstHeight / length);
        for (double& d : distance) d *= length;
      } else {
        law.height = firstHeight;
        law.growth = geometricGrowth(points, firstHeight, length);
        distance = geometricDistances(points, firstHeight, law.growth, length);
      }
      line.arc.parametersAt(distance, plan.wallEnd, t);
      t.front() = parameterAtEnd(blocks[b].volume, n, plan.wallEnd);
      t.back() = parameterAtEnd(blocks[b].volume, n, 1 - plan.wallEnd);
    };
    if (!byChords) {
      inArcLength();
      // Only the first height is exact here; the rest follows the tanh law in arc length.
      if (points > 2) t[1] = parameterAtDistance(line.curve, t.front(), plan.wallEnd == 0 ? 1 : -1, firstHeight, t[1]);
      if (points > 2) line.polynomial.evaluate(&t[1], t.size() - 2, &x[1], nullptr);
    } else {
      const int along = otherDirections(n)[0];
      // How many of the last lines lead up to this one along its row (0 .. 3), and the start
      // extrapolated from them (polynomial in the column index), kept if it leaves the points in
      // order and the law's free parameter positive.
      size_t known = 0;
      while (known < line.history.size() &&
             nextInRow(line.history[known], b, known == 0 ? base : line.history[known - 1].ijk, along)) {
        ++known;
      }
      bool placed = false;
      if (known > 0) {
        static constexpr double kWeights[3][3] = {{1.0, 0.0, 0.0}, {2.0, -1.0, 0.0}, {3.0, -3.0, 1.0}};
        const double* weight = kWeights[known - 1];
        auto extrapolate = [&](auto value) {
          double sum = 0.0;
          for (size_t h = 0; h < known; ++h) sum += weight[h] * value(line.history[h]);
          return sum;
        };
        t.resize(line.history[0].parameter.size());
        const double direction = line.history[0].parameter.back() > line.history[0].parameter.front() ? 1.0 : -1.0;
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
        placed = line.placer.place(line.polynomial, law, t, x);
      }
      if (!placed) {
        inArcLength();
        if (!line.placer.place(line.polynomial, law, t, x)) {
          throw SolverError(blockText(b) + ": the wall-normal line at (" + std::to_string(base[0]) + ", " +
                            std::to_string(base[1]) + ", " + std::to_string(base[2]) +
                            ") takes no geometric law in point distances (does it fold back?)");
        }
      }
      if (firstHeight > 0.0 && law.growth > options.growth * (1.0 + 1e-12)) {
        tabulateLine(b, base, line);
        const double length = line.arc.length();
        throw InvalidInputError(blockText(b) + ": a first cell height of " + std::to_string(firstHeight) + " over " +
                                std::to_string(length) + " with " + std::to_string(points) +
                                " wall-normal points needs a growth ratio of " + std::to_string(law.growth) +
                                ", above the maximum " + std::to_string(options.growth) + "; at least " +
                                std::to_string(geometricPointsNeeded(firstHeight, options.growth, length)) +
                                " points are needed (normal_points = 0 picks them)");
      }
      std::rotate(line.history.begin(), line.history.end() - 1, line.history.end());
      line.history[0].block = b;
      line.history[0].ijk = base;
      line.history[0].law = law;
      line.history[0].parameter.swap(t);  // t's storage is refilled before its next use
    }
    std::array<int, 3> ijk = base;
    double previousStep = 0.0;
    for (int k = 0; k < points; ++k) {
      ijk[static_cast<size_t>(n)] = plan.wallEnd == 0 ? k : points - 1 - k;
      grid.points.row(grid.index(ijk[0], ijk[1], ijk[2])) = x[static_cast<size_t>(k)].transpose();
      // Measured here, where the line's points are at hand (in the grid they lie far apart).
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
  });

  // Shared points made identical (the first block's copy wins), after checking they agree to
  // 1e-9 of the model (the largest block's pole box, which holds its points), or to what their
  // coordinates resolve where that is coarser (a model far from the origin).
  double extent = 0.0, coordinateScale = 0.0;
  for (const volume::Block& block : blocks) {
    const RowMatrixX3d& poles = block.volume.poles();
    extent = std::max(extent, (poles.colwise().maxCoeff() - poles.colwise().minCoeff()).norm());
    coordinateScale = std::max(coordinateScale, poles.cwiseAbs().maxCoeff());
  }
  const double sharedTolerance = std::max(1e-9 * extent, 64.0 * std::numeric_limits<double>::epsilon() * coordinateScale);
  const std::vector<Eigen::Index> roots = sharedRoots.get();
  auto locate = [&](Eigen::Index global) {
    const size_t b = static_cast<size_t>(std::upper_bound(offset.begin(), offset.end(), global) - offset.begin()) - 1;
    return std::pair<size_t, Eigen::Index>{b, global - offset[b]};
  };
  // Each copy reads a root, which is never written: chunks run in parallel; the first
  // disagreement in point order is reported, whatever the threads' timing.
  std::atomic<Eigen::Index> firstApart{std::numeric_limits<Eigen::Index>::max()};
  parallelChunks(offset.back(), 1 << 16, [&](std::int64_t begin, std::int64_t end) {
    size_t b = locate(begin).first;
    for (Eigen::Index global = begin; global < end; ++global) {
      while (global >= offset[b + 1]) ++b;
      const Eigen::Index root = roots[static_cast<size_t>(global)];
      if (root == global) continue;
      const auto [rb, rrow] = locate(root);
      auto mine = gridBlocks[b].points.row(global - offset[b]);
      const auto theirs = gridBlocks[rb].points.row(rrow);
      if ((mine - theirs).norm() > sharedTolerance) {
        Eigen::Index known = firstApart.load();
        while (global < known && !firstApart.compare_exchange_weak(known, global)) {
        }
        return;
      }
      mine = theirs;
    }
  });
  if (firstApart.load() != std::numeric_limits<Eigen::Index>::max()) {
    const auto [b, row] = locate(firstApart.load());
    const auto [rb, rrow] = locate(roots[static_cast<size_t>(firstApart.load())]);
    const double gap = (gridBlocks[b].points.row(row) - gridBlocks[rb].points.row(rrow)).norm();
    throw SolverError(blockText(b) + " point " + std::to_string(row) + " and " + blockText(rb) + " point " +
                      std::to_string(rrow) + " are shared but " + shortNumber(gap) +
                      " apart: the distributions disagree across a shared face (block layout not supported)");
  }

  RefinedGrid result;
  result.normalPoints = normalPoints;
  result.firstCellHeightAsked = firstHeight;
  result.firstCellHeightMin = columnOffset.back() > 0 ? measured.firstHeightMin : 0.0;
  result.firstCellHeightMax = measured.firstHeightMax;
  result.growthMax = measured.growthMax;
  if (options.outerDomain) result.outerFacesSplit = tagOuterQuads(gridBlocks, *options.outerDomain);
  result.grid = StructuredGrid(std::move(gridBlocks), firstHeight > 0.0);
  return result;
}

}  // namespace bvmesh::grid
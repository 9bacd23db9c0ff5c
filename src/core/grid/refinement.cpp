#include "core/grid/refinement.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <future>
#include <limits>
#include <map>
#include <mutex>
#include <numeric>
#include <optional>
#include <string>
#include <tuple>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"
#include "core/common/parallel.h"
#include "core/grid/distribution.h"
#include "core/grid/outer_quads.h"

namespace bvmesh::grid {
namespace {

using volume::BlockMesh;
using volume::BoundaryCondition;
using volume::BsplineVolume;

// Arc-length tables sample each knot span this often (Simpson + Hermite on polynomial pieces).
// Block edges: their tangential distributions follow arc length to about 1e-6. Wall-normal
// lines: only the start of Newton's placement by straight distances, which corrects them.
constexpr int kIntervalsPerSpan = 4;
constexpr int kLineIntervalsPerSpan = 1;
// Turning tables sample block edges this often per knot (a cubic span turns smoothly).
constexpr int kTurningSamplesPerSpan = 16;
// A set's shared measure is tabulated at this many fractions of arc length.
constexpr int kSharedMeasureSamples = 2048;

// The other two directions of `direction`, in increasing order.
std::array<int, 2> otherDirections(int direction) {
  return direction == 0 ? std::array<int, 2>{1, 2} : direction == 1 ? std::array<int, 2>{0, 2} : std::array<int, 2>{0, 1};
}

// Block directions (node 3 b + d) joined through connected faces, with the orientation of each
// relative to its set's root (parity 1: reversed).
class DirectionSets {
 public:
  explicit DirectionSets(int nodes) : parent_(static_cast<size_t>(nodes)), parity_(static_cast<size_t>(nodes), 0) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  std::pair<int, int> find(int x) {
    int parity = 0;
    while (parent_[static_cast<size_t>(x)] != x) {
      parity ^= parity_[static_cast<size_t>(x)];
      x = parent_[static_cast<size_t>(x)];
    }
    return {x, parity};
  }
  // Joins a and b, b reversed relative to a if `reversed`. False if that contradicts an earlier join.
  bool join(int a, int b, bool reversed) {
    const auto [ra, pa] = find(a);
    const auto [rb, pb] = find(b);
    const int wanted = pa ^ pb ^ (reversed ? 1 : 0);
    if (ra == rb) return wanted == 0;
    parent_[static_cast<size_t>(rb)] = ra;
    parity_[static_cast<size_t>(rb)] = wanted;
    return true;
  }

 private:
  std::vector<int> parent_;
  std::vector<int> parity_;
};

struct BlockPlan {
  std::array<int, 3> size{0, 0, 0};
  int normalDirection = -1;  // the wall-normal (column) direction, or -1
  int wallEnd = 0;           // 0: clustered at its lower end, 1: at its upper end
  // Per direction the parameters along its four edges; edge e = s1 + 2 s2 at the ends s1, s2 of
  // the two other directions (in increasing order).
  std::array<std::array<std::vector<double>, 4>, 3> edgeParameters;
};

double parameterAtEnd(const BsplineVolume& volume, int direction, int end) {
  return end == 0 ? volume.lower(direction) : volume.upper(direction);
}

BsplineCurve edgeCurve(const BsplineVolume& volume, int direction, int edge) {
  const auto [first, second] = otherDirections(direction);
  return volume.isoCurve(direction, parameterAtEnd(volume, first, edge & 1), parameterAtEnd(volume, second, edge >> 1));
}

// The parameter along `direction` at fractions (f1, f2) of the two other directions' index ranges:
// the bilinear blend of the four edges' parameters at index i.
double blendedParameter(const BlockPlan& plan, int direction, int i, double f1, double f2) {
  const auto& edges = plan.edgeParameters[static_cast<size_t>(direction)];
  const size_t at = static_cast<size_t>(i);
  return (1 - f1) * (1 - f2) * edges[0][at] + f1 * (1 - f2) * edges[1][at] + (1 - f1) * f2 * edges[2][at] +
         f1 * f2 * edges[3][at];
}

// Whether edge `edge` along `direction` lies on the block's wall face (or the block has no wall).
bool onWallOrNoWall(const BlockPlan& plan, int direction, int edge) {
  const int n = plan.normalDirection;
  if (n < 0 || n == direction) return true;
  const auto [first, second] = otherDirections(direction);
  return n == first ? (edge & 1) == plan.wallEnd : (edge >> 1) == plan.wallEnd;
}

// Index fraction along `direction`, or the clustered end when that is the wall-normal direction.
double fraction(const BlockPlan& plan, int direction, int index) {
  if (direction == plan.normalDirection) return plan.wallEnd;
  return static_cast<double>(index) / (plan.size[static_cast<size_t>(direction)] - 1);
}

// The parameter along `direction` of grid point ijk: its edges blended by the index fractions of
// the other two directions (the wall-normal one held at its wall end).
double pointParameter(const BlockPlan& plan, int direction, const std::array<int, 3>& ijk) {
  const auto [first, second] = otherDirections(direction);
  return blendedParameter(plan, direction, ijk[static_cast<size_t>(direction)],
                          fraction(plan, first, ijk[static_cast<size_t>(first)]),
                          fraction(plan, second, ijk[static_cast<size_t>(second)]));
}

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

std::string blockText(size_t b) { return "block " + std::to_string(b); }

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

// Per set (indexed by its root) and shared end, the step at that end as a fraction of the set's
// longest counted edge that keeps the jump to the finest continuing wall edge within maxJump (as
// far as an eighth of the set's mean spacing goes), or 0 where the set's own spacing already
// does. Continuations: the wall edges of other blocks or directions that start at the end's
// corner (shared corners are bit-identical points) and leave it within 45 degrees of straight
// on; their spacing is their mean (length over cells).
std::vector<std::array<double, 2>> continuationEndSteps(
    const std::vector<volume::Block>& blocks, const std::vector<BlockPlan>& plans, DirectionSets& sets,
    const std::vector<std::array<std::vector<ArcLength>, 3>>& edgeArcs, const std::vector<int>& counts,
    const std::vector<double>& longestEdge, double maxJump) {
  struct EdgeEnd {
    std::array<double, 3> corner;
    Eigen::Vector3d outward;  // unit tangent from the corner into the edge
    double spacing;
    size_t root;
    int sharedEnd;  // 0: the set's start, 1: its end
  };
  std::vector<EdgeEnd> ends;
  for (size_t b = 0; b < blocks.size(); ++b) {
    const int n = plans[b].normalDirection;
    if (n < 0) continue;
    for (int d = 0; d < 3; ++d) {
      if (d == n) continue;
      const auto [root, parity] = sets.find(static_cast<int>(3 * b) + d);
      for (int e = 0; e < 4; ++e) {
        if (!onWallOrNoWall(plans[b], d, e)) continue;
        // A clamped curve starts at its first pole, leaving towards its second.
        const RowMatrixX3d& poles = edgeCurve(blocks[b].volume, d, e).poles;
        const double spacing = edgeArcs[b][static_cast<size_t>(d)][static_cast<size_t>(e)].length() /
                               (counts[3 * b + static_cast<size_t>(d)] - 1);
        for (int end = 0; end < 2; ++end) {
          const Eigen::Index at = end == 0 ? 0 : poles.rows() - 1;
          const Eigen::Index next = end == 0 ? 1 : poles.rows() - 2;
          const Eigen::Vector3d corner = poles.row(at).transpose();
          ends.push_back({{corner.x(), corner.y(), corner.z()},
                          (poles.row(next).transpose() - corner).normalized(),
                          spacing,
                          static_cast<size_t>(root),
                          end ^ parity});
        }
      }
    }
  }
  std::map<std::array<double, 3>, std::vector<size_t>> atCorner;
  for (size_t k = 0; k < ends.size(); ++k) atCorner[ends[k].corner].push_back(k);
  const double straightOn = std::cos(M_PI / 4.0);
  std::vector<std::array<double, 2>> finest(
      counts.size(), {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()});
  for (const EdgeEnd& end : ends) {
    for (size_t other : atCorner[end.corner]) {
      if (ends[other].outward.dot(end.outward) >= -straightOn) continue;
      double& known = finest[end.root][static_cast<size_t>(end.sharedEnd)];
      known = std::min(known, ends[other].spacing);
    }
  }
  // A set is never clustered to less than an eighth of its mean spacing: a continuation far finer
  // than that (a 0.1 mm corner block beside a wing's 49 mm chordwise spacing) would squeeze the
  // whole set, and its narrower edges with it, into folded cells (on the M6's level-2 blocks at 17
  // points per edge: 8 cells with a negative Jacobian; none with the bound).
  constexpr double kMostClustering = 8.0;
  std::vector<std::array<double, 2>> steps(counts.size(), {0.0, 0.0});
  for (size_t root = 0; root < counts.size(); ++root) {
    if (!(longestEdge[root] > 0.0)) continue;
    const double own = longestEdge[root] / (counts[root] - 1);
    for (size_t end = 0; end < 2; ++end) {
      const double limited = maxJump * finest[root][end];
      if (limited < own) steps[root][end] = std::max(limited, own / kMostClustering) / longestEdge[root];
    }
  }
  return steps;
}

}  // namespace

RefinedGrid refineBlockMesh(const BlockMesh& mesh, const RefinementOptions& options) {
  checkOptions(options);
  const auto& blocks = mesh.blocks();
  const size_t blockCount = blocks.size();
  if (blockCount == 0) throw InvalidInputError("the block mesh has no blocks to refine");

  // Directions linked through connected faces share their point count (and orientation).
  DirectionSets sets(static_cast<int>(3 * blockCount));
  for (size_t b = 0; b < blockCount; ++b) {
    for (int f = 0; f < 6; ++f) {
      const volume::BlockFace& face = blocks[b].faces[static_cast<size_t>(f)];
      if (face.condition != BoundaryCondition::Connected) continue;
      const std::array<int, 2> mine = volume::faceDirections(f);
      const std::array<int, 2> theirs = volume::faceDirections(face.neighbour.face);
      for (int axis = 0; axis < 2; ++axis) {
        const int theirAxis = face.neighbour.swapped ? 1 - axis : axis;
        const bool reversed = theirAxis == 0 ? face.neighbour.reverseFirst : face.neighbour.reverseSecond;
        if (!sets.join(static_cast<int>(3 * b) + mine[static_cast<size_t>(axis)],
                       3 * face.neighbour.block + theirs[static_cast<size_t>(theirAxis)], reversed)) {
          throw InvalidInputError(blockText(b) + " face " + volume::blockFaceName(f) +
                                  ": the block connections orient a grid direction both ways round");
        }
      }
    }
  }
  // Wall-normal sets: those holding a direction with a wall at one end; wallParity per set root.
  std::vector<int> wallParity(3 * blockCount, -1);
  for (size_t b = 0; b < blockCount; ++b) {
    for (int d = 0; d < 3; ++d) {
      const bool atLower = blocks[b].faces[static_cast<size_t>(2 * d)].condition == BoundaryCondition::Wall;
      const bool atUpper = blocks[b].faces[static_cast<size_t>(2 * d + 1)].condition == BoundaryCondition::Wall;
      if (!atLower && !atUpper) continue;
      if (atLower && atUpper) {
        throw InvalidInputError(blockText(b) + " has walls at both ends of direction " + "uvw"[d] +
                                " (wall clustering from both ends is not supported)");
      }
      const auto [root, parity] = sets.find(static_cast<int>(3 * b) + d);
      const int wanted = parity ^ (atUpper ? 1 : 0);
      int& known = wallParity[static_cast<size_t>(root)];
      if (known >= 0 && known != wanted) {
        throw InvalidInputError(blockText(b) + " direction " + "uvw"[d] +
                                ": linked wall-normal lines start at walls at both ends");
      }
      known = wanted;
    }
  }
  std::vector<BlockPlan> plans(blockCount);
  for (size_t b = 0; b < blockCount; ++b) {
    for (int d = 0; d < 3; ++d) {
      const auto [root, parity] = sets.find(static_cast<int>(3 * b) + d);
      const int wall = wallParity[static_cast<size_t>(root)];
      if (wall < 0) continue;
      if (plans[b].normalDirection >= 0) {
        throw InvalidInputError(blockText(b) + " has wall-normal lines in two directions (walls on two sides)");
      }
      plans[b].normalDirection = d;
      plans[b].wallEnd = wall ^ parity;
      // A wall-normal line keeps its wall's tangential parameters up to its far end; a block
      // stacked on that end would take its own from its edges there, and the points would differ.
      const volume::BlockFace& far = blocks[b].faces[static_cast<size_t>(2 * d + 1 - plans[b].wallEnd)];
      if (far.condition == BoundaryCondition::Connected) {
        throw InvalidInputError(blockText(b) + "'s wall-normal lines end on " + blockText(static_cast<size_t>(far.neighbour.block)) +
                                " face " + volume::blockFaceName(far.neighbour.face) +
                                ": blocks stacked along the wall-normal direction are not supported (each wall-normal "
                                "line must run from the wall to the outer boundary in one block)");
      }
    }
  }

  // Tangential point counts: per set, from its wall edges (all its edges if it has none), each
  // asking for its length in spacings plus its turning in maxTurning steps. The edges' arc-length
  // and turning tables, kept for their distributions below. With a turning limit, a wall face's
  // middle grid line along each of its directions counts too (after the four edges): a face that
  // bulges turns more there than along its edges (a sphere's cube-layout face: 90 degrees across
  // its middle, 70.5 along its edges).
  const double maxTurning = options.maxTurningDegrees * M_PI / 180.0;
  std::vector<std::vector<const TurningTable*>> countedEdges(3 * blockCount);
  std::vector<double> longestEdge(3 * blockCount, 0.0);
  std::vector<std::array<std::vector<ArcLength>, 3>> edgeArcs(blockCount);
  std::vector<std::array<std::vector<TurningTable>, 3>> edgeTurning(blockCount);
  for (size_t b = 0; b < blockCount; ++b) {
    const BsplineVolume& volume = blocks[b].volume;
    for (int d = 0; d < 3; ++d) {
      const auto root = static_cast<size_t>(sets.find(static_cast<int>(3 * b) + d).first);
      edgeArcs[b][static_cast<size_t>(d)].reserve(4);
      edgeTurning[b][static_cast<size_t>(d)].reserve(5);
      auto turningOf = [&](const BsplineCurve& curve, const ArcLength& arc) -> const TurningTable& {
        // Without a turning limit the table serves arc length alone: one step.
        const int samples = maxTurning > 0.0 ? kTurningSamplesPerSpan * static_cast<int>(curve.knots.size()) : 1;
        return edgeTurning[b][static_cast<size_t>(d)].emplace_back(curve, arc, samples);
      };
      for (int e = 0; e < 4; ++e) {
        const BsplineCurve curve = edgeCurve(volume, d, e);
        const ArcLength& arc = edgeArcs[b][static_cast<size_t>(d)].emplace_back(curve, kIntervalsPerSpan);
        const TurningTable& turning = turningOf(curve, arc);
        if (onWallOrNoWall(plans[b], d, e)) {
          longestEdge[root] = std::max(longestEdge[root], arc.length());
          countedEdges[root].push_back(&turning);
        }
      }
      const int n = plans[b].normalDirection;
      if (maxTurning > 0.0 && n >= 0 && n != d) {
        const auto [first, second] = otherDirections(d);
        const int across = first == n ? second : first;
        auto at = [&](int direction) {
          return direction == n ? parameterAtEnd(volume, n, plans[b].wallEnd)
                                : 0.5 * (volume.lower(across) + volume.upper(across));
        };
        const BsplineCurve middle = volume.isoCurve(d, at(first), at(second));
        countedEdges[root].push_back(&turningOf(middle, ArcLength(middle, kIntervalsPerSpan)));
      }
    }
  }
  const double firstHeight = options.firstCellHeight > 0.0 ? options.firstCellHeight
                             : options.yPlus > 0.0
                                 ? flatPlateFirstCellHeight(options.yPlus, options.reynoldsNumber, options.referenceLength)
                                 : 0.0;
  auto countsFor = [&](double spacing, int normalPoints) {
    std::vector<int> count(3 * blockCount, 0);
    for (size_t node = 0; node < count.size(); ++node) {
      const auto root = static_cast<size_t>(sets.find(static_cast<int>(node)).first);
      if (wallParity[root] >= 0) {
        count[node] = normalPoints;
      } else if (spacing > 0.0) {
        double cells = 0.0;
        for (const TurningTable* edge : countedEdges[root]) cells = std::max(cells, edge->measure(spacing, maxTurning));
        // An edge a whole number of spacings long (to the rounding of its arc length) takes no extra point.
        count[node] = std::max(2, static_cast<int>(std::ceil(cells * (1.0 - 1e-12))) + 1);
      } else {
        count[node] = options.edgePoints;
      }
    }
    return count;
  };
  // Normal points before the columns are known (for the cell target): from the wall blocks' edges.
  int normalPoints = options.normalPoints;
  if (normalPoints == 0) {
    for (size_t b = 0; b < blockCount; ++b) {
      const int n = plans[b].normalDirection;
      if (n < 0) continue;
      for (const ArcLength& arc : edgeArcs[b][static_cast<size_t>(n)]) {
        normalPoints = std::max(normalPoints, geometricPointsNeeded(firstHeight, options.growth, arc.length()));
      }
    }
    normalPoints = std::max(normalPoints, 2);
  }
  double spacing = options.tangentialSpacing;
  if (options.targetCells > 0) {
    auto cells = [&](double h) {
      const std::vector<int> count = countsFor(h, normalPoints);
      double total = 0.0;
      for (size_t b = 0; b < blockCount; ++b) {
        total += static_cast<double>(count[3 * b] - 1) * (count[3 * b + 1] - 1) * (count[3 * b + 2] - 1);
      }
      return total;
    };
    const double longest = *std::max_element(longestEdge.begin(), longestEdge.end());
    double lo = longest * 1e-5, hi = 2.0 * longest;  // cells(lo) large, cells(hi) small
    for (int iteration = 0; iteration < 80; ++iteration) {
      const double mid = std::sqrt(lo * hi);
      (cells(mid) > static_cast<double>(options.targetCells) ? lo : hi) = mid;
    }
    spacing = hi;
  }
  const std::vector<int> tangentialCounts = countsFor(spacing, normalPoints);

  // Edge parameters of every direction but the wall-normal one, at the fractions of arc length
  // their set shares (uniform without a turning limit), or clustered at both ends, which keeps a
  // distribution the same seen from either end.
  std::vector<std::optional<SharedMeasure>> setMeasure(3 * blockCount);
  for (size_t b = 0; b < blockCount; ++b) {
    for (int d = 0; d < 3; ++d) {
      const auto [root, parity] = sets.find(static_cast<int>(3 * b) + d);
      std::optional<SharedMeasure>& shared = setMeasure[static_cast<size_t>(root)];
      if (wallParity[static_cast<size_t>(root)] >= 0) continue;
      if (!shared) {
        // With edge_points the set's spacing is what its longest counted edge gets.
        const double setSpacing = spacing > 0.0 ? spacing
                                                : longestEdge[static_cast<size_t>(root)] /
                                                      (tangentialCounts[static_cast<size_t>(root)] - 1);
        shared.emplace(kSharedMeasureSamples, setSpacing, setSpacing > 0.0 ? maxTurning : 0.0);
      }
      const std::vector<TurningTable>& tables = edgeTurning[b][static_cast<size_t>(d)];
      for (size_t e = 0; e < tables.size(); ++e) {
        if (e < 4 && !onWallOrNoWall(plans[b], d, static_cast<int>(e))) continue;
        shared->add(tables[e], parity == 1);
      }
    }
  }
  const std::vector<std::array<double, 2>> endSteps =
      options.maxSpacingJump > 0.0 ? continuationEndSteps(blocks, plans, sets, edgeArcs, tangentialCounts,
                                                          longestEdge, options.maxSpacingJump)
                                   : std::vector<std::array<double, 2>>(3 * blockCount, {0.0, 0.0});
  // A set's edges mostly ask for the same fractions (a stretched law solves for its parameter by
  // fixed-point steps, a few hundred edges over): each asked once per set.
  std::map<std::tuple<int, double, double>, std::vector<double>> fractionsOf;
  for (size_t b = 0; b < blockCount; ++b) {
    BlockPlan& plan = plans[b];
    for (int d = 0; d < 3; ++d) plan.size[static_cast<size_t>(d)] = tangentialCounts[3 * b + static_cast<size_t>(d)];
    for (int d = 0; d < 3; ++d) {
      if (d == plan.normalDirection) continue;
      const int points = plan.size[static_cast<size_t>(d)];
      const auto [root, parity] = sets.find(static_cast<int>(3 * b) + d);
      const SharedMeasure& shared = *setMeasure[static_cast<size_t>(root)];
      for (int e = 0; e < 4; ++e) {
        const ArcLength& arc = edgeArcs[b][static_cast<size_t>(d)][static_cast<size_t>(e)];
        if (!(arc.length() > 0.0)) {
          throw InvalidInputError(blockText(b) + " has an edge of zero length along " + "uvw"[d] +
                                  " (collapsed edges cannot be refined)");
        }
        // The end spacing as steps of the shared measure at the edge's two ends, in the shared
        // sense. In arc length the distribution is symmetric and read from the edge's own start
        // (so grids without a turning limit keep their points bit for bit).
        const double end = std::min(options.edgeEndSpacing / arc.length(), 0.5);
        const bool arcLength = shared.uniformInArcLength();
        double atStart = end > 0.0 ? shared.at(end) : 0.0;
        double atEnd = end > 0.0 ? (arcLength ? end : 1.0 - shared.at(1.0 - end)) : 0.0;
        // A spacing jump limited at a set end: the same fraction on every edge of the set; the
        // tighter of that and edge_end_spacing. In arc length the steps are the edge's own (its
        // start is the set's end `parity`), else the shared measure's.
        const auto& setSteps = endSteps[static_cast<size_t>(root)];
        const auto tighten = [](double& step, double limit) {
          if (limit > 0.0) step = step > 0.0 ? std::min(step, limit) : limit;
        };
        const int startEnd = arcLength ? parity : 0;
        const double startStep = setSteps[static_cast<size_t>(startEnd)];
        const double endStep = setSteps[static_cast<size_t>(1 - startEnd)];
        if (startStep > 0.0) tighten(atStart, arcLength ? startStep : shared.at(startStep));
        if (endStep > 0.0) tighten(atEnd, arcLength ? endStep : 1.0 - shared.at(1.0 - endStep));
        auto known = fractionsOf.find({root, atStart, atEnd});
        if (known == fractionsOf.end())
          known =
              fractionsOf
                  .emplace(std::make_tuple(root, atStart, atEnd), shared.fractions(points, atStart, atEnd))
                  .first;
        std::vector<double> sigma = known->second;
        if (parity == 1 && !arcLength) {
          std::reverse(sigma.begin(), sigma.end());
          for (double& x : sigma) x = 1.0 - x;
        }
        auto& parameters = plan.edgeParameters[static_cast<size_t>(d)][static_cast<size_t>(e)];
        parameters.resize(static_cast<size_t>(points));
        for (int i = 0; i < points; ++i) parameters[static_cast<size_t>(i)] = arc.parameterAt(sigma[static_cast<size_t>(i)] * arc.length());
        parameters.front() = blocks[b].volume.lower(d);
        parameters.back() = blocks[b].volume.upper(d);
      }
    }
  }

  // Wall-normal lines: per column the line along the normal direction through the tangential
  // parameters blended at the wall end; points at the wall law's distances along its arc length.
  std::vector<GridBlock> gridBlocks(blockCount);
  // Automatic: the edges' estimate served the cell target; the lines themselves decide.
  const bool automaticNormal = options.normalPoints == 0;
  if (automaticNormal) normalPoints = 2;
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

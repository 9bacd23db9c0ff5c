#include "core/grid/direction_sets.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <string>
#include <tuple>

#include "core/common/errors.h"
#include "core/common/number_text.h"
#include "core/grid/distribution.h"
#include "core/grid/feature_spacing.h"

namespace bvmesh::grid {
namespace {

using volume::BoundaryCondition;
using volume::BsplineVolume;

// Arc-length tables sample each knot span this often (Simpson + Hermite on polynomial pieces).
// Block edges: their tangential distributions follow arc length to about 1e-6.
constexpr int kIntervalsPerSpan = 4;
// Turning tables sample block edges this often per knot (a cubic span turns smoothly).
constexpr int kTurningSamplesPerSpan = 16;
// A set's shared measure is tabulated at this many fractions of arc length.
constexpr int kSharedMeasureSamples = 2048;
// Cells of a fan around a collapsed block edge (a sharp trailing edge's prisms) turn at most this
// far each: their corner at the edge has a scaled Jacobian of about its sine.
constexpr double kFanCellRadians = 30.0 * M_PI / 180.0;

// Block directions (node 3 b + d) joined through connected faces, with the orientation of each
// relative to its set's root (parity 1: reversed).
class DirectionSets {
 public:
  explicit DirectionSets(int nodes)
      : parent_(static_cast<size_t>(nodes)), parity_(static_cast<size_t>(nodes), 0) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  std::pair<int, int> find(int x) const {
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

BsplineCurve edgeCurve(const BsplineVolume& volume, int direction, int edge) {
  const auto [first, second] = otherDirections(direction);
  return volume.isoCurve(direction, parameterAtEnd(volume, first, edge & 1),
                         parameterAtEnd(volume, second, edge >> 1));
}

// Directions linked through connected faces share their point count (and orientation).
DirectionSets linkedDirections(const std::vector<volume::Block>& blocks) {
  DirectionSets sets(static_cast<int>(3 * blocks.size()));
  for (size_t b = 0; b < blocks.size(); ++b) {
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
  return sets;
}

// Wall-normal sets: those holding a direction with a wall at one end; per set root the parity of
// that end (-1: no wall).
std::vector<int> wallParities(const std::vector<volume::Block>& blocks, const DirectionSets& sets) {
  std::vector<int> wallParity(3 * blocks.size(), -1);
  for (size_t b = 0; b < blocks.size(); ++b) {
    for (int d = 0; d < 3; ++d) {
      const bool atLower = blocks[b].faces[static_cast<size_t>(2 * d)].condition == BoundaryCondition::Wall;
      const bool atUpper =
          blocks[b].faces[static_cast<size_t>(2 * d + 1)].condition == BoundaryCondition::Wall;
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
  return wallParity;
}

// Per block its wall-normal direction (a direction of a wall-normal set) and wall end.
std::vector<BlockPlan> wallNormalPlans(const std::vector<volume::Block>& blocks, const DirectionSets& sets,
                                       const std::vector<int>& wallParity) {
  std::vector<BlockPlan> plans(blocks.size());
  for (size_t b = 0; b < blocks.size(); ++b) {
    for (int d = 0; d < 3; ++d) {
      const auto [root, parity] = sets.find(static_cast<int>(3 * b) + d);
      const int wall = wallParity[static_cast<size_t>(root)];
      if (wall < 0) continue;
      if (plans[b].normalDirection >= 0) {
        throw InvalidInputError(blockText(b) +
                                " has wall-normal lines in two directions (walls on two sides)");
      }
      plans[b].normalDirection = d;
      plans[b].wallEnd = wall ^ parity;
      // A wall-normal line keeps its wall's tangential parameters up to its far end; a block
      // stacked on that end would take its own from its edges there, and the points would differ.
      const volume::BlockFace& far = blocks[b].faces[static_cast<size_t>(2 * d + 1 - plans[b].wallEnd)];
      if (far.condition == BoundaryCondition::Connected) {
        throw InvalidInputError(
            blockText(b) + "'s wall-normal lines end on " +
            blockText(static_cast<size_t>(far.neighbour.block)) + " face " +
            volume::blockFaceName(far.neighbour.face) +
            ": blocks stacked along the wall-normal direction are not supported (each wall-normal "
            "line must run from the wall to the outer boundary in one block)");
      }
    }
  }
  return plans;
}

// The line a collapsed edge along `direction` takes its distribution from: along it, through
// the middle of the block's other tangential direction and at the first knot off the wall (the
// middle, in a block without a wall); and the angle it sweeps round the point below it on the
// wall (`offWall` false), which the collapsed face's edge is.
BsplineCurve fanLine(const BsplineVolume& volume, const BlockPlan& plan, int direction, bool offWall = true) {
  const int n = plan.normalDirection;
  if (n == direction) {
    throw InvalidInputError("a block has a collapsed edge along its wall-normal direction " +
                            std::string(1, "uvw"[direction]) + " (collapsed edges must run along the wall)");
  }
  const auto [first, second] = otherDirections(direction);
  auto at = [&](int other) {
    if (other != n) return 0.5 * (volume.lower(other) + volume.upper(other));
    if (!offWall) return parameterAtEnd(volume, n, plan.wallEnd);
    const std::vector<double>& knots = volume.knots(n);
    const auto degree = static_cast<size_t>(volume.degree(n));
    return plan.wallEnd == 0 ? knots[degree + 1] : knots[knots.size() - degree - 2];
  };
  return volume.isoCurve(direction, at(first), at(second));
}

// The fan line collapsed edge `e` along `direction` (edgeCurve's numbering) places its points by
// where its block meets another fan end to end (a trailing edge turning at a crank): at the
// edge's own end of the block's other tangential direction, at the first knot off the wall, so
// that both blocks take the same line there, from their shared face's poles (each block's middle
// line, fanLine, put their points up to 5e-8 of the model apart). None elsewhere (an end on the
// symmetry plane, or closing), where the middle line serves.
std::optional<BsplineCurve> fanLineAtEdge(const volume::Block& block, const BlockPlan& plan, int direction, int e) {
  const int n = plan.normalDirection;
  if (n < 0 || n == direction) return std::nullopt;
  const auto [first, second] = otherDirections(direction);
  const int along = first == n ? second : first;  // the block's other tangential direction
  const int end = along == first ? (e & 1) : (e >> 1);
  if (block.faces[static_cast<size_t>(2 * along + end)].condition != BoundaryCondition::Connected) return std::nullopt;
  const BsplineVolume& volume = block.volume;
  auto at = [&](int other, int upper) {
    if (other != n) return upper != 0 ? volume.upper(other) : volume.lower(other);
    const std::vector<double>& knots = volume.knots(n);
    const auto degree = static_cast<size_t>(volume.degree(n));
    return plan.wallEnd == 0 ? knots[degree + 1] : knots[knots.size() - degree - 2];
  };
  return volume.isoCurve(direction, at(first, e & 1), at(second, e >> 1));
}

double sweptAngle(const BsplineCurve& fan, const BsplineCurve& below) {
  constexpr int kSamples = 64;
  const double start = fan.knots.front(), end = fan.knots.back();
  double angle = 0.0;
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (int k = 0; k <= kSamples; ++k) {
    const double t = start + (end - start) * k / kSamples;
    const Eigen::Vector3d ray = (fan.point(t) - below.point(t)).normalized();
    if (k > 0) angle += std::atan2(previous.cross(ray).norm(), previous.dot(ray));
    previous = ray;
  }
  return angle;
}

// The block edges' arc-length and turning tables, kept for their distributions, and per set
// (indexed by its root) the tables that count its points and its longest counted edge. An edge
// of zero length (on a collapsed face) takes its distribution from its block's fan line along
// that direction (fanLine); the set counts that line at the spacing and the angle it sweeps round
// the edge in fan cells.
struct EdgeTables {
  std::vector<std::array<std::vector<ArcLength>, 3>> arcs;        // per block and direction: its 4 edges
  std::vector<std::array<std::vector<TurningTable>, 3>> turning;  // the same edges, then a middle line
  std::vector<std::array<std::optional<ArcLength>, 3>> fanArcs;   // per block and direction, where an edge is collapsed
  std::vector<std::array<std::array<std::optional<ArcLength>, 4>, 3>> edgeFanArcs;  // per collapsed edge (fanLineAtEdge)
  std::vector<std::array<std::optional<TurningTable>, 3>> fanTurning;
  std::vector<std::vector<const TurningTable*>> counted;
  std::vector<std::vector<const TurningTable*>> countedFans;
  std::vector<double> fanAngle;  // per set, the largest angle a fan line of it sweeps round its edge
  std::vector<double> longestEdge;
  std::vector<std::array<std::array<bool, 4>, 3>> collapsed;  // per block, direction and edge

  // The arc-length table edge e of (b, d) places its points by: its own, or a fan line's.
  const ArcLength& placing(size_t b, int d, int e) const {
    if (!collapsed[b][static_cast<size_t>(d)][static_cast<size_t>(e)])
      return arcs[b][static_cast<size_t>(d)][static_cast<size_t>(e)];
    const std::optional<ArcLength>& own = edgeFanArcs[b][static_cast<size_t>(d)][static_cast<size_t>(e)];
    return own ? *own : *fanArcs[b][static_cast<size_t>(d)];
  }
};

// Whether edge `e` along `direction` (edgeCurve's numbering) lies on a collapsed face of the
// block that is one point along `direction`.
bool onCollapsedFace(const volume::Block& block, int direction, int e) {
  const auto [first, second] = otherDirections(direction);
  for (const int face : {2 * first + (e & 1), 2 * second + (e >> 1)}) {
    const volume::BlockFace& side = block.faces[static_cast<size_t>(face)];
    if (side.condition != BoundaryCondition::Collapsed) continue;
    const std::array<int, 2> axes = volume::faceDirections(face);
    for (int axis = 0; axis < 2; ++axis) {
      if (axes[static_cast<size_t>(axis)] == direction && side.collapsedAlong[static_cast<size_t>(axis)])
        return true;
    }
  }
  return false;
}

// A turning table's samples along `curve`; without a turning limit the table serves arc length
// alone: one step.
int turningSamples(const BsplineCurve& curve, double maxTurning) {
  return maxTurning > 0.0 ? kTurningSamplesPerSpan * static_cast<int>(curve.knots.size()) : 1;
}

// A set counts its wall edges (all its edges if it has none), each asking for its length in
// spacings plus its turning in maxTurning steps. With a turning limit, a wall face's middle grid
// line along each of its directions counts too (after the four edges): a face that bulges turns
// more there than along its edges (a sphere's cube-layout face: 90 degrees across its middle,
// 70.5 along its edges).
EdgeTables tabulateEdges(const std::vector<volume::Block>& blocks, const std::vector<BlockPlan>& plans,
                         const DirectionSets& sets, double maxTurning) {
  const size_t blockCount = blocks.size();
  EdgeTables tables{std::vector<std::array<std::vector<ArcLength>, 3>>(blockCount),
                    std::vector<std::array<std::vector<TurningTable>, 3>>(blockCount),
                    std::vector<std::array<std::optional<ArcLength>, 3>>(blockCount),
                    std::vector<std::array<std::array<std::optional<ArcLength>, 4>, 3>>(blockCount),
                    std::vector<std::array<std::optional<TurningTable>, 3>>(blockCount),
                    std::vector<std::vector<const TurningTable*>>(3 * blockCount),
                    std::vector<std::vector<const TurningTable*>>(3 * blockCount),
                    std::vector<double>(3 * blockCount, 0.0),
                    std::vector<double>(3 * blockCount, 0.0),
                    std::vector<std::array<std::array<bool, 4>, 3>>(blockCount)};
  for (size_t b = 0; b < blockCount; ++b) {
    const BsplineVolume& volume = blocks[b].volume;
    for (int d = 0; d < 3; ++d) {
      const auto root = static_cast<size_t>(sets.find(static_cast<int>(3 * b) + d).first);
      std::vector<ArcLength>& arcs = tables.arcs[b][static_cast<size_t>(d)];
      std::vector<TurningTable>& turnings = tables.turning[b][static_cast<size_t>(d)];
      arcs.reserve(4);
      turnings.reserve(5);  // `counted` points into it
      auto turningOf = [&](const BsplineCurve& curve, const ArcLength& arc) -> const TurningTable& {
        return turnings.emplace_back(curve, arc, turningSamples(curve, maxTurning));
      };
      for (int e = 0; e < 4; ++e) {
        const BsplineCurve curve = edgeCurve(volume, d, e);
        const ArcLength& arc = arcs.emplace_back(curve, kIntervalsPerSpan);
        const TurningTable& turning = turningOf(curve, arc);
        const bool collapsed = onCollapsedFace(blocks[b], d, e);
        if (!collapsed && !(arc.length() > 0.0)) {
          throw InvalidInputError(blockText(b) + " has an edge of zero length along " + "uvw"[d] +
                                  " on no collapsed face (a face that is one curve or point must be declared "
                                  "'collapsed')");
        }
        tables.collapsed[b][static_cast<size_t>(d)][static_cast<size_t>(e)] = collapsed;
        if (collapsed) {
          if (const std::optional<BsplineCurve> own = fanLineAtEdge(blocks[b], plans[b], d, e)) {
            ArcLength ownArc(*own, kIntervalsPerSpan);
            if (ownArc.length() > 0.0)
              tables.edgeFanArcs[b][static_cast<size_t>(d)][static_cast<size_t>(e)].emplace(std::move(ownArc));
          }
        }
        if (collapsed && !tables.fanArcs[b][static_cast<size_t>(d)]) {
          const BsplineCurve fan = fanLine(volume, plans[b], d);
          const ArcLength& fanArc = tables.fanArcs[b][static_cast<size_t>(d)].emplace(fan, kIntervalsPerSpan);
          if (!(fanArc.length() > 0.0)) {
            throw InvalidInputError(blockText(b) + " has an edge of zero length along " + "uvw"[d] +
                                    " whose block is collapsed across its middle as well (no line to fan along)");
          }
          tables.countedFans[root].push_back(&tables.fanTurning[b][static_cast<size_t>(d)].emplace(
              fan, fanArc, turningSamples(fan, maxTurning)));
          tables.fanAngle[root] =
              std::max(tables.fanAngle[root], sweptAngle(fan, fanLine(volume, plans[b], d, false)));
        }
        if (onWallOrNoWall(plans[b], d, e)) {
          if (collapsed) continue;
          tables.longestEdge[root] = std::max(tables.longestEdge[root], arc.length());
          tables.counted[root].push_back(&turning);
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
        tables.counted[root].push_back(&turningOf(middle, ArcLength(middle, kIntervalsPerSpan)));
      }
    }
  }
  return tables;
}

std::vector<EdgeEnd> wallEdgeEnds(const std::vector<volume::Block>& blocks,
                                  const std::vector<BlockPlan>& plans, const DirectionSets& sets,
                                  const EdgeTables& edges) {
  std::vector<EdgeEnd> ends;
  for (size_t b = 0; b < blocks.size(); ++b) {
    const int n = plans[b].normalDirection;
    if (n < 0) continue;
    for (int d = 0; d < 3; ++d) {
      if (d == n) continue;
      const auto [root, parity] = sets.find(static_cast<int>(3 * b) + d);
      for (int e = 0; e < 4; ++e) {
        if (!onWallOrNoWall(plans[b], d, e)) continue;
        if (edges.collapsed[b][static_cast<size_t>(d)][static_cast<size_t>(e)])
          continue;  // it continues nothing
        const RowMatrixX3d& poles = edgeCurve(blocks[b].volume, d, e).poles;
        const double length = edges.arcs[b][static_cast<size_t>(d)][static_cast<size_t>(e)].length();
        for (int end = 0; end < 2; ++end) {
          const Eigen::Index at = end == 0 ? 0 : poles.rows() - 1;
          const Eigen::Index next = end == 0 ? 1 : poles.rows() - 2;
          const Eigen::Vector3d corner = poles.row(at).transpose();
          ends.push_back({{corner.x(), corner.y(), corner.z()},
                          (poles.row(next).transpose() - corner).normalized(),
                          length,
                          3 * b + static_cast<size_t>(d),
                          e,
                          static_cast<size_t>(root),
                          end ^ parity});
        }
      }
    }
  }
  return ends;
}

// Point counts per direction node: `normalPoints` in wall-normal sets, else what the set's
// counted edges need at `spacing` (edge_points without one).
struct PointCounts {
  const DirectionSets& sets;
  const std::vector<int>& wallParity;
  const EdgeTables& edges;
  double maxTurning;
  int edgePoints;
  // With a spacing, a set also takes the cells its longest feature edge needs to grow from the
  // features' spacings to the set's by at most `growth`.
  const std::vector<FeatureDemand>& featureDemand;
  double growth;

  std::vector<int> operator()(double spacing, int normalPoints) const {
    std::vector<int> count(wallParity.size(), 0);
    for (size_t node = 0; node < count.size(); ++node) {
      const auto root = static_cast<size_t>(sets.find(static_cast<int>(node)).first);
      if (wallParity[root] >= 0) {
        count[node] = normalPoints;
      } else if (spacing > 0.0) {
        double cells = 0.0;
        for (const TurningTable* edge : edges.counted[root])
          cells = std::max(cells, edge->measure(spacing, maxTurning));
        for (const TurningTable* fan : edges.countedFans[root]) cells = std::max(cells, fan->measure(spacing, maxTurning));
        cells = std::max(cells, edges.fanAngle[root] / kFanCellRadians);
        const FeatureDemand& demand = featureDemand[root];
        const double featureLength = std::max(demand.length[0], demand.length[1]);
        if (featureLength > 0.0) {
          cells = std::max(cells, static_cast<double>(gradedCells(featureLength, demand.spacing[0],
                                                                  demand.spacing[1], spacing, growth)));
        }
        // Checked before the conversion: a count beyond int wrapped round to the 2-point minimum.
        if (!(cells < kMaxEdgePoints)) {
          throw InvalidInputError("the tangential spacing " + numberText(spacing) +
                                  " (or the turning limit) asks for " + numberText(cells) +
                                  " cells on a block edge, more than " + std::to_string(kMaxEdgePoints - 1) +
                                  ": give a coarser spacing");
        }
        // An edge a whole number of spacings long (to the rounding of its arc length) takes no extra point.
        count[node] = std::max(2, static_cast<int>(std::ceil(cells * (1.0 - 1e-12))) + 1);
      } else {
        count[node] = edgePoints;
      }
    }
    return count;
  }
};

// Normal points before the columns are known (for the cell target): from the wall blocks' edges.
int estimatedNormalPoints(const std::vector<BlockPlan>& plans, const EdgeTables& edges, double firstHeight,
                          double growth) {
  int normalPoints = 0;
  for (size_t b = 0; b < plans.size(); ++b) {
    const int n = plans[b].normalDirection;
    if (n < 0) continue;
    for (const ArcLength& arc : edges.arcs[b][static_cast<size_t>(n)]) {
      normalPoints = std::max(normalPoints, geometricPointsNeeded(firstHeight, growth, arc.length()));
    }
  }
  return std::max(normalPoints, 2);
}

// The tangential spacing that gives about `targetCells` cells in all (bisected in its logarithm).
double spacingForTarget(const PointCounts& countsFor, const std::vector<double>& longestEdge,
                        int normalPoints, long long targetCells) {
  auto cells = [&](double h) {
    const std::vector<int> count = countsFor(h, normalPoints);
    double total = 0.0;
    for (size_t node = 0; node < count.size(); node += 3) {
      total += static_cast<double>(count[node] - 1) * (count[node + 1] - 1) * (count[node + 2] - 1);
    }
    return total;
  };
  const double longest = *std::max_element(longestEdge.begin(), longestEdge.end());
  double lo = longest * 1e-5, hi = 2.0 * longest;  // cells(lo) large, cells(hi) small
  for (int iteration = 0; iteration < 80; ++iteration) {
    const double mid = std::sqrt(lo * hi);
    (cells(mid) > static_cast<double>(targetCells) ? lo : hi) = mid;
  }
  return hi;
}

// Per tangential set (indexed by its root) the measure its edges share: the fractions of arc
// length their points go at (uniform without a turning limit).
std::vector<std::optional<SharedMeasure>> sharedMeasures(
    const std::vector<BlockPlan>& plans, const DirectionSets& sets, const std::vector<int>& wallParity,
    const EdgeTables& edges, const std::vector<int>& counts, double spacing, double maxTurning) {
  std::vector<std::optional<SharedMeasure>> setMeasure(3 * plans.size());
  for (size_t b = 0; b < plans.size(); ++b) {
    for (int d = 0; d < 3; ++d) {
      const auto [root, parity] = sets.find(static_cast<int>(3 * b) + d);
      std::optional<SharedMeasure>& shared = setMeasure[static_cast<size_t>(root)];
      if (wallParity[static_cast<size_t>(root)] >= 0) continue;
      if (!shared) {
        // With edge_points the set's spacing is what its longest counted edge gets.
        const double setSpacing = spacing > 0.0 ? spacing
                                                : edges.longestEdge[static_cast<size_t>(root)] /
                                                      (counts[static_cast<size_t>(root)] - 1);
        shared.emplace(kSharedMeasureSamples, setSpacing, setSpacing > 0.0 ? maxTurning : 0.0);
      }
      const std::vector<TurningTable>& tables = edges.turning[b][static_cast<size_t>(d)];
      for (size_t e = 0; e < tables.size(); ++e) {
        if (e < 4 && (!onWallOrNoWall(plans[b], d, static_cast<int>(e)) ||
                      edges.collapsed[b][static_cast<size_t>(d)][e]))
          continue;
        shared->add(tables[e], parity == 1);
      }
      const std::optional<TurningTable>& fan = edges.fanTurning[b][static_cast<size_t>(d)];
      if (fan) shared->add(*fan, parity == 1);
    }
  }
  return setMeasure;
}

// Per set (indexed by its root) and shared end, the step at that end as a fraction of the set's
// longest counted edge that keeps the jump to the finest continuing wall edge within maxJump (as
// far as an eighth of the set's mean spacing goes), or 0 where the set's own spacing already
// does. Continuations: the wall edges of other blocks or directions that start at the end's
// corner (shared corners are bit-identical points) and leave it within 45 degrees of straight
// on; their spacing is their mean (length over cells).
std::vector<std::array<double, 2>> continuationEndSteps(const std::vector<EdgeEnd>& ends,
                                                        const EdgeTables& edges,
                                                        const std::vector<int>& counts, double maxJump) {
  std::map<std::array<double, 3>, std::vector<size_t>> atCorner;
  for (size_t k = 0; k < ends.size(); ++k) atCorner[ends[k].corner].push_back(k);
  const double straightOn = std::cos(M_PI / 4.0);
  std::vector<std::array<double, 2>> finest(
      counts.size(), {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()});
  for (const EdgeEnd& end : ends) {
    for (size_t other : atCorner[end.corner]) {
      if (ends[other].outward.dot(end.outward) >= -straightOn) continue;
      double& known = finest[end.root][static_cast<size_t>(end.sharedEnd)];
      known = std::min(known, ends[other].length / (counts[ends[other].node] - 1));
    }
  }
  // A set is never clustered to less than an eighth of its mean spacing: a continuation far finer
  // than that (a 0.1 mm corner block beside a wing's 49 mm chordwise spacing) would squeeze the
  // whole set, and its narrower edges with it, into folded cells (on the M6's level-2 blocks at 17
  // points per edge: 8 cells with a negative Jacobian; none with the bound).
  constexpr double kMostClustering = 8.0;
  const std::vector<double>& longestEdge = edges.longestEdge;
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

// Each block direction's set root.
std::vector<size_t> setRoots(const DirectionSets& sets, size_t nodes) {
  std::vector<size_t> roots(nodes);
  for (size_t node = 0; node < nodes; ++node)
    roots[node] = static_cast<size_t>(sets.find(static_cast<int>(node)).first);
  return roots;
}

// Per end the finer of two clusterings (0: none).
std::array<double, 2> finerSteps(std::array<double, 2> steps, const std::array<double, 2>& others) {
  for (size_t end = 0; end < 2; ++end) {
    if (others[end] > 0.0) steps[end] = steps[end] > 0.0 ? std::min(steps[end], others[end]) : others[end];
  }
  return steps;
}

// A set's edges mostly ask for the same fractions (a stretched law solves for its parameter by
// fixed-point steps, a few hundred edges over): each asked once per set.
using FractionsCache = std::map<std::tuple<int, double, double>, std::vector<double>>;

// The fractions of arc length of an edge's `points` points, its own start first: at equal steps
// of its set's shared measure, or clustered at both ends, which keeps a distribution the same
// seen from either end. `parity`: the edge's orientation in its set (rooted at `root`).
// `end`: edge_end_spacing as a fraction of the edge's length (at most a half).
std::vector<double> edgeFractions(const SharedMeasure& shared, int root, int parity, int points, double end,
                                  const std::array<double, 2>& setSteps, FractionsCache& cache) {
  // The end spacing as steps of the shared measure at the edge's two ends, in the shared
  // sense. In arc length the distribution is symmetric and read from the edge's own start
  // (so grids without a turning limit keep their points bit for bit).
  const bool arcLength = shared.uniformInArcLength();
  double atStart = end > 0.0 ? shared.at(end) : 0.0;
  double atEnd = end > 0.0 ? (arcLength ? end : 1.0 - shared.at(1.0 - end)) : 0.0;
  // A spacing jump limited at a set end: the same fraction on every edge of the set; the
  // tighter of that and edge_end_spacing. In arc length the steps are the edge's own (its
  // start is the set's end `parity`), else the shared measure's.
  const auto tighten = [](double& step, double limit) {
    if (limit > 0.0) step = step > 0.0 ? std::min(step, limit) : limit;
  };
  const int startEnd = arcLength ? parity : 0;
  const double startStep = setSteps[static_cast<size_t>(startEnd)];
  const double endStep = setSteps[static_cast<size_t>(1 - startEnd)];
  if (startStep > 0.0) tighten(atStart, arcLength ? startStep : shared.at(startStep));
  if (endStep > 0.0) tighten(atEnd, arcLength ? endStep : 1.0 - shared.at(1.0 - endStep));
  auto known = cache.find({root, atStart, atEnd});
  if (known == cache.end())
    known =
        cache.emplace(std::make_tuple(root, atStart, atEnd), shared.fractions(points, atStart, atEnd)).first;
  std::vector<double> sigma = known->second;
  if (parity == 1 && !arcLength) {
    std::reverse(sigma.begin(), sigma.end());
    for (double& x : sigma) x = 1.0 - x;
  }
  return sigma;
}

// The plans' sizes, and the edge parameters of every direction but the wall-normal one, at the
// fractions of arc length their set shares; with `evenOuterEdges` (even_far_field) an edge on the
// outer boundary takes its points uniform in arc length instead.
void placeEdgePoints(const std::vector<volume::Block>& blocks, const DirectionSets& sets,
                     const EdgeTables& edges, const std::vector<int>& counts,
                     const std::vector<std::optional<SharedMeasure>>& setMeasure,
                     const std::vector<std::array<double, 2>>& setSteps, const EdgeSteps& featureSteps,
                     double edgeEndSpacing, bool evenOuterEdges, std::vector<BlockPlan>& plans) {
  FractionsCache fractionsOf;
  for (size_t b = 0; b < blocks.size(); ++b) {
    BlockPlan& plan = plans[b];
    for (int d = 0; d < 3; ++d) plan.size[static_cast<size_t>(d)] = counts[3 * b + static_cast<size_t>(d)];
    for (int d = 0; d < 3; ++d) {
      if (d == plan.normalDirection) continue;
      const int points = plan.size[static_cast<size_t>(d)];
      const auto [root, parity] = sets.find(static_cast<int>(3 * b) + d);
      for (int e = 0; e < 4; ++e) {
        const ArcLength& arc = edges.placing(b, d, e);
        const std::vector<double> sigma =
            evenOuterEdges && !onWallOrNoWall(plan, d, e)
                ? vinokurFractions(points, 0.0, 0.0)
                : edgeFractions(*setMeasure[static_cast<size_t>(root)], root, parity, points,
                                std::min(edgeEndSpacing / arc.length(), 0.5),
                                finerSteps(setSteps[static_cast<size_t>(root)],
                                           featureSteps[3 * b + static_cast<size_t>(d)][static_cast<size_t>(e)]),
                                fractionsOf);
        auto& parameters = plan.edgeParameters[static_cast<size_t>(d)][static_cast<size_t>(e)];
        parameters.resize(static_cast<size_t>(points));
        for (int i = 0; i < points; ++i)
          parameters[static_cast<size_t>(i)] = arc.parameterAt(sigma[static_cast<size_t>(i)] * arc.length());
        parameters.front() = blocks[b].volume.lower(d);
        parameters.back() = blocks[b].volume.upper(d);
      }
    }
  }
}

}  // namespace

std::vector<BlockPlan> planDirectionSets(const std::vector<volume::Block>& blocks,
                                         const RefinementOptions& options, double firstHeight,
                                         const std::vector<int>& minimumPoints) {
  const DirectionSets sets = linkedDirections(blocks);
  const std::vector<int> wallParity = wallParities(blocks, sets);
  std::vector<BlockPlan> plans = wallNormalPlans(blocks, sets, wallParity);

  // Tangential point counts: per set, from its counted edges at the spacing asked, or at the
  // spacing that gives the cell target with the normal points known or estimated.
  const double maxTurning = options.maxTurningDegrees * M_PI / 180.0;
  const EdgeTables edges = tabulateEdges(blocks, plans, sets, maxTurning);
  const std::vector<EdgeEnd> ends = wallEdgeEnds(blocks, plans, sets, edges);
  const FeatureMatches features = matchFeatures(ends, options.featureSpacings, 3 * blocks.size());
  const PointCounts countsFor{
      sets, wallParity, edges, maxTurning, options.edgePoints, features.demands, options.growth};
  const int normalPoints = options.normalPoints != 0
                               ? options.normalPoints
                               : estimatedNormalPoints(plans, edges, firstHeight, options.growth);
  const double spacing = options.targetCells > 0 ? spacingForTarget(countsFor, edges.longestEdge,
                                                                    normalPoints, options.targetCells)
                                                 : options.tangentialSpacing;
  std::vector<int> counts = countsFor(spacing, normalPoints);
  if (!minimumPoints.empty()) {
    std::vector<int> setMinimum(counts.size(), 0);
    for (size_t node = 0; node < counts.size(); ++node) {
      int& least = setMinimum[static_cast<size_t>(sets.find(static_cast<int>(node)).first)];
      least = std::max(least, minimumPoints[node]);
    }
    for (size_t node = 0; node < counts.size(); ++node) {
      const auto root = static_cast<size_t>(sets.find(static_cast<int>(node)).first);
      if (wallParity[root] < 0) counts[node] = std::max(counts[node], setMinimum[root]);
    }
  }

  // Tangential edge distributions: the set's shared measure, clustered at its ends as asked.
  const std::vector<std::optional<SharedMeasure>> setMeasure =
      sharedMeasures(plans, sets, wallParity, edges, counts, spacing, maxTurning);
  const std::vector<std::array<double, 2>> jumpSteps =
      options.maxSpacingJump > 0.0 ? continuationEndSteps(ends, edges, counts, options.maxSpacingJump)
                                   : std::vector<std::array<double, 2>>(counts.size(), {0.0, 0.0});
  placeEdgePoints(blocks, sets, edges, counts, setMeasure, jumpSteps,
                  featureEdgeSteps(plans, setRoots(sets, counts.size()), ends, features, counts),
                  options.edgeEndSpacing, options.evenFarField, plans);
  return plans;
}

}  // namespace bvmesh::grid

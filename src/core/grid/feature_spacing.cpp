#include "core/grid/feature_spacing.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "core/common/closest_point.h"

namespace bvmesh::grid {
namespace {

// Distance from `point` to a polyline, and the unit direction of its nearest segment.
std::pair<double, Eigen::Vector3d> nearestOnPolyline(const RowMatrixX3d& line, const Eigen::Vector3d& point) {
  double nearest = std::numeric_limits<double>::infinity();
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  for (Eigen::Index k = 1; k < line.rows(); ++k) {
    const Eigen::Vector3d a = line.row(k - 1).transpose();
    const Eigen::Vector3d b = line.row(k).transpose();
    const double distance = (closestPointOnSegment(point, a, b) - point).norm();
    if (distance < nearest) {
      nearest = distance;
      direction = (b - a).normalized();
    }
  }
  return {nearest, direction};
}

}  // namespace

FeatureMatches matchFeatures(const std::vector<EdgeEnd>& ends, const std::vector<FeatureSpacing>& features,
                             size_t nodes) {
  FeatureMatches matches{std::vector<FeatureDemand>(nodes), std::vector<char>(ends.size(), 0)};
  if (features.empty()) return matches;
  Eigen::AlignedBox3d wall;
  for (const EdgeEnd& end : ends) wall.extend(Eigen::Vector3d(end.corner[0], end.corner[1], end.corner[2]));
  const double defaultTolerance = 1e-3 * wall.diagonal().norm();
  const double alongTheLine = std::cos(M_PI / 4.0);
  for (const FeatureSpacing& feature : features) {
    const double tolerance = feature.tolerance > 0.0 ? feature.tolerance : defaultTolerance;
    for (size_t k = 0; k < ends.size(); ++k) {
      const EdgeEnd& end = ends[k];
      const Eigen::Vector3d corner(end.corner[0], end.corner[1], end.corner[2]);
      const auto [distance, direction] = nearestOnPolyline(feature.points, corner);
      if (distance > tolerance || std::abs(direction.dot(end.outward)) >= alongTheLine) continue;
      matches.onFeature[k] = 1;
      FeatureDemand& demand = matches.demands[end.root];
      const auto at = static_cast<size_t>(end.sharedEnd);
      demand.spacing[at] =
          demand.spacing[at] > 0.0 ? std::min(demand.spacing[at], feature.spacing) : feature.spacing;
      demand.length[at] = std::max(demand.length[at], end.length);
    }
  }
  return matches;
}

int gradedCells(double length, double s0, double s1, double spacing, double growth) {
  const auto graded = [&](double s, double reach) {  // cells and length from s up to the spacing
    if (!(s > 0.0 && s < spacing)) return std::pair<int, double>{0, 0.0};
    const int cells = static_cast<int>(std::ceil(std::log(spacing / s) / std::log(growth)));
    return std::pair<int, double>{cells,
                                  std::min(reach, s * (std::pow(growth, cells) - 1.0) / (growth - 1.0))};
  };
  const auto [k0, l0] = graded(s0, length);
  const auto [k1, l1] = graded(s1, length);
  if (l0 + l1 < length)
    return k0 + k1 + static_cast<int>(std::ceil((length - l0 - l1) / spacing * (1.0 - 1e-12)));
  const auto toward = [&](double s, double reach) {  // geometric from s over `reach`
    return s > 0.0
               ? static_cast<int>(std::ceil(std::log(1.0 + reach * (growth - 1.0) / s) / std::log(growth)))
               : 0;
  };
  if (k0 > 0 && k1 > 0) return toward(s0, 0.5 * length) + toward(s1, 0.5 * length);
  return toward(k0 > 0 ? s0 : s1, length);
}

EdgeSteps featureEdgeSteps(const std::vector<BlockPlan>& plans, const std::vector<size_t>& rootOf,
                           const std::vector<EdgeEnd>& ends, const FeatureMatches& matches,
                           const std::vector<int>& counts) {
  constexpr double kFadePerBlock = 0.5;
  EdgeSteps steps(counts.size());
  std::vector<std::array<double, 2>> featureStep(counts.size(), {0.0, 0.0});
  bool any = false;
  for (size_t root = 0; root < counts.size(); ++root) {
    for (size_t end = 0; end < 2; ++end) {
      const double length = matches.demands[root].length[end];
      if (length > 0.0 && matches.demands[root].spacing[end] < length / (counts[root] - 1)) {
        featureStep[root][end] = matches.demands[root].spacing[end] / length;
        any = true;
      }
    }
  }
  if (!any) return steps;
  std::vector<char> alike(counts.size(), 0);
  for (size_t b = 0; b < plans.size(); ++b) {
    if (plans[b].normalDirection >= 0) continue;
    for (int d = 0; d < 3; ++d) {
      const size_t root = rootOf[3 * b + static_cast<size_t>(d)];
      alike[root] = 1;
      for (auto& edge : steps[3 * b + static_cast<size_t>(d)]) edge = featureStep[root];
    }
  }
  // Wall edges (pairs of ends) as graph nodes: one per physical edge, found by its corners.
  std::map<std::array<double, 6>, int> byCorners;
  std::vector<int> nodeOf(ends.size() / 2);
  for (size_t w = 0; w < nodeOf.size(); ++w) {
    std::array<double, 3> a = ends[2 * w].corner, b = ends[2 * w + 1].corner;
    if (b < a) std::swap(a, b);
    nodeOf[w] = byCorners
                    .emplace(std::array<double, 6>{a[0], a[1], a[2], b[0], b[1], b[2]},
                             static_cast<int>(byCorners.size()))
                    .first->second;
  }
  std::vector<std::vector<int>> next(byCorners.size());
  std::map<size_t, std::vector<int>> wallEdgesOf;  // per block direction
  for (size_t w = 0; w < nodeOf.size(); ++w) wallEdgesOf[ends[2 * w].node].push_back(nodeOf[w]);
  for (const auto& [node, ids] : wallEdgesOf) {
    for (int a : ids) {
      for (int b : ids) {
        if (a != b) next[static_cast<size_t>(a)].push_back(b);
      }
    }
  }
  for (size_t end = 0; end < 2; ++end) {
    std::vector<int> hops(byCorners.size(), -1);
    std::vector<int> queue;
    for (size_t k = 0; k < ends.size(); ++k) {
      if (matches.onFeature[k] != 0 && static_cast<size_t>(ends[k].sharedEnd) == end &&
          hops[static_cast<size_t>(nodeOf[k / 2])] < 0) {
        hops[static_cast<size_t>(nodeOf[k / 2])] = 0;
        queue.push_back(nodeOf[k / 2]);
      }
    }
    for (size_t at = 0; at < queue.size(); ++at) {
      for (int n : next[static_cast<size_t>(queue[at])]) {
        if (hops[static_cast<size_t>(n)] >= 0) continue;
        hops[static_cast<size_t>(n)] = hops[static_cast<size_t>(queue[at])] + 1;
        queue.push_back(n);
      }
    }
    for (size_t w = 0; w < nodeOf.size(); ++w) {
      const EdgeEnd& edge = ends[2 * w];
      const double f = featureStep[edge.root][end];
      const int k = hops[static_cast<size_t>(nodeOf[w])];
      if (!(f > 0.0) || alike[edge.root] != 0 || k < 0) continue;
      const double uniform = 1.0 / (counts[edge.root] - 1);
      const double share = std::pow(kFadePerBlock, k);
      if (share > 1e-3) {
        steps[edge.node][static_cast<size_t>(edge.edge)][end] = uniform * std::pow(f / uniform, share);
      }
    }
  }
  // A wall block's outer edges (whose points its wall-normal lines place) as the wall edge below.
  for (size_t b = 0; b < plans.size(); ++b) {
    const int n = plans[b].normalDirection;
    if (n < 0) continue;
    for (int d = 0; d < 3; ++d) {
      if (d == n) continue;
      const int first = otherDirections(d)[0];
      auto& edges = steps[3 * b + static_cast<size_t>(d)];
      for (int e = 0; e < 4; ++e) {
        if (onWallOrNoWall(plans[b], d, e)) continue;
        const int below = n == first ? (e & 2) | plans[b].wallEnd : (e & 1) | (plans[b].wallEnd << 1);
        edges[static_cast<size_t>(e)] = edges[static_cast<size_t>(below)];
      }
    }
  }
  return steps;
}

}  // namespace bvmesh::grid

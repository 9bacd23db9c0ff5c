// Bounding-volume hierarchy over axis-aligned boxes: the spatial index of the target's
// tessellation (triangles) and of edge polylines (segments). The tree knows only boxes;
// queries take a callback that measures the exact distance to one primitive, so the same
// tree serves triangles and segments.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace bvmesh::target {

struct Box3 {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());

  void extend(const Eigen::Vector3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void extend(const Box3& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  // Squared distance from p to the box (0 inside).
  double squaredDistance(const Eigen::Vector3d& p) const {
    return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).squaredNorm();
  }
  // Parameter interval [s0, s1] where the line o + s d crosses the box; false if it misses.
  bool lineInterval(const Eigen::Vector3d& o, const Eigen::Vector3d& inverseD, double& s0, double& s1) const {
    s0 = -std::numeric_limits<double>::infinity();
    s1 = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      double a = (lo[k] - o[k]) * inverseD[k];
      double b = (hi[k] - o[k]) * inverseD[k];
      if (std::isnan(a) || std::isnan(b)) {  // line parallel to the slab: inside or not
        if (o[k] < lo[k] || o[k] > hi[k]) return false;
        continue;
      }
      if (a > b) std::swap(a, b);
      s0 = std::max(s0, a);
      s1 = std::min(s1, b);
    }
    return s0 <= s1;
  }
};

class AabbTree {
public:
  AabbTree() = default;

  // boxes: one per primitive; primitive ids in queries are indices into this list.
  explicit AabbTree(std::vector<Box3> boxes) : boxes_(std::move(boxes)) {
    order_.resize(boxes_.size());
    for (std::size_t i = 0; i < order_.size(); ++i) order_[i] = static_cast<int>(i);
    if (!order_.empty()) {
      nodes_.reserve(2 * order_.size() / kLeafSize + 2);
      nodes_.emplace_back();
      buildInto(0, 0, static_cast<int>(order_.size()));
    }
  }

  bool empty() const { return nodes_.empty(); }

  // Nearest primitive to p. distance(id, p) returns the squared distance to primitive id; it is
  // called for every primitive whose box lies within the nearest distance found so far plus
  // `slack` (with slack > 0 the caller sees every primitive within slack of the nearest one,
  // in one traversal). Returns -1 for an empty tree; bestSquared receives the squared distance.
  template <class SquaredDistance>
  int nearest(const Eigen::Vector3d& p, SquaredDistance&& distance, double& bestSquared, double slack = 0.0) const {
    bestSquared = std::numeric_limits<double>::infinity();
    double reachSquared = bestSquared;  // (sqrt(bestSquared) + slack)^2
    int best = -1;
    if (nodes_.empty()) return best;
    // Nodes to visit with their box distances (computed once, when the parent is visited).
    std::pair<int, double> stack[128];
    int top = 0;
    stack[top++] = {0, nodes_[0].box.squaredDistance(p)};
    while (top > 0) {
      const auto [index, boxSquared] = stack[--top];
      if (boxSquared > reachSquared) continue;
      const Node& node = nodes_[static_cast<std::size_t>(index)];
      if (node.count > 0) {
        for (int i = node.first; i < node.first + node.count; ++i) {
          const int id = order_[static_cast<std::size_t>(i)];
          if (boxes_[static_cast<std::size_t>(id)].squaredDistance(p) > reachSquared) continue;
          const double d = distance(id, p);
          if (d < bestSquared) {
            bestSquared = d;
            best = id;
            reachSquared = (std::sqrt(d) + slack) * (std::sqrt(d) + slack);
          }
        }
      } else {
        // Visit the nearer child first so that the bound tightens early.
        const int a = node.first;
        const int b = node.first + 1;
        const double da = nodes_[static_cast<std::size_t>(a)].box.squaredDistance(p);
        const double db = nodes_[static_cast<std::size_t>(b)].box.squaredDistance(p);
        if (da < db) {
          stack[top++] = {b, db};
          stack[top++] = {a, da};
        } else {
          stack[top++] = {a, da};
          stack[top++] = {b, db};
        }
      }
    }
    return best;
  }

  // Calls visit(id) for every primitive whose box lies within `radius` of p.
  template <class Visit>
  void withinRadius(const Eigen::Vector3d& p, double radius, Visit&& visit) const {
    if (nodes_.empty()) return;
    const double r2 = radius * radius;
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[static_cast<std::size_t>(stack[--top])];
      if (node.box.squaredDistance(p) > r2) continue;
      if (node.count > 0) {
        for (int i = node.first; i < node.first + node.count; ++i) {
          const int id = order_[static_cast<std::size_t>(i)];
          if (boxes_[static_cast<std::size_t>(id)].squaredDistance(p) <= r2) visit(id);
        }
      } else {
        stack[top++] = node.first;
        stack[top++] = node.first + 1;
      }
    }
  }

  // Calls visit(id) for every primitive whose box the line o + s d (s in R) crosses.
  template <class Visit>
  void alongLine(const Eigen::Vector3d& o, const Eigen::Vector3d& d, Visit&& visit) const {
    if (nodes_.empty()) return;
    const Eigen::Vector3d inverseD = d.cwiseInverse();
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    double s0 = 0.0;
    double s1 = 0.0;
    while (top > 0) {
      const Node& node = nodes_[static_cast<std::size_t>(stack[--top])];
      if (!node.box.lineInterval(o, inverseD, s0, s1)) continue;
      if (node.count > 0) {
        for (int i = node.first; i < node.first + node.count; ++i) {
          const int id = order_[static_cast<std::size_t>(i)];
          if (boxes_[static_cast<std::size_t>(id)].lineInterval(o, inverseD, s0, s1)) visit(id);
        }
      } else {
        stack[top++] = node.first;
        stack[top++] = node.first + 1;
      }
    }
  }

private:
  static constexpr int kLeafSize = 4;

  struct Node {
    Box3 box;
    int first = 0;  // leaf: first index into order_; inner: index of the left child
    int count = 0;  // leaf: number of primitives; inner: 0
  };

  // Median split on the longest axis of the centroids' box; depth stays ~log2(n) < 128.
  // Children are stored next to each other: left at `first`, right at `first + 1`.
  void buildInto(int index, int begin, int end) {
    Box3 box;
    Box3 centroids;
    for (int i = begin; i < end; ++i) {
      const Box3& b = boxes_[static_cast<std::size_t>(order_[static_cast<std::size_t>(i)])];
      box.extend(b);
      centroids.extend(Eigen::Vector3d(0.5 * (b.lo + b.hi)));
    }
    nodes_[static_cast<std::size_t>(index)].box = box;
    if (end - begin <= kLeafSize) {
      nodes_[static_cast<std::size_t>(index)].first = begin;
      nodes_[static_cast<std::size_t>(index)].count = end - begin;
      return;
    }
    int axis = 0;
    (centroids.hi - centroids.lo).maxCoeff(&axis);
    const int middle = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end, [&](int a, int b) {
      const Box3& ba = boxes_[static_cast<std::size_t>(a)];
      const Box3& bb = boxes_[static_cast<std::size_t>(b)];
      return ba.lo[axis] + ba.hi[axis] < bb.lo[axis] + bb.hi[axis];
    });
    const int left = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    nodes_.emplace_back();
    nodes_[static_cast<std::size_t>(index)].first = left;
    nodes_[static_cast<std::size_t>(index)].count = 0;
    buildInto(left, begin, middle);
    buildInto(left + 1, middle, end);
  }

  std::vector<Box3> boxes_;
  std::vector<int> order_;
  std::vector<Node> nodes_;
};

}  // namespace bvmesh::target

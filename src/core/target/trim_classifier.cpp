// The trim test of a face in its parameter plane (TrimClassifier, target_data.h says how).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/common/errors.h"
#include "core/target/target_data.h"

namespace bvmesh::target {

TrimClassifier::TrimClassifier(double u0, double u1, double v0, double v1,
                               const std::vector<std::vector<Eigen::Vector2d>>& curves)
    : everywhere_(curves.empty()), origin_(u0, v0), step_((u1 - u0) / kSize, (v1 - v0) / kSize) {
  if (everywhere_) return;
  if (!(step_.minCoeff() > 0) || !step_.allFinite()) throw TopologyError("Target: a face has a degenerate parameter box");
  cells_.assign(kSize * kSize, Unknown);
  std::vector<std::vector<int>> lists(kSize * kSize);
  for (const std::vector<Eigen::Vector2d>& curve : curves) {
    for (std::size_t k = 0; k + 1 < curve.size(); ++k) {
      const Eigen::Vector2d& a = curve[k];
      const Eigen::Vector2d& b = curve[k + 1];
      const int id = static_cast<int>(segments_.size());
      segments_.emplace_back(a.x(), a.y(), b.x(), b.y());
      for (int j = index(std::min(a.y(), b.y()), 1); j <= index(std::max(a.y(), b.y()), 1); ++j)
        for (int i = index(std::min(a.x(), b.x()), 0); i <= index(std::max(a.x(), b.x()), 0); ++i)
          lists[static_cast<std::size_t>(j * kSize + i)].push_back(id);
      // Mark the cells along the segment (quarter-cell steps) and their neighbours: no segment
      // passes through a cell that is not marked.
      const int steps = 1 + static_cast<int>(4 * (b - a).cwiseAbs().cwiseQuotient(step_).maxCoeff());
      for (int s = 0; s <= steps; ++s) {
        const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(s) / steps);
        const int x = index(p.x(), 0), y = index(p.y(), 1);
        for (int j = std::max(0, y - 1); j <= std::min(kSize - 1, y + 1); ++j)
          for (int i = std::max(0, x - 1); i <= std::min(kSize - 1, x + 1); ++i)
            cells_[static_cast<std::size_t>(j * kSize + i)] = Boundary;
      }
    }
  }
  cellStart_.assign(1, 0);
  for (const std::vector<int>& list : lists) {
    cellSegments_.insert(cellSegments_.end(), list.begin(), list.end());
    cellStart_.push_back(static_cast<int>(cellSegments_.size()));
  }
  // Every other connected region of cells is on one side: test one cell (crossings up to the
  // box's end), fill the region.
  std::vector<int> stack;
  for (int start = 0; start < kSize * kSize; ++start) {
    if (cells_[static_cast<std::size_t>(start)] != Unknown) continue;
    const int x = start % kSize, y = start / kSize;
    const Eigen::Vector2d center = origin_ + Eigen::Vector2d(x + 0.5, y + 0.5).cwiseProduct(step_);
    const std::uint8_t value = oddCrossings(center, 0, 1, kSize - 1 - x) ? Inside : Outside;
    cells_[static_cast<std::size_t>(start)] = value;
    stack.assign(1, start);
    while (!stack.empty()) {
      const int cell = stack.back();
      stack.pop_back();
      const int cx = cell % kSize, cy = cell / kSize;
      for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
        const int nx = cx + dx, ny = cy + dy;
        if (nx < 0 || ny < 0 || nx >= kSize || ny >= kSize) continue;
        std::uint8_t& next = cells_[static_cast<std::size_t>(ny * kSize + nx)];
        if (next != Unknown) continue;
        next = value;
        stack.push_back(ny * kSize + nx);
      }
    }
  }
}

int TrimClassifier::index(double x, int axis) const {
  return std::clamp(static_cast<int>(std::floor((x - origin_[axis]) / step_[axis])), 0, kSize - 1);
}

bool TrimClassifier::oddCrossings(const Eigen::Vector2d& p, int axis, int direction, int steps) const {
  // Half-open across the ray so that a vertex shared by two segments counts once. A segment
  // listed in several cells counts in the cell holding its crossing only.
  const int across = 1 - axis;
  int cell[2] = {index(p.x(), 0), index(p.y(), 1)};
  bool odd = false;
  for (int n = 0; n <= steps; ++n, cell[axis] += direction) {
    const std::size_t c = static_cast<std::size_t>(cell[1] * kSize + cell[0]);
    for (int k = cellStart_[c]; k < cellStart_[c + 1]; ++k) {
      const Eigen::Vector4d& s = segments_[static_cast<std::size_t>(cellSegments_[static_cast<std::size_t>(k)])];
      const double a0 = s[axis], c0 = s[across], a1 = s[2 + axis], c1 = s[2 + across];
      if ((c0 > p[across]) == (c1 > p[across])) continue;
      const double crossing = std::clamp(a0 + (p[across] - c0) * (a1 - a0) / (c1 - c0), std::min(a0, a1), std::max(a0, a1));
      if (direction * (crossing - p[axis]) > 0 && index(crossing, axis) == cell[axis]) odd = !odd;
    }
  }
  return odd;
}

bool TrimClassifier::inside(double u, double v) const {
  if (everywhere_) return true;
  const Eigen::Vector2d p(u, v);
  const Eigen::Vector2d x = (p - origin_).cwiseQuotient(step_);
  if (!(x.minCoeff() >= 0 && x.maxCoeff() <= kSize)) return false;  // the box holds the boundary
  const int i = index(u, 0), j = index(v, 1);
  const std::uint8_t cell = cells_[static_cast<std::size_t>(j * kSize + i)];
  if (cell != Boundary) return cell == Inside;
  // Rays along +u, -u, +v, -v: the first to reach a known cell (or to leave the grid: outside)
  // decides. The point is on that cell's side when an even number of segments cross in between.
  constexpr int kAxis[4] = {0, 0, 1, 1};
  constexpr int kDirection[4] = {1, -1, 1, -1};
  for (int steps = 1;; ++steps) {
    for (int r = 0; r < 4; ++r) {
      const int ci = kAxis[r] == 0 ? i + kDirection[r] * steps : i;
      const int cj = kAxis[r] == 1 ? j + kDirection[r] * steps : j;
      const bool leaves = ci < 0 || cj < 0 || ci >= kSize || cj >= kSize;
      const std::uint8_t known = leaves ? std::uint8_t{Outside} : cells_[static_cast<std::size_t>(cj * kSize + ci)];
      if (known == Boundary) continue;
      return (known == Inside) != oddCrossings(p, kAxis[r], kDirection[r], steps - 1);
    }
  }
}

}  // namespace bvmesh::target

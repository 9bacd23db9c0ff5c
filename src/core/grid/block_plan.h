// What the refinement decides for each block before it evaluates any point: its point counts, its
// wall-normal direction and wall end, and the parameters along its edges; a grid point's parameters
// are its edges' blended by its index fractions.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/volume/bspline_volume.h"

namespace bvmesh::grid {

struct BlockPlan {
  std::array<int, 3> size{0, 0, 0};
  int normalDirection = -1;  // the wall-normal (column) direction, or -1
  int wallEnd = 0;           // 0: clustered at its lower end, 1: at its upper end
  // Per direction the parameters along its four edges; edge e = s1 + 2 s2 at the ends s1, s2 of
  // the two other directions (in increasing order).
  std::array<std::array<std::vector<double>, 4>, 3> edgeParameters;
};

// The other two directions of `direction`, in increasing order.
inline std::array<int, 2> otherDirections(int direction) {
  return direction == 0   ? std::array<int, 2>{1, 2}
         : direction == 1 ? std::array<int, 2>{0, 2}
                          : std::array<int, 2>{0, 1};
}

inline double parameterAtEnd(const volume::BsplineVolume& volume, int direction, int end) {
  return end == 0 ? volume.lower(direction) : volume.upper(direction);
}

// Whether edge `edge` along `direction` lies on the block's wall face (or the block has no wall).
inline bool onWallOrNoWall(const BlockPlan& plan, int direction, int edge) {
  const int n = plan.normalDirection;
  if (n < 0 || n == direction) return true;
  const auto [first, second] = otherDirections(direction);
  return n == first ? (edge & 1) == plan.wallEnd : (edge >> 1) == plan.wallEnd;
}

// The parameter along `direction` at fractions (f1, f2) of the two other directions' index ranges:
// the bilinear blend of the four edges' parameters at index i.
inline double blendedParameter(const BlockPlan& plan, int direction, int i, double f1, double f2) {
  const auto& edges = plan.edgeParameters[static_cast<size_t>(direction)];
  const size_t at = static_cast<size_t>(i);
  return (1 - f1) * (1 - f2) * edges[0][at] + f1 * (1 - f2) * edges[1][at] + (1 - f1) * f2 * edges[2][at] +
         f1 * f2 * edges[3][at];
}

// Index fraction along `direction`, or `normalEnd` (0 or 1) when that is the wall-normal direction.
inline double fraction(const BlockPlan& plan, int direction, int index, int normalEnd) {
  if (direction == plan.normalDirection) return normalEnd;
  return static_cast<double>(index) / (plan.size[static_cast<size_t>(direction)] - 1);
}

// The parameter along `direction` of grid point ijk's column at the wall-normal direction's end
// `normalEnd`: its edges blended by the index fractions of the other two directions.
inline double parameterAtNormalEnd(const BlockPlan& plan, int direction, const std::array<int, 3>& ijk,
                                   int normalEnd) {
  const auto [first, second] = otherDirections(direction);
  return blendedParameter(plan, direction, ijk[static_cast<size_t>(direction)],
                          fraction(plan, first, ijk[static_cast<size_t>(first)], normalEnd),
                          fraction(plan, second, ijk[static_cast<size_t>(second)], normalEnd));
}

// The parameter along `direction` of grid point ijk, the wall-normal direction held at its wall end.
inline double pointParameter(const BlockPlan& plan, int direction, const std::array<int, 3>& ijk) {
  return parameterAtNormalEnd(plan, direction, ijk, plan.wallEnd);
}

// The same on the block's outer boundary: the wall-normal direction held at its far end.
inline double outerParameter(const BlockPlan& plan, int direction, const std::array<int, 3>& ijk) {
  return parameterAtNormalEnd(plan, direction, ijk, 1 - plan.wallEnd);
}

// How messages name block b.
inline std::string blockText(size_t b) { return "block " + std::to_string(b); }

}  // namespace bvmesh::grid

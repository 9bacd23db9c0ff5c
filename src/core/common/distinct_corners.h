// A quad whose corners may repeat: a cell face or wall quad beside a collapsed face, where
// merged points make it a triangle (or less).
#pragma once

#include <array>

namespace bvmesh {

template <typename Index>
struct DistinctCorners {
  std::array<Index, 4> points{};
  int size = 0;  // 4, 3 for a triangle; below 3 no polygon
};

// The quad's corners in order without repeats: a corner equal to the one before it is dropped,
// and the last one when it equals the first.
template <typename Index>
DistinctCorners<Index> distinctCorners(const std::array<Index, 4>& quad) {
  DistinctCorners<Index> result;
  for (const Index point : quad) {
    if (result.size == 0 || result.points[static_cast<size_t>(result.size - 1)] != point)
      result.points[static_cast<size_t>(result.size++)] = point;
  }
  if (result.size > 1 && result.points[static_cast<size_t>(result.size - 1)] == result.points[0])
    --result.size;
  return result;
}

}  // namespace bvmesh

#include "core/io/io_common.h"

#include <cstdio>

namespace bvmesh::io {

std::string blockName(int block) {
  char name[32];
  std::snprintf(name, sizeof(name), "block_%04d", block + 1);
  return name;
}

DirectionMap directionMap(int face, const volume::FaceConnection& link) {
  DirectionMap map;
  const std::array<int, 2> mine = volume::faceDirections(face);
  const std::array<int, 2> theirs = volume::faceDirections(link.face);
  for (int axis = 0; axis < 2; ++axis) {
    // mapFacePosition's convention: swapped exchanges the axes, the reverse flags are the neighbour's.
    const int theirAxis = link.swapped ? 1 - axis : axis;
    const auto d = static_cast<size_t>(mine[static_cast<size_t>(axis)]);
    map.direction[d] = theirs[static_cast<size_t>(theirAxis)];
    map.reversed[d] = theirAxis == 0 ? link.reverseFirst : link.reverseSecond;
  }
  const auto normal = static_cast<size_t>(face / 2);
  map.direction[normal] = link.face / 2;
  map.reversed[normal] = face % 2 == link.face % 2;
  return map;
}

}  // namespace bvmesh::io

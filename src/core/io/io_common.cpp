#include "core/io/io_common.h"

#include <cstdio>
#include <cstring>

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

void appendLittleEndian(std::string& out, std::uint64_t value, int bytes) {
  for (int k = 0; k < bytes; ++k) out.push_back(static_cast<char>((value >> (8 * k)) & 0xffu));
}

void appendInt32(std::string& out, std::int32_t value) {
  appendLittleEndian(out, static_cast<std::uint32_t>(value), 4);
}

void appendFloat64(std::string& out, double value) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof(bits));
  appendLittleEndian(out, bits, 8);
}

void writeFloat64s(std::ostream& out, const double* values, size_t count, size_t stride) {
  std::string buffer;
  for (size_t v = 0; v < count; ++v) {
    appendFloat64(buffer, values[v * stride]);
    if (buffer.size() >= 65536) {
      out << buffer;
      buffer.clear();
    }
  }
  out << buffer;
}

std::uint64_t readLittleEndian(const unsigned char* in, int bytes) {
  std::uint64_t value = 0;
  for (int k = 0; k < bytes; ++k) value |= static_cast<std::uint64_t>(in[k]) << (8 * k);
  return value;
}

double readFloat64(const unsigned char* in) {
  const std::uint64_t bits = readLittleEndian(in, 8);
  double value = 0;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

}  // namespace bvmesh::io

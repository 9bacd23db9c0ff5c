// Pieces the solver-file writers share: the names of the grid's blocks (so that a CGNS zone, a
// VTK dataset and a G+Smo patch of one block carry one name), a face connection as a map of index
// directions (CGNS Transform, G+Smo dirMap/dirOrientation), and little-endian binary encoding
// (Plot3D and VTK binary data are little-endian whatever the host's byte order).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <ostream>
#include <string>

#include "core/volume/block_mesh.h"

namespace bvmesh::io {

// "block_0001" for block 0: one-based, zero-padded to four digits (wider past 9999 blocks), so
// the names sort in block order in file browsers and in ParaView's block list.
std::string blockName(int block);

// How the index directions (0, 1, 2 = i/u, j/v, k/w) of a block continue in the neighbour across
// its connected face `face`: direction d runs along the neighbour's direction[d], backwards when
// reversed[d]. Along the face this is the connection's axis map; across it (d = face / 2) the
// neighbour's normal direction, reversed when both faces are the same end (min-min, max-max):
// stepping into this block then steps out of the neighbour.
struct DirectionMap {
  std::array<int, 3> direction{0, 1, 2};
  std::array<bool, 3> reversed{false, false, false};
};
DirectionMap directionMap(int face, const volume::FaceConnection& link);

// Appends the low `bytes` bytes of `value`, least significant first.
void appendLittleEndian(std::string& out, std::uint64_t value, int bytes);
void appendInt32(std::string& out, std::int32_t value);
void appendFloat64(std::string& out, double value);

// Streams values[0], values[stride], ... (count of them) as little-endian Float64 through a small
// buffer, so that a block's coordinates are never copied whole.
void writeFloat64s(std::ostream& out, const double* values, size_t count, size_t stride = 1);

std::uint64_t readLittleEndian(const unsigned char* in, int bytes);
double readFloat64(const unsigned char* in);

}  // namespace bvmesh::io

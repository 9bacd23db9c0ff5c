// Pieces the solver-file writers share: the names of the grid's blocks (so that a CGNS zone, a
// VTK dataset and a G+Smo patch of one block carry one name), a face connection as a map of index
// directions (CGNS Transform, G+Smo dirMap/dirOrientation).
#pragma once

#include <array>
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

}  // namespace bvmesh::io

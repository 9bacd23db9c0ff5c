// OpenFOAM polyMesh from a structured grid: constant/polyMesh/{points, faces, owner, neighbour,
// boundary} in ASCII with round-trip (shortest exact) numbers, numbered as grid::HexTopology
// does (shared points merged, internal faces upper-triangular, owner < neighbour, boundary faces
// patch by patch), and a minimal system/ (controlDict, fvSchemes, fvSolution) when the case has
// none, so that checkMesh and the solvers run on it. Patches: wall (type wall), symmetry
// (symmetryPlane), farfield / inlet / outlet / side (patch).
#pragma once

#include <string>

#include "core/grid/hex_topology.h"

namespace bvmesh::io {

// Writes the case at `caseDirectory` (created if missing). Each file goes through a temporary
// renamed into place. Throws InvalidInputError naming the path when it cannot be written.
void writeOpenFoamCase(const grid::HexTopology& topology, const std::string& caseDirectory);

}  // namespace bvmesh::io

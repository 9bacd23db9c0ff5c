// The block mesh as a text file (docs/volume.md, "Block file"): every block's degrees, knot
// vectors and poles at full precision, and each face's boundary condition or connection.
#pragma once

#include <iosfwd>
#include <string>

#include "core/volume/block_mesh.h"

namespace bvmesh::volume {

void writeBlockMesh(const BlockMesh& mesh, std::ostream& out);
// Writes through a temporary file renamed into place; InvalidInputError on an unwritable path.
void writeBlockMeshFile(const BlockMesh& mesh, const std::string& path);

// Throws InvalidInputError naming the line (and the file) that cannot be read, or what the
// BlockMesh validation rejects.
BlockMesh readBlockMesh(std::istream& in, const std::string& name = "block mesh");
BlockMesh readBlockMeshFile(const std::string& path);

}  // namespace bvmesh::volume

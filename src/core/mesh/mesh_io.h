// Reading and writing control meshes: BVMesh's own text format (docs/control_mesh_format.md)
// and OBJ with OpenSubdiv's crease and corner tags ("t crease 2/1/0 v0 v1 s",
// "t corner 1/1/0 v s", 0-based vertex ids, sharpness >= 10 meaning infinitely sharp).
// Unreadable or corrupt files raise InvalidInputError naming the file and line; invalid meshes
// raise the ControlMesh errors prefixed with the file name.
#pragma once

#include <iosfwd>
#include <string>

#include "core/mesh/control_mesh.h"

namespace bvmesh {

enum class ControlMeshFormat {
  Auto,  // by file extension: ".obj" is OBJ, anything else the text format
  Text,
  Obj,
};

ControlMesh readControlMesh(const std::string& path,
                            ControlMeshFormat format = ControlMeshFormat::Auto);
void writeControlMesh(const ControlMesh& mesh, const std::string& path,
                      ControlMeshFormat format = ControlMeshFormat::Auto);

// Stream versions; `name` is used in error messages.
ControlMesh readControlMeshText(std::istream& in, const std::string& name);
ControlMesh readControlMeshObj(std::istream& in, const std::string& name);
void writeControlMeshText(const ControlMesh& mesh, std::ostream& out);
void writeControlMeshObj(const ControlMesh& mesh, std::ostream& out);

}  // namespace bvmesh

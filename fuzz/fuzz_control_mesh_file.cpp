// Fuzz target for the control-mesh file readers (core/mesh/mesh_io.h), BVMESH_FUZZ_MESH_FORMAT
// Text (.cmesh) or Obj: the bytes are parsed; a mesh that reads must write and read back with the
// same counts (an error or a difference there is a finding), and must subdivide once or fail with
// a core error.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <optional>
#include <sstream>
#include <string>

#include "core/mesh/mesh_io.h"
#include "core/subdiv/subdivision.h"

#define BVMESH_CONCAT(a, b) a##b
#define BVMESH_READER(format) BVMESH_CONCAT(bvmesh::readControlMesh, format)
#define BVMESH_WRITER(format) BVMESH_CONCAT(bvmesh::writeControlMesh, format)

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  std::optional<bvmesh::ControlMesh> mesh;
  try {
    mesh.emplace(BVMESH_READER(BVMESH_FUZZ_MESH_FORMAT)(in, "fuzz"));
  } catch (const std::exception&) {
    return 0;  // unreadable or invalid meshes: the core's errors are the expected outcome
  }
  // Outside any try: what the writer wrote must read back.
  std::stringstream copy;
  BVMESH_WRITER(BVMESH_FUZZ_MESH_FORMAT)(*mesh, copy);
  const bvmesh::ControlMesh again = BVMESH_READER(BVMESH_FUZZ_MESH_FORMAT)(copy, "fuzz copy");
  if (again.numVertices() != mesh->numVertices() || again.numFaces() != mesh->numFaces() ||
      again.creases().rows() != mesh->creases().rows() || again.corners().size() != mesh->corners().size()) {
    __builtin_trap();
  }
  try {
    if (mesh->numVertices() <= 4096) bvmesh::subdivide(*mesh);
  } catch (const std::exception&) {
  }
  return 0;
}

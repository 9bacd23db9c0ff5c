// Fuzz target for ControlMesh construction from raw arrays (what the Python ControlMesh(...) and
// every template hand to the core): the bytes decode into vertices, face sizes, indices, creases
// and corners with sharpness (raw_mesh_codec.h). Invalid arrays must raise the core's errors; a
// mesh that constructs must subdivide once or fail with a core error.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "core/subdiv/subdivision.h"
#include "raw_mesh_codec.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  bvmesh::fuzz::RawMesh raw = bvmesh::fuzz::RawMeshDecoder(data, size).decode();
  try {
    const bvmesh::ControlMesh mesh(std::move(raw.vertices), std::move(raw.faceSizes), std::move(raw.faceIndices),
                                   std::move(raw.creases), std::move(raw.creaseSharpness), std::move(raw.corners),
                                   std::move(raw.cornerSharpness));
    bvmesh::subdivide(mesh);
  } catch (const std::exception&) {
    // Invalid arrays: the core's errors are the expected outcome.
  }
  return 0;
}

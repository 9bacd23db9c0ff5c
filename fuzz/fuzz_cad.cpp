// Fuzz target for the in-process CAD readers the reader child runs (core/cad/isolated_reader.cpp,
// runCadReader): with BVMESH_FUZZ_CAD_EXTENSION the bytes are a file of that type for
// readShapeFile, without it BREP text for readBrepString; what reads is repaired (sewn for files,
// as the child does) and written back as BREP text. The core's documented errors are expected;
// anything else (a crash, an OCCT exception escaping the core's edge) is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <string>
#include <vector>

#include "core/cad/shape_io.h"
#include "core/cad/shape_repair.h"

namespace {

#ifdef BVMESH_FUZZ_CAD_EXTENSION
// One file per process, in $TMPDIR (scripts/fuzz.sh points it at /dev/shm).
const std::string& inputPath() {
  static const std::string path = [] {
    const char* folder = std::getenv("TMPDIR");
    return std::string(folder != nullptr ? folder : "/tmp") + "/bvmesh-fuzz-" + std::to_string(getpid()) +
           BVMESH_FUZZ_CAD_EXTENSION;
  }();
  return path;
}
#endif

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
#ifdef BVMESH_FUZZ_CAD_EXTENSION
    std::ofstream(inputPath(), std::ios::binary | std::ios::trunc) << bytes;
    std::vector<std::string> notes;
    const TopoDS_Shape shape = bvmesh::cad::readShapeFile(inputPath(), &notes);
    const bvmesh::cad::RepairOptions repair;
#else
    const TopoDS_Shape shape = bvmesh::cad::readBrepString(bytes);
    const bvmesh::cad::RepairOptions repair{false, 0.0};
#endif
    const bvmesh::cad::RepairedShape repaired = bvmesh::cad::repairShape(shape, repair);
    bvmesh::cad::writeBrepString(repaired.shape);
  } catch (const std::exception&) {
    // The core's errors (InvalidInputError, SolverError, ...) are the expected outcome.
  }
  return 0;
}

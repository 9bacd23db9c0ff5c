// bvmesh_fuzz_seeds OUT_DIR: the seed corpus of the fuzz targets, one folder per target. The CAD
// seeds come from tests/data (the small hemisphere-cylinder STEP file, and its BREP text and IGES
// faces as the core writes them); the mesh seeds are the test fixtures' cube (with creases and
// corners), open grid and prism, written by the core's writers and the raw-array encoder.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "core/cad/shape_io.h"
#include "core/mesh/mesh_io.h"
#include "mesh_fixtures.h"
#include "raw_mesh_codec.h"

namespace fs = std::filesystem;

namespace {

bvmesh::ControlMesh meshOf(const bvmesh::testing::MeshData& d, bvmesh::RowMatrixX2i creases = bvmesh::RowMatrixX2i(0, 2),
                           std::vector<int> corners = {}) {
  return bvmesh::ControlMesh(d.vertices, d.sizes, d.indices, std::move(creases), Eigen::VectorXd(), std::move(corners));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: bvmesh_fuzz_seeds OUT_DIR\n";
    return 2;
  }
  const fs::path out = argv[1];
  for (const char* target : {"step", "iges", "brep", "cmesh", "obj", "control_mesh"}) {
    fs::create_directories(out / target);
  }
  const std::string step = std::string(BVMESH_TEST_DATA_DIR) + "/hemisph-cyl.stp";
  fs::copy_file(step, out / "step" / "hemisph-cyl.stp", fs::copy_options::overwrite_existing);
  const TopoDS_Shape shape = bvmesh::cad::readShapeFile(step);
  std::ofstream(out / "brep" / "hemisph-cyl.brep") << bvmesh::cad::writeBrepString(shape);
  bvmesh::cad::writeIgesFaces(shape, (out / "iges" / "hemisph-cyl.igs").string());

  bvmesh::RowMatrixX2i topLoop(4, 2);
  topLoop << 4, 5, 5, 6, 6, 7, 7, 4;
  bvmesh::testing::MeshData prism = bvmesh::testing::prismData(5);
  prism.vertices *= 4.0;
  const std::vector<std::pair<std::string, bvmesh::ControlMesh>> meshes = {
      {"creased_cube", meshOf(bvmesh::testing::cubeData(), topLoop, {0, 1})},
      {"open_grid", meshOf(bvmesh::testing::gridData(2, 2))},
      {"prism", meshOf(prism)}};
  for (const auto& [name, mesh] : meshes) {
    bvmesh::writeControlMesh(mesh, (out / "cmesh" / (name + ".cmesh")).string(), bvmesh::ControlMeshFormat::Text);
    bvmesh::writeControlMesh(mesh, (out / "obj" / (name + ".obj")).string(), bvmesh::ControlMeshFormat::Obj);
    const std::vector<uint8_t> bytes = bvmesh::fuzz::encodeRawMesh(mesh);
    std::ofstream(out / "control_mesh" / (name + ".bin"), std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  std::cout << "seeds in " << out.string() << "\n";
  return 0;
}

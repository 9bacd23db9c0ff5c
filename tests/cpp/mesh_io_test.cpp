#include "core/mesh/mesh_io.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/common/errors.h"
#include "mesh_fixtures.h"

namespace bvmesh {
namespace {

ControlMesh taggedMesh() {
  testing::MeshData d = testing::prismData(5);  // pentagon caps and quads
  d.vertices = testing::perturbed(d.vertices, 0.1, 42);
  RowMatrixX2i creases(3, 2);
  creases << 5, 6, 6, 7, 0, 5;
  Eigen::VectorXd sharpness(3);
  sharpness << kInfiniteSharpness, 2.5, 0.75;
  return ControlMesh(d.vertices, d.sizes, d.indices, creases, sharpness, {3, 8},
                     Eigen::Vector2d(kInfiniteSharpness, 1.5));
}

void expectSameMesh(const ControlMesh& a, const ControlMesh& b) {
  EXPECT_EQ(a.vertices(), b.vertices());  // bit-exact: 17 significant digits are written
  EXPECT_EQ(a.faceSizes(), b.faceSizes());
  EXPECT_EQ(a.faceIndices(), b.faceIndices());
  EXPECT_EQ(a.creases(), b.creases());
  EXPECT_EQ(a.creaseSharpness(), b.creaseSharpness());
  EXPECT_EQ(a.corners(), b.corners());
  EXPECT_EQ(a.cornerSharpness(), b.cornerSharpness());
}

std::string outputPath(const std::string& name) {
  return std::string(BVMESH_TEST_OUTPUT_DIR) + "/" + name;
}

TEST(MeshIo, TextAndObjRoundTrip) {
  const ControlMesh mesh = taggedMesh();
  for (const std::string name : {"round_trip.cmesh", "round_trip.obj"}) {
    writeControlMesh(mesh, outputPath(name));
    expectSameMesh(mesh, readControlMesh(outputPath(name)));
  }
}

TEST(MeshIo, ReadsObjConventions) {
  // Slashes, negative (relative) indices, comments, other records and OpenSubdiv tags with one
  // sharpness for several pairs; sharpness 10 means infinite.
  std::istringstream in(
      "# a quad and a triangle\n"
      "mtllib x.mtl\n"
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0.5 0\n"
      "vt 0 0\nvn 0 0 1\ng part\ns off\n"
      "f 1/1/1 2/1/1 3//1 4\n"
      "f -4 -1 -3\n"
      "t crease 4/1/0 1 2 0 1 10\n"
      "t corner 1/1 3 2.0\n"
      "t interpolateboundary 1/0/0 2\n");
  const ControlMesh mesh = readControlMeshObj(in, "inline.obj");
  EXPECT_EQ(mesh.faceIndices(), (std::vector<int>{0, 1, 2, 3, 1, 4, 2}));
  ASSERT_EQ(mesh.creases().rows(), 2);
  EXPECT_EQ(mesh.creaseSharpness()(0), kInfiniteSharpness);
  EXPECT_EQ(mesh.corners(), std::vector<int>{3});
  EXPECT_EQ(mesh.cornerSharpness()(0), 2.0);
}

void expectReadError(const std::string& name, const std::string& content, const std::string& text) {
  const std::string path = outputPath(name);
  std::ofstream(path) << content;
  try {
    readControlMesh(path);
    FAIL() << "no exception for " << name;
  } catch (const InvalidInputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(text), std::string::npos) << message;
  }
}

TEST(MeshIo, CorruptFilesNameFileAndLine) {
  const std::string header = "bvmesh-control-mesh 1\nvertices 3\n0 0 0\n1 0 0\n0 1 0\n";
  expectReadError("bad_magic.cmesh", "solid cube\n", "line 1: not a BVMesh control mesh file");
  expectReadError("bad_number.cmesh", "bvmesh-control-mesh 1\nvertices 3\n0 0 0\n1 x 0\n",
                  "line 4: 'x' is not a number");
  expectReadError("short.cmesh", header + "faces 2\n3 0 1 2\n",
                  "expected face 1 (the file ends early)");
  expectReadError("face_count.cmesh", header + "faces 1\n4 0 1 2\n",
                  "line 7: face 0 announces 4 vertices but lists 3");
  expectReadError("trailing.cmesh", header + "faces 1\n3 0 1 2\nhello 1\n",
                  "line 8: unexpected 'hello'");
  expectReadError("index.cmesh", header + "faces 1\n3 0 1 7\n", "face 0 refers to vertex 7");
  expectReadError("crease.cmesh", header + "faces 1\n3 0 1 2\ncreases 1\n0 1 -2\n",
                  "line 9: sharpness '-2' must be > 0");
  expectReadError("bad_vertex.obj", "v 0 0\n", "line 1: a vertex needs 3 coordinates");
  expectReadError("zero_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
                  "line 4: OBJ vertex indices start at 1");
  expectReadError("bad_tag.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nt crease 2/1/0 0 1\n",
                  "line 5: malformed 'crease' tag");
  // Tag counts whose sum overflowed an int, and a negative count.
  expectReadError("huge_tag.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nt crease 2147483646/2147483647/0 0 1 5\n",
                  "line 5: malformed 'crease' tag");
  expectReadError("negative_tag.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nt crease 2/-1/0 0 1 5\n",
                  "line 5: malformed 'crease' tag");
  EXPECT_THROW(readControlMesh(outputPath("does_not_exist.cmesh")), InvalidInputError);
  // Connectivity errors keep their type and gain the file name.
  const std::string path = outputPath("not_an_edge.obj");
  std::ofstream(path)
      << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\nt crease 2/1/0 0 3 10\n";
  EXPECT_THROW(readControlMesh(path), TopologyError);
}

}  // namespace
}  // namespace bvmesh

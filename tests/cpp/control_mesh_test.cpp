#include "core/mesh/control_mesh.h"

#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "core/common/errors.h"
#include "mesh_fixtures.h"

namespace bvmesh {
namespace {

using testing::cubeData;
using testing::gridData;
using testing::makeMesh;
using testing::MeshData;

// Expects exactly error type E (not a subclass when E is InvalidInputError) with `text` in it.
template <class E>
void expectError(const std::function<void()>& action, const std::string& text) {
  try {
    action();
    FAIL() << "no exception, expected one mentioning '" << text << "'";
  } catch (const E& error) {
    const std::string message = error.what();
    if (std::is_same_v<E, InvalidInputError>) {
      EXPECT_EQ(dynamic_cast<const TopologyError*>(&error), nullptr) << message;
    }
    EXPECT_NE(message.find(text), std::string::npos) << message;
  }
}

ControlMesh fromData(const MeshData& d) { return makeMesh(d); }

TEST(ControlMesh, CubeConnectivity) {
  const ControlMesh cube = fromData(cubeData());
  EXPECT_EQ(cube.numVertices(), 8);
  EXPECT_EQ(cube.numFaces(), 6);
  EXPECT_EQ(cube.numEdges(), 12);
  EXPECT_TRUE(cube.boundaryEdges().empty());
  EXPECT_TRUE(cube.isAllQuads());
  // Edges are numbered by first use and oriented like their first face.
  EXPECT_EQ(cube.edges()(0, 0), 0);
  EXPECT_EQ(cube.edges()(0, 1), 3);
  for (int e = 0; e < cube.numEdges(); ++e) {
    EXPECT_EQ(cube.findEdge(cube.edges()(e, 0), cube.edges()(e, 1)), e);
    EXPECT_EQ(cube.findEdge(cube.edges()(e, 1), cube.edges()(e, 0)), e);
    EXPECT_GE(cube.edgeFaces()(e, 1), 0);
  }
  EXPECT_EQ(cube.findEdge(0, 6), -1);
}

TEST(ControlMesh, GridBoundaryAndCreases) {
  RowMatrixX2i creases(2, 2);
  creases << 1, 5, 5, 9;  // interior column of a 3 x 2 grid (vertex (1,0)-(1,1)-(1,2))
  Eigen::VectorXd sharpness(2);
  sharpness << 2.5, kInfiniteSharpness;
  const ControlMesh grid = makeMesh(gridData(3, 2), creases, sharpness, {0});
  EXPECT_EQ(grid.numEdges(), 17);
  EXPECT_EQ(grid.boundaryEdges().size(), 10u);
  EXPECT_DOUBLE_EQ(grid.edgeSharpness()(grid.findEdge(5, 1)), 2.5);
  EXPECT_EQ(grid.edgeSharpness()(grid.findEdge(5, 9)), kInfiniteSharpness);
  EXPECT_EQ(grid.cornerSharpness()(0), kInfiniteSharpness);
}

TEST(ControlMesh, SetVerticesChecksShapeAndValues) {
  ControlMesh cube = fromData(cubeData());
  RowMatrixX3d moved = cube.vertices() * 2.0;
  cube.setVertices(moved);
  EXPECT_EQ(cube.vertices(), moved);
  expectError<InvalidInputError>([&] { cube.setVertices(RowMatrixX3d::Zero(3, 3)); }, "expected 8");
  moved(2, 1) = std::nan("");
  expectError<InvalidInputError>([&] { cube.setVertices(moved); }, "vertex 2");
}

TEST(ControlMesh, ValidAtAnyScaleADoubleHolds) {
  // Cross products of raw coordinates overflow at 1e154 and underflow at 1e-160; the validation
  // measures in units of the mesh's own extent.
  for (double factor : {1e154, 1e-160, 1e-300, 1e300}) {
    MeshData d = cubeData();
    d.vertices *= factor;
    d.vertices.col(0).array() += 3.0 * factor;  // away from the origin too
    EXPECT_NO_THROW(fromData(d)) << factor;
    d.vertices.row(2) = d.vertices.row(3);
    expectError<InvalidInputError>([&] { fromData(d); }, "face 0 is degenerate");
  }
}

TEST(ControlMesh, RejectsBadValuesAndIndices) {
  MeshData d = cubeData();
  d.vertices(5, 2) = std::numeric_limits<double>::infinity();
  expectError<InvalidInputError>([&] { fromData(d); }, "vertex 5 has a non-finite coordinate");

  d = cubeData();
  d.indices[6] = 8;
  expectError<InvalidInputError>([&] { fromData(d); }, "face 1 refers to vertex 8");
  d.indices[6] = -1;
  expectError<InvalidInputError>([&] { fromData(d); }, "face 1 refers to vertex -1");

  d = cubeData();
  d.sizes = {4, 4, 4, 4, 4, 2, 2};
  expectError<InvalidInputError>([&] { fromData(d); }, "face 5 has 2 vertices");

  d = cubeData();
  d.indices.pop_back();
  expectError<InvalidInputError>([&] { fromData(d); }, "add up to 24, but only 23");

  d = cubeData();
  d.vertices.row(2) = d.vertices.row(3);  // face 0 gets a zero-length edge
  expectError<InvalidInputError>([&] { fromData(d); }, "face 0 is degenerate");

  // A flat face whose vertices are collinear has zero area.
  MeshData line;
  line.vertices.resize(4, 3);
  line.vertices << 0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0;
  line.sizes = {3, 3};
  line.indices = {0, 1, 2, 0, 2, 3};
  expectError<InvalidInputError>([&] { fromData(line); }, "face 0 is degenerate: its area is zero");

  // A face ten million times smaller than the mesh is small, not degenerate.
  MeshData far = cubeData();
  far.vertices.row(0) << 1e7, 1e7, 1e7;
  far.vertices.row(1) = far.vertices.row(0) + Eigen::RowVector3d(1.0, 0.0, 0.0);
  far.vertices.row(2) = far.vertices.row(0) + Eigen::RowVector3d(1.0, 1.0, 0.0);
  far.vertices.row(3) = far.vertices.row(0) + Eigen::RowVector3d(0.0, 1.0, 0.0);
  EXPECT_NO_THROW(fromData(far));
}

TEST(ControlMesh, RejectsBadConnectivity) {
  MeshData d = cubeData();
  d.indices[2] = 0;  // face 0 = (0, 3, 0, 1)
  expectError<TopologyError>([&] { fromData(d); }, "face 0 repeats vertex 0");

  // Three faces on edge (0, 1).
  MeshData fin = gridData(1, 1);
  fin.vertices.conservativeResize(6, 3);
  fin.vertices.row(4) << 0, -1, 1;
  fin.vertices.row(5) << 1, -1, 1;
  fin.sizes = {4, 4, 4};
  fin.indices = {0, 1, 3, 2, 1, 0, 4, 5, 0, 1, 5, 4};
  expectError<TopologyError>([&] { fromData(fin); }, "shared by more than two faces");

  d = cubeData();
  std::swap(d.indices[4], d.indices[6]);  // flip face 1 (top): (6, 5, 4, 7)
  expectError<TopologyError>([&] { fromData(d); }, "inconsistently oriented");

  MeshData bowtie;
  bowtie.vertices.resize(5, 3);
  bowtie.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0;
  bowtie.sizes = {3, 3};
  bowtie.indices = {0, 1, 2, 0, 3, 4};
  expectError<TopologyError>([&] { fromData(bowtie); }, "vertex 0 is non-manifold");

  d = cubeData();
  d.vertices.conservativeResize(9, 3);
  d.vertices.row(8) << 5, 5, 5;
  expectError<TopologyError>([&] { fromData(d); }, "vertex 8 is not used by any face");
}

TEST(ControlMesh, RejectsBadCreasesAndCorners) {
  const MeshData d = cubeData();
  RowMatrixX2i creases(1, 2);
  creases << 0, 6;
  expectError<TopologyError>([&] { makeMesh(d, creases); }, "crease 0 (0, 6) is not an edge");
  creases << 0, 9;
  expectError<InvalidInputError>([&] { makeMesh(d, creases); },
                                 "crease 0 (0, 9) refers to a vertex");
  creases << 0, 1;
  expectError<InvalidInputError>([&] { makeMesh(d, creases, Eigen::VectorXd::Zero(1)); },
                                 "must be > 0");
  expectError<InvalidInputError>([&] { makeMesh(d, creases, Eigen::VectorXd::Ones(2)); },
                                 "1 creases but 2 sharpness");
  RowMatrixX2i twice(2, 2);
  twice << 0, 1, 1, 0;
  expectError<InvalidInputError>([&] { makeMesh(d, twice); }, "crease 1 (1, 0) repeats edge");
  expectError<InvalidInputError>([&] { makeMesh(d, RowMatrixX2i(0, 2), {}, {8}); },
                                 "corner 0 (vertex 8) is outside");
  expectError<InvalidInputError>(
      [&] {
        makeMesh(d, RowMatrixX2i(0, 2), {}, {3, 3});
      },
      "corner 1 (vertex 3) is listed twice");
}

}  // namespace
}  // namespace bvmesh

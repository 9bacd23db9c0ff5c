#include "core/subdiv/subdivision.h"

#include <gtest/gtest.h>
#include <opensubdiv/far/error.h>

#include <numeric>
#include <set>

#include "core/common/errors.h"
#include "core/subdiv/osd_refiner.h"
#include "mesh_fixtures.h"

namespace bvmesh {
namespace {

using testing::cubeData;
using testing::gridData;
using testing::makeMesh;
using testing::MeshData;
using testing::perturbed;

// The thesis' rules (3.1)-(3.5), written out for one step: face points are centroids; a smooth
// edge point is (f_left + 2 e_c + f_right) / 4; a smooth vertex moves to (f~ + 2 e~ + (n-3) p) / n;
// boundary and infinitely sharp crease edges get their midpoint; a vertex on exactly two
// boundary/crease edges moves to (p_left + 6 p + p_right) / 8; corners (tagged, on more than two
// sharp edges, or a boundary vertex with one face) stay.
RowMatrixX3d thesisRules(const ControlMesh& mesh) {
  const RowMatrixX3d& p = mesh.vertices();
  const int nv = mesh.numVertices(), ne = mesh.numEdges(), nf = mesh.numFaces();
  RowMatrixX3d result(nv + ne + nf, 3);
  std::vector<Eigen::RowVector3d> facePoint(static_cast<size_t>(nf));
  for (int f = 0; f < nf; ++f) {
    Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
    for (int i = 0; i < mesh.faceSize(f); ++i) sum += p.row(mesh.faceVertex(f, i));
    facePoint[static_cast<size_t>(f)] = sum / mesh.faceSize(f);
    result.row(nv + ne + f) = facePoint[static_cast<size_t>(f)];
  }
  const auto sharp = [&](int e) { return mesh.isBoundaryEdge(e) || mesh.edgeSharpness()(e) > 0.0; };
  for (int e = 0; e < ne; ++e) {
    const Eigen::RowVector3d mid = 0.5 * (p.row(mesh.edges()(e, 0)) + p.row(mesh.edges()(e, 1)));
    result.row(nv + e) =
        sharp(e) ? mid
                 : Eigen::RowVector3d(
                       0.25 * (facePoint[static_cast<size_t>(mesh.edgeFaces()(e, 0))] + 2.0 * mid +
                               facePoint[static_cast<size_t>(mesh.edgeFaces()(e, 1))]));
  }
  std::vector<std::vector<int>> vertexEdges(static_cast<size_t>(nv)),
      vertexFaces(static_cast<size_t>(nv));
  for (int e = 0; e < ne; ++e) {
    vertexEdges[static_cast<size_t>(mesh.edges()(e, 0))].push_back(e);
    vertexEdges[static_cast<size_t>(mesh.edges()(e, 1))].push_back(e);
  }
  for (int f = 0; f < nf; ++f) {
    for (int i = 0; i < mesh.faceSize(f); ++i) {
      vertexFaces[static_cast<size_t>(mesh.faceVertex(f, i))].push_back(f);
    }
  }
  const std::set<int> corners(mesh.corners().begin(), mesh.corners().end());
  for (int v = 0; v < nv; ++v) {
    const auto& edges = vertexEdges[static_cast<size_t>(v)];
    const auto& faces = vertexFaces[static_cast<size_t>(v)];
    std::vector<int> sharpNeighbours;
    bool boundary = false;
    for (int e : edges) {
      if (sharp(e)) sharpNeighbours.push_back(mesh.edges()(e, 0) + mesh.edges()(e, 1) - v);
      boundary = boundary || mesh.isBoundaryEdge(e);
    }
    if (corners.count(v) || sharpNeighbours.size() > 2 || (boundary && faces.size() == 1)) {
      result.row(v) = p.row(v);
    } else if (sharpNeighbours.size() == 2) {
      result.row(v) =
          (p.row(sharpNeighbours[0]) + 6.0 * p.row(v) + p.row(sharpNeighbours[1])) / 8.0;
    } else {
      const double n = static_cast<double>(edges.size());
      Eigen::RowVector3d faceAverage = Eigen::RowVector3d::Zero(), edgeAverage = faceAverage;
      for (int f : faces) {
        faceAverage += facePoint[static_cast<size_t>(f)] / static_cast<double>(faces.size());
      }
      for (int e : edges) {
        edgeAverage += 0.5 * (p.row(mesh.edges()(e, 0)) + p.row(mesh.edges()(e, 1))) / n;
      }
      result.row(v) = (faceAverage + 2.0 * edgeAverage + (n - 3.0) * p.row(v)) / n;
    }
  }
  return result;
}

// The thesis' figure 3.1 kind of mesh: a pentagon, a quad and two triangles, open, perturbed,
// with one interior crease and the vertex 2 of valence 4 inside.
ControlMesh mixedMesh() {
  MeshData d;
  d.vertices.resize(8, 3);
  d.vertices << 0, 0, 0, 2, 0, 0, 1, 1, 0, 0, 2, 0, -1, 1, 0, 2, 2, 0, 1, 3, 0, 3, 1, 0;
  d.vertices = perturbed(d.vertices, 0.2, 7);
  d.sizes = {5, 4, 3, 3};
  d.indices = {0, 1, 2, 3, 4, 2, 5, 6, 3, 1, 7, 2, 7, 5, 2};
  RowMatrixX2i creases(1, 2);
  creases << 2, 3;
  return makeMesh(d, creases);
}

TEST(Subdivision, CountsAndQuads) {
  for (const ControlMesh& mesh :
       {mixedMesh(), makeMesh(testing::prismData(5)), makeMesh(gridData(3, 2))}) {
    const SubdivisionResult result = subdivide(mesh);
    const ControlMesh& child = result.mesh;
    const int sumSizes = static_cast<int>(mesh.faceIndices().size());
    EXPECT_EQ(child.numVertices(), mesh.numVertices() + mesh.numEdges() + mesh.numFaces());
    EXPECT_EQ(child.numFaces(), sumSizes);
    EXPECT_EQ(child.numEdges(), 2 * mesh.numEdges() + sumSizes);
    EXPECT_TRUE(child.isAllQuads());
    EXPECT_EQ(child.boundaryEdges().size(), 2 * mesh.boundaryEdges().size());
    EXPECT_EQ(result.subdivisionOperator.rows(), child.numVertices());
    EXPECT_EQ(result.subdivisionOperator.cols(), mesh.numVertices());
  }
}

TEST(Subdivision, MatchesThesisRules) {
  const ControlMesh mixed = mixedMesh();
  MeshData cube = cubeData();
  cube.vertices = perturbed(cube.vertices, 0.15, 3);
  RowMatrixX2i topLoop(4, 2);
  topLoop << 4, 5, 5, 6, 6, 7, 7, 4;
  const ControlMesh creasedCube = makeMesh(cube, topLoop, Eigen::VectorXd(), {0});
  MeshData grid = gridData(3, 3);
  grid.vertices = perturbed(grid.vertices, 0.2, 11);
  for (const ControlMesh& mesh :
       {mixed, creasedCube, makeMesh(grid), makeMesh(testing::prismData(7))}) {
    const SubdivisionResult result = subdivide(mesh);
    const RowMatrixX3d expected = thesisRules(mesh);
    EXPECT_LT((result.mesh.vertices() - expected).cwiseAbs().maxCoeff(), 1e-12);
    const RowMatrixX3d applied = result.subdivisionOperator * mesh.vertices();
    EXPECT_LT((applied - expected).cwiseAbs().maxCoeff(), 1e-12);
    // Every row is an affine combination.
    const Eigen::VectorXd rowSums =
        result.subdivisionOperator * Eigen::VectorXd::Ones(mesh.numVertices());
    for (Eigen::Index i = 0; i < rowSums.size(); ++i) {
      EXPECT_NEAR(rowSums(i), 1.0, 1e-12) << "row " << i;
    }
  }
}

TEST(Subdivision, ChildConnectivityFollowsTheDocumentedOrder) {
  const ControlMesh mesh = mixedMesh();
  const ControlMesh child = subdivide(mesh).mesh;
  const int nv = mesh.numVertices(), ne = mesh.numEdges();
  int c = 0;
  for (int f = 0; f < mesh.numFaces(); ++f) {
    const int size = mesh.faceSize(f);
    for (int i = 0; i < size; ++i, ++c) {
      EXPECT_EQ(child.faceVertex(c, 0), mesh.faceVertex(f, i));
      EXPECT_EQ(child.faceVertex(c, 1), nv + mesh.faceEdge(f, i));
      EXPECT_EQ(child.faceVertex(c, 2), nv + ne + f);
      EXPECT_EQ(child.faceVertex(c, 3), nv + mesh.faceEdge(f, (i + size - 1) % size));
    }
  }
}

TEST(Subdivision, CreasesAndCornersPropagate) {
  RowMatrixX2i creases(2, 2);
  creases << 4, 5, 5, 6;
  Eigen::VectorXd sharpness(2);
  sharpness << kInfiniteSharpness, 2.0;
  const ControlMesh mesh = makeMesh(cubeData(), creases, sharpness, {0});
  const ControlMesh child = subdivide(mesh).mesh;
  ASSERT_EQ(child.creases().rows(), 4);
  const int nv = mesh.numVertices();
  const int e45 = nv + mesh.findEdge(4, 5), e56 = nv + mesh.findEdge(5, 6);
  EXPECT_EQ(child.edgeSharpness()(child.findEdge(4, e45)), kInfiniteSharpness);
  EXPECT_EQ(child.edgeSharpness()(child.findEdge(e45, 5)), kInfiniteSharpness);
  EXPECT_DOUBLE_EQ(child.edgeSharpness()(child.findEdge(5, e56)), 1.0);  // decays by one level
  EXPECT_DOUBLE_EQ(child.edgeSharpness()(child.findEdge(e56, 6)), 1.0);
  EXPECT_EQ(child.corners(), std::vector<int>{0});
  // Sharpness 1 is used up after one more level.
  const ControlMesh grandchild = subdivide(child).mesh;
  EXPECT_EQ(grandchild.creases().rows(), 4);
  EXPECT_EQ(grandchild.corners(), std::vector<int>{0});
}

TEST(Subdivision, OptionsChangeTheResult) {
  MeshData grid = gridData(2, 2);
  const ControlMesh mesh = makeMesh(grid);
  // Vertex 0 has one face: a corner by default, a smooth boundary point with EdgeOnly.
  const RowMatrixX3d fixedCorner = subdivide(mesh).mesh.vertices();
  EXPECT_EQ(fixedCorner.row(0), mesh.vertices().row(0));
  SubdivisionOptions edgeOnly;
  edgeOnly.boundary = SubdivisionOptions::Boundary::EdgeOnly;
  const RowMatrixX3d smoothCorner = subdivide(mesh, edgeOnly).mesh.vertices();
  EXPECT_LT((smoothCorner.row(0) -
             (mesh.vertices().row(1) + 6.0 * mesh.vertices().row(0) + mesh.vertices().row(3)) / 8.0)
                .norm(),
            1e-12);

  const ControlMesh prism = makeMesh(testing::prismData(3));
  SubdivisionOptions smoothTriangles;
  smoothTriangles.triangleRule = SubdivisionOptions::TriangleRule::Smooth;
  EXPECT_GT(
      (subdivide(prism).mesh.vertices() - subdivide(prism, smoothTriangles).mesh.vertices()).norm(),
      1e-6);
}

TEST(Subdivision, OpenSubdivErrorsBecomeTopologyErrors) {
  osd::installErrorHandler();
  try {
    OpenSubdiv::Far::Error(OpenSubdiv::Far::FAR_RUNTIME_ERROR, "face %d is broken", 7);
    FAIL() << "no exception";
  } catch (const TopologyError& error) {
    EXPECT_STREQ(error.what(), "OpenSubdiv: face 7 is broken");
  }
}

}  // namespace
}  // namespace bvmesh

#include "core/subdiv/limit_samples.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "core/common/errors.h"
#include "core/subdiv/limit_evaluator.h"
#include "mesh_fixtures.h"

namespace bvmesh {
namespace {

using testing::cubeData;
using testing::gridData;
using testing::makeMesh;
using testing::MeshData;
using testing::perturbed;

// Quad mesh with positions randomly displaced (same topology, same tags).
ControlMesh withPositions(const ControlMesh& mesh, double amplitude, unsigned seed) {
  ControlMesh result = mesh;
  result.setVertices(perturbed(mesh.vertices(), amplitude, seed));
  return result;
}

// Closed forms for the limit position of a vertex of an all-quad mesh (independent of
// OpenSubdiv): smooth vertex of valence n (n^2 p + 4 sum e_j + sum f_j) / (n (n + 5)); vertex on
// two crease/boundary edges (p_prev + 4 p + p_next) / 6; corner p. Returns false for vertices
// none of these covers (darts).
bool closedFormLimit(const ControlMesh& mesh, int v, Eigen::RowVector3d& limit) {
  const RowMatrixX3d& p = mesh.vertices();
  std::vector<int> neighbours, sharpNeighbours, diagonals;
  for (int e = 0; e < mesh.numEdges(); ++e) {
    if (mesh.edges()(e, 0) != v && mesh.edges()(e, 1) != v) continue;
    const int other = mesh.edges()(e, 0) + mesh.edges()(e, 1) - v;
    neighbours.push_back(other);
    if (mesh.isBoundaryEdge(e) || mesh.edgeSharpness()(e) > 0.0) sharpNeighbours.push_back(other);
  }
  for (int f = 0; f < mesh.numFaces(); ++f) {
    for (int i = 0; i < 4; ++i) {
      if (mesh.faceVertex(f, i) == v) diagonals.push_back(mesh.faceVertex(f, (i + 2) % 4));
    }
  }
  const bool corner =
      std::find(mesh.corners().begin(), mesh.corners().end(), v) != mesh.corners().end();
  const bool boundaryWithOneFace = diagonals.size() == 1;
  if (corner || sharpNeighbours.size() > 2 || boundaryWithOneFace) {
    limit = p.row(v);
  } else if (sharpNeighbours.size() == 2) {
    limit = (p.row(sharpNeighbours[0]) + 4.0 * p.row(v) + p.row(sharpNeighbours[1])) / 6.0;
  } else if (sharpNeighbours.empty()) {
    const double n = static_cast<double>(neighbours.size());
    limit = n * n * p.row(v);
    for (int e : neighbours) limit += 4.0 * p.row(e);
    for (int f : diagonals) limit += p.row(f);
    limit /= n * (n + 5.0);
  } else {
    return false;
  }
  return true;
}

void expectClosedForms(const ControlMesh& mesh, int expectedChecked) {
  ASSERT_TRUE(mesh.isAllQuads());
  const LimitSamples samples(mesh);
  const RowMatrixX3d limits = samples.positions(mesh.vertices());
  int checked = 0;
  for (int v = 0; v < mesh.numVertices(); ++v) {
    Eigen::RowVector3d expected;
    if (!closedFormLimit(mesh, v, expected)) continue;
    EXPECT_LT((limits.row(v) - expected).norm(), 1e-12) << "vertex " << v;
    ++checked;
  }
  EXPECT_EQ(checked, expectedChecked);
}

TEST(LimitSamples, ExtraordinaryVerticesMatchClosedForm) {
  for (int n = 3; n <= 8; ++n) {
    // After one step the cap centres have valence n; everything else valence 3 or 4.
    const ControlMesh mesh = withPositions(subdivide(makeMesh(testing::prismData(n))).mesh, 0.05,
                                           100u + static_cast<unsigned>(n));
    expectClosedForms(mesh, mesh.numVertices());
  }
}

TEST(LimitSamples, CreaseBoundaryAndCornerVerticesMatchClosedForm) {
  RowMatrixX2i topLoop(4, 2);
  topLoop << 4, 5, 5, 6, 6, 7, 7, 4;
  const ControlMesh cube = subdivide(makeMesh(cubeData(), topLoop, Eigen::VectorXd(), {0})).mesh;
  expectClosedForms(withPositions(cube, 0.05, 5), cube.numVertices());

  MeshData grid = gridData(4, 3);
  grid.vertices = perturbed(grid.vertices, 0.2, 9);
  grid.vertices.col(2) += perturbed(RowMatrixX3d::Zero(grid.vertices.rows(), 3), 0.5, 10).col(2);
  RowMatrixX2i inner(1, 2);
  inner << 6, 7;  // one crease edge inside: its ends are darts, not covered by the closed forms
  const ControlMesh open = makeMesh(grid, inner);
  expectClosedForms(open, open.numVertices() - 2);
}

// Uniform cubic B-spline basis and derivative.
std::array<double, 4> basis(double t) {
  const double s = 1.0 - t;
  return {s * s * s / 6.0, (3 * t * t * t - 6 * t * t + 4) / 6.0,
          (-3 * t * t * t + 3 * t * t + 3 * t + 1) / 6.0, t * t * t / 6.0};
}
std::array<double, 4> basisDerivative(double t) {
  return {-(1 - t) * (1 - t) / 2.0, (9 * t * t - 12 * t) / 6.0, (-9 * t * t + 6 * t + 3) / 6.0,
          t * t / 2.0};
}

TEST(LimitSamples, RegularGridIsTheBicubicBSpline) {
  const int nx = 6, ny = 6;
  MeshData grid = gridData(nx, ny);
  grid.vertices = perturbed(grid.vertices, 0.25, 21);
  grid.vertices.col(2) += perturbed(RowMatrixX3d::Zero(grid.vertices.rows(), 3), 0.6, 22).col(2);
  const ControlMesh mesh = makeMesh(grid);
  const auto point = [&](int i, int j) -> Eigen::RowVector3d {
    return mesh.vertices().row(j * (nx + 1) + i);
  };
  // B-spline patch of face (i, j) at (u, v), with derivatives; u along i, v along j.
  const auto spline = [&](int i, int j, double u, double v, Eigen::RowVector3d& du,
                          Eigen::RowVector3d& dv) {
    const auto bu = basis(u), bv = basis(v), dbu = basisDerivative(u), dbv = basisDerivative(v);
    Eigen::RowVector3d position = Eigen::RowVector3d::Zero();
    du.setZero();
    dv.setZero();
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        const Eigen::RowVector3d q = point(i - 1 + a, j - 1 + b);
        position += bu[static_cast<size_t>(a)] * bv[static_cast<size_t>(b)] * q;
        du += dbu[static_cast<size_t>(a)] * bv[static_cast<size_t>(b)] * q;
        dv += bu[static_cast<size_t>(a)] * dbv[static_cast<size_t>(b)] * q;
      }
    }
    return position;
  };

  // Samples of the interior faces (those with a full 4 x 4 neighbourhood).
  const LimitSamples samples(mesh);
  const RowMatrixX3d positions = samples.positions(mesh.vertices());
  const RowMatrixX3d normals = samples.normals(mesh.vertices());
  int checked = 0;
  for (int s = 0; s < samples.size(); ++s) {
    const SurfaceLocation& at = samples.locations()[static_cast<size_t>(s)];
    const int i = at.face % nx, j = at.face / nx;
    if (i < 1 || i > nx - 2 || j < 1 || j > ny - 2) continue;
    Eigen::RowVector3d du, dv;
    const Eigen::RowVector3d expected = spline(i, j, at.u, at.v, du, dv);
    EXPECT_LT((positions.row(s) - expected).norm(), 1e-12) << "sample " << s;
    EXPECT_LT((normals.row(s) - du.cross(dv).normalized()).norm(), 1e-12) << "sample " << s;
    ++checked;
  }
  EXPECT_GT(checked, 40);

  // Any (u, v) through the patch table.
  const LimitEvaluator evaluator(mesh);
  std::vector<SurfaceLocation> locations;
  for (int k = 0; k < 50; ++k) {
    const int i = 1 + k % 4, j = 1 + (k / 4) % 4;
    locations.push_back(
        {j * nx + i, (k * 0.137) - std::floor(k * 0.137), (k * 0.291) - std::floor(k * 0.291)});
  }
  const LimitEvaluation evaluation = evaluator.evaluate(mesh.vertices(), locations);
  for (size_t k = 0; k < locations.size(); ++k) {
    const auto q = static_cast<Eigen::Index>(k);
    Eigen::RowVector3d du, dv;
    const Eigen::RowVector3d expected = spline(locations[k].face % nx, locations[k].face / nx,
                                               locations[k].u, locations[k].v, du, dv);
    EXPECT_LT((evaluation.positions.row(q) - expected).norm(), 1e-12);
    EXPECT_LT((evaluation.derivativesU.row(q) - du).norm(), 1e-11);
    EXPECT_LT((evaluation.derivativesV.row(q) - dv).norm(), 1e-11);
    EXPECT_LT((evaluation.normals.row(q) - du.cross(dv).normalized()).norm(), 1e-11);
  }
}

TEST(LimitSamples, CreasedCubeKeepsASharpEdge) {
  RowMatrixX2i topLoop(4, 2);
  topLoop << 4, 5, 5, 6, 6, 7, 7, 4;
  const ControlMesh cube = makeMesh(cubeData(), topLoop);
  const LimitEvaluator evaluator(cube);
  // Edge (4, 5) seen from the top face (face 1: 4 5 6 7, edge 0 at v = 0) and from the side face
  // (face 2: 0 1 5 4, edge 2 at v = 1).
  const LimitEvaluation e = evaluator.evaluate(cube.vertices(), {{1, 0.5, 0.0}, {2, 0.5, 1.0}});
  EXPECT_LT((e.positions.row(0) - e.positions.row(1)).norm(), 1e-12);
  EXPECT_LT(e.normals.row(0).dot(e.normals.row(1)), 0.5);  // more than 60 degrees apart
  EXPECT_GT(e.normals(0, 2), 0.9);                         // top face normal points up

  // Without the crease the surface is smooth there.
  const ControlMesh smooth = makeMesh(cubeData());
  const LimitEvaluation s =
      LimitEvaluator(smooth).evaluate(smooth.vertices(), {{1, 0.5, 0.0}, {2, 0.5, 1.0}});
  EXPECT_GT(s.normals.row(0).dot(s.normals.row(1)), 1.0 - 1e-12);
}

TEST(LimitSamples, DescribeTheirSources) {
  RowMatrixX2i topLoop(4, 2);
  topLoop << 4, 5, 5, 6, 6, 7, 7, 4;
  const ControlMesh cube = makeMesh(cubeData(), topLoop, Eigen::VectorXd(), {0});
  const LimitSamples samples(cube);
  ASSERT_EQ(samples.size(), 8 + 12 + 6);
  for (int v = 0; v < 8; ++v) {
    EXPECT_EQ(samples.elements()[static_cast<size_t>(v)], SampleElement::Vertex);
    EXPECT_EQ(samples.sourceIds()(v), v);
    EXPECT_EQ(samples.features()[static_cast<size_t>(v)], v == 0   ? SampleFeature::Corner
                                                          : v >= 4 ? SampleFeature::Crease
                                                                   : SampleFeature::Smooth);
  }
  for (int e = 0; e < 12; ++e) {
    const int s = 8 + e;
    EXPECT_EQ(samples.elements()[static_cast<size_t>(s)], SampleElement::Edge);
    EXPECT_EQ(samples.sourceVertices().row(s), cube.edges().row(e));
    const bool onLoop = cube.edgeSharpness()(e) > 0.0;
    EXPECT_EQ(samples.features()[static_cast<size_t>(s)],
              onLoop ? SampleFeature::Crease : SampleFeature::Smooth);
  }
  EXPECT_EQ(samples.elements().back(), SampleElement::Face);
  EXPECT_EQ(samples.sourceIds()(samples.size() - 1), 5);

  const ControlMesh grid = makeMesh(gridData(2, 1));
  const LimitSamples open(grid);
  EXPECT_EQ(open.features()[0], SampleFeature::Corner);    // one face: a boundary corner
  EXPECT_EQ(open.features()[1], SampleFeature::Boundary);  // two faces on the boundary
  const int boundaryEdge = grid.findEdge(0, 1);
  EXPECT_EQ(open.features()[static_cast<size_t>(grid.numVertices() + boundaryEdge)],
            SampleFeature::Boundary);
  EXPECT_EQ(open.features()[static_cast<size_t>(grid.numVertices() + grid.findEdge(1, 4))],
            SampleFeature::Smooth);
}

TEST(LimitSamples, AgreeWithTheEvaluatorAtTheirLocations) {
  // Polygons of every size, a boundary, a crease: sample positions are the limit surface at the
  // documented (ptex face, u, v) locations; tangents agree with the patch derivatives.
  MeshData d;
  d.vertices.resize(8, 3);
  d.vertices << 0, 0, 0, 2, 0, 0, 1, 1, 0.3, 0, 2, 0, -1, 1, 0.2, 2, 2, 0.1, 1, 3, 0, 3, 1, -0.2;
  d.sizes = {5, 4, 3, 3};
  d.indices = {0, 1, 2, 3, 4, 2, 5, 6, 3, 1, 7, 2, 7, 5, 2};
  RowMatrixX2i crease(1, 2);
  crease << 2, 3;
  // Vertex 2 is a dart (the end of crease 2-3 inside the surface), where the limit masks are not
  // exact and the patch table's limit stencils take over.
  for (const ControlMesh& mesh :
       {makeMesh(d, crease), makeMesh(d), makeMesh(testing::prismData(5))}) {
    const LimitSamples samples(mesh);
    const LimitEvaluator evaluator(mesh, {}, 10);
    const LimitEvaluation e = evaluator.evaluate(mesh.vertices(), samples.locations());
    const RowMatrixX3d positions = samples.positions(mesh.vertices());
    const RowMatrixX3d normals = samples.normals(mesh.vertices());
    for (int s = 0; s < samples.size(); ++s) {
      EXPECT_LT((positions.row(s) - e.positions.row(s)).norm(), 1e-12) << "sample " << s;
      if (samples.features()[static_cast<size_t>(s)] != SampleFeature::Smooth) {
        continue;  // one-sided there
        // Gregory end patches approximate the tangent plane near extraordinary vertices.
        EXPECT_GT(normals.row(s).dot(e.normals.row(s)), 1.0 - 1e-6) << "sample " << s;
      }
    }
  }
}

TEST(LimitSamples, DartLimitIsTheLimitOfRefinement) {
  // Independent of the patch table: the limit at a dart is the limit of its refined positions;
  // refine six times: the refined dart vertex must keep approaching the sample (OpenSubdiv's
  // smooth limit mask at the dart is off by about 3e-3 here, and refinement stalls there).
  MeshData grid = gridData(4, 4);
  grid.vertices = perturbed(grid.vertices, 0.2, 13);
  grid.vertices.col(2) += perturbed(RowMatrixX3d::Zero(grid.vertices.rows(), 3), 0.5, 14).col(2);
  RowMatrixX2i crease(2, 2);
  crease << 6, 7, 7, 12;  // ends at darts 6 and 12
  ControlMesh mesh = makeMesh(grid, crease);
  const RowMatrixX3d limits = LimitSamples(mesh).positions(mesh.vertices());
  double previous = 0.0, distance = 0.0;
  for (int level = 0; level < 6; ++level) {
    mesh = subdivide(mesh).mesh;  // old vertex ids are kept by every step
    previous = distance;
    distance = (mesh.vertices().row(6) - limits.row(6)).norm();
  }
  EXPECT_LT(distance, 1e-3);
  EXPECT_LT(distance, 0.7 * previous);  // still converging towards the sample
}

TEST(LimitSamples, EvaluatorDerivativesAreTheSlopeOfPositions) {
  const ControlMesh mesh = withPositions(subdivide(makeMesh(testing::prismData(5))).mesh, 0.05, 31);
  const LimitEvaluator evaluator(mesh);
  const double h = 1e-6;
  for (int face : {0, 7, 19}) {
    const LimitEvaluation e = evaluator.evaluate(mesh.vertices(), {{face, 0.3, 0.6},
                                                                   {face, 0.3 + h, 0.6},
                                                                   {face, 0.3 - h, 0.6},
                                                                   {face, 0.3, 0.6 + h},
                                                                   {face, 0.3, 0.6 - h}});
    EXPECT_LT((e.derivativesU.row(0) - (e.positions.row(1) - e.positions.row(2)) / (2 * h)).norm(),
              1e-6);
    EXPECT_LT((e.derivativesV.row(0) - (e.positions.row(3) - e.positions.row(4)) / (2 * h)).norm(),
              1e-6);
  }
  EXPECT_THROW(evaluator.evaluate(mesh.vertices(), {{mesh.numFaces(), 0.5, 0.5}}),
               InvalidInputError);
  EXPECT_THROW(evaluator.evaluate(mesh.vertices(), {{0, 1.5, 0.5}}), InvalidInputError);
  EXPECT_THROW(evaluator.evaluate(RowMatrixX3d::Zero(2, 3), {{0, 0.5, 0.5}}), InvalidInputError);
}

TEST(LimitSamples, LargeEvaluatorBatchesAgreeWithSmallOnes) {
  // Batches of 20000 locations or more are split over threads: the same values as one by one,
  // and a bad location anywhere in the batch is still reported by its index.
  const ControlMesh mesh = withPositions(subdivide(makeMesh(testing::prismData(5))).mesh, 0.05, 31);
  const LimitEvaluator evaluator(mesh);
  std::vector<SurfaceLocation> locations;
  for (int q = 0; q < 30000; ++q)
    locations.push_back({q % mesh.numFaces(), (q % 101) / 100.0, (q % 37) / 36.0});
  const LimitEvaluation batch = evaluator.evaluate(mesh.vertices(), locations);
  for (int q : {0, 14999, 15000, 29999}) {
    const LimitEvaluation one = evaluator.evaluate(mesh.vertices(), {locations[static_cast<size_t>(q)]});
    EXPECT_EQ(batch.positions.row(q), one.positions.row(0));
    EXPECT_EQ(batch.normals.row(q), one.normals.row(0));
  }
  locations[25000].u = 2.0;
  try {
    evaluator.evaluate(mesh.vertices(), locations);
    FAIL() << "a location outside the face accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("location 25000"), std::string::npos) << error.what();
  }
}

TEST(LimitSamples, OperatorsAreReusableAndStable) {
  const ControlMesh mesh = subdivide(makeMesh(testing::prismData(6))).mesh;
  const LimitSamples first(mesh), second(withPositions(mesh, 0.1, 3));
  EXPECT_EQ((first.positionOperator() - second.positionOperator()).norm(), 0.0);
  EXPECT_EQ((first.tangentOperatorU() - second.tangentOperatorU()).norm(), 0.0);
  const RowMatrixX3d moved = perturbed(mesh.vertices(), 0.1, 4);
  const RowMatrixX3d direct = second.positionOperator() * moved;
  EXPECT_EQ(first.positions(moved), direct);
  const Eigen::VectorXd rowSums =
      first.positionOperator() * Eigen::VectorXd::Ones(mesh.numVertices());
  for (Eigen::Index i = 0; i < rowSums.size(); ++i) {
    EXPECT_NEAR(rowSums(i), 1.0, 1e-12) << "row " << i;
  }
  EXPECT_THROW(first.positions(RowMatrixX3d::Zero(3, 3)), InvalidInputError);
}

TEST(LimitSamples, NonFiniteControlPointsAreNamed) {
  // A NaN or an infinity used to pass through the operators and come out as NaN positions.
  const ControlMesh mesh = subdivide(makeMesh(testing::prismData(5))).mesh;
  const LimitSamples samples(mesh);
  const LimitEvaluator evaluator(mesh);
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity()}) {
    RowMatrixX3d points = mesh.vertices();
    points(7, 1) = bad;
    const auto expectNamed = [](const auto& call) {
      try {
        call();
        ADD_FAILURE() << "a non-finite control point accepted";
      } catch (const InvalidInputError& error) {
        EXPECT_NE(std::string(error.what()).find("vertex 7 has a non-finite coordinate"), std::string::npos)
            << error.what();
      }
    };
    expectNamed([&] { samples.positions(points); });
    expectNamed([&] { samples.normals(points); });
    expectNamed([&] { evaluator.evaluate(points, {{0, 0.5, 0.5}}); });
  }
}

}  // namespace
}  // namespace bvmesh

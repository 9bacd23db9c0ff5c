// The two-sided check's target side against a known narrow miss: a planar CAD plate whose
// tessellation has nodes only at its corners, and a limit surface of two flat patches that cover
// it except a strip between them. The nodes all lie on the limit surface, so the node-only check
// sees nothing; points on the CAD inside the triangles (Target::surfaceSamples) find the strip,
// whose middle is half its width from the nearest limit point.
#include "core/fit/limit_target_distance.h"

#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <gp_Pln.hxx>

#include <cmath>

#include "core/common/errors.h"
#include "core/subdiv/limit_evaluator.h"
#include "core/subdiv/subdivision.h"

namespace bvmesh::fit {
namespace {

// The plate [0, 3] x [0, 1] in z = 0.
target::Target plate() {
  return target::Target(BRepBuilderAPI_MakeFace(gp_Pln(), 0.0, 3.0, 0.0, 1.0).Face());
}

// Two flat quads in z = 0: [0, 1.4] x [0, 1] and [1.6, 3] x [0, 1] (every vertex a corner of its
// one face, so each limit patch covers exactly its rectangle).
ControlMesh twoPatches() {
  RowMatrixX3d v(8, 3);
  v << 0, 0, 0, 1.4, 0, 0, 1.4, 1, 0, 0, 1, 0, 1.6, 0, 0, 3, 0, 0, 3, 1, 0, 1.6, 1, 0;
  return ControlMesh(v, {4, 4}, {0, 1, 2, 3, 4, 5, 6, 7});
}

TEST(TwoSidedDistance, DenseTargetSamplesFindANarrowMissBetweenTessellationNodes) {
  const target::Target cad = plate();
  ASSERT_EQ(cad.meshNodes().rows(), 4);  // a plane's tessellation: its four corners
  const ControlMesh mesh = twoPatches();
  SubdivisionOptions options;
  options.boundary = SubdivisionOptions::Boundary::EdgeAndCorner;

  const TwoSidedDistance nodes = measureTwoSidedDistance(mesh, options, cad, 4);
  EXPECT_EQ(nodes.targetPoints, 4);
  EXPECT_LT(nodes.targetToLimit, 1e-12);  // every node lies on the limit surface
  EXPECT_LT(nodes.limitToTarget, 1e-12);  // and the limit surface on the plate

  // 3 subdivisions: points at x = 1 and 2 (sides and centroids), none inside the strip 1.4 < x < 1.6.
  EXPECT_LT(measureTwoSidedDistance(mesh, options, cad, 4, nullptr, 3).targetToLimit, 1e-12);
  // 4: x = 1.5 on the long sides, the strip's middle, 0.1 from both patches.
  const TwoSidedDistance dense = measureTwoSidedDistance(mesh, options, cad, 4, nullptr, 4);
  EXPECT_EQ(dense.targetPoints, 4 + 5 * 3 + 2 * 3);  // nodes, 5 triangle sides, 2 triangles' insides
  EXPECT_NEAR(dense.targetToLimit, 0.1, 1e-9);
  EXPECT_NEAR(dense.targetToLimitAt.x(), 1.5, 1e-9);
  EXPECT_NEAR(dense.targetToLimitBeyondCad, 0.1, 1e-6);  // the plate's own tolerance is 1e-7
  EXPECT_LT(dense.limitToTarget, 1e-12);
}

// The target side is measured on the limit surface itself, not on its tessellation by the check's
// grid: a cube's limit surface (subdivided twice, scaled to a mean radius of 1) against the unit
// sphere. The limit surface is star-shaped about the origin, so each target point P is at most
// | |Q| - 1 | from the limit point Q on its ray: the distance is bounded by the largest | |q| - 1 |
// over the surface (a dense grid of limit points). The tessellation's chordal error at 2 points
// per face broke that bound, and the result varied with the grid.
TEST(TwoSidedDistance, TargetSideIsTheDistanceToTheLimitSurfaceWhateverTheGrid) {
  const target::Target cad(BRepPrimAPI_MakeSphere(1.0).Shape());
  RowMatrixX3d v(8, 3);
  v << -1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1;
  ControlMesh mesh(v, {4, 4, 4, 4, 4, 4},
                   {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7});
  mesh = subdivide(subdivide(mesh).mesh).mesh;
  const SubdivisionOptions options;

  const LimitEvaluator evaluator(mesh, options);
  std::vector<SurfaceLocation> dense;
  const int n = 32;
  for (int face = 0; face < evaluator.numPtexFaces(); ++face) {
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i <= n; ++i)
        dense.push_back({face, static_cast<double>(i) / n, static_cast<double>(j) / n});
    }
  }
  const RowMatrixX3d unscaled = evaluator.evaluate(mesh.vertices(), dense).positions;
  const double scale = 1.0 / unscaled.rowwise().norm().mean();
  mesh.setVertices(scale * mesh.vertices());
  const double radialBound = (scale * unscaled.rowwise().norm().array() - 1.0).abs().maxCoeff();
  ASSERT_GT(radialBound, 0.01);

  const TwoSidedDistance coarse = measureTwoSidedDistance(mesh, options, cad, 2);
  const TwoSidedDistance fine = measureTwoSidedDistance(mesh, options, cad, 8);
  EXPECT_GT(coarse.targetToLimit, 0.5 * radialBound);
  EXPECT_LE(coarse.targetToLimit, radialBound + 1e-9);
  EXPECT_NEAR(coarse.targetToLimit, fine.targetToLimit, 1e-9);
  EXPECT_NEAR((coarse.targetToLimitAt - fine.targetToLimitAt).norm(), 0.0, 1e-9);
  EXPECT_NEAR(coarse.targetToLimitBeyondCad, fine.targetToLimitBeyondCad, 1e-9);
}

TEST(TwoSidedDistance, SurfaceSamplesLieOnTheCad) {
  // A sphere's tessellation is a polyhedron inside it (its triangles' midpoints up to the
  // deflection); the samples are on the sphere itself, each once.
  const target::Target cad(BRepPrimAPI_MakeSphere(1.0).Shape());
  const target::SurfaceSamples samples = cad.surfaceSamples(4);
  EXPECT_GT(samples.points.rows(), 9 * cad.meshNodes().rows());
  EXPECT_LT((samples.points.rowwise().norm().array() - 1.0).abs().maxCoeff(), 1e-9);
  EXPECT_EQ(samples.tolerances.size(), samples.points.rows());
  const target::SurfaceSamples nodes = cad.surfaceSamples(1);
  EXPECT_EQ(nodes.points, cad.meshNodes());
  EXPECT_EQ(nodes.tolerances, cad.meshNodeTolerances());
  EXPECT_THROW(cad.surfaceSamples(0), InvalidInputError);
}

}  // namespace
}  // namespace bvmesh::fit

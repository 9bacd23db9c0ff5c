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

namespace bvmesh::fit {
namespace {

// The plate [0, 3] x [0, 1] in z = 0.
target::Target plate() { return target::Target(BRepBuilderAPI_MakeFace(gp_Pln(), 0.0, 3.0, 0.0, 1.0).Face()); }

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

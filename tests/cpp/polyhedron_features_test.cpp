// Feature curves of CAD targets and the mapping of polyhedron creases, boundaries and corners
// onto them. Independent truths: the primitives' known edges and vertices, and the M6 wing's CAD
// topology (read off the STEP file with FreeCAD).
#include <gtest/gtest.h>

#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/cad/shape_io.h"
#include "core/common/errors.h"
#include "core/polyhedron/feature_mapping.h"
#include "core/polyhedron/target_analysis.h"

namespace bvmesh::polyhedron {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A cube [-1, 1]^3 as a control mesh, optionally with creases along its 12 edges and corners.
ControlMesh cube(double half, bool creased) {
  RowMatrixX3d v(8, 3);
  v << -1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1;
  v *= half;
  const std::vector<int> faces{0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};
  if (!creased) return ControlMesh(v, std::vector<int>(6, 4), faces);
  RowMatrixX2i creases(12, 2);
  creases << 0, 1, 1, 2, 2, 3, 3, 0, 4, 5, 5, 6, 6, 7, 7, 4, 0, 4, 1, 5, 2, 6, 3, 7;
  return ControlMesh(v, std::vector<int>(6, 4), faces, creases, Eigen::VectorXd(), {0, 1, 2, 3, 4, 5, 6, 7});
}

TEST(FeatureCurves, BoxEdgesEndAtCornersWhereThreeMeet) {
  const target::Target box(BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), gp_Pnt(2, 3, 4)).Shape());
  const std::vector<FeatureCurve> curves = detectFeatureCurves(box);
  ASSERT_EQ(curves.size(), 12u);
  std::vector<double> lengths;
  for (const FeatureCurve& c : curves) {
    EXPECT_EQ(c.kind, FeatureCurveKind::Sharp);
    EXPECT_EQ(c.edges.size(), 1u);
    EXPECT_FALSE(c.closed);
    lengths.push_back(std::round(c.length * 1e6) / 1e6);
  }
  EXPECT_EQ(lengths, (std::vector<double>{4, 4, 4, 4, 3, 3, 3, 3, 2, 2, 2, 2}));  // longest first
}

TEST(FeatureCurves, CylinderRimsAreClosedCurves) {
  const target::Target cylinder(BRepPrimAPI_MakeCylinder(1.0, 2.0).Shape());
  const std::vector<FeatureCurve> curves = detectFeatureCurves(cylinder);
  ASSERT_EQ(curves.size(), 2u);  // the seam is not a feature
  for (const FeatureCurve& c : curves) {
    EXPECT_TRUE(c.closed);
    EXPECT_NEAR(c.length, 2.0 * kPi, 1e-3);
  }
}

TEST(FeatureCurves, OneraM6TrailingEdgeAndRootLoop) {
  const HalfModelShape half =
      removeSymmetryFace(cad::readShapeFile(std::string(BVMESH_TEST_DATA_DIR) + "/AileM6_with_sharp_TE.stp"));
  const target::Target wing(half.shape);
  const std::vector<FeatureCurve> curves = detectFeatureCurves(wing);
  // Longest sharp curve: the trailing edge, 1242.6 mm, from root (810.49, 0, 0) to tip.
  ASSERT_FALSE(curves.empty());
  EXPECT_EQ(curves[0].kind, FeatureCurveKind::Sharp);
  EXPECT_NEAR(curves[0].length, 1242.611, 0.01);
  // The root section: four free edges chained through tangent-continuous vertices into one loop
  // that starts and ends at the sharp root trailing edge.
  int loops = 0;
  for (const FeatureCurve& c : curves) {
    if (c.kind != FeatureCurveKind::Boundary) continue;
    ++loops;
    EXPECT_EQ(c.edges.size(), 4u);
    EXPECT_TRUE(c.closed);
    EXPECT_FALSE(c.smoothLoop);
    EXPECT_NEAR((wing.vertexPosition(c.startVertex) - Eigen::Vector3d(810.491484, 0, 0)).norm(), 0.0, 1e-5);
    EXPECT_NEAR(c.length, 818.733 + 818.735 + 4.627 + 4.627, 0.01);
    // The polyline runs along the chain from its start back to it, through the leading edge.
    const target::Points line = curvePolyline(wing, c);
    EXPECT_LT((line.row(0).transpose() - wing.vertexPosition(c.startVertex)).norm(), 1e-6);
    EXPECT_LT((line.row(line.rows() - 1).transpose() - wing.vertexPosition(c.endVertex)).norm(), 1e-6);
    EXPECT_LT(line.col(0).minCoeff(), 1e-3);
  }
  EXPECT_EQ(loops, 1);
  // Its plane is the symmetry plane y = 0, the wing on the +y side.
  const std::optional<fit::SymmetryPlane> plane = detectSymmetryPlane(wing, curves);
  ASSERT_TRUE(plane.has_value());
  EXPECT_NEAR(plane->normal.y(), 1.0, 1e-9);
  EXPECT_NEAR(plane->point.y(), 0.0, 1e-6);
}

TEST(MeshFeatureChains, LoopsAndCornersSplitChains) {
  const ControlMesh plain = cube(1.0, false);
  RowMatrixX2i top(4, 2);
  top << 4, 5, 5, 6, 6, 7, 7, 4;
  const ControlMesh loop(plain.vertices(), plain.faceSizes(), plain.faceIndices(), top);
  std::vector<MeshFeatureChain> chains = meshFeatureChains(loop);
  ASSERT_EQ(chains.size(), 1u);
  EXPECT_TRUE(chains[0].closed);
  EXPECT_EQ(chains[0].vertices.size(), 4u);
  // A corner on the loop opens it there.
  const ControlMesh cornered(plain.vertices(), plain.faceSizes(), plain.faceIndices(), top, Eigen::VectorXd(),
                             {6});
  chains = meshFeatureChains(cornered);
  ASSERT_EQ(chains.size(), 1u);
  EXPECT_FALSE(chains[0].closed);
  EXPECT_EQ(chains[0].vertices.front(), 6);
  EXPECT_EQ(chains[0].vertices.back(), 6);
  // The creased cube: 12 chains of one edge between corners.
  EXPECT_EQ(meshFeatureChains(cube(1.0, true)).size(), 12u);
}

TEST(FeatureMapping, CreasedCubeMapsOntoABox) {
  const target::Target box(BRepPrimAPI_MakeBox(gp_Pnt(-1, -1, -1), gp_Pnt(1, 1, 1)).Shape());
  const ControlMesh mesh = cube(1.02, true);  // a little off the box
  const FeatureMapping mapping = mapFeatures(mesh, box, detectFeatureCurves(box));
  EXPECT_TRUE(mapping.complete()) << mapping.describeUnmapped();
  ASSERT_EQ(mapping.map.curves.size(), 12u);
  for (int e : mesh.creaseEdges()) {
    const int curve = mapping.map.edgeCurve[static_cast<size_t>(e)];
    ASSERT_GE(curve, 0);
    ASSERT_EQ(mapping.map.curves[static_cast<size_t>(curve)].size(), 1u);
    // The CAD edge joins the CAD vertices nearest to the crease's end points.
    const std::array<int, 2> ends = box.edgeVertices(mapping.map.curves[static_cast<size_t>(curve)][0]);
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector3d p = mesh.vertices().row(mesh.edges()(e, k)).transpose() / 1.02;
      EXPECT_TRUE((box.vertexPosition(ends[0]) - p).norm() < 1e-9 ||
                  (box.vertexPosition(ends[1]) - p).norm() < 1e-9);
    }
  }
  for (int v = 0; v < 8; ++v) {
    const int cad = mapping.map.vertexCadVertex[static_cast<size_t>(v)];
    ASSERT_GE(cad, 0);
    EXPECT_LT((box.vertexPosition(cad) - mesh.vertices().row(v).transpose() / 1.02).norm(), 1e-9);
  }
}

TEST(FeatureMapping, UnmappedCreasesAreReportedNotThrown) {
  // A creased cube around a sphere: the sphere has no sharp curves and no vertices near the corners.
  const target::Target sphere(BRepPrimAPI_MakeSphere(1.0).Shape());
  const ControlMesh mesh = cube(0.6, true);
  const FeatureMapping mapping = mapFeatures(mesh, sphere, detectFeatureCurves(sphere));
  EXPECT_FALSE(mapping.complete());
  EXPECT_EQ(mapping.unmappedChains.size(), 12u);
  const std::string report = mapping.describeUnmapped();
  EXPECT_NE(report.find("crease chain 0 (vertices"), std::string::npos) << report;
  EXPECT_NE(report.find("the target has no sharp curves"), std::string::npos) << report;
  try {
    requireComplete(mapping);
    FAIL() << "incomplete mapping accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("unmapped polyhedron features"), std::string::npos);
  }
  // A crease across a box face (a diagonal) runs along no box edge: reported with the nearest
  // candidate's distance and angle.
  const target::Target box(BRepPrimAPI_MakeBox(gp_Pnt(-1, -1, -1), gp_Pnt(1, 1, 1)).Shape());
  const ControlMesh plain = cube(1.0, false);
  std::vector<int> sizes{3, 3, 4, 4, 4, 4, 4};
  std::vector<int> faces{0, 3, 2, 0, 2, 1};  // bottom face split along its diagonal 0-2
  faces.insert(faces.end(), plain.faceIndices().begin() + 4, plain.faceIndices().end());
  RowMatrixX2i diagonal(1, 2);
  diagonal << 0, 2;
  const ControlMesh split(plain.vertices(), sizes, faces, diagonal);
  const FeatureMapping crossing = mapFeatures(split, box, detectFeatureCurves(box));
  ASSERT_EQ(crossing.unmappedChains.size(), 1u);
  const ChainMapping& m = crossing.chainMappings[0];
  EXPECT_GE(m.nearestCurve, 0);
  EXPECT_GT(m.meanAngleDeg, 30.0);
  EXPECT_NE(crossing.describeUnmapped().find("the nearest is curve"), std::string::npos);
}

}  // namespace
}  // namespace bvmesh::polyhedron

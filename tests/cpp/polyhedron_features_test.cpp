// Feature curves of CAD targets and the mapping of polyhedron creases, boundaries and corners
// onto them. Independent truths: the primitives' known edges and vertices, and the M6 wing's CAD
// topology (read off the STEP file with FreeCAD).
#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
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

// Two 10 x 10 plates sewn along the edge x in [0, 10], y = 10, folded there by `angleDeg`.
TopoDS_Shape foldedPlates(double angleDeg) {
  const double a = angleDeg * kPi / 180.0;
  const auto face = [](const gp_Pnt& p0, const gp_Pnt& p1, const gp_Pnt& p2, const gp_Pnt& p3) {
    return BRepBuilderAPI_MakeFace(BRepBuilderAPI_MakePolygon(p0, p1, p2, p3, true).Wire()).Face();
  };
  BRepBuilderAPI_Sewing sewing(1e-7);
  sewing.Add(face({0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}));
  sewing.Add(face({0, 10, 0}, {10, 10, 0}, {10, 10 + 10 * std::cos(a), 10 * std::sin(a)},
                  {0, 10 + 10 * std::cos(a), 10 * std::sin(a)}));
  sewing.Perform();
  return sewing.SewedShape();
}

TEST(FeatureCurves, KinksAreEdgesWhoseRoundingCostsMoreThanTheTolerance) {
  // A 2 degree fold 10 long: rounded over its own length a smooth surface misses it by about
  // theta L / 4 = 0.0349 * 10 / 4 = 0.0873, so it is a kink against a tolerance of 0.08, not 0.09.
  const target::Target plates(foldedPlates(2.0));
  ASSERT_EQ(plates.freeEdges().size(), 6u);
  FeatureCurveOptions options;
  options.kinkTolerance = 0.08;
  const std::vector<int> kinks = kinkEdges(plates, options);
  ASSERT_EQ(kinks.size(), 1u);
  const std::array<int, 2> ends = plates.edgeVertices(kinks[0]);
  EXPECT_NEAR(plates.vertexPosition(ends[0]).y(), 10.0, 1e-9);
  EXPECT_NEAR(plates.vertexPosition(ends[1]).y(), 10.0, 1e-9);
  const std::vector<FeatureCurve> curves = detectFeatureCurves(plates, options);
  ASSERT_FALSE(curves.empty());  // the free boundary's curves, then the kink
  EXPECT_EQ(curves.back().kind, FeatureCurveKind::Kink);
  EXPECT_NEAR(curves.back().length, 10.0, 1e-9);
  EXPECT_EQ(std::count_if(curves.begin(), curves.end(),
                          [](const FeatureCurve& c) { return c.kind == FeatureCurveKind::Kink; }),
            1);
  options.kinkTolerance = 0.09;
  EXPECT_TRUE(kinkEdges(plates, options).empty());
  options.kinkTolerance = 0.0;  // 1e-5 of the diagonal (22.4)
  EXPECT_EQ(kinkEdges(plates, options).size(), 1u);
  options.includeKinks = false;
  EXPECT_TRUE(kinkEdges(plates, options).empty());
  // Flat plates have no kink; 30 degrees is sharp, not a kink.
  EXPECT_TRUE(kinkEdges(target::Target(foldedPlates(0.0))).empty());
  const target::Target sharp(foldedPlates(30.5));
  EXPECT_TRUE(kinkEdges(sharp).empty());
  EXPECT_EQ(detectFeatureCurves(sharp)[0].kind, FeatureCurveKind::Sharp);
}

TEST(FeatureCurves, OneraM6TipKinks) {
  // The M6's kinks at 1e-5 of its diagonal: where the tip's two leading-edge patches meet the
  // wing (FreeCAD's Edge7, Edge15: 12.3 mm, up to 2.3 degrees) and each other along the tip's
  // ridge (Edge6: 15.8 mm, 0.2-0.5 degrees). Not the tip section's edges behind them (Edge9,
  // Edge16, 448 mm), which turn by 0.1 degree next to the kinks' ends and are smooth along their
  // length; nor the leading-edge patches' edges to the tip cap (Edge8, Edge14: 0.26 degrees, with
  // an OCCT tolerance of 3.3e-2 mm that covers their rounding).
  const HalfModelShape half =
      removeSymmetryFace(cad::readShapeFile(std::string(BVMESH_TEST_DATA_DIR) + "/AileM6_with_sharp_TE.stp"));
  const target::Target wing(half.shape);
  const Eigen::Vector3d tipLeadingEdge(690.66, 1196.3, 0.0), lower(697.7, 1196.3, -9.3), upper(697.7, 1196.3, 9.3),
      ridge(703.1, 1205.6, 0.0), tipTrailingEdge(1144.0, 1196.3, 0.0);
  // The edge between two points, by its end vertices (within 0.1 mm in x and z, 0.5 mm in y).
  const auto edgeBetween = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const auto near = [&](int v, const Eigen::Vector3d& p) {
      const Eigen::Vector3d d = wing.vertexPosition(v) - p;
      return std::abs(d.x()) < 0.1 && std::abs(d.y()) < 0.5 && std::abs(d.z()) < 0.4;
    };
    for (int e = 0; e < wing.edgeCount(); ++e) {
      const std::array<int, 2> ends = wing.edgeVertices(e);
      if ((near(ends[0], a) && near(ends[1], b)) || (near(ends[0], b) && near(ends[1], a))) return e;
    }
    return -1;
  };
  std::vector<int> expected{edgeBetween(tipLeadingEdge, lower), edgeBetween(tipLeadingEdge, upper),
                            edgeBetween(tipLeadingEdge, ridge)};
  std::vector<int> kinks = kinkEdges(wing);
  std::sort(kinks.begin(), kinks.end());
  std::sort(expected.begin(), expected.end());
  EXPECT_GE(expected.front(), 0);
  EXPECT_EQ(kinks, expected);
  for (const Eigen::Vector3d& end : {lower, upper}) {
    const int behind = edgeBetween(end, tipTrailingEdge);  // Edge9, Edge16
    ASSERT_GE(behind, 0);
    // Rounded over its 448 mm, its largest angle (0.08-0.1 degrees, next to the kink's end) would
    // miss by more than the tolerance; its mean angle does not.
    const cad::EdgeInfo& info = wing.report().shape.edges[static_cast<size_t>(behind)];
    const double tolerance = 1e-5 * wing.report().diagonal;
    EXPECT_GT(info.maxDihedralDegrees * kPi / 180.0 * info.length / 4.0, tolerance);
    EXPECT_LT(info.meanDihedralDegrees * kPi / 180.0 * info.length / 4.0, tolerance);
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

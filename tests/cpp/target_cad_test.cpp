// Target on real CAD files, against independent truth: BRepExtrema_DistShapeShape (the
// algorithm behind FreeCAD's distToShape) for distances, BRepClass_FaceClassifier for trims.
#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRep_Builder.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_Surface.hxx>
#include <IGESControl_Writer.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/cad/isolated_reader.h"
#include "core/cad/shape_io.h"
#include "core/target/target.h"
#include "core/target/target_data.h"

namespace bvmesh::target {
namespace {

const std::string kDataDir = BVMESH_TEST_DATA_DIR;

// #count points: half near the surface (a tessellation node moved by up to 2% of the model
// size), half anywhere in the bounding box grown by half its size.
Points mixedPoints(const Target& target, int count, unsigned seed) {
  const TargetReport& report = target.report();
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<Eigen::Index> node(0, target.meshNodes().rows() - 1);
  const Eigen::Vector3d lo(report.shape.boundsMin[0], report.shape.boundsMin[1], report.shape.boundsMin[2]);
  const Eigen::Vector3d hi(report.shape.boundsMax[0], report.shape.boundsMax[1], report.shape.boundsMax[2]);
  const Eigen::Vector3d center = 0.5 * (lo + hi);
  Points points(count, 3);
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d random(unit(generator), unit(generator), unit(generator));
    if (i % 2 == 0)
      points.row(i) = target.meshNodes().row(node(generator)) + 0.02 * report.diagonal * random.transpose();
    else
      points.row(i) = (center + random.cwiseProduct(hi - lo)).transpose();
  }
  return points;
}

class TargetCad : public ::testing::TestWithParam<std::string> {};

TEST_P(TargetCad, DistancesMatchBRepExtremaAndFeetLieOnTheirTrimmedFaces) {
  const TopoDS_Shape shape = cad::readShapeFile(kDataDir + "/" + GetParam());
  const Target target(shape);
  const double size = target.report().diagonal;
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  ASSERT_EQ(faces.Extent(), target.faceCount());

  // The surface itself: BRepExtrema measures 0 for points inside a solid.
  TopoDS_Compound surface;
  BRep_Builder builder;
  builder.MakeCompound(surface);
  for (int f = 1; f <= faces.Extent(); ++f) builder.Add(surface, faces(f));

  const Points points = mixedPoints(target, 300, 11);
  const ProjectionResult result = target.project(points);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const gp_Pnt q(points(i, 0), points(i, 1), points(i, 2));
    BRepExtrema_DistShapeShape reference(BRepBuilderAPI_MakeVertex(q).Vertex(), surface);
    ASSERT_TRUE(reference.IsDone());
    const auto status = result.status[static_cast<std::size_t>(i)];
    ASSERT_TRUE(status == ProjectionStatus::Ok || status == ProjectionStatus::OnTrimBoundary) << "point " << i;
    // Where the nearest point is a vertex or lies on an edge, BRepExtrema measures to the vertex
    // point or the edge's 3D curve, which the model places only within that tolerance of the
    // faces (the M6's tip edges, tolerance 3.3e-2 mm, run up to 1.2e-2 mm off both of their
    // faces' surfaces), while a foot inside a face lies on its surface.
    double modelTolerance = 0;
    if (reference.SupportTypeShape2(1) == BRepExtrema_IsVertex)
      modelTolerance = BRep_Tool::Tolerance(TopoDS::Vertex(reference.SupportOnShape2(1)));
    else if (reference.SupportTypeShape2(1) == BRepExtrema_IsOnEdge)
      modelTolerance = BRep_Tool::Tolerance(TopoDS::Edge(reference.SupportOnShape2(1)));
    EXPECT_NEAR(result.distances[i], reference.Value(), 1e-9 * size + modelTolerance) << "point " << i;

    // The foot point is S(u, v) of its face, and (u, v) lies inside that face's trim.
    const TopoDS_Face& face = TopoDS::Face(faces(result.faces[i] + 1));
    const gp_Pnt onSurface = BRep_Tool::Surface(face)->Value(result.params(i, 0), result.params(i, 1));
    const double edgeTolerance = status == ProjectionStatus::OnTrimBoundary ? 2 * BRep_Tool::MaxTolerance(face, TopAbs_EDGE) : 0;
    EXPECT_LE(onSurface.Distance(gp_Pnt(result.points(i, 0), result.points(i, 1), result.points(i, 2))),
              1e-9 * size + edgeTolerance)
        << "point " << i;
    const BRepClass_FaceClassifier classifier(face, gp_Pnt2d(result.params(i, 0), result.params(i, 1)),
                                              BRep_Tool::Tolerance(face));
    EXPECT_NE(classifier.State(), TopAbs_OUT) << "point " << i << " face " << result.faces[i];
  }
}

TEST_P(TargetCad, WarmStartsEqualColdStarts) {
  const Target target(cad::readShapeFile(kDataDir + "/" + GetParam()));
  const double size = target.report().diagonal;
  const Points points = mixedPoints(target, 2000, 12);
  const ProjectionResult previous = target.project(points);
  // A fitting pass moves its samples a little and warm-starts from their previous locations.
  const Points moved = points + 1e-3 * size * mixedPoints(target, 2000, 13).rowwise().normalized();
  const SurfaceHints hints{previous.faces, previous.params};
  const ProjectionResult warm = target.project(moved, &hints);
  const ProjectionResult cold = target.project(moved);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    EXPECT_NEAR(warm.distances[i], cold.distances[i], 1e-12 * size) << "point " << i;
    EXPECT_LE((warm.points.row(i) - cold.points.row(i)).norm(), 1e-9 * size) << "point " << i;
    EXPECT_EQ(warm.status[static_cast<std::size_t>(i)], cold.status[static_cast<std::size_t>(i)]) << "point " << i;
  }
}

// The trim classifier (grid of known cells, rays to the nearest one) against OCCT's classifier
// on the exact pcurves, for random (u, v) in and around every face's parameter box. The
// polygon here samples each pcurve uniformly (deviation ~1e-8 of the box); points within 1e-6
// of the boundary (BRepClass: ON) are skipped.
TEST_P(TargetCad, TrimClassifierAgreesWithBRepClass) {
  const TopoDS_Shape shape = cad::readShapeFile(kDataDir + "/" + GetParam());
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  std::mt19937 generator(21);
  std::uniform_real_distribution<double> unit(-0.05, 1.05);
  for (int f = 1; f <= faces.Extent(); ++f) {
    const TopoDS_Face& face = TopoDS::Face(faces(f));
    double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
    BRepTools::UVBounds(face, u0, u1, v0, v1);
    std::vector<std::vector<Eigen::Vector2d>> curves;
    for (TopExp_Explorer it(face, TopAbs_EDGE); it.More(); it.Next()) {
      double first = 0, last = 0;
      const Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(TopoDS::Edge(it.Current()), face, first, last);
      ASSERT_FALSE(pcurve.IsNull());
      constexpr int kSamples = 4000;
      std::vector<Eigen::Vector2d> polyline;
      for (int k = 0; k <= kSamples; ++k) {
        const gp_Pnt2d p = pcurve->Value(first + (last - first) * k / kSamples);
        polyline.emplace_back(p.X(), p.Y());
      }
      curves.push_back(std::move(polyline));
    }
    const TrimClassifier classifier(u0, u1, v0, v1, curves);
    const double tolerance = 1e-6 * std::max(u1 - u0, v1 - v0);
    int compared = 0;
    for (int k = 0; k < 2000; ++k) {
      const double u = u0 + unit(generator) * (u1 - u0);
      const double v = v0 + unit(generator) * (v1 - v0);
      const TopAbs_State state = BRepClass_FaceClassifier(face, gp_Pnt2d(u, v), tolerance).State();
      if (state == TopAbs_ON) continue;
      ++compared;
      EXPECT_EQ(classifier.inside(u, v), state == TopAbs_IN) << "face " << f - 1 << " (u, v) = (" << u << ", " << v << ")";
    }
    EXPECT_GT(compared, 1900) << "face " << f - 1;
  }
}

INSTANTIATE_TEST_SUITE_P(Files, TargetCad, ::testing::Values("AileM6_with_sharp_TE.stp", "hemisph-cyl.stp"));

TEST(TargetCad, GapsBetweenConsecutivePcurvesDoNotOpenTheTrim) {
  // On the M6's upper surface (FreeCAD's Face11) the pcurves of the two tip edges meeting at the
  // vertex (697.74, 1196.3, 9.35) miss each other in v by 5e-7 (0.02668286 / 0.02668337 at u = 1).
  // Points whose trim test casts its ray through that gap were taken for outside the face and
  // projected 11.4 mm away onto the leading edge. Points 1e-4 off the surface along the stripe
  // through the gap, on both sides: the foot is the surface point.
  const TopoDS_Shape shape = cad::readShapeFile(kDataDir + "/AileM6_with_sharp_TE.stp");
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  const Handle(Geom_Surface) surface = BRep_Tool::Surface(TopoDS::Face(faces(11)));
  const Target target(shape);
  const double v = 0.5 * (0.0266828631725 + 0.0266833656468);
  Points points(0, 3);
  for (double u : {0.9, 0.95, 0.97, 0.975440971124, 0.98, 0.99, 0.995}) {
    gp_Pnt p;
    gp_Vec su, sv;
    surface->D1(u, v, p, su, sv);
    const gp_Vec normal = su.Crossed(sv).Normalized();
    for (double offset : {-1e-4, 1e-4}) {
      points.conservativeResize(points.rows() + 1, 3);
      points.row(points.rows() - 1) << p.X() + offset * normal.X(), p.Y() + offset * normal.Y(), p.Z() + offset * normal.Z();
    }
  }
  const ProjectionResult result = target.project(points);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    EXPECT_NEAR(result.distances[i], 1e-4, 1e-9) << "point " << i;
    EXPECT_EQ(result.status[static_cast<size_t>(i)], ProjectionStatus::Ok) << "point " << i;
  }
}

TEST(TargetCad, OneraM6Report) {
  const Target target(cad::readShapeFile(kDataDir + "/AileM6_with_sharp_TE.stp"));
  const TargetReport& report = target.report();
  EXPECT_EQ(report.shape.faceCount(), 11);
  EXPECT_EQ(report.shape.countFacesOfType("BSplineSurface"), 8);
  EXPECT_EQ(report.shape.countFacesOfType("Plane"), 3);
  EXPECT_GT(report.diagonal, 800.0);  // mm: root chord about 806
  EXPECT_TRUE(report.freeEdges.empty()) << "the wing is closed by its root plane";
  EXPECT_TRUE(report.gaps.empty());
  EXPECT_FALSE(report.sharpEdges.empty());
  EXPECT_TRUE(report.untessellatedFaces.empty());
}

// Points just off the upper and lower skins near the sharp trailing edge must project onto the
// skin they are next to, although the other skin is only a fraction of a millimetre away.
TEST(TargetCad, OneraM6TrailingEdgeSidesStaySeparate) {
  const TopoDS_Shape shape = cad::readShapeFile(kDataDir + "/AileM6_with_sharp_TE.stp");
  const Target target(shape);
  const TargetReport& report = target.report();
  // The trailing edge: the sharpest edge. It joins two narrow planar strips that close the
  // upper and lower skins at the trailing edge.
  ASSERT_FALSE(report.sharpEdges.empty());
  int trailingEdge = report.sharpEdges.front();
  for (int id : report.sharpEdges)
    if (report.shape.edges[static_cast<std::size_t>(id)].maxDihedralDegrees >
        report.shape.edges[static_cast<std::size_t>(trailingEdge)].maxDihedralDegrees)
      trailingEdge = id;
  const cad::EdgeInfo& edge = report.shape.edges[static_cast<std::size_t>(trailingEdge)];
  ASSERT_EQ(edge.faces.size(), 2u);
  EXPECT_GT(edge.maxDihedralDegrees, 150.0) << "a sharp trailing edge is nearly a knife edge";

  // Random points of the two faces' triangles put exactly on their face, then moved off it
  // along its outward normal by a tenth of their distance to the edge: there the other face
  // is farther away than the offset, but only by a fraction of a millimetre.
  std::mt19937 generator(21);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<int> sides;
  Points samples(0, 3);
  for (Eigen::Index t = 0; t < target.meshTriangles().rows(); ++t) {
    const int face = target.meshTriangleFaces()[t];
    const int side = face == edge.faces[0] ? 0 : face == edge.faces[1] ? 1 : -1;
    if (side < 0) continue;
    for (int k = 0; k < 15; ++k) {
      double a = unit(generator), b = unit(generator);
      if (a + b > 1) {
        a = 1 - a;
        b = 1 - b;
      }
      const auto nodes = target.meshTriangles().row(t);
      samples.conservativeResize(samples.rows() + 1, 3);
      samples.row(samples.rows() - 1) = (1 - a - b) * target.meshNodes().row(nodes[0]) +
                                        a * target.meshNodes().row(nodes[1]) + b * target.meshNodes().row(nodes[2]);
      sides.push_back(side);
    }
  }
  const ProjectionResult toEdge = target.projectToEdges(samples, {trailingEdge});
  const ProjectionResult toFace = target.project(samples);
  int checked[2] = {0, 0};
  for (Eigen::Index i = 0; i < samples.rows(); ++i) {
    const int side = sides[static_cast<std::size_t>(i)];
    const int face = edge.faces[static_cast<std::size_t>(side)];
    const double fromEdge = toEdge.distances[i];
    if (toFace.faces[i] != face || fromEdge < 0.2) continue;
    const double offset = 0.1 * fromEdge;
    const Points q = toFace.points.row(i) + offset * toFace.normals.row(i);
    const ProjectionResult result = target.project(q);
    EXPECT_EQ(result.faces[0], face) << "side " << side << " sample " << i;
    EXPECT_NEAR(result.distances[0], offset, 1e-9 * report.diagonal) << "side " << side << " sample " << i;
    // q lies outside the wing, so the distance to the shape is the distance to its surface.
    BRepExtrema_DistShapeShape reference(BRepBuilderAPI_MakeVertex(gp_Pnt(q(0, 0), q(0, 1), q(0, 2))).Vertex(), shape);
    EXPECT_NEAR(result.distances[0], reference.Value(), 1e-9 * report.diagonal) << "side " << side << " sample " << i;
    ++checked[side];
  }
  EXPECT_GE(checked[0], 10);
  EXPECT_GE(checked[1], 10);
}

// Surface points moved along their normal by delta come back to themselves when projected
// along the normal. Offsets of both signs, log-uniform from 1e-5 to 1e-2 of the model size,
// sampled evenly over every face (the narrow trailing-edge strips and the tiny tip patches
// too). Only offsets whose closest point is the base point itself at distance |delta| are
// kept: then no part of the surface is nearer along the line, so the base point is the
// nearest crossing.
TEST(TargetCad, OneraM6LinesAlongNormalsReturnToTheirFoot) {
  const Target target(cad::readShapeFile(kDataDir + "/AileM6_with_sharp_TE.stp"));
  const double size = target.report().diagonal;
  std::mt19937 generator(31);
  std::uniform_real_distribution<double> unit(0, 1);
  constexpr int kPerFace = 80;
  std::vector<std::vector<Eigen::Index>> faceTriangles(static_cast<std::size_t>(target.faceCount()));
  for (Eigen::Index t = 0; t < target.meshTriangles().rows(); ++t)
    faceTriangles[static_cast<std::size_t>(target.meshTriangleFaces()[t])].push_back(t);
  Points samples(kPerFace * target.faceCount(), 3);
  Eigen::VectorXd deltas(samples.rows());
  for (int f = 0; f < target.faceCount(); ++f) {
    const std::vector<Eigen::Index>& triangles = faceTriangles[static_cast<std::size_t>(f)];
    ASSERT_FALSE(triangles.empty()) << "face " << f;
    for (int k = 0; k < kPerFace; ++k) {
      const auto nodes = target.meshTriangles().row(triangles[static_cast<std::size_t>(unit(generator) * triangles.size()) % triangles.size()]);
      double a = unit(generator), b = unit(generator);
      if (a + b > 1) {
        a = 1 - a;
        b = 1 - b;
      }
      const Eigen::Index i = f * kPerFace + k;
      samples.row(i) = (1 - a - b) * target.meshNodes().row(nodes[0]) + a * target.meshNodes().row(nodes[1]) +
                       b * target.meshNodes().row(nodes[2]);
      deltas[i] = (k % 2 == 0 ? 1 : -1) * size * std::pow(10.0, -5 + 3 * unit(generator));
    }
  }
  const ProjectionResult feet = target.project(samples);
  Points offsets(samples.rows(), 3);
  for (Eigen::Index i = 0; i < samples.rows(); ++i)
    offsets.row(i) = feet.points.row(i) + deltas[i] * feet.normals.row(i);
  const ProjectionResult closest = target.project(offsets);
  const ProjectionResult along = target.projectAlong(offsets, feet.normals);
  std::vector<int> checked(static_cast<std::size_t>(target.faceCount()), 0);
  for (Eigen::Index i = 0; i < samples.rows(); ++i) {
    if (feet.status[static_cast<std::size_t>(i)] != ProjectionStatus::Ok) continue;
    if (std::abs(closest.distances[i] - std::abs(deltas[i])) > 1e-12 * size ||
        (closest.points.row(i) - feet.points.row(i)).norm() > 1e-9 * size)
      continue;
    ASSERT_EQ(along.status[static_cast<std::size_t>(i)], ProjectionStatus::Ok) << "sample " << i;
    EXPECT_LE((along.points.row(i) - feet.points.row(i)).norm(), 1e-9 * size)
        << "sample " << i << " on face " << feet.faces[i] << ", offset " << deltas[i];
    EXPECT_NEAR(along.distances[i], std::abs(deltas[i]), 1e-9 * size) << "sample " << i;
    ++checked[static_cast<std::size_t>(feet.faces[i])];
  }
  for (int f = 0; f < target.faceCount(); ++f) EXPECT_GE(checked[static_cast<std::size_t>(f)], 10) << "face " << f;
}

}  // namespace
}  // namespace bvmesh::target

namespace bvmesh::target {
namespace {

// An untrimmed IGES 128 surface (no 144 trimming entity) reads as a face with natural bounds;
// points off its interior along the normal project back to their base point.
TEST(TargetCad, UntrimmedIgesSurface) {
  TColgp_Array2OfPnt poles(1, 6, 1, 5);
  for (int i = 1; i <= 6; ++i)
    for (int j = 1; j <= 5; ++j) poles(i, j) = gp_Pnt(20.0 * i, 15.0 * j, 6.0 * std::sin(0.9 * i) * std::cos(0.7 * j));
  TColStd_Array1OfReal uKnots(1, 4), vKnots(1, 3);
  TColStd_Array1OfInteger uMults(1, 4), vMults(1, 3);
  for (int k = 1; k <= 4; ++k) uKnots(k) = k - 1.0;
  for (int k = 1; k <= 3; ++k) vKnots(k) = k - 1.0;
  uMults.Init(1);
  uMults(1) = uMults(4) = 4;
  vMults.Init(1);
  vMults(1) = vMults(3) = 4;
  const Handle(Geom_BSplineSurface) surface = new Geom_BSplineSurface(poles, uKnots, vKnots, uMults, vMults, 3, 3);
  const std::string path = std::string(BVMESH_TEST_OUTPUT_DIR) + "/target_untrimmed_128.igs";
  IGESControl_Writer writer;
  ASSERT_TRUE(writer.AddGeom(surface));
  writer.ComputeModel();
  ASSERT_TRUE(writer.Write(path.c_str()));

  const Target target(cad::readShapeFile(path));
  ASSERT_EQ(target.faceCount(), 1);
  EXPECT_EQ(target.report().shape.faceSurfaceTypes[0], "BSplineSurface");
  std::mt19937 generator(31);
  std::uniform_real_distribution<double> unit(0.05, 0.95), offset(-2.0, 2.0);
  Points points(500, 3);
  std::vector<double> expected(500);
  for (int i = 0; i < 500; ++i) {
    gp_Pnt p;
    gp_Vec su, sv;
    surface->D1(3.0 * unit(generator), 2.0 * unit(generator), p, su, sv);
    const double h = offset(generator);
    const gp_Vec n = su.Crossed(sv).Normalized();
    points.row(i) << p.X() + h * n.X(), p.Y() + h * n.Y(), p.Z() + h * n.Z();
    expected[static_cast<std::size_t>(i)] = std::abs(h);
  }
  const ProjectionResult result = target.project(points);
  for (int i = 0; i < 500; ++i) {
    EXPECT_EQ(result.status[static_cast<std::size_t>(i)], ProjectionStatus::Ok) << "point " << i;
    EXPECT_NEAR(result.distances[i], expected[static_cast<std::size_t>(i)], 1e-9 * target.report().diagonal)
        << "point " << i;
  }
}

// A line through an edge between two faces: the M6 written to IGES and read back (sewn), a line
// along the span at z = 0 across the rounded tip's ridge, the edge between its upper and lower
// faces. Both faces' trim tests put the crossing outside, so the line missed the tip and went on
// to the root face at y = 0 (the half-wing template's ridge vertex landed 120 mm from the
// STEP's and the volume folded).
TEST(TargetCad, OneraM6FromIgesLinesAcrossTheTipRidgeHitIt) {
  const TopoDS_Shape wing = cad::readShapeFile(kDataDir + "/AileM6_with_sharp_TE.stp");
  const std::string path = std::string(BVMESH_TEST_OUTPUT_DIR) + "/target_m6_brep_mode.igs";
  IGESControl_Writer writer("MM", 0);  // faces mode: trimmed surfaces, read back unsewn and sewn
  ASSERT_TRUE(writer.AddShape(wing));
  writer.ComputeModel();
  ASSERT_TRUE(writer.Write(path.c_str()));
  const Target fromStep(wing);
  const Target fromIges(cad::readShapeFileRepaired(path));
  Points origins(5, 3), directions(5, 3);
  for (int i = 0; i < 5; ++i) {
    origins.row(i) << 697.74 + 20.0 * i, 6000.0, 0.0;
    directions.row(i) << 0.0, -1.0, 0.0;
  }
  const ProjectionResult step = fromStep.projectAlong(origins, directions);
  const ProjectionResult iges = fromIges.projectAlong(origins, directions);
  for (int i = 0; i < 5; ++i) {
    EXPECT_GT(step.points(i, 1), 1200.0) << "line " << i;  // on the tip (the span ends at 1196.3)
    EXPECT_NE(iges.status[static_cast<std::size_t>(i)], ProjectionStatus::Fallback) << "line " << i;
    EXPECT_LT((iges.points.row(i) - step.points.row(i)).norm(), 1e-6 * fromStep.report().diagonal)
        << "line " << i << ": " << iges.points.row(i) << " against " << step.points.row(i);
    EXPECT_NEAR(iges.distances[i], 6000.0 - iges.points(i, 1), 1e-6) << "line " << i;
  }
}

// Span polynomials against Geom_BSplineSurface::D2 (de Boor on the poles) on the M6's eight
// B-spline faces (degree 5, 2 to 32 spans): random (u, v) and the domain's corners.
TEST(SpanPolynomials, MatchBSplineEvaluationOnTheM6) {
  const TopoDS_Shape shape = cad::readShapeFile(kDataDir + "/AileM6_with_sharp_TE.stp");
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  std::mt19937 generator(22);
  std::uniform_real_distribution<double> unit(0, 1);
  int tested = 0;
  for (int f = 1; f <= faces.Extent(); ++f) {
    const Handle(Geom_BSplineSurface) surface =
        Handle(Geom_BSplineSurface)::DownCast(BRep_Tool::Surface(TopoDS::Face(faces(f))));
    if (surface.IsNull() || surface->IsURational() || surface->IsVRational()) continue;
    ++tested;
    const SpanPolynomials polynomials(*surface);
    double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
    surface->Bounds(u0, u1, v0, v1);
    for (int k = 0; k < 500; ++k) {
      const double u = k < 4 ? (k % 2 == 0 ? u0 : u1) : u0 + unit(generator) * (u1 - u0);
      const double v = k < 4 ? (k / 2 == 0 ? v0 : v1) : v0 + unit(generator) * (v1 - v0);
      gp_Pnt p, q;
      gp_Vec d[5], e[5];
      surface->D2(u, v, p, d[0], d[1], d[2], d[3], d[4]);
      polynomials.D2(u, v, q, e[0], e[1], e[2], e[3], e[4]);
      EXPECT_LE(p.Distance(q), 1e-12 * (1 + p.XYZ().Modulus())) << "face " << f - 1 << " (u, v) = (" << u << ", " << v << ")";
      // Derivatives to round-off relative to the largest of their order.
      const double first = std::max(d[0].Magnitude(), d[1].Magnitude());
      const double second = std::max({d[2].Magnitude(), d[3].Magnitude(), d[4].Magnitude()});
      for (int n = 0; n < 5; ++n)
        EXPECT_LE((d[n] - e[n]).Magnitude(), 1e-9 * (n < 2 ? first : second) + 1e-300)
            << "face " << f - 1 << " derivative " << n << " (u, v) = (" << u << ", " << v << ")";
    }
  }
  EXPECT_EQ(tested, 8);
}

}  // namespace
}  // namespace bvmesh::target

#include <gtest/gtest.h>

#include <BRepAdaptor_Surface.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepOffsetAPI_ThruSections.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <GeomAbs_SurfaceType.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>

#include <chrono>
#include <fstream>
#include <functional>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "core/cad/bspline_face.h"
#include "core/cad/isolated_reader.h"
#include "core/cad/shape_io.h"
#include "core/cad/shape_summary.h"
#include "core/cad/solid_overlap.h"
#include "core/cad/step_scan.h"
#include "core/common/errors.h"
#include "wing_body_geometry.h"

namespace bvmesh::cad {
namespace {

const std::string kDataDir = BVMESH_TEST_DATA_DIR;
const std::string kWing = kDataDir + "/AileM6_with_sharp_TE.stp";

TEST(ShapeIo, ReadsTheM6WingStep) {
  const ShapeSummary summary = summarizeShape(readShapeFile(kWing));
  EXPECT_EQ(summary.faceCount(), 11);
  EXPECT_EQ(summary.countFacesOfType("BSplineSurface"), 8);
  EXPECT_EQ(summary.countFacesOfType("Plane"), 3);
  EXPECT_EQ(summary.solidCount, 1);
  // The half wing lies on y >= 0 with its root in y = 0 and a root chord of about 806 mm.
  EXPECT_NEAR(summary.boundsMin[1], 0.0, 1e-3);
  EXPECT_GT(summary.boundsMax[0] - summary.boundsMin[0], 800.0);
  // A closed solid: every edge has two faces (or is a seam / collapsed edge).
  EXPECT_EQ(summary.countEdges(EdgeKind::Free), 0);
  EXPECT_EQ(summary.countEdges(EdgeKind::NonManifold), 0);
  EXPECT_GT(summary.countEdges(EdgeKind::Sharp), 0);
}

TEST(ShapeIo, BrepTextRoundTripKeepsTheShape) {
  const TopoDS_Shape wing = readShapeFile(kWing);
  const TopoDS_Shape again = readBrepString(writeBrepString(wing));
  const ShapeSummary before = summarizeShape(wing);
  const ShapeSummary after = summarizeShape(again);
  EXPECT_EQ(after.faceSurfaceTypes, before.faceSurfaceTypes);
  EXPECT_EQ(after.edges.size(), before.edges.size());
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(after.boundsMax[k], before.boundsMax[k]);
}

TEST(ShapeIo, BadInputGivesClearErrors) {
  EXPECT_THROW(readShapeFile(kDataDir + "/no_such_file.stp"), InvalidInputError);
  EXPECT_THROW(readBrepString(""), InvalidInputError);
  EXPECT_THROW(readBrepString("this is not a BREP"), InvalidInputError);
  EXPECT_THROW(writeBrepString(TopoDS_Shape()), InvalidInputError);
  EXPECT_THROW(summarizeShape(TopoDS_Shape()), InvalidInputError);

  const std::string garbage = std::string(BVMESH_TEST_OUTPUT_DIR) + "/garbage.step";
  std::ofstream(garbage) << "ISO-10303-21;\nthis is no STEP data\n";
  try {
    readShapeFile(garbage);
    FAIL() << "corrupt STEP accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("garbage.step"), std::string::npos) << error.what();
  }
  const std::string unknown = std::string(BVMESH_TEST_OUTPUT_DIR) + "/shape.xyz";
  std::ofstream(unknown) << "1 2 3\n";
  EXPECT_THROW(readShapeFile(unknown), InvalidInputError);
}

// A copy of `path` with one text replaced, in the test output folder.
std::string editedCopy(const std::string& path, const std::string& from, const std::string& to, const std::string& name) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  std::string content = text.str();
  content.replace(content.find(from), from.size(), to);
  const std::string target = std::string(BVMESH_TEST_OUTPUT_DIR) + "/" + name;
  std::ofstream(target) << content;
  return target;
}

TEST(IsolatedReader, CorruptStepIsAnErrorNamingTheEntity) {
  const std::string path = editedCopy(kDataDir + "/hemisph-cyl.stp", "#22 = VERTEX_POINT('',#23);",
                                      "#22 = VERTEX_POINT('',#99999);", "dangling_reference.stp");
  for (const auto& read : {std::function<void()>([&] { readShapeFileIsolated(path); }),
                           std::function<void()>([&] { readShapeFile(path); })}) {
    try {
      read();
      FAIL() << "a dangling STEP reference was accepted";
    } catch (const InvalidInputError& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find("dangling_reference.stp"), std::string::npos) << message;
      EXPECT_NE(message.find("Unresolved Reference"), std::string::npos) << message;
    }
  }
}

TEST(IsolatedReader, GoodFileComesBackAsTheSameShape) {
  const TopoDS_Shape shape = readShapeFileSafely(kWing);
  EXPECT_EQ(summarizeShape(shape).faceCount(), 11);
  EXPECT_EQ(summarizeShape(readBrepStringSafely(writeBrepString(shape))).faceCount(), 11);
}

TEST(IsolatedReader, LoopingParseIsStoppedAtItsLimit) {
  // BREP text cut at 99 % makes OCCT's reader loop forever; the child is stopped, we carry on.
  const std::string brep = writeBrepString(readShapeFile(kWing));
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(checkBrepStringIsolated(brep.substr(0, brep.size() * 99 / 100), ReaderLimits{2.0, 2048.0}),
               InvalidInputError);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0);
  EXPECT_THROW(checkBrepStringIsolated(brep, ReaderLimits{-1.0, 2048.0}), InvalidInputError);
}

// One STEP entity with two million arguments on one line parsed for more than 15 minutes (OCCT's
// parser is quadratic in a list's length) and was stopped only at the reader's time limit; lists
// nested 100 000 deep crashed the reader (stack overflow). A pass over the text refuses both at
// once, in process and through the child, naming the entity and the line.
TEST(StepScan, AbsurdListsAreRefusedBeforeOcctParsesThem) {
  std::string items;
  for (int i = 0; i < 2000000; ++i) items += i ? ",0." : "0.";
  const std::string longList = editedCopy(kDataDir + "/hemisph-cyl.stp", "#23 = CARTESIAN_POINT('',(10.,-5.916456789158E-31,-100.));",
                                          "#23 = CARTESIAN_POINT('',(" + items + "));", "two_million_arguments.stp");
  const std::string deep = editedCopy(kDataDir + "/hemisph-cyl.stp", "#23 = CARTESIAN_POINT('',(10.,-5.916456789158E-31,-100.));",
                                      "#23 = CARTESIAN_POINT(''," + std::string(100000, '(') + "0." +
                                          std::string(100000, ')') + ");",
                                      "deeply_nested.stp");
  const auto expectRefused = [](const std::function<void()>& read, const std::string& what) {
    const auto start = std::chrono::steady_clock::now();
    try {
      read();
      ADD_FAILURE() << "accepted";
    } catch (const InvalidInputError& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find("is refused as STEP: entity #23 (line "), std::string::npos) << message;
      EXPECT_NE(message.find(what), std::string::npos) << message;
    }
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  };
  for (const auto& [path, what] : {std::pair{longList, std::string("has a list of 2000000 items")},
                                   std::pair{deep, std::string("nests lists more than 1000 deep")}}) {
    expectRefused([&] { readShapeFile(path); }, what);
    expectRefused([&] { readShapeFileIsolated(path); }, what);
  }
}

// Strings and comments are not lists: their parentheses, commas and quotes are skipped.
TEST(StepScan, CountsItemsOutsideStringsAndComments) {
  const std::string path = std::string(BVMESH_TEST_OUTPUT_DIR) + "/step_scan.stp";
  const auto scan = [&](const std::string& text) {
    std::ofstream(path) << text;
    checkStepLists(path, StepListLimits{3, 2});
  };
  EXPECT_NO_THROW(scan("#1=A('x,y,z,(((','it''s, (a)',(1,2,3));\n/* (1,2,3,4,(((( */ #2=B((1,2),());"));
  EXPECT_NO_THROW(scan("#7=C('',());"));
  try {
    scan("HEADER;\n#7=C('',\n(1,2,'a,b',4));");
    ADD_FAILURE() << "four items accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("entity #7 (line 2) has a list of 4 items"), std::string::npos)
        << error.what();
  }
  EXPECT_THROW(scan("#8=D(((1)));"), InvalidInputError);  // three deep
  EXPECT_THROW(scan("#9=E((1,2,3,4"), InvalidInputError);  // cut off
}

TEST(ShapeSummary, BoxHasTwelveSharpEdges) {
  const ShapeSummary summary = summarizeShape(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape());
  EXPECT_EQ(summary.faceCount(), 6);
  ASSERT_EQ(summary.edges.size(), 12u);
  for (const EdgeInfo& edge : summary.edges) {
    EXPECT_EQ(edge.kind, EdgeKind::Sharp);
    EXPECT_NEAR(edge.maxDihedralDegrees, 90.0, 1e-9);
    EXPECT_EQ(edge.faces.size(), 2u);
  }
  // A higher threshold than the box's dihedral angle makes every edge smooth.
  ShapeSummaryOptions options;
  options.sharpAngleDegrees = 91.0;
  EXPECT_EQ(summarizeShape(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape(), options).countEdges(EdgeKind::Sharp), 0);
  // Outside 0 .. 180 degrees every edge or none was sharp (NaN: none), a report that looked plausible.
  for (const double angle : {std::nan(""), -5.0, 400.0}) {
    options.sharpAngleDegrees = angle;
    try {
      summarizeShape(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape(), options);
      ADD_FAILURE() << "sharp angle " << angle << " accepted";
    } catch (const InvalidInputError& error) {
      EXPECT_NE(std::string(error.what()).find("the sharp angle must be 0 .. 180 degrees, got"), std::string::npos)
          << error.what();
    }
  }
}

// A wing lofted from single closed section curves (upper and lower surface in one B-spline, its
// ends meeting at the trailing edge) is one face whose seam is the trailing edge: the face meets
// itself there at the trailing-edge angle. Before, every seam was a smooth "seam" and the wing
// templates found no sharp trailing edge. A cylinder's seam stays smooth.
TEST(ShapeSummary, AFaceClosedWithAKinkAlongItsSeamIsSharpThere) {
  BRepOffsetAPI_ThruSections loft(true, false);
  loft.AddWire(testing::closedNacaSectionWire(0.0, 0.0, 1.0));
  loft.AddWire(testing::closedNacaSectionWire(0.6, 2.0, 0.5));
  const ShapeSummary wing = summarizeShape(loft.Shape());
  EXPECT_EQ(wing.faceCount(), 3);  // the wrapped surface and two section faces
  int seams = 0;
  for (const EdgeInfo& edge : wing.edges) {
    if (edge.faces.size() != 1) continue;
    ++seams;
    EXPECT_EQ(edge.kind, EdgeKind::Sharp);
    EXPECT_GT(edge.maxDihedralDegrees, 150.0);  // the trailing edge's 16-degree wedge
    EXPECT_NEAR(edge.length, std::hypot(2.0, 0.6 + 0.5 - 1.0), 1e-3);
  }
  EXPECT_EQ(seams, 1);
  for (const EdgeInfo& edge : summarizeShape(BRepPrimAPI_MakeCylinder(1.0, 2.0).Shape()).edges) {
    if (edge.faces.size() != 1) continue;
    EXPECT_EQ(edge.kind, EdgeKind::Seam);
    EXPECT_LT(edge.maxDihedralDegrees, 1e-6);
  }
}

// 2 - 2 genus, whatever the faces: periodic ones with seams, a sphere's degenerate poles, annular
// faces with a hole each.
TEST(ShapeSummary, EulerCharacteristicCountsTheHolesThroughTheBody) {
  const auto characteristic = [](const TopoDS_Shape& shape) { return summarizeShape(shape).eulerCharacteristic(); };
  EXPECT_EQ(characteristic(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape()), 2);
  EXPECT_EQ(characteristic(BRepPrimAPI_MakeSphere(1.0).Shape()), 2);
  EXPECT_EQ(characteristic(BRepPrimAPI_MakeCylinder(1.0, 2.0).Shape()), 2);
  EXPECT_EQ(characteristic(BRepPrimAPI_MakeTorus(2.0, 0.5).Shape()), 0);
  const TopoDS_Shape tube =
      BRepAlgoAPI_Cut(BRepPrimAPI_MakeCylinder(1.0, 2.0).Shape(), BRepPrimAPI_MakeCylinder(0.3, 2.0).Shape()).Shape();
  EXPECT_EQ(characteristic(tube), 0);
  const TopoDS_Shape plate = BRepPrimAPI_MakeBox(4.0, 2.0, 0.5).Shape();
  const TopoDS_Shape oneHole =
      BRepAlgoAPI_Cut(plate, BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(1, 1, -1), gp::DZ()), 0.3, 3.0).Shape()).Shape();
  const TopoDS_Shape twoHoles =
      BRepAlgoAPI_Cut(oneHole, BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(3, 1, -1), gp::DZ()), 0.3, 3.0).Shape()).Shape();
  EXPECT_EQ(characteristic(twoHoles), -2);
}

// Solids that run into each other, and solids that do not: apart, touching along a face.
TEST(SolidOverlap, NamesSolidsOneOfWhichReachesIntoTheOther) {
  const auto pair = [](const TopoDS_Shape& a, const TopoDS_Shape& b) {
    TopoDS_Compound compound;
    BRep_Builder builder;
    builder.MakeCompound(compound);
    builder.Add(compound, a);
    builder.Add(compound, b);
    return compound;
  };
  const TopoDS_Shape fuselage = BRepPrimAPI_MakeCylinder(gp_Ax2(gp::Origin(), gp::DX()), 0.6, 10.0).Shape();
  const TopoDS_Shape wing = BRepPrimAPI_MakeBox(gp_Pnt(4, -2, -0.1), 2.0, 4.0, 0.2).Shape();
  const std::vector<SolidOverlap> through = overlappingSolids(pair(fuselage, wing));
  ASSERT_EQ(through.size(), 1u);
  EXPECT_EQ(through[0].solid, 0);
  EXPECT_EQ(through[0].otherSolid, 1);
  const gp_Pnt where(through[0].where[0], through[0].where[1], through[0].where[2]);
  EXPECT_LT(std::hypot(where.Y(), where.Z()), 0.6) << "inside the fuselage";
  EXPECT_GT(where.X(), 4.0 - 1e-9);
  EXPECT_LT(where.X(), 6.0 + 1e-9);
  // A box inside another: none of the outer one's points is inside the inner one, but all of
  // the inner one's are inside the outer one.
  EXPECT_EQ(overlappingSolids(pair(BRepPrimAPI_MakeBox(4, 4, 4).Shape(),
                                   BRepPrimAPI_MakeBox(gp_Pnt(1, 1, 1), 1, 1, 1).Shape()))
                .size(),
            1u);
  EXPECT_TRUE(overlappingSolids(pair(BRepPrimAPI_MakeBox(1, 1, 1).Shape(),
                                     BRepPrimAPI_MakeBox(gp_Pnt(3, 0, 0), 1, 1, 1).Shape()))
                  .empty());
  EXPECT_TRUE(overlappingSolids(pair(BRepPrimAPI_MakeBox(1, 1, 1).Shape(),
                                     BRepPrimAPI_MakeBox(gp_Pnt(1, 0, 0), 1, 1, 1).Shape()))
                  .empty());
  EXPECT_TRUE(overlappingSolids(BRepPrimAPI_MakeBox(1, 1, 1).Shape()).empty());
}

// A bicubic patch with one interior knot per direction on a paraboloid-like grid.
BSplineSurfaceData bicubicPatch() {
  BSplineSurfaceData data;
  data.uPoleCount = 5;
  data.vPoleCount = 4;
  for (int i = 0; i < data.uPoleCount; ++i) {
    for (int j = 0; j < data.vPoleCount; ++j) {
      data.poles.insert(data.poles.end(), {double(i), double(j), 0.1 * (i * i - j * j)});
    }
  }
  data.uKnots = {0.0, 0.5, 1.0};
  data.uMultiplicities = {4, 1, 4};
  data.vKnots = {0.0, 1.0};
  data.vMultiplicities = {4, 4};
  return data;
}

TEST(BSplineFace, BuildsAValidFaceThatInterpolatesItsCornerPoles) {
  const TopoDS_Face face = makeBSplineFace(bicubicPatch());
  BRepAdaptor_Surface surface(face);
  EXPECT_EQ(surface.GetType(), GeomAbs_BSplineSurface);
  // Clamped knots: the surface passes through its corner poles.
  const gp_Pnt corner = surface.Value(1.0, 1.0);
  EXPECT_NEAR(corner.X(), 4.0, 1e-12);
  EXPECT_NEAR(corner.Y(), 3.0, 1e-12);
  EXPECT_NEAR(corner.Z(), 0.1 * (16 - 9), 1e-12);
  // ... and survives the trip through BREP text.
  const TopoDS_Shape copy = readBrepString(writeBrepString(face));
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(copy, TopAbs_FACE, faces);
  ASSERT_EQ(faces.Extent(), 1);
  EXPECT_NEAR(BRepAdaptor_Surface(TopoDS::Face(faces(1))).Value(1.0, 1.0).Z(), 0.7, 1e-12);
}

TEST(BSplineFace, InconsistentDataIsRejectedWithTheReason) {
  auto expectRejected = [](BSplineSurfaceData data, const std::string& expectedText) {
    try {
      makeBSplineFace(data);
      ADD_FAILURE() << "accepted data that should mention: " << expectedText;
    } catch (const InvalidInputError& error) {
      EXPECT_NE(std::string(error.what()).find(expectedText), std::string::npos) << error.what();
    }
  };
  BSplineSurfaceData data = bicubicPatch();
  data.uMultiplicities = {4, 2, 4};
  expectRejected(data, "multiplicities add up to");
  data = bicubicPatch();
  data.vKnots = {1.0, 0.0};
  expectRejected(data, "increase");
  data = bicubicPatch();
  data.poles[7] = std::nan("");
  expectRejected(data, "pole 2");
  data = bicubicPatch();
  data.poles.pop_back();
  expectRejected(data, "poles hold");
  data = bicubicPatch();
  data.uDegree = 0;
  expectRejected(data, "u degree 0");
  data = bicubicPatch();
  data.weights.assign(20, 1.0);
  data.weights[3] = -1.0;
  expectRejected(data, "weight 3");
}

}  // namespace
}  // namespace bvmesh::cad

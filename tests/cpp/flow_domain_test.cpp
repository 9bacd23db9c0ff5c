// Flow domains as CFD pre-processors write them (a box or sphere with the body cut out): the body's
// faces found as the target and the domain described for the far field, with no face selection.
#include <gtest/gtest.h>

#include <BRepAlgoAPI_Common.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeSolid.hxx>
#include <BRepGProp.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>
#include <gp_Ax2.hxx>

#include <cmath>
#include <string>

#include "core/cad/isolated_reader.h"
#include "core/cad/shape_io.h"
#include "core/common/errors.h"
#include "core/polyhedron/flow_domain.h"
#include "core/polyhedron/target_analysis.h"

namespace bvmesh::polyhedron {
namespace {

const std::string kData = BVMESH_TEST_DATA_DIR;
const std::string kOutput = BVMESH_TEST_OUTPUT_DIR;

double area(const TopoDS_Shape& shape) {
  GProp_GProps properties;
  BRepGProp::SurfaceProperties(shape, properties);
  return properties.Mass();
}

double facesArea(const TopoDS_Shape& shape, const std::vector<int>& faces) { return area(selectFaces(shape, faces)); }

// The M6 of tests/data (closed by its root face on y = 0) as a solid.
TopoDS_Shape m6Solid() {
  const TopoDS_Shape read = cad::readShapeFileRepaired(kData + "/AileM6_with_sharp_TE.stp").shape;
  TopExp_Explorer solids(read, TopAbs_SOLID);
  if (solids.More()) return solids.Current();
  TopExp_Explorer shells(read, TopAbs_SHELL);
  EXPECT_TRUE(shells.More());
  return BRepBuilderAPI_MakeSolid(TopoDS::Shell(shells.Current())).Solid();
}

int faceCount(const TopoDS_Shape& shape) {
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  return faces.Extent();
}

TEST(FlowDomain, HalfBoxAroundTheM6) {
  // A wind tunnel's half box on the symmetry plane y = 0 with the wing cut out: 3 root chords
  // ahead and above/below, 5 behind, 2 spans out.
  const TopoDS_Shape wing = m6Solid();
  const HalfModelShape half = removeSymmetryFace(wing);
  const gp_Pnt low(-2400.0, 0.0, -2400.0), high(5000.0, 2400.0, 2400.0);
  BRepAlgoAPI_Cut cut(BRepPrimAPI_MakeBox(low, high).Shape(), wing);
  ASSERT_TRUE(cut.IsDone());
  const TopoDS_Shape domainShape = cut.Shape();

  const FlowDomain domain = splitFlowDomain(domainShape);
  EXPECT_EQ(domain.shape, "box");
  EXPECT_EQ(domain.outerFaces.size(), 6u);
  EXPECT_EQ(static_cast<int>(domain.bodyFaces.size()), faceCount(half.shape));
  EXPECT_NEAR(facesArea(domainShape, domain.bodyFaces), area(half.shape), 1e-6 * area(half.shape));
  ASSERT_TRUE(domain.symmetryPlane.has_value());
  EXPECT_NEAR(domain.symmetryPlane->point.y(), 0.0, 1e-9);
  EXPECT_NEAR(domain.symmetryPlane->normal.y(), 1.0, 1e-12);
  // The half box: centred on the plane, its whole height above it.
  EXPECT_NEAR(domain.centre.x(), 1300.0, 1e-6);
  EXPECT_NEAR(domain.centre.y(), 0.0, 1e-9);
  EXPECT_NEAR(domain.centre.z(), 0.0, 1e-6);
  EXPECT_NEAR(domain.halfExtent.x(), 3700.0, 1e-6);
  EXPECT_NEAR(domain.halfExtent.y(), 2400.0, 1e-6);
  EXPECT_NEAR(domain.halfExtent.z(), 2400.0, 1e-6);
  // The symmetry face is the box's face on y = 0, with the root section as its hole.
  const TopoDS_Shape symmetryFace = selectFaces(domainShape, {domain.symmetryFace});
  Bnd_Box bounds;
  BRepBndLib::Add(symmetryFace, bounds);
  EXPECT_LT(bounds.CornerMax().Y() - bounds.CornerMin().Y(), 1e-4);  // the box grows by the edge tolerances
  int wires = 0;
  for (TopExp_Explorer wire(symmetryFace, TopAbs_WIRE); wire.More(); wire.Next()) ++wires;
  EXPECT_EQ(wires, 2);
}

TEST(FlowDomain, HalfSphereOfTheM6FlowDomainFile) {
  // ../shared/data's flow domain: far-field sphere (radius 100, face 0) and symmetry plane (face 1)
  // around the wing scaled to a unit root chord.
  const TopoDS_Shape shape = cad::readShapeFileRepaired(kData + "/onera-m6-sharp-te.stp").shape;
  const FlowDomain domain = splitFlowDomain(shape);
  EXPECT_EQ(domain.shape, "sphere");
  EXPECT_EQ(domain.outerFaces, (std::vector<int>{0, 1}));
  EXPECT_EQ(domain.bodyFaces, (std::vector<int>{2, 3, 4, 5, 6, 7, 8, 9, 10, 11}));
  EXPECT_EQ(domain.symmetryFace, 1);
  EXPECT_NEAR(domain.radius, 100.0, 1e-9);
  EXPECT_LT(domain.centre.norm(), 1e-9);
  ASSERT_TRUE(domain.symmetryPlane.has_value());
  EXPECT_NEAR(domain.symmetryPlane->normal.y(), 1.0, 1e-12);
}

TEST(FlowDomain, HemisphereCylinderRunningIntoItsOutflowPlane) {
  // ../shared/data's hemisphere-cylinder: the body (faces 3 and 4) lies on the symmetry plane
  // y = 0 (face 1) and runs into the outflow plane x = 10 (face 2) of the quarter sphere of
  // radius 100 around (10, 0, 0) (face 0).
  const TopoDS_Shape shape = cad::readShapeFileRepaired(kData + "/hemisph-cyl.stp").shape;
  const FlowDomain domain = splitFlowDomain(shape);
  EXPECT_EQ(domain.shape, "sphere");
  EXPECT_EQ(domain.outerFaces, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(domain.bodyFaces, (std::vector<int>{3, 4}));
  EXPECT_NEAR(domain.radius, 100.0, 1e-9);
  EXPECT_LT((domain.centre - Eigen::Vector3d(10.0, 0.0, 0.0)).norm(), 1e-9);
  EXPECT_EQ(domain.symmetryFace, 1);
  ASSERT_TRUE(domain.symmetryPlane.has_value());
  EXPECT_NEAR(domain.symmetryPlane->normal.y(), 1.0, 1e-12);
  EXPECT_EQ(domain.outflowFace, 2);
  ASSERT_TRUE(domain.outflowPlane.has_value());
  EXPECT_NEAR(domain.outflowPlane->normal.x(), -1.0, 1e-12);  // towards the domain, upstream
  EXPECT_NEAR(domain.outflowPlane->point.x(), 10.0, 1e-9);
}

// A quarter of a sphere of radius 20 around `centre` (y >= 0, x <= 5) with a half rod of radius 1
// from x = -3 into the plane x = 5 cut out.
TopoDS_Shape rodIntoQuarterSphere(const gp_Pnt& centre) {
  const TopoDS_Shape half = BRepPrimAPI_MakeBox(gp_Pnt(-40.0, 0.0, -40.0), gp_Pnt(5.0, 40.0, 40.0)).Shape();
  const TopoDS_Shape quarter = BRepAlgoAPI_Common(BRepPrimAPI_MakeSphere(centre, 20.0).Shape(), half).Shape();
  const TopoDS_Shape rod =
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(-3.0, 0.0, 0.0), gp_Dir(1, 0, 0)), 1.0, 8.0).Shape();
  return BRepAlgoAPI_Cut(quarter, rod).Shape();
}

TEST(FlowDomain, RodRunningIntoTheOutflowPlaneOfAQuarterSphere) {
  const FlowDomain domain = splitFlowDomain(rodIntoQuarterSphere(gp_Pnt(5.0, 0.0, 0.0)));
  EXPECT_EQ(domain.shape, "sphere");
  EXPECT_EQ(domain.bodyFaces.size(), 2u);  // the half cylinder and its front half disc
  ASSERT_TRUE(domain.symmetryPlane.has_value());
  ASSERT_TRUE(domain.outflowPlane.has_value());
  EXPECT_NEAR(domain.symmetryPlane->normal.y(), 1.0, 1e-12);
  EXPECT_NEAR(domain.outflowPlane->normal.x(), -1.0, 1e-12);
  EXPECT_LT((domain.centre - Eigen::Vector3d(5.0, 0.0, 0.0)).norm(), 1e-9);
  // The sphere's centre off the outflow plane: no domain the volume stage can march to.
  try {
    splitFlowDomain(rodIntoQuarterSphere(gp_Pnt(0.0, 0.0, 0.0)));
    FAIL() << "a sphere centred off the outflow plane was accepted";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("centre is off the outflow plane"), std::string::npos)
        << error.what();
  }
}

TEST(FlowDomain, M6FlowDomainFileWrittenFaceByFaceToIges) {
  // The same file as design tools write IGES (every face on its own), sewn on reading.
  const std::string iges = kOutput + "/onera-m6-sharp-te_faces.igs";
  cad::writeIgesFaces(cad::readShapeFile(kData + "/onera-m6-sharp-te.stp"), iges);
  const cad::RepairedShape sewn = cad::readShapeFileRepaired(iges);
  ASSERT_TRUE(sewn.report.sewingApplied) << sewn.report.keptReason;
  const FlowDomain domain = splitFlowDomain(sewn.shape);
  EXPECT_EQ(domain.shape, "sphere");
  EXPECT_EQ(domain.outerFaces.size(), 2u);
  EXPECT_EQ(domain.bodyFaces.size(), 10u);
  EXPECT_NEAR(domain.radius, 100.0, 1e-6);
  EXPECT_LT(domain.centre.norm(), 1e-6);
  ASSERT_TRUE(domain.symmetryPlane.has_value());
  EXPECT_NEAR(domain.symmetryPlane->normal.y(), 1.0, 1e-9);
}

TEST(FlowDomain, WholeBodyInABox) {
  // A sphere inside a box, touching nothing: no symmetry plane, the box's centre and half sizes.
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(gp_Pnt(-10.0, -6.0, -4.0), gp_Pnt(14.0, 6.0, 4.0)).Shape();
  const TopoDS_Shape shape = BRepAlgoAPI_Cut(box, BRepPrimAPI_MakeSphere(gp_Pnt(1.0, 0.5, 0.0), 1.0).Shape()).Shape();
  const FlowDomain domain = splitFlowDomain(shape);
  EXPECT_EQ(domain.shape, "box");
  EXPECT_EQ(domain.outerFaces.size(), 6u);
  EXPECT_EQ(domain.bodyFaces.size(), 1u);
  EXPECT_NEAR(facesArea(shape, domain.bodyFaces), 4.0 * M_PI, 1e-6);
  EXPECT_FALSE(domain.symmetryPlane.has_value());
  EXPECT_EQ(domain.symmetryFace, -1);
  EXPECT_LT((domain.centre - Eigen::Vector3d(2.0, 0.0, 0.0)).norm(), 1e-9);
  EXPECT_LT((domain.halfExtent - Eigen::Vector3d(12.0, 6.0, 4.0)).norm(), 1e-9);
}

TEST(FlowDomain, WhatIsNotAFlowDomainIsNamed) {
  // A convex body alone: every face bounds the hull, nothing is inside.
  EXPECT_THROW(
      {
        try {
          splitFlowDomain(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape());
        } catch (const InvalidInputError& error) {
          EXPECT_NE(std::string(error.what()).find("no body lies inside a domain"), std::string::npos) << error.what();
          throw;
        }
      },
      InvalidInputError);
  // The wing alone: its convex B-spline sides bound the hull, and they are no domain.
  EXPECT_THROW(
      {
        try {
          splitFlowDomain(m6Solid());
        } catch (const InvalidInputError& error) {
          EXPECT_NE(std::string(error.what()).find("is neither a plane nor a sphere"), std::string::npos) << error.what();
          throw;
        }
      },
      InvalidInputError);
  // A body that runs into a box on two faces (root and outflow) is refused naming both.
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(gp_Pnt(-10.0, 0.0, -5.0), gp_Pnt(4.0, 5.0, 5.0)).Shape();
  const TopoDS_Shape rod = BRepPrimAPI_MakeBox(gp_Pnt(0.0, 0.0, -0.5), gp_Pnt(4.0, 1.0, 0.5)).Shape();
  EXPECT_THROW(
      {
        try {
          splitFlowDomain(BRepAlgoAPI_Cut(box, rod).Shape());
        } catch (const InvalidInputError& error) {
          EXPECT_NE(std::string(error.what()).find("the body touches the box on face"), std::string::npos)
              << error.what();
          EXPECT_NE(std::string(error.what()).find("needs a sphere domain"), std::string::npos)
              << error.what();
          throw;
        }
      },
      InvalidInputError);
  // A convex prism of 100 sides: the classification stops at the 65th face bounding the hull.
  BRepBuilderAPI_MakePolygon polygon;
  for (int k = 0; k < 100; ++k) polygon.Add(gp_Pnt(std::cos(0.02 * M_PI * k), std::sin(0.02 * M_PI * k), 0.0));
  polygon.Close();
  const TopoDS_Shape prism = BRepPrimAPI_MakePrism(BRepBuilderAPI_MakeFace(polygon.Wire()).Face(), gp_Vec(0, 0, 1)).Shape();
  EXPECT_THROW(
      {
        try {
          splitFlowDomain(prism);
        } catch (const InvalidInputError& error) {
          EXPECT_NE(std::string(error.what()).find("more than 64 faces bound"), std::string::npos) << error.what();
          throw;
        }
      },
      InvalidInputError);
  EXPECT_THROW(splitFlowDomain(TopoDS_Shape()), InvalidInputError);
}

}  // namespace
}  // namespace bvmesh::polyhedron

// A wing-body half model built with OCCT for the wing-fuselage template tests (no CAD file in the
// repository): a fuselage of revolution (elliptic nose, cylinder, elliptic tail) fused with a
// swept, tapered half wing of NACA 0012 sections closed at a sharp trailing edge and a flat tip,
// cut at the symmetry plane y = 0 (the cut face stays; removeSymmetryFace takes it off).
#pragma once

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepOffsetAPI_ThruSections.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeRevol.hxx>
#include <GeomAPI_Interpolate.hxx>
#include <Geom_Ellipse.hxx>
#include <Geom_TrimmedCurve.hxx>
#include <TColgp_HArray1OfPnt.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Ax2.hxx>
#include <gp_Elips.hxx>
#include <gp_Vec.hxx>

#include <cmath>
#include <vector>

namespace bvmesh::testing {

// Lengths in body units; the fuselage axis is the x axis, the wing spans +y.
struct WingBodyParameters {
  double length = 10.0;     // nose (x = 0) to tail
  double radius = 0.6;      // of the cylindrical part
  double noseLength = 2.0;  // elliptic nose, x in [0, noseLength]
  double tailLength = 3.5;  // elliptic tail, x in [length - tailLength, length]
  double wingHeight = 0.0;  // z of the root chord line (0: mid wing, < 0: low wing)
  double rootChord = 2.6;   // chord of the root section (inside the fuselage)
  double rootLeadingEdge = 3.6;  // x of the root leading edge
  double tipChord = 1.0;
  double tipSpan = 4.0;  // y of the flat tip
  double sweepDeg = 25.0;     // leading-edge sweep
  double dihedralDeg = 0.0;
  double rootSpanFraction = 0.3;  // y of the root section / radius (inside the body)
};

inline double naca0012HalfThickness(double x) {  // closed trailing edge (coefficient -0.1036)
  return 0.6 * (0.2969 * std::sqrt(x) - 0.1260 * x - 0.3516 * x * x + 0.2843 * x * x * x -
                0.1036 * x * x * x * x);
}

// Section wire at span y: upper curve trailing edge -> leading edge, lower curve back, both
// interpolating NACA 0012 points with a vertical tangent at the leading edge, so that the leading
// edge is smooth and the trailing edge sharp.
inline TopoDS_Wire nacaSectionWire(double leadingEdge, double y, double z, double chord) {
  constexpr int kPoints = 41;
  const double pi = std::acos(-1.0);
  const auto point = [&](double x, double side) {
    return gp_Pnt(leadingEdge + chord * x, y, z + side * chord * naca0012HalfThickness(x));
  };
  const double slope = (naca0012HalfThickness(1.0) - naca0012HalfThickness(1.0 - 1e-6)) / 1e-6;
  BRepBuilderAPI_MakeWire wire;
  for (double side : {1.0, -1.0}) {
    Handle(TColgp_HArray1OfPnt) points = new TColgp_HArray1OfPnt(1, kPoints);
    for (int i = 0; i < kPoints; ++i) {
      const double x = 0.5 * (1.0 + std::cos(pi * i / (kPoints - 1)));  // 1 (trailing edge) .. 0
      points->SetValue(side > 0 ? i + 1 : kPoints - i, point(x, side));
    }
    const gp_Vec trailing = gp_Vec(1.0, 0.0, side * slope).Normalized();
    const gp_Vec down(0.0, 0.0, -1.0);
    GeomAPI_Interpolate interpolate(points, false, 1e-9);
    if (side > 0) {
      interpolate.Load(trailing.Reversed(), down);
    } else {
      interpolate.Load(down, trailing);
    }
    interpolate.Perform();
    wire.Add(BRepBuilderAPI_MakeEdge(interpolate.Curve()).Edge());
  }
  return wire.Wire();
}

inline TopoDS_Shape makeFuselage(const WingBodyParameters& p) {
  const double pi = std::acos(-1.0);
  const double tailStart = p.length - p.tailLength;
  // Profile in the half plane y = 0, z >= 0, closed along the axis.
  const gp_Dir x(1, 0, 0);
  Handle(Geom_Ellipse) nose =
      new Geom_Ellipse(gp_Elips(gp_Ax2(gp_Pnt(p.noseLength, 0, 0), gp_Dir(0, -1, 0), x), p.noseLength, p.radius));
  Handle(Geom_Ellipse) tail =
      new Geom_Ellipse(gp_Elips(gp_Ax2(gp_Pnt(tailStart, 0, 0), gp_Dir(0, -1, 0), x), p.tailLength, p.radius));
  BRepBuilderAPI_MakeWire profile;
  profile.Add(BRepBuilderAPI_MakeEdge(new Geom_TrimmedCurve(nose, 0.5 * pi, pi)).Edge());
  profile.Add(BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 0), gp_Pnt(p.length, 0, 0)).Edge());
  profile.Add(BRepBuilderAPI_MakeEdge(new Geom_TrimmedCurve(tail, 0.0, 0.5 * pi)).Edge());
  profile.Add(BRepBuilderAPI_MakeEdge(gp_Pnt(tailStart, 0, p.radius), gp_Pnt(p.noseLength, 0, p.radius)).Edge());
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(profile.Wire(), true).Face();
  return BRepPrimAPI_MakeRevol(face, gp_Ax1(gp_Pnt(0, 0, 0), x), 2.0 * pi).Shape();
}

inline TopoDS_Shape makeHalfWing(const WingBodyParameters& p) {
  const double pi = std::acos(-1.0);
  const double rootY = p.rootSpanFraction * p.radius;
  const double span = p.tipSpan - rootY;
  const double tipLeadingEdge = p.rootLeadingEdge + span * std::tan(p.sweepDeg * pi / 180.0);
  const double tipZ = p.wingHeight + span * std::tan(p.dihedralDeg * pi / 180.0);
  BRepOffsetAPI_ThruSections loft(true, false);
  loft.AddWire(nacaSectionWire(p.rootLeadingEdge, rootY, p.wingHeight, p.rootChord));
  loft.AddWire(nacaSectionWire(tipLeadingEdge, p.tipSpan, tipZ, p.tipChord));
  loft.Build();
  return loft.Shape();
}

// The fused wing-body cut at y = 0: fuselage faces with the wing's footprint removed, the wing
// outside the body, and the planar cut face on y = 0.
inline TopoDS_Shape makeWingBody(const WingBodyParameters& p = {}) {
  const TopoDS_Shape fused = BRepAlgoAPI_Fuse(makeFuselage(p), makeHalfWing(p)).Shape();
  const double big = 4.0 * (p.length + p.tipSpan);
  const TopoDS_Shape negative = BRepPrimAPI_MakeBox(gp_Pnt(-big, -big, -big), gp_Pnt(big, 0.0, big)).Shape();
  return BRepAlgoAPI_Cut(fused, negative).Shape();
}

// The second variant: larger low-mounted fuselage, more sweep and dihedral, smaller wing farther aft.
inline WingBodyParameters lowWingParameters() {
  WingBodyParameters p;
  p.radius = 0.75;
  p.noseLength = 2.4;
  p.tailLength = 3.0;
  p.wingHeight = -0.3;
  p.rootChord = 2.2;
  p.rootLeadingEdge = 4.2;
  p.tipChord = 0.8;
  p.tipSpan = 3.6;
  p.sweepDeg = 30.0;
  p.dihedralDeg = 4.0;
  return p;
}

}  // namespace bvmesh::testing

// A wing-body half model built with OCCT for the wing-fuselage template tests (no CAD file in the
// repository): a fuselage of revolution (elliptic nose, cylinder, elliptic tail) fused with a
// swept, tapered half wing of NACA 0012 sections closed at a sharp trailing edge and a flat tip,
// cut at the symmetry plane y = 0 (the cut face stays; removeSymmetryFace takes it off); and a
// nacelle of the same section.
#pragma once

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRepOffsetAPI_ThruSections.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeRevol.hxx>
#include <GeomAPI_Interpolate.hxx>
#include <Geom_Ellipse.hxx>
#include <Geom_TrimmedCurve.hxx>
#include <TColgp_HArray1OfPnt.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Ax2.hxx>
#include <gp_Elips.hxx>
#include <gp_Trsf.hxx>
#include <gp_Vec.hxx>

#include <cmath>

namespace bvmesh::testing {

// Lengths in body units; the fuselage axis is the x axis, the wing spans +y.
struct WingBodyParameters {
  double length = 10.0;          // nose (x = 0) to tail
  double radius = 0.6;           // of the cylindrical part
  double noseLength = 2.0;       // elliptic nose, x in [0, noseLength]
  double tailLength = 3.5;       // elliptic tail, x in [length - tailLength, length]
  double wingHeight = 0.0;       // z of the root chord line (0: mid wing, < 0: low wing)
  double rootChord = 2.6;        // chord of the root section (inside the fuselage)
  double rootLeadingEdge = 3.6;  // x of the root leading edge
  double tipChord = 1.0;
  double tipSpan = 4.0;    // y of the flat tip
  double sweepDeg = 25.0;  // leading-edge sweep
  double dihedralDeg = 0.0;
  double rootSpanFraction = 0.3;  // y of the root section / radius (inside the body)
  // false: each section's lower curve is interpolated on its own instead of mirroring the upper
  // one. OCCT's fuse then approximates the intersection curve near the trailing-edge vertex with
  // an edge tolerance of 1e-2 (the lower branch doubles back, its parameter crowds): a CAD defect
  // for testing projections. Mirrored sections give tolerances of 5e-6.
  bool mirroredSections = true;
};

inline double naca0012HalfThickness(double x) {  // closed trailing edge (coefficient -0.1036)
  return 0.6 *
         (0.2969 * std::sqrt(x) - 0.1260 * x - 0.3516 * x * x + 0.2843 * x * x * x - 0.1036 * x * x * x * x);
}

// Section wire at span y: the upper curve from the trailing to the leading edge interpolating
// NACA 0012 points, vertical at the leading edge, and below it its mirror image (`mirrored`) or
// a curve interpolating the lower points from the leading to the trailing edge (see
// WingBodyParameters::mirroredSections). The leading edge is smooth, the trailing edge sharp.
inline TopoDS_Wire nacaSectionWire(double leadingEdge, double y, double z, double chord,
                                   bool mirrored = true) {
  constexpr int kPoints = 41;
  const double pi = std::acos(-1.0);
  const double slope = (naca0012HalfThickness(1.0) - naca0012HalfThickness(1.0 - 1e-6)) / 1e-6;
  // sign 1: upper, trailing -> leading edge; -1: lower, leading -> trailing edge.
  const auto side = [&](double sign) {
    Handle(TColgp_HArray1OfPnt) points = new TColgp_HArray1OfPnt(1, kPoints);
    for (int i = 0; i < kPoints; ++i) {
      const double x = 0.5 * (1.0 + std::cos(pi * i / (kPoints - 1)));  // 1 .. 0
      points->SetValue(sign > 0 ? i + 1 : kPoints - i,
                       gp_Pnt(leadingEdge + chord * x, y, z + sign * chord * naca0012HalfThickness(x)));
    }
    const gp_Vec trailing = gp_Vec(1.0, 0.0, sign * slope).Normalized();
    GeomAPI_Interpolate interpolate(points, false, 1e-9);
    if (sign > 0) {
      interpolate.Load(trailing.Reversed(), gp_Vec(0.0, 0.0, -1.0));
    } else {
      interpolate.Load(gp_Vec(0.0, 0.0, -1.0), trailing);
    }
    interpolate.Perform();
    return BRepBuilderAPI_MakeEdge(interpolate.Curve()).Edge();
  };
  const TopoDS_Edge upper = side(1.0);
  gp_Trsf mirror;
  mirror.SetMirror(gp_Ax2(gp_Pnt(0.0, y, z), gp_Dir(0, 0, 1)));
  const TopoDS_Edge lower =
      mirrored ? TopoDS::Edge(BRepBuilderAPI_Transform(upper, mirror, true).Shape()) : side(-1.0);
  BRepBuilderAPI_MakeWire wire;
  wire.Add(upper);
  wire.Add(lower);
  return wire.Wire();
}

// Section wire at span y as one curve: NACA 0012 points from the trailing edge over the upper side
// to the leading edge and back under it, interpolated as one open B-spline whose ends meet at the
// trailing edge (a kink there). A loft of such wires wraps the wing in one face whose seam is the
// trailing edge, as lofts of single section curves in CAD systems do.
inline TopoDS_Wire closedNacaSectionWire(double leadingEdge, double y, double chord) {
  constexpr int kSide = 21;
  const double pi = std::acos(-1.0);
  Handle(TColgp_HArray1OfPnt) points = new TColgp_HArray1OfPnt(1, 2 * kSide - 1);
  for (int i = 0; i < kSide; ++i) {
    const double x = 0.5 * (1.0 + std::cos(pi * i / (kSide - 1)));  // 1 .. 0
    points->SetValue(i + 1, gp_Pnt(leadingEdge + chord * x, y, chord * naca0012HalfThickness(x)));
    points->SetValue(2 * kSide - 1 - i, gp_Pnt(leadingEdge + chord * x, y, -chord * naca0012HalfThickness(x)));
  }
  GeomAPI_Interpolate interpolate(points, false, 1e-9);
  interpolate.Perform();
  return BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(interpolate.Curve()).Edge()).Wire();
}

inline TopoDS_Shape makeFuselage(const WingBodyParameters& p) {
  const double pi = std::acos(-1.0);
  const double tailStart = p.length - p.tailLength;
  // Profile in the half plane y = 0, z >= 0, closed along the axis.
  const gp_Dir x(1, 0, 0);
  Handle(Geom_Ellipse) nose = new Geom_Ellipse(
      gp_Elips(gp_Ax2(gp_Pnt(p.noseLength, 0, 0), gp_Dir(0, -1, 0), x), p.noseLength, p.radius));
  Handle(Geom_Ellipse) tail = new Geom_Ellipse(
      gp_Elips(gp_Ax2(gp_Pnt(tailStart, 0, 0), gp_Dir(0, -1, 0), x), p.tailLength, p.radius));
  BRepBuilderAPI_MakeWire profile;
  profile.Add(BRepBuilderAPI_MakeEdge(new Geom_TrimmedCurve(nose, 0.5 * pi, pi)).Edge());
  profile.Add(BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 0), gp_Pnt(p.length, 0, 0)).Edge());
  profile.Add(BRepBuilderAPI_MakeEdge(new Geom_TrimmedCurve(tail, 0.0, 0.5 * pi)).Edge());
  profile.Add(
      BRepBuilderAPI_MakeEdge(gp_Pnt(tailStart, 0, p.radius), gp_Pnt(p.noseLength, 0, p.radius)).Edge());
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
  loft.AddWire(nacaSectionWire(p.rootLeadingEdge, rootY, p.wingHeight, p.rootChord, p.mirroredSections));
  loft.AddWire(nacaSectionWire(tipLeadingEdge, p.tipSpan, tipZ, p.tipChord, p.mirroredSections));
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

// A nacelle: a NACA 0012 lip profile of chord 1, inclined by 5 degrees (converging towards the
// rear), its leading edge 1 from the x axis, revolved about that axis. Its trailing edge is a sharp
// circle of radius 1 - sin(5 deg) about the axis.
inline TopoDS_Shape sharpLipNacelle() {
  gp_Trsf incidence;
  incidence.SetRotation(gp_Ax1(gp_Pnt(0, 0, 1), gp_Dir(0, 1, 0)), 5.0 * std::acos(-1.0) / 180.0);
  const TopoDS_Shape profile = BRepBuilderAPI_Transform(
      BRepBuilderAPI_MakeFace(nacaSectionWire(0.0, 0.0, 1.0, 1.0), true).Face(), incidence).Shape();
  return BRepPrimAPI_MakeRevol(profile, gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(1, 0, 0)), 2.0 * std::acos(-1.0)).Shape();
}

}  // namespace bvmesh::testing

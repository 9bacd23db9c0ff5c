#include "core/cad/shape_summary.h"

#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepGProp.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <Geom2d_Curve.hxx>
#include <GeomAbs_SurfaceType.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Vec.hxx>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>

#include "core/common/errors.h"
#include "core/common/math_constants.h"
#include "core/common/number_text.h"
#include "core/common/occt_errors.h"

namespace bvmesh::cad {
namespace {

// Outward normal of `face` at the point of `edge` with edge parameter t; false where the surface
// is singular there (e.g. a pole).
bool faceNormalOnEdge(const TopoDS_Face& face, const TopoDS_Edge& edge, double t, gp_Vec& normal) {
  double first = 0.0;
  double last = 0.0;
  Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(edge, face, first, last);
  if (pcurve.IsNull()) return false;
  const gp_Pnt2d uv = pcurve->Value(t);
  BRepAdaptor_Surface surface(face, false);
  gp_Pnt point;
  gp_Vec du;
  gp_Vec dv;
  surface.D1(uv.X(), uv.Y(), point, du, dv);
  normal = du.Crossed(dv);
  if (normal.Magnitude() < 1e-14 * std::max(1.0, du.Magnitude() * dv.Magnitude())) return false;
  normal.Normalize();
  if (face.Orientation() == TopAbs_REVERSED) normal.Reverse();
  return true;
}

// Largest and mean angle between the faces' normals along the edge, in degrees. onA, onB: the
// edge as each face uses it (a seam's two orientations pick its two pcurves on the one face).
std::pair<double, double> dihedralDegrees(const TopoDS_Edge& onA, const TopoDS_Face& a, const TopoDS_Edge& onB,
                                          const TopoDS_Face& b, int samples) {
  double first = 0.0;
  double last = 0.0;
  BRep_Tool::Range(onA, first, last);
  double maxAngle = 0.0;
  double sum = 0.0;
  int evenly = 0;
  // Interior points only (at the ends the edge meets other faces and normals may be singular),
  // evenly spread plus one close to each end, where a kink often peaks (the leading edge of a
  // swept wing's root section). The mean is over the evenly spread points.
  for (int i = -1; i <= samples; ++i) {
    const double fraction = i < 0 ? 1e-3 : i == samples ? 1.0 - 1e-3 : (i + 0.5) / samples;
    const double t = first + (last - first) * fraction;
    gp_Vec na;
    gp_Vec nb;
    if (!faceNormalOnEdge(a, onA, t, na) || !faceNormalOnEdge(b, onB, t, nb)) continue;
    const double angle = na.Angle(nb);
    maxAngle = std::max(maxAngle, angle);
    if (i >= 0 && i < samples) {
      sum += angle;
      ++evenly;
    }
  }
  return {maxAngle * 180.0 / kPi, evenly > 0 ? sum / evenly * 180.0 / kPi : 0.0};
}

EdgeInfo classifyEdge(const TopoDS_Edge& edge, const TopTools_ListOfShape& adjacentFaces,
                      const TopTools_IndexedMapOfShape& faceIndex,
                      const ShapeSummaryOptions& options) {
  EdgeInfo info;
  for (const TopoDS_Shape& face : adjacentFaces) {
    const int index = faceIndex.FindIndex(face) - 1;
    if (std::find(info.faces.begin(), info.faces.end(), index) == info.faces.end()) {
      info.faces.push_back(index);
    }
  }
  GProp_GProps props;
  BRepGProp::LinearProperties(edge, props);
  info.length = props.Mass();

  if (BRep_Tool::Degenerated(edge)) {
    info.kind = EdgeKind::Degenerate;
  } else if (info.faces.size() >= 3) {
    info.kind = EdgeKind::NonManifold;
  } else if (info.faces.size() == 1) {
    const TopoDS_Face& face = TopoDS::Face(faceIndex(info.faces[0] + 1));
    if (!BRep_Tool::IsClosed(edge, face)) {
      info.kind = EdgeKind::Free;
    } else {
      // A seam: the face meets itself. One closed with a kink there (a wing lofted from single
      // closed section curves, its seam the sharp trailing edge) is as sharp as two faces meeting
      // at that angle.
      std::tie(info.maxDihedralDegrees, info.meanDihedralDegrees) =
          dihedralDegrees(TopoDS::Edge(edge.Oriented(TopAbs_FORWARD)), face,
                          TopoDS::Edge(edge.Oriented(TopAbs_REVERSED)), face, options.samplesPerEdge);
      info.kind = info.maxDihedralDegrees >= options.sharpAngleDegrees ? EdgeKind::Sharp : EdgeKind::Seam;
    }
  } else if (info.faces.size() == 2) {
    std::tie(info.maxDihedralDegrees, info.meanDihedralDegrees) =
        dihedralDegrees(edge, TopoDS::Face(faceIndex(info.faces[0] + 1)), edge,
                        TopoDS::Face(faceIndex(info.faces[1] + 1)), options.samplesPerEdge);
    info.kind = info.maxDihedralDegrees >= options.sharpAngleDegrees ? EdgeKind::Sharp
                                                                      : EdgeKind::Smooth;
  } else {
    info.kind = EdgeKind::Free;  // an edge of the shape that bounds no face (wire geometry)
  }
  return info;
}

}  // namespace

int ShapeSummary::countEdges(EdgeKind kind) const {
  return static_cast<int>(std::count_if(edges.begin(), edges.end(),
                                        [kind](const EdgeInfo& edge) { return edge.kind == kind; }));
}

int ShapeSummary::eulerCharacteristic() const {
  int characteristic = vertexCount - (static_cast<int>(edges.size()) - countEdges(EdgeKind::Degenerate));
  for (int wires : faceWireCounts) characteristic += 2 - wires;
  return characteristic;
}

int ShapeSummary::countFacesOfType(const std::string& surfaceType) const {
  return static_cast<int>(std::count(faceSurfaceTypes.begin(), faceSurfaceTypes.end(), surfaceType));
}

std::string surfaceTypeName(int geomAbsSurfaceType) {
  switch (static_cast<GeomAbs_SurfaceType>(geomAbsSurfaceType)) {
    case GeomAbs_Plane: return "Plane";
    case GeomAbs_Cylinder: return "Cylinder";
    case GeomAbs_Cone: return "Cone";
    case GeomAbs_Sphere: return "Sphere";
    case GeomAbs_Torus: return "Torus";
    case GeomAbs_BezierSurface: return "BezierSurface";
    case GeomAbs_BSplineSurface: return "BSplineSurface";
    case GeomAbs_SurfaceOfRevolution: return "SurfaceOfRevolution";
    case GeomAbs_SurfaceOfExtrusion: return "SurfaceOfExtrusion";
    case GeomAbs_OffsetSurface: return "OffsetSurface";
    case GeomAbs_OtherSurface: return "OtherSurface";
  }
  return "OtherSurface";
}

const char* edgeKindName(EdgeKind kind) {
  switch (kind) {
    case EdgeKind::Smooth: return "smooth";
    case EdgeKind::Sharp: return "sharp";
    case EdgeKind::Free: return "free";
    case EdgeKind::Seam: return "seam";
    case EdgeKind::NonManifold: return "non-manifold";
    case EdgeKind::Degenerate: return "degenerate";
  }
  return "smooth";
}

ShapeSummary summarizeShape(const TopoDS_Shape& shape, const ShapeSummaryOptions& options) {
  if (shape.IsNull()) throw InvalidInputError("cannot summarize a null shape");
  if (options.samplesPerEdge < 1) throw InvalidInputError("samplesPerEdge must be at least 1");
  // Outside it every edge or none is sharp (NaN compares false with every angle): a report of
  // the shape that looks plausible and is not.
  if (!(options.sharpAngleDegrees >= 0.0 && options.sharpAngleDegrees <= 180.0)) {
    throw InvalidInputError("the sharp angle must be 0 .. 180 degrees, got " + numberText(options.sharpAngleDegrees));
  }
  return translateOcctErrors("summarizing shape", [&] {
    ShapeSummary summary;
    TopTools_IndexedMapOfShape solids;
    TopTools_IndexedMapOfShape shells;
    TopTools_IndexedMapOfShape faces;
    TopTools_IndexedMapOfShape vertices;
    TopExp::MapShapes(shape, TopAbs_SOLID, solids);
    TopExp::MapShapes(shape, TopAbs_SHELL, shells);
    TopExp::MapShapes(shape, TopAbs_FACE, faces);
    TopExp::MapShapes(shape, TopAbs_VERTEX, vertices);
    summary.solidCount = solids.Extent();
    summary.shellCount = shells.Extent();
    summary.vertexCount = vertices.Extent();

    for (int i = 1; i <= faces.Extent(); ++i) {
      const TopoDS_Face& face = TopoDS::Face(faces(i));
      summary.faceSurfaceTypes.push_back(surfaceTypeName(BRepAdaptor_Surface(face, false).GetType()));
      GProp_GProps props;
      BRepGProp::SurfaceProperties(face, props);
      summary.faceAreas.push_back(props.Mass());
      TopTools_IndexedMapOfShape wires;
      TopExp::MapShapes(face, TopAbs_WIRE, wires);
      summary.faceWireCounts.push_back(wires.Extent());
    }

    // Edges in MapShapes order, each with the faces around it.
    TopTools_IndexedDataMapOfShapeListOfShape edgeFaces;
    TopExp::MapShapesAndUniqueAncestors(shape, TopAbs_EDGE, TopAbs_FACE, edgeFaces);
    TopTools_IndexedMapOfShape edges;
    TopExp::MapShapes(shape, TopAbs_EDGE, edges);
    for (int i = 1; i <= edges.Extent(); ++i) {
      const TopoDS_Edge& edge = TopoDS::Edge(edges(i));
      const TopTools_ListOfShape* adjacent = edgeFaces.Seek(edge);
      summary.edges.push_back(
          classifyEdge(edge, adjacent != nullptr ? *adjacent : TopTools_ListOfShape(), faces, options));
    }

    Bnd_Box box;
    BRepBndLib::AddOptimal(shape, box, false, false);
    if (!box.IsVoid()) {
      box.Get(summary.boundsMin[0], summary.boundsMin[1], summary.boundsMin[2],
              summary.boundsMax[0], summary.boundsMax[1], summary.boundsMax[2]);
    }
    return summary;
  });
}

}  // namespace bvmesh::cad

#include "core/target/target.h"

#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <Bnd_Box.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepTools.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Tool.hxx>
#include <GCPnts_TangentialDeflection.hxx>
#include <GeomAdaptor_Curve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Poly_PolygonOnTriangulation.hxx>
#include <Poly_Triangulation.hxx>
#include <Precision.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Vec2d.hxx>
#include <Geom2d_Curve.hxx>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <limits>
#include <map>
#include <utility>

#include "core/common/errors.h"
#include "core/common/input_checks.h"
#include "core/common/number_text.h"
#include "core/common/occt_errors.h"
#include "core/target/target_data.h"

namespace bvmesh::target {
namespace {

// Limit of a face's span polynomials (coefficients per coordinate): 24 MB.
constexpr std::size_t kMaxSpanCoefficients = std::size_t{1} << 20;

int indexOf(const TopTools_IndexedMapOfShape& map, const TopoDS_Shape& shape) {
  return map.FindIndex(shape) - 1;
}

// Appends the points of pcurve on (t0, t1] so that every chord stays within deflection of it
// (midpoint test, recursive halving).
void samplePcurve(const Geom2d_Curve& pcurve, double t0, const gp_Pnt2d& p0, double t1, const gp_Pnt2d& p1,
                  double deflection, int depth, std::vector<Eigen::Vector2d>& points) {
  const double tm = 0.5 * (t0 + t1);
  const gp_Pnt2d pm = pcurve.Value(tm);
  const double sag = gp_Vec2d(0.5 * (p0.XY() + p1.XY()), pm.XY()).Magnitude();
  if (depth < 40 && (depth < 4 || sag > deflection)) {
    samplePcurve(pcurve, t0, p0, tm, pm, deflection, depth + 1, points);
    samplePcurve(pcurve, tm, pm, t1, p1, deflection, depth + 1, points);
    return;
  }
  points.emplace_back(p1.X(), p1.Y());
}

// The face's boundary pcurves as polylines within a 1e-8 fraction of its parameter box.
// The face's boundary in its parameter plane: one closed polygon per wire, its edges' pcurves in
// wire order. The pcurves of consecutive edges may miss each other by up to the vertex's
// tolerance (5e-7 of the parameter range at an M6 tip vertex); a polygon per edge would leave that
// gap open, and a ray through it would miss a crossing. Wires the explorer cannot walk in order
// (non-manifold ones) fall back to one polyline per edge.
std::vector<std::vector<Eigen::Vector2d>> boundaryPolylines(const FaceData& face) {
  const double deflection = 1e-8 * std::max(face.u1 - face.u0, face.v1 - face.v0);
  const auto sampleEdge = [&](const TopoDS_Edge& edge, std::vector<Eigen::Vector2d>& points) {
    double first = 0, last = 0;
    const Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(edge, face.face, first, last);
    if (pcurve.IsNull()) throw TopologyError("Target: an edge of a face has no curve in the face's parameter plane");
    if (edge.Orientation() == TopAbs_REVERSED) std::swap(first, last);
    const gp_Pnt2d start = pcurve->Value(first);
    points.emplace_back(start.X(), start.Y());
    samplePcurve(*pcurve, first, start, last, pcurve->Value(last), deflection, 0, points);
  };
  std::vector<std::vector<Eigen::Vector2d>> curves;
  for (TopExp_Explorer wires(face.face, TopAbs_WIRE); wires.More(); wires.Next()) {
    const TopoDS_Wire& wire = TopoDS::Wire(wires.Current());
    int edgeCount = 0;
    for (TopExp_Explorer edges(wire, TopAbs_EDGE); edges.More(); edges.Next()) ++edgeCount;
    std::vector<Eigen::Vector2d> polygon;
    int walked = 0;
    for (BRepTools_WireExplorer walk(wire, face.face); walk.More(); walk.Next(), ++walked) sampleEdge(walk.Current(), polygon);
    if (walked == edgeCount && !polygon.empty()) {
      polygon.push_back(polygon.front());
      curves.push_back(std::move(polygon));
      continue;
    }
    for (TopExp_Explorer edges(wire, TopAbs_EDGE); edges.More(); edges.Next()) {
      std::vector<Eigen::Vector2d> points;
      sampleEdge(TopoDS::Edge(edges.Current()), points);
      curves.push_back(std::move(points));
    }
  }
  return curves;
}

// Extracts faces, edges and vertices with their adjacency.
void extractTopology(Target::Data& data) {
  TopTools_IndexedMapOfShape faceMap, edgeMap, vertexMap;
  TopExp::MapShapes(data.shape, TopAbs_FACE, faceMap);
  TopExp::MapShapes(data.shape, TopAbs_EDGE, edgeMap);
  TopExp::MapShapes(data.shape, TopAbs_VERTEX, vertexMap);
  if (faceMap.IsEmpty()) throw TopologyError("Target: the shape has no faces");

  data.vertices.resize(static_cast<std::size_t>(vertexMap.Extent()));
  for (int i = 1; i <= vertexMap.Extent(); ++i)
    data.vertices[static_cast<std::size_t>(i - 1)] = toEigen(BRep_Tool::Pnt(TopoDS::Vertex(vertexMap(i))));

  data.edges.resize(static_cast<std::size_t>(edgeMap.Extent()));
  for (int i = 1; i <= edgeMap.Extent(); ++i) {
    const TopoDS_Edge& edge = TopoDS::Edge(edgeMap(i));
    EdgeData& e = data.edges[static_cast<std::size_t>(i - 1)];
    TopoDS_Vertex first, last;
    TopExp::Vertices(edge, first, last);
    if (!first.IsNull()) e.vertex0 = indexOf(vertexMap, first);
    if (!last.IsNull()) e.vertex1 = indexOf(vertexMap, last);
    e.degenerate = BRep_Tool::Degenerated(edge);
    e.tolerance = BRep_Tool::Tolerance(edge);
    if (!e.degenerate) e.curve = BRep_Tool::Curve(edge, e.first, e.last);
    if (e.curve.IsNull()) e.degenerate = true;
  }

  data.faces.resize(static_cast<std::size_t>(faceMap.Extent()));
  for (int i = 1; i <= faceMap.Extent(); ++i) {
    FaceData& f = data.faces[static_cast<std::size_t>(i - 1)];
    f.face = TopoDS::Face(faceMap(i));
    f.surface = BRep_Tool::Surface(f.face);
    if (f.surface.IsNull()) throw TopologyError("Target: face " + std::to_string(i - 1) + " has no surface");
    f.reversed = f.face.Orientation() == TopAbs_REVERSED;
    BRepTools::UVBounds(f.face, f.u0, f.u1, f.v0, f.v1);
    f.surface->Bounds(f.uMin, f.uMax, f.vMin, f.vMax);
    f.uPeriodic = f.surface->IsUPeriodic();
    f.vPeriodic = f.surface->IsVPeriodic();
    if (f.uPeriodic) f.uPeriod = f.surface->UPeriod();
    if (f.vPeriodic) f.vPeriod = f.surface->VPeriod();
    if (const Handle(Geom_BSplineSurface) bspline = Handle(Geom_BSplineSurface)::DownCast(f.surface); !bspline.IsNull()) {
      for (int k = 1; k <= bspline->NbUKnots(); ++k) f.uKnots.push_back(bspline->UKnot(k));
      for (int k = 1; k <= bspline->NbVKnots(); ++k) f.vKnots.push_back(bspline->VKnot(k));
      // Span polynomials for polynomial surfaces of moderate size (memory: spans x (du + 1) x
      // (dv + 1) x 3 doubles); rational and periodic ones stay with the adaptors.
      const bool polynomial = !bspline->IsURational() && !bspline->IsVRational() && !f.uPeriodic && !f.vPeriodic;
      const std::size_t spans = (f.uKnots.size() - 1) * (f.vKnots.size() - 1);
      if (polynomial && spans * static_cast<std::size_t>((bspline->UDegree() + 1) * (bspline->VDegree() + 1)) <= kMaxSpanCoefficients)
        f.polynomials = SpanPolynomials(*bspline);
    }
    for (TopExp_Explorer it(f.face, TopAbs_EDGE); it.More(); it.Next()) {
      const TopoDS_Edge& edge = TopoDS::Edge(it.Current());
      const int id = indexOf(edgeMap, edge);
      EdgeData& e = data.edges[static_cast<std::size_t>(id)];
      if (std::find(e.faces.begin(), e.faces.end(), i - 1) == e.faces.end()) e.faces.push_back(i - 1);
      if (e.degenerate) continue;
      double first = 0, last = 0;
      FaceEdgeUse use{id, BRep_Tool::CurveOnSurface(edge, f.face, first, last)};
      if (!use.pcurve.IsNull()) f.edges.push_back(use);
    }
    f.trim = TrimClassifier(f.u0, f.u1, f.v0, f.v1, boundaryPolylines(f));
  }

  TopTools_IndexedDataMapOfShapeListOfShape vertexFaces;
  TopExp::MapShapesAndAncestors(data.shape, TopAbs_VERTEX, TopAbs_FACE, vertexFaces);
  data.vertexFaces.resize(data.vertices.size());
  for (int i = 1; i <= vertexFaces.Extent(); ++i) {
    std::vector<int>& faces = data.vertexFaces[static_cast<std::size_t>(indexOf(vertexMap, vertexFaces.FindKey(i)))];
    for (const TopoDS_Shape& face : vertexFaces(i)) {
      const int id = indexOf(faceMap, face);
      if (std::find(faces.begin(), faces.end(), id) == faces.end()) faces.push_back(id);
    }
  }
}

// Refuses, before any geometry work, a shape OCCT cannot handle at its size or position. Too
// large: OCCT's geometry forms fourth powers of lengths (extrema, curvature), which overflow a
// double beyond about 1e77: a sphere of radius 1e80 fitted 200 times worse than one of radius 1,
// 1e90 failed in OCCT ("gp_VectorWithNullMagnitude") and 1e150 ran for minutes into a
// MemoryError. Too far from the origin: where the coordinates' spacing (their size times 2^-52)
// exceeds the tessellation's deflection, the target is not resolved (a unit sphere at 1e16 has
// coordinates 2 apart). shape: its bounding box from the geometry (quick, slightly loose).
void checkScale(const TopoDS_Shape& shape, const TargetOptions& options) {
  Bnd_Box box;
  BRepBndLib::Add(shape, box, false);
  if (box.IsVoid()) return;  // measureSize names a degenerate box
  double x0 = 0, y0 = 0, z0 = 0, x1 = 0, y1 = 0, z1 = 0;
  box.Get(x0, y0, z0, x1, y1, z1);
  const Eigen::Vector3d lo(x0, y0, z0), hi(x1, y1, z1);
  const double diagonal = (hi - lo).norm();
  constexpr double kLargest = 1e70;
  char message[400];
  if (!(diagonal <= kLargest)) {
    std::snprintf(message, sizeof(message),
                  "Target: the target is too large, %.3g across (its bounding-box diagonal); OCCT's geometry computes "
                  "fourth powers of lengths, which overflow beyond about 1e77, so a target must be at most %.0e across: "
                  "scale the model down",
                  diagonal, kLargest);
    throw InvalidInputError(message);
  }
  const double farthest = std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
  const double spacing = farthest * std::numeric_limits<double>::epsilon();
  const double deflection = options.relativeDeflection * diagonal;
  if (spacing > deflection) {
    std::snprintf(message, sizeof(message),
                  "Target: the target lies too far from the origin for its size: at %.3g from it coordinates are %.3g "
                  "apart, coarser than the tessellation's deflection %.3g (relative_deflection %g of its %.3g "
                  "diagonal): move the model towards the origin",
                  farthest, spacing, deflection, options.relativeDeflection, diagonal);
    throw InvalidInputError(message);
  }
}

void measureSize(Target::Data& data) {
  const cad::ShapeSummary& summary = data.report.shape;
  const Eigen::Vector3d lo(summary.boundsMin[0], summary.boundsMin[1], summary.boundsMin[2]);
  const Eigen::Vector3d hi(summary.boundsMax[0], summary.boundsMax[1], summary.boundsMax[2]);
  data.diagonal = (hi - lo).norm();
  if (!(data.diagonal > 0) || !std::isfinite(data.diagonal))
    throw TopologyError("Target: the shape's bounding box is degenerate or infinite");
  data.deflection = data.options.relativeDeflection * data.diagonal;
  // OCCT works to Precision::Confusion() (1e-7) in absolute terms: BRepMesh refuses a finer
  // deflection ("invalid parameter value"), and a shape that small is below its precision anyway.
  if (data.deflection < Precision::Confusion()) {
    char message[320];
    std::snprintf(message, sizeof(message),
                  "Target: the target is too small, %.3g across (its bounding-box diagonal); OCCT works to %.0e, "
                  "so at relative_deflection %g a target must be at least %.3g across: scale the model up",
                  data.diagonal, Precision::Confusion(), data.options.relativeDeflection,
                  Precision::Confusion() / data.options.relativeDeflection);
    throw InvalidInputError(message);
  }
  data.tolerance = data.options.relativeTolerance * data.diagonal;
  // BRepMesh keeps triangles within about the deflection of the surface; twice that is safe.
  data.margin = 2.0 * data.deflection + data.tolerance;
  data.convergence = 1e-14 * data.diagonal;
}

// Raises the tolerance of the face's boundary nodes (1-based in `mesh`, 0-based in `tolerance`)
// to that of the edges and end vertices they lie on.
void markBoundaryTolerances(const TopoDS_Face& face, const Handle(Poly_Triangulation)& mesh,
                            const TopLoc_Location& location, double* tolerance) {
  for (TopExp_Explorer it(face, TopAbs_EDGE); it.More(); it.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(it.Current());
    const Handle(Poly_PolygonOnTriangulation) polygon = BRep_Tool::PolygonOnTriangulation(edge, mesh, location);
    if (polygon.IsNull()) continue;
    TopoDS_Vertex first, last;
    TopExp::Vertices(edge, first, last);
    const double edgeTolerance = BRep_Tool::Tolerance(edge);
    const int count = polygon->NbNodes();
    for (int k = 1; k <= count; ++k) {
      double here = edgeTolerance;
      if (k == 1 && !first.IsNull()) here = std::max(here, BRep_Tool::Tolerance(first));
      if (k == count && !last.IsNull()) here = std::max(here, BRep_Tool::Tolerance(last));
      double& node = tolerance[polygon->Node(k) - 1];
      node = std::max(node, here);
    }
  }
}

void tessellate(Target::Data& data) {
  BRepMesh_IncrementalMesh mesher(data.shape, data.deflection, false, data.options.angularDeflection, true);
  std::vector<Eigen::Vector3d> nodes;
  std::vector<Eigen::Vector2d> uv;
  std::vector<double> tolerance;
  std::vector<Eigen::Vector3i> triangles;
  std::vector<int> triangleFaces;
  for (std::size_t f = 0; f < data.faces.size(); ++f) {
    TopLoc_Location location;
    const Handle(Poly_Triangulation) mesh = BRep_Tool::Triangulation(data.faces[f].face, location);
    if (mesh.IsNull() || !mesh->HasUVNodes()) continue;
    const gp_Trsf transform = location.Transformation();
    const int offset = static_cast<int>(nodes.size());
    for (int n = 1; n <= mesh->NbNodes(); ++n) {
      nodes.push_back(toEigen(mesh->Node(n).Transformed(transform)));
      const gp_Pnt2d p = mesh->UVNode(n);
      uv.emplace_back(p.X(), p.Y());
      tolerance.push_back(BRep_Tool::Tolerance(data.faces[f].face));
    }
    markBoundaryTolerances(data.faces[f].face, mesh, location, &tolerance[static_cast<std::size_t>(offset)]);
    for (int t = 1; t <= mesh->NbTriangles(); ++t) {
      int a, b, c;
      mesh->Triangle(t).Get(a, b, c);
      triangles.emplace_back(offset + a - 1, offset + b - 1, offset + c - 1);
      triangleFaces.push_back(static_cast<int>(f));
    }
  }
  data.nodes.resize(static_cast<Eigen::Index>(nodes.size()), 3);
  data.nodeUV.resize(static_cast<Eigen::Index>(nodes.size()), 2);
  data.nodeTolerance = Eigen::Map<const Eigen::VectorXd>(tolerance.data(), static_cast<Eigen::Index>(tolerance.size()));
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    data.nodes.row(static_cast<Eigen::Index>(n)) = nodes[n].transpose();
    data.nodeUV.row(static_cast<Eigen::Index>(n)) = uv[n].transpose();
  }
  data.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  data.triangleFaces.resize(static_cast<Eigen::Index>(triangles.size()));
  data.triangleSize.resize(triangles.size());
  std::vector<Box3> boxes(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    data.triangles.row(static_cast<Eigen::Index>(t)) = triangles[t].transpose();
    data.triangleFaces[static_cast<Eigen::Index>(t)] = triangleFaces[t];
    const Eigen::Vector3d& a = nodes[static_cast<std::size_t>(triangles[t][0])];
    const Eigen::Vector3d& b = nodes[static_cast<std::size_t>(triangles[t][1])];
    const Eigen::Vector3d& c = nodes[static_cast<std::size_t>(triangles[t][2])];
    boxes[t].extend(a);
    boxes[t].extend(b);
    boxes[t].extend(c);
    data.triangleSize[t] = std::max({(a - b).norm(), (b - c).norm(), (c - a).norm()});
  }
  data.tree = AabbTree(std::move(boxes));

  // Edge polylines within the deflection: seeds for the curve projections.
  for (std::size_t i = 0; i < data.edges.size(); ++i) {
    EdgeData& e = data.edges[i];
    if (e.degenerate) continue;
    GeomAdaptor_Curve curve(e.curve, e.first, e.last);
    GCPnts_TangentialDeflection sampler(curve, data.options.angularDeflection, data.deflection, 4);
    for (int k = 1; k <= sampler.NbPoints(); ++k) {
      e.polyline.push_back(toEigen(sampler.Value(k)));
      e.polyParams.push_back(sampler.Parameter(k));
      e.box.extend(e.polyline.back());
    }
    e.box.lo.array() -= data.margin;
    e.box.hi.array() += data.margin;
  }
}

// Free edges that nearly meet a free edge of another face.
void findGaps(const Target::Data& data, TargetReport& report) {
  const double search = data.options.relativeGapSearch * data.diagonal;
  ThreadContext context(data);
  std::vector<Box3> boxes(data.edges.size());
  for (int id : report.freeEdges)
    for (const Eigen::Vector3d& p : data.edges[static_cast<std::size_t>(id)].polyline)
      boxes[static_cast<std::size_t>(id)].extend(p);
  for (int id : report.freeEdges) {
    const EdgeData& e = data.edges[static_cast<std::size_t>(id)];
    Box3 grown = boxes[static_cast<std::size_t>(id)];
    grown.lo.array() -= search;
    grown.hi.array() += search;
    std::vector<int> others;
    for (int other : report.freeEdges) {
      const Box3& b = boxes[static_cast<std::size_t>(other)];
      const bool overlap = (b.lo.array() <= grown.hi.array()).all() && (b.hi.array() >= grown.lo.array()).all();
      if (other != id && overlap && data.edges[static_cast<std::size_t>(other)].faces != e.faces) others.push_back(other);
    }
    if (others.empty()) continue;
    constexpr int kSamples = 8;
    double width = 0.0;
    int nearestAtMiddle = -1;
    for (int k = 0; k < kSamples; ++k) {
      const double t = e.first + (k + 0.5) / kSamples * (e.last - e.first);
      const Eigen::Vector3d q = toEigen(e.curve->Value(t));
      double best = std::numeric_limits<double>::infinity();
      int bestEdge = -1;
      for (int other : others) {
        const Foot foot = closestOnEdge(data, context, other, q, best);
        if (foot.distance >= 0 && foot.distance < best) {
          best = foot.distance;
          bestEdge = other;
        }
      }
      width = std::max(width, best);
      if (k == kSamples / 2) nearestAtMiddle = bestEdge;
    }
    if (width > data.tolerance && width <= search && nearestAtMiddle >= 0)
      report.gaps.push_back({id, nearestAtMiddle, width});
  }
}

void buildReport(Target::Data& data) {
  TargetReport& report = data.report;
  report.triangleCount = static_cast<int>(data.triangles.rows());
  report.diagonal = data.diagonal;
  report.tolerance = data.tolerance;
  report.deflection = data.deflection;
  std::vector<bool> tessellated(data.faces.size(), false);
  for (Eigen::Index t = 0; t < data.triangleFaces.size(); ++t)
    tessellated[static_cast<std::size_t>(data.triangleFaces[t])] = true;
  for (std::size_t f = 0; f < tessellated.size(); ++f)
    if (!tessellated[f]) report.untessellatedFaces.push_back(static_cast<int>(f));
  const std::vector<cad::EdgeInfo>& edges = report.shape.edges;
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const int id = static_cast<int>(i);
    if (edges[i].kind == cad::EdgeKind::Sharp) report.sharpEdges.push_back(id);
    if (edges[i].kind == cad::EdgeKind::Free && !data.edges[i].degenerate) report.freeEdges.push_back(id);
    if (edges[i].kind == cad::EdgeKind::NonManifold) report.nonManifoldEdges.push_back(id);
  }
  findGaps(data, report);
}

}  // namespace

Eigen::Vector3d toEigen(const gp_Pnt& p) { return {p.X(), p.Y(), p.Z()}; }
Eigen::Vector3d toEigen(const gp_Vec& v) { return {v.X(), v.Y(), v.Z()}; }

GeomAdaptor_Surface& FaceSurface::adaptor(double u, double v) {
  if (face_.uKnots.empty()) {
    if (!adaptors_[0]) adaptors_[0] = std::make_unique<GeomAdaptor_Surface>(face_.surface);
    return *adaptors_[0];
  }
  // The span's key: which one the adaptor caches matters only for speed, not for the values.
  const auto iu = std::upper_bound(face_.uKnots.begin(), face_.uKnots.end(), u) - face_.uKnots.begin();
  const auto iv = std::upper_bound(face_.vKnots.begin(), face_.vKnots.end(), v) - face_.vKnots.begin();
  const std::int64_t span = static_cast<std::int64_t>(iu) * static_cast<std::int64_t>(face_.vKnots.size() + 1) + iv;
  int slot = 0;
  for (int k = 0; k < kSlots; ++k) {
    if (spans_[k] == span) {
      slot = k;
      break;
    }
    if (used_[k] < used_[slot]) slot = k;
  }
  if (spans_[slot] != span) {
    spans_[slot] = span;
    // GeomAdaptor_Surface evaluates a B-spline exactly on its first or last parameter by the
    // uncached de Boor path (one-sided derivatives at trimming knots), several times slower;
    // feet on the domain's border (Newton clamps there) are common. Bounds wider than the
    // domain keep every evaluation on the span cache, whose end values are the same polynomial.
    if (!adaptors_[slot]) {
      const double du = face_.uMax - face_.uMin, dv = face_.vMax - face_.vMin;
      adaptors_[slot] = std::make_unique<GeomAdaptor_Surface>(face_.surface, face_.uMin - du, face_.uMax + du,
                                                              face_.vMin - dv, face_.vMax + dv);
    }
  }
  used_[slot] = ++clock_;
  return *adaptors_[slot];
}

FaceSurface& ThreadContext::surface(int face) {
  std::unique_ptr<FaceSurface>& slot = surfaces_[static_cast<std::size_t>(face)];
  if (!slot) slot = std::make_unique<FaceSurface>(data_.faces[static_cast<std::size_t>(face)]);
  return *slot;
}

SpanPolynomials::SpanPolynomials(const Geom_BSplineSurface& surface)
    : uDegree_(surface.UDegree()), vDegree_(surface.VDegree()) {
  for (int k = 1; k <= surface.NbUKnots(); ++k) uBreaks_.push_back(surface.UKnot(k));
  for (int k = 1; k <= surface.NbVKnots(); ++k) vBreaks_.push_back(surface.VKnot(k));
  const int uSpans = static_cast<int>(uBreaks_.size()) - 1, vSpans = static_cast<int>(vBreaks_.size()) - 1;
  const int terms = (uDegree_ + 1) * (vDegree_ + 1);
  coefficients_.resize(static_cast<std::size_t>(uSpans * vSpans * terms * 3));
  for (int a = 0; a < uSpans; ++a) {
    for (int b = 0; b < vSpans; ++b) {
      const double u = uBreaks_[static_cast<std::size_t>(a)], v = vBreaks_[static_cast<std::size_t>(b)];
      const double hu = uBreaks_[static_cast<std::size_t>(a) + 1] - u, hv = vBreaks_[static_cast<std::size_t>(b) + 1] - v;
      double* out = &coefficients_[static_cast<std::size_t>((a * vSpans + b) * terms * 3)];
      // c_ij = d^(i+j) S / du^i dv^j * hu^i hv^j / (i! j!) of this span's polynomial at its corner.
      double uScale = 1.0;
      for (int i = 0; i <= uDegree_; ++i) {
        double scale = uScale;
        for (int j = 0; j <= vDegree_; ++j) {
          gp_XYZ d;
          if (i == 0 && j == 0) {
            gp_Pnt p;
            surface.LocalD0(u, v, a + 1, a + 2, b + 1, b + 2, p);
            d = p.XYZ();
          } else {
            d = surface.LocalDN(u, v, a + 1, a + 2, b + 1, b + 2, i, j).XYZ();
          }
          for (int k = 0; k < 3; ++k) out[(i * (vDegree_ + 1) + j) * 3 + k] = scale * d.Coord(k + 1);
          scale *= hv / (j + 1);
        }
        uScale *= hu / (i + 1);
      }
    }
  }
}

void SpanPolynomials::D2(double u, double v, gp_Pnt& p, gp_Vec& su, gp_Vec& sv, gp_Vec& suu, gp_Vec& svv,
                         gp_Vec& suv) const {
  const int uSpans = static_cast<int>(uBreaks_.size()) - 1, vSpans = static_cast<int>(vBreaks_.size()) - 1;
  const int a = std::clamp(static_cast<int>(std::upper_bound(uBreaks_.begin(), uBreaks_.end(), u) - uBreaks_.begin()) - 1, 0, uSpans - 1);
  const int b = std::clamp(static_cast<int>(std::upper_bound(vBreaks_.begin(), vBreaks_.end(), v) - vBreaks_.begin()) - 1, 0, vSpans - 1);
  const double u0 = uBreaks_[static_cast<std::size_t>(a)], v0 = vBreaks_[static_cast<std::size_t>(b)];
  const double hu = uBreaks_[static_cast<std::size_t>(a) + 1] - u0, hv = vBreaks_[static_cast<std::size_t>(b) + 1] - v0;
  const double s = (u - u0) / hu, t = (v - v0) / hv;
  const double* c = &coefficients_[static_cast<std::size_t>((a * vSpans + b) * (uDegree_ + 1) * (vDegree_ + 1) * 3)];
  // Horner in t for each power of s (value, first and second t-derivative: r0, r1, r2 / 2), then
  // Horner in s over those: S and its s-derivatives (s0, s1, s2 / 2), S_t and its s-derivative
  // (t0, t1), S_tt / 2 (tt).
  double s0[3] = {0, 0, 0}, s1[3] = {0, 0, 0}, s2[3] = {0, 0, 0}, t0[3] = {0, 0, 0}, t1[3] = {0, 0, 0}, tt[3] = {0, 0, 0};
  for (int i = uDegree_; i >= 0; --i) {
    const double* row = c + i * (vDegree_ + 1) * 3;
    double r0[3] = {row[vDegree_ * 3], row[vDegree_ * 3 + 1], row[vDegree_ * 3 + 2]};
    double r1[3] = {0, 0, 0}, r2[3] = {0, 0, 0};
    for (int j = vDegree_ - 1; j >= 0; --j) {
      for (int k = 0; k < 3; ++k) {
        r2[k] = r2[k] * t + r1[k];
        r1[k] = r1[k] * t + r0[k];
        r0[k] = r0[k] * t + row[j * 3 + k];
      }
    }
    for (int k = 0; k < 3; ++k) {
      s2[k] = s2[k] * s + s1[k];
      s1[k] = s1[k] * s + s0[k];
      s0[k] = s0[k] * s + r0[k];
      t1[k] = t1[k] * s + t0[k];
      t0[k] = t0[k] * s + r1[k];
      tt[k] = tt[k] * s + r2[k];
    }
  }
  p.SetCoord(s0[0], s0[1], s0[2]);
  su.SetCoord(s1[0] / hu, s1[1] / hu, s1[2] / hu);
  sv.SetCoord(t0[0] / hv, t0[1] / hv, t0[2] / hv);
  const double uu = 2 / (hu * hu), vv = 2 / (hv * hv), uv = 1 / (hu * hv);
  suu.SetCoord(uu * s2[0], uu * s2[1], uu * s2[2]);
  svv.SetCoord(vv * tt[0], vv * tt[1], vv * tt[2]);
  suv.SetCoord(uv * t1[0], uv * t1[1], uv * t1[2]);
}

GeomAdaptor_Curve& ThreadContext::curve(int edge) {
  std::unique_ptr<GeomAdaptor_Curve>& slot = curves_[static_cast<std::size_t>(edge)];
  if (!slot) {
    // Bounds wider than the edge's range, as for surfaces: the adaptor evaluates a B-spline on
    // its first or last parameter by the uncached path.
    const EdgeData& e = data_.edges[static_cast<std::size_t>(edge)];
    const double range = e.last - e.first;
    slot = std::make_unique<GeomAdaptor_Curve>(e.curve, e.first - range, e.last + range);
  }
  return *slot;
}

Eigen::Vector3d unitNormal(const FaceData& face, const gp_Vec& su, const gp_Vec& sv, double relativeTolerance) {
  const Eigen::Vector3d n = toEigen(su).cross(toEigen(sv));
  const double length = n.norm();
  if (!(length > relativeTolerance * (su.Magnitude() + sv.Magnitude()) + 1e-300) || !std::isfinite(length))
    return Eigen::Vector3d::Zero();
  return face.reversed ? Eigen::Vector3d(-n / length) : Eigen::Vector3d(n / length);
}

Eigen::Vector3d faceNormal(const FaceData& face, FaceSurface& surface, double u, double v) {
  gp_Pnt p;
  gp_Vec su, sv;
  surface.D1(u, v, p, su, sv);
  const Eigen::Vector3d n = unitNormal(face, su, sv, 1e-12);
  if (!n.isZero()) return n;
  // At a pole (sphere apex) one derivative vanishes: step towards the face's interior.
  const double uc = 0.5 * (face.u0 + face.u1);
  const double vc = 0.5 * (face.v0 + face.v1);
  surface.D1(u + 1e-6 * (uc - u), v + 1e-6 * (vc - v), p, su, sv);
  return unitNormal(face, su, sv, 0.0);
}

TrimClassifier::TrimClassifier(double u0, double u1, double v0, double v1,
                               const std::vector<std::vector<Eigen::Vector2d>>& curves)
    : everywhere_(curves.empty()), origin_(u0, v0), step_((u1 - u0) / kSize, (v1 - v0) / kSize) {
  if (everywhere_) return;
  if (!(step_.minCoeff() > 0) || !step_.allFinite()) throw TopologyError("Target: a face has a degenerate parameter box");
  cells_.assign(kSize * kSize, Unknown);
  std::vector<std::vector<int>> lists(kSize * kSize);
  for (const std::vector<Eigen::Vector2d>& curve : curves) {
    for (std::size_t k = 0; k + 1 < curve.size(); ++k) {
      const Eigen::Vector2d& a = curve[k];
      const Eigen::Vector2d& b = curve[k + 1];
      const int id = static_cast<int>(segments_.size());
      segments_.emplace_back(a.x(), a.y(), b.x(), b.y());
      for (int j = index(std::min(a.y(), b.y()), 1); j <= index(std::max(a.y(), b.y()), 1); ++j)
        for (int i = index(std::min(a.x(), b.x()), 0); i <= index(std::max(a.x(), b.x()), 0); ++i)
          lists[static_cast<std::size_t>(j * kSize + i)].push_back(id);
      // Mark the cells along the segment (quarter-cell steps) and their neighbours: no segment
      // passes through a cell that is not marked.
      const int steps = 1 + static_cast<int>(4 * (b - a).cwiseAbs().cwiseQuotient(step_).maxCoeff());
      for (int s = 0; s <= steps; ++s) {
        const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(s) / steps);
        const int x = index(p.x(), 0), y = index(p.y(), 1);
        for (int j = std::max(0, y - 1); j <= std::min(kSize - 1, y + 1); ++j)
          for (int i = std::max(0, x - 1); i <= std::min(kSize - 1, x + 1); ++i)
            cells_[static_cast<std::size_t>(j * kSize + i)] = Boundary;
      }
    }
  }
  cellStart_.assign(1, 0);
  for (const std::vector<int>& list : lists) {
    cellSegments_.insert(cellSegments_.end(), list.begin(), list.end());
    cellStart_.push_back(static_cast<int>(cellSegments_.size()));
  }
  // Every other connected region of cells is on one side: test one cell (crossings up to the
  // box's end), fill the region.
  std::vector<int> stack;
  for (int start = 0; start < kSize * kSize; ++start) {
    if (cells_[static_cast<std::size_t>(start)] != Unknown) continue;
    const int x = start % kSize, y = start / kSize;
    const Eigen::Vector2d center = origin_ + Eigen::Vector2d(x + 0.5, y + 0.5).cwiseProduct(step_);
    const std::uint8_t value = oddCrossings(center, 0, 1, kSize - 1 - x) ? Inside : Outside;
    cells_[static_cast<std::size_t>(start)] = value;
    stack.assign(1, start);
    while (!stack.empty()) {
      const int cell = stack.back();
      stack.pop_back();
      const int cx = cell % kSize, cy = cell / kSize;
      for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
        const int nx = cx + dx, ny = cy + dy;
        if (nx < 0 || ny < 0 || nx >= kSize || ny >= kSize) continue;
        std::uint8_t& next = cells_[static_cast<std::size_t>(ny * kSize + nx)];
        if (next != Unknown) continue;
        next = value;
        stack.push_back(ny * kSize + nx);
      }
    }
  }
}

int TrimClassifier::index(double x, int axis) const {
  return std::clamp(static_cast<int>(std::floor((x - origin_[axis]) / step_[axis])), 0, kSize - 1);
}

bool TrimClassifier::oddCrossings(const Eigen::Vector2d& p, int axis, int direction, int steps) const {
  // Half-open across the ray so that a vertex shared by two segments counts once. A segment
  // listed in several cells counts in the cell holding its crossing only.
  const int across = 1 - axis;
  int cell[2] = {index(p.x(), 0), index(p.y(), 1)};
  bool odd = false;
  for (int n = 0; n <= steps; ++n, cell[axis] += direction) {
    const std::size_t c = static_cast<std::size_t>(cell[1] * kSize + cell[0]);
    for (int k = cellStart_[c]; k < cellStart_[c + 1]; ++k) {
      const Eigen::Vector4d& s = segments_[static_cast<std::size_t>(cellSegments_[static_cast<std::size_t>(k)])];
      const double a0 = s[axis], c0 = s[across], a1 = s[2 + axis], c1 = s[2 + across];
      if ((c0 > p[across]) == (c1 > p[across])) continue;
      const double crossing = std::clamp(a0 + (p[across] - c0) * (a1 - a0) / (c1 - c0), std::min(a0, a1), std::max(a0, a1));
      if (direction * (crossing - p[axis]) > 0 && index(crossing, axis) == cell[axis]) odd = !odd;
    }
  }
  return odd;
}

bool TrimClassifier::inside(double u, double v) const {
  if (everywhere_) return true;
  const Eigen::Vector2d p(u, v);
  const Eigen::Vector2d x = (p - origin_).cwiseQuotient(step_);
  if (!(x.minCoeff() >= 0 && x.maxCoeff() <= kSize)) return false;  // the box holds the boundary
  const int i = index(u, 0), j = index(v, 1);
  const std::uint8_t cell = cells_[static_cast<std::size_t>(j * kSize + i)];
  if (cell != Boundary) return cell == Inside;
  // Rays along +u, -u, +v, -v: the first to reach a known cell (or to leave the grid: outside)
  // decides. The point is on that cell's side when an even number of segments cross in between.
  constexpr int kAxis[4] = {0, 0, 1, 1};
  constexpr int kDirection[4] = {1, -1, 1, -1};
  for (int steps = 1;; ++steps) {
    for (int r = 0; r < 4; ++r) {
      const int ci = kAxis[r] == 0 ? i + kDirection[r] * steps : i;
      const int cj = kAxis[r] == 1 ? j + kDirection[r] * steps : j;
      const bool leaves = ci < 0 || cj < 0 || ci >= kSize || cj >= kSize;
      const std::uint8_t known = leaves ? std::uint8_t{Outside} : cells_[static_cast<std::size_t>(cj * kSize + ci)];
      if (known == Boundary) continue;
      return (known == Inside) != oddCrossings(p, kAxis[r], kDirection[r], steps - 1);
    }
  }
}

std::unique_ptr<ThreadContext> Target::Data::acquireContext() const {
  std::lock_guard<std::mutex> lock(poolMutex);
  if (pool.empty()) return std::make_unique<ThreadContext>(*this);
  std::unique_ptr<ThreadContext> context = std::move(pool.back());
  pool.pop_back();
  return context;
}

void Target::Data::releaseContext(std::unique_ptr<ThreadContext> context) const {
  std::lock_guard<std::mutex> lock(poolMutex);
  pool.push_back(std::move(context));
}

void ProjectionResult::resize(Eigen::Index count) {
  points.setZero(count, 3);
  distances.setConstant(count, -1.0);
  ids.setConstant(count, -1);
  faces.setConstant(count, -1);
  params.setZero(count, 2);
  normals.setZero(count, 3);
  status.assign(static_cast<std::size_t>(count), ProjectionStatus::Failed);
}

void ProjectionResult::setRow(Eigen::Index i, const ProjectionResult& from, Eigen::Index k) {
  points.row(i) = from.points.row(k);
  distances[i] = from.distances[k];
  ids[i] = from.ids[k];
  faces[i] = from.faces[k];
  params.row(i) = from.params.row(k);
  normals.row(i) = from.normals.row(k);
  status[static_cast<std::size_t>(i)] = from.status[static_cast<std::size_t>(k)];
}

Target::Target(const TopoDS_Shape& shape, const TargetOptions& options) : data_(std::make_unique<Data>()) {
  if (shape.IsNull()) throw InvalidInputError("Target: the shape is null");
  // Every option named with its value, NaN and infinities included (they were accepted).
  checkFiniteAtLeast(options.relativeDeflection, 0.0, "Target: relative_deflection", true);
  checkFiniteAtLeast(options.angularDeflection, 0.0, "Target: angular_deflection", true);
  checkFiniteAtLeast(options.relativeTolerance, 0.0, "Target: relative_tolerance", true);
  checkFiniteAtLeast(options.relativeGapSearch, 0.0, "Target: relative_gap_search");
  if (!(options.sharpAngleDeg >= 0.0 && options.sharpAngleDeg <= 180.0))
    throw InvalidInputError("Target: sharp_angle_deg must be 0 .. 180, got " +
                            numberText(options.sharpAngleDeg));
  if (options.threads < 0)
    throw InvalidInputError("Target: threads must be 0 (every hardware thread) or more, got " +
                            std::to_string(options.threads));
  data_->options = options;
  translateOcctErrors("Target: reading the shape", [&] {
    checkScale(shape, options);
    // Own copy: meshing writes triangulations into the shape.
    data_->shape = BRepBuilderAPI_Copy(shape, true, false).Shape();
    extractTopology(*data_);
    cad::ShapeSummaryOptions summaryOptions;
    summaryOptions.sharpAngleDegrees = options.sharpAngleDeg;
    data_->report.shape = cad::summarizeShape(data_->shape, summaryOptions);
    measureSize(*data_);
    tessellate(*data_);
    buildReport(*data_);
  });
  if (data_->triangles.rows() == 0) throw TopologyError("Target: no face of the shape could be tessellated");
}

Target::Target(const cad::RepairedShape& shape, const TargetOptions& options) : Target(shape.shape, options) {
  data_->report.repair = shape.report;
}

Target::~Target() = default;
Target::Target(Target&&) noexcept = default;
Target& Target::operator=(Target&&) noexcept = default;

const TargetReport& Target::report() const { return data_->report; }
const TargetOptions& Target::options() const { return data_->options; }
int Target::faceCount() const { return static_cast<int>(data_->faces.size()); }
int Target::edgeCount() const { return static_cast<int>(data_->edges.size()); }
int Target::vertexCount() const { return static_cast<int>(data_->vertices.size()); }

std::vector<int> Target::sharpEdges(double angleDeg) const {
  // NaN compares false with every dihedral angle and gave an empty list, as if none were sharp.
  if (!(angleDeg >= 0.0 && angleDeg <= 180.0))
    throw InvalidInputError("Target: sharp_edges angle_deg must be 0 .. 180, got " + numberText(angleDeg));
  std::vector<int> result;
  const std::vector<cad::EdgeInfo>& edges = data_->report.shape.edges;
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const bool twoFaces = edges[i].kind == cad::EdgeKind::Smooth || edges[i].kind == cad::EdgeKind::Sharp;
    if (twoFaces && edges[i].maxDihedralDegrees >= angleDeg) result.push_back(static_cast<int>(i));
  }
  return result;
}

std::vector<int> Target::freeEdges() const { return data_->report.freeEdges; }

Eigen::Vector3d Target::vertexPosition(int vertex) const {
  if (vertex < 0 || vertex >= vertexCount())
    throw InvalidInputError("Target: vertex " + std::to_string(vertex) + " does not exist (" +
                            std::to_string(vertexCount()) + " vertices)");
  return data_->vertices[static_cast<std::size_t>(vertex)];
}

std::array<int, 2> Target::edgeVertices(int edge) const {
  if (edge < 0 || edge >= edgeCount())
    throw InvalidInputError("Target: edge " + std::to_string(edge) + " does not exist (" + std::to_string(edgeCount()) +
                            " edges)");
  const EdgeData& e = data_->edges[static_cast<std::size_t>(edge)];
  return {e.vertex0, e.vertex1};
}

double Target::edgeTolerance(int edge) const {
  edgeVertices(edge);  // checks the id
  return data_->edges[static_cast<std::size_t>(edge)].tolerance;
}

Points Target::edgePolyline(int edge) const {
  const std::array<int, 2> ends = edgeVertices(edge);
  const EdgeData& e = data_->edges[static_cast<std::size_t>(edge)];
  Points points(static_cast<Eigen::Index>(e.polyline.size()), 3);
  for (std::size_t k = 0; k < e.polyline.size(); ++k) points.row(static_cast<Eigen::Index>(k)) = e.polyline[k].transpose();
  // The polyline follows the curve's parameter; a reversed edge starts at its second vertex.
  if (points.rows() > 1 && ends[0] >= 0 && ends[1] >= 0 && ends[0] != ends[1]) {
    const Eigen::Vector3d start = points.row(0).transpose();
    if ((start - data_->vertices[static_cast<std::size_t>(ends[1])]).norm() <
        (start - data_->vertices[static_cast<std::size_t>(ends[0])]).norm()) {
      points = points.colwise().reverse().eval();
    }
  }
  return points;
}

const Points& Target::meshNodes() const { return data_->nodes; }
const Eigen::VectorXd& Target::meshNodeTolerances() const { return data_->nodeTolerance; }

SurfaceSamples Target::surfaceSamples(int subdivisions) const {
  if (subdivisions < 1 || subdivisions > 64) {
    throw InvalidInputError("Target::surfaceSamples: subdivisions must be within 1..64, got " +
                            std::to_string(subdivisions));
  }
  const Data& d = *data_;
  const int k = subdivisions;
  // Every triangle side once (node pairs of one face), each with the face that holds it.
  std::map<std::pair<int, int>, int> sides;
  for (Eigen::Index t = 0; t < d.triangles.rows(); ++t) {
    for (int c = 0; c < 3; ++c) {
      const int a = d.triangles(t, c), b = d.triangles(t, (c + 1) % 3);
      sides.emplace(std::minmax(a, b), d.triangleFaces[t]);
    }
  }
  const Eigen::Index nodes = d.nodes.rows();
  const Eigen::Index count = nodes + static_cast<Eigen::Index>(sides.size()) * (k - 1) +
                             d.triangles.rows() * static_cast<Eigen::Index>((k - 1) * (k - 2) / 2);
  SurfaceSamples samples;
  samples.points.resize(count, 3);
  samples.tolerances.resize(count);
  samples.points.topRows(nodes) = d.nodes;
  samples.tolerances.head(nodes) = d.nodeTolerance;
  Eigen::Index next = nodes;
  translateOcctErrors("Target::surfaceSamples", [&] {
    // The point of face f at the barycentric combination of nodes (weights w, summing to 1).
    const auto add = [&](int face, std::initializer_list<std::pair<int, double>> weights) {
      Eigen::Vector2d uv = Eigen::Vector2d::Zero();
      double tolerance = std::numeric_limits<double>::infinity();
      for (const auto& [node, weight] : weights) {
        uv += weight * d.nodeUV.row(node).transpose();
        if (weight > 0.0) tolerance = std::min(tolerance, d.nodeTolerance[node]);
      }
      samples.points.row(next) = toEigen(d.faces[static_cast<std::size_t>(face)].surface->Value(uv.x(), uv.y())).transpose();
      samples.tolerances[next] = tolerance;
      ++next;
    };
    for (const auto& [side, face] : sides) {
      for (int i = 1; i < k; ++i) add(face, {{side.first, 1.0 - static_cast<double>(i) / k}, {side.second, static_cast<double>(i) / k}});
    }
    for (Eigen::Index t = 0; t < d.triangles.rows(); ++t) {
      for (int i = 1; i < k; ++i) {
        for (int j = 1; i + j < k; ++j) {
          const double b = static_cast<double>(i) / k, c = static_cast<double>(j) / k;
          add(d.triangleFaces[t], {{d.triangles(t, 0), 1.0 - b - c}, {d.triangles(t, 1), b}, {d.triangles(t, 2), c}});
        }
      }
    }
  });
  return samples;
}
const Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>& Target::meshTriangles() const { return data_->triangles; }
const Eigen::VectorXi& Target::meshTriangleFaces() const { return data_->triangleFaces; }

}  // namespace bvmesh::target

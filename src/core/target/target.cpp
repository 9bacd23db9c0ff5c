// Target's construction: the shape's faces, edges and vertices extracted once, its scale checked,
// its tessellation with the spatial index, the gaps between faces and the report; and its accessors.
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
  // The tessellation's triangles grow as the inverse of the deflection (a sphere at 1e-5: 1.3 GB
  // and 20 s; at 1e-6 more than 8 GB), and finer gains nothing: the index's results do not depend on it.
  if (options.relativeDeflection < kFinestRelativeDeflection) {
    throw InvalidInputError("Target: relative_deflection must be at least " + numberText(kFinestRelativeDeflection) +
                            " (a finer tessellation of the projection index costs memory as its inverse and "
                            "changes no result), got " + numberText(options.relativeDeflection));
  }
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

#include "core/cad/shape_repair.h"

#include <BRepAdaptor_Curve.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepGProp.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GCPnts_AbscissaPoint.hxx>
#include <GProp_GProps.hxx>
#include <Geom_Surface.hxx>
#include <Poly_Triangulation.hxx>
#include <gp_Pnt2d.hxx>
#include <Precision.hxx>
#include <ShapeAnalysis_Curve.hxx>
#include <ShapeAnalysis_FreeBounds.hxx>
#include <ShapeAnalysis_Surface.hxx>
#include <ShapeAnalysis_ShapeTolerance.hxx>
#include <ShapeFix_Solid.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Iterator.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>
#include <TopoDS_Vertex.hxx>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>

#include <Eigen/Geometry>

#include "core/common/closest_point.h"
#include "core/common/errors.h"
#include "core/common/number_text.h"
#include "core/common/occt_errors.h"

namespace bvmesh::cad {
namespace {

// Gaps are looked for up to this width (relative to the model size): wider openings are the
// shape's real boundary (a half model's root, a wing's tip), not a gap between patches.
constexpr double kGapSearch = 2e-2;
constexpr int kSamples = 9;

TopoDS_Shape emptyCompound() {
  TopoDS_Compound compound;
  BRep_Builder().MakeCompound(compound);
  return compound;
}

double diagonalOf(const TopoDS_Shape& shape) {
  Bnd_Box box;
  BRepBndLib::Add(shape, box, false);
  return box.IsVoid() ? 0.0 : std::sqrt(box.SquareExtent());
}

double edgeLength(const TopoDS_Edge& edge) {
  if (BRep_Tool::Degenerated(edge)) return 0.0;
  try {
    return GCPnts_AbscissaPoint::Length(BRepAdaptor_Curve(edge));
  } catch (const Standard_Failure&) {
    return 0.0;  // an edge OCCT cannot measure is not one to size the tolerance by
  }
}

// How the edges of a shape are shared by its faces.
struct EdgeTopology {
  TopTools_IndexedMapOfShape faces;
  TopTools_IndexedMapOfShape edges;
  std::vector<int> faceCount;   // per edge: faces around it (a seam's face counts once)
  std::vector<int> firstFace;   // per edge: one face around it (0-based), -1 if none
  std::vector<bool> seam, degenerate;
  int shared = 0, free = 0, nonManifold = 0;

  explicit EdgeTopology(const TopoDS_Shape& shape) {
    TopExp::MapShapes(shape, TopAbs_FACE, faces);
    TopExp::MapShapes(shape, TopAbs_EDGE, edges);
    TopTools_IndexedDataMapOfShapeListOfShape edgeFaces;
    TopExp::MapShapesAndUniqueAncestors(shape, TopAbs_EDGE, TopAbs_FACE, edgeFaces);
    for (int i = 1; i <= edges.Extent(); ++i) {
      const TopoDS_Edge& edge = TopoDS::Edge(edges(i));
      const TopTools_ListOfShape* around = edgeFaces.Seek(edge);
      const int count = around != nullptr ? around->Extent() : 0;
      const bool isDegenerate = BRep_Tool::Degenerated(edge);
      const bool isSeam = count == 1 && BRep_Tool::IsClosed(edge, TopoDS::Face(around->First()));
      faceCount.push_back(count);
      firstFace.push_back(count > 0 ? faces.FindIndex(around->First()) - 1 : -1);
      seam.push_back(isSeam);
      degenerate.push_back(isDegenerate);
      if (isDegenerate || isSeam) continue;
      if (count == 2) ++shared;
      else if (count >= 3) ++nonManifold;
      else ++free;
    }
  }
  bool isFree(int i) const {  // 0-based
    const auto k = static_cast<std::size_t>(i);
    return !degenerate[k] && !seam[k] && faceCount[k] <= 1;
  }
};

std::vector<gp_Pnt> samplesOf(const BRepAdaptor_Curve& curve) {
  std::vector<gp_Pnt> points;
  const double first = curve.FirstParameter();
  const double last = curve.LastParameter();
  for (int k = 0; k < kSamples; ++k) points.push_back(curve.Value(first + (k + 0.5) / kSamples * (last - first)));
  return points;
}

double distanceToCurve(const gp_Pnt& point, const BRepAdaptor_Curve& curve) {
  gp_Pnt foot;
  double parameter = 0.0;
  return ShapeAnalysis_Curve().Project(curve, point, Precision::Confusion(), foot, parameter, true);
}

// Largest distance from the samples of `a` to `b`.
double edgeDistance(const TopoDS_Edge& a, const TopoDS_Edge& b) {
  const BRepAdaptor_Curve curveA(a);
  const BRepAdaptor_Curve curveB(b);
  double largest = 0.0;
  for (const gp_Pnt& p : samplesOf(curveA)) largest = std::max(largest, distanceToCurve(p, curveB));
  return largest;
}

// Free edges with a free edge of another face within the search width, farther apart than the
// tolerance at some sample. Edges that meet, or that both meet a third free edge, are the shape's
// outline turning a corner (the wedge of a sharp trailing edge at a half model's root), not a gap.
std::vector<OpenGap> findOpenGaps(const EdgeTopology& topology, double tolerance, double search) {
  struct FreeEdge {
    int id;
    int face;
    TopoDS_Edge edge;
    std::vector<gp_Pnt> samples;
    Bnd_Box box;
    std::vector<int> vertices;  // indices into `vertexIndex`
  };
  TopTools_IndexedMapOfShape vertexIndex;
  std::vector<FreeEdge> free;
  for (int i = 0; i < topology.edges.Extent(); ++i) {
    if (!topology.isFree(i)) continue;
    const TopoDS_Edge& edge = TopoDS::Edge(topology.edges(i + 1));
    FreeEdge item{i, topology.firstFace[static_cast<std::size_t>(i)], edge, samplesOf(BRepAdaptor_Curve(edge)), {}, {}};
    BRepBndLib::Add(edge, item.box, false);
    TopoDS_Vertex first, last;
    TopExp::Vertices(edge, first, last);
    for (const TopoDS_Vertex& v : {first, last})
      if (!v.IsNull()) item.vertices.push_back(vertexIndex.Add(v));
    free.push_back(std::move(item));
  }
  std::vector<std::vector<std::size_t>> atVertex(static_cast<std::size_t>(vertexIndex.Extent()) + 1);
  for (std::size_t k = 0; k < free.size(); ++k)
    for (int v : free[k].vertices) atVertex[static_cast<std::size_t>(v)].push_back(k);
  auto neighbours = [&](std::size_t k) {
    std::vector<std::size_t> out;
    for (int v : free[k].vertices)
      for (std::size_t other : atVertex[static_cast<std::size_t>(v)]) out.push_back(other);
    return out;
  };
  std::vector<OpenGap> gaps;
  for (std::size_t ka = 0; ka < free.size(); ++ka) {
    const FreeEdge& a = free[ka];
    std::vector<bool> outline(free.size(), false);
    for (std::size_t n : neighbours(ka)) {
      outline[n] = true;
      for (std::size_t m : neighbours(n)) outline[m] = true;
    }
    Bnd_Box grown = a.box;
    grown.Enlarge(search);
    std::vector<const FreeEdge*> near;
    for (std::size_t kb = 0; kb < free.size(); ++kb) {
      const FreeEdge& b = free[kb];
      if (b.face != a.face && !outline[kb] && !b.box.IsOut(grown)) near.push_back(&b);
    }
    if (near.empty()) continue;
    std::vector<BRepAdaptor_Curve> curves;
    for (const FreeEdge* b : near) curves.emplace_back(b->edge);
    double width = 0.0;
    int nearestAtMiddle = -1;
    for (std::size_t k = 0; k < a.samples.size(); ++k) {
      double best = std::numeric_limits<double>::infinity();
      int bestEdge = -1;
      for (std::size_t c = 0; c < near.size(); ++c) {
        const double d = distanceToCurve(a.samples[k], curves[c]);
        if (d < best) {
          best = d;
          bestEdge = static_cast<int>(c);
        }
      }
      width = std::max(width, best);
      if (k == a.samples.size() / 2) nearestAtMiddle = bestEdge;
    }
    if (!(width > tolerance && width <= search) || nearestAtMiddle < 0) continue;
    const FreeEdge& b = *near[static_cast<std::size_t>(nearestAtMiddle)];
    // One report per pair of edges, with the wider of the two widths.
    auto same = std::find_if(gaps.begin(), gaps.end(), [&](const OpenGap& g) { return g.edge == b.id && g.otherEdge == a.id; });
    if (same != gaps.end()) {
      same->width = std::max(same->width, width);
      continue;
    }
    const gp_Pnt middle = a.samples[a.samples.size() / 2];
    gaps.push_back({a.id, b.id, a.face, b.face, width, {middle.X(), middle.Y(), middle.Z()}});
  }
  return gaps;
}

// ---- overlapping faces -------------------------------------------------------------------------

// A face's tessellation: triangles with their corners' (u, v), their boxes, and the face's box.
struct FaceTriangles {
  std::vector<std::array<Eigen::Vector3d, 3>> corners;
  std::vector<std::array<bool, 3>> boundary;  // side k (corner k to k + 1) on the mesh's boundary
  std::vector<std::array<gp_XY, 3>> uv;
  std::vector<Bnd_Box> boxes;
  Bnd_Box box;
};

FaceTriangles faceTriangles(const TopoDS_Face& face) {
  FaceTriangles result;
  TopLoc_Location location;
  const Handle(Poly_Triangulation) mesh = BRep_Tool::Triangulation(face, location);
  if (mesh.IsNull() || !mesh->HasUVNodes()) return result;
  const gp_Trsf transform = location.Transformation();
  std::map<std::pair<int, int>, int> sides;  // node pair -> triangles using it
  for (int t = 1; t <= mesh->NbTriangles(); ++t) {
    int n[3];
    mesh->Triangle(t).Get(n[0], n[1], n[2]);
    for (int k = 0; k < 3; ++k) ++sides[std::minmax(n[k], n[(k + 1) % 3])];
  }
  for (int t = 1; t <= mesh->NbTriangles(); ++t) {
    int n[3];
    mesh->Triangle(t).Get(n[0], n[1], n[2]);
    std::array<bool, 3> boundary{};
    for (int k = 0; k < 3; ++k) boundary[static_cast<std::size_t>(k)] = sides[std::minmax(n[k], n[(k + 1) % 3])] == 1;
    result.boundary.push_back(boundary);
    std::array<Eigen::Vector3d, 3> corner;
    std::array<gp_XY, 3> uv;
    Bnd_Box box;
    for (std::size_t k = 0; k < 3; ++k) {
      const gp_Pnt p = mesh->Node(n[k]).Transformed(transform);
      corner[k] = Eigen::Vector3d(p.X(), p.Y(), p.Z());
      uv[k] = mesh->UVNode(n[k]).XY();
      box.Add(p);
    }
    result.corners.push_back(corner);
    result.uv.push_back(uv);
    result.boxes.push_back(box);
    result.box.Add(box);
  }
  return result;
}

// Area of `a` lying within `tolerance` of the inside of `b`, and its centroid. Triangles of a's
// tessellation near b's are split into up to 16 x 16 parts of at most `spacing`; a part counts
// when the point of a's surface at its centroid lies within the tolerance of b's surface (Newton
// from the nearest triangle of b) and inside b's trim. The tessellations (deflection
// `deflection`) only choose which points to project.
std::pair<double, Eigen::Vector3d> overlapArea(const TopoDS_Face& a, const FaceTriangles& ta, const TopoDS_Face& b,
                                               const FaceTriangles& tb, double tolerance, double deflection,
                                               double spacing) {
  const Handle(Geom_Surface) surfaceA = BRep_Tool::Surface(a);
  ShapeAnalysis_Surface surfaceB(BRep_Tool::Surface(b));
  const double band = tolerance + 2.0 * deflection;
  double area = 0.0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  std::vector<std::size_t> near;
  for (std::size_t t = 0; t < ta.corners.size(); ++t) {
    Bnd_Box reach = ta.boxes[t];
    reach.Enlarge(band);
    if (reach.IsOut(tb.box)) continue;
    near.clear();
    for (std::size_t k = 0; k < tb.corners.size(); ++k)
      if (!reach.IsOut(tb.boxes[k])) near.push_back(k);
    if (near.empty()) continue;
    const auto& [p0, p1, p2] = ta.corners[t];
    // Overlaps are wider than a triangle: one that does not come within the band of b at its
    // corners or centroid holds none.
    const auto withinBand = [&](const Eigen::Vector3d& q) {
      for (std::size_t k : near) {
        const auto& [q0, q1, q2] = tb.corners[k];
        if ((closestPointOnTriangle(q, q0, q1, q2) - q).squaredNorm() <= band * band) return true;
      }
      return false;
    };
    if (!withinBand(p0) && !withinBand(p1) && !withinBand(p2) && !withinBand((p0 + p1 + p2) / 3.0)) continue;
    const double longest = std::max({(p1 - p0).norm(), (p2 - p1).norm(), (p0 - p2).norm()});
    const int m = std::clamp(static_cast<int>(std::ceil(longest / spacing)), 1, 16);
    const double part = 0.5 * (p1 - p0).cross(p2 - p0).norm() / (m * m);
    // Centroids of the m^2 parts, in barycentric coordinates (s, r) of corners 1 and 2.
    for (int i = 0; i < m; ++i) {
      for (int j = 0; i + j < m; ++j) {
        for (int flip = 0; flip < (i + j + 1 < m ? 2 : 1); ++flip) {
          const double s1 = (i + (flip ? 2.0 : 1.0) / 3.0) / m, s2 = (j + (flip ? 2.0 : 1.0) / 3.0) / m;
          const gp_XY uv = (1.0 - s1 - s2) * ta.uv[t][0] + s1 * ta.uv[t][1] + s2 * ta.uv[t][2];
          const gp_Pnt onA = surfaceA->Value(uv.X(), uv.Y());
          const Eigen::Vector3d q(onA.X(), onA.Y(), onA.Z());
          double nearest = band * band;
          std::size_t seed = tb.corners.size();
          for (std::size_t k : near) {
            const auto& [q0, q1, q2] = tb.corners[k];
            const double d = (closestPointOnTriangle(q, q0, q1, q2) - q).squaredNorm();
            if (d <= nearest) {
              nearest = d;
              seed = k;
            }
          }
          if (seed == tb.corners.size()) continue;
          // Nearest to b's outline (where a meets b at a shared edge, or runs on beyond it): no
          // overlap there, and its foot lies outside b's trim.
          const auto& [q0, q1, q2] = tb.corners[seed];
          const Eigen::Vector3d foot = closestPointOnTriangle(q, q0, q1, q2);
          bool onOutline = false;
          for (std::size_t k = 0; k < 3 && !onOutline; ++k) {
            const Eigen::Vector3d& e0 = tb.corners[seed][k];
            const Eigen::Vector3d& e1 = tb.corners[seed][(k + 1) % 3];
            onOutline = tb.boundary[seed][k] &&
                        (closestPointOnSegment(foot, e0, e1) - foot).norm() <= 1e-9 * (1.0 + (e1 - e0).norm());
          }
          if (onOutline) continue;
          const gp_XY seedUv = (tb.uv[seed][0] + tb.uv[seed][1] + tb.uv[seed][2]) / 3.0;
          const gp_Pnt2d onB = surfaceB.NextValueOfUV(gp_Pnt2d(seedUv), onA, 0.1 * tolerance);
          if (surfaceB.Value(onB).Distance(onA) > tolerance) continue;
          if (BRepClass_FaceClassifier(b, onB, tolerance).State() != TopAbs_IN) continue;
          area += part;
          moment += part * q;
        }
      }
    }
  }
  return {area, area > 0.0 ? Eigen::Vector3d(moment / area) : Eigen::Vector3d::Zero()};
}

double facePerimeter(const TopoDS_Shape& face);

// Pairs of faces that overlap by more than a strip of twice the tolerance along the smaller
// one's boundary could (faces meeting at an edge touch along it, within the tolerance).
std::vector<FaceOverlap> findOverlaps(const TopoDS_Shape& shape, double tolerance, double modelSize) {
  const double deflection = 2e-3 * modelSize;
  // Below OCCT's precision BRepMesh refuses the deflection (the target says "too small").
  if (!(deflection >= Precision::Confusion())) return {};
  // A copy to tessellate: the shape itself goes back to the caller as read or sewn.
  const TopoDS_Shape copy = BRepBuilderAPI_Copy(shape, true, false).Shape();
  BRepMesh_IncrementalMesh(copy, deflection, false, 0.5);
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(copy, TopAbs_FACE, faces);
  std::vector<FaceTriangles> triangles;
  for (int i = 1; i <= faces.Extent(); ++i) triangles.push_back(faceTriangles(TopoDS::Face(faces(i))));
  std::vector<FaceOverlap> overlaps;
  for (int i = 0; i < faces.Extent(); ++i) {
    for (int j = i + 1; j < faces.Extent(); ++j) {
      const FaceTriangles& ti = triangles[static_cast<std::size_t>(i)];
      const FaceTriangles& tj = triangles[static_cast<std::size_t>(j)];
      if (ti.box.IsVoid() || tj.box.IsVoid()) continue;
      Bnd_Box grown = ti.box;
      grown.Enlarge(tolerance + 2.0 * deflection);
      if (grown.IsOut(tj.box)) continue;
      const TopoDS_Face& fi = TopoDS::Face(faces(i + 1));
      const TopoDS_Face& fj = TopoDS::Face(faces(j + 1));
      auto [area, where] = overlapArea(fi, ti, fj, tj, tolerance, deflection, 1e-2 * modelSize);
      const auto [areaBack, whereBack] = overlapArea(fj, tj, fi, ti, tolerance, deflection, 1e-2 * modelSize);
      if (areaBack > area) {
        area = areaBack;
        where = whereBack;
      }
      if (!(area > 0.0 && area > 2.0 * tolerance * std::min(facePerimeter(fi), facePerimeter(fj)))) continue;
      overlaps.push_back({i, j, area, {where.x(), where.y(), where.z()}});
    }
  }
  return overlaps;
}

double faceArea(const TopoDS_Shape& face) {
  GProp_GProps props;
  BRepGProp::SurfaceProperties(face, props);
  return props.Mass();
}

double facePerimeter(const TopoDS_Shape& face) {
  double length = 0.0;
  for (TopExp_Explorer e(face, TopAbs_EDGE); e.More(); e.Next()) length += edgeLength(TopoDS::Edge(e.Current()));
  return length;
}

// Why sewing must not be used: a face whose area changes by more than the tolerance can account
// for (its boundary moving by the tolerance all along its perimeter); empty when none does.
std::string geometryChange(const BRepBuilderAPI_Sewing& sewing, const TopTools_IndexedMapOfShape& faces,
                           double tolerance) {
  for (int i = 1; i <= faces.Extent(); ++i) {
    const TopoDS_Shape& face = faces(i);
    if (!sewing.IsModified(face)) continue;
    const TopoDS_Shape& sewn = sewing.Modified(face);
    if (sewn.IsNull() || sewn.ShapeType() != TopAbs_FACE) continue;  // removed as tiny: reported apart
    const double before = faceArea(face);
    const double after = faceArea(sewn);
    // 1e-5 of the area: BRepGProp's integration noise on trimmed B-spline faces.
    const double allowed = 2.0 * tolerance * facePerimeter(face) + 1e-5 * std::abs(before);
    if (std::abs(after - before) > allowed) {
      char text[256];
      std::snprintf(text, sizeof(text),
                    "sewing would change Face%d's area from %.6g to %.6g, more than the tolerance %.3g allows",
                    i, before, after, tolerance);
      return text;
    }
  }
  return "";
}

// The largest distance between two edges that sewing made one.
double largestSewnDistance(const BRepBuilderAPI_Sewing& sewing) {
  double largest = 0.0;
  for (int i = 1; i <= sewing.NbContigousEdges(); ++i) {
    const TopTools_ListOfShape& sections = sewing.ContigousEdgeCouple(i);
    if (sections.Extent() < 2) continue;
    const TopoDS_Edge& a = TopoDS::Edge(sections.First());
    const TopoDS_Edge& b = TopoDS::Edge(sections.Last());
    if (BRep_Tool::Degenerated(a) || BRep_Tool::Degenerated(b)) continue;
    try {
      largest = std::max(largest, std::max(edgeDistance(a, b), edgeDistance(b, a)));
    } catch (const Standard_Failure&) {
      // A section OCCT cannot sample: its distance is unknown, not zero; the edge tolerance bounds it.
      largest = std::max(largest, BRep_Tool::Tolerance(TopoDS::Edge(sewing.ContigousEdge(i))));
    }
  }
  return largest;
}

// The only shell of `shape` when it holds nothing else.
TopoDS_Shape loneShell(const TopoDS_Shape& shape) {
  if (shape.ShapeType() == TopAbs_SHELL) return shape;
  if (shape.ShapeType() != TopAbs_COMPOUND) return {};
  TopoDS_Iterator it(shape);
  if (!it.More()) return {};
  const TopoDS_Shape first = it.Value();
  it.Next();
  return !it.More() && first.ShapeType() == TopAbs_SHELL ? first : TopoDS_Shape();
}

void analyse(const TopoDS_Shape& shape, double tolerance, double modelSize, RepairReport& report) {
  const EdgeTopology topology(shape);
  report.faces = topology.faces.Extent();
  report.freeEdges = topology.free;
  report.nonManifoldEdges = topology.nonManifold;
  report.closedFreeLoops = report.openFreeChains = 0;
  if (topology.free > 0) {
    ShapeAnalysis_FreeBounds bounds(shape, false, true);
    for (TopoDS_Iterator it(bounds.GetClosedWires()); it.More(); it.Next()) ++report.closedFreeLoops;
    for (TopoDS_Iterator it(bounds.GetOpenWires()); it.More(); it.Next()) ++report.openFreeChains;
  }
  report.openGaps = findOpenGaps(topology, tolerance, kGapSearch * modelSize);
  try {
    report.overlaps = findOverlaps(shape, tolerance, modelSize);
  } catch (const Standard_Failure& failure) {
    // The search is a report, not a repair: the shape still goes on, with a note.
    report.notes.push_back(std::string("overlapping faces not searched: OpenCASCADE failed (") +
                           failure.GetMessageString() + ")");
  }
}

}  // namespace

double automaticSewingTolerance(const TopoDS_Shape& shape) {
  if (shape.IsNull()) throw InvalidInputError("cannot size a sewing tolerance for a null shape");
  return translateOcctErrors("sizing the sewing tolerance", [&] {
    const double size = diagonalOf(shape);
    const double fileTolerance = ShapeAnalysis_ShapeTolerance().Tolerance(shape, 1, TopAbs_VERTEX);
    double tolerance = std::clamp(2.0 * fileTolerance, 2e-4 * size, 1e-3 * size);
    double shortest = std::numeric_limits<double>::infinity();
    for (TopExp_Explorer e(shape, TopAbs_EDGE); e.More(); e.Next()) {
      const double length = edgeLength(TopoDS::Edge(e.Current()));
      if (length > 1e-5 * size) shortest = std::min(shortest, length);
    }
    if (std::isfinite(shortest)) tolerance = std::min(tolerance, 0.5 * shortest);
    tolerance = std::max(tolerance, fileTolerance);
    return tolerance > 0.0 ? tolerance : Precision::Confusion();
  });
}

RepairedShape repairShape(const TopoDS_Shape& shape, const RepairOptions& options) {
  if (shape.IsNull()) throw InvalidInputError("cannot repair a null shape");
  if (!(options.tolerance >= 0.0) || !std::isfinite(options.tolerance))
    throw InvalidInputError("the sewing tolerance must be 0 (automatic) or positive, got " +
                            numberText(options.tolerance));
  return translateOcctErrors("repairing the shape", [&] {
    RepairedShape result{shape, {}};
    RepairReport& report = result.report;
    report.modelSize = diagonalOf(shape);
    report.fileTolerance = ShapeAnalysis_ShapeTolerance().Tolerance(shape, 1, TopAbs_VERTEX);
    report.tolerance = options.tolerance > 0.0 ? options.tolerance : automaticSewingTolerance(shape);
    const EdgeTopology before(shape);
    report.facesRead = before.faces.Extent();
    report.freeEdgesRead = before.free;

    if (options.sew && before.free > 0 && report.facesRead > 0) {
      report.sewingAttempted = true;
      // Default options: analysis of degenerate shapes, cutting of edges, manifold only (an
      // edge never gets a third face by sewing).
      BRepBuilderAPI_Sewing sewing(report.tolerance, true, true, true, false);
      for (int i = 1; i <= before.faces.Extent(); ++i) sewing.Add(before.faces(i));
      sewing.Perform();
      const TopoDS_Shape sewn = sewing.SewedShape();
      const EdgeTopology after(sewn.IsNull() ? emptyCompound() : sewn);
      std::string change;
      if (after.faces.Extent() == 0) {
        report.keptReason = "sewing gave no faces";
      } else if (after.shared <= before.shared) {
        report.keptReason = "no edges of different faces lie within the tolerance of each other";
      } else if (!(change = geometryChange(sewing, before.faces, report.tolerance)).empty()) {
        report.keptReason = change;
      } else {
        report.sewingApplied = true;
        report.gapsClosed = after.shared - before.shared;
        report.largestGapClosed = largestSewnDistance(sewing);
        // Sewing lists the edges it found degenerate, those that were already (a sphere's poles) too.
        for (int i = 1; i <= sewing.NbDegeneratedShapes(); ++i) {
          const TopoDS_Shape& degenerated = sewing.DegeneratedShape(i);
          if (degenerated.ShapeType() == TopAbs_EDGE && !BRep_Tool::Degenerated(TopoDS::Edge(degenerated)))
            ++report.degenerateEdgesRemoved;
        }
        for (int i = 1; i <= sewing.NbDeletedFaces(); ++i)
          report.facesRemoved.push_back(before.faces.FindIndex(sewing.DeletedFace(i)) - 1);
        result.shape = sewn;
        // A closed manifold shell: a solid, oriented outwards like the STEP of the same body.
        const TopoDS_Shape shell = loneShell(sewn);
        if (!shell.IsNull() && after.free == 0 && after.nonManifold == 0) {
          const TopoDS_Solid solid = ShapeFix_Solid().SolidFromShell(TopoDS::Shell(shell));
          if (!solid.IsNull()) {
            result.shape = solid;
            report.madeSolid = true;
          }
        }
      }
    }
    analyse(result.shape, report.tolerance, report.modelSize, report);
    return result;
  });
}

std::string encodeRepairReport(const RepairReport& r) {
  std::ostringstream out;
  out.precision(17);
  out << "sewing_attempted " << r.sewingAttempted << "\nsewing_applied " << r.sewingApplied
      << "\ntolerance " << r.tolerance << "\nfile_tolerance " << r.fileTolerance << "\nmodel_size " << r.modelSize
      << "\nfaces_read " << r.facesRead << "\nfaces " << r.faces << "\nfree_edges_read " << r.freeEdgesRead
      << "\ngaps_closed " << r.gapsClosed << "\nlargest_gap_closed " << r.largestGapClosed
      << "\ndegenerate_edges_removed " << r.degenerateEdgesRemoved << "\nfree_edges " << r.freeEdges
      << "\nnon_manifold_edges " << r.nonManifoldEdges << "\nclosed_free_loops " << r.closedFreeLoops
      << "\nopen_free_chains " << r.openFreeChains << "\nmade_solid " << r.madeSolid << "\n";
  for (int face : r.facesRemoved) out << "face_removed " << face << "\n";
  for (const FaceOverlap& o : r.overlaps)
    out << "overlap " << o.face << " " << o.otherFace << " " << o.area << " " << o.where[0] << " " << o.where[1] << " "
        << o.where[2] << "\n";
  for (const OpenGap& g : r.openGaps)
    out << "gap " << g.edge << " " << g.otherEdge << " " << g.face << " " << g.otherFace << " " << g.width << " "
        << g.where[0] << " " << g.where[1] << " " << g.where[2] << "\n";
  // Free text last on its line; line breaks inside would end it.
  auto oneLine = [](std::string text) {
    std::replace(text.begin(), text.end(), '\n', ' ');
    return text;
  };
  if (!r.keptReason.empty()) out << "kept_reason " << oneLine(r.keptReason) << "\n";
  for (const std::string& note : r.notes) out << "note " << oneLine(note) << "\n";
  return out.str();
}

RepairReport decodeRepairReport(const std::string& text) {
  RepairReport r;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string key;
    fields >> key;
    auto rest = [&] {
      std::string value;
      std::getline(fields, value);
      return value.empty() ? value : value.substr(1);
    };
    if (key == "sewing_attempted") fields >> r.sewingAttempted;
    else if (key == "sewing_applied") fields >> r.sewingApplied;
    else if (key == "tolerance") fields >> r.tolerance;
    else if (key == "file_tolerance") fields >> r.fileTolerance;
    else if (key == "model_size") fields >> r.modelSize;
    else if (key == "faces_read") fields >> r.facesRead;
    else if (key == "faces") fields >> r.faces;
    else if (key == "free_edges_read") fields >> r.freeEdgesRead;
    else if (key == "gaps_closed") fields >> r.gapsClosed;
    else if (key == "largest_gap_closed") fields >> r.largestGapClosed;
    else if (key == "degenerate_edges_removed") fields >> r.degenerateEdgesRemoved;
    else if (key == "free_edges") fields >> r.freeEdges;
    else if (key == "non_manifold_edges") fields >> r.nonManifoldEdges;
    else if (key == "closed_free_loops") fields >> r.closedFreeLoops;
    else if (key == "open_free_chains") fields >> r.openFreeChains;
    else if (key == "made_solid") fields >> r.madeSolid;
    else if (key == "face_removed") {
      int face = -1;
      fields >> face;
      r.facesRemoved.push_back(face);
    } else if (key == "gap") {
      OpenGap g;
      fields >> g.edge >> g.otherEdge >> g.face >> g.otherFace >> g.width >> g.where[0] >> g.where[1] >> g.where[2];
      r.openGaps.push_back(g);
    } else if (key == "overlap") {
      FaceOverlap o;
      fields >> o.face >> o.otherFace >> o.area >> o.where[0] >> o.where[1] >> o.where[2];
      r.overlaps.push_back(o);
    } else if (key == "kept_reason") r.keptReason = rest();
    else if (key == "note") r.notes.push_back(rest());
    else if (!key.empty()) throw InvalidInputError("repair report: unknown line \"" + line + "\"");
  }
  return r;
}

std::vector<std::string> describeRepair(const RepairReport& r) {
  auto number = [](double value) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.3g", value);
    return std::string(text);
  };
  auto relative = [&](double value) {
    return r.modelSize > 0.0 ? " (" + number(value / r.modelSize) + " of the model size)" : std::string();
  };
  std::vector<std::string> lines;
  if (r.watertight()) {
    lines.push_back("watertight: yes (every edge is shared by exactly two faces)");
  } else {
    std::string line = "watertight: no (" + std::to_string(r.freeEdges) + " free edges";
    if (r.freeEdges > 0)
      line += " in " + std::to_string(r.closedFreeLoops) + " closed loops and " + std::to_string(r.openFreeChains) +
              " open chains";
    if (r.nonManifoldEdges > 0) line += ", " + std::to_string(r.nonManifoldEdges) + " non-manifold edges";
    lines.push_back(line + ")");
  }
  const std::string at = "sewing at tolerance " + number(r.tolerance) + relative(r.tolerance);
  if (r.sewingApplied) {
    lines.push_back(at + ": " + std::to_string(r.gapsClosed) + " gaps closed, largest " + number(r.largestGapClosed) +
                    "; " + std::to_string(r.facesRead) + " faces read, " + std::to_string(r.faces) + " kept" +
                    (r.madeSolid ? ", closed into a solid" : ""));
  } else if (r.sewingAttempted) {
    lines.push_back(at + ": nothing sewn, the faces are kept as read (" + r.keptReason + ")");
  } else if (r.freeEdgesRead == 0) {
    lines.push_back("sewing: nothing to sew (the faces already share their edges)");
  } else {
    lines.push_back("sewing: off (" + std::to_string(r.freeEdgesRead) + " free edges as read)");
  }
  if (r.degenerateEdgesRemoved > 0 || !r.facesRemoved.empty()) {
    std::string line = "removed: " + std::to_string(r.degenerateEdgesRemoved) +
                       " edges shorter than the tolerance (collapsed to a point), " +
                       std::to_string(r.facesRemoved.size()) + " faces smaller than the tolerance";
    for (std::size_t i = 0; i < r.facesRemoved.size() && i < 10; ++i)
      line += (i == 0 ? " (as read: Face" : ", Face") + std::to_string(r.facesRemoved[i] + 1);
    if (!r.facesRemoved.empty()) line += r.facesRemoved.size() > 10 ? ", ...)" : ")";
    lines.push_back(line);
  }
  if (!r.openGaps.empty()) {
    lines.push_back("gaps left open: " + std::to_string(r.openGaps.size()) + " (wider than the tolerance, up to " +
                    number(kGapSearch * r.modelSize) + ")");
    for (std::size_t i = 0; i < r.openGaps.size() && i < 10; ++i) {
      const OpenGap& g = r.openGaps[i];
      lines.push_back("  Edge" + std::to_string(g.edge + 1) + " (Face" + std::to_string(g.face + 1) + ") to Edge" +
                      std::to_string(g.otherEdge + 1) + " (Face" + std::to_string(g.otherFace + 1) + "): width " +
                      number(g.width) + relative(g.width) + " at (" + number(g.where[0]) + ", " + number(g.where[1]) +
                      ", " + number(g.where[2]) + ")");
    }
    if (r.openGaps.size() > 10) lines.push_back("  ...");
  }
  if (!r.overlaps.empty()) {
    double total = 0.0;
    for (const FaceOverlap& o : r.overlaps) total += o.area;
    lines.push_back("overlapping faces: " + std::to_string(r.overlaps.size()) + " pairs (within the tolerance of " +
                    "each other over an area of " + number(total) + " in all)");
    for (std::size_t i = 0; i < r.overlaps.size() && i < 10; ++i) {
      const FaceOverlap& o = r.overlaps[i];
      lines.push_back("  Face" + std::to_string(o.face + 1) + " and Face" + std::to_string(o.otherFace + 1) +
                      ": area " + number(o.area) + " around (" + number(o.where[0]) + ", " + number(o.where[1]) +
                      ", " + number(o.where[2]) + ")");
    }
    if (r.overlaps.size() > 10) lines.push_back("  ...");
  }
  for (const std::string& note : r.notes) lines.push_back(note);
  return lines;
}

}  // namespace bvmesh::cad

#include "core/cad/solid_overlap.h"

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepClass3d_SolidClassifier.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <gp_Pnt.hxx>

#include <cmath>
#include <memory>

#include "core/common/occt_errors.h"

namespace bvmesh::cad {
namespace {

// Points on the solid's boundary: its vertices, its edges' and its faces' parametric middles.
std::vector<gp_Pnt> boundaryPoints(const TopoDS_Shape& solid) {
  std::vector<gp_Pnt> points;
  TopTools_IndexedMapOfShape vertices, edges, faces;
  TopExp::MapShapes(solid, TopAbs_VERTEX, vertices);
  TopExp::MapShapes(solid, TopAbs_EDGE, edges);
  TopExp::MapShapes(solid, TopAbs_FACE, faces);
  for (int i = 1; i <= vertices.Extent(); ++i) points.push_back(BRep_Tool::Pnt(TopoDS::Vertex(vertices(i))));
  for (int i = 1; i <= edges.Extent(); ++i) {
    const TopoDS_Edge& edge = TopoDS::Edge(edges(i));
    if (BRep_Tool::Degenerated(edge)) continue;
    const BRepAdaptor_Curve curve(edge);
    points.push_back(curve.Value(0.5 * (curve.FirstParameter() + curve.LastParameter())));
  }
  for (int i = 1; i <= faces.Extent(); ++i) {
    const TopoDS_Face& face = TopoDS::Face(faces(i));
    double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
    BRepTools::UVBounds(face, u0, u1, v0, v1);
    points.push_back(BRepAdaptor_Surface(face).Value(0.5 * (u0 + u1), 0.5 * (v0 + v1)));
  }
  return points;
}

// A point of `points` strictly inside the classifier's solid (farther inside than `tolerance`), or
// none. At most kMostPointsClassified of them, evenly spread, so that solids of many faces stay
// quick to check.
bool firstInside(BRepClass3d_SolidClassifier& classifier, const std::vector<gp_Pnt>& points, double tolerance,
                 gp_Pnt& inside) {
  constexpr std::size_t kMostPointsClassified = 2000;
  const std::size_t stride = points.size() / kMostPointsClassified + 1;
  for (std::size_t k = 0; k < points.size(); k += stride) {
    const gp_Pnt& p = points[k];
    classifier.Perform(p, tolerance);
    if (classifier.State() == TopAbs_IN) {
      inside = p;
      return true;
    }
  }
  return false;
}

}  // namespace

std::vector<SolidOverlap> overlappingSolids(const TopoDS_Shape& shape) {
  std::vector<SolidOverlap> overlaps;
  if (shape.IsNull()) return overlaps;
  TopTools_IndexedMapOfShape solids;
  TopExp::MapShapes(shape, TopAbs_SOLID, solids);
  if (solids.Extent() < 2 || solids.Extent() > kMostSolidsChecked) return overlaps;
  return translateOcctErrors("checking the solids for overlaps", [&] {
    std::vector<Bnd_Box> boxes(static_cast<std::size_t>(solids.Extent()));
    std::vector<std::vector<gp_Pnt>> points(boxes.size());
    std::vector<std::unique_ptr<BRepClass3d_SolidClassifier>> classifiers;  // one per solid, set up once
    Bnd_Box all;
    for (int i = 0; i < solids.Extent(); ++i) {
      BRepBndLib::Add(solids(i + 1), boxes[static_cast<std::size_t>(i)]);
      all.Add(boxes[static_cast<std::size_t>(i)]);
      points[static_cast<std::size_t>(i)] = boundaryPoints(solids(i + 1));
      classifiers.push_back(std::make_unique<BRepClass3d_SolidClassifier>(solids(i + 1)));
    }
    const double tolerance = 1e-7 * std::sqrt(all.SquareExtent());
    for (int i = 0; i < solids.Extent(); ++i) {
      for (int j = i + 1; j < solids.Extent(); ++j) {
        if (boxes[static_cast<std::size_t>(i)].IsOut(boxes[static_cast<std::size_t>(j)])) continue;
        gp_Pnt p;
        if (firstInside(*classifiers[static_cast<std::size_t>(i)], points[static_cast<std::size_t>(j)],
                        tolerance, p) ||
            firstInside(*classifiers[static_cast<std::size_t>(j)], points[static_cast<std::size_t>(i)],
                        tolerance, p))
          overlaps.push_back({i, j, {p.X(), p.Y(), p.Z()}});
      }
    }
    return overlaps;
  });
}

}  // namespace bvmesh::cad

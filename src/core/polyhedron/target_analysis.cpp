#include "core/polyhedron/target_analysis.h"

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepGProp.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <GProp_GProps.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Pln.hxx>

#include <Eigen/Eigenvalues>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/common/errors.h"
#include "core/common/occt_errors.h"

namespace bvmesh::polyhedron {
namespace {

// Unit eigenvectors of a symmetric 3x3 matrix as columns, eigenvalues decreasing.
std::pair<Eigen::Matrix3d, Eigen::Vector3d> sortedEigen(const Eigen::Matrix3d& covariance) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  Eigen::Matrix3d vectors;
  Eigen::Vector3d values;
  for (int k = 0; k < 3; ++k) {
    vectors.col(k) = solver.eigenvectors().col(2 - k);
    values[k] = solver.eigenvalues()[2 - k];
  }
  if (vectors.determinant() < 0) vectors.col(2) *= -1.0;  // right-handed
  return {vectors, values};
}

// Where two principal variances are equal (a square plate, a cube, a ring) the axes in their
// plane are any pair the eigen solver's rounding picks: a box placed on a 10 x 10 x 1 plate stood
// at some angle to it, its corners 0.82 off the plate's, and a nacelle's rings started at another
// angle on the same ring read from another file. Within such a plane the axes turn to line up
// with the surface normals: the angle maximising sum_t w_t ((n_t . a)^4 + (n_t . b)^4) over the
// triangles (area w_t, unit normal n_t), in closed form (the in-plane part r (cos phi, sin phi)
// of n_t contributes w_t r^4 (3 + cos 4 (phi - theta)) / 4). Where the normals have no such
// direction (a round section) the first axis becomes the model's x, y or z axis as projected
// into the plane (the first of those most in it). Returns whether the normals decided.
bool alignInPlane(Eigen::Matrix3d& axes, int a, int b, const target::Points& nodes,
                  const Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>& triangles) {
  double c = 0.0, s = 0.0, total = 0.0;
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const Eigen::Vector3d p = nodes.row(triangles(t, 0)).transpose();
    const Eigen::Vector3d n = (nodes.row(triangles(t, 1)).transpose() - p).cross(nodes.row(triangles(t, 2)).transpose() - p);
    const double w = 0.5 * n.norm();
    if (!(w > 0.0)) continue;
    const double x = n.dot(axes.col(a)) / (2.0 * w), y = n.dot(axes.col(b)) / (2.0 * w);
    const double r2 = x * x + y * y;
    const double phi = std::atan2(y, x);
    c += w * r2 * r2 * std::cos(4.0 * phi);
    s += w * r2 * r2 * std::sin(4.0 * phi);
    total += w * r2 * r2;
  }
  const bool byNormals = std::hypot(c, s) > 0.1 * total;
  double theta = 0.25 * std::atan2(s, c);
  if (!byNormals) {
    Eigen::Vector2d inPlane[3];
    double most = 0.0;
    for (int k = 0; k < 3; ++k) {
      inPlane[k] = Eigen::Vector2d(axes(k, a), axes(k, b));  // world axis k in the plane's coordinates
      most = std::max(most, inPlane[k].norm());
    }
    int k = 0;
    while (inPlane[k].norm() < most - 1e-3) ++k;
    theta = std::atan2(inPlane[k].y(), inPlane[k].x());
  }
  const Eigen::Vector3d u = std::cos(theta) * axes.col(a) + std::sin(theta) * axes.col(b);
  const Eigen::Vector3d v = -std::sin(theta) * axes.col(a) + std::cos(theta) * axes.col(b);
  axes.col(a) = u;
  axes.col(b) = v;
  return byNormals && std::abs(theta) > 1e-12;
}

}  // namespace

PrincipalFrame principalFrame(const target::Target& target) {
  const target::Points& nodes = target.meshNodes();
  const auto& triangles = target.meshTriangles();
  if (triangles.rows() == 0)
    throw InvalidInputError("the target has no tessellated faces to place a template on");
  double area = 0.0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const Eigen::Vector3d a = nodes.row(triangles(t, 0)).transpose();
    const Eigen::Vector3d b = nodes.row(triangles(t, 1)).transpose();
    const Eigen::Vector3d c = nodes.row(triangles(t, 2)).transpose();
    const double w = 0.5 * (b - a).cross(c - a).norm();
    // Exact second moment of a triangle: (sum of outer products of vertices + 9 g g^T) / 12.
    const Eigen::Vector3d g = (a + b + c) / 3.0;
    area += w;
    centre += w * g;
    second +=
        w * (a * a.transpose() + b * b.transpose() + c * c.transpose() + 9.0 * g * g.transpose()) / 12.0;
  }
  if (!(area > 0.0))
    throw InvalidInputError("the target's tessellation has zero area: nothing to place a template on");
  PrincipalFrame frame;
  frame.centre = centre / area;
  const Eigen::Matrix3d covariance = second / area - frame.centre * frame.centre.transpose();
  std::tie(frame.axes, frame.variances) = sortedEigen(covariance);
  // Equal variances (within 1e-3 of the largest) leave the axes in their plane undetermined.
  const double equal = 1e-3 * frame.variances[0];
  const bool equal01 = frame.variances[0] - frame.variances[1] <= equal;
  const bool equal12 = frame.variances[1] - frame.variances[2] <= equal;
  if (equal01 && equal12) {
    // All three (a cube): turn plane by plane, as Jacobi sweeps, until no plane turns; with no
    // direction in the normals at all (a sphere) the model's own axes.
    bool decided = false;
    for (int sweep = 0; sweep < 16; ++sweep) {
      bool turned = false;
      for (const auto& [a, b] : {std::pair{0, 1}, std::pair{0, 2}, std::pair{1, 2}})
        turned = alignInPlane(frame.axes, a, b, nodes, triangles) || turned;
      decided = decided || turned;
      if (!turned) break;
    }
    if (!decided) frame.axes.setIdentity();
  } else if (equal01) {
    alignInPlane(frame.axes, 0, 1, nodes, triangles);
  } else if (equal12) {
    alignInPlane(frame.axes, 1, 2, nodes, triangles);
  }
  frame.low.setConstant(std::numeric_limits<double>::infinity());
  frame.high.setConstant(-std::numeric_limits<double>::infinity());
  for (Eigen::Index n = 0; n < nodes.rows(); ++n) {
    const Eigen::Vector3d local = frame.axes.transpose() * (nodes.row(n).transpose() - frame.centre);
    frame.low = frame.low.cwiseMin(local);
    frame.high = frame.high.cwiseMax(local);
  }
  return frame;
}

PlaneSection::PlaneSection(const target::Target& target, const Eigen::Vector3d& planePoint,
                           const Eigen::Vector3d& planeNormal) {
  const target::Points& nodes = target.meshNodes();
  const auto& triangles = target.meshTriangles();
  const Eigen::Vector3d n = planeNormal.normalized();
  normal_ = n;
  Eigen::VectorXd side(nodes.rows());
  for (Eigen::Index k = 0; k < nodes.rows(); ++k) side[k] = (nodes.row(k).transpose() - planePoint).dot(n);
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    std::vector<Eigen::Vector3d> crossings;
    for (int k = 0; k < 3; ++k) {
      const int i = triangles(t, k);
      const int j = triangles(t, (k + 1) % 3);
      const double di = side[i];
      const double dj = side[j];
      // Nodes exactly on the plane count as above it, so each crossing is found once.
      if ((di < 0.0) == (dj < 0.0)) continue;
      const double s = di / (di - dj);
      crossings.push_back(nodes.row(i).transpose() + s * (nodes.row(j) - nodes.row(i)).transpose());
    }
    if (crossings.size() == 2) segments_.emplace_back(crossings[0], crossings[1]);
  }
  points_.resize(2 * static_cast<Eigen::Index>(segments_.size()), 3);
  for (size_t k = 0; k < segments_.size(); ++k) {
    points_.row(2 * static_cast<Eigen::Index>(k)) = segments_[k].first.transpose();
    points_.row(2 * static_cast<Eigen::Index>(k) + 1) = segments_[k].second.transpose();
  }
}

std::vector<double> PlaneSection::lineHits(const Eigen::Vector3d& origin,
                                           const Eigen::Vector3d& direction) const {
  std::vector<double> hits;
  const double length2 = direction.squaredNorm();
  if (!(length2 > 0.0) || segments_.empty()) return hits;
  const Eigen::Vector3d across = normal_.cross(direction).normalized();
  for (const auto& [a, b] : segments_) {
    const double wa = (a - origin).dot(across);
    const double wb = (b - origin).dot(across);
    if ((wa < 0.0) == (wb < 0.0)) continue;
    const double t = wa / (wa - wb);
    const Eigen::Vector3d p = a + t * (b - a);
    hits.push_back((p - origin).dot(direction) / length2);
  }
  std::sort(hits.begin(), hits.end());
  return hits;
}

std::optional<fit::SymmetryPlane> detectSymmetryPlane(const target::Target& target,
                                                      const std::vector<FeatureCurve>& curves,
                                                      double relativeFlatness) {
  const double diagonal = target.report().diagonal;
  const target::Points& nodes = target.meshNodes();
  const auto planeThrough = [&](const target::Points& points) -> std::optional<fit::SymmetryPlane> {
    if (points.rows() < 3) return std::nullopt;
    const Eigen::Vector3d centre = points.colwise().mean().transpose();
    const Eigen::MatrixXd centred = points.rowwise() - centre.transpose();
    const auto [vectors, values] =
        sortedEigen(centred.transpose() * centred / static_cast<double>(points.rows()));
    if (!(values[1] > 1e-6 * values[0])) return std::nullopt;  // a straight line spans no plane
    Eigen::Vector3d normal = vectors.col(2);
    const Eigen::VectorXd offsets = centred * normal;
    if (offsets.cwiseAbs().maxCoeff() > relativeFlatness * diagonal) return std::nullopt;
    // The whole target on one side (within the tessellation's deflection).
    const Eigen::VectorXd sides = (nodes.rowwise() - centre.transpose()) * normal;
    const double slack = 2.0 * target.report().deflection;
    if (sides.minCoeff() < -slack && sides.maxCoeff() > slack) return std::nullopt;
    if (sides.sum() < 0.0) normal = -normal;
    fit::SymmetryPlane plane;
    plane.point = centre;
    plane.normal = normal;
    return plane;
  };
  std::vector<target::Points> boundaries;
  for (const FeatureCurve& curve : curves) {  // boundary curves come longest first
    if (curve.kind != FeatureCurveKind::Boundary) continue;
    boundaries.push_back(curvePolyline(target, curve));
    if (auto plane = planeThrough(boundaries.back())) return plane;
  }
  // A boundary of straight curves only (a half cylinder's: its two sides and the ends' diameters)
  // spans its plane together.
  Eigen::Index rows = 0;
  for (const target::Points& points : boundaries) rows += points.rows();
  target::Points all(rows, 3);
  rows = 0;
  for (const target::Points& points : boundaries) {
    all.middleRows(rows, points.rows()) = points;
    rows += points.rows();
  }
  return planeThrough(all);
}

HalfModelShape removeSymmetryFace(const TopoDS_Shape& shape, double relativeFlatness) {
  if (shape.IsNull()) throw InvalidInputError("removeSymmetryFace: the shape is null");
  return translateOcctErrors("removeSymmetryFace", [&] {
    TopTools_IndexedMapOfShape faces, vertices, edges;
    TopExp::MapShapes(shape, TopAbs_FACE, faces);
    TopExp::MapShapes(shape, TopAbs_VERTEX, vertices);
    TopExp::MapShapes(shape, TopAbs_EDGE, edges);
    // Points of the shape: its vertices and samples along its edges.
    std::vector<Eigen::Vector3d> points;
    for (int i = 1; i <= vertices.Extent(); ++i) {
      const gp_Pnt p = BRep_Tool::Pnt(TopoDS::Vertex(vertices(i)));
      points.emplace_back(p.X(), p.Y(), p.Z());
    }
    for (int i = 1; i <= edges.Extent(); ++i) {
      const TopoDS_Edge& edge = TopoDS::Edge(edges(i));
      if (BRep_Tool::Degenerated(edge)) continue;
      const BRepAdaptor_Curve curve(edge);
      for (int k = 1; k < 16; ++k) {
        const gp_Pnt p =
            curve.Value(curve.FirstParameter() + k * (curve.LastParameter() - curve.FirstParameter()) / 16.0);
        points.emplace_back(p.X(), p.Y(), p.Z());
      }
    }
    Eigen::AlignedBox3d box;
    for (const Eigen::Vector3d& p : points) box.extend(p);
    const double tolerance = relativeFlatness * box.diagonal().norm();
    HalfModelShape result;
    double bestArea = 0.0;
    double bestAlignment = 0.0;
    for (int i = 1; i <= faces.Extent(); ++i) {
      const TopoDS_Face& face = TopoDS::Face(faces(i));
      const BRepAdaptor_Surface surface(face);
      if (surface.GetType() != GeomAbs_Plane) continue;
      const gp_Pln plane = surface.Plane();
      const Eigen::Vector3d origin(plane.Location().X(), plane.Location().Y(), plane.Location().Z());
      Eigen::Vector3d normal(plane.Axis().Direction().X(), plane.Axis().Direction().Y(),
                             plane.Axis().Direction().Z());
      double low = 0.0, high = 0.0;
      for (const Eigen::Vector3d& p : points) {
        const double d = (p - origin).dot(normal);
        low = std::min(low, d);
        high = std::max(high, d);
      }
      if (low < -tolerance && high > tolerance) continue;
      if (high <= tolerance) normal = -normal;
      GProp_GProps properties;
      BRepGProp::SurfaceProperties(face, properties);
      const double area = properties.Mass();
      // Among faces of about the same area, the one facing +-y (the aircraft convention) wins.
      const double alignment = std::abs(normal.y());
      const bool clearlyLarger = area > 1.05 * bestArea;
      const bool aboutEqual = area > bestArea / 1.05;
      if (result.face < 0 || clearlyLarger || (aboutEqual && alignment > bestAlignment)) {
        result.face = i - 1;
        result.plane.point = origin;
        result.plane.normal = normal;
        bestArea = area;
        bestAlignment = alignment;
      }
    }
    if (result.face < 0) {
      throw InvalidInputError(
          "removeSymmetryFace: no planar face has the whole shape on one side of its plane");
    }
    std::vector<int> others;
    for (int i = 0; i < faces.Extent(); ++i) {
      if (i != result.face) others.push_back(i);
    }
    result.shape = selectFaces(shape, others);
    return result;
  });
}

TopoDS_Shape selectFaces(const TopoDS_Shape& shape, const std::vector<int>& faces) {
  TopTools_IndexedMapOfShape map;
  TopExp::MapShapes(shape, TopAbs_FACE, map);
  BRep_Builder builder;
  TopoDS_Compound compound;
  builder.MakeCompound(compound);
  for (int f : faces) {
    if (f < 0 || f >= map.Extent()) {
      throw InvalidInputError("selectFaces: face " + std::to_string(f) + " does not exist (" +
                              std::to_string(map.Extent()) + " faces)");
    }
    builder.Add(compound, map(f + 1));
  }
  return compound;
}

}  // namespace bvmesh::polyhedron

#include "core/polyhedron/flow_domain.h"

#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Poly_Triangulation.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopLoc_Location.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Pln.hxx>
#include <gp_Sphere.hxx>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>

#include "core/common/errors.h"
#include "core/common/number_text.h"
#include "core/common/occt_errors.h"

namespace bvmesh::polyhedron {
namespace {

Eigen::Vector3d toEigen(const gp_XYZ& p) { return {p.X(), p.Y(), p.Z()}; }

constexpr int kSamplesPerFace = 64;
// A box or sphere domain has a handful of faces (a sphere may come in patches).
constexpr size_t kMaxOuterFaces = 64;

// A face's samples: its tessellation's nodes (inside the face whatever its trimming) with the
// surface normal at each.
struct FaceSamples {
  std::vector<Eigen::Vector3d> points, normals;
};

FaceSamples sampleFace(const TopoDS_Face& face) {
  FaceSamples samples;
  TopLoc_Location location;
  const Handle(Poly_Triangulation) triangulation = BRep_Tool::Triangulation(face, location);
  if (triangulation.IsNull()) return samples;
  const BRepAdaptor_Surface surface(face);
  const int nodes = triangulation->NbNodes();
  const bool hasUV = triangulation->HasUVNodes();
  // At most about kSamplesPerFace nodes, spread over the face: the test compares every sample with
  // every other, so a CAD of thousands of faces must stay at a fraction of a second.
  const int stride = std::max(1, nodes / kSamplesPerFace);
  for (int i = 1; i <= nodes; i += stride) {
    const gp_Pnt node = triangulation->Node(i).Transformed(location.Transformation());
    samples.points.push_back(toEigen(node.XYZ()));
    if (!hasUV) continue;
    const gp_Pnt2d uv = triangulation->UVNode(i);
    gp_Pnt p;
    gp_Vec du, dv;
    surface.D1(uv.X(), uv.Y(), p, du, dv);
    const gp_Vec normal = du.Crossed(dv);
    if (normal.Magnitude() > 0.0) samples.normals.push_back(toEigen(normal.Normalized().XYZ()));
    else samples.points.pop_back();  // a pole of the parametrisation: no tangent plane there
  }
  if (!hasUV) samples.points.clear();
  return samples;
}

std::string surfaceTypeName(GeomAbs_SurfaceType type) {
  switch (type) {
    case GeomAbs_Plane: return "plane";
    case GeomAbs_Cylinder: return "cylinder";
    case GeomAbs_Cone: return "cone";
    case GeomAbs_Sphere: return "sphere";
    case GeomAbs_Torus: return "torus";
    case GeomAbs_BezierSurface: return "Bezier surface";
    case GeomAbs_BSplineSurface: return "B-spline surface";
    case GeomAbs_SurfaceOfRevolution: return "surface of revolution";
    case GeomAbs_SurfaceOfExtrusion: return "surface of extrusion";
    case GeomAbs_OffsetSurface: return "offset surface";
    default: return "surface";
  }
}

Eigen::Vector3d meanOf(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) sum += p;
  return sum / static_cast<double>(points.size());
}

struct Plane {
  Eigen::Vector3d point, normal;
};

// The plane all points lie on within `tolerance` (their least-squares plane), if any.
std::optional<Plane> planeThrough(const std::vector<Eigen::Vector3d>& points, double tolerance) {
  if (points.size() < 3) return std::nullopt;
  const Eigen::Vector3d mean = meanOf(points);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) covariance += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  const Eigen::Vector3d normal = solver.eigenvectors().col(0);
  for (const Eigen::Vector3d& p : points) {
    if (std::abs(normal.dot(p - mean)) > tolerance) return std::nullopt;
  }
  return Plane{mean, normal};
}

struct Sphere {
  Eigen::Vector3d centre;
  double radius = 0.0;
};

// The sphere all points lie on within `tolerance`, if any: |x|^2 = 2 c.x + (r^2 - |c|^2) is linear
// in c and the constant, solved in the least-squares sense about the points' mean.
std::optional<Sphere> sphereThrough(const std::vector<Eigen::Vector3d>& points, double tolerance) {
  if (points.size() < 4) return std::nullopt;
  const Eigen::Vector3d mean = meanOf(points);
  const Eigen::Index n = static_cast<Eigen::Index>(points.size());
  Eigen::MatrixXd a(n, 4);
  Eigen::VectorXd b(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d x = points[static_cast<size_t>(i)] - mean;
    a.row(i) << 2.0 * x.transpose(), 1.0;
    b[i] = x.squaredNorm();
  }
  const Eigen::Vector4d solution = a.colPivHouseholderQr().solve(b);
  const Eigen::Vector3d centre = solution.head<3>();
  const double squared = solution[3] + centre.squaredNorm();
  if (!(squared > 0.0) || !centre.allFinite()) return std::nullopt;
  const Sphere sphere{centre + mean, std::sqrt(squared)};
  for (const Eigen::Vector3d& p : points) {
    if (std::abs((p - sphere.centre).norm() - sphere.radius) > tolerance) return std::nullopt;
  }
  return sphere;
}

std::string faceText(int face) { return "face " + std::to_string(face) + " (FreeCAD's Face" + std::to_string(face + 1) + ")"; }

}  // namespace

FlowDomain splitFlowDomain(const TopoDS_Shape& shape) {
  if (shape.IsNull()) throw InvalidInputError("splitFlowDomain: the shape is null");
  return translateOcctErrors("splitFlowDomain", [&] {
    TopTools_IndexedMapOfShape faces;
    TopExp::MapShapes(shape, TopAbs_FACE, faces);
    if (faces.Extent() == 0) throw InvalidInputError("splitFlowDomain: the shape has no faces");
    Bnd_Box bounds;
    BRepBndLib::Add(shape, bounds);
    const double diagonal = std::sqrt(bounds.SquareExtent());
    // Coarse: the nodes serve as samples of where the shape is, not as a surface.
    BRepMesh_IncrementalMesh mesher(shape, 0.01 * diagonal, false, 0.5, true);
    std::vector<FaceSamples> samples;
    std::vector<Eigen::Vector3d> cloud;
    for (int i = 1; i <= faces.Extent(); ++i) {
      samples.push_back(sampleFace(TopoDS::Face(faces(i))));
      cloud.insert(cloud.end(), samples.back().points.begin(), samples.back().points.end());
    }
    // In a fixed shuffled order, a body face meets points on both sides of its plane within a few
    // samples; only the domain's few faces need the whole cloud.
    std::shuffle(cloud.begin(), cloud.end(), std::mt19937(12345));
    const double tolerance = 1e-6 * diagonal;
    // Whether the whole shape lies on one side of the plane through p with normal n.
    const auto supporting = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
      double low = 0.0, high = 0.0;
      for (const Eigen::Vector3d& x : cloud) {
        const double d = n.dot(x - p);
        low = std::min(low, d);
        high = std::max(high, d);
        if (low < -tolerance && high > tolerance) return false;
      }
      return true;
    };
    FlowDomain domain;
    for (int f = 0; f < faces.Extent(); ++f) {
      const FaceSamples& face = samples[static_cast<size_t>(f)];
      bool outer = !face.points.empty();
      for (size_t k = 0; k < face.points.size() && outer; ++k) outer = supporting(face.points[k], face.normals[k]);
      (outer ? domain.outerFaces : domain.bodyFaces).push_back(f);
      if (domain.outerFaces.size() > kMaxOuterFaces) {
        throw InvalidInputError("splitFlowDomain: more than " + std::to_string(kMaxOuterFaces) +
                                " faces bound the shape's convex hull: a body alone, not a flow domain (whose "
                                "boundary is a box or a sphere)");
      }
    }
    if (domain.bodyFaces.empty()) {
      throw InvalidInputError("splitFlowDomain: every face bounds the shape's convex hull, so no body lies inside a "
                              "domain (a convex body alone? use it as the target directly)");
    }
    if (domain.outerFaces.empty()) throw InvalidInputError("splitFlowDomain: no face bounds the shape: not a flow domain");

    // The body's points, to find the outer face its root lies on: its samples and its vertices
    // (a root loop's corners, whatever samples the stride kept).
    std::vector<Eigen::Vector3d> body;
    for (int f : domain.bodyFaces) {
      const FaceSamples& face = samples[static_cast<size_t>(f)];
      body.insert(body.end(), face.points.begin(), face.points.end());
      for (TopExp_Explorer vertex(faces(f + 1), TopAbs_VERTEX); vertex.More(); vertex.Next()) {
        body.push_back(toEigen(BRep_Tool::Pnt(TopoDS::Vertex(vertex.Current())).XYZ()));
      }
    }
    Eigen::Vector3d low = Eigen::Vector3d::Constant(HUGE_VAL), high = -low;
    std::optional<Sphere> sphere;
    std::vector<std::pair<int, Plane>> planes;
    for (int f : domain.outerFaces) {
      const std::vector<Eigen::Vector3d>& points = samples[static_cast<size_t>(f)].points;
      for (const Eigen::Vector3d& p : points) {
        low = low.cwiseMin(p);
        high = high.cwiseMax(p);
      }
      // Exact where the surface says what it is; else by the samples, since a file may carry a
      // plane or a sphere as a B-spline or a surface of revolution (IGES does).
      const BRepAdaptor_Surface surface(TopoDS::Face(faces(f + 1)));
      if (surface.GetType() == GeomAbs_Plane) {
        const gp_Pln plane = surface.Plane();
        planes.emplace_back(f, Plane{toEigen(plane.Location().XYZ()), toEigen(plane.Axis().Direction().XYZ())});
        continue;
      }
      if (surface.GetType() != GeomAbs_Sphere) {
        if (const std::optional<Plane> plane = planeThrough(points, tolerance)) {
          planes.emplace_back(f, *plane);
          continue;
        }
      }
      const std::optional<Sphere> mine = surface.GetType() == GeomAbs_Sphere
                                             ? Sphere{toEigen(surface.Sphere().Location().XYZ()), surface.Sphere().Radius()}
                                             : sphereThrough(points, tolerance);
      if (!mine) {
        throw InvalidInputError("splitFlowDomain: " + faceText(f) + " bounds the domain but is neither a plane nor a "
                                "sphere (a " + surfaceTypeName(surface.GetType()) +
                                "): only box and sphere domains are recognised");
      }
      if (sphere && (std::abs(mine->radius - sphere->radius) > tolerance || (mine->centre - sphere->centre).norm() > tolerance)) {
        throw InvalidInputError("splitFlowDomain: the domain's spheres differ (" + faceText(f) +
                                " has radius " + numberText(mine->radius) + ", another " +
                                numberText(sphere->radius) + ")");
      }
      sphere = mine;
    }
    std::vector<std::pair<int, Plane>> touched;
    for (const auto& [f, plane] : planes) {
      const auto onPlane = std::count_if(body.begin(), body.end(), [&](const Eigen::Vector3d& p) {
        return std::abs(plane.normal.dot(p - plane.point)) <= tolerance;
      });
      if (onPlane >= 2) touched.emplace_back(f, plane);
    }
    if (touched.size() > 2) {
      throw InvalidInputError("splitFlowDomain: the body touches the domain on " +
                              faceText(touched[0].first) + ", " + faceText(touched[1].first) + " and " +
                              faceText(touched[2].first) +
                              ": a body lies on one symmetry plane and runs into at most one outflow plane");
    }
    if (touched.size() == 2) {
      if (!sphere) {
        throw InvalidInputError(
            "splitFlowDomain: the body touches the box on " + faceText(touched[0].first) + " and " +
            faceText(touched[1].first) +
            ": a body that runs into the outflow boundary (a sting) needs a sphere domain");
      }
      if (std::abs(touched[0].second.normal.dot(touched[1].second.normal)) > 1e-6) {
        throw InvalidInputError("splitFlowDomain: the body touches " + faceText(touched[0].first) + " and " +
                                faceText(touched[1].first) + ", which are not perpendicular");
      }
      // The symmetry plane holds the body's profile, the outflow plane a section of it.
      std::array<double, 2> width{0.0, 0.0};
      for (size_t k = 0; k < 2; ++k) {
        const Plane& plane = touched[k].second;
        Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL), hi = -lo;
        for (const Eigen::Vector3d& p : body) {
          if (std::abs(plane.normal.dot(p - plane.point)) > tolerance) continue;
          lo = lo.cwiseMin(p);
          hi = hi.cwiseMax(p);
        }
        width[k] = (hi - lo).norm();
      }
      if (std::max(width[0], width[1]) < 1.5 * std::min(width[0], width[1])) {
        throw InvalidInputError(
            "splitFlowDomain: the body touches " + faceText(touched[0].first) + " and " +
            faceText(touched[1].first) + " over similar widths (" + numberText(width[0]) + " and " +
            numberText(width[1]) +
            "): which one is the symmetry plane and which the outflow plane is not clear");
      }
      if (width[1] > width[0]) std::swap(touched[0], touched[1]);
    }
    // Towards the domain: the side the body lies on; the point: the body's mean on the plane.
    const auto planeTowardsBody = [&](const Plane& plane) {
      fit::SymmetryPlane result;
      result.normal = plane.normal;
      const Eigen::Vector3d mean = meanOf(body);
      const double side = result.normal.dot(mean - plane.point);
      result.point = mean - side * result.normal;
      if (side < 0.0) result.normal = -result.normal;
      return result;
    };
    if (!touched.empty()) {
      domain.symmetryFace = touched[0].first;
      domain.symmetryPlane = planeTowardsBody(touched[0].second);
    }
    if (touched.size() == 2) {
      domain.outflowFace = touched[1].first;
      domain.outflowPlane = planeTowardsBody(touched[1].second);
    }

    const auto onSymmetryPlane = [&](const Eigen::Vector3d& p) {
      if (!domain.symmetryPlane) return p;
      return Eigen::Vector3d(p - (p - domain.symmetryPlane->point).dot(domain.symmetryPlane->normal) * domain.symmetryPlane->normal);
    };
    if (sphere) {
      domain.shape = "sphere";
      domain.centre = onSymmetryPlane(sphere->centre);
      domain.radius = sphere->radius;
      if ((domain.centre - sphere->centre).norm() > tolerance) {
        throw InvalidInputError("splitFlowDomain: the far-field sphere's centre is off the symmetry plane of " +
                                faceText(domain.symmetryFace) + ": not a half sphere");
      }
      if (domain.outflowPlane &&
          std::abs((domain.centre - domain.outflowPlane->point).dot(domain.outflowPlane->normal)) >
              tolerance) {
        throw InvalidInputError(
            "splitFlowDomain: the far-field sphere's centre is off the outflow plane of " +
            faceText(domain.outflowFace) + ", which the body runs into");
      }
      return domain;
    }
    domain.shape = "box";
    for (const auto& [f, plane] : planes) {
      if (plane.normal.cwiseAbs().maxCoeff() < 1.0 - 1e-9) {
        throw InvalidInputError("splitFlowDomain: " + faceText(f) +
                                " bounds the domain but is not normal to the x, y or z axis: only axis-aligned "
                                "boxes are recognised");
      }
    }
    domain.centre = 0.5 * (low + high);
    domain.halfExtent = 0.5 * (high - low);
    if (domain.symmetryPlane) {
      // The half box: centred on the plane, reaching as far from it as the domain does.
      Eigen::Index axis = 0;
      domain.symmetryPlane->normal.cwiseAbs().maxCoeff(&axis);
      domain.centre = onSymmetryPlane(domain.centre);
      domain.halfExtent[axis] = high[axis] - low[axis];
    }
    return domain;
  });
}

}  // namespace bvmesh::polyhedron

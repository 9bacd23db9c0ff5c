#include "core/volume/volume_options.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "core/common/errors.h"
#include "core/common/input_checks.h"
#include "core/common/math_constants.h"
#include "core/common/number_text.h"

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

// Volume enclosed by the front (with the symmetry plane closing a half model): negative when the
// wall is oriented inwards.
double enclosedVolume(const MarchingFront& front, const Vector3d& origin) {
  double volume = 0.0;
  for (const auto& q : front.quads) {
    const Vector3d a = front.points.row(q[0]).transpose() - origin, b = front.points.row(q[1]).transpose() - origin;
    const Vector3d c = front.points.row(q[2]).transpose() - origin, d = front.points.row(q[3]).transpose() - origin;
    volume += (a.dot(b.cross(c)) + a.dot(c.cross(d))) / 6.0;
  }
  return volume;
}

}  // namespace

Vector3d symmetryPlaneNormal(const VolumeMeshOptions& options) {
  const Vector3d normal = options.planeNormal.normalized();
  if (options.hasSymmetryPlane && !(options.planeNormal.norm() > 0 && options.planePoint.allFinite() && normal.allFinite())) {
    throw InvalidInputError("the symmetry plane needs a finite point and a non-zero normal");
  }
  return normal;
}

BoundaryPlanes boundaryPlanesOf(const VolumeMeshOptions& options) {
  BoundaryPlanes planes;
  planes.point[0] = options.planePoint;
  planes.normal[0] = symmetryPlaneNormal(options);
  if (!options.hasOutflowPlane) return planes;
  const Vector3d normal = options.outflowNormal.normalized();
  if (!(options.outflowNormal.norm() > 0 && options.outflowPoint.allFinite() && normal.allFinite())) {
    throw InvalidInputError("the outflow plane needs a finite point and a non-zero normal");
  }
  // Mirror images in both planes close a ring only when they commute.
  if (options.hasSymmetryPlane && std::abs(normal.dot(planes.normal[0])) > 1e-9) {
    throw InvalidInputError(
        "the outflow plane must be perpendicular to the symmetry plane (they meet at " +
        numberText(std::acos(std::clamp(std::abs(normal.dot(planes.normal[0])), 0.0, 1.0)) * 180.0 / kPi) +
        " degrees)");
  }
  planes.point[1] = options.outflowPoint;
  planes.normal[1] = normal;
  return planes;
}

size_t openSidePlane(const VolumeMeshOptions& options, const BoundaryPlanes& planes,
                     const std::vector<Vector3d>& points, double tolerance, const std::string& where) {
  const std::array<bool, 2> given{options.hasSymmetryPlane, options.hasOutflowPlane};
  if (!given[0] && !given[1]) {
    throw InvalidInputError("the wall is open at " + where +
                            ": close it, or give the symmetry plane it lies on (a half model) or the outflow "
                            "plane it runs into");
  }
  std::array<double, 2> off{0.0, 0.0};
  for (const Vector3d& x : points) {
    for (size_t k = 0; k < 2; ++k)
      off[k] = std::max(off[k], std::abs((x - planes.point[k]).dot(planes.normal[k])));
  }
  const size_t k = !given[1] || (given[0] && off[0] <= off[1]) ? 0 : 1;
  if (off[k] > tolerance) {
    throw InvalidInputError("the wall's open boundary at " + where + " lies " + numberText(off[k]) +
                            " off the " + kBoundaryPlaneNames[k] +
                            (given[1] ? ""
                                      : " (a wall that runs into the domain's outflow boundary needs that "
                                        "outflow plane given)"));
  }
  return k;
}

double flatPlateBoundaryLayerThickness(double reynoldsNumber, double length) {
  if (!(std::isfinite(reynoldsNumber) && reynoldsNumber > 0.0 && std::isfinite(length) && length > 0.0)) {
    throw InvalidInputError(
        "the flat-plate boundary-layer estimate needs a Reynolds number and a length > 0, got " +
        numberText(reynoldsNumber) + " and " + numberText(length));
  }
  return 0.37 * length * std::pow(reynoldsNumber, -0.2);
}

ResolvedVolumeOptions resolveVolumeOptions(const VolumeMeshOptions& options, const MarchingFront& front) {
  const BoundaryPlanes planes = boundaryPlanesOf(options);
  const unsigned planeBits =
      (options.hasSymmetryPlane ? kSymmetryPlaneBit : 0u) | (options.hasOutflowPlane ? kOutflowPlaneBit : 0u);
  const Vector3d lo = front.points.colwise().minCoeff().transpose();
  const Vector3d hi = front.points.colwise().maxCoeff().transpose();
  ResolvedVolumeOptions result;
  // On the planes, which then close the wall for the enclosed volume's sign.
  Vector3d centre = planes.onto(0.5 * (lo + hi), planeBits);
  if (enclosedVolume(front, centre) <= 0.0) {
    throw InvalidInputError("the wall surface is oriented inwards (its faces' normals point into the body): "
                            "reverse the order of every face's vertices");
  }

  const Vector3d extent = hi - lo;
  checkFiniteAtLeast(options.referenceLength, 0.0, "reference length (0: the default)");
  checkFiniteAtLeast(options.boundaryLayerThickness, 0.0, "boundary-layer thickness (0: the default)");
  checkFiniteAtLeast(options.farfieldDistance, 0.0, "far-field distance (0: the default)");
  // Every layer keeps a copy of the front: the bound keeps a mistyped count from marching for
  // hours into all of memory (the M6 takes 31 layers).
  if (options.maxLayers < 2 || options.maxLayers > kMaxControlLayers) {
    throw InvalidInputError("max_layers must be in [2, " + std::to_string(kMaxControlLayers) + "], got " +
                            std::to_string(options.maxLayers));
  }
  if (options.maxLayerPoints < 0) {
    throw InvalidInputError("max_layer_points must be 0 (no limit) or more, got " +
                            std::to_string(options.maxLayerPoints));
  }
  if (!(options.reynoldsNumber >= 1e3 && options.reynoldsNumber <= 1e10)) {
    throw InvalidInputError("Reynolds number must be in [1e3, 1e10], got " +
                            numberText(options.reynoldsNumber));
  }
  result.referenceLength = options.referenceLength > 0 ? options.referenceLength : extent.maxCoeff();
  result.boundaryLayerThickness =
      options.boundaryLayerThickness > 0
          ? options.boundaryLayerThickness
          : flatPlateBoundaryLayerThickness(options.reynoldsNumber, result.referenceLength);
  result.farfieldDistance = options.farfieldDistance > 0 ? options.farfieldDistance : 20.0 * result.referenceLength;
  if (options.domainCentre) {
    const Vector3d& asked = *options.domainCentre;
    if (!asked.allFinite()) throw InvalidInputError("the domain centre must be a finite point");
    for (size_t k = 0; k < 2; ++k) {
      const double off = (asked - planes.point[k]).dot(planes.normal[k]);
      if ((planeBits & (1u << k)) != 0 && std::abs(off) > 1e-9 * (extent.norm() + asked.norm())) {
        throw InvalidInputError(std::string("the domain centre must lie on the ") + kBoundaryPlaneNames[k] +
                                " (it is " + numberText(off) + " off it)");
      }
    }
    centre = asked;
  }
  result.domainCentre = centre;
  if (result.farfieldDistance <= result.boundaryLayerThickness) {
    throw InvalidInputError("far-field distance " + numberText(result.farfieldDistance) +
                            " is not beyond the boundary-layer thickness " +
                            numberText(result.boundaryLayerThickness));
  }

  MarchingOptions& marching = result.marching;
  marching.boundaryLayerThickness = result.boundaryLayerThickness;
  marching.boundaryLayerLayers = options.boundaryLayerLayers;
  marching.boundaryLayerGrowth = options.boundaryLayerGrowth;
  marching.sharpEdgeSplay = options.sharpEdgeSplay;
  marching.farfieldDistance = result.farfieldDistance;
  marching.farfieldGrowth = options.farfieldGrowth;
  marching.domain.shape = options.domain;
  marching.domain.centre = centre;
  marching.domain.size = result.farfieldDistance;
  for (int axis = 0; axis < 3; ++axis) {
    const double half = options.boxHalfExtent[axis];
    if (!(half >= 0.0) || !std::isfinite(half)) {
      throw InvalidInputError("box half sizes must be positive (or 0 for the far-field distance), got " +
                              numberText(half));
    }
    marching.domain.halfExtent[axis] = half > 0.0 ? half : result.farfieldDistance;
    if (options.domain == DomainShape::Box && marching.domain.halfExtent[axis] > 1e4 * result.referenceLength) {
      std::ostringstream message;
      message << "box half size " << marching.domain.halfExtent[axis] << " is beyond 1e4 reference lengths ("
              << result.referenceLength << ")";
      throw InvalidInputError(message.str());
    }
  }
  if (options.domain == DomainShape::Box) {
    // The layers are marched out to the box's nearest face, then stretched onto the box.
    marching.farfieldDistance = marching.domain.halfExtent.minCoeff();
    result.farfieldDistance = marching.farfieldDistance;
  }
  if (options.hasOutflowPlane && options.domain != DomainShape::Sphere) {
    throw InvalidInputError(
        std::string("a wall running into an outflow plane needs the sphere domain, not the ") +
        domainShapeName(options.domain) + " (the sphere's centre on the plane)");
  }
  const double flow = options.flowDirection.norm();
  if (!std::isfinite(flow) || !(flow > 0.0)) throw InvalidInputError("the flow direction must be a finite, non-zero vector");
  marching.domain.flowDirection = options.flowDirection / flow;
  marching.domain.validate();
  if (options.domain == DomainShape::Box && marching.domain.halfExtent.minCoeff() <= result.boundaryLayerThickness) {
    throw InvalidInputError("the box's half sizes must be beyond the boundary-layer thickness " +
                            numberText(result.boundaryLayerThickness));
  }
  // A domain around a centre of the user's must still hold the wall, a boundary-layer thickness
  // inside it along each ray (around the wall's own centre the marching's set-up checks the room).
  for (Eigen::Index i = 0; options.domainCentre && i < front.points.rows(); ++i) {
    const Vector3d x = front.points.row(i).transpose();
    if ((x - centre).norm() <= result.boundaryLayerThickness) continue;  // next to the centre
    const Vector3d boundary = marching.domain.onBoundary(x);
    if ((boundary - centre).norm() - (x - centre).norm() <= result.boundaryLayerThickness) {
      std::ostringstream message;
      message << "the wall point (" << x.x() << ", " << x.y() << ", " << x.z() << ") is not inside the "
              << domainShapeName(options.domain) << " domain by a boundary-layer thickness ("
              << result.boundaryLayerThickness << "): enlarge the domain or move its centre";
      throw InvalidInputError(message.str());
    }
  }
  marching.planes = planes;
  marching.smoothing = options.smoothing;
  marching.farfieldScheme = options.farfieldScheme;
  marching.minScaledJacobian = options.minScaledJacobian;
  marching.maxLayers = options.maxLayers;
  marching.maxLayerPoints = options.maxLayerPoints;
  return result;
}

}  // namespace bvmesh::volume

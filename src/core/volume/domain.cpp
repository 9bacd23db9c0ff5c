#include "core/volume/domain.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/common/errors.h"

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

// The flow-aligned parts of x - centre for a cylinder: (along the axis, across it).
std::pair<double, Vector3d> axialSplit(const Domain& d, const Vector3d& x) {
  const Vector3d r = x - d.centre;
  const double along = r.dot(d.flowDirection);
  return {along, r - along * d.flowDirection};
}

}  // namespace

void Domain::validate() const {
  if (!centre.allFinite()) throw InvalidInputError("the domain centre is not finite");
  const double flow = flowDirection.norm();
  if (!std::isfinite(flow) || std::abs(flow - 1.0) > 1e-9) {
    throw InvalidInputError("the flow direction must be a finite unit vector");
  }
  if (shape == DomainShape::Box) {
    if (!halfExtent.allFinite() || !(halfExtent.minCoeff() > 0.0)) {
      throw InvalidInputError("the box domain's half sizes must be finite and positive");
    }
  } else if (!std::isfinite(size) || !(size > 0.0)) {
    throw InvalidInputError("the domain size must be finite and positive, got " + std::to_string(size));
  }
}

Vector3d Domain::onBoundary(const Vector3d& x) const {
  const Vector3d r = x - centre;
  const double length = r.norm();
  if (!(length > 0.0)) throw InvalidInputError("a point at the domain centre has no ray to the boundary");
  double t = 0.0;  // the boundary is at centre + t r
  switch (shape) {
    case DomainShape::Sphere:
      t = size / length;
      break;
    case DomainShape::Box: {
      // Onto the cube [-1, 1]^3 along the ray, then scaled to the box: the cube's diagonal planes
      // map onto the box's edges whatever its proportions, so a body's chart borders that run in
      // those planes (any cube-like layout) end at the box's edges.
      Vector3d onCube = r / r.cwiseAbs().maxCoeff();
      for (int axis = 0; axis < 3; ++axis) {
        // Within 1e-6 of an edge or corner a point is put on it exactly.
        if (std::abs(std::abs(onCube[axis]) - 1.0) <= 1e-6) onCube[axis] = onCube[axis] >= 0.0 ? 1.0 : -1.0;
      }
      return centre + halfExtent.cwiseProduct(onCube);
    }
    case DomainShape::Cylinder: {
      const auto [along, across] = axialSplit(*this, x);
      t = std::numeric_limits<double>::infinity();
      if (along != 0.0) t = std::min(t, size / std::abs(along));
      if (across.norm() > 0.0) t = std::min(t, size / across.norm());
      break;
    }
  }
  return centre + t * r;
}

Vector3d Domain::outwardNormal(const Vector3d& boundaryPoint) const {
  const Vector3d r = boundaryPoint - centre;
  switch (shape) {
    case DomainShape::Sphere:
      return r.normalized();
    case DomainShape::Box: {
      int axis = 0;
      for (int a = 1; a < 3; ++a) {
        if (std::abs(r[a]) / halfExtent[a] > std::abs(r[axis]) / halfExtent[axis]) axis = a;
      }
      Vector3d n = Vector3d::Zero();
      n[axis] = r[axis] >= 0.0 ? 1.0 : -1.0;
      return n;
    }
    case DomainShape::Cylinder: {
      const auto [along, across] = axialSplit(*this, boundaryPoint);
      if (std::abs(along) >= across.norm()) return along >= 0.0 ? flowDirection : Vector3d(-flowDirection);
      return across.normalized();
    }
  }
  return r.normalized();
}

int Domain::pieceAt(const Vector3d& boundaryPoint) const {
  const Vector3d n = outwardNormal(boundaryPoint);
  switch (shape) {
    case DomainShape::Sphere:
      return 0;
    case DomainShape::Box:
      for (int axis = 0; axis < 3; ++axis) {
        if (n[axis] != 0.0) return 2 * axis + (n[axis] > 0.0 ? 1 : 0);
      }
      return 0;
    case DomainShape::Cylinder: {
      const double along = n.dot(flowDirection);
      return along > 0.5 ? 1 : along < -0.5 ? 2 : 0;
    }
  }
  return 0;
}

double Domain::distanceToPiece(const Vector3d& x, int piece) const {
  const Vector3d r = x - centre;
  switch (shape) {
    case DomainShape::Sphere:
      return std::abs(r.norm() - size);
    case DomainShape::Box: {
      const int axis = piece / 2;
      return std::abs(r[axis] - (piece % 2 == 1 ? halfExtent[axis] : -halfExtent[axis]));
    }
    case DomainShape::Cylinder: {
      const auto [along, across] = axialSplit(*this, x);
      if (piece == 0) return std::abs(across.norm() - size);
      return std::abs(along - (piece == 1 ? size : -size));
    }
  }
  return 0.0;
}

BoundaryCondition Domain::conditionAt(const Vector3d& boundaryPoint) const {
  if (shape == DomainShape::Sphere) return BoundaryCondition::Farfield;
  const double facing = outwardNormal(boundaryPoint).dot(flowDirection);
  if (facing < -0.5) return BoundaryCondition::Inlet;
  if (facing > 0.5) return BoundaryCondition::Outlet;
  return BoundaryCondition::Side;
}

DomainShape domainShapeOf(const std::string& name) {
  if (name == "sphere") return DomainShape::Sphere;
  if (name == "box") return DomainShape::Box;
  if (name == "cylinder") return DomainShape::Cylinder;
  throw InvalidInputError("domain must be 'sphere', 'box' or 'cylinder', got '" + name + "'");
}

const char* domainShapeName(DomainShape shape) {
  switch (shape) {
    case DomainShape::Sphere:
      return "sphere";
    case DomainShape::Box:
      return "box";
    case DomainShape::Cylinder:
      return "cylinder";
  }
  return "sphere";
}

}  // namespace bvmesh::volume

#include "core/volume/boundary_planes.h"

namespace bvmesh::volume {

using Eigen::Vector3d;

Vector3d BoundaryPlanes::along(const Vector3d& d, unsigned mask) const {
  Vector3d result = d;
  for (size_t k = 0; k < 2; ++k) {
    if ((mask & (1u << k)) != 0) result -= result.dot(normal[k]) * normal[k];
  }
  return result;
}

Vector3d BoundaryPlanes::onto(const Vector3d& x, unsigned mask) const {
  Vector3d result = x;
  for (size_t k = 0; k < 2; ++k) {
    if ((mask & (1u << k)) != 0) result -= (result - point[k]).dot(normal[k]) * normal[k];
  }
  return result;
}

Vector3d BoundaryPlanes::mirrored(const Vector3d& x, unsigned mask) const {
  Vector3d result = x;
  for (size_t k = 0; k < 2; ++k) {
    if ((mask & (1u << k)) != 0) result -= 2.0 * (result - point[k]).dot(normal[k]) * normal[k];
  }
  return result;
}

Eigen::Matrix3d BoundaryPlanes::mirrorMatrix(unsigned mask) const {
  Eigen::Matrix3d result = Eigen::Matrix3d::Identity();
  for (size_t k = 0; k < 2; ++k) {
    if ((mask & (1u << k)) != 0)
      result = (Eigen::Matrix3d::Identity() - 2.0 * normal[k] * normal[k].transpose()) * result;
  }
  return result;
}

int planeCount(unsigned mask) { return ((mask & 1u) != 0 ? 1 : 0) + ((mask & 2u) != 0 ? 1 : 0); }

}  // namespace bvmesh::volume

// The planes a marched front ends on: a half model's symmetry plane, and the outflow plane of a
// body that runs into the domain's outflow boundary (a sting, the hemisphere-cylinder of the
// UGAWG cases). A front point on some of them (MarchingFront::onPlanes, one bit per plane) stays
// on them as it marches, and its neighbourhood is closed by its neighbours' mirror images in them
// (ghost points). Two planes must be perpendicular: the images of a point's quarter ring on both
// then close its ring, and projecting onto one plane keeps a point on the other.
#pragma once

#include <Eigen/Core>

#include <array>

namespace bvmesh::volume {

constexpr unsigned char kSymmetryPlaneBit = 1;
constexpr unsigned char kOutflowPlaneBit = 2;
// Plane k's name in messages.
constexpr std::array<const char*, 2> kBoundaryPlaneNames{"symmetry plane", "outflow plane"};

struct BoundaryPlanes {
  // Plane 0 the symmetry plane (bit kSymmetryPlaneBit), plane 1 the outflow plane; unit normals.
  std::array<Eigen::Vector3d, 2> point{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::array<Eigen::Vector3d, 2> normal{Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitX()};

  // d without its components along the normals of the planes in `mask`.
  Eigen::Vector3d along(const Eigen::Vector3d& d, unsigned mask) const;
  // x projected onto the planes in `mask` (onto their common line for both).
  Eigen::Vector3d onto(const Eigen::Vector3d& x, unsigned mask) const;
  // x mirrored in every plane in `mask`, and the linear part of that map.
  Eigen::Vector3d mirrored(const Eigen::Vector3d& x, unsigned mask) const;
  Eigen::Matrix3d mirrorMatrix(unsigned mask) const;
};

// The number of planes in a mask.
int planeCount(unsigned mask);

}  // namespace bvmesh::volume

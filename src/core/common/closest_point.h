// Closest points on simple primitives, shared by the spatial queries of the core.
#pragma once

#include <Eigen/Core>

namespace bvmesh {

// The point of triangle (a, b, c) nearest to p; degenerate triangles are handled (their nearest
// edge point is returned).
Eigen::Vector3d closestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                       const Eigen::Vector3d& c);

// The point of segment (a, b) nearest to p.
Eigen::Vector3d closestPointOnSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b);

}  // namespace bvmesh

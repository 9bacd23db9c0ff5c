// Closest points on simple primitives, shared by the spatial queries of the core.
#pragma once

#include <Eigen/Core>

namespace bvmesh {

// A point of a triangle (a, b, c) and its barycentric weights: non-negative, summing to 1, the
// point = weights[0] a + weights[1] b + weights[2] c.
struct TriangleFoot {
  Eigen::Vector3d point;
  Eigen::Vector3d weights;
};

// The point of triangle (a, b, c) nearest to p, with its weights (for interpolating data given at
// the corners, such as surface parameters); degenerate triangles are handled (their nearest edge
// point is returned).
TriangleFoot closestFootOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                   const Eigen::Vector3d& c);

// The point of triangle (a, b, c) nearest to p.
Eigen::Vector3d closestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                       const Eigen::Vector3d& c);

// The point of segment (a, b) nearest to p.
Eigen::Vector3d closestPointOnSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b);

}  // namespace bvmesh

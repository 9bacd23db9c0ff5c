#include "core/common/closest_point.h"

#include <Eigen/Geometry>

#include <algorithm>

namespace bvmesh {

Eigen::Vector3d closestPointOnSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length2 = ab.squaredNorm();
  if (length2 <= 0.0) return a;
  return a + std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) * ab;
}

Eigen::Vector3d closestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                       const Eigen::Vector3d& c) {
  const Eigen::Vector3d normal = (b - a).cross(c - a);
  const double area2 = normal.squaredNorm();
  if (area2 > 0.0) {
    // Barycentric coordinates of p's projection onto the triangle's plane; inside: done.
    const Eigen::Vector3d q = p - (p - a).dot(normal) / area2 * normal;
    const double wa = (c - b).cross(q - b).dot(normal) / area2;
    const double wb = (a - c).cross(q - c).dot(normal) / area2;
    const double wc = 1.0 - wa - wb;
    if (wa >= 0.0 && wb >= 0.0 && wc >= 0.0) return q;
  }
  // Outside (or degenerate): the nearest point lies on one of the edges.
  const Eigen::Vector3d candidates[3] = {closestPointOnSegment(p, a, b), closestPointOnSegment(p, b, c),
                                         closestPointOnSegment(p, c, a)};
  const Eigen::Vector3d* best = &candidates[0];
  for (const Eigen::Vector3d& candidate : candidates) {
    if ((candidate - p).squaredNorm() < (*best - p).squaredNorm()) best = &candidate;
  }
  return *best;
}

}  // namespace bvmesh

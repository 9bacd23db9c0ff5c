#include "core/common/closest_point.h"

#include <Eigen/Geometry>

#include <algorithm>

namespace bvmesh {
namespace {

// Parameter in [0, 1] of the point of segment (a, b) nearest to p (0 for a point-like segment).
double segmentParameter(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length2 = ab.squaredNorm();
  return length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
}

// The nearest point of the three edges: a degenerate triangle's nearest point.
TriangleFoot closestFootOnEdges(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                const Eigen::Vector3d& c) {
  const double tab = segmentParameter(p, a, b), tbc = segmentParameter(p, b, c), tca = segmentParameter(p, c, a);
  const TriangleFoot feet[3] = {{a + tab * (b - a), {1.0 - tab, tab, 0.0}},
                                {b + tbc * (c - b), {0.0, 1.0 - tbc, tbc}},
                                {c + tca * (a - c), {tca, 0.0, 1.0 - tca}}};
  const TriangleFoot* best = &feet[0];
  for (const TriangleFoot& foot : feet) {
    if ((foot.point - p).squaredNorm() < (best->point - p).squaredNorm()) best = &foot;
  }
  return *best;
}

}  // namespace

Eigen::Vector3d closestPointOnSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return a + segmentParameter(p, a, b) * (b - a);
}

// Ericson's Voronoi-region walk (Real-Time Collision Detection, 5.1.5): dot products alone,
// cheap enough for the triangle loops of the tree queries. A degenerate triangle (tessellations
// have them at a surface's pole, two corners at one point) ends in a division by zero, or by a
// vanishing area, where it goes to its edges instead.
TriangleFoot closestFootOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                   const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {a, {1.0, 0.0, 0.0}};
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {b, {0.0, 1.0, 0.0}};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    if (!(d1 - d3 > 0.0)) return closestFootOnEdges(p, a, b, c);  // d1 - d3 = |ab|^2
    const double t = d1 / (d1 - d3);
    return {a + t * ab, {1.0 - t, t, 0.0}};
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {c, {0.0, 0.0, 1.0}};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    if (!(d2 - d6 > 0.0)) return closestFootOnEdges(p, a, b, c);  // |ac|^2
    const double t = d2 / (d2 - d6);
    return {a + t * ac, {1.0 - t, 0.0, t}};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
    if (!((d4 - d3) + (d5 - d6) > 0.0)) return closestFootOnEdges(p, a, b, c);  // |bc|^2
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {b + t * (c - b), {0.0, 1.0 - t, t}};
  }
  const double area2 = va + vb + vc;  // |ab x ac|^2: against |ab|^2 |ac|^2, the angle at a's squared sine
  if (!(area2 > 1e-12 * ab.squaredNorm() * ac.squaredNorm())) return closestFootOnEdges(p, a, b, c);
  const double wb = vb / area2, wc = vc / area2;
  return {a + wb * ab + wc * ac, {1.0 - wb - wc, wb, wc}};
}

Eigen::Vector3d closestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                       const Eigen::Vector3d& c) {
  return closestFootOnTriangle(p, a, b, c).point;
}

}  // namespace bvmesh

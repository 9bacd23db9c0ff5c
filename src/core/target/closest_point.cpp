// Closest points on the target: on the trimmed surface (warm or cold start) and on one edge.
//
// Closest point on the surface, per point q:
//   1. candidates: tessellation triangles within r of q, nearest first, where r is the
//      distance to the nearest triangle (cold) or to the warm-started foot point, plus the
//      margin by which the surface may deviate from its tessellation;
//   2. per candidate (face, (u, v) interpolated from the triangle's nodes): Levenberg-Marquardt
//      Newton on |S(u, v) - q|^2 with the exact Hessian (D2), inside the surface's domain;
//   3. trim test in the face's parameter plane; outside the trim, a second descent that may not
//      leave it, and if that stops at the border, the closest point of the face's boundary
//      edges (Newton on each edge curve whose box is near enough);
//   4. keep the nearest; stop when a triangle's distance minus the margin exceeds the best.
// Candidates near a foot point already found on the same face are skipped (same basin).
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <functional>

#include "core/common/closest_point.h"
#include "core/target/projection_steps.h"

namespace bvmesh::target {
namespace {

constexpr int kMaxFaceSolvesPerPoint = 16;
constexpr int kMaxCurveSeeds = 4;

struct TrianglePoint {
  Eigen::Vector3d point;
  double u, v;
};

TrianglePoint closestOnMeshTriangle(const Target::Data& data, int triangle, const Eigen::Vector3d& q) {
  const auto nodes = data.triangles.row(triangle);
  const TriangleFoot foot = closestFootOnTriangle(q, data.nodes.row(nodes[0]).transpose(),
                                                  data.nodes.row(nodes[1]).transpose(),
                                                  data.nodes.row(nodes[2]).transpose());
  const Eigen::Vector2d uv = foot.weights[0] * data.nodeUV.row(nodes[0]) +
                             foot.weights[1] * data.nodeUV.row(nodes[1]) +
                             foot.weights[2] * data.nodeUV.row(nodes[2]);
  return {foot.point, uv[0], uv[1]};
}

// Closest point on the trimmed face: Newton from (u, v), then the trim test; outside the trim a
// trim-constrained descent, then the face's boundary edges. Returns no foot (distance < 0) when
// the face cannot beat bestSoFar.
// bestSoFar: distance of the best foot found on other candidates (< 0: none).
Foot solveOnFace(const Target::Data& data, ThreadContext& context, int faceId, const Eigen::Vector3d& q, double u,
                 double v, double bestSoFar) {
  const FaceData& face = data.faces[static_cast<std::size_t>(faceId)];
  NewtonResult newton = newtonOnSurface(face, context.surface(faceId), q, u, v, data.convergence);
  for (int escape = 0; escape < 2 && newton.singular; ++escape) {
    if (!leavePole(face, context.surface(faceId), q, u, v)) break;
    newton = newtonOnSurface(face, context.surface(faceId), q, u, v, data.convergence);
  }
  Foot foot;
  foot.face = faceId;
  foot.u = wrapInto(newton.u, face.uPeriodic, face.uPeriod, face.u0);
  foot.v = wrapInto(newton.v, face.vPeriodic, face.vPeriod, face.v0);
  if (insideTrim(context, face, faceId, foot.u, foot.v)) {
    foot.point = newton.point;
    foot.distance = (newton.point - q).norm();
    foot.normal = newton.normal;
    foot.status = newton.converged ? ProjectionStatus::Ok : ProjectionStatus::Fallback;
    return foot;
  }
  // The minimum over the untrimmed surface lies outside the trim. Descend again from the seed
  // without leaving the trim: an interior minimum of the trimmed face, or a stop at its border,
  // whose nearest point is then on a boundary edge.
  const std::function<bool(double, double)> inside = [&](double un, double vn) {
    return context.inside(faceId, wrapInto(un, face.uPeriodic, face.uPeriod, face.u0),
                          wrapInto(vn, face.vPeriodic, face.vPeriod, face.v0));
  };
  if (inside(u, v)) {
    const NewtonResult constrained = newtonOnSurface(face, context.surface(faceId), q, u, v, data.convergence, &inside);
    if (constrained.converged && !constrained.blocked) {
      foot.point = constrained.point;
      foot.distance = (constrained.point - q).norm();
      foot.u = wrapInto(constrained.u, face.uPeriodic, face.uPeriod, face.u0);
      foot.v = wrapInto(constrained.v, face.vPeriodic, face.vPeriod, face.v0);
      foot.normal = constrained.normal;
      foot.status = ProjectionStatus::Ok;
      return foot;
    }
  }
  for (const FaceEdgeUse& use : face.edges) {
    // An edge whose box is farther than the best foot (here or elsewhere) cannot hold a nearer one.
    const double bound = foot.distance >= 0 ? foot.distance : bestSoFar;
    if (bound >= 0 && data.edges[static_cast<std::size_t>(use.edge)].box.squaredDistance(q) > bound * bound) continue;
    const Foot onEdge = closestOnEdge(data, context, use.edge, q, bound);
    if (onEdge.distance < 0 || (bound >= 0 && onEdge.distance >= bound)) continue;
    const gp_Pnt2d uv = use.pcurve->Value(onEdge.t);
    foot.point = onEdge.point;
    foot.distance = onEdge.distance;
    foot.u = uv.X();
    foot.v = uv.Y();
    foot.edge = onEdge.edge;
    foot.t = onEdge.t;
    foot.status = ProjectionStatus::OnTrimBoundary;
  }
  return foot;
}

}  // namespace

bool nearAnchor(const ThreadContext& context, int face, const Eigen::Vector3d& point, double radius) {
  for (const ThreadContext::Anchor& anchor : context.anchors)
    if (anchor.face == face && (anchor.point - point).squaredNorm() <= radius * radius) return true;
  return false;
}

Foot closestOnSurface(const Target::Data& data, ThreadContext& context, const Eigen::Vector3d& q, int hintFace,
                      double hintU, double hintV) {
  Foot best;
  context.anchors.clear();
  context.candidates.clear();
  double radius = 0;
  if (hintFace >= 0) {
    best = solveOnFace(data, context, hintFace, q, hintU, hintV, -1.0);
    // A descent that did not converge (held at a surface's pole, where u is undefined) marks no
    // basin: the triangles round it are solved as they would be without the warm start.
    if (best.status != ProjectionStatus::Fallback) context.anchors.push_back({hintFace, best.point});
  }
  auto addCandidate = [&](int t) {
    const TrianglePoint closest = closestOnMeshTriangle(data, t, q);
    const double distance = (closest.point - q).norm();
    context.candidates.push_back({t, distance, closest.point, closest.u, closest.v});
    return distance;
  };
  if (best.distance >= 0) {
    radius = best.distance + data.margin;
    data.tree.withinRadius(q, radius, [&](int t) {
      // A triangle of the warm-start face with a node within half its size of the warm-started
      // foot lies within 1.5 sizes of it: the loop below would skip it as the same basin.
      const double size = data.triangleSize[static_cast<std::size_t>(t)];
      if (!context.anchors.empty() && data.triangleFaces[t] == hintFace &&
          (data.nodes.row(data.triangles(t, 0)).transpose() - context.anchors.front().point).squaredNorm() <=
              0.25 * size * size)
        return;
      addCandidate(t);
    });
  } else {
    // The triangles within the margin of the nearest one, found in the same traversal.
    double nearestSquared = 0;
    const int nearest = data.tree.nearest(
        q, [&](int t, const Eigen::Vector3d&) { const double d = addCandidate(t); return d * d; }, nearestSquared,
        data.margin);
    if (nearest < 0) return best;
    radius = std::sqrt(nearestSquared) + data.margin;
  }
  context.candidates.erase(std::remove_if(context.candidates.begin(), context.candidates.end(),
                                          [&](const ThreadContext::Candidate& c) { return c.distance > radius; }),
                           context.candidates.end());
  std::sort(context.candidates.begin(), context.candidates.end(),
            [](const ThreadContext::Candidate& a, const ThreadContext::Candidate& b) { return a.distance < b.distance; });
  int solves = 0;
  // The nearest foot inside its face: faces that overlap within the target's tolerance (a patch
  // written twice, or run on over its neighbour) are one surface there, and a foot on the trim
  // boundary of one of them is no better than the other's inside foot at the same place.
  Foot inside;
  for (const ThreadContext::Candidate& candidate : context.candidates) {
    // The surface under this triangle is at least (distance - margin) away.
    if (best.distance >= 0 && candidate.distance - data.margin > best.distance + data.tolerance) break;
    const int face = data.triangleFaces[candidate.triangle];
    if (nearAnchor(context, face, candidate.point, 1.5 * data.triangleSize[static_cast<std::size_t>(candidate.triangle)]))
      continue;
    if (++solves > kMaxFaceSolvesPerPoint) break;
    const Foot foot = solveOnFace(data, context, face, q, candidate.u, candidate.v, best.distance);
    if (foot.status == ProjectionStatus::Fallback) {  // no basin either (above)
      if (best.distance < 0 || foot.distance < best.distance) best = foot;
      continue;
    }
    context.anchors.push_back({face, candidate.point});
    if (foot.distance < 0) continue;
    context.anchors.push_back({face, foot.point});
    // On a tie (a foot on an edge shared by two faces) prefer the face interior, so that warm
    // and cold starts agree on the status too.
    const bool tie = best.distance >= 0 && std::abs(foot.distance - best.distance) <= data.convergence;
    if (best.distance < 0 || (tie ? foot.status < best.status : foot.distance < best.distance)) best = foot;
    if (foot.status == ProjectionStatus::Ok && (inside.distance < 0 || foot.distance < inside.distance)) inside = foot;
  }
  // Only next to the surface (where the fit's samples are) and only for a foot within the
  // tolerance of the nearest one: far from the surface two feet at nearly the same distance may lie
  // far apart, and the nearest is the answer there.
  if (best.status != ProjectionStatus::Ok && inside.distance >= 0 && best.distance <= data.margin &&
      inside.distance <= best.distance + data.tolerance && (inside.point - best.point).norm() <= data.tolerance)
    return inside;
  return best;
}

Foot closestOnEdge(const Target::Data& data, ThreadContext& context, int edgeId, const Eigen::Vector3d& q, double bound) {
  const EdgeData& edge = data.edges[static_cast<std::size_t>(edgeId)];
  Foot best;
  if (edge.degenerate || edge.polyline.size() < 2) return best;
  // Seeds: local minima of the distance to the polyline's segments within the margin of the
  // nearest (the curve lies within the margin of its polyline), the kMaxCurveSeeds nearest of
  // them; Newton on the curve from each. One pass, no storage: keeping the nearest local minima
  // and dropping those beyond the margin at the end selects the same seeds.
  const std::size_t segments = edge.polyline.size() - 1;
  auto segmentDistance = [&](std::size_t k, double& param) {
    const Eigen::Vector3d& a = edge.polyline[k];
    const Eigen::Vector3d ab = edge.polyline[k + 1] - a;
    const double length2 = ab.squaredNorm();
    const double w = length2 > 0 ? clampTo((q - a).dot(ab) / length2, 0, 1) : 0;
    param = edge.polyParams[k] + w * (edge.polyParams[k + 1] - edge.polyParams[k]);
    return (a + w * ab - q).norm();
  };
  double seedDistance[kMaxCurveSeeds];
  double seedParam[kMaxCurveSeeds];
  int seeds = 0;
  double previous = std::numeric_limits<double>::infinity();
  double param = 0;
  double distance = segmentDistance(0, param);
  double nearest = distance;
  for (std::size_t k = 0; k < segments; ++k) {
    double nextParam = 0;
    const double next = k + 1 < segments ? segmentDistance(k + 1, nextParam) : std::numeric_limits<double>::infinity();
    nearest = std::min(nearest, next);
    if (distance <= previous && distance <= next) {
      int slot = seeds;
      if (seeds < kMaxCurveSeeds) {
        ++seeds;
      } else {
        slot = static_cast<int>(std::max_element(seedDistance, seedDistance + seeds) - seedDistance);
        if (seedDistance[slot] <= distance) slot = -1;
      }
      if (slot >= 0) {
        seedDistance[slot] = distance;
        seedParam[slot] = param;
      }
    }
    previous = distance;
    distance = next;
    param = nextParam;
  }
  // A seed farther than the margin beyond the nearest seed or the bound cannot hold a foot
  // nearer than either.
  const double limit = std::min(nearest, bound >= 0 ? bound : std::numeric_limits<double>::infinity()) + data.margin;
  for (int s = 0; s < seeds; ++s) {
    if (seedDistance[s] > limit) continue;
    const CurveResult result = newtonOnCurve(edge, context.curve(edgeId), q, seedParam[s], data.convergence);
    const double footDistance = (result.point - q).norm();
    if (best.distance < 0 || footDistance < best.distance) {
      best.point = result.point;
      best.distance = footDistance;
      best.edge = edgeId;
      best.t = result.t;
      best.status = ProjectionStatus::Ok;
    }
  }
  return best;
}

}  // namespace bvmesh::target

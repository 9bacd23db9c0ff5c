// Crossings of a line with the target: Newton on the line's equation from the tessellation's
// hits, with a bracketed root of the signed distance where Newton fails.
#include <Precision.hxx>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/target/projection_steps.h"

namespace bvmesh::target {
namespace {

constexpr int kMaxLineHits = 16;

// A crossing of the line q + s d with a face's (untrimmed) surface.
struct LineHit {
  double u = 0, v = 0, s = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  bool found = false;
};

// Intersection of the line q + s d with the face near (u, v, s): Newton on S(u, v) - q - s d.
// Fails (found = false) where the Jacobian (Su, Sv, -d) is singular, as at a sphere's pole.
LineHit newtonOnLine(const FaceData& face, FaceSurface& surface, const Eigen::Vector3d& q,
                     const Eigen::Vector3d& d, double convergence, double u, double v, double s) {
  const double uLo = face.uPeriodic ? -Precision::Infinite() : face.uMin;
  const double uHi = face.uPeriodic ? Precision::Infinite() : face.uMax;
  const double vLo = face.vPeriodic ? -Precision::Infinite() : face.vMin;
  const double vHi = face.vPeriodic ? Precision::Infinite() : face.vMax;
  gp_Pnt p;
  gp_Vec su, sv;
  surface.D1(u, v, p, su, sv);
  Eigen::Vector3d residual = toEigen(p) - q - s * d;
  LineHit hit;
  for (int iteration = 0; iteration < kMaxNewtonIterations; ++iteration) {
    Eigen::Matrix3d jacobian;
    jacobian << toEigen(su), toEigen(sv), -d;
    Eigen::Vector3d step = jacobian.partialPivLu().solve(-residual);
    if (!step.allFinite()) return hit;
    step.head<2>() = clipStep(face, step.head<2>());
    double scale = 1.0;
    bool accepted = false;
    for (int attempt = 0; attempt < 30 && !accepted; ++attempt, scale *= 0.5) {
      const double un = clampTo(u + scale * step[0], uLo, uHi);
      const double vn = clampTo(v + scale * step[1], vLo, vHi);
      const double sn = s + scale * step[2];
      gp_Pnt pn;
      gp_Vec sun, svn;
      surface.D1(un, vn, pn, sun, svn);
      const Eigen::Vector3d rn = toEigen(pn) - q - sn * d;
      if (rn.norm() <= residual.norm() * (1 + 1e-12) + 1e-300) {
        accepted = true;
        const double moved = (toEigen(pn) - toEigen(p)).norm();
        u = un; v = vn; s = sn; p = pn; su = sun; sv = svn; residual = rn;
        if (moved <= convergence) iteration = kMaxNewtonIterations;
      }
    }
    if (!accepted) break;
  }
  hit.found = residual.norm() <= 1e3 * convergence && !isSingular(su, sv);
  hit.u = u;
  hit.v = v;
  hit.s = s;
  hit.point = toEigen(p);
  return hit;
}

// Closest point of the face's surface to x near (u, v) (updated to the foot), and the distance
// signed against a reference normal: a function of the line parameter that changes sign where
// the line crosses the surface, defined at degenerate points too (the closest-point solve
// handles poles).
double signedDistance(const FaceData& face, FaceSurface& surface, const Eigen::Vector3d& x,
                      const Eigen::Vector3d& reference, double convergence, double& u, double& v,
                      Eigen::Vector3d& foot) {
  NewtonResult newton = newtonOnSurface(face, surface, x, u, v, convergence);
  for (int escape = 0; escape < 2 && newton.singular; ++escape) {
    double pu = newton.u, pv = newton.v;
    if (!leavePole(face, surface, x, pu, pv)) break;
    newton = newtonOnSurface(face, surface, x, pu, pv, convergence);
  }
  u = newton.u;
  v = newton.v;
  foot = newton.point;
  const Eigen::Vector3d r = x - foot;
  return r.dot(reference) >= 0 ? r.norm() : -r.norm();
}

// Crossing of the line near s0 found as the root of the signed distance along it: bracketed in
// widening intervals around s0 (up to 16 reach), then regula falsi (Illinois). Slower than
// Newton on the line but indifferent to the surface's parametrization.
LineHit bracketOnLine(const FaceData& face, FaceSurface& surface, const Eigen::Vector3d& q,
                      const Eigen::Vector3d& d, const Eigen::Vector3d& reference, double convergence, double u,
                      double v, double s0, double reach) {
  LineHit hit;
  struct Sample {
    double s, g, u, v;
    Eigen::Vector3d foot;
  };
  auto sample = [&](double s, double su, double sv) {
    Sample x{s, 0.0, su, sv, Eigen::Vector3d::Zero()};
    x.g = signedDistance(face, surface, q + s * d, reference, convergence, x.u, x.v, x.foot);
    return x;
  };
  const Sample center = sample(s0, u, v);
  if (std::abs(center.g) <= convergence) {
    hit = {center.u, center.v, s0, center.foot, true};
    return hit;
  }
  Sample a = center, b = center;
  bool bracketed = false;
  for (double width = reach; width <= 16 * reach && !bracketed; width *= 4) {
    // Both sides cross: the one whose interpolated crossing is nearer s0.
    const Sample below = sample(s0 - width, center.u, center.v);
    const Sample above = sample(s0 + width, center.u, center.v);
    const bool crossBelow = (below.g < 0) != (center.g < 0);
    const bool crossAbove = (above.g < 0) != (center.g < 0);
    if (crossBelow && (!crossAbove || std::abs(below.g - center.g) >= std::abs(above.g - center.g))) {
      a = below;
      bracketed = true;
    } else if (crossAbove) {
      b = above;
      bracketed = true;
    }
  }
  if (!bracketed) return hit;
  // Illinois: regula falsi that halves the value kept at an end that stays twice in a row.
  int side = 0;
  Sample x = std::abs(a.g) < std::abs(b.g) ? a : b;
  for (int iteration = 0; iteration < kMaxNewtonIterations && b.s - a.s > convergence; ++iteration) {
    const double s = clampTo(a.s - a.g * (b.s - a.s) / (b.g - a.g), a.s, b.s);
    x = sample(s, x.u, x.v);
    if (std::abs(x.g) <= convergence) break;
    if ((x.g < 0) == (a.g < 0)) {
      a = x;
      if (side < 0) b.g *= 0.5;
      side = -1;
    } else {
      b = x;
      if (side > 0) a.g *= 0.5;
      side = 1;
    }
  }
  if (!(std::abs(x.g) <= 1e3 * convergence)) return hit;
  hit = {x.u, x.v, x.s, x.foot, true};
  return hit;
}

}  // namespace

Foot alongLine(const Target::Data& data, ThreadContext& context, const Eigen::Vector3d& q, const Eigen::Vector3d& direction) {
  const Eigen::Vector3d d = direction.normalized();
  context.candidates.clear();
  // Line-triangle hits with a generous barycentric tolerance: a line that passes the
  // tessellation just outside a triangle may still cross the true surface of its face.
  constexpr double kSlack = 0.25;
  data.tree.alongLine(q, d, [&](int t) {
    const auto nodes = data.triangles.row(t);
    const Eigen::Vector3d a = data.nodes.row(nodes[0]).transpose();
    const Eigen::Vector3d e1 = data.nodes.row(nodes[1]).transpose() - a;
    const Eigen::Vector3d e2 = data.nodes.row(nodes[2]).transpose() - a;
    const Eigen::Vector3d pvec = d.cross(e2);
    const double det = e1.dot(pvec);
    if (std::abs(det) <= 1e-300) return;
    const Eigen::Vector3d tvec = q - a;
    const double wb = tvec.dot(pvec) / det;
    const Eigen::Vector3d qvec = tvec.cross(e1);
    const double wc = d.dot(qvec) / det;
    if (wb < -kSlack || wc < -kSlack || wb + wc > 1 + kSlack) return;
    const double s = e2.dot(qvec) / det;
    const double cb = clampTo(wb, 0, 1), cc = clampTo(wc, 0, 1 - clampTo(wb, 0, 1));
    const Eigen::Vector2d uv = (1 - cb - cc) * data.nodeUV.row(nodes[0]) + cb * data.nodeUV.row(nodes[1]) +
                               cc * data.nodeUV.row(nodes[2]);
    context.candidates.push_back({t, std::abs(s), q + s * d, uv[0], uv[1]});
  });
  std::sort(context.candidates.begin(), context.candidates.end(),
            [](const ThreadContext::Candidate& a, const ThreadContext::Candidate& b) { return a.distance < b.distance; });
  context.anchors.clear();
  Foot best;
  std::vector<Eigen::Vector3d> outsideTrim;  // crossings of a face's surface that its trim test refused
  // A crossing inside the trim that is nearer than the best so far replaces it.
  auto consider = [&](int faceId, const LineHit& hit) {
    if (!hit.found) return false;
    const FaceData& face = data.faces[static_cast<std::size_t>(faceId)];
    const double u = wrapInto(hit.u, face.uPeriodic, face.uPeriod, face.u0);
    const double v = wrapInto(hit.v, face.vPeriodic, face.vPeriod, face.v0);
    if (!insideTrim(context, face, faceId, u, v)) {
      outsideTrim.push_back(hit.point);
      return false;
    }
    context.anchors.push_back({faceId, hit.point});
    const double distance = (hit.point - q).norm();
    if (best.distance < 0 || distance < best.distance) {
      best.point = hit.point;
      best.distance = distance;
      best.face = faceId;
      best.u = u;
      best.v = v;
      best.status = ProjectionStatus::Ok;
    }
    return true;
  };
  int solves = 0;
  for (const ThreadContext::Candidate& candidate : context.candidates) {
    const int faceId = data.triangleFaces[candidate.triangle];
    const double size = data.triangleSize[static_cast<std::size_t>(candidate.triangle)];
    if (nearAnchor(context, faceId, candidate.point, 1.5 * size)) continue;
    if (++solves > kMaxLineHits) break;
    context.anchors.push_back({faceId, candidate.point});
    const FaceData& face = data.faces[static_cast<std::size_t>(faceId)];
    FaceSurface& surface = context.surface(faceId);
    const double s = (candidate.point - q).dot(d);
    // The crossing of the surface under this triangle lies within about a triangle of the
    // tessellation's crossing; Newton may converge to another crossing farther away (it is
    // kept, but the local one is then searched for too).
    const double reach = size + data.margin;
    const LineHit newton = newtonOnLine(face, surface, q, d, data.convergence, candidate.u, candidate.v, s);
    const bool local = consider(faceId, newton) && std::abs(newton.s - s) <= 4 * reach;
    if (local) continue;
    const auto nodes = data.triangles.row(candidate.triangle);
    const Eigen::Vector3d a = data.nodes.row(nodes[0]).transpose();
    const Eigen::Vector3d reference =
        (data.nodes.row(nodes[1]).transpose() - a).cross(data.nodes.row(nodes[2]).transpose() - a);
    consider(faceId, bracketOnLine(face, surface, q, d, reference, data.convergence, candidate.u, candidate.v, s, reach));
  }
  // A line through an edge between two faces crosses both surfaces on their trim boundaries,
  // which the trim test may put outside each (the M6 read from IGES: a ray across its tip's
  // ridge missed, and the template's vertex went to the tip's far end or the root). Such a
  // crossing nearer than the best counts when the target passes through it (its closest point
  // within the target's tolerance). Checked after the candidates: the closest-point search
  // reuses the context's lists.
  std::sort(outsideTrim.begin(), outsideTrim.end(), [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return (a - q).squaredNorm() < (b - q).squaredNorm();
  });
  for (const Eigen::Vector3d& crossing : outsideTrim) {
    if (best.distance >= 0 && (crossing - q).norm() >= best.distance) break;
    Foot onTarget = closestOnSurface(data, context, crossing, -1, 0, 0);
    if (onTarget.distance >= 0 && onTarget.distance <= data.tolerance) {
      onTarget.distance = (onTarget.point - q).norm();
      return onTarget;
    }
  }
  if (best.distance >= 0) return best;
  Foot fallback = closestOnSurface(data, context, q, -1, 0, 0);
  if (fallback.distance >= 0) fallback.status = ProjectionStatus::Fallback;
  return fallback;
}

}  // namespace bvmesh::target

// Projections onto the target: closest points on the trimmed surface (warm or cold start),
// on edge chains and on vertices, and intersections along given directions.
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
#include <BRep_Tool.hxx>
#include <Precision.hxx>
#include <Standard_Failure.hxx>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <functional>

#include "core/common/errors.h"
#include "core/common/parallel.h"
#include "core/common/input_checks.h"
#include "core/target/target.h"
#include "core/target/target_data.h"

namespace bvmesh::target {
namespace {

constexpr int kMaxNewtonIterations = 200;
// Relative change of |S - q|^2 below which a step counts as not increasing it (round-off).
constexpr double kRoundOff = 1e-13;
constexpr int kMaxFaceSolvesPerPoint = 16;
constexpr int kMaxCurveSeeds = 4;
constexpr int kMaxBlockedSteps = 8;
constexpr int kMaxLineHits = 16;

// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5);
// returns the barycentric weights of b and c in (wb, wc).
Eigen::Vector3d closestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const Eigen::Vector3d& c, double& wb, double& wc) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) { wb = 0; wc = 0; return a; }
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) { wb = 1; wc = 0; return b; }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    wb = d1 / (d1 - d3); wc = 0;
    return a + wb * ab;
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) { wb = 0; wc = 1; return c; }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    wb = 0; wc = d2 / (d2 - d6);
    return a + wc * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    wc = (d4 - d3) / ((d4 - d3) + (d5 - d6)); wb = 1 - wc;
    return b + wc * (c - b);
  }
  const double denominator = 1.0 / (va + vb + vc);
  wb = vb * denominator;
  wc = vc * denominator;
  return a + wb * ab + wc * ac;
}

struct TrianglePoint {
  Eigen::Vector3d point;
  double u, v;
};

TrianglePoint closestOnMeshTriangle(const Target::Data& data, int triangle, const Eigen::Vector3d& q) {
  const auto nodes = data.triangles.row(triangle);
  double wb = 0, wc = 0;
  const Eigen::Vector3d point =
      closestOnTriangle(q, data.nodes.row(nodes[0]).transpose(), data.nodes.row(nodes[1]).transpose(),
                        data.nodes.row(nodes[2]).transpose(), wb, wc);
  const Eigen::Vector2d uv = (1 - wb - wc) * data.nodeUV.row(nodes[0]) + wb * data.nodeUV.row(nodes[1]) +
                             wc * data.nodeUV.row(nodes[2]);
  return {point, uv[0], uv[1]};
}

double clampTo(double x, double lo, double hi) { return std::min(std::max(x, lo), hi); }

// Brings a periodic parameter into the face's range [lo, lo + period] so that equal points get
// equal (u, v); a parameter already in the range (u = 2 pi included) stays.
double wrapInto(double x, bool periodic, double period, double lo) {
  if (!periodic || !(period > 0) || (x >= lo && x <= lo + period)) return x;
  return x - period * std::floor((x - lo) / period);
}

// Trust region in parameter space: a step moves u and v each by at most half the face's
// parameter range, so that a seed near a singular point (sphere pole, where the Hessian loses
// rank in one parameter) cannot throw the iteration far away. Clipping per parameter keeps the
// well-determined parameter's step intact.
Eigen::Vector2d clipStep(const FaceData& face, const Eigen::Vector2d& step) {
  const double du = 0.5 * (face.u1 - face.u0);
  const double dv = 0.5 * (face.v1 - face.v0);
  return {du > 0 ? clampTo(step[0], -du, du) : step[0], dv > 0 ? clampTo(step[1], -dv, dv) : step[1]};
}

struct SurfaceSample {
  gp_Pnt p;
  gp_Vec su, sv, suu, svv, suv;
};

struct NewtonResult {
  double u = 0, v = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  bool converged = false;
  bool singular = false;  // stopped where the parametrization degenerates (a pole)
  bool blocked = false;   // stopped at the trim (constrained iteration only)
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit normal at the point; 0 at a pole
};

bool isSingular(const gp_Vec& su, const gp_Vec& sv) {
  const double scale = su.Magnitude() + sv.Magnitude();
  return !(su.Crossed(sv).Magnitude() > 1e-10 * scale * scale);
}

// Minimizes |S(u, v) - q|^2 over the surface's domain: Newton with the exact Hessian and
// Levenberg-Marquardt damping (raised until the damped Hessian is positive definite and the
// step descends) as trust region; bounds handled by fixing a parameter whose descent direction
// leaves the domain.
// With `inside` set, trial points outside the face's trim are rejected like steps that do not
// descend, so the iteration stays in the trimmed face (`blocked` reports a stop at its border).
NewtonResult newtonOnSurface(const FaceData& face, FaceSurface& surface, const Eigen::Vector3d& q, double u,
                             double v, double convergence, const std::function<bool(double, double)>* inside = nullptr) {
  const double uLo = face.uPeriodic ? -Precision::Infinite() : face.uMin;
  const double uHi = face.uPeriodic ? Precision::Infinite() : face.uMax;
  const double vLo = face.vPeriodic ? -Precision::Infinite() : face.vMin;
  const double vHi = face.vPeriodic ? Precision::Infinite() : face.vMax;
  u = clampTo(u, uLo, uHi);
  v = clampTo(v, vLo, vHi);
  SurfaceSample s;
  surface.D2(u, v, s.p, s.su, s.sv, s.suu, s.svv, s.suv);
  Eigen::Vector3d r = toEigen(s.p) - q;
  double f = r.squaredNorm();
  double lambda = 0.0;
  int blockedSteps = 0;
  NewtonResult result;
  for (int iteration = 0; iteration < kMaxNewtonIterations; ++iteration) {
    const Eigen::Vector3d su = toEigen(s.su), sv = toEigen(s.sv);
    const Eigen::Vector2d g(r.dot(su), r.dot(sv));
    Eigen::Matrix2d jtj;
    jtj << su.dot(su), su.dot(sv), su.dot(sv), sv.dot(sv);
    Eigen::Matrix2d h = jtj;
    h(0, 0) += r.dot(toEigen(s.suu));
    h(1, 1) += r.dot(toEigen(s.svv));
    h(0, 1) += r.dot(toEigen(s.suv));
    h(1, 0) = h(0, 1);
    // A parameter on its bound whose descent leaves the domain stays fixed.
    const bool fixU = (u <= uLo && g[0] > 0) || (u >= uHi && g[0] < 0);
    const bool fixV = (v <= vLo && g[1] > 0) || (v >= vHi && g[1] < 0);
    if (fixU && fixV) {
      result.converged = true;
      break;
    }
    bool accepted = false;
    bool fullStep = false;
    bool settled = false;
    double moved = 0.0;
    for (int attempt = 0; attempt < 60 && !accepted; ++attempt) {
      fullStep = lambda == 0.0;
      Eigen::Matrix2d a = h;
      a(0, 0) += lambda * jtj(0, 0) + 1e-300;
      a(1, 1) += lambda * jtj(1, 1) + 1e-300;
      // Where the Hessian is not positive definite (beyond a focal point), damp until it is.
      const double determinant = a.determinant();
      const bool definite = fixU ? a(1, 1) > 0 : fixV ? a(0, 0) > 0 : a(0, 0) > 0 && determinant > 0;
      Eigen::Vector2d step = Eigen::Vector2d::Zero();
      if (fixU) step[1] = -g[1] / a(1, 1);
      else if (fixV) step[0] = -g[0] / a(0, 0);
      else step = Eigen::Vector2d(a(0, 1) * g[1] - a(1, 1) * g[0], a(1, 0) * g[0] - a(0, 0) * g[1]) / determinant;
      if (!definite || !step.allFinite()) {
        lambda = std::max(1e-6, 10 * lambda);
        continue;
      }
      step = clipStep(face, step);
      const double un = clampTo(u + step[0], uLo, uHi);
      const double vn = clampTo(v + step[1], vLo, vHi);
      // An undamped step that moves the point by less than the tolerance (to first order; the
      // step is far too small for the second) would end the iteration after one more
      // evaluation that only confirms it: the point has converged.
      if (fullStep && inside == nullptr && (su * (un - u) + sv * (vn - v)).norm() <= convergence) {
        settled = true;
        break;
      }
      if (inside != nullptr && !(*inside)(un, vn)) {
        lambda = std::max(1e-6, 10 * lambda);
        result.blocked = true;
        // Pressing against the trim again and again: the minimum lies beyond it.
        if (++blockedSteps > kMaxBlockedSteps) break;
        continue;
      }
      SurfaceSample t;
      surface.D2(un, vn, t.p, t.su, t.sv, t.suu, t.svv, t.suv);
      const Eigen::Vector3d rn = toEigen(t.p) - q;
      const double fn = rn.squaredNorm();
      // Near the surface, the rounding of S itself (~1e-16 of the coordinates) changes |S - q|^2
      // by more than its relative round-off, and would reject the last, tiny Newton steps: a
      // step may also raise the distance by a tenth of the tolerance.
      if (fn <= f * (1 + kRoundOff) + 1e-300 || std::sqrt(fn) <= std::sqrt(f) + 0.1 * convergence) {
        moved = (rn - r).norm();
        accepted = true;
        result.blocked = false;
        u = un;
        v = vn;
        s = t;
        r = rn;
        f = fn;
        lambda = lambda < 1e-9 ? 0.0 : 0.1 * lambda;
      } else {
        lambda = std::max(1e-6, 10 * lambda);
      }
    }
    // Converged: a step moved (or an undamped step would move) the point by less than the
    // tolerance and was either undamped or taken where the gradient vanishes; or no step
    // descends any more.
    // Stationary: the gradient along the free parameters vanishes (relative to |S_u|, |S_v|).
    const double gu = fixU ? 0.0 : g[0] * g[0] / std::max(jtj(0, 0), 1e-300);
    const double gv = fixV ? 0.0 : g[1] * g[1] / std::max(jtj(1, 1), 1e-300);
    const bool stationary = std::sqrt(gu + gv) <= 1e3 * convergence;
    if (settled || !accepted || (moved <= convergence && (fullStep || stationary))) {
      result.converged = settled || accepted || stationary;
      break;
    }
  }
  result.u = u;
  result.v = v;
  result.point = toEigen(s.p);
  result.singular = isSingular(s.su, s.sv);
  result.normal = unitNormal(face, s.su, s.sv, 1e-12);
  return result;
}

struct CurveResult {
  double t = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

// Minimizes |C(t) - q|^2 on [first, last]: Newton with the exact second derivative, Gauss-Newton
// where it is not positive or where Newton stalls, halving steps that do not descend.
CurveResult newtonOnCurve(const EdgeData& edge, GeomAdaptor_Curve& curve, const Eigen::Vector3d& q, double t,
                          double convergence) {
  t = clampTo(t, edge.first, edge.last);
  gp_Pnt p;
  gp_Vec d1, d2;
  curve.D2(t, p, d1, d2);
  Eigen::Vector3d r = toEigen(p) - q;
  double f = r.squaredNorm();
  bool gaussNewton = false;
  for (int iteration = 0; iteration < kMaxNewtonIterations; ++iteration) {
    const Eigen::Vector3d c1 = toEigen(d1);
    const double g = r.dot(c1);
    double h = c1.squaredNorm() + (gaussNewton ? 0.0 : r.dot(toEigen(d2)));
    if (!(h > 0)) h = c1.squaredNorm();
    if (!(h > 0)) break;
    double step = -g / h;
    bool accepted = false;
    double moved = 0;
    for (int attempt = 0; attempt < 40 && !accepted; ++attempt, step *= 0.5) {
      const double tn = clampTo(t + step, edge.first, edge.last);
      gp_Pnt pn;
      gp_Vec e1, e2;
      curve.D2(tn, pn, e1, e2);
      const Eigen::Vector3d rn = toEigen(pn) - q;
      const double fn = rn.squaredNorm();
      if (fn <= f * (1 + kRoundOff) + 1e-300) {
        moved = (rn - r).norm();
        accepted = true;
        t = tn;
        p = pn;
        d1 = e1;
        d2 = e2;
        r = rn;
        f = fn;
      }
    }
    // A large curvature term (a parameterisation that crowds at one end, as on approximated
    // intersection curves) can make Newton's steps tiny while the foot is still far along the
    // curve: go on with Gauss-Newton steps (towards the foot on the tangent line).
    const double along = std::abs(r.dot(toEigen(d1))) / std::max(toEigen(d1).norm(), 1e-300);
    if (accepted && moved <= convergence && along > convergence && !gaussNewton) {
      gaussNewton = true;
      continue;
    }
    if (!accepted || moved <= convergence) break;
  }
  return {t, toEigen(p)};
}

// At a pole (one parameter undetermined, the other at its bound) Newton cannot tell along
// which meridian to leave. Picks the meridian of steepest descent from the pole and sets (u, v)
// a little way along it; false when no meridian descends (the pole is the minimum).
bool leavePole(const FaceData& face, FaceSurface& surface, const Eigen::Vector3d& q, double& u, double& v) {
  gp_Pnt p;
  gp_Vec su, sv;
  surface.D1(u, v, p, su, sv);
  const Eigen::Vector3d r = toEigen(p) - q;
  const bool uFree = su.Magnitude() < sv.Magnitude();  // Su = 0: u only turns around the pole
  const double radial = uFree ? v : u;
  const double radialLo = uFree ? face.v0 : face.u0, radialHi = uFree ? face.v1 : face.u1;
  const double inward = radial - radialLo < radialHi - radial ? 1.0 : -1.0;
  const double freeLo = uFree ? face.u0 : face.v0, freeHi = uFree ? face.u1 : face.v1;
  constexpr int kMeridians = 16;
  double bestSlope = 0.0;
  double bestFree = 0.0;
  for (int k = 0; k < kMeridians; ++k) {
    const double c = freeLo + (k + 0.5) / kMeridians * (freeHi - freeLo);
    surface.D1(uFree ? c : u, uFree ? v : c, p, su, sv);
    const double slope = inward * r.dot(toEigen(uFree ? sv : su));
    if (slope < bestSlope) {
      bestSlope = slope;
      bestFree = c;
    }
  }
  if (!(bestSlope < 0)) return false;
  const double step = inward * 1e-3 * (radialHi - radialLo);
  if (uFree) {
    u = bestFree;
    v += step;
  } else {
    v = bestFree;
    u += step;
  }
  return true;
}

// Whether (u, v) (wrapped into the face's range) lies inside the face's trim. At a degenerate
// point (a pole, where one parameter is arbitrary and the trim polygon does not close), the
// test is made a little way towards the face's interior: the point belongs to the face when
// the face's points next to it do.
bool insideTrim(ThreadContext& context, const FaceData& face, int faceId, double u, double v) {
  if (context.inside(faceId, u, v)) return true;
  gp_Pnt p;
  gp_Vec su, sv;
  context.surface(faceId).D1(u, v, p, su, sv);
  if (!isSingular(su, sv)) return false;
  const double nudge = 1e-6;
  return context.inside(faceId, u + nudge * (0.5 * (face.u0 + face.u1) - u), v + nudge * (0.5 * (face.v0 + face.v1) - v));
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
    context.anchors.push_back({hintFace, best.point});
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
      if (data.triangleFaces[t] == hintFace &&
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
  // A crossing inside the trim that is nearer than the best so far replaces it.
  auto consider = [&](int faceId, const LineHit& hit) {
    if (!hit.found) return false;
    const FaceData& face = data.faces[static_cast<std::size_t>(faceId)];
    const double u = wrapInto(hit.u, face.uPeriodic, face.uPeriod, face.u0);
    const double v = wrapInto(hit.v, face.vPeriodic, face.vPeriod, face.v0);
    if (!insideTrim(context, face, faceId, u, v)) return false;
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
  if (best.distance >= 0) return best;
  Foot fallback = closestOnSurface(data, context, q, -1, 0, 0);
  if (fallback.distance >= 0) fallback.status = ProjectionStatus::Fallback;
  return fallback;
}

// Interleaves the bits of three 21-bit integers: nearby points get nearby keys.
std::uint64_t mortonKey(const Eigen::Vector3d& unit) {
  std::uint64_t key = 0;
  for (int k = 0; k < 3; ++k) {
    const auto cell = static_cast<std::uint64_t>(clampTo(unit[k], 0.0, 1.0) * 2097151.0);
    for (int bit = 0; bit < 21; ++bit) key |= ((cell >> bit) & 1u) << (3 * bit + k);
  }
  return key;
}

// Runs work(context, i) for every point i on the configured number of threads, each with its
// own evaluation context. Points are visited in spatial (Morton) order: consecutive points then
// fall into the same B-spline spans, whose polynomial form the surface adaptors cache. An OCCT
// failure on one point marks that point failed (work's job); any other exception stops the
// call and is rethrown.
template <class Work>
void parallelFor(const Target::Data& data, const Eigen::Ref<const Points>& points, Work&& work) {
  constexpr Eigen::Index kChunk = 64;
  const Eigen::Index count = points.rows();
  const Eigen::Vector3d lo(data.report.shape.boundsMin[0], data.report.shape.boundsMin[1], data.report.shape.boundsMin[2]);
  const Eigen::Vector3d hi(data.report.shape.boundsMax[0], data.report.shape.boundsMax[1], data.report.shape.boundsMax[2]);
  const Eigen::Vector3d extent = (hi - lo).cwiseMax(1e-300);
  std::vector<std::pair<std::uint64_t, Eigen::Index>> order(static_cast<std::size_t>(count));
  for (Eigen::Index i = 0; i < count; ++i)
    order[static_cast<std::size_t>(i)] = {mortonKey((points.row(i).transpose() - lo).cwiseQuotient(extent)), i};
  std::sort(order.begin(), order.end());
  // parallelChunks takes fewer threads when the system refuses more (resource limits).
  parallelChunks(count, kChunk, [&](std::int64_t begin, std::int64_t end) {
    std::unique_ptr<ThreadContext> context = data.acquireContext();
    for (Eigen::Index k = begin; k < end; ++k) work(*context, order[static_cast<std::size_t>(k)].second);
    data.releaseContext(std::move(context));
  }, static_cast<unsigned>(std::max(0, data.options.threads)));
}

void checkPoints(const char* function, const Eigen::Ref<const Points>& points) {
  checkFinitePoints(points, std::string(function) + ": point");
}

// Unit bisector of the adjacent faces' normals at parameter t of an edge.
Eigen::Vector3d edgeNormal(const Target::Data& data, ThreadContext& context, int edgeId, double t, int& face,
                           double& u, double& v) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  face = -1;
  for (int faceId : data.edges[static_cast<std::size_t>(edgeId)].faces) {
    const FaceData& f = data.faces[static_cast<std::size_t>(faceId)];
    for (const FaceEdgeUse& use : f.edges) {
      if (use.edge != edgeId) continue;
      const gp_Pnt2d uv = use.pcurve->Value(t);
      if (face < 0) {
        face = faceId;
        u = uv.X();
        v = uv.Y();
      }
      sum += faceNormal(f, context.surface(faceId), uv.X(), uv.Y());
      break;
    }
  }
  const double length = sum.norm();
  return length > 1e-12 ? Eigen::Vector3d(sum / length) : Eigen::Vector3d::Zero();
}

// Unit mean of the adjacent faces' normals at a vertex (taken at the ends of their edges).
Eigen::Vector3d vertexNormal(const Target::Data& data, ThreadContext& context, int vertex) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int faceId : data.vertexFaces[static_cast<std::size_t>(vertex)]) {
    const FaceData& f = data.faces[static_cast<std::size_t>(faceId)];
    for (const FaceEdgeUse& use : f.edges) {
      const EdgeData& e = data.edges[static_cast<std::size_t>(use.edge)];
      if (e.vertex0 != vertex && e.vertex1 != vertex) continue;
      const gp_Pnt2d uv = use.pcurve->Value(e.vertex0 == vertex ? e.first : e.last);
      sum += faceNormal(f, context.surface(faceId), uv.X(), uv.Y());
      break;
    }
  }
  const double length = sum.norm();
  return length > 1e-12 ? Eigen::Vector3d(sum / length) : Eigen::Vector3d::Zero();
}

void storeFoot(const Target::Data& data, ThreadContext& context, const Foot& foot, Eigen::Index i,
               ProjectionResult& result) {
  if (foot.distance < 0 || foot.face < 0) return;
  result.points.row(i) = foot.point.transpose();
  result.distances[i] = foot.distance;
  result.ids[i] = foot.face;
  result.faces[i] = foot.face;
  result.params(i, 0) = foot.u;
  result.params(i, 1) = foot.v;
  result.normals.row(i) =
      (foot.normal.isZero()
           ? faceNormal(data.faces[static_cast<std::size_t>(foot.face)], context.surface(foot.face), foot.u, foot.v)
           : foot.normal)
          .transpose();
  result.status[static_cast<std::size_t>(i)] = foot.status;
}

}  // namespace

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

ProjectionResult Target::project(const Eigen::Ref<const Points>& points, const SurfaceHints* hints) const {
  checkPoints("Target::project", points);
  const Eigen::Index count = points.rows();
  if (hints != nullptr) {
    if (hints->faces.size() != count || hints->uv.rows() != count)
      throw InvalidInputError("Target::project: hints for " + std::to_string(hints->faces.size()) + " faces and " +
                              std::to_string(hints->uv.rows()) + " (u, v) pairs, expected " + std::to_string(count));
    for (Eigen::Index i = 0; i < count; ++i) {
      if (hints->faces[i] >= faceCount() || hints->faces[i] < -1)
        throw InvalidInputError("Target::project: hint face " + std::to_string(hints->faces[i]) + " of point " +
                                std::to_string(i) + " does not exist (" + std::to_string(faceCount()) + " faces)");
      if (hints->faces[i] >= 0 && !hints->uv.row(i).allFinite())
        throw InvalidInputError("Target::project: hint (u, v) of point " + std::to_string(i) + " is not finite");
    }
  }
  ProjectionResult result;
  result.resize(count);
  parallelFor(*data_, points, [&](ThreadContext& context, Eigen::Index i) {
    const Eigen::Vector3d q = points.row(i).transpose();
    const int hint = hints != nullptr ? hints->faces[i] : -1;
    try {
      const Foot foot = closestOnSurface(*data_, context, q, hint, hint >= 0 ? hints->uv(i, 0) : 0.0,
                                         hint >= 0 ? hints->uv(i, 1) : 0.0);
      storeFoot(*data_, context, foot, i, result);
    } catch (const Standard_Failure&) {
      // Left as Failed: the kernel could not evaluate this point.
    }
    if (result.status[static_cast<std::size_t>(i)] == ProjectionStatus::Failed) result.points.row(i) = q.transpose();
  });
  return result;
}

ProjectionResult Target::projectToEdges(const Eigen::Ref<const Points>& points, const std::vector<int>& edges) const {
  checkPoints("Target::projectToEdges", points);
  if (edges.empty()) throw InvalidInputError("Target::projectToEdges: no edges given");
  std::vector<Box3> boxes;
  std::vector<int> boxEdge;
  for (int id : edges) {
    if (id < 0 || id >= edgeCount())
      throw InvalidInputError("Target::projectToEdges: edge " + std::to_string(id) + " does not exist (" +
                              std::to_string(edgeCount()) + " edges)");
    const EdgeData& e = data_->edges[static_cast<std::size_t>(id)];
    if (e.degenerate) throw InvalidInputError("Target::projectToEdges: edge " + std::to_string(id) + " is degenerate");
    Box3 box;
    for (const Eigen::Vector3d& p : e.polyline) box.extend(p);
    boxes.push_back(box);
    boxEdge.push_back(id);
  }
  // The polyline lies within the deflection of its curve: grow the boxes by the margin.
  for (Box3& box : boxes) {
    box.lo.array() -= data_->margin;
    box.hi.array() += data_->margin;
  }
  ProjectionResult result;
  result.resize(points.rows());
  parallelFor(*data_, points, [&](ThreadContext& context, Eigen::Index i) {
    const Eigen::Vector3d q = points.row(i).transpose();
    try {
      // Nearest boxes first; a box farther than the best foot cannot hold a nearer point.
      std::vector<std::pair<double, std::size_t>> order(boxes.size());
      for (std::size_t b = 0; b < boxes.size(); ++b) order[b] = {boxes[b].squaredDistance(q), b};
      std::sort(order.begin(), order.end());
      Foot best;
      for (const auto& [boxSquared, b] : order) {
        if (best.distance >= 0 && boxSquared > best.distance * best.distance) break;
        const Foot foot = closestOnEdge(*data_, context, boxEdge[b], q, best.distance);
        if (foot.distance >= 0 && (best.distance < 0 || foot.distance < best.distance)) best = foot;
      }
      if (best.distance >= 0) {
        int face = -1;
        double u = 0, v = 0;
        const Eigen::Vector3d normal = edgeNormal(*data_, context, best.edge, best.t, face, u, v);
        result.points.row(i) = best.point.transpose();
        result.distances[i] = best.distance;
        result.ids[i] = best.edge;
        result.faces[i] = face;
        result.params(i, 0) = best.t;
        result.normals.row(i) = normal.transpose();
        result.status[static_cast<std::size_t>(i)] = ProjectionStatus::Ok;
      }
    } catch (const Standard_Failure&) {
      // Left as Failed.
    }
    if (result.status[static_cast<std::size_t>(i)] == ProjectionStatus::Failed) result.points.row(i) = q.transpose();
  });
  return result;
}

ProjectionResult Target::projectToFreeBoundary(const Eigen::Ref<const Points>& points) const {
  if (data_->report.freeEdges.empty()) {
    checkPoints("Target::projectToFreeBoundary", points);
    ProjectionResult result;
    result.resize(points.rows());
    result.points = points;
    return result;
  }
  return projectToEdges(points, data_->report.freeEdges);
}

ProjectionResult Target::projectToVertices(const Eigen::Ref<const Points>& points, const std::vector<int>& vertices) const {
  checkPoints("Target::projectToVertices", points);
  if (vertices.empty()) throw InvalidInputError("Target::projectToVertices: no vertices given");
  for (int id : vertices)
    if (id < 0 || id >= vertexCount())
      throw InvalidInputError("Target::projectToVertices: vertex " + std::to_string(id) + " does not exist (" +
                              std::to_string(vertexCount()) + " vertices)");
  ProjectionResult result;
  result.resize(points.rows());
  parallelFor(*data_, points, [&](ThreadContext& context, Eigen::Index i) {
    const Eigen::Vector3d q = points.row(i).transpose();
    int best = vertices.front();
    for (int id : vertices)
      if ((data_->vertices[static_cast<std::size_t>(id)] - q).squaredNorm() <
          (data_->vertices[static_cast<std::size_t>(best)] - q).squaredNorm())
        best = id;
    const Eigen::Vector3d& p = data_->vertices[static_cast<std::size_t>(best)];
    result.points.row(i) = p.transpose();
    result.distances[i] = (p - q).norm();
    result.ids[i] = best;
    try {
      result.normals.row(i) = vertexNormal(*data_, context, best).transpose();
    } catch (const Standard_Failure&) {
      result.normals.row(i).setZero();
    }
    result.status[static_cast<std::size_t>(i)] = ProjectionStatus::Ok;
  });
  return result;
}

ProjectionResult Target::projectAlong(const Eigen::Ref<const Points>& points, const Eigen::Ref<const Points>& directions) const {
  checkPoints("Target::projectAlong", points);
  if (directions.rows() != points.rows())
    throw InvalidInputError("Target::projectAlong: " + std::to_string(directions.rows()) + " directions for " +
                            std::to_string(points.rows()) + " points");
  for (Eigen::Index i = 0; i < directions.rows(); ++i)
    if (!directions.row(i).allFinite() || !(directions.row(i).norm() > 0))
      throw InvalidInputError("Target::projectAlong: direction " + std::to_string(i) + " is zero or not finite");
  ProjectionResult result;
  result.resize(points.rows());
  parallelFor(*data_, points, [&](ThreadContext& context, Eigen::Index i) {
    const Eigen::Vector3d q = points.row(i).transpose();
    try {
      storeFoot(*data_, context, alongLine(*data_, context, q, directions.row(i).transpose()), i, result);
    } catch (const Standard_Failure&) {
      // Left as Failed.
    }
    if (result.status[static_cast<std::size_t>(i)] == ProjectionStatus::Failed) result.points.row(i) = q.transpose();
  });
  return result;
}

}  // namespace bvmesh::target

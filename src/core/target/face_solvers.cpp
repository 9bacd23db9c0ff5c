// Local solvers on one face's surface or one edge's curve: damped Newton for the closest point,
// the way off a pole, and the trim test at degenerate points.
#include <Precision.hxx>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

#include "core/target/projection_steps.h"

namespace bvmesh::target {
namespace {

// Relative change of |S - q|^2 below which a step counts as not increasing it (round-off).
constexpr double kRoundOff = 1e-13;
constexpr int kMaxBlockedSteps = 8;

struct SurfaceSample {
  gp_Pnt p;
  gp_Vec su, sv, suu, svv, suv;
};

}  // namespace

Eigen::Vector2d clipStep(const FaceData& face, const Eigen::Vector2d& step) {
  const double du = 0.5 * (face.u1 - face.u0);
  const double dv = 0.5 * (face.v1 - face.v0);
  return {du > 0 ? clampTo(step[0], -du, du) : step[0], dv > 0 ? clampTo(step[1], -dv, dv) : step[1]};
}

bool isSingular(const gp_Vec& su, const gp_Vec& sv) {
  const double scale = su.Magnitude() + sv.Magnitude();
  return !(su.Crossed(sv).Magnitude() > 1e-10 * scale * scale);
}

NewtonResult newtonOnSurface(const FaceData& face, FaceSurface& surface, const Eigen::Vector3d& q, double u,
                             double v, double convergence, const std::function<bool(double, double)>* inside) {
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

bool insideTrim(ThreadContext& context, const FaceData& face, int faceId, double u, double v) {
  if (context.inside(faceId, u, v)) return true;
  gp_Pnt p;
  gp_Vec su, sv;
  context.surface(faceId).D1(u, v, p, su, sv);
  if (!isSingular(su, sv)) return false;
  const double nudge = 1e-6;
  return context.inside(faceId, u + nudge * (0.5 * (face.u0 + face.u1) - u), v + nudge * (0.5 * (face.v0 + face.v1) - v));
}

}  // namespace bvmesh::target

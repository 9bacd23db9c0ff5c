// The steps of Target's projections, shared by its files: local solvers on one face's surface
// or one edge's curve (face_solvers.cpp), the closest point on the whole target
// (closest_point.cpp) and the crossing of a line with it (line_intersection.cpp). The public
// projections (target_projection.cpp) run them per point.
#pragma once

#include <gp_Vec.hxx>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <functional>

#include "core/target/target_data.h"

namespace bvmesh::target {

constexpr int kMaxNewtonIterations = 200;

inline double clampTo(double x, double lo, double hi) { return std::min(std::max(x, lo), hi); }

// Brings a periodic parameter into the face's range [lo, lo + period] so that equal points get
// equal (u, v); a parameter already in the range (u = 2 pi included) stays.
inline double wrapInto(double x, bool periodic, double period, double lo) {
  if (!periodic || !(period > 0) || (x >= lo && x <= lo + period)) return x;
  return x - period * std::floor((x - lo) / period);
}

// Trust region in parameter space: a step moves u and v each by at most half the face's
// parameter range, so that a seed near a singular point (sphere pole, where the Hessian loses
// rank in one parameter) cannot throw the iteration far away. Clipping per parameter keeps the
// well-determined parameter's step intact.
Eigen::Vector2d clipStep(const FaceData& face, const Eigen::Vector2d& step);

// Whether the derivatives span no tangent plane (a pole).
bool isSingular(const gp_Vec& su, const gp_Vec& sv);

struct NewtonResult {
  double u = 0, v = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  bool converged = false;
  bool singular = false;  // stopped where the parametrization degenerates (a pole)
  bool blocked = false;   // stopped at the trim (constrained iteration only)
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit normal at the point; 0 at a pole
};

// Minimizes |S(u, v) - q|^2 over the surface's domain: Newton with the exact Hessian and
// Levenberg-Marquardt damping (raised until the damped Hessian is positive definite and the
// step descends) as trust region; bounds handled by fixing a parameter whose descent direction
// leaves the domain.
// With `inside` set, trial points outside the face's trim are rejected like steps that do not
// descend, so the iteration stays in the trimmed face (`blocked` reports a stop at its border).
NewtonResult newtonOnSurface(const FaceData& face, FaceSurface& surface, const Eigen::Vector3d& q, double u,
                             double v, double convergence, const std::function<bool(double, double)>* inside = nullptr);

struct CurveResult {
  double t = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

// Minimizes |C(t) - q|^2 on [first, last]: Newton with the exact second derivative, Gauss-Newton
// where it is not positive or where Newton stalls, halving steps that do not descend.
CurveResult newtonOnCurve(const EdgeData& edge, GeomAdaptor_Curve& curve, const Eigen::Vector3d& q, double t,
                          double convergence);

// At a pole (one parameter undetermined, the other at its bound) Newton cannot tell along
// which meridian to leave. Picks the meridian of steepest descent from the pole and sets (u, v)
// a little way along it; false when no meridian descends (the pole is the minimum).
bool leavePole(const FaceData& face, FaceSurface& surface, const Eigen::Vector3d& q, double& u, double& v);

// Whether (u, v) (wrapped into the face's range) lies inside the face's trim. At a degenerate
// point (a pole, where one parameter is arbitrary and the trim polygon does not close), the
// test is made a little way towards the face's interior: the point belongs to the face when
// the face's points next to it do.
bool insideTrim(ThreadContext& context, const FaceData& face, int faceId, double u, double v);

// Closest point on the trimmed target (the file comment of closest_point.cpp says how); the hint
// face and (u, v) (hintFace < 0: none) warm-start it.
Foot closestOnSurface(const Target::Data& data, ThreadContext& context, const Eigen::Vector3d& q, int hintFace,
                      double hintU, double hintV);

// Whether a foot point on `face` within `radius` of `point` was already found for this point
// (the same basin: the candidate is skipped).
bool nearAnchor(const ThreadContext& context, int face, const Eigen::Vector3d& point, double radius);

// Nearest crossing of the line q + s direction with the trimmed target (either way along it);
// where there is none, the closest point (status Fallback).
Foot alongLine(const Target::Data& data, ThreadContext& context, const Eigen::Vector3d& q, const Eigen::Vector3d& direction);

}  // namespace bvmesh::target

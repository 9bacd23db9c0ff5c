// Evaluation of the target's faces and edges by one thread: the shared span polynomials of a
// B-spline face, the per-thread adaptors (and their span slots), unit normals, and the pool of
// thread contexts kept between calls.
#include <Geom_BSplineSurface.hxx>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <mutex>
#include <utility>

#include "core/target/target_data.h"

namespace bvmesh::target {

Eigen::Vector3d toEigen(const gp_Pnt& p) { return {p.X(), p.Y(), p.Z()}; }
Eigen::Vector3d toEigen(const gp_Vec& v) { return {v.X(), v.Y(), v.Z()}; }

GeomAdaptor_Surface& FaceSurface::adaptor(double u, double v) {
  if (face_.uKnots.empty()) {
    if (!adaptors_[0]) adaptors_[0] = std::make_unique<GeomAdaptor_Surface>(face_.surface);
    return *adaptors_[0];
  }
  // The span's key: which one the adaptor caches matters only for speed, not for the values.
  const auto iu = std::upper_bound(face_.uKnots.begin(), face_.uKnots.end(), u) - face_.uKnots.begin();
  const auto iv = std::upper_bound(face_.vKnots.begin(), face_.vKnots.end(), v) - face_.vKnots.begin();
  const std::int64_t span = static_cast<std::int64_t>(iu) * static_cast<std::int64_t>(face_.vKnots.size() + 1) + iv;
  int slot = 0;
  for (int k = 0; k < kSlots; ++k) {
    if (spans_[k] == span) {
      slot = k;
      break;
    }
    if (used_[k] < used_[slot]) slot = k;
  }
  if (spans_[slot] != span) {
    spans_[slot] = span;
    // GeomAdaptor_Surface evaluates a B-spline exactly on its first or last parameter by the
    // uncached de Boor path (one-sided derivatives at trimming knots), several times slower;
    // feet on the domain's border (Newton clamps there) are common. Bounds wider than the
    // domain keep every evaluation on the span cache, whose end values are the same polynomial.
    if (!adaptors_[slot]) {
      const double du = face_.uMax - face_.uMin, dv = face_.vMax - face_.vMin;
      adaptors_[slot] = std::make_unique<GeomAdaptor_Surface>(face_.surface, face_.uMin - du, face_.uMax + du,
                                                              face_.vMin - dv, face_.vMax + dv);
    }
  }
  used_[slot] = ++clock_;
  return *adaptors_[slot];
}

FaceSurface& ThreadContext::surface(int face) {
  std::unique_ptr<FaceSurface>& slot = surfaces_[static_cast<std::size_t>(face)];
  if (!slot) slot = std::make_unique<FaceSurface>(data_.faces[static_cast<std::size_t>(face)]);
  return *slot;
}

SpanPolynomials::SpanPolynomials(const Geom_BSplineSurface& surface)
    : uDegree_(surface.UDegree()), vDegree_(surface.VDegree()) {
  for (int k = 1; k <= surface.NbUKnots(); ++k) uBreaks_.push_back(surface.UKnot(k));
  for (int k = 1; k <= surface.NbVKnots(); ++k) vBreaks_.push_back(surface.VKnot(k));
  const int uSpans = static_cast<int>(uBreaks_.size()) - 1, vSpans = static_cast<int>(vBreaks_.size()) - 1;
  const int terms = (uDegree_ + 1) * (vDegree_ + 1);
  coefficients_.resize(static_cast<std::size_t>(uSpans * vSpans * terms * 3));
  for (int a = 0; a < uSpans; ++a) {
    for (int b = 0; b < vSpans; ++b) {
      const double u = uBreaks_[static_cast<std::size_t>(a)], v = vBreaks_[static_cast<std::size_t>(b)];
      const double hu = uBreaks_[static_cast<std::size_t>(a) + 1] - u, hv = vBreaks_[static_cast<std::size_t>(b) + 1] - v;
      double* out = &coefficients_[static_cast<std::size_t>((a * vSpans + b) * terms * 3)];
      // c_ij = d^(i+j) S / du^i dv^j * hu^i hv^j / (i! j!) of this span's polynomial at its corner.
      double uScale = 1.0;
      for (int i = 0; i <= uDegree_; ++i) {
        double scale = uScale;
        for (int j = 0; j <= vDegree_; ++j) {
          gp_XYZ d;
          if (i == 0 && j == 0) {
            gp_Pnt p;
            surface.LocalD0(u, v, a + 1, a + 2, b + 1, b + 2, p);
            d = p.XYZ();
          } else {
            d = surface.LocalDN(u, v, a + 1, a + 2, b + 1, b + 2, i, j).XYZ();
          }
          for (int k = 0; k < 3; ++k) out[(i * (vDegree_ + 1) + j) * 3 + k] = scale * d.Coord(k + 1);
          scale *= hv / (j + 1);
        }
        uScale *= hu / (i + 1);
      }
    }
  }
}

void SpanPolynomials::D2(double u, double v, gp_Pnt& p, gp_Vec& su, gp_Vec& sv, gp_Vec& suu, gp_Vec& svv,
                         gp_Vec& suv) const {
  const int uSpans = static_cast<int>(uBreaks_.size()) - 1, vSpans = static_cast<int>(vBreaks_.size()) - 1;
  const int a = std::clamp(static_cast<int>(std::upper_bound(uBreaks_.begin(), uBreaks_.end(), u) - uBreaks_.begin()) - 1, 0, uSpans - 1);
  const int b = std::clamp(static_cast<int>(std::upper_bound(vBreaks_.begin(), vBreaks_.end(), v) - vBreaks_.begin()) - 1, 0, vSpans - 1);
  const double u0 = uBreaks_[static_cast<std::size_t>(a)], v0 = vBreaks_[static_cast<std::size_t>(b)];
  const double hu = uBreaks_[static_cast<std::size_t>(a) + 1] - u0, hv = vBreaks_[static_cast<std::size_t>(b) + 1] - v0;
  const double s = (u - u0) / hu, t = (v - v0) / hv;
  const double* c = &coefficients_[static_cast<std::size_t>((a * vSpans + b) * (uDegree_ + 1) * (vDegree_ + 1) * 3)];
  // Horner in t for each power of s (value, first and second t-derivative: r0, r1, r2 / 2), then
  // Horner in s over those: S and its s-derivatives (s0, s1, s2 / 2), S_t and its s-derivative
  // (t0, t1), S_tt / 2 (tt).
  double s0[3] = {0, 0, 0}, s1[3] = {0, 0, 0}, s2[3] = {0, 0, 0}, t0[3] = {0, 0, 0}, t1[3] = {0, 0, 0}, tt[3] = {0, 0, 0};
  for (int i = uDegree_; i >= 0; --i) {
    const double* row = c + i * (vDegree_ + 1) * 3;
    double r0[3] = {row[vDegree_ * 3], row[vDegree_ * 3 + 1], row[vDegree_ * 3 + 2]};
    double r1[3] = {0, 0, 0}, r2[3] = {0, 0, 0};
    for (int j = vDegree_ - 1; j >= 0; --j) {
      for (int k = 0; k < 3; ++k) {
        r2[k] = r2[k] * t + r1[k];
        r1[k] = r1[k] * t + r0[k];
        r0[k] = r0[k] * t + row[j * 3 + k];
      }
    }
    for (int k = 0; k < 3; ++k) {
      s2[k] = s2[k] * s + s1[k];
      s1[k] = s1[k] * s + s0[k];
      s0[k] = s0[k] * s + r0[k];
      t1[k] = t1[k] * s + t0[k];
      t0[k] = t0[k] * s + r1[k];
      tt[k] = tt[k] * s + r2[k];
    }
  }
  p.SetCoord(s0[0], s0[1], s0[2]);
  su.SetCoord(s1[0] / hu, s1[1] / hu, s1[2] / hu);
  sv.SetCoord(t0[0] / hv, t0[1] / hv, t0[2] / hv);
  const double uu = 2 / (hu * hu), vv = 2 / (hv * hv), uv = 1 / (hu * hv);
  suu.SetCoord(uu * s2[0], uu * s2[1], uu * s2[2]);
  svv.SetCoord(vv * tt[0], vv * tt[1], vv * tt[2]);
  suv.SetCoord(uv * t1[0], uv * t1[1], uv * t1[2]);
}

GeomAdaptor_Curve& ThreadContext::curve(int edge) {
  std::unique_ptr<GeomAdaptor_Curve>& slot = curves_[static_cast<std::size_t>(edge)];
  if (!slot) {
    // Bounds wider than the edge's range, as for surfaces: the adaptor evaluates a B-spline on
    // its first or last parameter by the uncached path.
    const EdgeData& e = data_.edges[static_cast<std::size_t>(edge)];
    const double range = e.last - e.first;
    slot = std::make_unique<GeomAdaptor_Curve>(e.curve, e.first - range, e.last + range);
  }
  return *slot;
}

Eigen::Vector3d unitNormal(const FaceData& face, const gp_Vec& su, const gp_Vec& sv, double relativeTolerance) {
  const Eigen::Vector3d n = toEigen(su).cross(toEigen(sv));
  const double length = n.norm();
  if (!(length > relativeTolerance * (su.Magnitude() + sv.Magnitude()) + 1e-300) || !std::isfinite(length))
    return Eigen::Vector3d::Zero();
  return face.reversed ? Eigen::Vector3d(-n / length) : Eigen::Vector3d(n / length);
}

Eigen::Vector3d faceNormal(const FaceData& face, FaceSurface& surface, double u, double v) {
  gp_Pnt p;
  gp_Vec su, sv;
  surface.D1(u, v, p, su, sv);
  const Eigen::Vector3d n = unitNormal(face, su, sv, 1e-12);
  if (!n.isZero()) return n;
  // At a pole (sphere apex) one derivative vanishes: step towards the face's interior.
  const double uc = 0.5 * (face.u0 + face.u1);
  const double vc = 0.5 * (face.v0 + face.v1);
  surface.D1(u + 1e-6 * (uc - u), v + 1e-6 * (vc - v), p, su, sv);
  return unitNormal(face, su, sv, 0.0);
}

std::unique_ptr<ThreadContext> Target::Data::acquireContext() const {
  std::lock_guard<std::mutex> lock(poolMutex);
  if (pool.empty()) return std::make_unique<ThreadContext>(*this);
  std::unique_ptr<ThreadContext> context = std::move(pool.back());
  pool.pop_back();
  return context;
}

void Target::Data::releaseContext(std::unique_ptr<ThreadContext> context) const {
  std::lock_guard<std::mutex> lock(poolMutex);
  pool.push_back(std::move(context));
}

}  // namespace bvmesh::target

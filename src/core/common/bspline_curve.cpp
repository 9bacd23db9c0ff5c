#include "core/common/bspline_curve.h"

#include <algorithm>

#include "core/common/bspline_basis.h"

namespace bvmesh {

Eigen::Vector3d BsplineCurve::point(double t, Eigen::Vector3d* tangent) const {
  constexpr int kMaxOrder = 8;
  double values[kMaxOrder];
  double derivatives[kMaxOrder];
  const double x = std::min(upper(), std::max(lower(), t));
  const int span = findKnotSpan(knots, degree, x);
  basisFunctions(knots, degree, span, x, values, tangent ? derivatives : nullptr);
  Eigen::Vector3d result = Eigen::Vector3d::Zero();
  if (tangent) tangent->setZero();
  for (int r = 0; r <= degree; ++r) {
    const Eigen::Vector3d pole = poles.row(span - degree + r).transpose();
    result += values[r] * pole;
    if (tangent) *tangent += derivatives[r] * pole;
  }
  return result;
}

}  // namespace bvmesh

#include "core/volume/turning.h"

#include <Eigen/Geometry>

#include <cmath>

#include "core/common/math_constants.h"

namespace bvmesh::volume {

using Eigen::Vector3d;

Eigen::Vector3d turnedBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double fraction,
                              const Eigen::Vector3d& outside) {
  // About an axis normal to a and b (to a and `outside` where they are opposite), turned so that
  // the turn starts towards `outside`; b's part off that plane is added along the way.
  constexpr double kOpposite = 1e-6;
  Vector3d axis = a.cross(b);
  if (axis.norm() < kOpposite) axis = a.cross(outside);
  if (axis.norm() < kOpposite * kOpposite)
    return ((1.0 - fraction) * a + fraction * b).normalized();  // one direction
  axis.normalize();
  if (outside.squaredNorm() > 0.0 && axis.cross(a).dot(outside) < 0.0) axis = -axis;
  double angle = std::atan2(a.cross(b).dot(axis), a.dot(b));
  if (angle < 0.0) angle += 2.0 * kPi;
  const auto turned = [&](double by) -> Vector3d {
    return std::cos(by) * a + std::sin(by) * axis.cross(a) + (1.0 - std::cos(by)) * axis.dot(a) * axis;
  };
  return (turned(fraction * angle) + fraction * (b - turned(angle))).normalized();
}

Eigen::Vector3d turnedRound(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& axis,
                            double fraction, const Eigen::Vector3d& outside) {
  constexpr double kSmall = 1e-6;
  if (axis.norm() < kSmall) return turnedBetween(a, b, fraction, outside);  // no edge direction (a cusp)
  Vector3d along = axis.normalized();
  const Vector3d aSquare = a - a.dot(along) * along, bSquare = b - b.dot(along) * along;
  if (aSquare.norm() < kSmall || bSquare.norm() < kSmall) return turnedBetween(a, b, fraction, outside);
  if (along.cross(aSquare).dot(outside) < 0.0) along = -along;  // turning from a towards the outside
  double angle = std::atan2(aSquare.cross(bSquare).dot(along), aSquare.dot(bSquare));
  if (angle < 0.0) angle += 2.0 * kPi;
  const Vector3d unit = aSquare.normalized();
  const Vector3d square =
      (std::cos(fraction * angle) * unit + std::sin(fraction * angle) * along.cross(unit)) *
      ((1.0 - fraction) * aSquare.norm() + fraction * bSquare.norm());
  return (square + ((1.0 - fraction) * a.dot(along) + fraction * b.dot(along)) * along).normalized();
}

}  // namespace bvmesh::volume

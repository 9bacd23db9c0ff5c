// A B-spline curve in space on a full clamped knot vector: the iso-parametric lines of the volume
// blocks (block edges, wall-normal grid lines), evaluated point by point with their tangents.
#pragma once

#include <Eigen/Core>

#include <vector>

#include "core/common/types.h"

namespace bvmesh {

struct BsplineCurve {
  int degree = 3;
  std::vector<double> knots;  // full, clamped; #poles + degree + 1 entries
  RowMatrixX3d poles;

  double lower() const { return knots.front(); }
  double upper() const { return knots.back(); }
  // The point at t (clamped into the knot range) and, if `tangent` is not null, dC/dt.
  Eigen::Vector3d point(double t, Eigen::Vector3d* tangent = nullptr) const;
};

}  // namespace bvmesh

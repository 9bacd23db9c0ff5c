// Directions turned part of the way from one unit direction to another at a constant rate: the
// grid lines of a knife edge's fan and of the splay bands.
#pragma once

#include <Eigen/Core>

namespace bvmesh::volume {

// The unit direction at `fraction` of the turn from unit `a` to unit `b` at a constant rate: in
// their plane the short way round, or, with `outside` given, the way round through the side
// `outside` points to (opposite a and b: in the plane of a and `outside`; without it they must
// not be opposite).
Eigen::Vector3d turnedBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double fraction,
                              const Eigen::Vector3d& outside = Eigen::Vector3d::Zero());

// The unit direction at `fraction` of the turn from unit `a` to unit `b` round `axis` (an edge's
// direction; not unit): their parts square to the axis turn about it at a constant rate, the
// way round through the side `outside` points to, their lengths and their parts along the axis
// blended linearly. Two lines leaning alike along the axis give lines that all lean so, evenly
// spaced round it (turnedBetween would turn them in their own plane, which holds the axis).
// Without an axis, or with a or b along it, turnedBetween.
Eigen::Vector3d turnedRound(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& axis,
                            double fraction, const Eigen::Vector3d& outside);

}  // namespace bvmesh::volume

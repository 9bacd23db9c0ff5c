// Checks of point arrays that come from outside the core (control points, vertex positions): the
// row count and finite coordinates, with messages that name the offending row. NaN or infinite
// points would otherwise pass through the linear algebra unnoticed and come out as NaN results.
#pragma once

#include <string>

#include "core/common/types.h"

namespace bvmesh {

// Throws InvalidInputError "<noun> <i> has a non-finite coordinate (x, y, z)" for the first row
// holding a NaN or an infinity.
void checkFinitePoints(const Eigen::Ref<const RowMatrixX3d>& points, const std::string& noun = "vertex");

// Throws InvalidInputError "expected <expected> x 3 <what>, got <rows> x 3" for another row count,
// then checks the rows as checkFinitePoints.
void checkPointCount(const RowMatrixX3d& points, Eigen::Index expected, const char* what = "control points");

}  // namespace bvmesh

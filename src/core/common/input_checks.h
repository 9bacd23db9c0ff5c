// Checks of input from outside the core, with messages that name the offending item: point arrays
// (control points, vertex positions: the row count and finite coordinates) and option values
// (finite, in range). NaN or infinite values would otherwise pass through the computations
// unnoticed and come out as NaN results or unrelated failures.
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

// Throws InvalidInputError "<name> must be a finite number >= <lowest>, got <value>" (with
// `strict`: "> <lowest>").
void checkFiniteAtLeast(double value, double lowest, const std::string& name, bool strict = false);

}  // namespace bvmesh

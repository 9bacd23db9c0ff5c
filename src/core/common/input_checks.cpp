#include "core/common/input_checks.h"

#include <cmath>
#include <sstream>

#include "core/common/errors.h"

namespace bvmesh {

void checkFinitePoints(const Eigen::Ref<const RowMatrixX3d>& points, const std::string& noun) {
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    if (points.row(i).allFinite()) continue;
    std::ostringstream message;
    message << noun << " " << i << " has a non-finite coordinate (" << points(i, 0) << ", " << points(i, 1) << ", "
            << points(i, 2) << ")";
    throw InvalidInputError(message.str());
  }
}

void checkPointCount(const RowMatrixX3d& points, Eigen::Index expected, const char* what) {
  if (points.rows() != expected) {
    throw InvalidInputError("expected " + std::to_string(expected) + " x 3 " + what + ", got " +
                            std::to_string(points.rows()) + " x 3");
  }
  checkFinitePoints(points);
}

void checkFiniteAtLeast(double value, double lowest, const std::string& name, bool strict) {
  if (std::isfinite(value) && (strict ? value > lowest : value >= lowest)) return;
  std::ostringstream message;
  message << name << " must be a finite number " << (strict ? "> " : ">= ") << lowest << ", got " << value;
  throw InvalidInputError(message.str());
}

}  // namespace bvmesh

#include "core/common/number_text.h"

#include <cstdio>

namespace bvmesh {

std::string numberText(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

std::string coordinatesText(const Eigen::Vector3d& point) {
  return numberText(point.x()) + ", " + numberText(point.y()) + ", " + numberText(point.z());
}

}  // namespace bvmesh

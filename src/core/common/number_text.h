// Numbers and points in messages, to six significant digits at any scale: std::to_string prints
// 1e-9 as "0.000000" (a model in metres with micrometre features said "0.000000 apart").
#pragma once

#include <Eigen/Core>

#include <string>

namespace bvmesh {

std::string numberText(double value);

// "x, y, z"
std::string coordinatesText(const Eigen::Vector3d& point);

}  // namespace bvmesh

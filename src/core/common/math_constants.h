// Mathematical constants of the core (C++17 has no std::numbers; M_PI is not standard C++).
#pragma once

namespace bvmesh {

inline constexpr double kPi = 3.14159265358979323846;

}  // namespace bvmesh

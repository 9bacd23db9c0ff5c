// What the volume benchmarks share: wall-clock seconds, the peak resident memory, and the wall
// they grow their meshes around (the Catmull-Clark limit surface of a cube refined `levels`
// times, 6 * 4^levels quads).
#pragma once

#include <sys/resource.h>

#include <array>
#include <chrono>
#include <vector>

#include "core/subdiv/subdivision.h"
#include "core/surface/limit_points.h"

using Clock = std::chrono::steady_clock;

inline double seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

inline long peakKilobytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}

inline bvmesh::surface::QuadControlMesh refinedCube(int levels) {
  const std::vector<Eigen::Vector3d> points{{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                            {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  const std::vector<std::array<int, 4>> quads{{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                              {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  bvmesh::ControlMesh mesh = bvmesh::surface::toControlMesh(bvmesh::surface::makeQuadControlMesh(points, quads));
  for (int l = 0; l < levels; ++l) mesh = bvmesh::subdivide(mesh).mesh;
  return bvmesh::surface::toQuadControlMesh(mesh);
}

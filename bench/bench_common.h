// What the benchmarks share: wall-clock seconds, the peak resident memory, growth exponents, and
// the wall they grow their meshes around (the Catmull-Clark limit surface of a cube refined
// `levels` times, 6 * 4^levels quads).
#pragma once

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <type_traits>
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

// The peak resident memory in MB since the last resetPeak() (Linux >= 4.0: writing 5 to
// clear_refs resets VmHWM), so that each stage of a run reports its own.
inline double vmHwmMegabytes() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmHWM:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;
  }
  return 0.0;
}

inline void resetPeak() { std::ofstream("/proc/self/clear_refs") << "5"; }

// Runs `measure` in a forked child, so that each run's peak memory is its own, and hands its
// (trivially copyable) result back through a pipe. False when the child failed.
template <class Figures, class Measure>
bool measureInChild(Measure&& measure, Figures& figures) {
  static_assert(std::is_trivially_copyable_v<Figures>, "the figures travel through a pipe as bytes");
  int channel[2];
  if (pipe(channel) != 0) return false;
  const pid_t child = fork();
  if (child == 0) {
    close(channel[0]);
    const Figures measured = measure();
    const ssize_t written = write(channel[1], &measured, sizeof measured);
    _exit(written == static_cast<ssize_t>(sizeof measured) ? 0 : 1);
  }
  close(channel[1]);
  const ssize_t got = read(channel[0], &figures, sizeof figures);
  close(channel[0]);
  int status = 0;
  waitpid(child, &status, 0);
  return got == static_cast<ssize_t>(sizeof figures) && status == 0;
}

// Least-squares slope of log y over log x: the growth exponent (1 = linear).
inline double slope(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t k = x.size();
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < k; ++i) {
    sx += std::log(x[i]);
    sy += std::log(y[i]);
    sxx += std::log(x[i]) * std::log(x[i]);
    sxy += std::log(x[i]) * std::log(y[i]);
  }
  return (static_cast<double>(k) * sxy - sx * sy) / (static_cast<double>(k) * sxx - sx * sx);
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

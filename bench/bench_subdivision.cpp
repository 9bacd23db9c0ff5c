// Step 1 and 2 costs against mesh size: control mesh construction (validation), one
// subdivision step with its operator, the limit sample operators (A and the two tangent
// operators) and the limit evaluator (patch table), for closed quad tori with one crease loop
// of 1k, 10k, 100k and 1M faces. Each size runs in a forked child so that its peak memory
// (VmHWM growth) is its own. Prints the times, the memory and the log-log growth exponents.
//
//   build/bench/bench_subdivision [max_faces]      (default 1000000)
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "core/subdiv/limit_evaluator.h"
#include "core/subdiv/limit_samples.h"
#include "core/subdiv/subdivision.h"

namespace {

using bvmesh::ControlMesh;
using bvmesh::RowMatrixX2i;
using bvmesh::RowMatrixX3d;

constexpr int kStages = 4;
const char* const kStageNames[kStages] = {"construct", "subdivide", "limit ops", "evaluator"};

struct Figures {
  double seconds[kStages];
  double peakMegabytes[kStages];  // VmHWM growth over the child's start
  int faces;
  int samples;
};

// Torus of n x m quads (major radius 2, minor 1) with the loop j = 0 creased.
ControlMesh torus(int n, int m) {
  RowMatrixX3d vertices(n * m, 3);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) {
      const double a = 2.0 * M_PI * i / n, b = 2.0 * M_PI * j / m;
      vertices.row(i * m + j) << (2.0 + std::cos(b)) * std::cos(a), (2.0 + std::cos(b)) * std::sin(a), std::sin(b);
    }
  }
  std::vector<int> sizes(static_cast<size_t>(n) * static_cast<size_t>(m), 4), indices;
  indices.reserve(4 * sizes.size());
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) {
      const int i1 = (i + 1) % n, j1 = (j + 1) % m;
      indices.insert(indices.end(), {i * m + j, i1 * m + j, i1 * m + j1, i * m + j1});
    }
  }
  RowMatrixX2i creases(n, 2);
  for (int i = 0; i < n; ++i) creases.row(i) << i * m, ((i + 1) % n) * m;
  return ControlMesh(vertices, sizes, indices, creases);
}

double vmHwmMegabytes() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmHWM:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;
  }
  return 0.0;
}

// Resets the peak so that each stage reports its own (Linux >= 4.0: write 5 to clear_refs).
void resetPeak() { std::ofstream("/proc/self/clear_refs") << "5"; }

Figures measure(int n, int m) {
  Figures figures{};
  using Clock = std::chrono::steady_clock;
  const auto stage = [&](int index, auto&& work) {
    resetPeak();
    const double before = vmHwmMegabytes();
    const auto start = Clock::now();
    work();
    figures.seconds[index] = std::chrono::duration<double>(Clock::now() - start).count();
    figures.peakMegabytes[index] = vmHwmMegabytes() - before;
  };
  std::unique_ptr<ControlMesh> mesh;
  stage(0, [&] { mesh = std::make_unique<ControlMesh>(torus(n, m)); });
  figures.faces = mesh->numFaces();
  stage(1, [&] { bvmesh::subdivide(*mesh); });
  stage(2, [&] { figures.samples = bvmesh::LimitSamples(*mesh).size(); });
  stage(3, [&] { const bvmesh::LimitEvaluator evaluator(*mesh); });
  return figures;
}

double slope(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t k = x.size();
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < k; ++i) {
    sx += std::log(x[i]);
    sy += std::log(y[i]);
    sxx += std::log(x[i]) * std::log(x[i]);
    sxy += std::log(x[i]) * std::log(y[i]);
  }
  return (k * sxy - sx * sy) / (k * sxx - sx * sx);
}

}  // namespace

int main(int argc, char** argv) {
  const int maxFaces = argc > 1 ? std::atoi(argv[1]) : 1000000;
  const std::vector<std::pair<int, int>> shapes = {{40, 25}, {125, 80}, {400, 250}, {1250, 800}};
  std::vector<Figures> results;
  std::printf("%9s %8s", "faces", "samples");
  for (const char* name : kStageNames) std::printf(" | %10s s %7s MB", name, "peak");
  std::printf("\n");
  for (const auto& [n, m] : shapes) {
    if (n * m > maxFaces) break;
    int channel[2];
    if (pipe(channel) != 0) return 1;
    const pid_t child = fork();
    if (child == 0) {
      close(channel[0]);
      const Figures figures = measure(n, m);
      const ssize_t written = write(channel[1], &figures, sizeof figures);
      _exit(written == static_cast<ssize_t>(sizeof figures) ? 0 : 1);
    }
    close(channel[1]);
    Figures figures{};
    const ssize_t got = read(channel[0], &figures, sizeof figures);
    close(channel[0]);
    int status = 0;
    waitpid(child, &status, 0);
    if (got != static_cast<ssize_t>(sizeof figures) || status != 0) {
      std::fprintf(stderr, "size %d x %d failed\n", n, m);
      return 1;
    }
    std::printf("%9d %8d", figures.faces, figures.samples);
    for (int s = 0; s < kStages; ++s) std::printf(" | %12.4f %9.1f", figures.seconds[s], figures.peakMegabytes[s]);
    std::printf("\n");
    std::fflush(stdout);
    results.push_back(figures);
  }
  if (results.size() < 2) return 0;
  std::vector<double> faces;
  for (const Figures& f : results) faces.push_back(f.faces);
  std::printf("growth exponents (log-log least-squares slope over all sizes; 1 = linear):\n");
  for (int s = 0; s < kStages; ++s) {
    std::vector<double> times, memory;
    for (const Figures& f : results) {
      times.push_back(f.seconds[s]);
      memory.push_back(std::max(f.peakMegabytes[s], 1e-3));
    }
    std::printf("  %-10s time %.2f  memory %.2f\n", kStageNames[s], slope(faces, times), slope(faces, memory));
  }
  return 0;
}

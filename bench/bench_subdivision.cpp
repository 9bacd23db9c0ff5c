// Step 1 and 2 costs against mesh size: control mesh construction (validation), one
// subdivision step with its operator, the limit sample operators (A and the two tangent
// operators) and the limit evaluator (patch table), for closed quad tori with one crease loop
// of 1k, 10k, 100k and 1M faces. Baseline: OpenSubdiv's LimitStencilTableFactory at the same
// sample locations (adaptive refinement + patch table + limit stencils, positions and first
// derivatives), the ready-made way to get the same operators. Each size runs in a forked child so
// that its peak memory (VmHWM growth) is its own. Prints the times, the memory, the ratio of our
// limit operator build to the baseline and the log-log growth exponents.
//
//   build/bench/bench_subdivision [max_faces]      (default 1000000)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/stencilTableFactory.h>

#include "core/subdiv/limit_evaluator.h"
#include "core/subdiv/limit_samples.h"
#include "core/subdiv/osd_refiner.h"
#include "core/subdiv/subdivision.h"
#include "bench_common.h"

namespace {

using bvmesh::ControlMesh;
using bvmesh::RowMatrixX2i;
using bvmesh::RowMatrixX3d;

constexpr int kStages = 5;
const char* const kStageNames[kStages] = {"construct", "subdivide", "limit ops", "evaluator",
                                          "OSD limit"};

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
      vertices.row(i * m + j) << (2.0 + std::cos(b)) * std::cos(a),
          (2.0 + std::cos(b)) * std::sin(a), std::sin(b);
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

// The baseline: OpenSubdiv's limit stencils at the given locations.
void osdLimitStencils(const ControlMesh& mesh, const std::vector<bvmesh::SurfaceLocation>& at) {
  namespace Far = OpenSubdiv::Far;
  const auto refiner = bvmesh::osd::createRefiner(mesh, {});
  Far::TopologyRefiner::AdaptiveOptions adaptive(6);
  adaptive.useInfSharpPatch = true;
  refiner->RefineAdaptive(adaptive);
  std::vector<double> u, v;
  for (const auto& location : at) {
    u.push_back(location.u);
    v.push_back(location.v);
  }
  using Factory = Far::LimitStencilTableFactoryReal<double>;
  Factory::LocationArrayVec arrays(at.size());
  for (size_t i = 0; i < at.size(); ++i) {
    arrays[i].ptexIdx = at[i].face;
    arrays[i].numLocations = 1;
    arrays[i].s = &u[i];
    arrays[i].t = &v[i];
  }
  const std::unique_ptr<const Far::LimitStencilTableReal<double>> table(
      Factory::Create(*refiner, arrays));
  if (table->GetNumStencils() != static_cast<int>(at.size())) std::abort();
}

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
  std::vector<bvmesh::SurfaceLocation> locations;
  stage(2, [&] {
    const bvmesh::LimitSamples samples(*mesh);
    figures.samples = samples.size();
    locations = samples.locations();
  });
  stage(3, [&] { const bvmesh::LimitEvaluator evaluator(*mesh); });
  stage(4, [&] { osdLimitStencils(*mesh, locations); });
  return figures;
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
    Figures figures{};
    if (!measureInChild([&] { return measure(n, m); }, figures)) {
      std::fprintf(stderr, "size %d x %d failed\n", n, m);
      return 1;
    }
    std::printf("%9d %8d", figures.faces, figures.samples);
    for (int s = 0; s < kStages; ++s) {
      std::printf(" | %12.4f %9.1f", figures.seconds[s], figures.peakMegabytes[s]);
    }
    std::printf("\n");
    std::fflush(stdout);
    results.push_back(figures);
  }
  std::printf("limit ops time / OpenSubdiv LimitStencilTableFactory time:");
  for (const Figures& f : results) std::printf(" %.2f", f.seconds[2] / f.seconds[4]);
  std::printf("\n");
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
    std::printf("  %-10s time %.2f  memory %.2f\n", kStageNames[s], slope(faces, times),
                slope(faces, memory));
  }
  return 0;
}

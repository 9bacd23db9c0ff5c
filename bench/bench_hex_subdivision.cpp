// Volumetric Catmull-Clark against mesh size: one step (validation, topology, the boundary's
// surface subdivision, the operator and the refined mesh) on a shell of hexahedra around a cube
// refined `levels` times (valence-3 edges at the cube's corners), of about 10k, 100k and 1M cells.
// Baseline in the same run: applying the operator once to the points (what a fitting pass pays
// per use of it), so the build cost reads as a number of applications. Each size runs in a forked
// child so its peak memory (VmHWM growth) is its own. Prints time, memory, operator entries and
// the log-log growth exponents (1 = linear).
//
//   build/bench/bench_hex_subdivision [max_cells]      (default 1100000)
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "bench_common.h"
#include "core/volume/hex_subdivision.h"

namespace {

using bvmesh::volume::BoundaryCondition;
using bvmesh::volume::HexMesh;

struct Figures {
  long cells;
  long newPoints;
  long entries;
  double stepSeconds;
  double stepPeakMegabytes;
  double applySeconds;
};

// The cube's refined quads pushed out to radius 1 + layer / layers (the wall at radius 1, the
// far field at 2), one hex per quad and layer.
HexMesh cubeShell(int levels, int layers) {
  const bvmesh::ControlMesh wall = bvmesh::surface::toControlMesh(refinedCube(levels));
  const int perLayer = wall.numVertices();
  HexMesh mesh;
  mesh.points.resize(static_cast<Eigen::Index>(perLayer) * (layers + 1), 3);
  for (int layer = 0; layer <= layers; ++layer) {
    for (int v = 0; v < perLayer; ++v) {
      mesh.points.row(static_cast<Eigen::Index>(layer) * perLayer + v) =
          (1.0 + static_cast<double>(layer) / layers) * wall.vertices().row(v).normalized();
    }
  }
  for (int layer = 0; layer < layers; ++layer) {
    for (int f = 0; f < wall.numFaces(); ++f) {
      std::array<int, 8> cell{};
      for (int k = 0; k < 4; ++k) {
        cell[static_cast<size_t>(k)] = layer * perLayer + wall.faceVertex(f, k);
        cell[static_cast<size_t>(k + 4)] = (layer + 1) * perLayer + wall.faceVertex(f, k);
      }
      mesh.cells.push_back(cell);
    }
  }
  for (int f = 0; f < wall.numFaces(); ++f) {
    std::array<int, 4> inner{}, outer{};
    for (int k = 0; k < 4; ++k) {
      inner[static_cast<size_t>(k)] = wall.faceVertex(f, k);
      outer[static_cast<size_t>(k)] = layers * perLayer + wall.faceVertex(f, k);
    }
    mesh.boundaryFaces.push_back(inner);
    mesh.boundaryConditions.push_back(BoundaryCondition::Wall);
    mesh.boundaryFaces.push_back(outer);
    mesh.boundaryConditions.push_back(BoundaryCondition::Farfield);
  }
  return mesh;
}

Figures measure(int levels, int layers) {
  const HexMesh mesh = cubeShell(levels, layers);
  Figures figures{};
  figures.cells = static_cast<long>(mesh.cells.size());
  resetPeak();
  const double before = vmHwmMegabytes();
  const auto start = Clock::now();
  const bvmesh::volume::HexSubdivisionResult result = bvmesh::volume::subdivideHexMesh(mesh);
  figures.stepSeconds = seconds(start);
  figures.stepPeakMegabytes = vmHwmMegabytes() - before;
  figures.newPoints = static_cast<long>(result.mesh.points.rows());
  figures.entries = static_cast<long>(result.subdivisionOperator.nonZeros());
  const auto applyStart = Clock::now();
  const bvmesh::RowMatrixX3d moved = result.subdivisionOperator * mesh.points;
  figures.applySeconds = seconds(applyStart);
  if (moved.rows() != result.mesh.points.rows()) std::abort();
  return figures;
}

}  // namespace

int main(int argc, char** argv) {
  const long maxCells = argc > 1 ? std::atol(argv[1]) : 1100000;
  // 6 * 4^levels quads times layers: 10752, 98304, 983040 cells.
  const std::vector<std::pair<int, int>> shapes = {{4, 7}, {5, 16}, {6, 40}};
  std::printf("%9s %10s %11s | %9s %9s %10s | %9s %8s\n", "cells", "new points", "entries", "step s", "peak MB",
              "bytes/cell", "apply s", "ratio");
  std::vector<Figures> results;
  for (const auto& [levels, layers] : shapes) {
    if (6L * (1L << (2 * levels)) * layers > maxCells) break;
    Figures figures{};
    if (!measureInChild([&] { return measure(levels, layers); }, figures)) {
      std::fprintf(stderr, "cube shell level %d x %d layers failed\n", levels, layers);
      return 1;
    }
    std::printf("%9ld %10ld %11ld | %9.3f %9.1f %10.0f | %9.4f %8.1f\n", figures.cells, figures.newPoints,
                figures.entries, figures.stepSeconds, figures.stepPeakMegabytes,
                figures.stepPeakMegabytes * 1048576.0 / static_cast<double>(figures.cells), figures.applySeconds,
                figures.stepSeconds / figures.applySeconds);
    std::fflush(stdout);
    results.push_back(figures);
  }
  std::printf("ratio: one step / one application of its operator\n");
  if (results.size() < 2) return 0;
  std::vector<double> cells, times, memory;
  for (const Figures& f : results) {
    cells.push_back(static_cast<double>(f.cells));
    times.push_back(f.stepSeconds);
    memory.push_back(std::max(f.stepPeakMegabytes, 1e-3));
  }
  std::printf("growth exponents (log-log least-squares slope over all sizes; 1 = linear): time %.2f  memory %.2f\n",
              slope(cells, times), slope(cells, memory));
  return 0;
}

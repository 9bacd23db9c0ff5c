// Volume stage costs: the block mesh (wall charts, marching, layer interpolation) around the limit
// surface of a cube refined 2, 3 and 4 times (the wall growing 4x per level), and the evaluation
// of the blocks on tensor grids against per-point evaluation of the same blocks measured in the
// same run (the naive way: every point on its own, basis functions and 64-pole sums).
//
//   build/bench/bench_volume [points_per_block_direction]   (default 64)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "core/volume/volume_blocks.h"
#include "bench_common.h"

using bvmesh::RowMatrixX3d;

int main(int argc, char** argv) {
  const int perDirection = argc > 1 ? std::atoi(argv[1]) : 64;
  bvmesh::volume::VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.02;
  options.farfieldDistance = 40.0;
  std::printf("%-6s %10s %8s %8s %12s %10s %9s\n", "level", "wall quads", "blocks", "layers", "poles", "time s",
              "min SJ");
  bvmesh::volume::VolumeMesh largest;
  for (int level = 2; level <= 4; ++level) {
    const bvmesh::surface::QuadControlMesh wall = refinedCube(level);
    const auto start = Clock::now();
    bvmesh::volume::VolumeMesh result = bvmesh::volume::generateVolumeMesh(wall, options);
    const double time = seconds(start);
    long poles = 0;
    for (const auto& block : result.blocks.blocks()) poles += static_cast<long>(block.volume.poles().rows());
    double worst = 1.0;
    for (double q : result.layerMinScaledJacobian) worst = std::min(worst, q);
    std::printf("%-6d %10ld %8d %8zu %12ld %10.3f %9.3f\n", level, static_cast<long>(wall.faces.rows()),
                result.blocks.blockCount(), result.layerDistance.size(), poles, time, worst);
    largest = std::move(result);
  }
  // Grid evaluation of every block of the largest mesh, positions and first derivatives.
  auto gridOf = [perDirection](const bvmesh::volume::BsplineVolume& volume) {
    std::array<std::vector<double>, 3> at;
    for (int d = 0; d < 3; ++d) {
      for (int s = 0; s < perDirection; ++s) {
        at[static_cast<size_t>(d)].push_back(volume.lower(d) + (volume.upper(d) - volume.lower(d)) * s / (perDirection - 1));
      }
    }
    return at;
  };
  long points = 0;
  const auto start = Clock::now();
  for (const auto& block : largest.blocks.blocks()) {
    const auto at = gridOf(block.volume);
    RowMatrixX3d x, du, dv, dw;
    block.volume.evaluateGrid(at[0], at[1], at[2], x, &du, &dv, &dw);
    points += x.rows();
  }
  const double gridTime = seconds(start);
  long positionPoints = 0;
  const auto positionStart = Clock::now();
  for (const auto& block : largest.blocks.blocks()) {
    const auto at = gridOf(block.volume);
    RowMatrixX3d x;
    block.volume.evaluateGrid(at[0], at[1], at[2], x);
    positionPoints += x.rows();
  }
  const double positionTime = seconds(positionStart);
  // Baseline: the same kind of points one by one, on a sample of them.
  const auto& volume = largest.blocks.blocks()[0].volume;
  const int sample = 200000;
  RowMatrixX3d parameters(sample, 3);
  for (int p = 0; p < sample; ++p) {
    for (int d = 0; d < 3; ++d) {
      parameters(p, d) = volume.lower(d) + (volume.upper(d) - volume.lower(d)) * ((p * (d + 7) * 2654435761u) % 100000) / 99999.0;
    }
  }
  const auto naiveStart = Clock::now();
  RowMatrixX3d x, du, dv, dw;
  volume.evaluate(parameters, x, &du, &dv, &dw);
  const double naiveTime = seconds(naiveStart);
  const double gridRate = points / gridTime;
  const double naiveRate = sample / naiveTime;
  std::printf("grid evaluation with derivatives: %ld points in %.3f s = %.1f M points/s\n", points, gridTime, gridRate / 1e6);
  std::printf("grid evaluation, positions only: %.1f M points/s\n", positionPoints / positionTime / 1e6);
  std::printf("per-point evaluation (baseline): %.2f M points/s; grid / per-point = %.1f\n", naiveRate / 1e6,
              gridRate / naiveRate);
  std::printf("peak memory %.0f MB\n", peakKilobytes() / 1024.0);
  return 0;
}

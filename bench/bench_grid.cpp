// Volume output costs: the B-spline blocks around the limit surface of a cube (refined 3 times)
// refined into a stretched, point-matched grid of about 1 M cells (first cell height 1e-5 of the
// body, growth <= 1.2), against per-point evaluation of as many points measured in the same run
// (the naive way: basis functions and 64-pole sums for every point on its own); then each writer
// and the quality metrics, with time and the growth of the peak resident memory per cell.
//
//   build/bench/bench_grid [target_cells]   (default 1000000)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "core/grid/hex_topology.h"
#include "core/grid/refinement.h"
#include "core/io/cgns_writer.h"
#include "core/io/openfoam_writer.h"
#include "core/io/plot3d_io.h"
#include "core/io/vtk_writer.h"
#include "core/quality/cell_quality.h"
#include "core/volume/volume_blocks.h"
#include "bench_common.h"

namespace {

// Runs `step`, prints its time and how far it raised the peak memory, per cell.
void measure(const char* name, long long cells, const std::function<void()>& step) {
  const long before = peakKilobytes();
  const auto start = Clock::now();
  step();
  const double time = seconds(start);
  const double grown = 1024.0 * static_cast<double>(peakKilobytes() - before);
  std::printf("%-28s %8.3f s   peak memory +%6.1f bytes/cell\n", name, time, grown / static_cast<double>(cells));
}

}  // namespace

int main(int argc, char** argv) {
  const long long target = argc > 1 ? std::atoll(argv[1]) : 1000000;
  bvmesh::volume::VolumeMeshOptions volumeOptions;
  volumeOptions.boundaryLayerThickness = 0.02;
  volumeOptions.farfieldDistance = 40.0;
  const bvmesh::volume::VolumeMesh volume = bvmesh::volume::generateVolumeMesh(refinedCube(3), volumeOptions);

  bvmesh::grid::RefinementOptions options;
  options.normalPoints = 0;
  options.firstCellHeight = 1e-5 * 2.0;
  options.targetCells = target;
  const auto refineStart = Clock::now();
  const long beforeRefine = peakKilobytes();
  const bvmesh::grid::RefinedGrid refined = bvmesh::grid::refineBlockMesh(volume.blocks, options);
  const double refineTime = seconds(refineStart);
  const bvmesh::grid::StructuredGrid& grid = refined.grid;
  const long long cells = grid.cellCount();
  const long long points = grid.pointCount();
  std::printf("grid: %d blocks, %lld cells, %lld points, %d wall-normal points, first height %.3g..%.3g, growth <= %.4f\n",
              grid.blockCount(), cells, points, refined.normalPoints, refined.firstCellHeightMin,
              refined.firstCellHeightMax, refined.growthMax);
  std::printf("%-28s %8.3f s   %.1f M points/s, peak memory +%.1f bytes/cell\n", "refinement", refineTime,
              static_cast<double>(points) / refineTime / 1e6,
              1024.0 * static_cast<double>(peakKilobytes() - beforeRefine) / static_cast<double>(cells));

  // Baseline: as many points evaluated one by one at scattered parameters of the blocks.
  const auto& blocks = volume.blocks.blocks();
  const Eigen::Index perBlock = points / static_cast<Eigen::Index>(blocks.size());
  const auto naiveStart = Clock::now();
  for (const auto& block : blocks) {
    bvmesh::RowMatrixX3d parameters(perBlock, 3);
    for (Eigen::Index p = 0; p < perBlock; ++p) {
      for (int d = 0; d < 3; ++d) {
        const double fraction = static_cast<double>((static_cast<unsigned long long>(p) * (d + 7) * 2654435761ull) % 100000) / 99999.0;
        parameters(p, d) = block.volume.lower(d) + (block.volume.upper(d) - block.volume.lower(d)) * fraction;
      }
    }
    bvmesh::RowMatrixX3d x;
    block.volume.evaluate(parameters, x);
  }
  const double naiveTime = seconds(naiveStart);
  std::printf("%-28s %8.3f s   %.1f M points/s; refinement / per-point = %.2f\n", "per-point evaluation (baseline)",
              naiveTime, static_cast<double>(points) / naiveTime / 1e6, naiveTime / refineTime);

  const std::filesystem::path folder = std::filesystem::temp_directory_path() / "bvmesh_bench_grid";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  std::optional<bvmesh::grid::HexTopology> topology;
  measure("hex topology", cells, [&] { topology.emplace(grid); });
  measure("quality (all metrics)", cells, [&] { bvmesh::quality::measureCellQuality(*topology); });
  measure("CGNS", cells, [&] { bvmesh::io::writeCgns(grid, (folder / "grid.cgns").string()); });
  measure("OpenFOAM polyMesh", cells, [&] { bvmesh::io::writeOpenFoamCase(*topology, (folder / "case").string()); });
  measure("Plot3D binary", cells, [&] { bvmesh::io::writePlot3d(grid, (folder / "grid.p3d").string()); });
  measure("VTK multiblock", cells, [&] { bvmesh::io::writeVtk(grid, (folder / "grid.vtm").string()); });
  std::printf("peak memory %.0f MB; coordinates %.0f MB\n", peakKilobytes() / 1024.0,
              static_cast<double>(points) * 24.0 / 1048576.0);
  std::filesystem::remove_all(folder);
  return 0;
}

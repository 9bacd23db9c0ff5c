// Volume output costs: B-spline blocks refined into a stretched, point-matched grid of about 1 M
// cells, against per-point evaluation of as many points measured in the same run (each the
// fastest of 5 runs; the naive way:
// BsplineVolume::evaluate, basis functions and 64-pole sums for every point on its own, at a
// lattice of the same size as each block's grid), both in memory new from the kernel and in memory
// the allocator kept (on a virtual machine a new page's first touch can cost more than the
// arithmetic done on it; the cost per page is measured first); then each writer and the quality
// metrics. Each step runs in a child process of its own, so its peak memory is its own and not
// the largest of the steps before it.
//
//   build/bench/bench_grid [target_cells]
//       the blocks around the limit surface of a cube (refined 3 times), first cell height 1e-5
//       of the body, growth <= 1.2
//   build/bench/bench_grid target_cells block_file reference_length reynolds_number
//       a block file (BlockMesh.write; bench_volume_m6.py writes the M6's) refined with the
//       euler and rans presets of bvmesh.grid, the writers on the euler grid
#include <malloc.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <string>

#include "core/grid/hex_topology.h"
#include "core/grid/refinement.h"
#include "core/io/cgns_writer.h"
#include "core/io/openfoam_writer.h"
#include "core/io/plot3d_io.h"
#include "core/io/vtk_writer.h"
#include "core/quality/cell_quality.h"
#include "core/volume/block_mesh_io.h"
#include "core/volume/volume_blocks.h"
#include "bench_common.h"

namespace {

using bvmesh::grid::RefinementOptions;

constexpr double kCoordinateBytes = 24.0;  // three doubles per point

// Runs `step` in a forked copy of this process (which starts at this one's resident size) and
// prints its time and how far it raised the resident memory, per cell: what the step itself
// needs, whatever the steps before it needed.
void measure(const char* name, long long cells, const std::function<void()>& step) {
  std::fflush(stdout);
  const pid_t child = fork();
  if (child == 0) {
    const long before = peakKilobytes();
    const auto start = Clock::now();
    step();
    const double time = seconds(start);
    const double grown = 1024.0 * static_cast<double>(peakKilobytes() - before);
    std::printf("| %-30s | %8.3f | %8.1f |\n", name, time, grown / static_cast<double>(cells));
    std::fflush(stdout);
    _exit(0);
  }
  int status = 0;
  waitpid(child, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) std::printf("| %-30s | failed | |\n", name);
}

// How a run finds its memory. Fresh: every large allocation is pages new from the kernel, as for
// a process's first grid; kept: the allocator keeps what the run before freed, as for a grid
// refined again. Both are set explicitly: glibc's own choice (a threshold that moves with what
// was freed) made the fastest of 5 runs fresh in one build and kept in the next.
enum class Memory { Fresh, Kept };

const char* memoryName(Memory memory) { return memory == Memory::Fresh ? "fresh" : "kept"; }

void useMemory(Memory memory) {
  if (memory == Memory::Fresh) {
    // Fixed: each large block mapped when allocated, unmapped when freed.
    mallopt(M_MMAP_THRESHOLD, 128 * 1024);
    mallopt(M_TRIM_THRESHOLD, 0);
  } else {
    mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);  // glibc's largest: every block of these grids on the heap
    mallopt(M_TRIM_THRESHOLD, std::numeric_limits<int>::max());
  }
}

// Microseconds to touch one page of memory new from the kernel (the fastest of 3 passes over
// 64 MB): what a grid's fresh memory costs on this machine before any arithmetic.
double freshPageMicroseconds() {
  const size_t bytes = size_t{64} << 20;
  const auto page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
  double fastest = std::numeric_limits<double>::infinity();
  for (int run = 0; run < 3; ++run) {
    void* mapped = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mapped == MAP_FAILED) return std::numeric_limits<double>::quiet_NaN();
    auto* memory = static_cast<volatile char*>(mapped);
    const auto start = Clock::now();
    for (size_t at = 0; at < bytes; at += page) memory[at] = 1;
    fastest = std::min(fastest, seconds(start));
    munmap(mapped, bytes);
  }
  return 1e6 * fastest / static_cast<double>(bytes / page);
}

// Refinement against per-point evaluation of as many points, block by block, in the same run and
// with the same `memory` (the per-point results allocated for every run, as the refinement's
// grid is). Each is timed kRuns times and the fastest run counts (the machine is shared: single
// runs vary by 2x); the peak memory is the first refinement's.
constexpr int kRuns = 5;

void compareWithPerPoint(const char* preset, const bvmesh::volume::BlockMesh& blocks,
                         const RefinementOptions& options, Memory memory) {
  std::fflush(stdout);
  const pid_t child = fork();
  if (child == 0) {
    useMemory(memory);
    const long before = peakKilobytes();
    const auto start = Clock::now();
    const bvmesh::grid::RefinedGrid refined = bvmesh::grid::refineBlockMesh(blocks, options);
    const double firstTime = seconds(start);
    const double grown = 1024.0 * static_cast<double>(peakKilobytes() - before);
    double refineTime = firstTime;
    for (int run = 1; run < kRuns; ++run) {
      const auto again = Clock::now();
      bvmesh::grid::refineBlockMesh(blocks, options);
      refineTime = std::min(refineTime, seconds(again));
    }
    const bvmesh::grid::StructuredGrid& grid = refined.grid;
    const auto cells = static_cast<double>(grid.cellCount());
    const auto points = static_cast<double>(grid.pointCount());
    double naiveTime = 0.0;
    for (int b = 0; b < grid.blockCount(); ++b) {
      const auto& volume = blocks.blocks()[static_cast<size_t>(b)].volume;
      const auto& size = grid.blocks()[static_cast<size_t>(b)].size;
      bvmesh::RowMatrixX3d parameters(grid.blocks()[static_cast<size_t>(b)].pointCount(), 3);
      Eigen::Index row = 0;
      for (int k = 0; k < size[2]; ++k) {
        for (int j = 0; j < size[1]; ++j) {
          for (int i = 0; i < size[0]; ++i, ++row) {
            const std::array<int, 3> ijk{i, j, k};
            for (int d = 0; d < 3; ++d) {
              const double fraction = static_cast<double>(ijk[static_cast<size_t>(d)]) / (size[static_cast<size_t>(d)] - 1);
              parameters(row, d) = volume.lower(d) + (volume.upper(d) - volume.lower(d)) * fraction;
            }
          }
        }
      }
      double fastest = std::numeric_limits<double>::infinity();
      for (int run = 0; run < kRuns; ++run) {
        const auto naiveStart = Clock::now();
        bvmesh::RowMatrixX3d x;
        volume.evaluate(parameters, x);
        fastest = std::min(fastest, seconds(naiveStart));
      }
      naiveTime += fastest;
    }
    std::printf(
        "| %-5s | %-5s | %d | %.0f | %.0f | %d | %.3g..%.3g | %.4f | %.3f | %.1f | %.1f | %.2f | %.1f |\n",
        preset, memoryName(memory), grid.blockCount(), cells, points, refined.normalPoints,
        refined.firstCellHeightMin, refined.firstCellHeightMax, refined.growthMax, refineTime,
        points / refineTime / 1e6, points / naiveTime / 1e6, naiveTime / refineTime,
        (grown - kCoordinateBytes * points) / cells);
    std::fflush(stdout);
    _exit(0);
  }
  int status = 0;
  waitpid(child, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    std::printf("| %-5s | %-5s | failed |\n", preset, memoryName(memory));
}

}  // namespace

int main(int argc, char** argv) {
  const long long target = argc > 1 ? std::atoll(argv[1]) : 1000000;
  std::optional<bvmesh::volume::BlockMesh> blocks;
  std::vector<std::pair<const char*, RefinementOptions>> presets;
  RefinementOptions options;
  options.targetCells = target;
  if (argc > 4) {
    blocks = bvmesh::volume::readBlockMeshFile(argv[2]);
    options.normalPoints = 49;  // bvmesh.grid.PRESETS
    options.growth = 1.2;
    options.maxSpacingJump = 4.0;
    options.evenFarField = true;
    presets.emplace_back("euler", options);
    options.normalPoints = 0;
    options.yPlus = 1.0;
    options.referenceLength = std::atof(argv[3]);
    options.reynoldsNumber = std::atof(argv[4]);
    presets.emplace_back("rans", options);
  } else {
    bvmesh::volume::VolumeMeshOptions volumeOptions;
    volumeOptions.boundaryLayerThickness = 0.02;
    volumeOptions.farfieldDistance = 40.0;
    blocks = bvmesh::volume::generateVolumeMesh(refinedCube(3), volumeOptions).blocks;
    options.normalPoints = 0;
    options.firstCellHeight = 1e-5 * 2.0;
    presets.emplace_back("wall", options);
  }
  std::printf("memory new from the kernel: %.2f us per page at first touch\n\n", freshPageMicroseconds());
  std::printf(
      "| grid | memory | blocks | cells | points | wall-normal points | first height | growth max | "
      "refinement s | M points/s | per-point M points/s | ratio | peak bytes/cell beyond coordinates |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& [name, presetOptions] : presets) {
    for (const Memory memory : {Memory::Fresh, Memory::Kept})
      compareWithPerPoint(name, *blocks, presetOptions, memory);
  }

  // The writers on the first preset's grid.
  const bvmesh::grid::StructuredGrid grid = bvmesh::grid::refineBlockMesh(*blocks, presets.front().second).grid;
  const long long cells = grid.cellCount();
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / "bvmesh_bench_grid";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  std::printf("\n%s grid, %lld cells, %lld points (coordinates %.0f MB):\n\n", presets.front().first, cells,
              static_cast<long long>(grid.pointCount()), kCoordinateBytes * static_cast<double>(grid.pointCount()) / 1048576.0);
  std::printf("| step | s | peak bytes/cell |\n|---|---|---|\n");
  measure("hex topology", cells, [&] { const bvmesh::grid::HexTopology topology(grid); });
  const bvmesh::grid::HexTopology topology(grid);
  measure("quality (all metrics)", cells, [&] { bvmesh::quality::measureCellQuality(topology); });
  const bvmesh::quality::CellQuality quality = bvmesh::quality::measureCellQuality(topology);
  measure("quality summaries, all and per block", cells, [&] {
    bvmesh::quality::summarizeQuality(topology, quality);
    for (int b = 0; b < grid.blockCount(); ++b) bvmesh::quality::summarizeQuality(topology, quality, b);
  });
  measure("CGNS", cells, [&] { bvmesh::io::writeCgns(grid, (folder / "grid.cgns").string()); });
  measure("OpenFOAM polyMesh", cells, [&] { bvmesh::io::writeOpenFoamCase(topology, (folder / "case").string()); });
  measure("OpenFOAM with its topology", cells, [&] {
    bvmesh::io::writeOpenFoamCase(bvmesh::grid::HexTopology(grid), (folder / "case2").string());
  });
  measure("Plot3D binary", cells, [&] { bvmesh::io::writePlot3d(grid, (folder / "grid.p3d").string()); });
  measure("VTK multiblock", cells, [&] { bvmesh::io::writeVtk(grid, (folder / "grid.vtm").string()); });
  std::filesystem::remove_all(folder);
  return 0;
}

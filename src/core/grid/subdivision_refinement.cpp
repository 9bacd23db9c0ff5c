#include "core/grid/subdivision_refinement.h"

#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/common/errors.h"

namespace bvmesh::grid {
namespace {

using volume::HexMesh;

// A block seen through the hex mesh: the point at each of its (i, j, k) grid positions and the
// cell at each cell position (i fastest). `reversed`: its cells run with i reversed.
struct BlockLattice {
  std::array<int, 3> size{};  // points per direction
  std::vector<int> pointAt;
  std::vector<int> cellAt;
  bool reversed = false;

  size_t point(int i, int j, int k) const {
    return static_cast<size_t>(i) + static_cast<size_t>(size[0]) * (static_cast<size_t>(j) + static_cast<size_t>(size[1]) * static_cast<size_t>(k));
  }
  size_t cell(int i, int j, int k) const {
    return static_cast<size_t>(i) +
           static_cast<size_t>(size[0] - 1) * (static_cast<size_t>(j) + static_cast<size_t>(size[1] - 1) * static_cast<size_t>(k));
  }
};

// Corner order of a cell whose i direction is reversed: corner (x, y, z) becomes (1 - x, y, z).
constexpr std::array<size_t, 8> kReversedCorners{1, 0, 3, 2, 5, 4, 7, 6};

struct BlockHexMesh {
  HexMesh mesh;
  std::vector<BlockLattice> lattices;
};

BlockHexMesh blockHexMesh(const volume::BlockMesh& blocks) {
  const volume::VolumeControlMesh control = volume::volumeControlMesh(blocks);
  BlockHexMesh result;
  result.mesh.points = control.points;
  result.mesh.boundaryFaces = control.boundaryFaces;
  result.mesh.boundaryConditions = control.boundaryConditions;
  int cellBase = 0;
  for (int b = 0; b < blocks.blockCount(); ++b) {
    const volume::BsplineVolume& volume = blocks.blocks()[static_cast<size_t>(b)].volume;
    BlockLattice lattice;
    lattice.size = {volume.poleCount(0), volume.poleCount(1), volume.poleCount(2)};
    const size_t cellCount = static_cast<size_t>(lattice.size[0] - 1) * static_cast<size_t>(lattice.size[1] - 1) *
                             static_cast<size_t>(lattice.size[2] - 1);
    // Handedness from the summed corner Jacobians of its cells, as grid::HexTopology decides it.
    double volumeSum = 0.0;
    for (size_t c = 0; c < cellCount; ++c) {
      for (double j : volume::cornerJacobians(control.points, control.cells[static_cast<size_t>(cellBase) + c])) volumeSum += j;
    }
    if (!(volumeSum != 0.0)) throw InvalidInputError("block " + std::to_string(b) + ": its control net has no volume");
    lattice.reversed = volumeSum < 0.0;
    lattice.pointAt.resize(static_cast<size_t>(volume.poles().rows()));
    for (size_t r = 0; r < lattice.pointAt.size(); ++r) {
      lattice.pointAt[r] = control.pointOfPole[static_cast<size_t>(control.blockPointOffset[static_cast<size_t>(b)]) + r];
    }
    lattice.cellAt.resize(cellCount);
    for (size_t c = 0; c < cellCount; ++c) {
      const std::array<int, 8>& corners = control.cells[static_cast<size_t>(cellBase) + c];
      std::array<int, 8> cell = corners;
      if (lattice.reversed) {
        for (size_t q = 0; q < 8; ++q) cell[q] = corners[kReversedCorners[q]];
      }
      result.mesh.cells.push_back(cell);
      // volumeControlMesh lists a block's cells i fastest, as BlockLattice::cell numbers them.
      lattice.cellAt[c] = cellBase + static_cast<int>(c);
    }
    cellBase += static_cast<int>(cellCount);
    result.lattices.push_back(std::move(lattice));
  }
  return result;
}

// The block after one step: child o of cell c is cell 8 c + o, its corners the refined points
// (volume::HexSubdivisionResult), placed back on the block's grid.
BlockLattice refinedLattice(const BlockLattice& old, const HexMesh& refined) {
  BlockLattice next;
  next.reversed = old.reversed;
  for (size_t d = 0; d < 3; ++d) next.size[d] = 2 * old.size[d] - 1;
  next.pointAt.assign(static_cast<size_t>(next.size[0]) * static_cast<size_t>(next.size[1]) * static_cast<size_t>(next.size[2]), -1);
  next.cellAt.assign(old.cellAt.size() * 8, -1);
  for (int k = 0; k + 1 < old.size[2]; ++k) {
    for (int j = 0; j + 1 < old.size[1]; ++j) {
      for (int i = 0; i + 1 < old.size[0]; ++i) {
        const int cell = old.cellAt[old.cell(i, j, k)];
        for (int child = 0; child < 8; ++child) {
          const std::array<int, 3> octant{child & 1, child >> 1 & 1, child >> 2 & 1};
          const int blockX = old.reversed ? 1 - octant[0] : octant[0];
          const int childCell = 8 * cell + child;
          next.cellAt[next.cell(2 * i + blockX, 2 * j + octant[1], 2 * k + octant[2])] = childCell;
          const std::array<int, 8>& corners = refined.cells[static_cast<size_t>(childCell)];
          for (int q = 0; q < 8; ++q) {
            // Corner q of the child at (x, y, z) = octant + corner bits in the cell's frame.
            const auto& bits = volume::kHexCornerBits[static_cast<size_t>(q)];
            const int x = octant[0] + bits[0];
            const int y = octant[1] + bits[1];
            const int z = octant[2] + bits[2];
            next.pointAt[next.point(2 * i + (old.reversed ? 2 - x : x), 2 * j + y, 2 * k + z)] = corners[static_cast<size_t>(q)];
          }
        }
      }
    }
  }
  return next;
}

}  // namespace

HexMesh hexMeshOfBlocks(const volume::BlockMesh& blocks) { return blockHexMesh(blocks).mesh; }

StructuredGrid subdivideBlockMesh(const volume::BlockMesh& blocks, int steps) {
  if (steps < 0) throw InvalidInputError("subdivision steps must be >= 0, got " + std::to_string(steps));
  BlockHexMesh current = blockHexMesh(blocks);
  const double pointsAfter = static_cast<double>(current.mesh.points.rows()) * std::pow(8.0, steps);
  if (pointsAfter > static_cast<double>(std::numeric_limits<int>::max())) {
    throw InvalidInputError(std::to_string(steps) + " subdivision steps would make about " + std::to_string(pointsAfter) +
                            " points, more than the 2^31 a hex mesh can number");
  }
  for (int step = 0; step < steps; ++step) {
    volume::HexSubdivisionResult refined = volume::subdivideHexMesh(current.mesh);
    for (BlockLattice& lattice : current.lattices) lattice = refinedLattice(lattice, refined.mesh);
    current.mesh = std::move(refined.mesh);
  }
  std::vector<GridBlock> gridBlocks;
  for (size_t b = 0; b < current.lattices.size(); ++b) {
    const BlockLattice& lattice = current.lattices[b];
    GridBlock block;
    block.size = lattice.size;
    block.points.resize(static_cast<Eigen::Index>(lattice.pointAt.size()), 3);
    for (size_t r = 0; r < lattice.pointAt.size(); ++r) {
      block.points.row(static_cast<Eigen::Index>(r)) = current.mesh.points.row(lattice.pointAt[r]);
    }
    block.faces = blocks.blocks()[b].faces;
    gridBlocks.push_back(std::move(block));
  }
  return StructuredGrid(std::move(gridBlocks));
}

}  // namespace bvmesh::grid

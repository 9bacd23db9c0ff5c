#include "core/grid/folded_cells.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>

#include "core/common/parallel.h"
#include "core/volume/hex_scaled_jacobian.h"

namespace bvmesh::grid {

std::vector<char> foldedBlocks(const std::vector<GridBlock>& grids) {
  // Rows of cells along i, numbered block after block: one pool of threads for all.
  std::vector<std::int64_t> offset{0};
  for (const GridBlock& grid : grids) {
    offset.push_back(offset.back() + static_cast<std::int64_t>(grid.size[1] - 1) * (grid.size[2] - 1));
  }
  // One flag per block: a block's rows are skipped once a fold is found in it.
  std::unique_ptr<std::atomic<bool>[]> folded(new std::atomic<bool>[grids.size()]);
  for (size_t b = 0; b < grids.size(); ++b) folded[b] = false;
  parallelChunks(offset.back(), 64, [&](std::int64_t begin, std::int64_t end) {
    size_t b =
        static_cast<size_t>(std::upper_bound(offset.begin(), offset.end(), begin) - offset.begin()) - 1;
    // Along a row the face at i + 1 of one cell is the face at i of the next: its points and its
    // j- and k-edges are carried over, so each cell reads 4 points and takes 8 edge differences.
    struct CellFace {
      Eigen::Vector3d x[2][2];               // [j][k]
      Eigen::Vector3d alongJ[2], alongK[2];  // the j-edges at k = 0, 1; the k-edges at j = 0, 1
    };
    auto load = [](const GridBlock& grid, int i, int j0, int k0, CellFace& face) {
      for (int k = 0; k < 2; ++k) {
        for (int j = 0; j < 2; ++j) face.x[j][k] = grid.points.row(grid.index(i, j0 + j, k0 + k)).transpose();
      }
      for (int c = 0; c < 2; ++c) {
        face.alongJ[c] = face.x[1][c] - face.x[0][c];
        face.alongK[c] = face.x[c][1] - face.x[c][0];
      }
    };
    CellFace face[2];
    for (std::int64_t row = begin; row < end; ++row) {
      while (row >= offset[b + 1]) ++b;
      if (folded[b].load(std::memory_order_relaxed)) continue;
      const GridBlock& grid = grids[b];
      const std::int64_t local = row - offset[b], nj = grid.size[1] - 1;
      const int j0 = static_cast<int>(local % nj), k0 = static_cast<int>(local / nj);
      load(grid, 0, j0, k0, face[0]);
      for (int i0 = 0; i0 + 1 < grid.size[0]; ++i0) {
        const CellFace& low = face[i0 & 1];
        CellFace& high = face[(i0 + 1) & 1];
        load(grid, i0 + 1, j0, k0, high);
        // The edges' triple product at every corner first (the scaled Jacobian's sign); only a
        // cell where one is not positive (folded, or on a collapsed face, whose merged corners
        // have none) is measured as the quality does.
        bool positive = true;  // NaN is not
        for (int j = 0; j < 2; ++j) {
          for (int k = 0; k < 2; ++k) {
            const Eigen::Vector3d alongI = high.x[j][k] - low.x[j][k];
            positive &= alongI.cross(low.alongJ[k]).dot(low.alongK[j]) > 0.0;
            positive &= alongI.cross(high.alongJ[k]).dot(high.alongK[j]) > 0.0;
          }
        }
        if (positive) continue;
        // hexScaledJacobian's corner order: 000 100 110 010 001 101 111 011.
        const std::array<Eigen::Vector3d, 8> corners{low.x[0][0], high.x[0][0], high.x[1][0], low.x[1][0],
                                                     low.x[0][1], high.x[0][1], high.x[1][1], low.x[1][1]};
        if (!(volume::hexScaledJacobian(corners) > 0.0)) {
          folded[b] = true;
          break;
        }
      }
    }
  });
  std::vector<char> result(grids.size());
  for (size_t b = 0; b < grids.size(); ++b) result[b] = folded[b].load() ? 1 : 0;
  return result;
}

}  // namespace bvmesh::grid

// Hand-made grids and options the grid tests share.
#pragma once

#include <Eigen/Core>

#include <array>
#include <vector>

#include "core/grid/refinement.h"
#include "core/grid/structured_grid.h"

namespace bvmesh::test {

// The unwarped box's refinement: 5 points per tangential edge, 9 along z.
inline grid::RefinementOptions affineBoxOptions() {
  grid::RefinementOptions options;
  options.edgePoints = 5;
  options.normalPoints = 9;
  options.growth = 1.3;
  return options;
}

// A block of 3 x 2 x 2 points (two unit cells along i), corner (i, j, k) of its cells at
// (i, j, k) before `moved` is added to point `at`.
inline std::vector<grid::GridBlock> twoCellRow(const std::array<int, 3>& at, const Eigen::Vector3d& moved) {
  grid::GridBlock block;
  block.size = {3, 2, 2};
  block.points.resize(block.pointCount(), 3);
  for (int k = 0; k < 2; ++k) {
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 3; ++i) block.points.row(block.index(i, j, k)) << i, j, k;
    }
  }
  block.points.row(block.index(at[0], at[1], at[2])) += moved.transpose();
  return {block};
}

}  // namespace bvmesh::test

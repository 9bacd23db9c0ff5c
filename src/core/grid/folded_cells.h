// Whether a grid folds, and where: the checks the refinement makes before it keeps a grid whose
// wall-normal lines slid towards the even far field (RefinementOptions::evenFarField), and before
// it gives the blocks a fold is in more tangential points.
#pragma once

#include <vector>

#include "core/grid/structured_grid.h"

namespace bvmesh::grid {

// Per block of `grids` whether some cell of it has a non-positive scaled Jacobian (as
// quality::measureCellQuality scores it: a collapsed face's merged corners as a prism's). Cells
// whose edges' triple products are positive at all eight corners are passed without the full
// measure.
std::vector<char> foldedBlocks(const std::vector<GridBlock>& grids);

}  // namespace bvmesh::grid

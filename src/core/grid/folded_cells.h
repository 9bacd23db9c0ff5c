// Whether a grid folds: the check the refinement makes before it keeps a grid whose wall-normal
// lines slid towards the even far field (RefinementOptions::evenFarField).
#pragma once

#include <vector>

#include "core/grid/structured_grid.h"

namespace bvmesh::grid {

// Whether some cell of `grids` has a non-positive scaled Jacobian (as quality::measureCellQuality
// scores it: a collapsed face's merged corners as a prism's). Cells whose edges' triple products
// are positive at all eight corners are passed without the full measure.
bool hasFoldedCell(const std::vector<GridBlock>& grids);

}  // namespace bvmesh::grid

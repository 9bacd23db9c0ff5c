// Direction sets: block directions linked through connected faces share their point count and
// orientation. Per set: whether it runs wall-normal (one of its directions has a wall at one end),
// how many points it takes (from its wall edges' lengths and turning, or the cell target), and
// where its edges put them (at fractions of arc length its edges share, clustered at its ends as
// edge_end_spacing and the spacing-jump limit ask).
#pragma once

#include <vector>

#include "core/grid/block_plan.h"
#include "core/grid/refinement.h"
#include "core/volume/block_mesh.h"

namespace bvmesh::grid {

// Every block's plan: its wall-normal direction and wall end, its tangential point counts and
// edge parameters. Along the wall-normal direction the size is options.normalPoints, or when
// that is automatic (0) the estimate from the wall blocks' edges that served the cell target
// (the wall-normal lines decide the count). firstHeight: the first cell height asked (0: none).
// minimumPoints: per block direction (3 b + d) the fewest points its tangential set takes (empty:
// none). Throws InvalidInputError for block layouts the refinement cannot take (naming the block).
std::vector<BlockPlan> planDirectionSets(const std::vector<volume::Block>& blocks,
                                         const RefinementOptions& options, double firstHeight,
                                         const std::vector<int>& minimumPoints = {});

}  // namespace bvmesh::grid

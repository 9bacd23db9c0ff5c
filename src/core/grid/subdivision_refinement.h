// Refinement by subdivision, the alternative to B-spline evaluation: k steps of volumetric
// Catmull-Clark (volume/hex_subdivision.h) of the blocks' control mesh. Every step splits each
// cell in 8, so a block's (n_u, n_v, n_w) poles become (2 n_u - 1, 2 n_v - 1, 2 n_w - 1) points
// and the result is again a point-matched structured grid with the blocks' connections and
// conditions. Its points are control points of the Catmull-Clark solid of the control mesh,
// which is the blocks' B-spline volume only where their knots are uniform: near clamped block
// faces (the wall among them) the two differ, by less at every step.
#pragma once

#include "core/grid/structured_grid.h"
#include "core/volume/block_mesh.h"
#include "core/volume/control_volume.h"
#include "core/volume/hex_subdivision.h"

namespace bvmesh::grid {

// The blocks' volume control mesh as a HexMesh: a left-handed block's cells are taken with their
// i direction reversed, so every cell is right-handed. Throws InvalidInputError naming the block
// when its control net has no volume.
volume::HexMesh hexMeshOfBlocks(const volume::BlockMesh& blocks);

// `steps` >= 0 subdivision steps of the control mesh (0: the control net itself). Throws
// InvalidInputError for steps < 0 or a grid that would pass 2^31 points or maxPoints (> 0; 0: no
// limit: a memory budget, point_budget.h), and what volume::subdivideHexMesh throws for the
// control mesh.
StructuredGrid subdivideBlockMesh(const volume::BlockMesh& blocks, int steps, long long maxPoints = 0);

// `steps` >= 0 subdivision steps of the control volume marched from the fit's own control mesh
// (volume/control_volume.h), as a grid with its blocks, and the wall points then moved to their
// limit positions: the grid's wall lies on the fitted limit surface at level L + steps, which is
// the surface fit's subdivision to that level. Throws as subdivideBlockMesh.
StructuredGrid subdivideControlVolume(const volume::ControlVolume& volume, int steps, long long maxPoints = 0);

}  // namespace bvmesh::grid

// Layers marched from a coarser level of the wall (the marching wall), carried onto the wall's own
// grid: the blocks then stand on the finer fit while their layers are the coarse wall's.
#pragma once

#include <Eigen/Core>

#include <vector>

#include "core/surface/quad_charts.h"
#include "core/volume/domain.h"
#include "core/volume/marching.h"
#include "core/volume/wall_grid.h"
#include "core/volume/wall_patches.h"

namespace bvmesh::volume {

// How many times `coarse` must be refined to have `fine`'s face count (-1: never).
int refinementSteps(const surface::QuadControlMesh& coarse, const surface::QuadControlMesh& fine);

// The coarse marching's layers carried onto the wall's grid: each wall grid point takes the coarse
// layer surfaces at its place on the coarse patches, moved by its distance from the coarse wall
// (fully at the wall, fading to nothing at the top of the boundary layer, so the boundary layer's
// grid lines keep their direction and the far field is the coarse one).
// coarsePoles: the coarse layers' patch poles (per coarse patch and layer, as the blocks take
// them); steps: refinementSteps from the marching wall to the wall. Throws InvalidInputError when
// the two layouts do not correspond or a wall point lies more than half the first control layer
// from the marching wall.
MarchingResult transferLayers(const MarchingResult& coarse, const std::vector<WallPatch>& coarsePatches,
                              const std::vector<std::vector<Eigen::MatrixXd>>& coarsePoles,
                              const std::vector<WallPatch>& patches, const WallGrid& grid, int steps,
                              double boundaryLayerThickness, const Domain& domain);

}  // namespace bvmesh::volume

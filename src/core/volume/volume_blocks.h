// From a fitted wall to the block-structured B-spline volume mesh: the wall's B-spline charts
// (conforming patches), the Greville points of their poles as the surface grid to march, the
// marched layers, and per patch one tricubic block whose w = 0 face is the patch surface, whose
// w direction interpolates the layers and whose faces shared with neighbours are identical.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/surface/quad_charts.h"
#include "core/volume/block_mesh.h"
#include "core/volume/marching.h"
#include "core/volume/volume_options.h"

namespace bvmesh::volume {

struct VolumeMesh {
  BlockMesh blocks;
  std::vector<int> blockChart;           // chart of the wall surface each block stands on
  std::vector<double> layerDistance;     // mean marched distance of each control layer
  std::vector<double> layerMinScaledJacobian;
  int farfieldLayersSmoothed = 0;  // MarchingResult::farfieldLayersSmoothed
  // The options as resolved (defaults filled in).
  double referenceLength = 0.0;
  double boundaryLayerThickness = 0.0;
  double farfieldDistance = 0.0;
  Eigen::Vector3d domainCentre = Eigen::Vector3d::Zero();
  Domain domain;
  double wallMaxDistance = 0.0;  // the wall charts' distance from the limit surface (LimitBSplines::maxDistance)
  // Far-field block faces whose poles lie on more than one face of a box or cylinder domain (they
  // bend around its edge; each is tagged by the part its middle lies on).
  int farfieldFacesAcrossDomainEdges = 0;
};

// The volume mesh around the limit surface of `wall` (an all-quad Catmull-Clark control mesh,
// outward oriented, closed or open only on the symmetry plane). Throws InvalidInputError for bad
// options or an inward / open wall, SolverError when the marching would fold.
//
// With `marchingWall` (the same wall at a coarser level: `wall`'s control mesh is it subdivided
// one or more times and refitted, old vertices keeping their ids), the layers are marched from the
// marching wall and carried over: the blocks' wall faces are `wall`'s charts (the finer fit,
// within its tolerance), their other layers the coarse layers evaluated at `wall`'s grid, shifted
// by the distance between the two walls over the boundary layer. A fine wall whose own front
// would fold where the coarse one does not (a chart corner of the M6's tip at level 3) gets the
// coarse wall's grid lines. Throws InvalidInputError when the two walls do not correspond or lie
// more than half the first control layer apart.
VolumeMesh generateVolumeMesh(const surface::QuadControlMesh& wall, const VolumeMeshOptions& options = {},
                              const surface::QuadControlMesh* marchingWall = nullptr);

}  // namespace bvmesh::volume

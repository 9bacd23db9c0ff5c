// The volume control mesh of the thesis' second path (1.3.3): the fitted wall's own Catmull-Clark
// control mesh marched outward, layer by layer, into hexahedral control cells. Unlike the B-spline
// blocks (volume_blocks.h), whose wall nets are the charts' clamped B-spline nets, its wall faces
// are the fit's control faces with their creases and corners, so volumetric Catmull-Clark
// (hex_subdivision.h) refines its wall exactly as the surface stage refines the fit, and fitting
// can go on from it (fit/volume_fit.h) at the next level.
#pragma once

#include <vector>

#include "core/surface/quad_charts.h"
#include "core/volume/hex_subdivision.h"
#include "core/volume/volume_options.h"

namespace bvmesh::volume {

struct ControlVolume {
  // Points layer by layer: wall vertex v of layer k is point k * wallVertices + v (layer 0: the
  // wall's control vertices). Boundary faces: wall (the control faces), symmetry (the open
  // boundary's edges swept through the layers), and the outer layer's faces tagged by the domain.
  // Creases and corners: the wall's.
  HexMesh mesh;
  int wallVertices = 0;
  // Block structure, as the B-spline blocks have it: the wall's charts split until they meet side
  // to side, each times the layers one block of cells (i, j along the chart, k outward; k = 0 the
  // wall, the last k the outer boundary), with its faces' conditions and connections.
  std::vector<HexBlock> blocks;
  std::vector<std::array<BlockFace, 6>> blockFaces;
  std::vector<int> blockChart;  // chart of the wall each block stands on
  std::vector<double> layerDistance;           // mean marched distance of each layer
  std::vector<double> layerMinScaledJacobian;  // per layer k >= 1
  double referenceLength = 0.0;
  double boundaryLayerThickness = 0.0;
  double farfieldDistance = 0.0;
};

// The control volume around `wall` (an all-quad Catmull-Clark control mesh, outward oriented,
// closed or open only on the symmetry plane), marched with the same options and rules as the
// B-spline blocks, from the wall's control vertices along their mean limit normals. Throws
// InvalidInputError for bad options, an inward wall, or an open boundary off the symmetry plane
// (naming its vertex); SolverError when the marching would fold.
ControlVolume controlVolumeMesh(const surface::QuadControlMesh& wall, const VolumeMeshOptions& options = {});

}  // namespace bvmesh::volume

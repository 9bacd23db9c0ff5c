// The boundary layer's grid-line directions: the wall normals, fanned out in splay bands round the
// wall's sharp convex edges, along the best-seeing direction at concave creases, and turned round
// the knife edges' fans (marching.h marches the layers along them).
#pragma once

#include "core/common/types.h"
#include "core/volume/boundary_planes.h"
#include "core/volume/marching.h"

namespace bvmesh::volume {

// Per point of `front` the unit direction of its boundary-layer grid line: splayed in bands of
// geodesic width `width` round the sharp convex edges (knife edges cut open for their fans;
// blended to the closed edge's lines where fans close, over the fans' arc at the top of the
// boundary layer of `thickness`), kept in the boundary planes a point lies on.
RowMatrixX3d boundaryLayerLines(const MarchingFront& front, const BoundaryPlanes& planes, double thickness,
                                double width);

}  // namespace bvmesh::volume

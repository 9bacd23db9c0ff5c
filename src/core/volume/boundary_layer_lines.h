// The boundary layer's grid-line directions: the wall normals, fanned out in splay bands round the
// wall's sharp convex edges, along the best-seeing direction at concave creases, and turned round
// the knife edges' fans (marching.h marches the layers along them).
#pragma once

#include "core/common/types.h"
#include "core/volume/boundary_planes.h"
#include "core/volume/marching.h"

namespace bvmesh::volume {

// The boundary layer's grid lines: per point of the front its unit direction, and the line's
// length per unit of boundary-layer distance (1 but in a concave crease's band, where the line
// leans off the wall's normals: there as long as keeps its layers at their distance from the
// wall cells round it, at most 2).
struct BoundaryLayerLines {
  RowMatrixX3d directions;
  Eigen::VectorXd lengths;
};

// The lines splayed in bands of geodesic width `width` round the sharp convex edges (knife edges
// cut open for their fans; blended to the closed edge's lines where fans close, over the fans'
// arc at the top of the boundary layer of `thickness`), turned towards the best-seeing line of
// concave creases within a few thicknesses of them, and kept in the boundary planes a point lies
// on.
BoundaryLayerLines boundaryLayerLines(const MarchingFront& front, const BoundaryPlanes& planes,
                                      double thickness, double width);

}  // namespace bvmesh::volume

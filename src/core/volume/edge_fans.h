// Fans of prisms round the wall's knife edges. Where two wall patches meet along a crease whose
// faces' normals are nearly opposite (a sharp trailing edge, whose wedge is a few degrees wide),
// a single grid line leaving the edge has the wall's two faces at nearly 180 degrees from it:
// the cells there are flat whatever the line's direction (an O-grid's knife-edge cells). Instead
// the edge's vertex chain is cut open into a copy for each face, whose grid lines leave along
// that face's own normal, and a fan patch is put between the copies: the edge repeated across
// the fan (collapsed), whose block's lines turn from one face's normal to the other's round the
// edge. Its block's wall face is the edge itself, a collapsed face, and its first cells are
// prisms with their corner at the edge.
//
// Where the knife edge ends on the mesh boundary (a half model's symmetry plane) the fan's end
// lies on it; where it ends inside the wall (a trailing edge meeting a wing tip's cap) the edge's
// copies join there again and the fan closes to that point: its end side is collapsed too.
#pragma once

#include <vector>

#include "core/volume/wall_patches.h"

namespace bvmesh::volume {

// Wall-patch sides on a convex crease whose two patches' normals lie more than this apart at
// every point of the side between its ends are knife edges.
constexpr double kKnifeEdgeDegrees = 120.0;

// Cubic spans of a fan round its edge.
constexpr int kFanSpans = 3;

// Cuts every knife edge of `patches` (conformingWallPatches' patches, surfaces included) open
// and appends a fan patch between its copies; returns the number of fans appended. The patches'
// side links, copies and collapsed sides are set so that the wall grid and the blocks see the
// copies as distinct and the fans as part of the wall. Throws InvalidInputError where more than
// two knife edges end at a vertex on the symmetry plane, or where the knife edges through a
// vertex do not part the patches round it in two.
int insertEdgeFans(std::vector<WallPatch>& patches);

}  // namespace bvmesh::volume

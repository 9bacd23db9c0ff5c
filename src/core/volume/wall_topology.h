// Whether a wall can be marched out to the domain boundary at all: a marched front keeps the
// wall's topology, and the domain boundary (a sphere, a box, a cylinder; on a symmetry plane their
// halves) is one sphere or one disc.
#pragma once

#include "core/surface/quad_charts.h"

namespace bvmesh::volume {

// Throws InvalidInputError naming the problem when the wall (an all-quad control mesh) is several
// bodies (their volume meshes would overlap), a ring (a nacelle, a torus: the front's hole closes
// on itself before the far field), or, on a symmetry plane (`halfModel`), meets it in more than one
// loop (a half ring: the front's pieces on the plane close the gap between them).
void requireMarchableWall(const surface::QuadControlMesh& wall, bool halfModel);

}  // namespace bvmesh::volume

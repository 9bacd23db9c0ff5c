// Improvement of an initial polyhedron before fitting: tangential relaxation (equal edge lengths;
// crease and boundary vertices slide along their chains, corners stay) with projection onto the
// target by vertex role, then limit push-out (vertices move until their Catmull-Clark limit
// points lie on the target, so the polyhedron encloses a convex-ish target instead of
// shrinking inside it), and snapping of boundary vertices to the symmetry plane.
#pragma once

#include <optional>

#include "core/fit/surface_fitter.h"
#include "core/mesh/control_mesh.h"
#include "core/target/target.h"

namespace bvmesh::polyhedron {

struct ImproveOptions {
  int relaxationPasses = 3;  // relaxation + projection passes
  double relaxation = 0.5;   // fraction of the way to the neighbours' average per pass
  int pushOutPasses = 3;     // limit push-out passes (0: none)
  // Boundary vertices within this distance of the plane (relative to the diagonal) are put on it.
  double relativeSnapDistance = 1e-3;
  std::optional<fit::SymmetryPlane> symmetryPlane;
};

// Moves the vertices of `mesh` (topology unchanged). `features` as for SurfaceFitter (may be empty).
void improvePolyhedron(ControlMesh& mesh, const target::Target& target, const fit::FeatureMap& features,
                       const ImproveOptions& options = {});

}  // namespace bvmesh::polyhedron

// Fitting that goes on after the volume exists (thesis 1.3.3): iteration step 1 by the volume
// rules (volume/hex_subdivision.h) instead of the surface ones, steps 2-4 on the wall faces of the
// refined mesh as the surface fit does them, and the interior points following the wall by a
// harmonic (graph-Laplacian) displacement, the rest of the boundary held. The cells' corner
// Jacobians are checked afterwards; nothing is written over a mesh that turned over.
#pragma once

#include <memory>

#include "core/fit/surface_fitter.h"
#include "core/volume/hex_subdivision.h"

namespace bvmesh::fit {

struct VolumeFitResult {
  volume::HexMesh mesh;                 // the refined mesh with the wall fitted and the interior followed
  RowSparseMatrix subdivisionOperator;  // #P' x #P, the step's operator (before fitting)
  PassRecord wall;                      // the wall's last pass (limit samples against their projections)
  double minScaledJacobian = 0.0;       // over every corner of every refined cell
};

// One level: subdivideHexMesh, then `passes` >= 1 passes of steps 2-4 on the boundary faces
// tagged Wall (crease and corner tags of the mesh on the wall kept; `options` as for
// SurfaceFitter: symmetry plane, weights, solver, ...), then the interior displacement. Throws
// InvalidInputError for passes < 1 or a mesh without wall faces, what subdivideHexMesh and
// SurfaceFitter throw, and SolverError naming the first cell whose corner Jacobian is not
// positive after the interior followed.
VolumeFitResult subdivideAndFitVolume(const volume::HexMesh& mesh, std::shared_ptr<const target::Target> target,
                                      const FitOptions& options = {}, int passes = 3);

}  // namespace bvmesh::fit

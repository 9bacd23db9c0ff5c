// The independent convergence check of the fitting: distances between the limit surface and the
// target on a sampling denser than (and different from) the fitting samples, both ways.
#pragma once

#include "core/fit/surface_fitter.h"

namespace bvmesh::fit {

// limitToTarget: the limit surface evaluated on an (n+1) x (n+1) grid per ptex face, each point
//   projected onto the target (exact closest point on the trimmed CAD surface).
// targetToLimit: every node of the target's tessellation, or with targetSubdivisions k > 1 the
//   points of Target::surfaceSamples(k) (k^2 times as many, exactly on the CAD), to the nearest
//   point of the limit surface itself: the grids' triangles find the candidate ptex faces (every
//   face with a triangle within the point's distance to the triangles plus twice their chordal
//   deviation), and Gauss-Newton steps on those faces the nearest limit point. Only points that
//   could still raise the maximum are measured so; the result does not depend on the grid's
//   density as a tessellation's chordal error would.
// faceHints (optional, one per ptex face): a nearby location on the target for each face, which
// warm-starts the projections of that face's grid points.
TwoSidedDistance measureTwoSidedDistance(const ControlMesh& mesh, const SubdivisionOptions& options,
                                         const target::Target& target, int samplesPerFace,
                                         const target::SurfaceHints* faceHints = nullptr,
                                         int targetSubdivisions = 1);

}  // namespace bvmesh::fit

// The independent convergence check of the fitting: distances between the limit surface and the
// target on a sampling denser than (and different from) the fitting samples, both ways.
#pragma once

#include "core/fit/surface_fitter.h"

namespace bvmesh::fit {

// limitToTarget: the limit surface evaluated on an (n+1) x (n+1) grid per ptex face, each point
//   projected onto the target (exact closest point on the trimmed CAD surface).
// targetToLimit: every node of the target's tessellation, or with targetSubdivisions k > 1 the
//   points of Target::surfaceSamples(k) (k^2 times as many, exactly on the CAD), to the nearest
//   point of the limit surface, tessellated by the same grids (so it includes the grid's chordal
//   error, which is small against the grid spacing squared times the curvature).
// faceHints (optional, one per ptex face): a nearby location on the target for each face, which
// warm-starts the projections of that face's grid points.
TwoSidedDistance measureTwoSidedDistance(const ControlMesh& mesh, const SubdivisionOptions& options,
                                         const target::Target& target, int samplesPerFace,
                                         const target::SurfaceHints* faceHints = nullptr,
                                         int targetSubdivisions = 1);

}  // namespace bvmesh::fit

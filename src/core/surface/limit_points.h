// How the B-spline conversion reads the limit surface: a callback that returns limit points at
// (ptex face, u, v) locations, and the adapters to the core's ControlMesh and shared
// LimitEvaluator (core/subdiv), which the one-shot conversion uses.
#pragma once

#include <functional>
#include <vector>

#include "core/mesh/control_mesh.h"
#include "core/subdiv/limit_evaluator.h"
#include "core/subdiv/surface_location.h"
#include "core/surface/quad_charts.h"

namespace bvmesh::surface {

// Fills `points` (resized to #locations x 3) with limit points and, unless `normals` is null,
// `normals` with unit limit normals (zero where undefined). On an all-quad mesh the ptex face of a
// location is the mesh face, (0, 0) at its vertex 0, (1, 0) at vertex 1, (0, 1) at vertex 3.
using LimitPointsFunction = std::function<void(const std::vector<SurfaceLocation>& locations,
                                               RowMatrixX3d& points, RowMatrixX3d* normals)>;

// The quad mesh as the core's ControlMesh, every crease and corner infinitely sharp.
ControlMesh toControlMesh(const QuadControlMesh& mesh);

// A ControlMesh as quad arrays. Throws InvalidInputError naming the face that is not a quad or
// the crease / corner that is not infinitely sharp (chart borders must be sharp or smooth).
QuadControlMesh toQuadControlMesh(const ControlMesh& mesh);

// Limit points of `evaluator` for `controlPoints` (#V x 3); both must outlive the function.
LimitPointsFunction limitPoints(const LimitEvaluator& evaluator, const RowMatrixX3d& controlPoints);

}  // namespace bvmesh::surface

// Internal: the bridge between ControlMesh and OpenSubdiv's Far layer (not part of the public
// API; OpenSubdiv types stay inside src/core/subdiv).
#pragma once

#include <opensubdiv/far/topologyRefiner.h>

#include <memory>
#include <vector>

#include "core/mesh/control_mesh.h"
#include "core/subdiv/subdivision.h"

namespace bvmesh::osd {

namespace Far = OpenSubdiv::Far;

// Makes OpenSubdiv report errors as TopologyError instead of printing them (installed once).
void installErrorHandler();

// A Catmark refiner for the mesh's topology, creases and corners (level 0 only).
std::unique_ptr<Far::TopologyRefiner> createRefiner(const ControlMesh& mesh,
                                                    const SubdivisionOptions& options);

// A refiner refined uniformly by one level, with full topology in that level (needed for limit
// masks).
std::unique_ptr<Far::TopologyRefiner> createRefinedOnce(const ControlMesh& mesh,
                                                        const SubdivisionOptions& options);

// For every level-1 vertex of OpenSubdiv, its index in our child order (old vertices, then edge
// points in ControlMesh edge order, then face points).
std::vector<int> childVertexOrder(const Far::TopologyRefiner& refiner, const ControlMesh& mesh);

// #V' x #V operator of the first refinement, rows in our child order.
RowSparseMatrix subdivisionOperator(const Far::TopologyRefiner& refiner,
                                    const std::vector<int>& childOrder);

// OpenSubdiv encodes infinite sharpness as 10.
float toOsdSharpness(double sharpness);
double fromOsdSharpness(float sharpness);

}  // namespace bvmesh::osd

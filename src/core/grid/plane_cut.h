// A plane cut through a structured grid: the grid lines where the plane crosses the cells' faces,
// as CFD engineers look at a mesh around a wing section. Each segment knows its cell, so a cut can
// be coloured by a per-cell quality metric.
#pragma once

#include <vector>

#include "core/common/types.h"
#include "core/grid/structured_grid.h"

namespace bvmesh::grid {

struct PlaneCut {
  RowMatrixX3d start;               // segment s runs from start.row(s) to end.row(s)
  RowMatrixX3d end;
  std::vector<Eigen::Index> cell;  // the cell (HexTopology numbering) whose face holds the segment
};

// The segments where the plane through `point` with normal `normal` (any length > 0) crosses
// the faces of the grid's cells. Faces inside a block are cut once; faces on a block boundary
// once per block that holds them; a crossing of no length (a collapsed face, a face touched at a
// corner) is no segment. A plane the grid lies wholly on one side of (a half model's symmetry
// plane) gives the grid lines lying in it. Throws InvalidInputError for a zero or non-finite normal.
PlaneCut cutByPlane(const StructuredGrid& grid, const Eigen::Vector3d& point, const Eigen::Vector3d& normal);

}  // namespace bvmesh::grid

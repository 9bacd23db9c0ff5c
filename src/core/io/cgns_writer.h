// The structured grid as a CGNS file (HDF5 flavour, through Debian's libcgns 3.4), the
// interchange format most finite-volume flow solvers (SU2, CFL3D-derived codes, Star-CCM+,
// Fluent, ...) read multi-block structured grids from:
//  - one CGNSBase_t (cell dimension 3, physical dimension 3), one Structured zone per block,
//    named io::blockName ("block_0001" = block 0), with CoordinateX/Y/Z in RealDouble;
//  - per connected face a GridConnectivity1to1_t, written from both sides, with PointRange,
//    PointRangeDonor and Transform derived from the face connection;
//  - per other face a BC_t (PointRange) of the condition's BCType and a FamilyName; the base holds
//    one Family_t with FamilyBC_t per condition used, named as boundaryConditionName:
//      wall -> BCWallViscous if grid.viscousWall() else BCWall, symmetry -> BCSymmetryPlane,
//      farfield -> BCFarfield, inlet -> BCInflow, outlet -> BCOutflow, side -> BCFarfield
//    (the lateral faces of the far-field box; a family of their own so that a solver set-up can
//    re-type them, e.g. to symmetry or periodic, without touching the grid).
#pragma once

#include <string>

#include "core/grid/structured_grid.h"

namespace bvmesh::io {

// Writes through "<path>.partial" renamed into place, so a failure leaves no file under `path`.
// Throws InvalidInputError naming the path when it cannot be created, SolverError with the CGNS
// library's message when a write fails.
void writeCgns(const grid::StructuredGrid& grid, const std::string& path);

}  // namespace bvmesh::io

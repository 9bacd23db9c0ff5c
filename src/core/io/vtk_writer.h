// The structured grid for ParaView and VTK-based scripts: a VTK XML multiblock file
// ("grid.vtm") listing one StructuredGrid file per block in the folder next to it
// ("grid_blocks/block_0001.vts", ...), each with the block's points and any per-cell fields
// (cell quality, block number, ...). The data is appended raw binary (little-endian Float64,
// UInt64 byte-count headers): exact and a third of the size of 17-digit text, and read by every
// VTK since 5.x (vtkXMLMultiBlockDataReader, meshio, ParaView).
#pragma once

#include <string>
#include <vector>

#include "core/grid/structured_grid.h"

namespace bvmesh::io {

// One value per cell of every block: perBlock[b][i + (ni - 1) * (j + (nj - 1) * k)] for cell
// (i, j, k) of block b.
struct CellField {
  std::string name;
  std::vector<std::vector<double>> perBlock;
};

// `path` ends in ".vtm"; its folder must exist, "<stem>_blocks/" beside it is created. Every file
// is written through a temporary renamed into place, the .vtm last, so a failure never leaves a
// .vtm under `path` that lists missing or partial blocks (block files of an earlier, larger grid
// stay in the folder, unlisted). Throws InvalidInputError naming the
// path (unwritable, not .vtm) or the field and block (wrong number of values, unnamed, repeated).
void writeVtk(const grid::StructuredGrid& grid, const std::string& path,
              const std::vector<CellField>& cellFields = {});

}  // namespace bvmesh::io

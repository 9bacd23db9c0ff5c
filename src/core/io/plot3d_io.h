// Plot3D multi-block whole grid files (x, y, z only, no IBLANK), the lowest common denominator
// of structured-grid readers (Tecplot, ParaView, Pointwise, OVERFLOW-era codes, OpenFOAM's
// plot3dToFoam):
//   nblocks
//   ni nj nk            (per block)
//   x..., y..., z...    (per block, i fastest, then j, then k)
// Binary is what Fortran writes with `form='unformatted'` (sequential access): every `write`
// is a record framed by its byte length as int32 before and after; three records (nblocks; all
// dimensions; one per block with its x, y, z), int32 integers and float64 coordinates, little-
// endian. ASCII carries the same numbers, coordinates with 17 significant digits, so both formats
// give the points back bit for bit (plot3dToFoam merges block faces only when they are).
// plot3dToFoam reads the ASCII form and expects IBLANK unless called with -noBlank.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/common/types.h"
#include "core/grid/structured_grid.h"

namespace bvmesh::io {

enum class Plot3dFormat { Binary, Ascii };

struct Plot3dBlock {
  std::array<int, 3> size{0, 0, 0};  // points along i, j, k
  RowMatrixX3d points;               // point (i, j, k) at row i + ni * (j + nj * k)
};

// Writes through "<path>.partial" renamed into place. Throws InvalidInputError naming the path
// when it cannot be written, or the block when it is too large for an int32 record length.
void writePlot3d(const grid::StructuredGrid& grid, const std::string& path,
                 Plot3dFormat format = Plot3dFormat::Binary);

// Reads either format (told apart by the first record marker). Throws InvalidInputError naming
// the file and what is wrong: unreadable, truncated, bad counts, record markers that disagree,
// data after the last block.
std::vector<Plot3dBlock> readPlot3d(const std::string& path);

}  // namespace bvmesh::io

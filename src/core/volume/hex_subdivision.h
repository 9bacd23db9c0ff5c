// Volumetric Catmull-Clark: one subdivision step of a hexahedral mesh, as a sparse operator so
// that a fitting pass can reuse it (the volume counterpart of subdiv/subdivision.h).
//
// Interior points follow Joy and MacCracken's rules where they agree with Bajaj et al.'s
// split-and-average scheme (cell points, face points, edge points of 4 cells, vertices whose
// edges all have 4 cells) and Bajaj et al.'s averaging elsewhere; in closed form, a new interior
// point is the mean, over the old cells around it, of the cell's trilinear map at the centre of
// the cell's children that touch the point (docs/volume.md says why). Points on the boundary
// are the surface stage's Catmull-Clark refinement of the boundary quads, with the given creases
// and corners plus, as creases, the edges where the boundary condition changes (so a symmetry
// plane stays a plane and the wall meets it along a cubic B-spline curve, as the surface stage's
// open wall boundary does).
#pragma once

#include <array>
#include <vector>

#include "core/common/types.h"
#include "core/mesh/control_mesh.h"
#include "core/subdiv/subdivision.h"
#include "core/volume/block_mesh.h"

namespace bvmesh::volume {

// Corner c of a hexahedral cell sits at (x, y, z) = kHexCornerBits[c] of the unit cube.
inline constexpr std::array<std::array<int, 3>, 8> kHexCornerBits{
    {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};

// A hexahedral mesh with a boundary condition on every boundary face.
struct HexMesh {
  RowMatrixX3d points;                                // #P x 3
  std::vector<std::array<int, 8>> cells;              // #C, right-handed: 000 100 110 010 001 101 111 011
  std::vector<std::array<int, 4>> boundaryFaces;      // #B quads, each the face of exactly one cell (any order)
  std::vector<BoundaryCondition> boundaryConditions;  // #B, none Connected
  RowMatrixX2i creases = RowMatrixX2i(0, 2);          // point pairs, each an edge of the boundary; infinitely sharp
  std::vector<int> corners;                           // boundary points that stay fixed
};

struct HexSubdivisionResult {
  // Points in a fixed order: the #P moved old points (same ids), then one point per edge, per
  // face and per cell of the old mesh (edges and faces numbered in order of first use walking
  // the cells). Child (x, y, z) of old cell c is cell 8 c + x + 2 y + 4 z, corners in the same
  // order and handedness as its parent. The children of boundary face f are faces 4 f .. 4 f + 3,
  // pointing out of the mesh, child i starting at corner i of the face as the surface stage
  // orders them (corner i, edge point i, face point, edge point i - 1), where the face's corners
  // are as given, reversed after the first if they pointed inwards. Creases: the halves of every
  // crease used (given ones and condition changes); corners stay corners.
  HexMesh mesh;
  // #P' x #P operator: mesh.points == subdivisionOperator * old points.
  RowSparseMatrix subdivisionOperator;
};

// Throws InvalidInputError naming the cell, face, crease or corner for indices out of range,
// repeated cell corners, non-finite points, cells with non-positive volume (inverted or flat),
// boundary faces that are not faces of exactly one cell or not tagged, Connected tags, creases
// that are not boundary edges; TopologyError for a face shared by more than two cells or by two
// cells that both see it with the same orientation, and for a boundary surface the surface
// stage cannot subdivide (non-manifold edges).
HexSubdivisionResult subdivideHexMesh(const HexMesh& mesh, const SubdivisionOptions& options = {});

// The boundary faces tagged Wall as a surface control mesh pointing out of the body (the surface
// fit's orientation), with the mesh's creases along it (not those on its border, which is sharp
// anyway) and its corners on it; local vertex v is mesh point points[v]. Throws InvalidInputError
// when the mesh has no wall face.
struct WallControlMesh {
  std::vector<int> points;
  ControlMesh mesh;
};
WallControlMesh wallControlMesh(const HexMesh& mesh);

// A structured block of a hex mesh: the point at each (i, j, k) lattice position and the cell at
// each cell position, i fastest. `reversed`: the block is left-handed, so its cells were taken
// with i reversed (corner (x, y, z) of a cell sits at lattice offset (1 - x, y, z)).
struct HexBlock {
  std::array<int, 3> size{};  // points per direction
  std::vector<int> pointAt;
  std::vector<int> cellAt;
  bool reversed = false;

  size_t point(int i, int j, int k) const {
    return static_cast<size_t>(i) + static_cast<size_t>(size[0]) * (static_cast<size_t>(j) + static_cast<size_t>(size[1]) * static_cast<size_t>(k));
  }
  size_t cell(int i, int j, int k) const {
    return static_cast<size_t>(i) +
           static_cast<size_t>(size[0] - 1) * (static_cast<size_t>(j) + static_cast<size_t>(size[1] - 1) * static_cast<size_t>(k));
  }
};

// The block after one step of subdivideHexMesh, whose result is `refined`: (2 n - 1) points per
// direction, the children of its cells placed on its lattice.
HexBlock refineHexBlock(const HexBlock& block, const HexMesh& refined);

// The 12 edges of a cell as corner pairs: 4 along x, 4 along y, 4 along z.
inline constexpr std::array<std::array<int, 2>, 12> kHexCellEdges{
    {{0, 1}, {3, 2}, {4, 5}, {7, 6}, {0, 3}, {1, 2}, {4, 7}, {5, 6}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}};

// The 8 corner Jacobian determinants of a cell (corner order as HexMesh::cells): the volume
// spanned at each corner by its three edges, in the right-handed frame; `scaled`: of the edges'
// unit vectors (1 at a right-angled corner).
std::array<double, 8> cornerJacobians(const RowMatrixX3d& points, const std::array<int, 8>& cell, bool scaled = false);

}  // namespace bvmesh::volume

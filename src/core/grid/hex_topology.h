// The structured grid seen as one unstructured hexahedral mesh, numbered the way OpenFOAM's
// polyMesh wants it: distinct points (shared faces merged), cells block by block (i fastest),
// internal faces in upper-triangular order (by owner, then neighbour; owner < neighbour, the
// face pointing from owner to neighbour), then boundary faces patch by patch, pointing out.
// Faces are enumerated on the fly, so writers and quality metrics stream them without storing
// the whole face list. Where a block has a collapsed face, its cells there have merged corners
// (prisms; tetrahedral wedges where two collapsed faces meet, pyramids where one is a point): their faces
// lose the repeated points, and faces left with fewer than three points (on the collapsed face itself) are no
// faces.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "core/grid/structured_grid.h"

namespace bvmesh::grid {

struct HexFace {
  std::array<Eigen::Index, 4> points;  // merged point numbers, counter-clockwise seen from outside the owner
  int size = 4;                        // 4, or 3 where a cell corner merged with the next
  Eigen::Index owner = -1;
  Eigen::Index neighbour = -1;         // -1 on a boundary face
};

// Face `side` (i-min, i-max, j-min, j-max, k-min, k-max) of a right-handed cell with these
// merged corners (order 000 100 110 010 001 101 111 011), counter-clockwise seen from outside,
// its repeated points dropped: a quad, a triangle, or (size below 3) no face.
HexFace hexCellFace(const std::array<Eigen::Index, 8>& corners, int side);

struct BoundaryPatch {
  volume::BoundaryCondition condition;
  std::string name;       // "wall", "symmetry", "farfield", ...
  Eigen::Index size = 0;  // faces
};

class HexTopology {
 public:
  // Refers to `grid`, which must outlive it (a temporary grid is refused at compile time).
  explicit HexTopology(const StructuredGrid& grid);
  explicit HexTopology(StructuredGrid&&) = delete;

  const StructuredGrid& grid() const { return grid_; }
  const MergedPoints& points() const { return merged_; }
  Eigen::Index cellCount() const { return cellOffset_.back(); }
  Eigen::Index internalFaceCount() const { return internalFaces_; }
  const std::vector<BoundaryPatch>& patches() const { return patches_; }
  // The first cell of block b (cells of a block: (i, j, k) at i + (ni - 1) ((j + (nj - 1) k)).
  Eigen::Index cellOffset(size_t b) const { return cellOffset_[b]; }
  // A left-handed block (its (i, j, k) axes span negative volumes) has its cells' corners taken
  // with i reversed, so every cell is right-handed.
  bool mirrored(size_t b) const { return mirrored_[b]; }
  // The 8 merged corners of a cell, right-handed, order 000 100 110 010 001 101 111 011.
  std::array<Eigen::Index, 8> cellCorners(Eigen::Index cell) const;

  void forEachInternalFace(const std::function<void(const HexFace&)>& visit) const;
  // Boundary faces, patch after patch in patches() order; visit(patch, face).
  void forEachBoundaryFace(const std::function<void(size_t, const HexFace&)>& visit) const;

 private:
  struct BlockCell {
    size_t block;
    std::array<int, 3> ijk;
  };
  BlockCell locate(Eigen::Index cell) const;
  // Face `side` (BlockFaceSide order) of a cell, outward, as merged points without repeats; its
  // size is below 3 where the face has collapsed.
  HexFace cellFace(Eigen::Index cell, int side) const;
  // The cell across block face `side` of a cell on that face (another block's), or -1.
  Eigen::Index acrossBlockFace(const BlockCell& at, int side) const;

  const StructuredGrid& grid_;
  MergedPoints merged_;
  std::vector<Eigen::Index> cellOffset_;
  std::vector<bool> mirrored_;
  std::vector<bool> collapsing_;
  std::vector<BoundaryPatch> patches_;
  // Faces between blocks with owner < neighbour, sorted by (owner, neighbour): (owner, side, neighbour).
  std::vector<std::array<Eigen::Index, 3>> interBlock_;
  Eigen::Index internalFaces_ = 0;
};

}  // namespace bvmesh::grid

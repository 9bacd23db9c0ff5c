#include "core/grid/hex_topology.h"

#include <Eigen/Geometry>

#include <algorithm>

#include "core/common/distinct_corners.h"

namespace bvmesh::grid {
namespace {

using volume::BoundaryCondition;

// Outward faces of a right-handed hexahedron (corners 000 100 110 010 001 101 111 011), per side
// i-min, i-max, j-min, j-max, k-min, k-max: counter-clockwise seen from outside.
constexpr std::array<std::array<int, 4>, 6> kCellFaces{{
    {0, 4, 7, 3}, {1, 2, 6, 5}, {0, 1, 5, 4}, {3, 7, 6, 2}, {0, 3, 2, 1}, {4, 5, 6, 7}}};

constexpr std::array<BoundaryCondition, 6> kPatchOrder{BoundaryCondition::Wall,     BoundaryCondition::Symmetry,
                                                        BoundaryCondition::Farfield, BoundaryCondition::Inlet,
                                                        BoundaryCondition::Outlet,   BoundaryCondition::Side};

std::array<int, 3> cellSizes(const GridBlock& block) { return {block.size[0] - 1, block.size[1] - 1, block.size[2] - 1}; }

// Calls visit(ijk) for the cells along block face `side`.
template <class Visit>
void forEachFaceCell(const GridBlock& block, int side, Visit&& visit) {
  const std::array<int, 3> cells = cellSizes(block);
  const std::array<int, 2> counts = volume::faceGridCounts(cells, side);
  for (int b = 0; b < counts[1]; ++b) {
    for (int a = 0; a < counts[0]; ++a) visit(a, b, volume::faceGridPosition(cells, side, a, b));
  }
}

}  // namespace

HexFace hexCellFace(const std::array<Eigen::Index, 8>& corners, int side) {
  std::array<Eigen::Index, 4> quad{};
  for (size_t v = 0; v < 4; ++v)
    quad[v] = corners[static_cast<size_t>(kCellFaces[static_cast<size_t>(side)][v])];
  const DistinctCorners<Eigen::Index> distinct = distinctCorners(quad);
  HexFace face;
  face.points = distinct.points;
  face.size = distinct.size;
  return face;
}

HexTopology::HexTopology(const StructuredGrid& grid) : grid_(grid), merged_(mergePoints(grid)) {
  const auto& blocks = grid.blocks();
  cellOffset_.assign(1, 0);
  for (const GridBlock& block : blocks) {
    cellOffset_.push_back(cellOffset_.back() + block.cellCount());
    // Handedness from the summed corner Jacobians of its cells.
    double volume = 0.0;
    for (int k = 0; k + 1 < block.size[2]; ++k) {
      for (int j = 0; j + 1 < block.size[1]; ++j) {
        for (int i = 0; i + 1 < block.size[0]; ++i) {
          const Eigen::Vector3d x = block.points.row(block.index(i, j, k)).transpose();
          const Eigen::Vector3d a = block.points.row(block.index(i + 1, j, k)).transpose() - x;
          const Eigen::Vector3d b = block.points.row(block.index(i, j + 1, k)).transpose() - x;
          const Eigen::Vector3d c = block.points.row(block.index(i, j, k + 1)).transpose() - x;
          volume += a.cross(b).dot(c);
        }
      }
    }
    mirrored_.push_back(volume < 0.0);
  }
  // Only cells of a block whose own grid positions share a merged point (its collapsed face's,
  // or a neighbour's merged into two of its own) can have merged corners.
  std::vector<char> seen(static_cast<size_t>(merged_.points.rows()), 0);
  for (size_t b = 0; b < blocks.size(); ++b) {
    const auto first = merged_.pointOf.begin() + merged_.blockOffset[b];
    const auto last = merged_.pointOf.begin() + merged_.blockOffset[b + 1];
    bool repeats = false;
    for (auto p = first; p != last; ++p) {
      repeats = repeats || seen[static_cast<size_t>(*p)] != 0;
      seen[static_cast<size_t>(*p)] = 1;
    }
    for (auto p = first; p != last; ++p) seen[static_cast<size_t>(*p)] = 0;
    collapsing_.push_back(repeats);
  }
  auto collapsedFace = [&](Eigen::Index cell, int side) { return cellFace(cell, side).size < 3; };
  for (size_t b = 0; b < blocks.size(); ++b) {
    for (int side = 0; side < 6; ++side) {
      const volume::BlockFace& face = blocks[b].faces[static_cast<size_t>(side)];
      if (face.condition != BoundaryCondition::Connected) continue;
      forEachFaceCell(blocks[b], side, [&](int, int, const std::array<int, 3>& ijk) {
        const std::array<int, 3> cells = cellSizes(blocks[b]);
        const Eigen::Index cell = cellOffset_[b] + ijk[0] + static_cast<Eigen::Index>(cells[0]) * (ijk[1] + static_cast<Eigen::Index>(cells[1]) * ijk[2]);
        const Eigen::Index other = acrossBlockFace({b, ijk}, side);
        if (cell < other && !(collapsing_[b] && collapsedFace(cell, side))) interBlock_.push_back({cell, side, other});
      });
    }
  }
  std::sort(interBlock_.begin(), interBlock_.end(),
            [](const auto& x, const auto& y) { return x[0] != y[0] ? x[0] < y[0] : x[2] < y[2]; });
  internalFaces_ = static_cast<Eigen::Index>(interBlock_.size());
  for (size_t b = 0; b < blocks.size(); ++b) {
    const std::array<int, 3> c = cellSizes(blocks[b]);
    internalFaces_ += static_cast<Eigen::Index>(c[0] - 1) * c[1] * c[2] + static_cast<Eigen::Index>(c[0]) * (c[1] - 1) * c[2] +
                      static_cast<Eigen::Index>(c[0]) * c[1] * (c[2] - 1);
    if (!collapsing_[b]) continue;
    for (Eigen::Index cell = cellOffset_[b]; cell < cellOffset_[b + 1]; ++cell) {
      const BlockCell at = locate(cell);
      for (int d = 0; d < 3; ++d) {
        if (at.ijk[static_cast<size_t>(d)] + 1 < c[static_cast<size_t>(d)] && collapsedFace(cell, 2 * d + 1)) --internalFaces_;
      }
    }
  }
  for (BoundaryCondition condition : kPatchOrder) {
    BoundaryPatch patch{condition, volume::boundaryConditionName(condition), 0};
    for (size_t b = 0; b < blocks.size(); ++b) {
      const GridBlock& block = blocks[b];
      const std::array<int, 3> c = cellSizes(block);
      for (int side = 0; side < 6; ++side) {
        const BoundaryCondition own = block.faces[static_cast<size_t>(side)].condition;
        if (own == BoundaryCondition::Connected || own == BoundaryCondition::Collapsed) continue;
        forEachFaceCell(block, side, [&](int qa, int qb, const std::array<int, 3>& ijk) {
          if (block.quadCondition(side, qa, qb) != condition) return;
          const Eigen::Index cell = cellOffset_[b] + ijk[0] + static_cast<Eigen::Index>(c[0]) * (ijk[1] + static_cast<Eigen::Index>(c[1]) * ijk[2]);
          if (!(collapsing_[b] && collapsedFace(cell, side))) ++patch.size;
        });
      }
    }
    if (patch.size > 0) patches_.push_back(patch);
  }
}

HexTopology::BlockCell HexTopology::locate(Eigen::Index cell) const {
  const size_t b = static_cast<size_t>(std::upper_bound(cellOffset_.begin(), cellOffset_.end(), cell) - cellOffset_.begin()) - 1;
  const std::array<int, 3> c = cellSizes(grid_.blocks()[b]);
  const Eigen::Index local = cell - cellOffset_[b];
  return {b, {static_cast<int>(local % c[0]), static_cast<int>((local / c[0]) % c[1]),
              static_cast<int>(local / (static_cast<Eigen::Index>(c[0]) * c[1]))}};
}

std::array<Eigen::Index, 8> HexTopology::cellCorners(Eigen::Index cell) const {
  const BlockCell at = locate(cell);
  const GridBlock& block = grid_.blocks()[at.block];
  const bool flip = mirrored_[at.block];
  std::array<Eigen::Index, 8> corners{};
  for (int corner = 0; corner < 8; ++corner) {
    const int k = corner / 4;
    const int j = (corner % 4) / 2;
    const int i = (corner % 4 == 1 || corner % 4 == 2) ? 1 : 0;
    const int along = flip ? 1 - i : i;
    const Eigen::Index row = block.index(at.ijk[0] + along, at.ijk[1] + j, at.ijk[2] + k);
    corners[static_cast<size_t>(corner)] = merged_.pointOf[static_cast<size_t>(merged_.blockOffset[at.block] + row)];
  }
  return corners;
}

HexFace HexTopology::cellFace(Eigen::Index cell, int side) const {
  const BlockCell at = locate(cell);
  // In a mirrored block the grid's i-min side is the right-handed cell's i-max side.
  const int logical = mirrored_[at.block] && side < 2 ? 1 - side : side;
  HexFace face = hexCellFace(cellCorners(cell), logical);
  face.owner = cell;
  return face;
}

Eigen::Index HexTopology::acrossBlockFace(const BlockCell& at, int side) const {
  const GridBlock& block = grid_.blocks()[at.block];
  const volume::FaceConnection& link = block.faces[static_cast<size_t>(side)].neighbour;
  const std::array<int, 2> directions = volume::faceDirections(side);
  const int a = at.ijk[static_cast<size_t>(directions[0])];
  const int b = at.ijk[static_cast<size_t>(directions[1])];
  const GridBlock& other = grid_.blocks()[static_cast<size_t>(link.block)];
  const std::array<int, 3> otherCells = cellSizes(other);
  const std::array<int, 2> there =
      volume::BlockMesh::mapFacePosition(link, volume::faceGridCounts(otherCells, link.face), a, b);
  const std::array<int, 3> ijk = volume::faceGridPosition(otherCells, link.face, there[0], there[1]);
  return cellOffset_[static_cast<size_t>(link.block)] + ijk[0] +
         static_cast<Eigen::Index>(otherCells[0]) * (ijk[1] + static_cast<Eigen::Index>(otherCells[1]) * ijk[2]);
}

void HexTopology::forEachInternalFace(const std::function<void(const HexFace&)>& visit) const {
  auto next = interBlock_.begin();
  for (size_t b = 0; b < grid_.blocks().size(); ++b) {
    const std::array<int, 3> c = cellSizes(grid_.blocks()[b]);
    const Eigen::Index strides[3] = {1, c[0], static_cast<Eigen::Index>(c[0]) * c[1]};
    for (Eigen::Index cell = cellOffset_[b]; cell < cellOffset_[b + 1]; ++cell) {
      const BlockCell at = locate(cell);
      // In-block neighbours (i + 1, j + 1, k + 1 come in increasing order), then faces to later
      // blocks' cells, which have larger numbers still.
      for (int d = 0; d < 3; ++d) {
        if (at.ijk[static_cast<size_t>(d)] + 1 < c[static_cast<size_t>(d)]) {
          HexFace face = cellFace(cell, 2 * d + 1);
          face.neighbour = cell + strides[d];
          if (face.size >= 3) visit(face);
        }
      }
      for (; next != interBlock_.end() && (*next)[0] == cell; ++next) {
        HexFace face = cellFace(cell, static_cast<int>((*next)[1]));
        face.neighbour = (*next)[2];
        visit(face);
      }
    }
  }
}

void HexTopology::forEachBoundaryFace(const std::function<void(size_t, const HexFace&)>& visit) const {
  const auto& blocks = grid_.blocks();
  for (size_t patch = 0; patch < patches_.size(); ++patch) {
    for (size_t b = 0; b < blocks.size(); ++b) {
      const std::array<int, 3> c = cellSizes(blocks[b]);
      for (int side = 0; side < 6; ++side) {
        const BoundaryCondition own = blocks[b].faces[static_cast<size_t>(side)].condition;
        if (own == BoundaryCondition::Connected || own == BoundaryCondition::Collapsed) continue;
        forEachFaceCell(blocks[b], side, [&](int qa, int qb, const std::array<int, 3>& ijk) {
          if (blocks[b].quadCondition(side, qa, qb) != patches_[patch].condition) return;
          const Eigen::Index cell = cellOffset_[b] + ijk[0] + static_cast<Eigen::Index>(c[0]) * (ijk[1] + static_cast<Eigen::Index>(c[1]) * ijk[2]);
          const HexFace face = cellFace(cell, side);
          if (face.size >= 3) visit(patch, face);
        });
      }
    }
  }
}

}  // namespace bvmesh::grid

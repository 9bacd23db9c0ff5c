#include "core/grid/structured_grid.h"

#include <algorithm>
#include <string>

#include "core/common/errors.h"
#include "core/common/input_checks.h"
#include "core/common/number_text.h"
#include "core/common/parallel.h"

namespace bvmesh::grid {

Eigen::Index GridBlock::facePoint(int face, int a, int b) const {
  const std::array<int, 3> ijk = volume::faceGridPosition(size, face, a, b);
  return index(ijk[0], ijk[1], ijk[2]);
}

volume::BoundaryCondition GridBlock::quadCondition(int face, int a, int b) const {
  const std::vector<volume::BoundaryCondition>& quads = quadConditions[static_cast<size_t>(face)];
  if (quads.empty()) return faces[static_cast<size_t>(face)].condition;
  const std::array<int, 2> counts = volume::faceGridCounts(size, face);
  return quads[static_cast<size_t>(a + static_cast<Eigen::Index>(counts[0] - 1) * b)];
}

StructuredGrid::StructuredGrid(std::vector<GridBlock> blocks, bool viscousWall)
    : blocks_(std::move(blocks)), viscousWall_(viscousWall) {
  std::vector<std::array<volume::BlockFace, 6>> faces;
  std::vector<std::array<int, 3>> sizes;
  for (size_t b = 0; b < blocks_.size(); ++b) {
    const GridBlock& block = blocks_[b];
    const std::string name = "grid block " + std::to_string(b);
    for (int d = 0; d < 3; ++d) {
      if (block.size[static_cast<size_t>(d)] < 2) {
        throw InvalidInputError(name + " has " + std::to_string(block.size[static_cast<size_t>(d)]) +
                                " points along direction " + "ijk"[d] + " (at least 2 are needed)");
      }
    }
    if (block.points.rows() != block.pointCount()) {
      throw InvalidInputError(name + " has " + std::to_string(block.points.rows()) + " points, its size " +
                              std::to_string(block.size[0]) + " x " + std::to_string(block.size[1]) + " x " +
                              std::to_string(block.size[2]) + " needs " + std::to_string(block.pointCount()));
    }
    for (int f = 0; f < 6; ++f) {
      findCollapsedAxes(b, f);
      const std::vector<volume::BoundaryCondition>& quads = block.quadConditions[static_cast<size_t>(f)];
      if (quads.empty()) continue;
      const std::array<int, 2> counts = volume::faceGridCounts(block.size, f);
      const auto expected = static_cast<size_t>(counts[0] - 1) * static_cast<size_t>(counts[1] - 1);
      const volume::BoundaryCondition whole = block.faces[static_cast<size_t>(f)].condition;
      const auto notABoundary = [](volume::BoundaryCondition c) {
        return c == volume::BoundaryCondition::Connected || c == volume::BoundaryCondition::Collapsed;
      };
      if (notABoundary(whole) || quads.size() != expected ||
          std::any_of(quads.begin(), quads.end(), notABoundary)) {
        throw InvalidInputError(name + " face " + volume::blockFaceName(f) + " (" +
                                volume::boundaryConditionName(whole) + ") has " +
                                std::to_string(quads.size()) +
                                " quad conditions; a boundary face takes one per quad (" +
                                std::to_string(expected) + "), none of them 'connected' or 'collapsed'");
      }
    }
    faces.push_back(block.faces);
    sizes.push_back(block.size);
  }
  volume::checkFaceConnections(faces, sizes, "points");
  // The points' checks, per block its points and its connected faces, on every core (a
  // million-cell grid's checks took a tenth of its refinement on one).
  parallelChunks(static_cast<std::int64_t>(blocks_.size()), 1, [&](std::int64_t begin, std::int64_t end) {
    for (auto b = static_cast<size_t>(begin); b < static_cast<size_t>(end); ++b) {
      checkFinitePoints(blocks_[b].points, "grid block " + std::to_string(b) + " point");
      for (int f = 0; f < 6; ++f) {
        if (faces[b][static_cast<size_t>(f)].condition == volume::BoundaryCondition::Connected) checkPointMatching(b, f);
      }
    }
  });
}

void StructuredGrid::findCollapsedAxes(size_t b, int f) {
  GridBlock& block = blocks_[b];
  volume::BlockFace& face = block.faces[static_cast<size_t>(f)];
  face.collapsedAlong =
      face.condition == volume::BoundaryCondition::Collapsed
          ? volume::collapsedFaceAxes(block.points, block.size, f,
                                      "grid block " + std::to_string(b) + " face " + volume::blockFaceName(f),
                                      "points")
          : std::array<bool, 2>{false, false};
}

void StructuredGrid::checkPointMatching(size_t b, int f) const {
  const GridBlock& mine = blocks_[b];
  const volume::BlockFace& face = mine.faces[static_cast<size_t>(f)];
  const GridBlock& theirs = blocks_[static_cast<size_t>(face.neighbour.block)];
  const std::array<int, 2> counts = volume::faceGridCounts(mine.size, f);
  const volume::FaceRows here = volume::faceRows(mine.size, f);
  const volume::FaceRows there = volume::BlockMesh::neighbourFaceRows(face.neighbour, theirs.size);
  for (int c = 0; c < counts[1]; ++c) {
    for (int a = 0; a < counts[0]; ++a) {
      const auto p = mine.points.row(here.at(a, c));
      const auto q = theirs.points.row(there.at(a, c));
      if (p != q) {
        throw InvalidInputError(
            "grid block " + std::to_string(b) + " face " + volume::blockFaceName(f) + " point (" +
            std::to_string(a) + ", " + std::to_string(c) + ") differs from its neighbour's in block " +
            std::to_string(face.neighbour.block) + " face " + volume::blockFaceName(face.neighbour.face) +
            " by " + numberText((p - q).norm()) + " (shared faces must be point-matched)");
      }
    }
  }
}

Eigen::Index StructuredGrid::pointCount() const {
  Eigen::Index total = 0;
  for (const GridBlock& block : blocks_) total += block.pointCount();
  return total;
}

Eigen::Index StructuredGrid::cellCount() const {
  Eigen::Index total = 0;
  for (const GridBlock& block : blocks_) total += block.cellCount();
  return total;
}

MergedPoints mergePoints(const StructuredGrid& grid) {
  std::vector<std::array<volume::BlockFace, 6>> faces;
  std::vector<std::array<int, 3>> sizes;
  MergedPoints result;
  result.blockOffset.assign(1, 0);
  for (const GridBlock& block : grid.blocks()) {
    faces.push_back(block.faces);
    sizes.push_back(block.size);
    result.blockOffset.push_back(result.blockOffset.back() + block.pointCount());
  }
  const std::vector<Eigen::Index> roots = volume::sharedGridRoots(faces, sizes);
  result.pointOf.assign(roots.size(), -1);
  Eigen::Index distinct = 0;
  for (size_t global = 0; global < roots.size(); ++global) {
    const auto root = static_cast<size_t>(roots[global]);
    // A root is the smallest of its set, so it is met (and numbered) before its other members.
    if (root == global) result.pointOf[global] = distinct++;
    else result.pointOf[global] = result.pointOf[root];
  }
  result.points.resize(distinct, 3);
  for (size_t b = 0; b < grid.blocks().size(); ++b) {
    const RowMatrixX3d& points = grid.blocks()[b].points;
    for (Eigen::Index r = 0; r < points.rows(); ++r) {
      const auto global = static_cast<size_t>(result.blockOffset[b] + r);
      if (static_cast<size_t>(roots[global]) == global) result.points.row(result.pointOf[global]) = points.row(r);
    }
  }
  return result;
}

}  // namespace bvmesh::grid

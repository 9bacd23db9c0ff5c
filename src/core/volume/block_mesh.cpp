#include "core/volume/block_mesh.h"

#include <cmath>
#include <numeric>
#include <string>

#include "core/common/errors.h"
#include "core/common/number_text.h"

namespace bvmesh::volume {
namespace {

std::string faceText(int block, int face) {
  return "block " + std::to_string(block) + " face " + blockFaceName(face);
}

// The knot vector seen backwards, moved back onto the same range.
std::vector<double> mirrored(const std::vector<double>& knots) {
  std::vector<double> result(knots.size());
  for (size_t k = 0; k < knots.size(); ++k) result[k] = knots.front() + knots.back() - knots[knots.size() - 1 - k];
  return result;
}

bool sameKnots(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  const double scale = std::max(1.0, std::abs(a.back() - a.front()));
  for (size_t k = 0; k < a.size(); ++k) {
    if (std::abs(a[k] - b[k]) > 1e-12 * scale) return false;
  }
  return true;
}

}  // namespace

const char* boundaryConditionName(BoundaryCondition condition) {
  switch (condition) {
    case BoundaryCondition::Connected:
      return "connected";
    case BoundaryCondition::Wall:
      return "wall";
    case BoundaryCondition::Symmetry:
      return "symmetry";
    case BoundaryCondition::Farfield:
      return "farfield";
    case BoundaryCondition::Inlet:
      return "inlet";
    case BoundaryCondition::Outlet:
      return "outlet";
    case BoundaryCondition::Side:
      return "side";
    case BoundaryCondition::Collapsed:
      return "collapsed";
  }
  return "";
}

std::optional<BoundaryCondition> findBoundaryCondition(const std::string& name) {
  for (BoundaryCondition c : {BoundaryCondition::Connected, BoundaryCondition::Wall, BoundaryCondition::Symmetry,
                              BoundaryCondition::Farfield, BoundaryCondition::Inlet, BoundaryCondition::Outlet,
                              BoundaryCondition::Side, BoundaryCondition::Collapsed}) {
    if (name == boundaryConditionName(c)) return c;
  }
  return std::nullopt;
}

const char* blockFaceName(int face) {
  static const char* names[] = {"u_min", "u_max", "v_min", "v_max", "w_min", "w_max"};
  return face >= 0 && face < 6 ? names[face] : "(no face)";
}

std::array<int, 2> faceDirections(int face) {
  switch (face / 2) {
    case 0:
      return {1, 2};
    case 1:
      return {0, 2};
    default:
      return {0, 1};
  }
}

std::array<int, 2> faceGridCounts(const std::array<int, 3>& counts, int face) {
  const auto [first, second] = faceDirections(face);
  return {counts[static_cast<size_t>(first)], counts[static_cast<size_t>(second)]};
}

std::array<int, 3> faceGridPosition(const std::array<int, 3>& counts, int face, int a, int b) {
  const int fixed = face / 2;
  std::array<int, 3> ijk{};
  const auto [first, second] = faceDirections(face);
  ijk[static_cast<size_t>(fixed)] = face % 2 == 0 ? 0 : counts[static_cast<size_t>(fixed)] - 1;
  ijk[static_cast<size_t>(first)] = a;
  ijk[static_cast<size_t>(second)] = b;
  return ijk;
}

FaceRows faceRows(const std::array<int, 3>& counts, int face) {
  const std::array<Eigen::Index, 3> stride{1, counts[0], static_cast<Eigen::Index>(counts[0]) * counts[1]};
  const std::array<int, 3> origin = faceGridPosition(counts, face, 0, 0);
  const auto [first, second] = faceDirections(face);
  return {origin[0] * stride[0] + origin[1] * stride[1] + origin[2] * stride[2],
          stride[static_cast<size_t>(first)], stride[static_cast<size_t>(second)]};
}

std::array<bool, 2> coincidentAlongFace(const RowMatrixX3d& grid, const std::array<int, 3>& counts, int face) {
  const std::array<int, 2> sizes = faceGridCounts(counts, face);
  const FaceRows rows = faceRows(counts, face);
  std::array<bool, 2> along{true, true};
  for (int b = 0; b < sizes[1]; ++b) {
    for (int a = 0; a < sizes[0]; ++a) {
      if (grid.row(rows.at(a, b)) != grid.row(rows.at(0, b))) along[0] = false;
      if (grid.row(rows.at(a, b)) != grid.row(rows.at(a, 0))) along[1] = false;
    }
  }
  return along;
}

std::array<bool, 2> collapsedFaceAxes(const RowMatrixX3d& grid, const std::array<int, 3>& counts, int face,
                                      const std::string& faceName, const std::string& pointsName) {
  const std::array<bool, 2> along = coincidentAlongFace(grid, counts, face);
  if (!along[0] && !along[1]) {
    throw InvalidInputError(
        faceName + " is collapsed, but its " + pointsName +
        " differ along both of its directions (a collapsed face is one curve or one point: its " +
        pointsName + " identical bit for bit along a row)");
  }
  return along;
}

namespace {
std::array<int, 3> poleCounts(const BsplineVolume& volume) {
  return {volume.poleCount(0), volume.poleCount(1), volume.poleCount(2)};
}
}  // namespace

std::array<int, 2> BlockMesh::facePoleCounts(const BsplineVolume& volume, int face) {
  return faceGridCounts(poleCounts(volume), face);
}

Eigen::Index BlockMesh::facePole(const BsplineVolume& volume, int face, int a, int b) {
  const std::array<int, 3> ijk = faceGridPosition(poleCounts(volume), face, a, b);
  return volume.poleIndex(ijk[0], ijk[1], ijk[2]);
}

FaceRows BlockMesh::neighbourFaceRows(const FaceConnection& connection,
                                      const std::array<int, 3>& neighbourCounts) {
  const FaceRows theirs = faceRows(neighbourCounts, connection.face);
  const std::array<int, 2> counts = faceGridCounts(neighbourCounts, connection.face);
  // Along the neighbour's own face directions, then swapped onto (a, b).
  FaceRows rows{theirs.base, theirs.first, theirs.second};
  if (connection.reverseFirst) {
    rows.base += (counts[0] - 1) * theirs.first;
    rows.first = -theirs.first;
  }
  if (connection.reverseSecond) {
    rows.base += (counts[1] - 1) * theirs.second;
    rows.second = -theirs.second;
  }
  if (connection.swapped) std::swap(rows.first, rows.second);
  return rows;
}

std::array<int, 2> BlockMesh::mapFacePosition(const FaceConnection& connection,
                                              const std::array<int, 2>& neighbourCounts, int a, int b) {
  std::array<int, 2> mapped = connection.swapped ? std::array<int, 2>{b, a} : std::array<int, 2>{a, b};
  if (connection.reverseFirst) mapped[0] = neighbourCounts[0] - 1 - mapped[0];
  if (connection.reverseSecond) mapped[1] = neighbourCounts[1] - 1 - mapped[1];
  return mapped;
}

void checkFaceConnections(const std::vector<std::array<BlockFace, 6>>& faces,
                          const std::vector<std::array<int, 3>>& counts, const char* unit) {
  const int blockCount = static_cast<int>(faces.size());
  for (int b = 0; b < blockCount; ++b) {
    for (int f = 0; f < 6; ++f) {
      const BlockFace& face = faces[static_cast<size_t>(b)][static_cast<size_t>(f)];
      if (face.condition != BoundaryCondition::Connected) continue;
      const FaceConnection& link = face.neighbour;
      if (link.block < 0 || link.block >= blockCount || link.face < 0 || link.face >= 6) {
        throw InvalidInputError(faceText(b, f) + " is connected to block " + std::to_string(link.block) + " face " +
                                std::to_string(link.face) + ", which does not exist (" + std::to_string(blockCount) +
                                " blocks)");
      }
      if (link.block == b && link.face == f) throw InvalidInputError(faceText(b, f) + " is connected to itself");
      const BlockFace& back = faces[static_cast<size_t>(link.block)][static_cast<size_t>(link.face)];
      const bool firstBack = link.swapped ? link.reverseSecond : link.reverseFirst;
      const bool secondBack = link.swapped ? link.reverseFirst : link.reverseSecond;
      if (back.condition != BoundaryCondition::Connected || back.neighbour.block != b || back.neighbour.face != f ||
          back.neighbour.swapped != link.swapped || back.neighbour.reverseFirst != firstBack ||
          back.neighbour.reverseSecond != secondBack) {
        throw InvalidInputError(faceText(b, f) + " is connected to " + faceText(link.block, link.face) +
                                ", which is not connected back with the inverse orientation");
      }
      const std::array<int, 2> mine = faceGridCounts(counts[static_cast<size_t>(b)], f);
      const std::array<int, 2> theirs = faceGridCounts(counts[static_cast<size_t>(link.block)], link.face);
      for (int axis = 0; axis < 2; ++axis) {
        const int theirAxis = link.swapped ? 1 - axis : axis;
        if (mine[static_cast<size_t>(axis)] != theirs[static_cast<size_t>(theirAxis)]) {
          throw InvalidInputError(faceText(b, f) + " has " + std::to_string(mine[static_cast<size_t>(axis)]) + " " +
                                  unit + " along its axis " + std::to_string(axis) + ", its neighbour " +
                                  faceText(link.block, link.face) + " " +
                                  std::to_string(theirs[static_cast<size_t>(theirAxis)]));
        }
      }
    }
  }
}

BlockMesh::BlockMesh(std::vector<Block> blocks) : blocks_(std::move(blocks)) {
  std::vector<std::array<BlockFace, 6>> faces;
  std::vector<std::array<int, 3>> poleGrids;
  for (const Block& block : blocks_) {
    faces.push_back(block.faces);
    poleGrids.push_back(poleCounts(block.volume));
  }
  checkFaceConnections(faces, poleGrids, "poles");
  const int count = blockCount();
  for (int b = 0; b < count; ++b) {
    for (int f = 0; f < 6; ++f) {
      BlockFace& face = blocks_[static_cast<size_t>(b)].faces[static_cast<size_t>(f)];
      if (face.condition == BoundaryCondition::Collapsed) {
        face.collapsedAlong =
            collapsedFaceAxes(blocks_[static_cast<size_t>(b)].volume.poles(),
                              poleGrids[static_cast<size_t>(b)], f, faceText(b, f), "poles");
        continue;
      }
      face.collapsedAlong = {false, false};
      if (face.condition != BoundaryCondition::Connected) continue;
      const FaceConnection& link = face.neighbour;
      const BsplineVolume& mine = blocks_[static_cast<size_t>(b)].volume;
      const BsplineVolume& theirs = blocks_[static_cast<size_t>(link.block)].volume;
      const std::array<int, 2> counts = facePoleCounts(mine, f);
      const std::array<int, 2> otherCounts = facePoleCounts(theirs, link.face);
      const std::array<int, 2> myDirections = faceDirections(f);
      const std::array<int, 2> theirDirections = faceDirections(link.face);
      for (int axis = 0; axis < 2; ++axis) {
        const int theirAxis = link.swapped ? 1 - axis : axis;
        const bool reversed = theirAxis == 0 ? link.reverseFirst : link.reverseSecond;
        const std::vector<double>& myKnots = mine.knots(myDirections[static_cast<size_t>(axis)]);
        const std::vector<double>& theirKnots = theirs.knots(theirDirections[static_cast<size_t>(theirAxis)]);
        if (mine.degree(myDirections[static_cast<size_t>(axis)]) !=
                theirs.degree(theirDirections[static_cast<size_t>(theirAxis)]) ||
            !sameKnots(reversed ? mirrored(theirKnots) : theirKnots, myKnots)) {
          throw InvalidInputError(faceText(b, f) + " and " + faceText(link.block, link.face) +
                                  " have different degrees or knot vectors along the shared face");
        }
      }
      for (int a = 0; a < counts[0]; ++a) {
        for (int c = 0; c < counts[1]; ++c) {
          const std::array<int, 2> there = mapFacePosition(link, otherCounts, a, c);
          const auto p = mine.poles().row(facePole(mine, f, a, c));
          const auto q = theirs.poles().row(facePole(theirs, link.face, there[0], there[1]));
          if (p != q) {
            throw InvalidInputError(faceText(b, f) + " pole (" + std::to_string(a) + ", " +
                                    std::to_string(c) + ") differs from its neighbour's in " +
                                    faceText(link.block, link.face) + " by " + numberText((p - q).norm()) +
                                    " (shared faces must be identical)");
          }
        }
      }
    }
  }
}

std::vector<Eigen::Index> sharedGridRoots(const std::vector<std::array<BlockFace, 6>>& faces,
                                          const std::vector<std::array<int, 3>>& counts) {
  std::vector<Eigen::Index> offset(counts.size() + 1, 0);
  for (size_t b = 0; b < counts.size(); ++b) {
    offset[b + 1] = offset[b] + static_cast<Eigen::Index>(counts[b][0]) * counts[b][1] * counts[b][2];
  }
  std::vector<Eigen::Index> parent(static_cast<size_t>(offset.back()));
  std::iota(parent.begin(), parent.end(), Eigen::Index{0});
  auto find = [&](Eigen::Index x) {
    while (parent[static_cast<size_t>(x)] != x) {
      parent[static_cast<size_t>(x)] = parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
      x = parent[static_cast<size_t>(x)];
    }
    return x;
  };
  // The smaller index becomes the root, so every position's root is the smallest it is shared with.
  auto join = [&](Eigen::Index p, Eigen::Index q) {
    const Eigen::Index rp = find(p), rq = find(q);
    if (rp != rq) parent[static_cast<size_t>(std::max(rp, rq))] = std::min(rp, rq);
  };
  for (size_t b = 0; b < faces.size(); ++b) {
    for (int f = 0; f < 6; ++f) {
      const BlockFace& face = faces[b][static_cast<size_t>(f)];
      const std::array<int, 2> mine = faceGridCounts(counts[b], f);
      const FaceRows here = faceRows(counts[b], f);
      if (face.condition == BoundaryCondition::Collapsed) {
        for (int c = 0; c < mine[1]; ++c) {
          for (int a = 0; a < mine[0]; ++a) {
            if (face.collapsedAlong[0]) join(offset[b] + here.at(a, c), offset[b] + here.at(0, c));
            if (face.collapsedAlong[1]) join(offset[b] + here.at(a, c), offset[b] + here.at(a, 0));
          }
        }
        continue;
      }
      if (face.condition != BoundaryCondition::Connected) continue;
      const size_t other = static_cast<size_t>(face.neighbour.block);
      const FaceRows there = BlockMesh::neighbourFaceRows(face.neighbour, counts[other]);
      for (int c = 0; c < mine[1]; ++c) {
        for (int a = 0; a < mine[0]; ++a) join(offset[b] + here.at(a, c), offset[other] + there.at(a, c));
      }
    }
  }
  for (Eigen::Index x = 0; x < offset.back(); ++x) parent[static_cast<size_t>(x)] = find(x);
  return parent;
}

VolumeControlMesh volumeControlMesh(const BlockMesh& mesh) {
  VolumeControlMesh result;
  const auto& blocks = mesh.blocks();
  result.blockPointOffset.resize(blocks.size() + 1, 0);
  std::vector<std::array<BlockFace, 6>> faces;
  std::vector<std::array<int, 3>> poleGrids;
  for (size_t b = 0; b < blocks.size(); ++b) {
    result.blockPointOffset[b + 1] =
        result.blockPointOffset[b] + static_cast<int>(blocks[b].volume.poles().rows());
    faces.push_back(blocks[b].faces);
    poleGrids.push_back(poleCounts(blocks[b].volume));
  }
  const std::vector<Eigen::Index> roots = sharedGridRoots(faces, poleGrids);
  result.pointOfPole.assign(roots.size(), -1);
  std::vector<int> pointOfRoot(roots.size(), -1);
  std::vector<Eigen::Vector3d> points;
  for (size_t b = 0; b < blocks.size(); ++b) {
    const RowMatrixX3d& poles = blocks[b].volume.poles();
    for (Eigen::Index r = 0; r < poles.rows(); ++r) {
      const int global = result.blockPointOffset[b] + static_cast<int>(r);
      const auto root = roots[static_cast<size_t>(global)];
      if (pointOfRoot[static_cast<size_t>(root)] < 0) {
        pointOfRoot[static_cast<size_t>(root)] = static_cast<int>(points.size());
        points.emplace_back(poles.row(r).transpose());
      }
      result.pointOfPole[static_cast<size_t>(global)] = pointOfRoot[static_cast<size_t>(root)];
    }
  }
  result.points.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t p = 0; p < points.size(); ++p) result.points.row(static_cast<Eigen::Index>(p)) = points[p].transpose();
  for (size_t b = 0; b < blocks.size(); ++b) {
    const BsplineVolume& volume = blocks[b].volume;
    auto point = [&](int i, int j, int k) {
      return result.pointOfPole[static_cast<size_t>(result.blockPointOffset[b] + volume.poleIndex(i, j, k))];
    };
    const int nu = volume.poleCount(0), nv = volume.poleCount(1), nw = volume.poleCount(2);
    for (int k = 0; k + 1 < nw; ++k) {
      for (int j = 0; j + 1 < nv; ++j) {
        for (int i = 0; i + 1 < nu; ++i) {
          result.cells.push_back({point(i, j, k), point(i + 1, j, k), point(i + 1, j + 1, k), point(i, j + 1, k),
                                  point(i, j, k + 1), point(i + 1, j, k + 1), point(i + 1, j + 1, k + 1),
                                  point(i, j + 1, k + 1)});
          result.cellBlock.push_back(static_cast<int>(b));
        }
      }
    }
    for (int f = 0; f < 6; ++f) {
      const BoundaryCondition condition = blocks[b].faces[static_cast<size_t>(f)].condition;
      if (condition == BoundaryCondition::Connected || condition == BoundaryCondition::Collapsed) continue;
      const std::array<int, 2> counts = BlockMesh::facePoleCounts(volume, f);
      for (int a = 0; a + 1 < counts[0]; ++a) {
        for (int c = 0; c + 1 < counts[1]; ++c) {
          auto at = [&](int x, int y) {
            return result.pointOfPole[static_cast<size_t>(result.blockPointOffset[b] +
                                                          BlockMesh::facePole(volume, f, x, y))];
          };
          result.boundaryFaces.push_back({at(a, c), at(a + 1, c), at(a + 1, c + 1), at(a, c + 1)});
          result.boundaryConditions.push_back(condition);
        }
      }
    }
  }
  return result;
}

}  // namespace bvmesh::volume

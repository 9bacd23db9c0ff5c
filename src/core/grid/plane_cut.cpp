#include "core/grid/plane_cut.h"

#include <array>
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/common/errors.h"
#include "core/common/parallel.h"

namespace bvmesh::grid {
namespace {

struct Segments {
  std::vector<Eigen::Vector3d> start, end;
  std::vector<Eigen::Index> cell;
};

// Crossings closer than this, relative to the quad's size and coordinates, are one point.
constexpr double kCoincidentCrossings = 1e-12;

// The cut of one quad (corners in cyclic order, signed distances d) into `out`: no segment, one,
// or two at a saddle (all four edges crossed), paired by the sign at the quad's centre. A segment
// whose two ends coincide is left out: a face collapsed into an edge (a fan's wall face, the merged
// side of a prism) has no grid line of its own, nor has a face the plane touches at a corner alone,
// and a drawn segment needs two distinct points.
void cutQuad(const std::array<Eigen::Vector3d, 4>& corner, const std::array<double, 4>& d, Eigen::Index cell, Segments& out) {
  std::array<Eigen::Vector3d, 4> crossing;
  int count = 0;
  for (int e = 0; e < 4; ++e) {
    const int a = e, b = (e + 1) % 4;
    if ((d[a] >= 0.0) == (d[b] >= 0.0)) continue;
    const double t = d[a] / (d[a] - d[b]);
    crossing[count] = corner[a] + t * (corner[b] - corner[a]);
    ++count;
  }
  double scale = 0.0;
  for (int c = 0; c < 4; ++c) {
    scale = std::max({scale, corner[c].lpNorm<Eigen::Infinity>(),
                      (corner[(c + 1) % 4] - corner[c]).lpNorm<Eigen::Infinity>()});
  }
  const auto add = [&](int p, int q) {
    if ((crossing[p] - crossing[q]).lpNorm<Eigen::Infinity>() <= kCoincidentCrossings * scale) return;
    out.start.push_back(crossing[p]);
    out.end.push_back(crossing[q]);
    out.cell.push_back(cell);
  };
  if (count == 2) {
    add(0, 1);
  } else if (count == 4) {
    // Corner 0's side holds the centre: the segments cut corners 1 and 3 off; else 0 and 2.
    const bool centreWithCorner0 = ((d[0] + d[1] + d[2] + d[3]) >= 0.0) == (d[0] >= 0.0);
    if (centreWithCorner0) {
      add(0, 1), add(2, 3);
    } else {
      add(1, 2), add(3, 0);
    }
  }
}

}  // namespace

PlaneCut cutByPlane(const StructuredGrid& grid, const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
  const double length = normal.norm();
  if (!std::isfinite(length) || length == 0.0 || !point.allFinite()) {
    throw InvalidInputError("the cut plane needs a finite point and a finite, non-zero normal");
  }
  const Eigen::Vector3d unit = normal / length;
  const std::vector<GridBlock>& blocks = grid.blocks();
  // A plane the grid only touches from its positive side (the symmetry plane of a half model, a
  // box domain's face) is cut from the other side: points on the plane then count as the plane's
  // positive side, every other point as its negative one, and the cells along the plane draw the
  // grid lines lying in it.
  std::vector<Eigen::VectorXd> distances(blocks.size());
  bool anyNegative = false;
  for (size_t b = 0; b < blocks.size(); ++b) {
    distances[b] = (blocks[b].points.rowwise() - point.transpose()) * unit;
    anyNegative = anyNegative || (distances[b].size() > 0 && distances[b].minCoeff() < 0.0);
  }
  if (!anyNegative) {
    for (Eigen::VectorXd& distance : distances) distance = -distance;
  }
  std::vector<Segments> perBlock(blocks.size());
  std::vector<Eigen::Index> cellOffset(blocks.size() + 1, 0);
  for (size_t b = 0; b < blocks.size(); ++b) cellOffset[b + 1] = cellOffset[b] + blocks[b].cellCount();

  parallelChunks(static_cast<std::int64_t>(blocks.size()), 1, [&](std::int64_t first, std::int64_t last) {
    for (std::int64_t b = first; b < last; ++b) {
      const GridBlock& block = blocks[static_cast<size_t>(b)];
      const int ni = block.size[0], nj = block.size[1], nk = block.size[2];
      const Eigen::VectorXd& distance = distances[static_cast<size_t>(b)];
      const auto at = [&](int i, int j, int k) { return Eigen::Vector3d(block.points.row(block.index(i, j, k)).transpose()); };
      const auto sideOf = [&](int i, int j, int k) { return distance(block.index(i, j, k)) >= 0.0; };
      Segments& out = perBlock[static_cast<size_t>(b)];
      // Every face of the block once: the faces normal to direction `axis` at each index along it;
      // the face's cell is the one on its upper side (the lower one at the block's far end).
      for (int axis = 0; axis < 3; ++axis) {
        const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
        const std::array<int, 3> n{ni, nj, nk};
        for (int s = 0; s < n[axis]; ++s) {
          for (int q = 0; q + 1 < n[a2]; ++q) {
            for (int p = 0; p + 1 < n[a1]; ++p) {
              std::array<std::array<int, 3>, 4> ijk;
              const std::array<std::array<int, 2>, 4> offsets{{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
              bool positive = false, negative = false;
              for (int c = 0; c < 4; ++c) {
                ijk[c][axis] = s;
                ijk[c][a1] = p + offsets[c][0];
                ijk[c][a2] = q + offsets[c][1];
                (sideOf(ijk[c][0], ijk[c][1], ijk[c][2]) ? positive : negative) = true;
              }
              if (!positive || !negative) continue;
              std::array<Eigen::Vector3d, 4> corner;
              std::array<double, 4> d;
              for (int c = 0; c < 4; ++c) {
                corner[c] = at(ijk[c][0], ijk[c][1], ijk[c][2]);
                d[c] = distance(block.index(ijk[c][0], ijk[c][1], ijk[c][2]));
              }
              std::array<int, 3> cellIjk;
              cellIjk[axis] = std::min(s, n[axis] - 2);
              cellIjk[a1] = p;
              cellIjk[a2] = q;
              const Eigen::Index cell =
                  cellOffset[static_cast<size_t>(b)] + cellIjk[0] +
                  static_cast<Eigen::Index>(ni - 1) * (cellIjk[1] + static_cast<Eigen::Index>(nj - 1) * cellIjk[2]);
              cutQuad(corner, d, cell, out);
            }
          }
        }
      }
    }
  });

  PlaneCut cut;
  Eigen::Index total = 0;
  for (const Segments& s : perBlock) total += static_cast<Eigen::Index>(s.cell.size());
  cut.start.resize(total, 3);
  cut.end.resize(total, 3);
  cut.cell.reserve(static_cast<size_t>(total));
  Eigen::Index row = 0;
  for (const Segments& s : perBlock) {
    for (size_t k = 0; k < s.cell.size(); ++k, ++row) {
      cut.start.row(row) = s.start[k].transpose();
      cut.end.row(row) = s.end[k].transpose();
      cut.cell.push_back(s.cell[k]);
    }
  }
  return cut;
}

}  // namespace bvmesh::grid

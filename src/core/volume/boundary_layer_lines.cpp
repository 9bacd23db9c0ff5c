#include "core/volume/boundary_layer_lines.h"

#include <Eigen/Geometry>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <queue>
#include <set>

#include "core/common/errors.h"
#include "core/common/math_constants.h"
#include "core/volume/turning.h"

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

// A wall cell turned further than this from a point's normal (or from another cell at the point)
// makes the point sharp.
constexpr double kSharpAngle = kPi / 6.0;

// The wall as the splay bands see it: per point the node standing for it (itself; another point
// where a knife edge's copies are one; -1 for none, a fan's point), the nodes' normals and their
// neighbours.
struct WallView {
  std::vector<int> node;
  RowMatrixX3d normals;
  std::vector<std::vector<int>> neighbours;
};

class SplayBands {
 public:
  SplayBands(const MarchingFront& front, const BoundaryPlanes& planes, double thickness)
      : front_(front),
        planes_(planes),
        thickness_(thickness),
        wallNeighbours_(frontNeighbours(front, true)) {}

  // The wall's cells round each node of `view`: their unit normals and centres (a fan's quads,
  // collapsed onto their edge, are no wall cells).
  struct CellsAround {
    std::vector<std::vector<Vector3d>> normals, centres;
  };
  CellsAround cellsAround(const WallView& view) const {
    const auto n = static_cast<size_t>(front_.points.rows());
    CellsAround cells{std::vector<std::vector<Vector3d>>(n), std::vector<std::vector<Vector3d>>(n)};
    for (const auto& q : front_.quads) {
      const Vector3d a = front_.points.row(q[0]).transpose(), b = front_.points.row(q[1]).transpose();
      const Vector3d c = front_.points.row(q[2]).transpose(), d = front_.points.row(q[3]).transpose();
      const Vector3d area = (c - a).cross(d - b);
      if (area.norm() == 0.0) continue;
      for (int corner : q) {
        const int node = view.node[static_cast<size_t>(corner)];
        if (node < 0) continue;
        cells.normals[static_cast<size_t>(node)].push_back(area.normalized());
        cells.centres[static_cast<size_t>(node)].push_back(0.25 * (a + b + c + d));
      }
    }
    return cells;
  }

  // Points where the wall turns sharply: an adjacent cell's normal more than 30 degrees off the
  // point's (averaged) normal, per node of `view`.
  std::vector<char> sharpEdgePoints(const WallView& view, const CellsAround& cells) const {
    std::vector<char> sharp(cells.normals.size(), 0);
    for (size_t p = 0; p < sharp.size(); ++p) {
      const Vector3d mean = view.normals.row(static_cast<Eigen::Index>(p)).transpose();
      for (const Vector3d& normal : cells.normals[p]) {
        if (normal.dot(mean) < std::cos(kSharpAngle)) sharp[p] = 1;
      }
    }
    return sharp;
  }

  // Per sharp point on a concave crease (a wing-body junction, where a trailing edge ends on the
  // fuselage), the direction that sees its wall cells best: the largest smallest dot product with
  // their normals, found among the directions that one, two or three of the normals fix (the axis
  // of the smallest cone holding them). Zero elsewhere. The band's harmonic interpolation there
  // mixes the fuselage's normal with the trailing edge's cancelling ones and leaves a line nearly in
  // the wing's surface; this one runs along the fuselage, downstream, between both.
  RowMatrixX3d concaveCornerLines(const CellsAround& cells, const std::vector<char>& sharp) const {
    const Eigen::Index n = front_.points.rows();
    RowMatrixX3d lines = RowMatrixX3d::Zero(n, 3);
    for (Eigen::Index p = 0; p < n; ++p) {
      if (sharp[static_cast<size_t>(p)] == 0) continue;
      const auto& around = cells.normals[static_cast<size_t>(p)];
      // Beyond a few cells (a wall point has 4 per patch meeting there) the cubic candidate search
      // would cost more than the marching; such a point keeps the band's line.
      constexpr size_t kMostCells = 16;
      if (onPlane(p) || around.size() > kMostCells ||
          !onConcaveCrease(front_.points.row(p).transpose(), around, cells.centres[static_cast<size_t>(p)])) {
        continue;
      }
      std::vector<Vector3d> candidates(around.begin(), around.end());
      for (size_t i = 0; i < around.size(); ++i) {
        for (size_t j = i + 1; j < around.size(); ++j) {
          candidates.push_back(around[i] + around[j]);
          for (size_t k = j + 1; k < around.size(); ++k) {
            const Vector3d axis = (around[i] - around[j]).cross(around[i] - around[k]);
            candidates.push_back(axis.dot(around[i]) >= 0.0 ? axis : Vector3d(-axis));
          }
        }
      }
      double best = 0.0;  // a point no direction sees all cells from keeps the band's line
      for (const Vector3d& candidate : candidates) {
        if (candidate.norm() < 1e-12) continue;
        const Vector3d d = candidate.normalized();
        double seen = 1.0;
        for (const Vector3d& normal : around) seen = std::min(seen, normal.dot(d));
        if (seen > best) {
          best = seen;
          lines.row(p) = d.transpose();
        }
      }
    }
    return lines;
  }

  // Whether some wall cell at `point` lies in front of another's plane where the two turn by more
  // than the sharp angle: a concave crease. In front by more than a quarter of its distance across
  // the crease between them (a cell long along the crease is only a little in front of the other's
  // plane, by a tenth of its whole distance at least).
  static bool onConcaveCrease(const Vector3d& point, const std::vector<Vector3d>& normals,
                              const std::vector<Vector3d>& centres) {
    for (const Vector3d& normal : normals) {
      for (size_t j = 0; j < normals.size(); ++j) {
        if (normal.dot(normals[j]) >= std::cos(kSharpAngle)) continue;
        const Vector3d toCell = centres[j] - point;
        const Vector3d crease = normal.cross(normals[j]).normalized();
        const Vector3d across = toCell - toCell.dot(crease) * crease;
        const double ahead = normal.dot(toCell);
        if (ahead > 0.25 * across.norm() && ahead > 0.1 * toCell.norm()) return true;
      }
    }
    return false;
  }

  // Points on a crease, per node of `view`: the `sharp` ones, and those two of whose wall cells
  // turn by more than the sharp angle. A crease that turns by less than twice the sharp angle
  // leaves its points' cells within the sharp angle of their mean normal, so that they are not
  // sharp (a flat wing tip meeting its strongly swept nose at 55 degrees).
  std::vector<char> creasePoints(const CellsAround& cells, const std::vector<char>& sharp) const {
    std::vector<char> crease = sharp;
    for (size_t p = 0; p < crease.size(); ++p) {
      const auto& around = cells.normals[p];
      for (size_t i = 0; i < around.size() && crease[p] == 0; ++i) {
        for (size_t j = i + 1; j < around.size(); ++j) {
          if (around[i].dot(around[j]) < std::cos(kSharpAngle)) crease[p] = 1;
        }
      }
    }
    return crease;
  }

  // Per front point the largest distance from the sharp edges of the region it lies in (the points
  // connected without crossing a `separator`); separators get infinity.
  std::vector<double> regionReach(const WallView& view, const std::vector<char>& separator,
                                  const std::vector<double>& distance) const {
    const size_t n = separator.size();
    std::vector<double> result(n, std::numeric_limits<double>::infinity());
    std::vector<char> seen(n, 0);
    std::vector<int> members;
    for (size_t seed = 0; seed < n; ++seed) {
      if (separator[seed] != 0 || seen[seed] != 0) continue;
      members.assign(1, static_cast<int>(seed));
      seen[seed] = 1;
      double reach = 0.0;
      for (size_t next = 0; next < members.size(); ++next) {
        const auto p = static_cast<size_t>(members[next]);
        reach = std::max(reach, distance[p]);
        for (int q : view.neighbours[p]) {
          if (separator[static_cast<size_t>(q)] != 0 || seen[static_cast<size_t>(q)] != 0) continue;
          seen[static_cast<size_t>(q)] = 1;
          members.push_back(q);
        }
      }
      for (int p : members) result[static_cast<size_t>(p)] = reach;
    }
    return result;
  }

  // Per front point the splay band's width: `width`, or half the largest distance from the sharp
  // edges in the point's smooth region where that is less. The regions are parted by the sharp
  // points, and also by the crease points where the face so parted off reaches at least half a
  // boundary layer's thickness from its sharp edges: a flat tip whose rim is sharp but for a few
  // points at its swept nose would otherwise join the wing's surfaces there, and its lines would
  // take theirs, running along the tip (80 degrees off its normal). A narrower tip is left to the
  // band, whose lines fan across it as across a rounded one: parted off, its band (half its
  // reach) would turn its lines through 45 degrees within less than a quarter of the boundary
  // layer's thickness, and the far field folded above it.
  // A region reaching less than kNarrowRegion boundary-layer thicknesses from its sharp edges (a
  // blunt trailing edge's base) is banded to its farthest points: its lines fan from edge to edge
  // as round a rounded edge. Banded over half its reach, its outer halves fanned and its middle
  // went straight, and the blocks' cubic interpolation of that kinked fan crossed the middle, where
  // the base's two halves' blocks meet (a lofted wing's base, 0.05 thicknesses: 632 negative cells).
  // A wing-body's flat tip (0.26) banded whole folded at the first layer.
  static constexpr double kNarrowRegion = 0.1;
  std::vector<double> bandWidths(const WallView& view, const CellsAround& cells,
                                 const std::vector<char>& sharp, const std::vector<double>& distance,
                                 double width) const {
    const std::vector<char> crease = creasePoints(cells, sharp);
    const std::vector<double> bySharp = regionReach(view, sharp, distance);
    const std::vector<double> byCrease = regionReach(view, crease, distance);
    std::vector<double> result(sharp.size(), width);
    for (size_t p = 0; p < sharp.size(); ++p) {
      const double reach = crease[p] == 0 && byCrease[p] >= 0.5 * thickness_ ? byCrease[p] : bySharp[p];
      const double share = reach < kNarrowRegion * thickness_ ? 1.0 : 0.5;
      result[p] = std::min(width, share * reach);
    }
    return result;
  }

  // Boundary-layer grid-line directions: the wall normals, except in a band of geodesic width
  // `width` around sharp convex edges (a tip; a knife edge without a fan), where they are the
  // harmonic interpolation between the normals at the band's rim. A single grid line leaving such
  // an edge along the mean normal would fan the cells next to it over ~90 degrees in one cell,
  // which the blocks' cubic interpolation of the layers turns into folds; the band spreads the fan
  // over several cells and keeps the wall orthogonal everywhere outside it. The band covers at
  // most half of the smooth region it lies in (half its farthest point's distance from the sharp
  // edges): a face narrower than the band, such as a body's flat base inside its rim, would
  // otherwise have no rim of its own in the band, and every line on it would take its
  // neighbours' normals, leaving the first cells flat. On the nodes of `view`; every point gets
  // its node's line (a fan's points none: turnFans sets them).
  BoundaryLayerLines splayedAtSharpEdges(const WallView& view, double width) const {
    const Eigen::Index n = front_.points.rows();
    const CellsAround cells = cellsAround(view);
    const std::vector<char> sharp = sharpEdgePoints(view, cells);
    const std::vector<double> distance = geodesicFrom(view, sharp).distance;
    const std::vector<double> bandWidth = bandWidths(view, cells, sharp, distance, width);
    const RowMatrixX3d cornerLines = concaveCornerLines(cells, sharp);
    auto heldAtCorner = [&](Eigen::Index p) { return cornerLines.row(p).squaredNorm() > 0.0; };
    auto isNode = [&](Eigen::Index p) { return view.node[static_cast<size_t>(p)] == p; };
    auto inBand = [&](Eigen::Index p) {
      return isNode(p) && !heldAtCorner(p) &&
             distance[static_cast<size_t>(p)] < bandWidth[static_cast<size_t>(p)];
    };
    std::vector<Eigen::Triplet<double>> entries;
    for (Eigen::Index p = 0; p < n; ++p) {
      if (!inBand(p)) {
        entries.emplace_back(p, p, 1.0);
        continue;
      }
      const auto& near = view.neighbours[static_cast<size_t>(p)];
      entries.emplace_back(p, p, static_cast<double>(near.size()));
      for (int q : near) entries.emplace_back(p, q, -1.0);
    }
    Eigen::SparseMatrix<double> matrix(n, n);
    matrix.setFromTriplets(entries.begin(), entries.end());
    Eigen::SparseLU<Eigen::SparseMatrix<double>> solver(matrix);
    if (solver.info() != Eigen::Success)
      throw SolverError("the splay at the wall's sharp edges could not be factored");
    Eigen::MatrixXd rim = view.normals;  // column major, as SparseLU solves
    for (Eigen::Index p = 0; p < n; ++p) {
      if (inBand(p) || !isNode(p)) rim.row(p).setZero();
      if (heldAtCorner(p)) rim.row(p) = cornerLines.row(p);
    }
    const RowMatrixX3d solved = Eigen::MatrixXd(solver.solve(rim));
    RowMatrixX3d lines = front_.normals;
    for (Eigen::Index p = 0; p < n; ++p) {
      const int node = view.node[static_cast<size_t>(p)];
      if (node < 0) continue;
      Vector3d d = solved.row(node).transpose();
      d = inPlanes(p, d);
      lines.row(p) = d.normalized().transpose();
    }
    BoundaryLayerLines result{std::move(lines), Eigen::VectorXd::Ones(n)};
    bendTowardsConcaveCreases(view, cells, sharp, cornerLines, result);
    return result;
  }

  // Geodesic distance along the wall's edges (of `view`) from the `source` points, and per point
  // the source it is nearest to (-1 where none is reached).
  struct Geodesic {
    std::vector<double> distance;
    std::vector<int> nearest;
  };
  Geodesic geodesicFrom(const WallView& view, const std::vector<char>& source) const {
    const auto n = source.size();
    Geodesic result{std::vector<double>(n, std::numeric_limits<double>::infinity()), std::vector<int>(n, -1)};
    using Entry = std::pair<double, int>;
    std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
    for (size_t p = 0; p < n; ++p) {
      if (source[p] == 0) continue;
      result.distance[p] = 0.0;
      result.nearest[p] = static_cast<int>(p);
      queue.emplace(0.0, static_cast<int>(p));
    }
    while (!queue.empty()) {
      const auto [d, p] = queue.top();
      queue.pop();
      if (d > result.distance[static_cast<size_t>(p)]) continue;
      for (int q : view.neighbours[static_cast<size_t>(p)]) {
        const double through = d + (front_.points.row(p) - front_.points.row(q)).norm();
        if (through < result.distance[static_cast<size_t>(q)]) {
          result.distance[static_cast<size_t>(q)] = through;
          result.nearest[static_cast<size_t>(q)] = result.nearest[static_cast<size_t>(p)];
          queue.emplace(through, q);
        }
      }
    }
    return result;
  }

  // Next to a concave crease (a wing-body junction) the two faces' normals cross within about the
  // corner's width, so that straight lines along them converge and their cells fold as soon as the
  // boundary layer is thicker than the wall's cells there are wide. Within kConcaveBandWidth
  // boundary-layer thicknesses of the crease the lines turn towards the nearest crease point's
  // best-seeing line, wholly at the crease and not at all at the band's width: lines so blended in
  // a 90 degree corner first cross at about 1.27 times that width, above the boundary layer. The
  // lines of a convex sharp edge next to the crease (a trailing edge ending on the junction) turn
  // too, or they would run into the crease's. Each line in the band is as long as keeps its layers
  // at their distance from the wall cells round its point (1 / its smallest cosine with their
  // normals, at most kLongestLine: the bisector of a 90 degree corner 1.41 times the distance), so
  // that the boundary layer's top is the walls' offset and does not dip into the corner, where the
  // far field would start from a notch; nearer a convex sharp point than the crease that length
  // fades to 1 (its splayed lines lean off its cells' normals by design).
  void bendTowardsConcaveCreases(const WallView& view, const CellsAround& cells,
                                 const std::vector<char>& sharp, const RowMatrixX3d& cornerLines,
                                 BoundaryLayerLines& lines) const {
    constexpr double kConcaveBandWidth = 4.0;
    constexpr double kLongestLine = 2.0;
    const auto n = sharp.size();
    std::vector<char> concave(n, 0), convex(n, 0);
    for (size_t p = 0; p < n; ++p) {
      concave[p] = cornerLines.row(static_cast<Eigen::Index>(p)).squaredNorm() > 0.0 ? 1 : 0;
      convex[p] = sharp[p] != 0 && concave[p] == 0 ? 1 : 0;
    }
    if (std::none_of(concave.begin(), concave.end(), [](char c) { return c != 0; })) return;
    const Geodesic fromConcave = geodesicFrom(view, concave);
    const std::vector<double> fromConvex = geodesicFrom(view, convex).distance;
    const double width = kConcaveBandWidth * thickness_;
    for (Eigen::Index p = 0; p < lines.directions.rows(); ++p) {
      const auto node = view.node[static_cast<size_t>(p)];
      if (node < 0) continue;
      const double d = fromConcave.distance[static_cast<size_t>(node)];
      if (d >= width) continue;
      const double toConvex = fromConvex[static_cast<size_t>(node)];
      const double crease = std::isinf(toConvex) ? 1.0 : toConvex / (d + toConvex);
      Vector3d line = lines.directions.row(p).transpose();
      if (d > 0.0) {
        const Vector3d towards = cornerLines.row(fromConcave.nearest[static_cast<size_t>(node)]).transpose();
        line = inPlanes(p, turnedBetween(line, towards, 1.0 - d / width)).normalized();
        lines.directions.row(p) = line.transpose();
      }
      double nearest = 1.0;
      for (const Vector3d& normal : cells.normals[static_cast<size_t>(node)])
        nearest = std::min(nearest, normal.dot(line));
      lines.lengths[p] = 1.0 + crease * ((nearest > 1.0 / kLongestLine ? 1.0 / nearest : kLongestLine) - 1.0);
    }
  }

  // The wall as the splay bands see it: with every knife edge cut open for its fan (each copy a
  // node of its own with its face's normal, the fans' points none), or (`closed`) with each
  // edge's copies one node again, on their mean normal, as an O-grid's edge.
  WallView wallView(bool closed) const {
    const Eigen::Index n = front_.points.rows();
    WallView view;
    view.node.resize(static_cast<size_t>(n));
    std::iota(view.node.begin(), view.node.end(), 0);
    view.normals = front_.normals;
    for (const FanPoint& fan : front_.fanPoints) view.node[static_cast<size_t>(fan.point)] = -1;
    if (closed) {
      for (const KnifeCopies& copies : front_.knifeCopies) {
        view.node[static_cast<size_t>(copies.second)] = copies.first;
        view.normals.row(copies.first) =
            (front_.normals.row(copies.first) + front_.normals.row(copies.second)).normalized();
        view.normals.row(copies.second) = view.normals.row(copies.first);
      }
    }
    std::vector<std::set<int>> sets(static_cast<size_t>(n));
    for (Eigen::Index p = 0; p < n; ++p) {
      const int node = view.node[static_cast<size_t>(p)];
      if (node < 0) continue;
      for (int q : wallNeighbours_[static_cast<size_t>(p)]) {
        const int other = view.node[static_cast<size_t>(q)];
        if (other >= 0 && other != node) sets[static_cast<size_t>(node)].insert(other);
      }
    }
    view.neighbours.resize(static_cast<size_t>(n));
    for (Eigen::Index p = 0; p < n; ++p)
      view.neighbours[static_cast<size_t>(p)].assign(sets[static_cast<size_t>(p)].begin(),
                                                     sets[static_cast<size_t>(p)].end());
    return view;
  }

  // The boundary layer's grid lines: splayed at sharp edges with the knife edges cut open; where
  // fans close (their edge ending in a sharp corner inside the wall), blended from the O-grid's
  // lines at that corner (the knife edge closed, as if it had no fan) to them in proportion to
  // the distance, over the length on which the fans' arc at the top of the boundary layer (their
  // widest angle times the thickness) equals the distance: straight lines nearer than that would
  // turn the fan's cells at the corner over, were they the fan's own. The fan narrows to nothing
  // at the corner, whose cells are the O-grid's.
  BoundaryLayerLines lines(double width) const {
    BoundaryLayerLines result = splayedAtSharpEdges(wallView(false), width);
    RowMatrixX3d& lines = result.directions;
    if (!front_.fanClosings.empty()) {
      const RowMatrixX3d closed = splayedAtSharpEdges(wallView(true), width).directions;
      for (Eigen::Index p = 0; p < lines.rows(); ++p) {
        double share = 1.0;
        for (const FanClosing& closing : front_.fanClosings) {
          const double length = closing.widestAngle * thickness_;
          share = std::min(share, (front_.points.row(p) - front_.points.row(closing.point)).norm() / length);
        }
        if (share < 1.0)
          lines.row(p) =
              turnedBetween(closed.row(p).transpose(), lines.row(p).transpose(), share).transpose();
      }
    }
    turnFans(front_, planes_, lines);
    return result;
  }

 private:
  bool onPlane(Eigen::Index p) const { return front_.planesAt(p) != 0; }
  // A direction at point p kept in the boundary planes the point lies on.
  Vector3d inPlanes(Eigen::Index p, const Vector3d& d) const { return planes_.along(d, front_.planesAt(p)); }

  const MarchingFront& front_;
  const BoundaryPlanes& planes_;
  double thickness_;
  std::vector<std::vector<int>> wallNeighbours_;  // without the knife edges' fans
};

}  // namespace

BoundaryLayerLines boundaryLayerLines(const MarchingFront& front, const BoundaryPlanes& planes,
                                      double thickness, double width) {
  return SplayBands(front, planes, thickness).lines(width);
}

}  // namespace bvmesh::volume

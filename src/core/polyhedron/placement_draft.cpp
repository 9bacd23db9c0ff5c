#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <type_traits>
#include <utility>

#include "core/common/closest_point.h"
#include "core/common/errors.h"
#include "core/polyhedron/draft_check.h"
#include "core/polyhedron/placement_parts.h"
#include "core/polyhedron/target_analysis.h"

namespace bvmesh::polyhedron::placement_detail {

ControlMesh Draft::build(const Vec& reference) {
  double volume = 0.0;
  for (const std::vector<int>& face : faces) {
    for (size_t c = 1; c + 1 < face.size(); ++c) {
      const Vec a = vertices[static_cast<size_t>(face[0])] - reference;
      const Vec b = vertices[static_cast<size_t>(face[c])] - reference;
      const Vec d = vertices[static_cast<size_t>(face[c + 1])] - reference;
      volume += a.dot(b.cross(d));
    }
  }
  RowMatrixX3d x(static_cast<Eigen::Index>(vertices.size()), 3);
  for (size_t v = 0; v < vertices.size(); ++v)
    x.row(static_cast<Eigen::Index>(v)) = vertices[v].transpose();
  std::vector<int> sizes, indices;
  for (std::vector<int> face : faces) {
    if (volume < 0.0) std::reverse(face.begin(), face.end());
    sizes.push_back(static_cast<int>(face.size()));
    indices.insert(indices.end(), face.begin(), face.end());
  }
  // Creases and corners are sets: generators may mark one twice (curves meeting on a ring).
  std::set<std::pair<int, int>> creased;
  std::vector<std::array<int, 2>> unique;
  for (const std::array<int, 2>& crease : creases)
    if (creased.insert(std::minmax(crease[0], crease[1])).second) unique.push_back(crease);
  RowMatrixX2i pairs(static_cast<Eigen::Index>(unique.size()), 2);
  for (size_t c = 0; c < unique.size(); ++c)
    pairs.row(static_cast<Eigen::Index>(c)) << unique[c][0], unique[c][1];
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  return ControlMesh(x, sizes, indices, pairs, Eigen::VectorXd(), corners);
}

// Outermost intersections of the rays origin + s d (s > 0) with the target; the closest point
// where a ray misses. origins, directions: #P x 3. A hit behind the origin (a line through a
// singular point such as a sphere's pole may report the far side) is cast again slightly tilted.
target::Points outerHits(const target::Target& target, const target::Points& origins,
                         const target::Points& directions) {
  const double reach = 2.0 * target.report().diagonal;
  target::Points unit = directions;
  for (Eigen::Index i = 0; i < unit.rows(); ++i) unit.row(i).normalize();
  target::Points hits(origins.rows(), 3);
  std::vector<Eigen::Index> pending(static_cast<size_t>(origins.rows()));
  for (Eigen::Index i = 0; i < origins.rows(); ++i) pending[static_cast<size_t>(i)] = i;
  for (int attempt = 0; attempt < 4 && !pending.empty(); ++attempt) {
    target::Points far(static_cast<Eigen::Index>(pending.size()), 3), along(far.rows(), 3);
    for (size_t k = 0; k < pending.size(); ++k) {
      Vec d = unit.row(pending[k]).transpose();
      if (attempt > 0) {  // tilt by 0.01 rad per attempt about a different axis across d
        const Vec across = d.unitOrthogonal();
        d = (d + 0.01 * attempt * (Eigen::AngleAxisd(attempt * 2.1, d) * across)).normalized();
      }
      along.row(static_cast<Eigen::Index>(k)) = d.transpose();
      far.row(static_cast<Eigen::Index>(k)) = origins.row(pending[k]) + reach * d.transpose();
    }
    const target::Points feet = target.projectAlong(far, along).points;
    std::vector<Eigen::Index> again;
    for (size_t k = 0; k < pending.size(); ++k) {
      const Eigen::Index i = pending[k];
      hits.row(i) = feet.row(static_cast<Eigen::Index>(k));
      if ((hits.row(i) - origins.row(i)).dot(along.row(static_cast<Eigen::Index>(k))) <= 0.0)
        again.push_back(i);
    }
    pending = std::move(again);
  }
  return hits;
}

void RayBatch::resolve(const target::Target& target, Draft& draft, bool firstHit) const {
  if (vertices.empty()) return;
  target::Points o(static_cast<Eigen::Index>(origins.size()), 3),
      d(static_cast<Eigen::Index>(origins.size()), 3);
  for (size_t i = 0; i < origins.size(); ++i) {
    o.row(static_cast<Eigen::Index>(i)) = origins[i].transpose();
    d.row(static_cast<Eigen::Index>(i)) = directions[i].transpose();
  }
  target::Points hits = outerHits(target, o, d);
  if (firstHit) {
    const target::ProjectionResult near = target.projectAlong(o, d);
    for (Eigen::Index i = 0; i < o.rows(); ++i) {
      const bool ahead = (near.points.row(i) - o.row(i)).dot(d.row(i)) > 0.0;
      if (near.status[static_cast<size_t>(i)] != target::ProjectionStatus::Fallback &&
          near.status[static_cast<size_t>(i)] != target::ProjectionStatus::Failed && ahead)
        hits.row(i) = near.points.row(i);
    }
  }
  for (size_t i = 0; i < vertices.size(); ++i)
    draft.vertices[static_cast<size_t>(vertices[i])] = hits.row(static_cast<Eigen::Index>(i)).transpose();
}

Lattice latticeSurface(const std::array<int, 3>& n, const std::array<bool, 6>& sides) {
  Lattice lattice;
  lattice.n = n;
  std::map<std::array<int, 3>, int> ids;
  const auto id = [&](const std::array<int, 3>& c) {
    const auto [it, inserted] = ids.emplace(c, static_cast<int>(lattice.coords.size()));
    if (inserted) lattice.coords.push_back(c);
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis) {
    const int b = (axis + 1) % 3;
    const int c = (axis + 2) % 3;
    for (int sign = 0; sign < 2; ++sign) {
      if (!sides[static_cast<size_t>(2 * axis + sign)]) continue;
      for (int i = 0; i < n[static_cast<size_t>(b)]; ++i) {
        for (int j = 0; j < n[static_cast<size_t>(c)]; ++j) {
          std::vector<int> quad;
          for (const auto& [di, dj] : {std::pair{0, 0}, std::pair{1, 0}, std::pair{1, 1}, std::pair{0, 1}}) {
            std::array<int, 3> p{};
            p[static_cast<size_t>(axis)] = sign ? n[static_cast<size_t>(axis)] : 0;
            p[static_cast<size_t>(b)] = i + di;
            p[static_cast<size_t>(c)] = j + dj;
            quad.push_back(id(p));
          }
          if (!sign) std::reverse(quad.begin(), quad.end());
          lattice.faces.push_back(quad);
        }
      }
    }
  }
  return lattice;
}

// Lattice edges as vertex pairs (each once).
std::vector<std::array<int, 2>> latticeEdges(const Lattice& lattice) {
  std::vector<std::array<int, 2>> edges;
  for (const std::vector<int>& face : lattice.faces) {
    for (size_t k = 0; k < face.size(); ++k) {
      const int a = face[k];
      const int b = face[(k + 1) % face.size()];
      edges.push_back({std::min(a, b), std::max(a, b)});
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}


// Points where a polyline (#K x 3; closed: the last point joins the first) crosses a plane.
std::vector<Vec> planeCrossings(const target::Points& line, bool closed, const Vec& point,
                                const Vec& normal) {
  std::vector<Vec> crossings;
  const Eigen::Index count = line.rows();
  for (Eigen::Index k = 0; k + (closed ? 0 : 1) < count; ++k) {
    const Vec a = line.row(k).transpose();
    const Vec b = line.row((k + 1) % count).transpose();
    const double da = (a - point).dot(normal);
    const double db = (b - point).dot(normal);
    if ((da <= 0.0) != (db <= 0.0)) crossings.push_back(a + da / (da - db) * (b - a));
  }
  return crossings;
}

}  // namespace bvmesh::polyhedron::placement_detail

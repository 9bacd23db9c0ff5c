#include "core/polyhedron/placement.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <type_traits>

#include "core/common/closest_point.h"
#include "core/common/errors.h"
#include "core/polyhedron/draft_check.h"
#include "core/polyhedron/target_analysis.h"

namespace bvmesh::polyhedron {
namespace {

constexpr double kPi = 3.14159265358979323846;

using Vec = Eigen::Vector3d;

// A polyhedron under construction.
struct Draft {
  std::vector<Vec> vertices;
  std::vector<std::vector<int>> faces;
  std::vector<std::array<int, 2>> creases;
  std::vector<int> corners;

  int add(const Vec& p) {
    vertices.push_back(p);
    return static_cast<int>(vertices.size()) - 1;
  }

  // Orients the faces so that they enclose positive volume measured from `reference` (any point
  // for a closed polyhedron, a point on the symmetry plane of a half model), then validates.
  ControlMesh build(const Vec& reference) {
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
    RowMatrixX2i pairs(static_cast<Eigen::Index>(creases.size()), 2);
    for (size_t c = 0; c < creases.size(); ++c)
      pairs.row(static_cast<Eigen::Index>(c)) << creases[c][0], creases[c][1];
    std::sort(corners.begin(), corners.end());
    corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
    return ControlMesh(x, sizes, indices, pairs, Eigen::VectorXd(), corners);
  }
};

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

// Collects rays and resolves them in one batch.
struct RayBatch {
  std::vector<int> vertices;
  std::vector<Vec> origins, directions;
  void add(int vertex, const Vec& origin, const Vec& direction) {
    vertices.push_back(vertex);
    origins.push_back(origin);
    directions.push_back(direction);
  }
  // firstHit: the nearest intersection ahead of each origin (origins inside the body); rays
  // without one, and all rays otherwise, take the outermost intersection.
  void resolve(const target::Target& target, Draft& draft, bool firstHit = false) const {
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
};

// The surface of the lattice box [0,n0] x [0,n1] x [0,n2], only the given sides
// (x-, x+, y-, y+, z-, z+), as quads; vertices carry their lattice coordinates.
struct Lattice {
  std::array<int, 3> n{};
  std::vector<std::array<int, 3>> coords;
  std::vector<std::vector<int>> faces;
};

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

Vec frameMid(const PrincipalFrame& f) { return f.centre + f.axes * (0.5 * (f.low + f.high)); }

// ---- box and sphere -------------------------------------------------------------------------

Draft buildBox(const TemplateValues& values, const target::Target& target) {
  const PrincipalFrame frame = principalFrame(target);
  const std::array<int, 3> n{values.integer("segments_1"), values.integer("segments_2"),
                             values.integer("segments_3")};
  const Lattice lattice = latticeSurface(n, {true, true, true, true, true, true});
  Draft draft;
  const auto extreme = [&](const std::array<int, 3>& c, int axis) {
    return c[static_cast<size_t>(axis)] == 0 || c[static_cast<size_t>(axis)] == n[static_cast<size_t>(axis)];
  };
  for (const std::array<int, 3>& c : lattice.coords) {
    Vec local;
    for (int a = 0; a < 3; ++a) {
      const double t = static_cast<double>(c[static_cast<size_t>(a)]) / n[static_cast<size_t>(a)];
      local[a] = frame.low[a] + t * (frame.high[a] - frame.low[a]);
    }
    draft.add(frame.centre + frame.axes * local);
    if (extreme(c, 0) && extreme(c, 1) && extreme(c, 2))
      draft.corners.push_back(static_cast<int>(draft.vertices.size()) - 1);
  }
  draft.faces = lattice.faces;
  for (const auto& [a, b] : latticeEdges(lattice)) {
    const std::array<int, 3>& ca = lattice.coords[static_cast<size_t>(a)];
    const std::array<int, 3>& cb = lattice.coords[static_cast<size_t>(b)];
    int extremes = 0;
    for (int axis = 0; axis < 3; ++axis) {
      if (ca[static_cast<size_t>(axis)] == cb[static_cast<size_t>(axis)] && extreme(ca, axis)) ++extremes;
    }
    if (extremes == 2) draft.creases.push_back({a, b});
  }
  return draft;
}

Draft buildSphere(const TemplateValues& values, const target::Target& target) {
  const PrincipalFrame frame = principalFrame(target);
  const int n = values.integer("segments");
  const Lattice lattice = latticeSurface({n, n, n}, {true, true, true, true, true, true});
  const Vec mid = frameMid(frame);
  const Vec half = 0.5 * (frame.high - frame.low);
  Draft draft;
  draft.faces = lattice.faces;
  RayBatch rays;
  for (const std::array<int, 3>& c : lattice.coords) {
    Vec q;  // equiangular cube-to-sphere map: even spacing on the sphere
    for (int a = 0; a < 3; ++a) q[a] = std::tan(0.25 * kPi * (2.0 * c[static_cast<size_t>(a)] / n - 1.0));
    const Vec onEllipsoid = mid + frame.axes * q.normalized().cwiseProduct(half);
    rays.add(draft.add(onEllipsoid), mid, onEllipsoid - mid);
  }
  rays.resolve(target, draft);
  return draft;
}

// ---- bodies of revolution -------------------------------------------------------------------

// Whether a free-boundary curve (other than one lying in the symmetry plane) lies across the axis
// at `end` (its axial coordinate from `origin`), within `reach`: that end of the body is open.
bool boundaryNear(const target::Target& target, const std::vector<FeatureCurve>& curves,
                  const std::optional<fit::SymmetryPlane>& plane, const Vec& origin, const Vec& axis,
                  double end, double reach) {
  for (const FeatureCurve& curve : curves) {
    if (curve.kind != FeatureCurveKind::Boundary) continue;
    const target::Points points = curvePolyline(target, curve);
    bool inPlane = plane.has_value();
    bool atEnd = points.rows() > 0;
    for (Eigen::Index k = 0; k < points.rows(); ++k) {
      const Vec p = points.row(k).transpose();
      if (plane && std::abs((p - plane->point).dot(plane->normal.normalized())) > reach) inPlane = false;
      if (std::abs((p - origin).dot(axis) - end) > reach) atEnd = false;
    }
    if (atEnd && !inPlane) return true;
  }
  return false;
}

Vec sectionCentre(const PlaneSection& section, const Vec& fallback) {
  if (section.empty()) return fallback;
  Vec sum = Vec::Zero();
  double weight = 0.0;
  const target::Points& p = section.points();
  for (Eigen::Index k = 0; k + 1 < p.rows(); k += 2) {
    const double w = (p.row(k + 1) - p.row(k)).norm();
    sum += w * 0.5 * (p.row(k) + p.row(k + 1)).transpose();
    weight += w;
  }
  return weight > 0.0 ? Vec(sum / weight) : fallback;
}

// A body of revolution's axis frame: stations run along e1 from `lo` to `hi` (coordinates from
// `origin`); a half body lies on the e2 side of the symmetry plane through `origin`.
struct BodyAxis {
  bool half = false;
  Vec origin = Vec::Zero();
  Vec e1 = Vec::UnitX(), e2 = Vec::UnitY(), e3 = Vec::UnitZ();
  double lo = 0.0, hi = 0.0;
  double radius = 0.0;              // largest distance of the body from the axis
  std::array<std::string, 2> ends;  // nose (at lo) and tail (at hi): round, flat or open
};

int quarterSegments(const TemplateValues& values) {
  const int circumferential = values.integer("circumferential");
  if (circumferential % 4 != 0) {
    throw InvalidInputError("template parameter 'circumferential' must be a multiple of 4, got " +
                            std::to_string(circumferential));
  }
  return circumferential / 4;
}

// Resolves `auto` nose and tail choices from the target's free boundary and records them.
void resolveEnds(const TemplateValues& values, const target::Target& target,
                 const std::vector<FeatureCurve>& curves, const std::optional<fit::SymmetryPlane>& plane,
                 BodyAxis& body, std::map<std::string, std::string>& used) {
  body.ends = {values.choice("nose"), values.choice("tail")};
  for (int side = 0; side < 2; ++side) {
    std::string& end = body.ends[static_cast<size_t>(side)];
    if (end == "auto") {
      end = boundaryNear(target, curves, plane, body.origin, body.e1, side ? body.hi : body.lo,
                         0.01 * (body.hi - body.lo))
                ? "open"
                : "round";
    }
  }
  used["nose"] = body.ends[0];
  used["tail"] = body.ends[1];
}

// Axial coordinates of the end rims: a round end's dome takes `cap` of the length.
std::array<double, 2> bodyRims(const BodyAxis& body) {
  const double length = body.hi - body.lo;
  const double cap = std::min(body.radius, 0.25 * length);
  const double inset = 1e-4 * length;
  return {body.ends[0] == "round" ? body.lo + cap : body.lo + inset,
          body.ends[1] == "round" ? body.hi - cap : body.hi - inset};
}

// The body grid: the lattice [0, #stations - 1] x [0, ny] x [0, n] (a half body without its
// j = 0 side, open ends without their end sides) with rings at the station centres (#stations,
// on the axis in order from nose rim to tail rim), each ring vertex cast radially onto the target,
// the end caps cast from their rim centres (domes) or along the axis (flat). Draft vertex v is
// lattice vertex v. `firstHit`: cast to the nearest surface from the centre (a body with other
// parts around it, such as a wing); otherwise to the outermost surface.
Draft buildBodyGrid(const target::Target& target, const BodyAxis& body, int n,
                    const std::vector<Vec>& centres, bool firstHit, Lattice& lattice) {
  const bool half = body.half;
  const int axial = static_cast<int>(centres.size()) - 1;
  const int ny = half ? std::max(1, (n + 1) / 2) : n;
  const double cap = std::min(body.radius, 0.25 * (body.hi - body.lo));
  lattice = latticeSurface({axial, ny, n},
                           {body.ends[0] != "open", body.ends[1] != "open", !half, true, true, true});
  Draft draft;
  draft.faces = lattice.faces;
  RayBatch rays;
  std::vector<int> flatRim;
  for (const std::array<int, 3>& c : lattice.coords) {
    const auto [i, j, k] = c;
    const double s = half ? static_cast<double>(j) / ny : 2.0 * j / ny - 1.0;
    const double t = 2.0 * k / n - 1.0;
    const double a = s * std::sqrt(1.0 - 0.5 * t * t);  // square to disc (elliptical grid map)
    const double b = t * std::sqrt(1.0 - 0.5 * s * s);
    const bool ring = (!half && j == 0) || j == ny || k == 0 || k == n;
    const Vec radial = a * body.e2 + b * body.e3;
    const Vec& centre = centres[static_cast<size_t>(i)];
    const int v = draft.add(centre + body.radius * radial);
    // Rays in the symmetry plane would graze the target's boundary there: cast them from just
    // inside the body; the improvement snaps the vertices back onto the plane.
    const Vec lift = half && j == 0 ? Vec(1e-3 * body.radius * body.e2) : Vec::Zero();
    if (ring) {
      rays.add(v, centre + lift, radial);
      if ((i == 0 && body.ends[0] == "flat") || (i == axial && body.ends[1] == "flat")) flatRim.push_back(v);
      // Half models: where the symmetry boundary meets an open or flat end.
      if (half && j == 0 && (k == 0 || k == n) &&
          ((i == 0 && body.ends[0] != "round") || (i == axial && body.ends[1] != "round"))) {
        draft.corners.push_back(v);
      }
      continue;
    }
    const double outward = i == 0 ? -1.0 : 1.0;
    const std::string& end = body.ends[i == 0 ? 0 : 1];
    if (end == "round") {
      const double rho = std::min(1.0, std::sqrt(a * a + b * b));
      const Vec dome = body.radius * radial + outward * cap * std::sqrt(1.0 - rho * rho) * body.e1;
      rays.add(v, centre + lift, dome);
    } else {
      rays.add(v, centre + body.radius * radial + lift, outward * body.e1);
    }
  }
  rays.resolve(target, draft, firstHit);
  for (const auto& [a, b] : latticeEdges(lattice)) {
    const bool aRim = std::find(flatRim.begin(), flatRim.end(), a) != flatRim.end();
    const bool bRim = std::find(flatRim.begin(), flatRim.end(), b) != flatRim.end();
    const auto& ca = lattice.coords[static_cast<size_t>(a)];
    const auto& cb = lattice.coords[static_cast<size_t>(b)];
    if (aRim && bRim && ca[0] == cb[0]) draft.creases.push_back({a, b});
  }
  return draft;
}

Draft buildRevolution(const TemplateValues& values, const target::Target& target,
                      const std::vector<FeatureCurve>& curves, std::optional<fit::SymmetryPlane>& plane,
                      std::map<std::string, std::string>& used) {
  const PrincipalFrame frame = principalFrame(target);
  const int axial = values.integer("axial");
  const int n = quarterSegments(values);
  const std::string& halfChoice = values.choice("half");
  const std::optional<fit::SymmetryPlane> detected = detectSymmetryPlane(target, curves);
  if (halfChoice == "yes" && !detected) {
    throw InvalidInputError(
        "a half body needs a symmetry plane: the target has no free boundary curve lying in a plane "
        "with the whole target on one side");
  }
  BodyAxis body;
  body.half = halfChoice == "yes" || (halfChoice == "auto" && detected);
  used["half"] = body.half ? "yes" : "no";
  body.e1 = frame.axes.col(0);
  body.e2 = frame.axes.col(1);
  body.e3 = frame.axes.col(2);
  body.origin = frame.centre;
  if (body.half) {
    plane.emplace(*detected);  // a half body has a detected plane (checked above)
    body.e2 = plane->normal.normalized();
    body.e1 = (body.e1 - body.e1.dot(body.e2) * body.e2).normalized();
    body.e3 = body.e1.cross(body.e2);
    body.origin = frame.centre - (frame.centre - plane->point).dot(body.e2) * body.e2;
  } else {
    plane.reset();
  }
  const target::Points& nodes = target.meshNodes();
  body.lo = std::numeric_limits<double>::infinity();
  body.hi = -body.lo;
  for (Eigen::Index k = 0; k < nodes.rows(); ++k) {
    const Vec d = nodes.row(k).transpose() - body.origin;
    const double a = d.dot(body.e1);
    body.lo = std::min(body.lo, a);
    body.hi = std::max(body.hi, a);
    body.radius = std::max(body.radius, (d - a * body.e1).norm());
  }
  resolveEnds(values, target, curves, plane, body, used);
  const auto [rimNose, rimTail] = bodyRims(body);
  std::vector<Vec> centres(static_cast<size_t>(axial + 1));
  for (int i = 0; i <= axial; ++i) {
    const double a = rimNose + (rimTail - rimNose) * i / axial;
    const Vec fallback = body.origin + a * body.e1;
    const PlaneSection section(target, fallback, body.e1);
    Vec centre = sectionCentre(section, fallback);
    centre += (a - (centre - body.origin).dot(body.e1)) * body.e1;
    if (body.half) centre -= (centre - plane->point).dot(body.e2) * body.e2;
    centres[static_cast<size_t>(i)] = centre;
  }
  Lattice lattice;
  return buildBodyGrid(target, body, n, centres, false, lattice);
}

// ---- wings ----------------------------------------------------------------------------------

struct WingFrame {
  Vec origin;                                 // a point at span 0
  Vec span;                                   // unit span direction
  double low = 0.0, high = 0.0;               // span range of the stations (trailing-edge ends)
  double extentLow = 0.0, extentHigh = 0.0;   // span range of the whole target
  std::vector<target::Points> trailingEdges;  // polylines of the sharp spanwise curves
  std::vector<int> trailingEdgeCurves;        // their indices in the feature curve list
  std::map<double, target::Points> kinks;     // polylines of the sharp curves across the span, by span
  double extent() const { return extentHigh - extentLow; }
  // How far a placed vertex may lie from a CAD curve's tessellation polyline and still count as on
  // it (covers the polyline's chordal error).
  double nearCurve() const { return 1e-3 * extent(); }
};

// The trailing-edge point at span s: where a trailing-edge polyline crosses the plane.
std::optional<Vec> trailingEdgeAt(const WingFrame& w, double s) {
  for (const target::Points& line : w.trailingEdges) {
    for (Eigen::Index k = 0; k + 1 < line.rows(); ++k) {
      const double a = (line.row(k).transpose() - w.origin).dot(w.span) - s;
      const double b = (line.row(k + 1).transpose() - w.origin).dot(w.span) - s;
      if ((a <= 0.0) != (b <= 0.0)) {
        const double t = a / (a - b);
        return Vec((line.row(k) + t * (line.row(k + 1) - line.row(k))).transpose());
      }
    }
  }
  return std::nullopt;
}

WingFrame wingFrame(const target::Target& target, const std::vector<FeatureCurve>& curves, bool half,
                    std::optional<fit::SymmetryPlane>& plane) {
  WingFrame w;
  if (half) {
    plane = detectSymmetryPlane(target, curves);
    if (!plane) {
      throw InvalidInputError(
          "a half wing needs its root on a symmetry plane: the target has no free boundary curve "
          "lying in a plane with the whole target on one side (leave out the root face)");
    }
    w.origin = plane->point;
    w.span = plane->normal.normalized();
  } else {
    plane.reset();
    const PrincipalFrame frame = principalFrame(target);
    w.origin = frame.centre;
    w.span = frame.axes.col(0);
  }
  const target::Points& nodes = target.meshNodes();
  const Eigen::VectorXd s = (nodes.rowwise() - w.origin.transpose()) * w.span;
  w.extentLow = half ? 0.0 : s.minCoeff();
  w.extentHigh = s.maxCoeff();
  double best = 0.0;
  for (size_t c = 0; c < curves.size(); ++c) {
    if (curves[c].kind != FeatureCurveKind::Sharp || curves[c].closed)
      continue;  // loops: tip rims, junctions
    const target::Points line = curvePolyline(target, curves[c]);
    const Vec chord = (line.row(line.rows() - 1) - line.row(0)).transpose();
    if (std::abs(chord.normalized().dot(w.span)) < 0.5) continue;  // not spanwise
    const double from = (line.row(0).transpose() - w.origin).dot(w.span);
    const double to = (line.row(line.rows() - 1).transpose() - w.origin).dot(w.span);
    w.trailingEdges.push_back(line);
    w.trailingEdgeCurves.push_back(static_cast<int>(c));
    if (w.trailingEdges.size() == 1) {
      w.low = std::min(from, to);
      w.high = std::max(from, to);
    } else {
      w.low = std::min({w.low, from, to});
      w.high = std::max({w.high, from, to});
    }
    best = std::max(best, std::abs(to - from));
  }
  if (w.trailingEdges.empty() || best < 0.25 * (w.extentHigh - w.extentLow)) {
    throw InvalidInputError(
        "the wing templates need a sharp trailing edge: no sharp feature curve runs along the span "
        "for at least a quarter of it (check the sharp angle)");
  }
  if (half) w.low = 0.0;
  return w;
}

// A wing section: the trailing-edge point, the leading edge (the section point farthest from it)
// and the direction from the lower to the upper side.
struct WingSection {
  Vec trailingEdge = Vec::Zero(), leadingEdge = Vec::Zero(), thickness = Vec::Zero();
  Vec chord() const { return trailingEdge - leadingEdge; }
  // Chord fraction of a point: 1 at the trailing edge, 0 at the leading edge.
  double fraction(const Vec& p) const { return (p - leadingEdge).dot(chord()) / chord().squaredNorm(); }
};

// Chord fractions of a ring's upper (or lower) side from the trailing edge towards the leading
// edge, both ends excluded: cosine spacing, dense at both edges.
std::vector<double> cosineFractions(int m) {
  std::vector<double> xi;
  for (int i = 1; i < m; ++i) xi.push_back(0.5 * (1.0 + std::cos(kPi * i / m)));
  return xi;
}

// Ring of section points starting at the trailing edge `te` (index 0): the upper side at the
// chord fractions `upper`, the leading edge (the point of `outline` farthest from the trailing
// edge) at index n = upper.size() + 1, the lower side at the fractions `lower` (same count) back
// towards the trailing edge. `onSide(base, thickness, upperSide)` gives the section's point across
// the chord at `base` on that side (thickness: span x chord, from the lower to the upper side).
template <class OnSide>
std::vector<Vec> sectionRing(const Vec& te, const target::Points& outline, const Vec& span,
                             const std::vector<double>& upper, const std::vector<double>& lower,
                             WingSection& section, OnSide&& onSide) {
  Vec le = te;
  for (Eigen::Index k = 0; k < outline.rows(); ++k) {
    if ((outline.row(k).transpose() - te).norm() > (le - te).norm()) le = outline.row(k).transpose();
  }
  section = WingSection{te, le, span.cross(Vec(te - le)).normalized()};
  const size_t n = upper.size() + 1;
  std::vector<Vec> ring(2 * n);
  ring[0] = te;
  ring[n] = le;
  for (size_t i = 1; i < n; ++i) {
    ring[i] = onSide(Vec(le + upper[i - 1] * section.chord()), section.thickness, true);
    ring[2 * n - i] = onSide(Vec(le + lower[i - 1] * section.chord()), section.thickness, false);
  }
  return ring;
}

// The wing's ring at span s (sectionRing on the plane section of the target).
std::vector<Vec> wingRing(const target::Target& target, const WingFrame& w, double s,
                          const std::vector<double>& upper, const std::vector<double>& lower,
                          WingSection* sectionOut = nullptr) {
  // The section is taken a little inside the tips, and beside a kink section (whose plane holds
  // tessellation edges, which would make the section degenerate).
  const double inset = 1e-4 * (w.extentHigh - w.extentLow);
  const double cut = std::clamp(s, w.low + inset, w.high - inset) + (w.kinks.count(s) ? inset : 0.0);
  const PlaneSection section(target, w.origin + cut * w.span, w.span);
  const std::optional<Vec> te = trailingEdgeAt(w, cut);
  if (section.empty() || !te) {
    throw InvalidInputError("wing placement: no section of the target at span " + std::to_string(cut));
  }
  WingSection wing;
  std::vector<Vec> ring =
      sectionRing(*te, section.points(), w.span, upper, lower, wing,
                  [&](const Vec& base, const Vec& thickness, bool upperSide) {
                    const std::vector<double> hits = section.lineHits(base, thickness);
                    if (hits.empty()) return base;
                    return Vec(base + (upperSide ? hits.back() : hits.front()) * thickness);
                  });
  // Stations at the ends of the span lie on the end itself.
  for (Vec& v : ring) v += (s - (v - w.origin).dot(w.span)) * w.span;
  if (sectionOut) *sectionOut = WingSection{ring[0], ring[upper.size() + 1], wing.thickness};
  return ring;
}

// Short sharp curves that close the trailing-edge wedge at a tip, leaving the trailing edge's tip
// vertex: along the upper and the lower side of the tip section (where the wedge's flat sides meet
// the tip cap) and along the tip's ridge. Each is given by its far CAD vertex; absent when the CAD
// has no such curve (a wedge that simply runs into a rounded cap).
struct TrailingEdgeTip {
  std::optional<Vec> upper, lower, ridge;
};

TrailingEdgeTip trailingEdgeTip(const target::Target& target, const std::vector<FeatureCurve>& curves,
                                const WingFrame& w, const WingSection& tipSection) {
  const double chord = tipSection.chord().norm();
  // The trailing edge's CAD vertex at this tip.
  int corner = -1;
  double nearest = 1e-3 * chord;
  for (int c : w.trailingEdgeCurves) {
    for (int v : {curves[static_cast<size_t>(c)].startVertex, curves[static_cast<size_t>(c)].endVertex}) {
      if (v < 0) continue;
      const double d = (target.vertexPosition(v) - tipSection.trailingEdge).norm();
      if (d <= nearest) {
        nearest = d;
        corner = v;
      }
    }
  }
  TrailingEdgeTip tip;
  if (corner < 0) return tip;
  struct Candidate {
    Vec end;
    double side;  // thickness component of the unit direction from the corner
  };
  std::vector<Candidate> candidates;
  for (size_t c = 0; c < curves.size(); ++c) {
    const FeatureCurve& curve = curves[c];
    if (curve.kind != FeatureCurveKind::Sharp || curve.closed || curve.length > 0.1 * chord) continue;
    if (std::find(w.trailingEdgeCurves.begin(), w.trailingEdgeCurves.end(), static_cast<int>(c)) !=
        w.trailingEdgeCurves.end())
      continue;
    int far = -1;
    if (curve.startVertex == corner) far = curve.endVertex;
    if (curve.endVertex == corner) far = curve.startVertex;
    if (far < 0) continue;
    const Vec end = target.vertexPosition(far);
    const Vec direction = (end - tipSection.trailingEdge).normalized();
    if (direction.dot(-tipSection.chord().normalized()) <= 0.0) continue;  // must run forward
    candidates.push_back({end, direction.dot(tipSection.thickness)});
  }
  double largestSide = 0.0;
  for (const Candidate& c : candidates) largestSide = std::max(largestSide, std::abs(c.side));
  for (const Candidate& c : candidates) {
    if (c.side > 0.5 * largestSide) {
      if (!tip.upper ||
          c.side > (*tip.upper - tipSection.trailingEdge).normalized().dot(tipSection.thickness))
        tip.upper = c.end;
    } else if (c.side < -0.5 * largestSide) {
      if (!tip.lower ||
          c.side < (*tip.lower - tipSection.trailingEdge).normalized().dot(tipSection.thickness))
        tip.lower = c.end;
    } else if (!tip.ridge ||
               (c.end - tipSection.trailingEdge).norm() > (*tip.ridge - tipSection.trailingEdge).norm()) {
      tip.ridge = c.end;
    }
  }
  // The wedge's sides are closed as a pair or not at all.
  if (!tip.upper || !tip.lower) tip.upper = tip.lower = std::nullopt;
  return tip;
}

// Inserts a chord fraction into a descending list, keeping it strictly descending.
void insertFraction(std::vector<double>& fractions, double xi) {
  if (xi <= 0.0 || xi >= 1.0) return;
  const auto at = std::find_if(fractions.begin(), fractions.end(), [&](double f) { return f <= xi; });
  if (at != fractions.end() && std::abs(*at - xi) < 1e-9) return;
  fractions.insert(at, xi);
}

WingPlanform measurePlanform(const WingFrame& w, const WingSection& root, const WingSection& tip) {
  WingPlanform planform;
  planform.spanDirection = w.span;
  planform.rootChord = root.chord().norm();
  planform.tipChord = tip.chord().norm();
  planform.span = (tip.trailingEdge - root.trailingEdge).dot(w.span);
  // Sweep: angle of an edge line from the span direction, towards the root chord.
  const Vec downstream = (root.chord() - root.chord().dot(w.span) * w.span).normalized();
  const auto sweep = [&](const Vec& from, const Vec& to) {
    const Vec d = to - from;
    return std::atan2(d.dot(downstream), d.dot(w.span)) * 180.0 / kPi;
  };
  planform.leadingEdgeSweepDeg = sweep(root.leadingEdge, tip.leadingEdge);
  planform.trailingEdgeSweepDeg = sweep(root.trailingEdge, tip.trailingEdge);
  return planform;
}

// The chord fractions of a wing's rings and its tips' wedge closures.
// A sharp curve other than the trailing edge, at least 5 % of the span long (a tip rim, a kink
// section): its polyline and the span range it covers.
struct SpanCurve {
  target::Points line;
  double low = 0.0, high = 0.0;
};

std::vector<SpanCurve> longSharpCurves(const target::Target& target, const std::vector<FeatureCurve>& curves,
                                       const WingFrame& w) {
  std::vector<SpanCurve> result;
  for (size_t c = 0; c < curves.size(); ++c) {
    if (curves[c].kind != FeatureCurveKind::Sharp || curves[c].length < 0.05 * w.extent()) continue;
    if (std::find(w.trailingEdgeCurves.begin(), w.trailingEdgeCurves.end(), static_cast<int>(c)) !=
        w.trailingEdgeCurves.end())
      continue;
    SpanCurve curve{curvePolyline(target, curves[c])};
    const Eigen::VectorXd s = (curve.line.rowwise() - w.origin.transpose()) * w.span;
    curve.low = s.minCoeff();
    curve.high = s.maxCoeff();
    result.push_back(std::move(curve));
  }
  return result;
}

// Resolves the `tip` choice: `auto` is flat when a sharp curve other than the trailing edge, and
// longer than 5 % of the span, lies within 1 % of the span of the tip's end (a flat tip's rim),
// else rounded. Records the choice.
bool roundedTip(const TemplateValues& values, const target::Target& target, const std::vector<FeatureCurve>& curves,
                const WingFrame& w, double tipSpan, std::map<std::string, std::string>& used) {
  std::string tip = values.choice("tip");
  if (tip == "auto") {
    bool rim = false;
    for (const SpanCurve& curve : longSharpCurves(target, curves, w))
      rim |= std::max(std::abs(curve.low - tipSpan), std::abs(curve.high - tipSpan)) <= 0.01 * w.extent();
    tip = rim ? "flat" : "rounded";
  }
  used["tip"] = tip;
  return tip == "rounded";
}

struct WingLayout {
  std::vector<double> upper, lower;                   // chord fractions of the side vertices
  std::map<int, TrailingEdgeTip> tips;                // by station
  std::map<int, std::array<double, 2>> tipFractions;  // upper and lower closure ends' chord fractions
  int leadingEdge() const { return static_cast<int>(upper.size()) + 1; }  // its ring index
};

// Kink curves (FeatureCurveKind::Kink) lying in the plane across the span at `span` (within 1e-3
// of the span extent, as kink sections do), as polylines.
std::vector<target::Points> kinksInPlane(const target::Target& target, const std::vector<FeatureCurve>& curves,
                                         const WingFrame& w, double span) {
  std::vector<target::Points> lines;
  for (const FeatureCurve& curve : curves) {
    if (curve.kind != FeatureCurveKind::Kink) continue;
    target::Points line = curvePolyline(target, curve);
    const Eigen::VectorXd s = (line.rowwise() - w.origin.transpose()) * w.span;
    if ((s.array() - span).abs().maxCoeff() <= 1e-3 * w.extent()) lines.push_back(std::move(line));
  }
  return lines;
}

// The tips' wedge closures decide the chord fractions of every station: where the wedge's flat
// sides end at a tip, every section gets a vertex at that chord fraction, so that the tip's
// closing creases run from the trailing edge along the ring to that vertex. Likewise where a kink
// in a tip's plane ends (the edge between a wing and the leading-edge patch of its rounded tip,
// where the CAD turns by a few degrees): a ring vertex there gives the tip the CAD's patch layout,
// the cap's leading-edge faces ending where the kinked patch does, and halves the spacing along
// the kink (a tangent-continuous surface rounds a kink over about one face). Kink ends at the
// leading or trailing edge are those ring vertices already; the fractions are dropped when they
// would leave the sides unpaired. `tipSpans`: span of each tip station, by station.
WingLayout wingLayout(const target::Target& target, const std::vector<FeatureCurve>& curves,
                      const WingFrame& w, int m, bool rounded, const std::map<int, double>& tipSpans) {
  WingLayout layout;
  layout.upper = layout.lower = cosineFractions(m);
  std::vector<double> kinkUpper, kinkLower;  // chord fractions of the tips' kink ends
  for (const auto& [j, span] : tipSpans) {
    WingSection section;
    wingRing(target, w, span, layout.upper, layout.lower, &section);
    const TrailingEdgeTip tip = rounded ? trailingEdgeTip(target, curves, w, section) : TrailingEdgeTip{};
    layout.tips[j] = tip;
    if (tip.upper) layout.tipFractions[j] = {section.fraction(*tip.upper), section.fraction(*tip.lower)};
    for (const target::Points& line : kinksInPlane(target, curves, w, span)) {
      for (const Eigen::Index end : {Eigen::Index{0}, line.rows() - 1}) {
        const Vec p = line.row(end).transpose();
        if (std::min((p - section.leadingEdge).norm(), (p - section.trailingEdge).norm()) <= w.nearCurve()) continue;
        ((p - section.leadingEdge).dot(section.thickness) > 0.0 ? kinkUpper : kinkLower)
            .push_back(section.fraction(p));
      }
    }
  }
  if (!layout.tipFractions.empty()) {  // one pair of fractions for all stations: the first tip's
    insertFraction(layout.upper, layout.tipFractions.begin()->second[0]);
    insertFraction(layout.lower, layout.tipFractions.begin()->second[1]);
  }
  if (layout.upper.size() != layout.lower.size()) {  // the two sides must stay paired for the tip caps
    layout.upper = layout.lower = cosineFractions(m);
    layout.tipFractions.clear();
  }
  std::vector<double> upper = layout.upper, lower = layout.lower;
  for (double xi : kinkUpper) insertFraction(upper, xi);
  for (double xi : kinkLower) insertFraction(lower, xi);
  if (upper.size() == lower.size()) {
    layout.upper = std::move(upper);
    layout.lower = std::move(lower);
  }
  return layout;
}

// Quad strips between consecutive wing rings (trailing edge first) and the trailing-edge crease
// along their first vertices.
void addWingStrips(Draft& draft, const std::vector<std::vector<int>>& rings) {
  for (size_t j = 0; j + 1 < rings.size(); ++j) {
    const std::vector<int>& a = rings[j];
    const std::vector<int>& b = rings[j + 1];
    for (size_t k = 0; k < a.size(); ++k) {
      const size_t k1 = (k + 1) % a.size();
      draft.faces.push_back({a[k], a[k1], b[k1], b[k]});
    }
    draft.creases.push_back({a[0], b[0]});
  }
}

// Ring index of the side vertex whose chord fraction is nearest `xi`.
int nearestIndex(const std::vector<double>& fractions, double xi) {
  size_t best = 0;
  for (size_t i = 1; i < fractions.size(); ++i)
    if (std::abs(fractions[i] - xi) < std::abs(fractions[best] - xi)) best = i;
  return static_cast<int>(best) + 1;
}

// Tip cap on the ring of station `station`: a row of vertices along the tip's ridge between upper
// and lower surface, cast along outward x span onto a rounded tip, in the ring's plane with a
// creased rim for a flat one. Ridge vertex i sits across ring vertices i + 1 (upper) and
// 2n - i - 1 (lower); at the trailing edge the cap is two triangles (a quad would fold around the
// thin wedge, with a corner angle of a few degrees), meeting at ridge vertex 0, which is the end
// of the CAD's ridge crease when it has one. outward 1: the far tip, continuing the strips'
// orientation; -1: a full wing's near tip, reversed. The trailing edge becomes a corner.
void addTipCap(Draft& draft, const target::Target& target, const WingFrame& w, const WingLayout& layout,
               int station, const std::vector<int>& ring, double outward, bool rounded) {
  const int n = layout.leadingEdge();
  const int ringSize = 2 * n;
  const auto r = [&](int k) { return ring[static_cast<size_t>((k + ringSize) % ringSize)]; };
  const auto at = [&](int vertex) -> Vec& { return draft.vertices[static_cast<size_t>(vertex)]; };
  static const TrailingEdgeTip kNoClosure;
  const auto found = layout.tips.find(station);
  const TrailingEdgeTip& tip = found == layout.tips.end() ? kNoClosure : found->second;
  const auto fractions = layout.tipFractions.find(station);
  if (fractions != layout.tipFractions.end()) {  // the wedge's closing creases, along the ring
    const int upperEnd = nearestIndex(layout.upper, fractions->second[0]);
    const int lowerEnd = ringSize - nearestIndex(layout.lower, fractions->second[1]);
    at(r(upperEnd)) = *tip.upper;
    at(r(lowerEnd)) = *tip.lower;
    for (int k = 0; k < upperEnd; ++k) draft.creases.push_back({r(k), r(k + 1)});
    for (int k = lowerEnd; k < ringSize; ++k) draft.creases.push_back({r(k), r(k + 1)});
    draft.corners.push_back(r(upperEnd));
    draft.corners.push_back(r(lowerEnd));
  }
  RayBatch rays;
  std::vector<int> c(static_cast<size_t>(n - 1), -1);
  for (int i = 0; i + 1 < n; ++i) {
    const Vec mid = 0.5 * (at(r(i + 1)) + at(r(ringSize - i - 1)));
    c[static_cast<size_t>(i)] = draft.add(mid);
    if (i == 0 && tip.ridge) {
      at(c[0]) = *tip.ridge;
      draft.creases.push_back({r(0), c[0]});
      draft.corners.push_back(c[0]);
    } else if (rounded) {
      rays.add(c[static_cast<size_t>(i)], mid, outward * w.span);
    }
  }
  rays.resolve(target, draft);
  const auto cv = [&](int i) { return c[static_cast<size_t>(i)]; };
  std::vector<std::vector<int>> faces;
  faces.push_back({r(0), r(1), cv(0)});
  faces.push_back({r(0), cv(0), r(ringSize - 1)});
  for (int i = 1; i + 1 < n; ++i) {
    faces.push_back({r(i), r(i + 1), cv(i), cv(i - 1)});
    faces.push_back({cv(i - 1), cv(i), r(ringSize - i - 1), r(ringSize - i)});
  }
  faces.push_back({r(n - 1), r(n), r(n + 1), cv(n - 2)});
  for (std::vector<int>& face : faces) {
    if (outward < 0.0) std::reverse(face.begin(), face.end());
    draft.faces.push_back(face);
  }
  if (!rounded) {
    for (int k = 0; k < ringSize; ++k) draft.creases.push_back({r(k), r(k + 1)});
  }
  draft.corners.push_back(ring[0]);
}

// Sharp curves across the wing inside its span: each lies in one plane across the span (within
// 1e-3 of the span extent), away from the tips, and is at least 5 % of the span long, such as the
// leading-edge kink where the two halves of a swept wing meet at the root. By span coordinate.
std::map<double, target::Points> kinkSections(const target::Target& target, const std::vector<FeatureCurve>& curves,
                                              const WingFrame& w) {
  std::map<double, target::Points> kinks;
  for (SpanCurve& curve : longSharpCurves(target, curves, w)) {
    const double mid = 0.5 * (curve.low + curve.high);
    if (curve.high - curve.low <= 1e-3 * w.extent() && std::min(mid - w.low, w.high - mid) >= 0.01 * w.extent())
      kinks[mid] = std::move(curve.line);
  }
  return kinks;
}

// Creases the ring edges that run along a sharp curve (both ends within `tolerance` of its
// polyline, a tessellation polyline: the tolerance covers its chordal error); the ends of each
// creased run are corners.
void creaseAlong(Draft& draft, const std::vector<int>& ring, const target::Points& line, double tolerance) {
  const auto onLine = [&](int vertex) {
    const Vec p = draft.vertices[static_cast<size_t>(vertex)];
    for (Eigen::Index k = 0; k + 1 < line.rows(); ++k) {
      if ((closestPointOnSegment(p, line.row(k).transpose(), line.row(k + 1).transpose()) - p).norm() <= tolerance)
        return true;
    }
    return false;
  };
  const size_t count = ring.size();
  std::vector<bool> on(count);
  for (size_t k = 0; k < count; ++k) on[k] = onLine(ring[k]);
  for (size_t k = 0; k < count; ++k) {
    const size_t next = (k + 1) % count, previous = (k + count - 1) % count;
    if (on[k] && on[next]) draft.creases.push_back({ring[k], ring[next]});
    if (on[k] && on[previous] != on[next]) draft.corners.push_back(ring[k]);  // a run's end
  }
}

// A station next to each tip whose wedge is closed by corners, as far from the tip as the cap's
// edge at those corners is long (about 0.5 mm on the M6). The closure's corners stay put under
// subdivision; with the previous station tens of millimetres away, the first subdivision drags the
// points of the short edges at a corner far behind it, and the limit surface folds there (at every
// level and after fitting). With the corner's quads about as long as wide it does not. Moves the
// tip's layout entries and the kink rings to the new station numbers.
void addWedgeCornerStations(WingLayout& layout, std::vector<double>& spans, std::map<int, target::Points>& kinkRings,
                            int tip) {
  const auto cornerEdge = [&](int station) {
    const auto found = layout.tips.find(station);
    if (found == layout.tips.end() || !found->second.ridge || !found->second.upper || !found->second.lower) return 0.0;
    const TrailingEdgeTip& closure = found->second;
    return std::min((*closure.upper - *closure.ridge).norm(), (*closure.lower - *closure.ridge).norm());
  };
  // Station numbers from `first` on move up by one.
  const auto renumber = [](auto& byStation, int first) {
    std::decay_t<decltype(byStation)> result;
    for (auto& [station, value] : byStation) result.emplace(station >= first ? station + 1 : station, std::move(value));
    byStation = std::move(result);
  };
  const double far = cornerEdge(tip);
  if (far > 0.0 && far < spans[spans.size() - 1] - spans[spans.size() - 2]) {
    spans.insert(spans.end() - 1, spans.back() - far);
    renumber(layout.tips, tip);
    renumber(layout.tipFractions, tip);
  }
  const double near = tip > 0 ? cornerEdge(0) : 0.0;
  if (near > 0.0 && near < spans[1] - spans[0]) {
    spans.insert(spans.begin() + 1, spans.front() + near);
    renumber(layout.tips, 1);
    renumber(layout.tipFractions, 1);
    renumber(kinkRings, 1);
  }
}

Draft buildWing(const TemplateValues& values, const target::Target& target,
                const std::vector<FeatureCurve>& curves, std::optional<fit::SymmetryPlane>& plane,
                std::map<std::string, std::string>& used, std::optional<WingPlanform>& planform) {
  const int m = values.integer("chordwise");
  const int stations = values.integer("spanwise");
  const bool half = values.choice("span") == "half";
  WingFrame w = wingFrame(target, curves, half, plane);
  w.kinks = kinkSections(target, curves, w);
  const bool rounded = roundedTip(values, target, curves, w, w.high, used);
  // Stations dense towards the tips, whose caps and wedge closures are small features, and coarse
  // where a wing's sections change slowly: half-cosine spacing, a half wing's root being no tip.
  std::vector<double> spans;
  for (int j = 0; j <= stations; ++j) {
    const double t = static_cast<double>(j) / stations;
    spans.push_back(w.low + (w.high - w.low) * (half ? std::sin(0.5 * kPi * t) : 0.5 * (1.0 - std::cos(kPi * t))));
  }
  // A kink section takes the place of the nearest inner station, whose ring is creased along it.
  std::map<int, target::Points> kinkRings;
  for (const auto& [span, line] : w.kinks) {
    int nearest = -1;
    for (int j = 1; j < stations; ++j) {
      if (!kinkRings.count(j) && (nearest < 0 || std::abs(spans[static_cast<size_t>(j)] - span) <
                                                    std::abs(spans[static_cast<size_t>(nearest)] - span)))
        nearest = j;
    }
    if (nearest < 0) continue;
    spans[static_cast<size_t>(nearest)] = span;
    kinkRings[nearest] = line;
  }
  const auto spanAt = [&](int j) { return spans[static_cast<size_t>(j)]; };
  std::map<int, double> tipSpans{{stations, spanAt(stations)}};  // the far tip, and a full wing's near one
  if (!half) tipSpans[0] = spanAt(0);
  WingLayout layout = wingLayout(target, curves, w, m, rounded, tipSpans);
  addWedgeCornerStations(layout, spans, kinkRings, stations);
  const int tipStation = static_cast<int>(spans.size()) - 1;

  Draft draft;
  std::vector<std::vector<int>> rings;
  WingSection rootSection, tipSection;
  for (int j = 0; j <= tipStation; ++j) {
    WingSection section;
    std::vector<Vec> ring = wingRing(target, w, spanAt(j), layout.upper, layout.lower, &section);
    if (j == 0) rootSection = section;
    if (j == tipStation) tipSection = section;
    std::vector<int> ids;
    for (const Vec& p : ring) ids.push_back(draft.add(p));
    rings.push_back(ids);
  }
  addWingStrips(draft, rings);
  const double kinkTolerance = w.nearCurve();
  for (const auto& [j, line] : kinkRings) {
    const std::vector<int>& ring = rings[static_cast<size_t>(j)];
    creaseAlong(draft, ring, line, kinkTolerance);
    // Where the trailing edge ends on the kink section (its two halves meet at an angle there),
    // its vertex is a corner.
    bool trailingEdgeEnds = false;
    for (int c : w.trailingEdgeCurves) {
      for (int v : {curves[static_cast<size_t>(c)].startVertex, curves[static_cast<size_t>(c)].endVertex})
        trailingEdgeEnds |= v >= 0 && (target.vertexPosition(v) - draft.vertices[static_cast<size_t>(ring[0])]).norm() <=
                                          kinkTolerance;
    }
    if (trailingEdgeEnds) draft.corners.push_back(ring[0]);
  }
  planform = measurePlanform(w, rootSection, tipSection);
  addTipCap(draft, target, w, layout, tipStation, rings.back(), 1.0, rounded);
  if (half) {
    draft.corners.push_back(rings.front()[0]);
  } else {
    addTipCap(draft, target, w, layout, 0, rings.front(), -1.0, rounded);
  }
  return draft;
}

// ---- wing-fuselage half model -----------------------------------------------------------------

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

// Drops vertices no face uses and renumbers the rest.
void removeUnusedVertices(Draft& draft) {
  std::vector<int> index(draft.vertices.size(), -1);
  for (const std::vector<int>& face : draft.faces) {
    for (int v : face) index[static_cast<size_t>(v)] = 0;
  }
  std::vector<Vec> kept;
  for (size_t v = 0; v < index.size(); ++v) {
    if (index[v] < 0) continue;
    index[v] = static_cast<int>(kept.size());
    kept.push_back(draft.vertices[v]);
  }
  draft.vertices = std::move(kept);
  for (std::vector<int>& face : draft.faces) {
    for (int& v : face) v = index[static_cast<size_t>(v)];
  }
  for (std::array<int, 2>& crease : draft.creases)
    crease = {index[static_cast<size_t>(crease[0])], index[static_cast<size_t>(crease[1])]};
  for (int& corner : draft.corners) corner = index[static_cast<size_t>(corner)];
}

// A half fuselage (the revolution generator's body grid, its axis and stations taken from the
// body's profile in the symmetry plane) with a hole where the wing root meets it, and the half
// wing (the wing generator's stations and tip cap) extruded from the hole's boundary, which lies
// on the wing-body intersection curve and is creased. The hole spans chordwise - 2 axial segments
// (stations at the root ring's chord fractions) and two circumferential segments centred on the
// wing; its ends are the root's leading- and trailing-edge vertices.
Draft buildWingFuselage(const TemplateValues& values, const target::Target& target,
                        const std::vector<FeatureCurve>& curves, std::optional<fit::SymmetryPlane>& plane,
                        std::map<std::string, std::string>& used, std::optional<WingPlanform>& planform) {
  const int axial = values.integer("axial");
  const int n = quarterSegments(values);
  const int m = values.integer("chordwise");
  const int stations = values.integer("spanwise");
  if (n < 2) {
    throw InvalidInputError(
        "template parameter 'circumferential' must be at least 8 for a wing-fuselage model, got " +
        std::to_string(4 * n));
  }
  plane = detectSymmetryPlane(target, curves);
  if (!plane) {
    throw InvalidInputError(
        "a wing-fuselage half model needs a symmetry plane: the target has no free boundary curve lying in a "
        "plane with the whole target on one side (leave out the symmetry-plane face)");
  }
  BodyAxis body;
  body.half = true;
  body.e2 = plane->normal.normalized();
  // The body's profile: the free-boundary curves in the symmetry plane. Its main direction is the
  // axis (the wing would tilt the principal axes of the whole target).
  const double diagonal = target.report().diagonal;
  std::vector<target::Points> profile;
  std::vector<Vec> profilePoints;
  for (const FeatureCurve& curve : curves) {
    if (curve.kind != FeatureCurveKind::Boundary) continue;
    const target::Points line = curvePolyline(target, curve);
    const Eigen::VectorXd offsets = (line.rowwise() - plane->point.transpose()) * body.e2;
    if (line.rows() < 2 || offsets.cwiseAbs().maxCoeff() > 1e-3 * diagonal) continue;
    profile.push_back(line);
    for (Eigen::Index k = 0; k < line.rows(); ++k) profilePoints.push_back(line.row(k).transpose());
  }
  Vec centre = Vec::Zero();
  for (const Vec& p : profilePoints) centre += p / static_cast<double>(profilePoints.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Vec& p : profilePoints) covariance += (p - centre) * (p - centre).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  body.e1 = eigen.eigenvectors().col(2);  // largest eigenvalue last
  body.e1 = (body.e1 - body.e1.dot(body.e2) * body.e2).normalized();
  body.e3 = body.e1.cross(body.e2);
  body.origin = centre - (centre - plane->point).dot(body.e2) * body.e2;
  body.lo = std::numeric_limits<double>::infinity();
  body.hi = -body.lo;
  for (const Vec& p : profilePoints) {
    const double a = (p - body.origin).dot(body.e1);
    body.lo = std::min(body.lo, a);
    body.hi = std::max(body.hi, a);
  }
  resolveEnds(values, target, curves, plane, body, used);
  // Station centres: midway between the profile's extreme crossings (a round body's axis).
  const auto centreAt = [&](double a) {
    const Vec point = body.origin + a * body.e1;
    double low = std::numeric_limits<double>::infinity(), high = -low;
    for (const target::Points& line : profile) {
      for (const Vec& p : planeCrossings(line, false, point, body.e1)) {
        low = std::min(low, (p - point).dot(body.e3));
        high = std::max(high, (p - point).dot(body.e3));
      }
    }
    return low <= high ? Vec(point + 0.5 * (low + high) * body.e3) : point;
  };
  for (const target::Points& line : profile) {
    for (Eigen::Index k = 0; k < line.rows(); ++k) {
      const Vec p = line.row(k).transpose();
      const double a = (p - body.origin).dot(body.e1);
      body.radius = std::max(body.radius, std::abs((p - centreAt(a)).dot(body.e3)));
    }
  }

  // The wing: its trailing edge and, through the trailing edge's inner end, the intersection curve.
  std::optional<fit::SymmetryPlane> wingPlane;
  WingFrame w = wingFrame(target, curves, true, wingPlane);
  // The junction: a closed sharp curve starting at an end vertex of a (spanwise, open) trailing-
  // edge curve, the innermost one if several (a flat tip's rim also starts at the trailing edge).
  const auto spanOf = [&](const Vec& p) { return (p - w.origin).dot(w.span); };
  target::Points junction;
  Vec teRoot = Vec::Zero();
  w.low = std::numeric_limits<double>::infinity();
  for (const FeatureCurve& te : curves) {
    if (te.kind != FeatureCurveKind::Sharp || te.closed) continue;
    for (const FeatureCurve& loop : curves) {
      if (loop.kind != FeatureCurveKind::Sharp || !loop.closed || loop.startVertex < 0 ||
          (loop.startVertex != te.startVertex && loop.startVertex != te.endVertex))
        continue;
      const Vec corner = target.vertexPosition(loop.startVertex);
      const target::Points line = curvePolyline(target, te);
      const Eigen::VectorXd along = (line.rowwise() - w.origin.transpose()) * w.span;
      // Spanwise and reaching outboard from the vertex.
      if (std::abs(along.maxCoeff() - along.minCoeff()) < 0.25 * (w.extentHigh - w.extentLow) ||
          along.maxCoeff() <= spanOf(corner) + 1e-3 * diagonal || spanOf(corner) >= w.low)
        continue;
      w.low = spanOf(corner);
      teRoot = corner;
      junction = curvePolyline(target, loop);
    }
  }
  if (junction.rows() == 0) {
    throw InvalidInputError(
        "wing-fuselage placement: no closed sharp curve (the wing-body intersection) starts where the "
        "trailing edge meets the body: the wing must be fused with the body, the intersection curve sharp");
  }
  const bool rounded = roundedTip(values, target, curves, w, w.high, used);
  const WingLayout layout = wingLayout(target, curves, w, m, rounded, {{stations, w.high}});
  const int lead = layout.leadingEdge();  // ring index of the leading edge (chordwise, or one more
                                          // for a rounded tip's wedge closure)
  const int holeSegments = lead - 2;
  if (lead < 3 || axial < holeSegments + 2) {
    throw InvalidInputError(
        "template parameters: the wing-fuselage model needs chordwise >= 3 and axial >= "
        "chordwise (the wing root takes chordwise - 2 axial segments), got axial " +
        std::to_string(axial) + ", chordwise " + std::to_string(lead));
  }
  WingSection rootSection;
  const std::vector<Vec> root =
      sectionRing(teRoot, junction, w.span, layout.upper, layout.lower, rootSection,
                  [&](const Vec& base, const Vec& thickness, bool upperSide) {
                    // The junction's extreme crossing with the plane across the chord at `base`.
                    Vec best = base;
                    double height = -std::numeric_limits<double>::infinity();
                    for (const Vec& p : planeCrossings(junction, true, base, w.span.cross(thickness))) {
                      const double h = (upperSide ? 1.0 : -1.0) * (p - base).dot(thickness);
                      if (h > height) {
                        height = h;
                        best = p;
                      }
                    }
                    return best;
                  });

  // Stations: the hole's columns at the root ring's chord fractions, the rest spread evenly
  // ahead of and behind the wing.
  const bool trailingAft = (root[0] - root[static_cast<size_t>(lead)]).dot(body.e1) > 0.0;
  const auto axialOf = [&](int r) {  // ring points r and 2 lead - r (r = 1 .. lead - 1)
    return (0.5 * (root[static_cast<size_t>(r)] + root[static_cast<size_t>(2 * lead - r)]) - body.origin)
        .dot(body.e1);
  };
  std::vector<double> columns;  // axial coordinates of the hole's columns, increasing
  for (int r = 1; r < lead; ++r) columns.push_back(axialOf(r));
  if (trailingAft) std::reverse(columns.begin(), columns.end());
  const auto [rimNose, rimTail] = bodyRims(body);
  const double front = columns.front() - rimNose, back = rimTail - columns.back();
  if (!(front > 0.0 && back > 0.0)) {
    throw InvalidInputError("wing-fuselage placement: the wing root reaches beyond the body's " +
                            std::string(front > 0.0 ? "tail" : "nose") + " rim");
  }
  const int free = axial - holeSegments;
  const int i0 = std::clamp(static_cast<int>(std::lround(free * front / (front + back))), 1, free - 1);
  const int i1 = i0 + holeSegments;
  std::vector<Vec> centres;
  for (int i = 0; i <= axial; ++i) {
    double a = 0.0;
    if (i <= i0) {
      a = rimNose + (columns.front() - rimNose) * i / i0;
    } else if (i <= i1) {
      a = columns[static_cast<size_t>(i - i0)];
    } else {
      a = columns.back() + (rimTail - columns.back()) * (i - i1) / (axial - i1);
    }
    centres.push_back(centreAt(a));
  }
  Lattice lattice;
  Draft draft = buildBodyGrid(target, body, n, centres, true, lattice);

  // Side vertices by (station, position q around the half ring from the plane below to the plane above).
  const int ny = std::max(1, (n + 1) / 2);
  const int around = 2 * ny + n;
  std::map<std::pair<int, int>, int> side;
  std::vector<std::pair<int, int>> place(draft.vertices.size(), {-1, -1});
  for (size_t v = 0; v < lattice.coords.size(); ++v) {
    const auto [i, j, k] = lattice.coords[v];
    const int q = k == 0 ? j : j == ny ? ny + k : k == n ? ny + n + (ny - j) : -1;
    if (q < 0) continue;
    side[{i, q}] = static_cast<int>(v);
    place[v] = {i, q};
  }
  const auto at = [&](int i, int q) { return draft.vertices[static_cast<size_t>(side.at({i, q}))]; };
  // The hole's middle row: the ring position nearest the root's centre, two positions from the plane.
  Vec rootCentre = Vec::Zero();
  for (const Vec& p : root) rootCentre += p / static_cast<double>(root.size());
  const int im = (i0 + i1) / 2;
  const Vec toRoot = rootCentre - centres[static_cast<size_t>(im)];
  int qc = 2;
  for (int q = 2; q <= around - 2; ++q) {
    const auto cosine = [&](int r) {
      return (at(im, r) - centres[static_cast<size_t>(im)]).normalized().dot(toRoot.normalized());
    };
    if (cosine(q) > cosine(qc)) qc = q;
  }
  const Vec thickness = w.span.cross(root[0] - root[static_cast<size_t>(lead)]);
  double upwards = 0.0;
  for (int i = i0; i <= i1; ++i) upwards += (at(i, qc + 1) - at(i, qc - 1)).dot(thickness);
  const int upperRow = upwards > 0.0 ? qc + 1 : qc - 1;
  const int lowerRow = 2 * qc - upperRow;
  std::vector<int> junctionRing(static_cast<size_t>(2 * lead));
  const auto column = [&](int r) { return trailingAft ? i1 - (r - 1) : i0 + (r - 1); };
  junctionRing[0] = side.at({trailingAft ? i1 : i0, qc});
  junctionRing[static_cast<size_t>(lead)] = side.at({trailingAft ? i0 : i1, qc});
  for (int r = 1; r < lead; ++r) {
    junctionRing[static_cast<size_t>(r)] = side.at({column(r), upperRow});
    junctionRing[static_cast<size_t>(2 * lead - r)] = side.at({column(r), lowerRow});
  }
  for (size_t r = 0; r < root.size(); ++r) draft.vertices[static_cast<size_t>(junctionRing[r])] = root[r];
  // The hole: the 2 (chordwise - 2) side quads within its columns and rows.
  const auto inHole = [&](int v) {
    const auto [i, q] = place[static_cast<size_t>(v)];
    return i >= i0 && i <= i1 && q >= qc - 1 && q <= qc + 1;
  };
  draft.faces.erase(std::remove_if(draft.faces.begin(), draft.faces.end(),
                                   [&](const std::vector<int>& face) {
                                     return std::all_of(face.begin(), face.end(), inHole);
                                   }),
                    draft.faces.end());

  // The wing from the junction ring to the tip; its first station clear of the body.
  double clear = -std::numeric_limits<double>::infinity();
  for (const Vec& p : root) clear = std::max(clear, (p - w.origin).dot(w.span));
  for (int i = i0; i <= i1; ++i) {
    for (int q = 0; q <= around; ++q) {
      if (std::abs(q - qc) > 1) clear = std::max(clear, (at(i, q) - w.origin).dot(w.span));
    }
  }
  clear += 0.02 * (w.high - w.low);
  const double first = std::max(w.low + (w.high - w.low) / stations, clear);
  std::vector<std::vector<int>> rings{junctionRing};
  WingSection tipSection;
  for (int j = 1; j <= stations; ++j) {
    const double s = j == stations ? w.high : first + (w.high - first) * (j - 1) / (stations - 1);
    const std::vector<Vec> tip = wingRing(target, w, s, layout.upper, layout.lower, &tipSection);
    std::vector<int> ids;
    for (const Vec& p : tip) ids.push_back(draft.add(p));
    rings.push_back(ids);
  }
  Draft wing;
  wing.vertices = draft.vertices;
  addWingStrips(wing, rings);
  addTipCap(wing, target, w, layout, stations, rings.back(), 1.0, rounded);
  // The wing's faces must run against the fuselage's along the junction edges.
  const int a = junctionRing[0], b = junctionRing[1];
  const bool sameWay = std::any_of(draft.faces.begin(), draft.faces.end(), [&](const std::vector<int>& face) {
    for (size_t c = 0; c < face.size(); ++c) {
      if (face[c] == a && face[(c + 1) % face.size()] == b) return true;
    }
    return false;
  });
  for (std::vector<int>& face : wing.faces) {
    if (sameWay) std::reverse(face.begin(), face.end());
    draft.faces.push_back(face);
  }
  draft.vertices = wing.vertices;
  draft.creases.insert(draft.creases.end(), wing.creases.begin(), wing.creases.end());
  draft.corners.insert(draft.corners.end(), wing.corners.begin(), wing.corners.end());
  for (int r = 0; r < 2 * lead; ++r) {
    draft.creases.push_back(
        {junctionRing[static_cast<size_t>(r)], junctionRing[static_cast<size_t>((r + 1) % (2 * lead))]});
  }
  draft.corners.push_back(junctionRing[0]);
  planform = measurePlanform(w, rootSection, tipSection);
  removeUnusedVertices(draft);
  return draft;
}

// ---- nacelle ring ---------------------------------------------------------------------------

// A nacelle lip's trailing edge: the closed sharp curve crossing every meridian half-plane once
// (as a polyline), or empty when the target has none (a rounded lip, a torus).
target::Points lipTrailingEdge(const target::Target& target, const std::vector<FeatureCurve>& curves,
                               const Vec& centre, const Vec& axis, const Vec& u, const Vec& v,
                               int circumferential) {
  for (const FeatureCurve& curve : curves) {
    if (curve.kind != FeatureCurveKind::Sharp || !curve.closed) continue;
    const target::Points line = curvePolyline(target, curve);
    bool aroundAxis = true;
    for (int k = 0; k < circumferential && aroundAxis; ++k) {
      const double phi = 2.0 * kPi * k / circumferential;
      const Vec radial = std::cos(phi) * u + std::sin(phi) * v;
      int crossings = 0;
      for (const Vec& c : planeCrossings(line, true, centre, axis.cross(radial)))
        crossings += (c - centre).dot(radial) > 0.0 ? 1 : 0;
      aroundAxis = crossings == 1;
    }
    if (aroundAxis) return line;
  }
  return target::Points(0, 3);
}

Draft buildNacelle(const TemplateValues& values, const target::Target& target,
                   const std::vector<FeatureCurve>& curves) {
  const PrincipalFrame frame = principalFrame(target);
  const int around = values.integer("section");
  const int circumferential = values.integer("circumferential");
  // The ring's axis: the principal axis whose variance differs most from the other two (a ring
  // has two equal ones).
  int axisIndex = 0;
  double bestGap = -1.0;
  for (int a = 0; a < 3; ++a) {
    const double variance = frame.variances[a];
    const double gap = std::min(std::abs(variance - frame.variances[(a + 1) % 3]),
                                std::abs(variance - frame.variances[(a + 2) % 3]));
    if (gap > bestGap) {
      bestGap = gap;
      axisIndex = a;
    }
  }
  const Vec axis = frame.axes.col(axisIndex);
  const Vec u = frame.axes.col((axisIndex + 1) % 3);
  const Vec v = axis.cross(u);
  const Vec centre = frameMid(frame);
  // A lip with a sharp trailing edge gets airfoil rings like a wing's sections (trailing edge,
  // cosine-spaced chord fractions on both sides), the trailing edge a closed crease loop; a
  // rounded lip gets rings cast from the profile's centre.
  const target::Points trailingEdge = lipTrailingEdge(target, curves, centre, axis, u, v, circumferential);
  const std::vector<double> fractions = cosineFractions(std::max(2, around / 2));
  Draft draft;
  std::vector<std::vector<int>> rings;
  for (int k = 0; k < circumferential; ++k) {
    const double phi = 2.0 * kPi * k / circumferential;
    const Vec radial = std::cos(phi) * u + std::sin(phi) * v;
    const Vec meridianNormal = axis.cross(radial);
    const PlaneSection section(target, centre, meridianNormal);
    // The profile on this side of the axis.
    std::vector<Vec> profile;
    const target::Points& p = section.points();
    for (Eigen::Index r = 0; r < p.rows(); ++r) {
      if ((p.row(r).transpose() - centre).dot(radial) > 0.0) profile.push_back(p.row(r).transpose());
    }
    if (profile.empty())
      throw InvalidInputError(
          "nacelle placement: the target does not surround its axis (no section at angle " +
          std::to_string(phi * 180.0 / kPi) + " deg)");
    // Distances along a line in the meridian plane to the profile on this side of the axis.
    const auto hitsOnThisSide = [&](const Vec& origin, const Vec& direction) {
      std::vector<double> hits;
      for (double hit : section.lineHits(origin, direction))
        if ((origin + hit * direction - centre).dot(radial) > 0.0) hits.push_back(hit);
      return hits;
    };
    std::vector<Vec> positions;
    if (trailingEdge.rows() > 0) {
      Vec te = Vec::Zero();
      for (const Vec& c : planeCrossings(trailingEdge, true, centre, meridianNormal))
        if ((c - centre).dot(radial) > 0.0) te = c;
      target::Points outline(static_cast<Eigen::Index>(profile.size()), 3);
      for (size_t r = 0; r < profile.size(); ++r) outline.row(static_cast<Eigen::Index>(r)) = profile[r].transpose();
      WingSection lip;
      positions = sectionRing(te, outline, meridianNormal, fractions, fractions, lip,
                              [&](const Vec& base, const Vec& thickness, bool upperSide) {
                                const std::vector<double> hits = hitsOnThisSide(base, thickness);
                                if (hits.empty()) return base;
                                const auto [lo, hi] = std::minmax_element(hits.begin(), hits.end());
                                return Vec(base + (upperSide ? *hi : *lo) * thickness);
                              });
    } else {
      Vec profileCentre = Vec::Zero();
      for (const Vec& q : profile) profileCentre += q;
      profileCentre /= static_cast<double>(profile.size());
      for (int i = 0; i < around; ++i) {
        const double theta = 2.0 * kPi * i / around;
        const Vec direction = std::cos(theta) * axis + std::sin(theta) * radial;
        double nearest = 0.0;
        for (double hit : hitsOnThisSide(profileCentre, direction))
          if (hit > 0.0 && (nearest == 0.0 || hit < nearest)) nearest = hit;
        positions.push_back(profileCentre + nearest * direction);
      }
    }
    std::vector<int> ring;
    for (const Vec& position : positions) ring.push_back(draft.add(position));
    rings.push_back(ring);
  }
  for (int k = 0; k < circumferential; ++k) {
    const std::vector<int>& a = rings[static_cast<size_t>(k)];
    const std::vector<int>& b = rings[static_cast<size_t>((k + 1) % circumferential)];
    for (size_t i = 0; i < a.size(); ++i) {
      const size_t i1 = (i + 1) % a.size();
      draft.faces.push_back({a[i], a[i1], b[i1], b[i]});
    }
    if (trailingEdge.rows() > 0) draft.creases.push_back({a[0], b[0]});
  }
  return draft;
}

}  // namespace

PlacedPolyhedron placeTemplate(const PolyhedronTemplate& polyhedronTemplate, const target::Target& target,
                               const PlacementOptions& options) {
  const TemplateValues values(polyhedronTemplate, options.parameters);
  std::map<std::string, std::string> used = values.all();
  const std::vector<FeatureCurve> curves = detectFeatureCurves(target, options.curves);
  std::optional<fit::SymmetryPlane> plane;
  std::optional<WingPlanform> planform;
  const PrincipalFrame frame = principalFrame(target);
  Draft draft;
  switch (polyhedronTemplate.generator) {
    case Generator::Box:
      draft = buildBox(values, target);
      break;
    case Generator::Sphere:
      draft = buildSphere(values, target);
      break;
    case Generator::Revolution:
      draft = buildRevolution(values, target, curves, plane, used);
      break;
    case Generator::Wing:
      draft = buildWing(values, target, curves, plane, used, planform);
      break;
    case Generator::Nacelle:
      draft = buildNacelle(values, target, curves);
      break;
    case Generator::WingFuselage:
      draft = buildWingFuselage(values, target, curves, plane, used, planform);
      break;
  }
  // The signed volume of a closed polyhedron does not depend on the reference point; an open half
  // model is closed by its symmetry plane, so the reference lies in that plane.
  Vec reference = frameMid(frame);
  if (plane)
    reference -= (reference - plane->point).dot(plane->normal.normalized()) * plane->normal.normalized();
  checkPlacedFaces(polyhedronTemplate.name, draft.vertices, draft.faces, target);
  ControlMesh mesh = draft.build(reference);
  FeatureMapping mapping = mapFeatures(mesh, target, curves, options.mapping);
  if (options.improve) {
    ImproveOptions improvement;
    if (options.improvement) {
      improvement = *options.improvement;
    } else {
      if (polyhedronTemplate.relaxationPasses >= 0)
        improvement.relaxationPasses = polyhedronTemplate.relaxationPasses;
      if (polyhedronTemplate.pushOutPasses >= 0) improvement.pushOutPasses = polyhedronTemplate.pushOutPasses;
    }
    improvement.symmetryPlane = plane;
    try {
      improvePolyhedron(mesh, target, mapping.map, improvement);
    } catch (const InvalidInputError& error) {
      // The moved vertices failed the mesh's own check: say so as the template's failure.
      std::string choices;
      for (const auto& [name, value] : used) choices += (choices.empty() ? "" : ", ") + name + "=" + value;
      throw InvalidInputError(placementFailure(polyhedronTemplate.name,
                                               std::string("improving the polyhedron placed with ") + choices +
                                                   " would make it invalid (" + error.what() + ")",
                                               target));
    }
    mapping = mapFeatures(mesh, target, curves, options.mapping);
  }
  return PlacedPolyhedron{
      polyhedronTemplate.name, std::move(mesh), std::move(mapping), curves, plane, used, planform};
}

}  // namespace bvmesh::polyhedron

#include "core/polyhedron/placement.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

#include "core/common/errors.h"
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
  void resolve(const target::Target& target, Draft& draft) const {
    if (vertices.empty()) return;
    target::Points o(static_cast<Eigen::Index>(origins.size()), 3),
        d(static_cast<Eigen::Index>(origins.size()), 3);
    for (size_t i = 0; i < origins.size(); ++i) {
      o.row(static_cast<Eigen::Index>(i)) = origins[i].transpose();
      d.row(static_cast<Eigen::Index>(i)) = directions[i].transpose();
    }
    const target::Points hits = outerHits(target, o, d);
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

Draft buildRevolution(const TemplateValues& values, const target::Target& target,
                      const std::vector<FeatureCurve>& curves, std::optional<fit::SymmetryPlane>& plane,
                      std::map<std::string, std::string>& used) {
  const PrincipalFrame frame = principalFrame(target);
  const int axial = values.integer("axial");
  const int circumferential = values.integer("circumferential");
  if (circumferential % 4 != 0) {
    throw InvalidInputError("template parameter 'circumferential' must be a multiple of 4, got " +
                            std::to_string(circumferential));
  }
  const std::string& halfChoice = values.choice("half");
  const std::optional<fit::SymmetryPlane> detected = detectSymmetryPlane(target, curves);
  if (halfChoice == "yes" && !detected) {
    throw InvalidInputError(
        "a half body needs a symmetry plane: the target has no free boundary curve lying in a plane "
        "with the whole target on one side");
  }
  const bool half = halfChoice == "yes" || (halfChoice == "auto" && detected);
  used["half"] = half ? "yes" : "no";
  Vec e1 = frame.axes.col(0), e2 = frame.axes.col(1), e3 = frame.axes.col(2);
  Vec origin = frame.centre;
  if (half) {
    plane = detected;
    e2 = plane->normal.normalized();
    e1 = (e1 - e1.dot(e2) * e2).normalized();
    e3 = e1.cross(e2);
    origin = frame.centre - (frame.centre - plane->point).dot(e2) * e2;
  } else {
    plane.reset();
  }
  const target::Points& nodes = target.meshNodes();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, radius = 0.0;
  for (Eigen::Index k = 0; k < nodes.rows(); ++k) {
    const Vec d = nodes.row(k).transpose() - origin;
    const double a = d.dot(e1);
    lo = std::min(lo, a);
    hi = std::max(hi, a);
    radius = std::max(radius, (d - a * e1).norm());
  }
  const double length = hi - lo;
  std::array<std::string, 2> ends{values.choice("nose"), values.choice("tail")};
  for (int side = 0; side < 2; ++side) {
    std::string& end = ends[static_cast<size_t>(side)];
    if (end == "auto") {
      end = boundaryNear(target, curves, plane, origin, e1, side ? hi : lo, 0.01 * length) ? "open" : "round";
    }
  }
  used["nose"] = ends[0];
  used["tail"] = ends[1];
  const double cap = std::min(radius, 0.25 * length);
  const double inset = 1e-4 * length;
  const double rimNose = ends[0] == "round" ? lo + cap : lo + inset;
  const double rimTail = ends[1] == "round" ? hi - cap : hi - inset;

  const int n = circumferential / 4;
  const int ny = half ? std::max(1, (n + 1) / 2) : n;
  const std::array<int, 3> sizes{axial, ny, n};
  const Lattice lattice =
      latticeSurface(sizes, {ends[0] != "open", ends[1] != "open", !half, true, true, true});
  std::vector<Vec> centres(static_cast<size_t>(axial + 1));
  for (int i = 0; i <= axial; ++i) {
    const double a = rimNose + (rimTail - rimNose) * i / axial;
    const Vec fallback = origin + a * e1;
    const PlaneSection section(target, fallback, e1);
    Vec centre = sectionCentre(section, fallback);
    centre += (a - (centre - origin).dot(e1)) * e1;
    if (half) centre -= (centre - plane->point).dot(e2) * e2;
    centres[static_cast<size_t>(i)] = centre;
  }
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
    const Vec radial = a * e2 + b * e3;
    const int v = draft.add(centres[static_cast<size_t>(i)] + radius * radial);
    // Rays in the symmetry plane would graze the target's boundary there: cast them from just
    // inside the body; the improvement snaps the vertices back onto the plane.
    const Vec lift = half && j == 0 ? Vec(1e-3 * radius * e2) : Vec::Zero();
    if (ring) {
      rays.add(v, centres[static_cast<size_t>(i)] + lift, radial);
      if ((i == 0 && ends[0] == "flat") || (i == axial && ends[1] == "flat")) flatRim.push_back(v);
      // Half models: where the symmetry boundary meets an open or flat end.
      if (half && j == 0 && (k == 0 || k == n) &&
          ((i == 0 && ends[0] != "round") || (i == axial && ends[1] != "round"))) {
        draft.corners.push_back(v);
      }
      continue;
    }
    const Vec rim = centres[static_cast<size_t>(i)];
    const double outward = i == 0 ? -1.0 : 1.0;
    const std::string& end = ends[i == 0 ? 0 : 1];
    if (end == "round") {
      const double rho = std::min(1.0, std::sqrt(a * a + b * b));
      const Vec dome = radius * radial + outward * cap * std::sqrt(1.0 - rho * rho) * e1;
      rays.add(v, rim + lift, dome);
    } else {
      rays.add(v, rim + radius * radial + lift, outward * e1);
    }
  }
  rays.resolve(target, draft);
  for (const auto& [a, b] : latticeEdges(lattice)) {
    const bool aRim = std::find(flatRim.begin(), flatRim.end(), a) != flatRim.end();
    const bool bRim = std::find(flatRim.begin(), flatRim.end(), b) != flatRim.end();
    const auto& ca = lattice.coords[static_cast<size_t>(a)];
    const auto& cb = lattice.coords[static_cast<size_t>(b)];
    if (aRim && bRim && ca[0] == cb[0]) draft.creases.push_back({a, b});
  }
  return draft;
}

// ---- wings ----------------------------------------------------------------------------------

struct WingFrame {
  Vec origin;                                 // a point at span 0
  Vec span;                                   // unit span direction
  double low = 0.0, high = 0.0;               // span range of the stations (trailing-edge ends)
  double extentLow = 0.0, extentHigh = 0.0;   // span range of the whole target
  std::vector<target::Points> trailingEdges;  // polylines of the sharp spanwise curves
  std::vector<int> trailingEdgeCurves;        // their indices in the feature curve list
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
    if (curves[c].kind != FeatureCurveKind::Sharp) continue;
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

// Ring of section points starting at the trailing edge (index 0): the upper side at the chord
// fractions `upper`, the leading edge at index n = upper.size() + 1, the lower side at the
// fractions `lower` (same count) back towards the trailing edge.
std::vector<Vec> wingRing(const target::Target& target, const WingFrame& w, double s,
                          const std::vector<double>& upper, const std::vector<double>& lower,
                          WingSection* sectionOut = nullptr) {
  const double inset = 1e-4 * (w.extentHigh - w.extentLow);
  const double cut = std::clamp(s, w.low + inset, w.high - inset);
  const PlaneSection section(target, w.origin + cut * w.span, w.span);
  const std::optional<Vec> te = trailingEdgeAt(w, cut);
  if (section.empty() || !te) {
    throw InvalidInputError("wing placement: no section of the target at span " + std::to_string(cut));
  }
  Vec le = *te;
  const target::Points& p = section.points();
  for (Eigen::Index k = 0; k < p.rows(); ++k) {
    if ((p.row(k).transpose() - *te).norm() > (le - *te).norm()) le = p.row(k).transpose();
  }
  const WingSection wing{*te, le, w.span.cross(Vec(*te - le)).normalized()};
  const auto onSide = [&](double xi, bool upperSide) {
    const Vec base = le + xi * wing.chord();
    const std::vector<double> hits = section.lineHits(base, wing.thickness);
    if (hits.empty()) return base;
    return Vec(base + (upperSide ? hits.back() : hits.front()) * wing.thickness);
  };
  const size_t n = upper.size() + 1;
  std::vector<Vec> ring(2 * n);
  ring[0] = *te;
  ring[n] = le;
  for (size_t i = 1; i < n; ++i) {
    ring[i] = onSide(upper[i - 1], true);
    ring[2 * n - i] = onSide(lower[i - 1], false);
  }
  // Stations at the ends of the span lie on the end itself.
  for (Vec& v : ring) v += (s - (v - w.origin).dot(w.span)) * w.span;
  if (sectionOut) *sectionOut = WingSection{ring[0], ring[n], wing.thickness};
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
      if (!tip.upper || c.side > (*tip.upper - tipSection.trailingEdge).normalized().dot(tipSection.thickness))
        tip.upper = c.end;
    } else if (c.side < -0.5 * largestSide) {
      if (!tip.lower || c.side < (*tip.lower - tipSection.trailingEdge).normalized().dot(tipSection.thickness))
        tip.lower = c.end;
    } else if (!tip.ridge || (c.end - tipSection.trailingEdge).norm() > (*tip.ridge - tipSection.trailingEdge).norm()) {
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

Draft buildWing(const TemplateValues& values, const target::Target& target,
                const std::vector<FeatureCurve>& curves, std::optional<fit::SymmetryPlane>& plane,
                std::optional<WingPlanform>& planform) {
  const int m = values.integer("chordwise");
  const int stations = values.integer("spanwise");
  const bool half = values.choice("span") == "half";
  const bool rounded = values.choice("tip") == "rounded";
  const WingFrame w = wingFrame(target, curves, half, plane);
  // Stations dense towards the tips, whose caps and wedge closures are small features, and coarse
  // where a wing's sections change slowly: half-cosine spacing, a half wing's root being no tip.
  const auto spanAt = [&](int j) {
    const double t = static_cast<double>(j) / stations;
    const double f = half ? std::sin(0.5 * kPi * t) : 0.5 * (1.0 - std::cos(kPi * t));
    return w.low + (w.high - w.low) * f;
  };

  // The tips' wedge closures decide the chord fractions of every station: where the wedge's flat
  // sides end at a tip, every section gets a vertex at that chord fraction, so that the tip's
  // closing creases run from the trailing edge along the ring to that vertex.
  std::vector<double> upper = cosineFractions(m), lower = cosineFractions(m);
  std::map<int, TrailingEdgeTip> tips;  // by station: the far tip, and the near one of full wings
  std::map<int, std::array<double, 2>> tipFractions;  // upper and lower closure ends' chord fractions
  for (int j : half ? std::vector<int>{stations} : std::vector<int>{0, stations}) {
    WingSection section;
    wingRing(target, w, spanAt(j), upper, lower, &section);
    const TrailingEdgeTip tip = rounded ? trailingEdgeTip(target, curves, w, section) : TrailingEdgeTip{};
    tips[j] = tip;
    if (tip.upper) tipFractions[j] = {section.fraction(*tip.upper), section.fraction(*tip.lower)};
  }
  if (!tipFractions.empty()) {  // one pair of fractions for all stations: the first tip's
    insertFraction(upper, tipFractions.begin()->second[0]);
    insertFraction(lower, tipFractions.begin()->second[1]);
  }
  if (upper.size() != lower.size()) {  // the two sides must stay paired for the tip caps
    upper = lower = cosineFractions(m);
    tipFractions.clear();
  }
  const int n = static_cast<int>(upper.size()) + 1;  // ring index of the leading edge
  const int ringSize = 2 * n;
  // Ring index of the side vertex whose chord fraction is nearest `xi`.
  const auto nearestIndex = [](const std::vector<double>& fractions, double xi) {
    size_t best = 0;
    for (size_t i = 1; i < fractions.size(); ++i)
      if (std::abs(fractions[i] - xi) < std::abs(fractions[best] - xi)) best = i;
    return static_cast<int>(best) + 1;
  };

  Draft draft;
  std::vector<std::vector<int>> rings;
  WingSection rootSection, tipSection;
  for (int j = 0; j <= stations; ++j) {
    WingSection section;
    std::vector<Vec> ring = wingRing(target, w, spanAt(j), upper, lower, &section);
    if (j == 0) rootSection = section;
    if (j == stations) tipSection = section;
    std::vector<int> ids;
    for (const Vec& p : ring) ids.push_back(draft.add(p));
    rings.push_back(ids);
  }
  for (int j = 0; j < stations; ++j) {
    for (int k = 0; k < ringSize; ++k) {
      const int k1 = (k + 1) % ringSize;
      draft.faces.push_back({rings[static_cast<size_t>(j)][static_cast<size_t>(k)],
                             rings[static_cast<size_t>(j)][static_cast<size_t>(k1)],
                             rings[static_cast<size_t>(j + 1)][static_cast<size_t>(k1)],
                             rings[static_cast<size_t>(j + 1)][static_cast<size_t>(k)]});
    }
    draft.creases.push_back({rings[static_cast<size_t>(j)][0], rings[static_cast<size_t>(j + 1)][0]});
  }
  // Tip caps: a row of vertices along the tip's ridge between upper and lower surface. Ridge vertex
  // i sits across ring vertices i + 1 (upper) and 2n - i - 1 (lower); at the trailing edge the cap
  // is two triangles (a quad would fold around the thin wedge, with a corner angle of a few
  // degrees), meeting at ridge vertex 0, which is the end of the CAD's ridge crease when it has one.
  const auto cap = [&](int station, double outward) {
    const std::vector<int>& ring = rings[static_cast<size_t>(station)];
    const auto r = [&](int k) { return ring[static_cast<size_t>((k + ringSize) % ringSize)]; };
    const auto at = [&](int vertex) -> Vec& { return draft.vertices[static_cast<size_t>(vertex)]; };
    const TrailingEdgeTip& tip = tips[station];
    if (tipFractions.count(station)) {  // the wedge's closing creases, along the ring
      const int upperEnd = nearestIndex(upper, tipFractions[station][0]);
      const int lowerEnd = ringSize - nearestIndex(lower, tipFractions[station][1]);
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
    // The far tip continues the strips' orientation; the near one (full wings) is reversed.
    for (std::vector<int>& face : faces) {
      if (outward < 0.0) std::reverse(face.begin(), face.end());
      draft.faces.push_back(face);
    }
    if (!rounded) {
      for (int k = 0; k < ringSize; ++k) draft.creases.push_back({r(k), r(k + 1)});
    }
    draft.corners.push_back(ring[0]);
  };
  planform = measurePlanform(w, rootSection, tipSection);
  cap(stations, 1.0);
  if (half) {
    draft.corners.push_back(rings.front()[0]);
  } else {
    cap(0, -1.0);
  }
  return draft;
}

// ---- nacelle ring ---------------------------------------------------------------------------

Draft buildNacelle(const TemplateValues& values, const target::Target& target) {
  const PrincipalFrame frame = principalFrame(target);
  const int around = values.integer("section");
  const int circumferential = values.integer("circumferential");
  // The ring's axis: the principal axis whose variance differs most from the other two (a ring
  // has two equal ones).
  int axisIndex = 0;
  double bestGap = -1.0;
  for (int a = 0; a < 3; ++a) {
    const double v = frame.variances[a];
    const double gap =
        std::min(std::abs(v - frame.variances[(a + 1) % 3]), std::abs(v - frame.variances[(a + 2) % 3]));
    if (gap > bestGap) {
      bestGap = gap;
      axisIndex = a;
    }
  }
  const Vec axis = frame.axes.col(axisIndex);
  const Vec u = frame.axes.col((axisIndex + 1) % 3);
  const Vec v = axis.cross(u);
  const Vec centre = frameMid(frame);
  Draft draft;
  std::vector<std::vector<int>> rings;
  for (int k = 0; k < circumferential; ++k) {
    const double phi = 2.0 * kPi * k / circumferential;
    const Vec radial = std::cos(phi) * u + std::sin(phi) * v;
    const PlaneSection section(target, centre, axis.cross(radial));
    // The profile on this side of the axis: its centre, then rays in the meridian plane.
    Vec sum = Vec::Zero();
    int count = 0;
    const target::Points& p = section.points();
    for (Eigen::Index r = 0; r < p.rows(); ++r) {
      if ((p.row(r).transpose() - centre).dot(radial) > 0.0) {
        sum += p.row(r).transpose();
        ++count;
      }
    }
    if (count == 0)
      throw InvalidInputError(
          "nacelle placement: the target does not surround its axis (no section at angle " +
          std::to_string(phi * 180.0 / kPi) + " deg)");
    const Vec profileCentre = sum / count;
    std::vector<int> ring;
    for (int i = 0; i < around; ++i) {
      const double theta = 2.0 * kPi * i / around;
      const Vec direction = std::cos(theta) * axis + std::sin(theta) * radial;
      double far = 0.0;
      bool found = false;
      for (double hit : section.lineHits(profileCentre, direction)) {
        const Vec point = profileCentre + hit * direction;
        if (hit > 0.0 && (point - centre).dot(radial) > 0.0) {
          far = found ? std::min(far, hit) : hit;
          found = true;
        }
      }
      ring.push_back(draft.add(profileCentre + far * direction));
    }
    rings.push_back(ring);
  }
  for (int k = 0; k < circumferential; ++k) {
    const std::vector<int>& a = rings[static_cast<size_t>(k)];
    const std::vector<int>& b = rings[static_cast<size_t>((k + 1) % circumferential)];
    for (int i = 0; i < around; ++i) {
      const int i1 = (i + 1) % around;
      draft.faces.push_back({a[static_cast<size_t>(i)], a[static_cast<size_t>(i1)],
                             b[static_cast<size_t>(i1)], b[static_cast<size_t>(i)]});
    }
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
      draft = buildWing(values, target, curves, plane, planform);
      break;
    case Generator::Nacelle:
      draft = buildNacelle(values, target);
      break;
  }
  // The signed volume of a closed polyhedron does not depend on the reference point; an open half
  // model is closed by its symmetry plane, so the reference lies in that plane.
  Vec reference = frameMid(frame);
  if (plane)
    reference -= (reference - plane->point).dot(plane->normal.normalized()) * plane->normal.normalized();
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
    improvePolyhedron(mesh, target, mapping.map, improvement);
    mapping = mapFeatures(mesh, target, curves, options.mapping);
  }
  return PlacedPolyhedron{
      polyhedronTemplate.name, std::move(mesh), std::move(mapping), curves, plane, used, planform};
}

}  // namespace bvmesh::polyhedron

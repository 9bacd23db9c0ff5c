#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <type_traits>

#include "core/common/closest_point.h"
#include "core/common/errors.h"
#include "core/common/number_text.h"
#include "core/polyhedron/draft_check.h"
#include "core/polyhedron/placement_parts.h"
#include "core/polyhedron/target_analysis.h"

namespace bvmesh::polyhedron::placement_detail {

// ---- bodies of revolution -------------------------------------------------------------------

// Whether a feature curve of `kind` lies within `reach` of the axial position `end` all along,
// other than one lying in the symmetry plane (a half model's cut): an open end's free boundary,
// or the crease round a flat end's face.
bool curveAtEnd(const target::Target& target, const std::vector<FeatureCurve>& curves, FeatureCurveKind kind,
                const std::optional<fit::SymmetryPlane>& plane, const Vec& origin, const Vec& axis, double end,
                double reach) {
  for (const FeatureCurve& curve : curves) {
    if (curve.kind != kind) continue;
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


// Mean distance of the section's outline from `centre` (weighted by segment length): a
// station's radius; `fallback` where the plane misses the target.
double sectionRadius(const PlaneSection& section, const Vec& centre, double fallback) {
  double sum = 0.0, weight = 0.0;
  const target::Points& p = section.points();
  for (Eigen::Index k = 0; k + 1 < p.rows(); k += 2) {
    const double w = (p.row(k + 1) - p.row(k)).norm();
    sum += w * (0.5 * (p.row(k) + p.row(k + 1)).transpose() - centre).norm();
    weight += w;
  }
  return weight > 0.0 ? sum / weight : fallback;
}

int quarterSegments(const TemplateValues& values) {
  const int circumferential = values.integer("circumferential");
  if (circumferential % 4 != 0) {
    throw InvalidInputError("template parameter 'circumferential' must be a multiple of 4, got " +
                            std::to_string(circumferential));
  }
  return circumferential / 4;
}

// The target's vertex at the tip of a pointed end (axial position `end`, outward the direction
// from the body to the end): a vertex within `reach` of the axis there, round which the surface
// leaves the axis at a slope, not across it as a round end's does (its normals 1e-3 of the
// length from the tip more than 30 degrees off the axis). None for a round, flat or open end.
std::optional<int> pointedTip(const target::Target& target, const BodyAxis& body, double end, double outward,
                              double reach) {
  const Vec tipPoint = body.origin + end * body.e1;
  std::optional<int> tip;
  for (int v = 0; v < target.vertexCount(); ++v) {
    if ((target.vertexPosition(v) - tipPoint).norm() <= reach &&
        (!tip || (target.vertexPosition(v) - tipPoint).norm() < (target.vertexPosition(*tip) - tipPoint).norm()))
      tip = v;
  }
  if (!tip) return std::nullopt;
  const Vec at = target.vertexPosition(*tip);
  const double step = 1e-3 * (body.hi - body.lo);
  constexpr int kProbes = 8;
  target::Points probes(kProbes, 3);
  for (int k = 0; k < kProbes; ++k) {
    const double phi = 2.0 * kPi * k / kProbes;
    probes.row(k) = (at - outward * step * body.e1 + step * (std::cos(phi) * body.e2 + std::sin(phi) * body.e3))
                        .transpose();
  }
  const target::ProjectionResult feet = target.project(probes);
  for (int k = 0; k < kProbes; ++k) {
    if (feet.status[static_cast<size_t>(k)] == target::ProjectionStatus::Failed) return std::nullopt;
    if (std::abs(feet.normals.row(k).dot(body.e1)) > std::cos(kPi / 6.0)) return std::nullopt;  // round there
  }
  return tip;
}

void resolveEnds(const TemplateValues& values, const target::Target& target,
                 const std::vector<FeatureCurve>& curves, const std::optional<fit::SymmetryPlane>& plane,
                 BodyAxis& body, std::map<std::string, std::string>& used) {
  body.ends = {values.choice("nose"), values.choice("tail")};
  for (int side = 0; side < 2; ++side) {
    std::string& end = body.ends[static_cast<size_t>(side)];
    const double at = side ? body.hi : body.lo, reach = 0.01 * (body.hi - body.lo);
    const double outward = side ? 1.0 : -1.0;
    std::optional<int> tip;
    if (end == "auto") {
      if (curveAtEnd(target, curves, FeatureCurveKind::Boundary, plane, body.origin, body.e1, at, reach)) {
        end = "open";
      } else if (curveAtEnd(target, curves, FeatureCurveKind::Sharp, plane, body.origin, body.e1, at, reach)) {
        end = "flat";
      } else {
        tip = pointedTip(target, body, at, outward, reach);
        end = tip ? "pointed" : "round";
      }
    } else if (end == "pointed") {
      tip = pointedTip(target, body, at, outward, reach);
      if (!tip) {
        throw InvalidInputError("template '" + values.templateName() + "' cannot be placed on this target: " +
                                (side ? "tail" : "nose") +
                                " pointed: the target has no vertex on the axis at that end with a pointed "
                                "surface round it (choose round, flat or open)");
      }
    }
    if (tip) body.tips[static_cast<size_t>(side)] = target.vertexPosition(*tip);
  }
  used["nose"] = body.ends[0];
  used["tail"] = body.ends[1];
}

// Whether an end is a dome cast from its rim's centre: a round end, or a pointed one (whose
// middle vertex then moves onto the tip).
bool domed(const std::string& end) { return end == "round" || end == "pointed"; }

// A ring-capped flat end's inner ring, as a fraction of the end's radius.
constexpr double kCapRing = 0.5;

// The stations whose rings are the nose's and the tail's rims (of stations 0 .. last): a
// ring-capped end's rim is the station next to its end.
std::array<int, 2> rimStations(const BodyAxis& body, int last) {
  return {body.ringCapped[0] ? 1 : 0, body.ringCapped[1] ? last - 1 : last};
}

// Axial coordinates of the end rims: a round end's dome takes `cap` of the length.
std::array<double, 2> bodyRims(const BodyAxis& body) {
  const double length = body.hi - body.lo;
  const double cap = std::min(body.radius, 0.25 * length);
  const double inset = 1e-4 * length;
  return {domed(body.ends[0]) ? body.lo + cap : body.lo + inset, domed(body.ends[1]) ? body.hi - cap : body.hi - inset};
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
  const std::array<int, 2> rim = rimStations(body, axial);
  auto capRing = [&](int i) { return (i == 0 && body.ringCapped[0]) || (i == axial && body.ringCapped[1]); };
  // A flat end's vertices are cast along the axis from within the end's own radius: with the
  // body's (largest) radius a frustum's small end was missed, its cap ring landed on the side
  // and the fit crept at first order.
  std::array<double, 2> endRadius{body.radius, body.radius};
  for (int side = 0; side < 2; ++side) {
    if (body.ends[static_cast<size_t>(side)] != "flat") continue;
    const Vec& centre = centres[static_cast<size_t>(side == 0 ? 0 : axial)];
    endRadius[static_cast<size_t>(side)] =
        std::min(body.radius, sectionRadius(PlaneSection(target, centre, body.e1), centre, body.radius));
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
    const Vec radial = a * body.e2 + b * body.e3;
    const Vec& centre = centres[static_cast<size_t>(i)];
    const int v = draft.add(centre + body.radius * radial);
    // Rays in the symmetry plane would graze the target's boundary there: cast them from just
    // inside the body; the improvement snaps the vertices back onto the plane.
    const Vec lift = half && j == 0 ? Vec(1e-3 * body.radius * body.e2) : Vec::Zero();
    const double outward = i == 0 ? -1.0 : 1.0;
    const double ownRadius = endRadius[i == 0 ? 0 : 1];
    if (capRing(i)) {  // the end face: its ring and its inside, pulled in to kCapRing of the end's radius
      draft.vertices[static_cast<size_t>(v)] = centre + kCapRing * ownRadius * radial;
      rays.add(v, centre + kCapRing * ownRadius * radial + lift, outward * body.e1);
      continue;
    }
    if (ring) {
      rays.add(v, centre + lift, radial);
      if ((i == rim[0] && body.ends[0] == "flat") || (i == rim[1] && body.ends[1] == "flat")) flatRim.push_back(v);
      // Half models: where the symmetry boundary meets an open or flat end.
      if (half && j == 0 && (k == 0 || k == n) &&
          ((i == rim[0] && !domed(body.ends[0])) || (i == rim[1] && !domed(body.ends[1])))) {
        draft.corners.push_back(v);
      }
      continue;
    }
    const std::string& end = body.ends[i == 0 ? 0 : 1];
    if (domed(end)) {
      const double rho = std::min(1.0, std::sqrt(a * a + b * b));
      const Vec dome = body.radius * radial + outward * cap * std::sqrt(1.0 - rho * rho) * body.e1;
      rays.add(v, centre + lift, dome);
    } else {
      rays.add(v, centre + ownRadius * radial + lift, outward * body.e1);
    }
  }
  rays.resolve(target, draft, firstHit);
  // A pointed end's middle vertex (s = t = 0 of its dome) sits on the tip as a corner: the limit
  // surface then comes to a point there instead of rounding it off (a cone's apex by 2 % of the
  // body's length).
  for (int side = 0; side < 2; ++side) {
    const std::optional<Vec>& tip = body.tips[static_cast<size_t>(side)];
    if (!tip) continue;
    const int station = side == 0 ? 0 : axial;
    for (size_t v = 0; v < lattice.coords.size(); ++v) {
      const auto [i, j, k] = lattice.coords[v];
      if (i == station && 2 * k == n && (half ? j == 0 : 2 * j == ny)) {
        draft.vertices[v] = *tip;
        draft.corners.push_back(static_cast<int>(v));
      }
    }
  }
  for (const auto& [a, b] : latticeEdges(lattice)) {
    const bool aRim = std::find(flatRim.begin(), flatRim.end(), a) != flatRim.end();
    const bool bRim = std::find(flatRim.begin(), flatRim.end(), b) != flatRim.end();
    const auto& ca = lattice.coords[static_cast<size_t>(a)];
    const auto& cb = lattice.coords[static_cast<size_t>(b)];
    if (aRim && bRim && ca[0] == cb[0]) draft.creases.push_back({a, b});
  }
  return draft;
}

namespace {

// Area enclosed by the ring of body-grid station i, projected across the axis: the lattice
// boundary of (j, k) in [0, ny] x [0, n] walked once around.
double ringArea(const BodyAxis& body, const Draft& draft, const Lattice& lattice, int i) {
  std::map<std::array<int, 3>, int> vertexAt;
  for (size_t v = 0; v < lattice.coords.size(); ++v) vertexAt.emplace(lattice.coords[v], static_cast<int>(v));
  const int ny = lattice.n[1], n = lattice.n[2];
  std::vector<std::array<int, 2>> walk;
  for (int j = 0; j < ny; ++j) walk.push_back({j, 0});
  for (int k = 0; k < n; ++k) walk.push_back({ny, k});
  for (int j = ny; j > 0; --j) walk.push_back({j, n});
  for (int k = n; k > 0; --k) walk.push_back({0, k});
  std::vector<Vec> ring;  // a half body has no vertices inside its j = 0 side: its chord closes the ring
  for (const auto& [j, k] : walk) {
    const auto found = vertexAt.find({i, j, k});
    if (found != vertexAt.end()) ring.push_back(draft.vertices[static_cast<size_t>(found->second)] - body.origin);
  }
  Vec area = Vec::Zero();
  for (size_t w = 0; w < ring.size(); ++w) area += ring[w].cross(ring[(w + 1) % ring.size()]);
  return 0.5 * std::abs(area.dot(body.e1));
}

}  // namespace

void checkFlatEnds(const std::string& templateName, const BodyAxis& body, const Draft& draft,
                   const Lattice& lattice) {
  const int last = lattice.n[0];
  double largest = 0.0;
  for (int i = 0; i <= last; ++i) largest = std::max(largest, ringArea(body, draft, lattice, i));
  for (int side = 0; side < 2; ++side) {
    if (body.ends[static_cast<size_t>(side)] != "flat") continue;
    const double area = ringArea(body, draft, lattice, rimStations(body, last)[static_cast<size_t>(side)]);
    if (area >= 1e-2 * largest) continue;
    const char* name = side ? "tail" : "nose";
    char what[560];
    std::snprintf(what, sizeof(what),
                  "its %s is not flat across the target's main axis (%.3g, %.3g, %.3g): next to that end the target's "
                  "section encloses %.3g, %.2g %% of its largest section (%.3g), so the target ends there in an edge, a "
                  "point or a slanted or rounded face, not in a face across the axis; a flat end needs one: choose "
                  "%s=round (the capsule template) or a template that suits the target's shape",
                  name, body.e1.x(), body.e1.y(), body.e1.z(), area, 100.0 * area / largest, largest, name);
    throw InvalidInputError("template '" + templateName + "' cannot be placed on this target: " + what);
  }
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
  // Flat ends get ring caps: a single quad grid across the end has its corners on the rim, where
  // the rim runs straight through them, and the charts there meet at 180 degrees (a volume
  // block's wall face then has du parallel to dv at that corner).
  for (int side = 0; side < 2; ++side) {
    if (body.ends[static_cast<size_t>(side)] != "flat") continue;
    body.ringCapped[static_cast<size_t>(side)] = true;
    if (side == 0) centres.insert(centres.begin(), centres.front());
    else centres.push_back(centres.back());
  }
  Lattice lattice;
  Draft draft = buildBodyGrid(target, body, n, centres, false, lattice);
  checkFlatEnds(values.templateName(), body, draft, lattice);
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
          numberText(phi * 180.0 / kPi) + " deg)");
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

}  // namespace bvmesh::polyhedron::placement_detail

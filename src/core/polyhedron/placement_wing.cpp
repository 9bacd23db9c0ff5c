#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <type_traits>

#include "core/common/errors.h"
#include "core/common/number_text.h"
#include "core/polyhedron/draft_check.h"
#include "core/polyhedron/placement_parts.h"
#include "core/polyhedron/target_analysis.h"

namespace bvmesh::polyhedron::placement_detail {

// ---- wings ----------------------------------------------------------------------------------

// Where the trailing-edge polylines cross the plane at span s: one point per edge (two curves of
// one edge cross at their common vertex; a blunt edge's base can be thinner than nearCurve).
std::vector<Vec> trailingEdgesAt(const WingFrame& w, double s) {
  std::vector<Vec> points;
  for (const target::Points& line : w.trailingEdges) {
    for (Eigen::Index k = 0; k + 1 < line.rows(); ++k) {
      const double a = (line.row(k).transpose() - w.origin).dot(w.span) - s;
      const double b = (line.row(k + 1).transpose() - w.origin).dot(w.span) - s;
      if ((a <= 0.0) == (b <= 0.0)) continue;
      const Vec p = (line.row(k) + a / (a - b) * (line.row(k + 1) - line.row(k))).transpose();
      if (std::none_of(points.begin(), points.end(),
                       [&](const Vec& q) { return (q - p).norm() <= 1e-6 * w.extent(); }))
        points.push_back(p);
    }
  }
  return points;
}

bool bluntTrailingEdge(const target::Target& target, const WingFrame& w) {
  const double middle = 0.5 * (w.low + w.high);
  const std::vector<Vec> edges = trailingEdgesAt(w, middle);
  if (edges.size() < 2) return false;
  // The chord: from the edges' middle to the section point farthest from it.
  const Vec te = 0.5 * (edges[0] + edges[1]);
  const PlaneSection section(target, w.origin + middle * w.span, w.span);
  double chord = 0.0;
  for (Eigen::Index k = 0; k < section.points().rows(); ++k)
    chord = std::max(chord, (section.points().row(k).transpose() - te).norm());
  const double apart = (edges[0] - edges[1]).norm();
  if (edges.size() > 2 || apart > 0.2 * chord) {
    throw InvalidInputError(
        "the wing templates take one sharp trailing edge or a blunt one (two sharp edges less than a "
        "fifth of the chord apart): " +
        std::to_string(edges.size()) + " sharp spanwise curves cross the section half way along the span" +
        (edges.size() == 2 ? ", " + numberText(apart) + " apart on a chord of " + numberText(chord) +
                                 " (a sharp leading edge?)"
                           : std::string()));
  }
  return edges.size() == 2;
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


// Chord fractions of a ring's upper (or lower) side from the trailing edge towards the leading
// edge, both ends excluded: cosine spacing, dense at both edges.
std::vector<double> cosineFractions(int m) {
  std::vector<double> xi;
  for (int i = 1; i < m; ++i) xi.push_back(0.5 * (1.0 + std::cos(kPi * i / m)));
  return xi;
}

void requireFlatTipForBluntEdge(const WingFrame& w, bool rounded) {
  if (w.blunt && rounded) {
    throw InvalidInputError(
        "the wing templates close a blunt trailing edge only at a flat tip (a sharp rim round the tip "
        "face); this wing's tip is rounded");
  }
}

void putBaseEdges(std::vector<Vec>& ring, const Vec& a, const Vec& b, const Vec& thickness) {
  const bool aUpper = (a - b).dot(thickness) >= 0.0;
  ring[0] = aUpper ? a : b;
  ring.push_back(aUpper ? b : a);
}

// The wing's ring at span s (sectionRing on the plane section of the target).
std::vector<Vec> wingRing(const target::Target& target, const WingFrame& w, double s,
                          const std::vector<double>& upper, const std::vector<double>& lower,
                          WingSection* sectionOut) {
  // The section is taken a little inside the tips, and beside a kink section (whose plane holds
  // tessellation edges, which would make the section degenerate).
  const double inset = 1e-4 * (w.extentHigh - w.extentLow);
  const double cut = std::clamp(s, w.low + inset, w.high - inset) + (w.kinks.count(s) ? inset : 0.0);
  const PlaneSection section(target, w.origin + cut * w.span, w.span);
  std::vector<Vec> edges = trailingEdgesAt(w, cut);
  if (section.empty() || edges.empty()) {
    throw InvalidInputError("wing placement: no section of the target at span " + std::to_string(cut));
  }
  if (edges.size() != (w.blunt ? 2u : 1u)) {
    throw InvalidInputError("wing placement: the section at span " + std::to_string(cut) + " meets " +
                            std::to_string(edges.size()) +
                            " trailing-edge curves where the one half way along the span meets " +
                            (w.blunt ? "two (a blunt trailing edge)" : "one (a sharp trailing edge)"));
  }
  // A blunt edge's chord runs from the middle of its base.
  const Vec te = w.blunt ? Vec(0.5 * (edges[0] + edges[1])) : edges[0];
  WingSection wing;
  std::vector<Vec> ring =
      sectionRing(te, section.points(), w.span, upper, lower, wing,
                  [&](const Vec& base, const Vec& thickness, bool upperSide) {
                    const std::vector<double> hits = section.lineHits(base, thickness);
                    if (hits.empty()) return base;
                    return Vec(base + (upperSide ? hits.back() : hits.front()) * thickness);
                  });
  if (w.blunt) putBaseEdges(ring, edges[0], edges[1], wing.thickness);
  // Stations at the ends of the span lie on the end itself.
  for (Vec& v : ring) v += (s - (v - w.origin).dot(w.span)) * w.span;
  if (sectionOut) {
    const Vec trailingEdge = w.blunt ? Vec(0.5 * (ring.front() + ring.back())) : ring[0];
    *sectionOut = WingSection{trailingEdge, ring[upper.size() + 1], wing.thickness};
  }
  return ring;
}


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
// A feature curve of the given kinds other than the trailing edge, at least 5 % of the span long
// (a tip rim, a kink section): its polyline and the span range it covers.
struct SpanCurve {
  target::Points line;
  double low = 0.0, high = 0.0;
};

std::vector<SpanCurve> longCurves(const target::Target& target, const std::vector<FeatureCurve>& curves,
                                  const WingFrame& w, std::initializer_list<FeatureCurveKind> kinds) {
  std::vector<SpanCurve> result;
  for (size_t c = 0; c < curves.size(); ++c) {
    if (std::find(kinds.begin(), kinds.end(), curves[c].kind) == kinds.end() ||
        curves[c].length < 0.05 * w.extent())
      continue;
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
    for (const SpanCurve& curve : longCurves(target, curves, w, {FeatureCurveKind::Sharp}))
      rim |= std::max(std::abs(curve.low - tipSpan), std::abs(curve.high - tipSpan)) <= 0.01 * w.extent();
    tip = rim ? "flat" : "rounded";
  }
  used["tip"] = tip;
  return tip == "rounded";
}


// Ring index of the side vertex whose chord fraction is nearest `xi`.
int nearestIndex(const std::vector<double>& fractions, double xi) {
  size_t best = 0;
  for (size_t i = 1; i < fractions.size(); ++i)
    if (std::abs(fractions[i] - xi) < std::abs(fractions[best] - xi)) best = i;
  return static_cast<int>(best) + 1;
}

// The feature curves of the given kinds lying in the plane across the span at `span` (within 1e-3
// of the span extent, as kink sections do), by index.
std::vector<int> curvesInPlane(const target::Target& target, const std::vector<FeatureCurve>& curves,
                               const WingFrame& w, double span, std::initializer_list<FeatureCurveKind> kinds) {
  std::vector<int> found;
  for (size_t c = 0; c < curves.size(); ++c) {
    if (std::find(kinds.begin(), kinds.end(), curves[c].kind) == kinds.end()) continue;
    const target::Points line = curvePolyline(target, curves[c]);
    const Eigen::VectorXd s = (line.rowwise() - w.origin.transpose()) * w.span;
    if ((s.array() - span).abs().maxCoeff() <= 1e-3 * w.extent()) found.push_back(static_cast<int>(c));
  }
  return found;
}

// The tips' wedge closures decide the chord fractions of every station: where the wedge's flat
// sides end at a tip, every section gets a vertex at that chord fraction, so that the tip's
// closing creases run from the trailing edge along the ring to that vertex. With followKinks
// (the template's tip_kinks = follow), where a kink in the first tip's plane ends (the edge
// between a wing and the leading-edge patch of its rounded tip, where the CAD turns by a few
// degrees) the nearest cosine fraction moves onto the kink end's: the cap's leading-edge faces
// then end where the kinked patch does (a tangent-continuous surface rounds a kink over about one
// face). Kink ends at the leading or trailing edge are those ring vertices already.
// `tipSpans`: span of each tip station, by station.
WingLayout wingLayout(const target::Target& target, const std::vector<FeatureCurve>& curves,
                      const WingFrame& w, int m, bool rounded, const std::map<int, double>& tipSpans,
                      bool followKinks) {
  WingLayout layout;
  layout.upper = layout.lower = cosineFractions(m);
  std::vector<double> kinkUpper, kinkLower;  // chord fractions of the first tip's kink ends
  for (const auto& [j, span] : tipSpans) {
    WingSection section;
    wingRing(target, w, span, layout.upper, layout.lower, &section);
    // A blunt trailing edge's base ends at the tip in an edge of its own: no wedge to close.
    const TrailingEdgeTip tip =
        rounded && !w.blunt ? trailingEdgeTip(target, curves, w, section) : TrailingEdgeTip{};
    layout.tips[j] = tip;
    if (tip.upper) layout.tipFractions[j] = {section.fraction(*tip.upper), section.fraction(*tip.lower)};
    if (!followKinks || !kinkUpper.empty() || !kinkLower.empty()) continue;
    for (const int c : curvesInPlane(target, curves, w, span, {FeatureCurveKind::Kink})) {
      const target::Points line = curvePolyline(target, curves[static_cast<size_t>(c)]);
      for (const Eigen::Index end : {Eigen::Index{0}, line.rows() - 1}) {
        const Vec p = line.row(end).transpose();
        if (std::min((p - section.leadingEdge).norm(), (p - section.trailingEdge).norm()) <= w.nearCurve()) continue;
        ((p - section.leadingEdge).dot(section.thickness) > 0.0 ? kinkUpper : kinkLower)
            .push_back(section.fraction(p));
      }
    }
  }
  // Each kink end moves the nearest cosine fraction onto it (no thin extra column, the sides stay
  // paired).
  for (double xi : kinkUpper) layout.upper[static_cast<size_t>(nearestIndex(layout.upper, xi) - 1)] = xi;
  for (double xi : kinkLower) layout.lower[static_cast<size_t>(nearestIndex(layout.lower, xi) - 1)] = xi;
  if (!layout.tipFractions.empty()) {  // one pair of fractions for all stations: the first tip's
    insertFraction(layout.upper, layout.tipFractions.begin()->second[0]);
    insertFraction(layout.lower, layout.tipFractions.begin()->second[1]);
  }
  if (layout.upper.size() != layout.lower.size()) {  // the two sides must stay paired for the tip caps
    layout.upper = layout.lower = cosineFractions(m);
    layout.tipFractions.clear();
  }
  return layout;
}

// Quad strips between consecutive wing rings (trailing edge first) and the trailing-edge crease
// along their first vertices.
void addWingStrips(Draft& draft, const std::vector<std::vector<int>>& rings, bool blunt) {
  for (size_t j = 0; j + 1 < rings.size(); ++j) {
    const std::vector<int>& a = rings[j];
    const std::vector<int>& b = rings[j + 1];
    for (size_t k = 0; k < a.size(); ++k) {
      const size_t k1 = (k + 1) % a.size();
      draft.faces.push_back({a[k], a[k1], b[k1], b[k]});
    }
    draft.creases.push_back({a[0], b[0]});
    if (blunt) draft.creases.push_back({a.back(), b.back()});
  }
}

// addTipCap for a blunt trailing edge's ring (2n + 1 vertices) at a flat tip: ridge vertex i
// (1 <= i < n) half way between ring vertices i and 2n - i, a pentagon between the base's two
// edges and ridge vertex 1, the rim creased, the base's ends corners.
void addBluntTipCap(Draft& draft, const WingLayout& layout, const std::vector<int>& ring, double outward) {
  const int n = layout.leadingEdge();
  const int ringSize = 2 * n + 1;
  const auto r = [&](int k) { return ring[static_cast<size_t>((k + ringSize) % ringSize)]; };
  std::vector<int> c(static_cast<size_t>(n), -1);  // c[0] unused: the base's edge closes the cap there
  for (int i = 1; i < n; ++i) {
    c[static_cast<size_t>(i)] = draft.add(0.5 * (draft.vertices[static_cast<size_t>(r(i))] +
                                                 draft.vertices[static_cast<size_t>(r(2 * n - i))]));
  }
  const auto cv = [&](int i) { return c[static_cast<size_t>(i)]; };
  std::vector<std::vector<int>> faces;
  faces.push_back({r(0), r(1), cv(1), r(2 * n - 1), r(2 * n)});
  for (int i = 1; i + 1 < n; ++i) {
    faces.push_back({r(i), r(i + 1), cv(i + 1), cv(i)});
    faces.push_back({cv(i), cv(i + 1), r(2 * n - i - 1), r(2 * n - i)});
  }
  faces.push_back({r(n - 1), r(n), r(n + 1), cv(n - 1)});
  for (std::vector<int>& face : faces) {
    if (outward < 0.0) std::reverse(face.begin(), face.end());
    draft.faces.push_back(face);
  }
  for (int k = 0; k < ringSize; ++k) draft.creases.push_back({r(k), r(k + 1)});
  draft.corners.push_back(r(0));
  draft.corners.push_back(r(2 * n));
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
  if (w.blunt) {
    addBluntTipCap(draft, layout, ring, outward);
    return;
  }
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

// Spans of the sections across the wing where the CAD has an edge: a sharp or kink curve (not the
// trailing edge) at least 5 % of the span long lying in one plane across the span (within 1e-3 of
// the span extent), away from the tips, such as the root section where the two halves of a swept
// wing meet (sharp at the leading edge) or a crank where two lofts meet (a kink of a few degrees).
// Curves within 1e-3 of the span extent of each other (a crank's upper and lower seams) are one
// section.
std::set<double> kinkSections(const target::Target& target, const std::vector<FeatureCurve>& curves,
                              const WingFrame& w) {
  std::set<double> kinks;
  for (const SpanCurve& curve : longCurves(target, curves, w, {FeatureCurveKind::Sharp, FeatureCurveKind::Kink})) {
    const double mid = 0.5 * (curve.low + curve.high);
    const bool across = curve.high - curve.low <= 1e-3 * w.extent();
    const bool inside = std::min(mid - w.low, w.high - mid) >= 0.01 * w.extent();
    const bool known = std::any_of(kinks.begin(), kinks.end(),
                                   [&](double k) { return std::abs(k - mid) <= 1e-3 * w.extent(); });
    if (across && inside && !known) kinks.insert(mid);
  }
  return kinks;
}

// Whether a CAD vertex of the trailing edge's curves (an end of any of their edges: where the
// trailing edge turns at a crank inside one curve, too) lies within `tolerance` of p.
bool trailingEdgeVertexAt(const target::Target& target, const std::vector<FeatureCurve>& curves, const WingFrame& w,
                          const Vec& p, double tolerance) {
  for (int c : w.trailingEdgeCurves) {
    for (int e : curves[static_cast<size_t>(c)].edges) {
      for (int v : target.edgeVertices(e))
        if (v >= 0 && (target.vertexPosition(v) - p).norm() <= tolerance) return true;
    }
  }
  return false;
}

// Creases the ring edges that run along a CAD curve (both ends within `tolerance` of its edges,
// measured exactly: a tessellation polyline's chordal error, near a leading edge, broke a run into
// pieces whose ends mapped to no CAD vertex); the ends of each creased run are corners. A blunt
// trailing edge's ring is open over its base (the base can be thinner than the tolerance, and a
// section's sharp outline ends at both of its edges).
void creaseAlong(Draft& draft, const target::Target& target, const std::vector<int>& ring, const FeatureCurve& curve,
                 double tolerance, bool openOverBase) {
  const size_t count = ring.size();
  target::Points points(static_cast<Eigen::Index>(count), 3);
  for (size_t k = 0; k < count; ++k)
    points.row(static_cast<Eigen::Index>(k)) = draft.vertices[static_cast<size_t>(ring[k])].transpose();
  const target::ProjectionResult feet = target.projectToEdges(points, curve.edges);
  std::vector<bool> on(count);
  for (size_t k = 0; k < count; ++k)
    on[k] = feet.status[k] != target::ProjectionStatus::Failed &&
            feet.distances[static_cast<Eigen::Index>(k)] <= tolerance;
  const auto onAt = [&](size_t k, bool forward) {  // the neighbour's flag; off beyond an open base
    if (openOverBase && (forward ? k + 1 == count : k == 0)) return false;
    return static_cast<bool>(on[forward ? (k + 1) % count : (k + count - 1) % count]);
  };
  for (size_t k = 0; k < count; ++k) {
    if (on[k] && onAt(k, true)) draft.creases.push_back({ring[k], ring[(k + 1) % count]});
    if (on[k] && onAt(k, false) != onAt(k, true)) draft.corners.push_back(ring[k]);  // a run's end
  }
}

// A station next to each tip whose wedge is closed by corners, as far from the tip as the cap's
// edge at those corners is long (about 0.5 mm on the M6). The closure's corners stay put under
// subdivision; with the previous station tens of millimetres away, the first subdivision drags the
// points of the short edges at a corner far behind it, and the limit surface folds there (at every
// level and after fitting). With the corner's quads about as long as wide it does not. Moves the
// tip's layout entries and the kink rings to the new station numbers.
void addWedgeCornerStations(WingLayout& layout, std::vector<double>& spans, std::map<int, double>& kinkRings,
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
  w.blunt = bluntTrailingEdge(target, w);
  used["trailing_edge"] = w.blunt ? "blunt" : "sharp";
  w.kinks = kinkSections(target, curves, w);
  const bool rounded = roundedTip(values, target, curves, w, w.high, used);
  requireFlatTipForBluntEdge(w, rounded);
  // Stations dense towards the tips, whose caps and wedge closures are small features, and coarse
  // where a wing's sections change slowly: half-cosine spacing, a half wing's root being no tip.
  std::vector<double> spans;
  for (int j = 0; j <= stations; ++j) {
    const double t = static_cast<double>(j) / stations;
    spans.push_back(w.low + (w.high - w.low) * (half ? std::sin(0.5 * kPi * t) : 0.5 * (1.0 - std::cos(kPi * t))));
  }
  // A kink section takes the place of the nearest inner station not taken yet when it lies within
  // half that station's smaller gap to a neighbour (its ring is creased along it), else it is a
  // station of its own: a wing of many ruled sections keeps the stations dense towards the tip
  // (given all of them, its uniform sections left the tip's strip coarse and the far field folded
  // at the tip's leading edge).
  std::vector<bool> taken(spans.size(), false);
  for (const double span : w.kinks) {
    int nearest = -1;
    for (int j = 1; j < stations; ++j) {
      if (!taken[static_cast<size_t>(j)] &&
          (nearest < 0 || std::abs(spans[static_cast<size_t>(j)] - span) <
                              std::abs(spans[static_cast<size_t>(nearest)] - span)))
        nearest = j;
    }
    const auto at = [&](int j) { return spans[static_cast<size_t>(j)]; };
    if (nearest < 0 ||
        std::abs(at(nearest) - span) > 0.5 * std::min(at(nearest) - at(nearest - 1), at(nearest + 1) - at(nearest))) {
      spans.push_back(span);
      continue;
    }
    spans[static_cast<size_t>(nearest)] = span;
    taken[static_cast<size_t>(nearest)] = true;
  }
  std::sort(spans.begin(), spans.end());
  std::map<int, double> kinkRings;  // span by station
  for (size_t j = 0; j < spans.size(); ++j)
    if (w.kinks.count(spans[j])) kinkRings[static_cast<int>(j)] = spans[j];
  const auto spanAt = [&](int j) { return spans[static_cast<size_t>(j)]; };
  const int farTip = static_cast<int>(spans.size()) - 1;
  std::map<int, double> tipSpans{{farTip, spanAt(farTip)}};  // the far tip, and a full wing's near one
  if (!half) tipSpans[0] = spanAt(0);
  WingLayout layout = wingLayout(target, curves, w, m, rounded, tipSpans, values.choice("tip_kinks") == "follow");
  addWedgeCornerStations(layout, spans, kinkRings, farTip);
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
  addWingStrips(draft, rings, w.blunt);
  const double kinkTolerance = w.nearCurve();
  for (const auto& [j, span] : kinkRings) {
    const std::vector<int>& ring = rings[static_cast<size_t>(j)];
    // The ring is creased along every sharp curve and kink in its plane: on a swept full wing's
    // root the sharp seam and the trailing-edge wedge's two seams (kinks), without which the
    // wedge's faces, smooth across the planform's notch between the trailing edges (more than 180
    // degrees), bulged 1 mm behind it at level 3 on the full M6. A curve can be shorter than the
    // placement's reach (the M6's wedge seams: 4.6 mm, 1.1 mm apart): a tenth of its length then.
    for (const int c : curvesInPlane(target, curves, w, span, {FeatureCurveKind::Sharp, FeatureCurveKind::Kink})) {
      const FeatureCurve& curve = curves[static_cast<size_t>(c)];
      creaseAlong(draft, target, ring, curve, std::min(kinkTolerance, 0.1 * curve.length), w.blunt);
    }
    // Where the trailing edge turns on the kink section (the two halves of a full wing, a crank),
    // its vertex is a corner.
    const bool trailingEdgeTurns = trailingEdgeVertexAt(target, curves, w, draft.vertices[static_cast<size_t>(ring[0])],
                                                        kinkTolerance);
    if (trailingEdgeTurns) draft.corners.push_back(ring[0]);
    // A blunt edge's base folds there too (by a few degrees: a kink of the CAD).
    if (trailingEdgeTurns && w.blunt) draft.creases.push_back({ring.back(), ring[0]});
  }
  // A full wing's root is half way between its tips (on the kink section there, if any), not its
  // first station, which is the other tip.
  if (!half) {
    double root = 0.5 * (w.low + w.high);
    for (const double span : w.kinks)
      if (std::abs(span - root) <= 1e-3 * w.extent()) root = span;
    wingRing(target, w, root, layout.upper, layout.lower, &rootSection);
  }
  planform = measurePlanform(w, rootSection, tipSection);
  addTipCap(draft, target, w, layout, tipStation, rings.back(), 1.0, rounded);
  if (half) {
    draft.corners.push_back(rings.front()[0]);
    if (w.blunt) draft.corners.push_back(rings.front().back());
  } else {
    addTipCap(draft, target, w, layout, 0, rings.front(), -1.0, rounded);
  }
  return draft;
}

}  // namespace bvmesh::polyhedron::placement_detail

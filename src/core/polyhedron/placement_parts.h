// The parts of template placement (placement.h) shared between its files: the draft polyhedron,
// its ray casting and lattices (placement_draft.cpp), bodies of revolution and nacelles
// (placement_body.cpp), wings (placement_wing.cpp) and the wing-fuselage half model
// (placement_wing_fuselage.cpp); placement.cpp holds boxes, spheres and placeTemplate.
#pragma once

#include <Eigen/Core>

#include <array>
#include <map>
#include <set>
#include <optional>
#include <string>
#include <vector>

#include "core/common/math_constants.h"
#include "core/polyhedron/placement.h"
#include "core/polyhedron/target_analysis.h"

namespace bvmesh::polyhedron::placement_detail {

using Vec = Eigen::Vector3d;

// ---- draft polyhedron, rays, lattices (placement_draft.cpp) ---------------------------------

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
  ControlMesh build(const Vec& reference);
};

// Outermost intersections of the rays origin + s d (s > 0) with the target; the closest point
// where a ray misses. origins, directions: #P x 3. A hit behind the origin (a line through a
// singular point such as a sphere's pole may report the far side) is cast again slightly tilted.
target::Points outerHits(const target::Target& target, const target::Points& origins,
                         const target::Points& directions);

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
  void resolve(const target::Target& target, Draft& draft, bool firstHit = false) const;
};

// The surface of the lattice box [0,n0] x [0,n1] x [0,n2], only the given sides
// (x-, x+, y-, y+, z-, z+), as quads; vertices carry their lattice coordinates.
struct Lattice {
  std::array<int, 3> n{};
  std::vector<std::array<int, 3>> coords;
  std::vector<std::vector<int>> faces;
};

Lattice latticeSurface(const std::array<int, 3>& n, const std::array<bool, 6>& sides);

// Lattice edges as vertex pairs (each once).
std::vector<std::array<int, 2>> latticeEdges(const Lattice& lattice);

// Points where a polyline (#K x 3; closed: the last point joins the first) crosses a plane.
std::vector<Vec> planeCrossings(const target::Points& line, bool closed, const Vec& point,
                                const Vec& normal);

inline Vec frameMid(const PrincipalFrame& f) { return f.centre + f.axes * (0.5 * (f.low + f.high)); }

// ---- bodies of revolution and nacelles (placement_body.cpp) ---------------------------------

// A body of revolution's axis frame: stations run along e1 from `lo` to `hi` (coordinates from
// `origin`); a half body lies on the e2 side of the symmetry plane through `origin`.
struct BodyAxis {
  bool half = false;
  Vec origin = Vec::Zero();
  Vec e1 = Vec::UnitX(), e2 = Vec::UnitY(), e3 = Vec::UnitZ();
  double lo = 0.0, hi = 0.0;
  double radius = 0.0;              // largest distance of the body from the axis
  std::array<std::string, 2> ends;  // nose (at lo) and tail (at hi): round, pointed, flat or open
  std::array<std::optional<Vec>, 2> tips;  // a pointed end's tip (the target's vertex there)
  // Per end, whether a flat end is capped O-wise: its first station repeats the rim's and its ring
  // lies on the end face (buildBodyGrid), so that every rim vertex has two end-face quads.
  std::array<bool, 2> ringCapped{false, false};
};

int quarterSegments(const TemplateValues& values);

// Resolves `auto` nose and tail choices from the target's free boundary, creases and tips, finds
// a pointed end's tip (BodyAxis::tips), and records them.
void resolveEnds(const TemplateValues& values, const target::Target& target,
                 const std::vector<FeatureCurve>& curves, const std::optional<fit::SymmetryPlane>& plane,
                 BodyAxis& body, std::map<std::string, std::string>& used);

// Axial coordinates of the end rims: a round end's dome takes `cap` of the length.
std::array<double, 2> bodyRims(const BodyAxis& body);

// The body grid: the lattice [0, #stations - 1] x [0, ny] x [0, n] (a half body without its
// j = 0 side, open ends without their end sides) with rings at the station centres (#stations,
// on the axis in order from nose rim to tail rim), each ring vertex cast radially onto the target,
// the end caps cast from their rim centres (domes) or along the axis (flat; a ring-capped flat
// end's first station is a ring at kCapRing of the radius on the end face, the next one its rim).
// Draft vertex v is
// lattice vertex v. `firstHit`: cast to the nearest surface from the centre (a body with other
// parts around it, such as a wing); otherwise to the outermost surface.
Draft buildBodyGrid(const target::Target& target, const BodyAxis& body, int n,
                    const std::vector<Vec>& centres, bool firstHit, Lattice& lattice);

// Throws InvalidInputError naming the template when a flat end of the body grid (cast by
// buildBodyGrid) has no end face across the axis: its rim ring, next to the end, encloses less
// than 1 % of the largest ring's area. The flat end's vertices are cast along the axis onto the
// target's end face; where the target ends in an edge instead (a cylinder along an L-shaped
// block's main axis ends at one of the block's edges), they pile onto that edge and the
// improvement collapsed the end's faces ("face 0 is degenerate").
void checkFlatEnds(const std::string& templateName, const BodyAxis& body, const Draft& draft,
                   const Lattice& lattice);

Draft buildRevolution(const TemplateValues& values, const target::Target& target,
                      const std::vector<FeatureCurve>& curves, std::optional<fit::SymmetryPlane>& plane,
                      std::map<std::string, std::string>& used);

Draft buildNacelle(const TemplateValues& values, const target::Target& target,
                   const std::vector<FeatureCurve>& curves);

// ---- wings (placement_wing.cpp) -------------------------------------------------------------

struct WingFrame {
  Vec origin;                                 // a point at span 0
  Vec span;                                   // unit span direction
  double low = 0.0, high = 0.0;               // span range of the stations (trailing-edge ends)
  double extentLow = 0.0, extentHigh = 0.0;   // span range of the whole target
  std::vector<target::Points> trailingEdges;  // polylines of the sharp spanwise curves
  std::vector<int> trailingEdgeCurves;        // their indices in the feature curve list
  std::set<double> kinks;                     // spans of the kink sections (kinkSections)
  // A blunt trailing edge: two spanwise sharp curves (its upper and lower edges) with a base face
  // between them; rings then have both edges as vertices (set by the wing generator).
  bool blunt = false;
  double extent() const { return extentHigh - extentLow; }
  // How far a placed vertex may lie from a CAD curve's tessellation polyline and still count as on
  // it (covers the polyline's chordal error).
  double nearCurve() const { return 1e-3 * extent(); }
};

// A wing section: the trailing-edge point, the leading edge (the section point farthest from it)
// and the direction from the lower to the upper side.
struct WingSection {
  Vec trailingEdge = Vec::Zero(), leadingEdge = Vec::Zero(), thickness = Vec::Zero();
  Vec chord() const { return trailingEdge - leadingEdge; }
  // Chord fraction of a point: 1 at the trailing edge, 0 at the leading edge.
  double fraction(const Vec& p) const { return (p - leadingEdge).dot(chord()) / chord().squaredNorm(); }
};

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

// Short sharp curves that close the trailing-edge wedge at a tip, leaving the trailing edge's tip
// vertex: along the upper and the lower side of the tip section (where the wedge's flat sides meet
// the tip cap) and along the tip's ridge. Each is given by its far CAD vertex; absent when the CAD
// has no such curve (a wedge that simply runs into a rounded cap).
struct TrailingEdgeTip {
  std::optional<Vec> upper, lower, ridge;
};

struct WingLayout {
  std::vector<double> upper, lower;                   // chord fractions of the side vertices
  std::map<int, TrailingEdgeTip> tips;                // by station
  std::map<int, std::array<double, 2>> tipFractions;  // upper and lower closure ends' chord fractions
  int leadingEdge() const { return static_cast<int>(upper.size()) + 1; }  // its ring index
};

// Chord fractions of a ring's upper (or lower) side from the trailing edge towards the leading
// edge, both ends excluded: cosine spacing, dense at both edges.
std::vector<double> cosineFractions(int m);

WingFrame wingFrame(const target::Target& target, const std::vector<FeatureCurve>& curves, bool half,
                    std::optional<fit::SymmetryPlane>& plane);

// Whether the wing's trailing edge is blunt: the section half way along the stations meets two
// trailing-edge curves less than a fifth of its chord apart, the edges of its base face (a
// flatback's base is up to about a tenth). Throws InvalidInputError naming them when it meets
// more, or two farther apart (a sharp leading edge).
bool bluntTrailingEdge(const target::Target& target, const WingFrame& w);

// A blunt trailing edge's base is closed at a flat tip only (addTipCap): InvalidInputError on a
// rounded one.
void requireFlatTipForBluntEdge(const WingFrame& w, bool rounded);

// A blunt trailing edge's ring (sectionRing's, started at the base's middle): its upper edge
// (along `thickness`) in place of that first vertex, its lower edge appended last.
void putBaseEdges(std::vector<Vec>& ring, const Vec& a, const Vec& b, const Vec& thickness);

// The wing's ring at span s (sectionRing on the plane section of the target).
std::vector<Vec> wingRing(const target::Target& target, const WingFrame& w, double s,
                          const std::vector<double>& upper, const std::vector<double>& lower,
                          WingSection* sectionOut = nullptr);

WingPlanform measurePlanform(const WingFrame& w, const WingSection& root, const WingSection& tip);

// Resolves the `tip` choice: `auto` is flat when a sharp curve other than the trailing edge, and
// longer than 5 % of the span, lies within 1 % of the span of the tip's end (a flat tip's rim),
// else rounded. Records the choice.
bool roundedTip(const TemplateValues& values, const target::Target& target, const std::vector<FeatureCurve>& curves,
                const WingFrame& w, double tipSpan, std::map<std::string, std::string>& used);

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
                      bool followKinks);

// Quad strips between consecutive wing rings (trailing edge first) and the trailing-edge crease
// along their first vertices; a blunt trailing edge's rings end at its lower edge, creased too
// (the strip between last and first vertices lies on the base).
void addWingStrips(Draft& draft, const std::vector<std::vector<int>>& rings, bool blunt);

// Tip cap on the ring of station `station`: a row of vertices along the tip's ridge between upper
// and lower surface, cast along outward x span onto a rounded tip, in the ring's plane with a
// creased rim for a flat one. Ridge vertex i sits across ring vertices i + 1 (upper) and
// 2n - i - 1 (lower); at the trailing edge the cap is two triangles (a quad would fold around the
// thin wedge, with a corner angle of a few degrees), meeting at ridge vertex 0, which is the end
// of the CAD's ridge crease when it has one. outward 1: the far tip, continuing the strips'
// orientation; -1: a full wing's near tip, reversed. The trailing edge becomes a corner. A blunt
// trailing edge's ring (2n + 1 vertices, the base's upper edge at 0, its lower edge at 2n; flat
// tips only) pairs ring vertices i and 2n - i; the cap's face at the base is the pentagon between
// the two base edges and the first ridge vertex, and both base edges' ends are corners.
void addTipCap(Draft& draft, const target::Target& target, const WingFrame& w, const WingLayout& layout,
               int station, const std::vector<int>& ring, double outward, bool rounded);

Draft buildWing(const TemplateValues& values, const target::Target& target,
                const std::vector<FeatureCurve>& curves, std::optional<fit::SymmetryPlane>& plane,
                std::map<std::string, std::string>& used, std::optional<WingPlanform>& planform);

// ---- wing-fuselage half model (placement_wing_fuselage.cpp) ---------------------------------

// A half fuselage (the revolution generator's body grid, its axis and stations taken from the
// body's profile in the symmetry plane) with a hole where the wing root meets it, and the half
// wing (the wing generator's stations and tip cap) extruded from the hole's boundary, which lies
// on the wing-body intersection curve and is creased. The hole spans chordwise - 2 axial segments
// (stations at the root ring's chord fractions) and two circumferential segments centred on the
// wing; its ends are the root's leading- and trailing-edge vertices.
Draft buildWingFuselage(const TemplateValues& values, const target::Target& target,
                        const std::vector<FeatureCurve>& curves, std::optional<fit::SymmetryPlane>& plane,
                        std::map<std::string, std::string>& used, std::optional<WingPlanform>& planform);

}  // namespace bvmesh::polyhedron::placement_detail

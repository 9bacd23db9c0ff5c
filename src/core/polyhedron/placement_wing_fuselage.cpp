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
#include "core/polyhedron/placement_parts.h"
#include "core/polyhedron/target_analysis.h"

namespace bvmesh::polyhedron::placement_detail {

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

namespace {

// The wing-body intersection: a closed polyline round the wing root, and where the trailing edge
// meets it (one point for a sharp edge; a blunt edge's upper and lower edge).
struct Junction {
  target::Points loop;
  std::vector<Vec> trailingEdge;
};

const char* const kNotFused = "the wing must be fused with the body, the intersection curve sharp";

// A sharp trailing edge: the closed sharp curve starting at an end vertex of a (spanwise, open)
// trailing-edge curve, the innermost one if several (a flat tip's rim also starts at the trailing
// edge).
Junction sharpJunction(const target::Target& target, const std::vector<FeatureCurve>& curves,
                       const WingFrame& w) {
  const double diagonal = target.report().diagonal;
  const auto spanOf = [&](const Vec& p) { return (p - w.origin).dot(w.span); };
  Junction junction;
  double innermost = std::numeric_limits<double>::infinity();
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
          along.maxCoeff() <= spanOf(corner) + 1e-3 * diagonal || spanOf(corner) >= innermost)
        continue;
      innermost = spanOf(corner);
      junction.trailingEdge = {corner};
      junction.loop = curvePolyline(target, loop);
    }
  }
  if (junction.loop.rows() == 0) {
    throw InvalidInputError(
        std::string(
            "wing-fuselage placement: no closed sharp curve (the wing-body intersection) starts where "
            "the trailing edge meets the body: ") +
        kNotFused);
  }
  return junction;
}

// A blunt trailing edge: its two curves' inner ends are joined by two sharp curves, the longer one
// round the wing and the base's edge on the body (each ends there, where three sharp edges meet).
Junction bluntJunction(const target::Target& target, const std::vector<FeatureCurve>& curves,
                       const WingFrame& w) {
  std::vector<int> ends;
  for (const int c : w.trailingEdgeCurves) {
    const FeatureCurve& te = curves[static_cast<size_t>(c)];
    if (te.startVertex < 0 || te.endVertex < 0) continue;
    const auto spanOf = [&](int v) { return (target.vertexPosition(v) - w.origin).dot(w.span); };
    ends.push_back(spanOf(te.startVertex) < spanOf(te.endVertex) ? te.startVertex : te.endVertex);
  }
  std::vector<const FeatureCurve*> between;
  if (ends.size() == 2) {
    for (const FeatureCurve& curve : curves) {
      if (curve.kind == FeatureCurveKind::Sharp && !curve.closed &&
          ((curve.startVertex == ends[0] && curve.endVertex == ends[1]) ||
           (curve.startVertex == ends[1] && curve.endVertex == ends[0])))
        between.push_back(&curve);
    }
  }
  if (between.size() != 2) {
    throw InvalidInputError(
        "wing-fuselage placement: the blunt trailing edge's inner ends should be joined by two sharp curves "
        "on the body (round the wing root and across the base), found " +
        std::to_string(between.size()) + ": " + kNotFused);
  }
  if (between[0]->length < between[1]->length) std::swap(between[0], between[1]);
  // Round the wing from ends[0] to ends[1], then back across the base.
  std::vector<Vec> points;
  for (int part = 0; part < 2; ++part) {
    target::Points line = curvePolyline(target, *between[static_cast<size_t>(part)]);
    if (between[static_cast<size_t>(part)]->startVertex != ends[static_cast<size_t>(part)])
      line = line.colwise().reverse().eval();
    for (Eigen::Index k = part == 0 ? 0 : 1; k < line.rows(); ++k) points.push_back(line.row(k).transpose());
  }
  Junction junction;
  junction.loop.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t k = 0; k < points.size(); ++k)
    junction.loop.row(static_cast<Eigen::Index>(k)) = points[k].transpose();
  junction.trailingEdge = {target.vertexPosition(ends[0]), target.vertexPosition(ends[1])};
  return junction;
}

Junction wingBodyJunction(const target::Target& target, const std::vector<FeatureCurve>& curves,
                          const WingFrame& w) {
  return w.blunt ? bluntJunction(target, curves, w) : sharpJunction(target, curves, w);
}

// Removes `vertex` where exactly two faces use it, sharing one edge from it: the two become one
// face along their other edges (two quads, a pentagon).
void dropVertexBetweenFaces(Draft& draft, int vertex) {
  std::vector<size_t> users;
  for (size_t f = 0; f < draft.faces.size(); ++f) {
    const std::vector<int>& face = draft.faces[f];
    if (std::find(face.begin(), face.end(), vertex) != face.end()) users.push_back(f);
  }
  if (users.size() != 2) {
    throw InvalidInputError(
        "wing-fuselage placement: the body vertex beside the blunt trailing edge's base has " +
        std::to_string(users.size()) + " faces behind the wing instead of 2");
  }
  // Rotated so that each face starts at the vertex: a = (vertex, y, ...), b = (vertex, ..., y).
  auto rotated = [&](size_t f) {
    std::vector<int> face = draft.faces[f];
    std::rotate(face.begin(), std::find(face.begin(), face.end(), vertex), face.end());
    return face;
  };
  std::vector<int> a = rotated(users[0]), b = rotated(users[1]);
  if (a[1] != b.back()) std::swap(a, b);
  if (a[1] != b.back()) {
    throw InvalidInputError(
        "wing-fuselage placement: the two faces behind the blunt trailing edge's base share no edge");
  }
  // a walks vertex -> y -> ... -> vertex, b walks vertex -> ... -> y -> vertex: the merged face
  // runs y ... (a's rest), then b's vertices between the vertex and y.
  std::vector<int> merged(a.begin() + 1, a.end());
  merged.insert(merged.end(), b.begin() + 1, b.end() - 1);
  draft.faces[users[0]] = merged;
  draft.faces.erase(draft.faces.begin() + static_cast<std::ptrdiff_t>(users[1]));
}

}  // namespace

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
  w.blunt = bluntTrailingEdge(target, w);
  used["trailing_edge"] = w.blunt ? "blunt" : "sharp";
  const Junction junction = wingBodyJunction(target, curves, w);
  const Vec teRoot = 0.5 * (junction.trailingEdge.front() + junction.trailingEdge.back());
  w.low = (teRoot - w.origin).dot(w.span);
  const bool rounded = roundedTip(values, target, curves, w, w.high, used);
  requireFlatTipForBluntEdge(w, rounded);
  const WingLayout layout = wingLayout(target, curves, w, m, rounded, {{stations, w.high}}, false);
  const int lead = layout.leadingEdge();  // ring index of the leading edge (chordwise, or one more
                                          // for a rounded tip's wedge closure)
  // The hole's columns: one per ring point pair of the upper and lower side; the trailing edge's
  // vertex shares the first (a sharp edge) or has one of its own (a blunt edge's base).
  const int holeSegments = w.blunt ? lead - 1 : lead - 2;
  if (lead < 3 || axial < holeSegments + 2) {
    throw InvalidInputError(
        "template parameters: the wing-fuselage model needs chordwise >= 3 and axial >= " +
        std::string(w.blunt ? "chordwise + 1 (the wing root with a blunt trailing edge takes chordwise - 1"
                            : "chordwise (the wing root takes chordwise - 2") +
        " axial segments), got axial " + std::to_string(axial) + ", chordwise " + std::to_string(lead));
  }
  WingSection rootSection;
  std::vector<Vec> root =
      sectionRing(teRoot, junction.loop, w.span, layout.upper, layout.lower, rootSection,
                  [&](const Vec& base, const Vec& thickness, bool upperSide) {
                    // The junction's extreme crossing with the plane across the chord at `base`.
                    Vec best = base;
                    double height = -std::numeric_limits<double>::infinity();
                    for (const Vec& p : planeCrossings(junction.loop, true, base, w.span.cross(thickness))) {
                      const double h = (upperSide ? 1.0 : -1.0) * (p - base).dot(thickness);
                      if (h > height) {
                        height = h;
                        best = p;
                      }
                    }
                    return best;
                  });
  if (w.blunt) putBaseEdges(root, junction.trailingEdge[0], junction.trailingEdge[1], rootSection.thickness);

  // Stations: the hole's columns at the root ring's chord fractions, the rest spread evenly
  // ahead of and behind the wing.
  const bool trailingAft = (root[0] - root[static_cast<size_t>(lead)]).dot(body.e1) > 0.0;
  const auto axialOf = [&](int r) {  // ring points r and 2 lead - r (r = 1 .. lead - 1)
    return (0.5 * (root[static_cast<size_t>(r)] + root[static_cast<size_t>(2 * lead - r)]) - body.origin)
        .dot(body.e1);
  };
  std::vector<double> columns;  // axial coordinates of the hole's columns, increasing
  if (w.blunt) columns.push_back((teRoot - body.origin).dot(body.e1));
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
  checkFlatEnds(values.templateName(), body, draft, lattice);

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
  std::vector<int> junctionRing(root.size());
  const int teColumn = trailingAft ? i1 : i0;
  const int firstColumn = w.blunt ? 1 : 0;  // of ring point 1, counted from the trailing edge's
  const auto column = [&](int r) {
    return trailingAft ? i1 - (r - 1 + firstColumn) : i0 + (r - 1 + firstColumn);
  };
  if (w.blunt) {
    junctionRing.front() = side.at({teColumn, upperRow});
    junctionRing.back() = side.at({teColumn, lowerRow});
  } else {
    junctionRing[0] = side.at({teColumn, qc});
  }
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
  // A blunt edge's base meets the body in one edge between its two ring vertices: the body vertex
  // between them goes, its two faces behind the wing becoming one pentagon.
  if (w.blunt) dropVertexBetweenFaces(draft, side.at({teColumn, qc}));

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
  addWingStrips(wing, rings, w.blunt);
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
  for (size_t r = 0; r < junctionRing.size(); ++r)
    draft.creases.push_back({junctionRing[r], junctionRing[(r + 1) % junctionRing.size()]});
  draft.corners.push_back(junctionRing.front());
  if (w.blunt) draft.corners.push_back(junctionRing.back());
  planform = measurePlanform(w, rootSection, tipSection);
  removeUnusedVertices(draft);
  return draft;
}

}  // namespace bvmesh::polyhedron::placement_detail

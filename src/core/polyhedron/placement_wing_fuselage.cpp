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
  if (bluntTrailingEdge(target, w)) {
    throw InvalidInputError(
        "the wing_fuselage template takes a sharp trailing edge; this wing's is blunt (the wing "
        "templates take blunt ones)");
  }
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
  const WingLayout layout = wingLayout(target, curves, w, m, rounded, {{stations, w.high}}, false);
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
  addWingStrips(wing, rings, false);
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

}  // namespace bvmesh::polyhedron::placement_detail

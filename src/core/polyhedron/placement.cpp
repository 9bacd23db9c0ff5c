#include "core/polyhedron/placement.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <type_traits>

#include "core/common/closest_point.h"
#include "core/common/errors.h"
#include "core/polyhedron/draft_check.h"
#include "core/polyhedron/placement_parts.h"
#include "core/polyhedron/target_analysis.h"

namespace bvmesh::polyhedron {
namespace {

using namespace placement_detail;

// ---- box and sphere -------------------------------------------------------------------------

// Segments along a principal axis in proportion to its extent, `shortest` along the third axis.
int segmentsByExtent(const PrincipalFrame& frame, int axis, int shortest) {
  constexpr int kMostSegments = 64;  // the templates' bound on a count
  const Vec extent = frame.high - frame.low;
  return static_cast<int>(
      std::clamp(std::round(shortest * extent[axis] / extent[2]), 1.0, double{kMostSegments}));
}

// Segments per principal axis; an axis given 0 follows its extent, so that the faces are about
// square: from a 2 x 1 x 1 box with two segments on every axis (faces of 2:1 cells on the long
// sides) the marching folded at the corners.
std::array<int, 3> boxSegments(const TemplateValues& values, const PrincipalFrame& frame,
                               std::map<std::string, std::string>& used) {
  std::array<int, 3> n{};
  for (int axis = 0; axis < 3; ++axis) {
    const std::string name = "segments_" + std::to_string(axis + 1);
    int& count = n[static_cast<size_t>(axis)];
    count = values.integer(name);
    if (count == 0) count = segmentsByExtent(frame, axis, values.integer("segments_3"));
    used[name] = std::to_string(count);
  }
  return n;
}

Draft buildBox(const TemplateValues& values, const target::Target& target,
               std::map<std::string, std::string>& used) {
  const PrincipalFrame frame = principalFrame(target);
  const std::array<int, 3> n = boxSegments(values, frame, used);
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

// Segments along the shortest axis of a sphere template left at 0: the thesis' plain cube on a
// round body; 2 on a body whose longest extent is kRoundBodyRatio times its shortest or more.
// With one segment across, an elongated or flat body's tips lie under the middle of a coarse
// face: from 3:1:1, 3:3:1 and 3:2:1 ellipsoids on, the fit stagnated or stopped 0.4-5 % of the
// length from the target and the boundary layer folded; with 2 every one of them to 6:3:1 fits and
// marches (docs/templates.md).
int sphereShortestSegments(const PrincipalFrame& frame, int given) {
  constexpr double kRoundBodyRatio = 1.2;
  if (given > 0) return given;
  const Vec extent = frame.high - frame.low;
  return extent.maxCoeff() < kRoundBodyRatio * extent[2] ? 1 : 2;
}

Draft buildSphere(const TemplateValues& values, const target::Target& target,
                  std::map<std::string, std::string>& used) {
  const PrincipalFrame frame = principalFrame(target);
  // Segments in proportion to the extents: the plain cube on a 2 x 1 x 1 ellipsoid left its tips
  // under one face each, far inside, and the fit stagnated 0.4 from the target.
  const int shortest = sphereShortestSegments(frame, values.integer("segments"));
  used["segments"] = std::to_string(shortest);
  std::array<int, 3> n{};
  for (int axis = 0; axis < 3; ++axis) n[static_cast<size_t>(axis)] = segmentsByExtent(frame, axis, shortest);
  const Lattice lattice = latticeSurface(n, {true, true, true, true, true, true});
  const Vec mid = frameMid(frame);
  const Vec half = 0.5 * (frame.high - frame.low);
  Draft draft;
  draft.faces = lattice.faces;
  RayBatch rays;
  for (const std::array<int, 3>& c : lattice.coords) {
    Vec q;  // equiangular cube-to-sphere map: even spacing on the sphere
    for (int a = 0; a < 3; ++a)
      q[a] = std::tan(0.25 * kPi * (2.0 * c[static_cast<size_t>(a)] / n[static_cast<size_t>(a)] - 1.0));
    const Vec onEllipsoid = mid + frame.axes * q.normalized().cwiseProduct(half);
    rays.add(draft.add(onEllipsoid), mid, onEllipsoid - mid);
  }
  rays.resolve(target, draft);
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
  checkTargetHasVolume(polyhedronTemplate.name, frame, target);
  checkTargetIsOneBody(polyhedronTemplate.name, target);
  checkTargetGenus(polyhedronTemplate.name, polyhedronTemplate.generator == Generator::Nacelle ? 1 : 0, target);
  Draft draft;
  if (polyhedronTemplate.generator == Generator::Box || polyhedronTemplate.generator == Generator::Sphere)
    checkNotAHalfModel(polyhedronTemplate.name, target, curves);
  switch (polyhedronTemplate.generator) {
    case Generator::Box:
      draft = buildBox(values, target, used);
      break;
    case Generator::Sphere:
      draft = buildSphere(values, target, used);
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
    checkCornersOnDistinctVertices(polyhedronTemplate.name, mapping.map.vertexCadVertex, target);
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

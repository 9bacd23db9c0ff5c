#include "core/fit/surface_fitter.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <utility>

#include "core/common/errors.h"
#include "core/common/input_checks.h"
#include "core/common/number_text.h"
#include "core/fit/limit_target_distance.h"

namespace bvmesh::fit {
namespace {

using Clock = std::chrono::steady_clock;

// Where the projection step sends one limit sample.
enum class Destination { Surface, Curve, FreeBoundary, SharpEdges, CadVertex };

struct SampleDestination {
  Destination kind = Destination::Surface;
  int id = -1;  // curve index (Curve) or target vertex (CadVertex)
};

bool isFeatureEdge(const ControlMesh& mesh, int edge) {
  return mesh.isBoundaryEdge(edge) || mesh.edgeSharpness()(edge) > 0.0;
}

std::vector<std::vector<int>> vertexEdgeLists(const ControlMesh& mesh) {
  std::vector<std::vector<int>> lists(static_cast<size_t>(mesh.numVertices()));
  for (int e = 0; e < mesh.numEdges(); ++e) {
    lists[static_cast<size_t>(mesh.edges()(e, 0))].push_back(e);
    lists[static_cast<size_t>(mesh.edges()(e, 1))].push_back(e);
  }
  return lists;
}

int otherEnd(const ControlMesh& mesh, int edge, int vertex) {
  return mesh.edges()(edge, 0) == vertex ? mesh.edges()(edge, 1) : mesh.edges()(edge, 0);
}

void checkFeatureMap(FeatureMap& features, const ControlMesh& mesh, const target::Target& target) {
  if (features.edgeCurve.empty()) features.edgeCurve.assign(static_cast<size_t>(mesh.numEdges()), -1);
  if (features.vertexCadVertex.empty()) features.vertexCadVertex.assign(static_cast<size_t>(mesh.numVertices()), -1);
  if (static_cast<int>(features.edgeCurve.size()) != mesh.numEdges()) {
    throw InvalidInputError("the feature map names curves for " + std::to_string(features.edgeCurve.size()) +
                            " edges, but the control mesh has " + std::to_string(mesh.numEdges()));
  }
  if (static_cast<int>(features.vertexCadVertex.size()) != mesh.numVertices()) {
    throw InvalidInputError("the feature map names CAD vertices for " + std::to_string(features.vertexCadVertex.size()) +
                            " vertices, but the control mesh has " + std::to_string(mesh.numVertices()));
  }
  for (size_t c = 0; c < features.curves.size(); ++c) {
    if (features.curves[c].empty()) throw InvalidInputError("feature curve " + std::to_string(c) + " has no CAD edge");
    for (int edge : features.curves[c]) {
      if (edge < 0 || edge >= target.edgeCount()) {
        throw InvalidInputError("feature curve " + std::to_string(c) + " names CAD edge " + std::to_string(edge) +
                                ", but the target has " + std::to_string(target.edgeCount()) + " edges");
      }
    }
  }
  for (size_t e = 0; e < features.edgeCurve.size(); ++e) {
    const int curve = features.edgeCurve[e];
    if (curve < -1 || curve >= static_cast<int>(features.curves.size())) {
      throw InvalidInputError("control-mesh edge " + std::to_string(e) + " names feature curve " + std::to_string(curve) +
                              ", but there are " + std::to_string(features.curves.size()));
    }
    if (curve >= 0 && !isFeatureEdge(mesh, static_cast<int>(e))) {
      throw InvalidInputError("control-mesh edge " + std::to_string(e) +
                              " follows a CAD curve but is neither a crease nor a boundary edge");
    }
  }
  for (size_t v = 0; v < features.vertexCadVertex.size(); ++v) {
    const int cadVertex = features.vertexCadVertex[v];
    if (cadVertex < -1 || cadVertex >= target.vertexCount()) {
      throw InvalidInputError("control-mesh vertex " + std::to_string(v) + " names CAD vertex " +
                              std::to_string(cadVertex) + ", but the target has " +
                              std::to_string(target.vertexCount()) + " vertices");
    }
  }
}

// The children of a feature edge follow its curve; old vertices keep their CAD vertex (the
// subdivided mesh numbers old vertices first, then one edge point per old edge).
FeatureMap propagateFeatures(const FeatureMap& features, const ControlMesh& coarse, const ControlMesh& fine) {
  FeatureMap result;
  result.curves = features.curves;
  result.edgeCurve.assign(static_cast<size_t>(fine.numEdges()), -1);
  for (int e = 0; e < coarse.numEdges(); ++e) {
    const int curve = features.edgeCurve[static_cast<size_t>(e)];
    if (curve < 0) continue;
    const int mid = coarse.numVertices() + e;
    for (int end = 0; end < 2; ++end) {
      const int child = fine.findEdge(coarse.edges()(e, end), mid);
      if (child >= 0) result.edgeCurve[static_cast<size_t>(child)] = curve;
    }
  }
  result.vertexCadVertex = features.vertexCadVertex;
  result.vertexCadVertex.resize(static_cast<size_t>(fine.numVertices()), -1);
  return result;
}

}  // namespace

struct SurfaceFitter::State {
  State(std::shared_ptr<const target::Target> t, ControlMesh m, FeatureMap f, FitOptions o)
      : target(std::move(t)), mesh(std::move(m)), features(std::move(f)), options(std::move(o)) {}

  std::shared_ptr<const target::Target> target;
  ControlMesh mesh;
  std::vector<ControlMesh> lowerLevels;  // the mesh as each lower level was left
  FeatureMap features;
  FitOptions options;
  double tolerance = 0.0;
  int level = 0;
  int correction = 0;

  // Built once per topology (level), dropped by subdivide().
  std::optional<LimitSamples> samples;
  std::vector<SampleDestination> destinations;
  std::vector<std::vector<int>> destinationCurves;  // edge lists: the feature curves, then unions at junctions
  std::unique_ptr<ControlPointSolver> solver;

  // Valid for the current control points; dropped when they move.
  RowMatrixX3d positions;
  bool positionsValid = false;
  target::ProjectionResult projections;
  bool projectionsValid = false;
  // Per-sample surface locations that warm-start the next projection: the last projections of
  // this topology, or after a subdivision those of the parent samples at (or next to) each sample.
  target::SurfaceHints hints;
  bool haveHints = false;

  std::vector<PassRecord> history;
  bool historyIsCurrent = false;  // the last record measures the current control points
  Clock::time_point lastRecord = Clock::now();

  void dropGeometry() {
    positionsValid = false;
    projectionsValid = false;
    historyIsCurrent = false;
  }

  void dropTopology() {
    samples.reset();
    solver.reset();
    destinations.clear();
    haveHints = false;
    correction = 0;
    dropGeometry();
  }

  // The vertices of the subdivided mesh are numbered like the parent's samples (old vertices,
  // edge points, face points), and each lies at its parent sample's limit point: it inherits that
  // sample's projection as a hint. New edge and face samples take the hint of their first vertex.
  void inheritHints(const target::SurfaceHints& parent) {
    ensureSamples();
    hints.faces.resize(samples->size());
    hints.uv.resize(samples->size(), 2);
    for (int i = 0; i < samples->size(); ++i) {
      const int source = samples->sourceIds()[i];
      int parentSample = source;
      switch (samples->elements()[static_cast<size_t>(i)]) {
        case SampleElement::Vertex: break;
        case SampleElement::Edge: parentSample = mesh.edges()(source, 0); break;
        case SampleElement::Face: parentSample = mesh.faceVertex(source, 0); break;
      }
      hints.faces[i] = parent.faces[parentSample];
      hints.uv.row(i) = parent.uv.row(parentSample);
    }
    haveHints = true;
  }

  // Curve id for a set of CAD edges; unions at feature junctions get ids after the user's curves.
  int curveFor(std::vector<int> edges) {
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    for (size_t c = 0; c < destinationCurves.size(); ++c) {
      if (destinationCurves[c] == edges) return static_cast<int>(c);
    }
    destinationCurves.push_back(std::move(edges));
    return static_cast<int>(destinationCurves.size()) - 1;
  }

  SampleDestination vertexDestination(int vertex, SampleFeature feature,
                                      const std::vector<std::vector<int>>& vertexEdges) {
    const int cadVertex = features.vertexCadVertex[static_cast<size_t>(vertex)];
    if (cadVertex >= 0) return {Destination::CadVertex, cadVertex};
    if (feature == SampleFeature::Smooth) return {Destination::Surface, -1};
    std::vector<int> cadEdges;
    bool onBoundary = false;
    for (int edge : vertexEdges[static_cast<size_t>(vertex)]) {
      onBoundary = onBoundary || mesh.isBoundaryEdge(edge);
      const int curve = features.edgeCurve[static_cast<size_t>(edge)];
      if (curve >= 0) {
        const std::vector<int>& chain = features.curves[static_cast<size_t>(curve)];
        cadEdges.insert(cadEdges.end(), chain.begin(), chain.end());
      }
    }
    if (!cadEdges.empty()) return {Destination::Curve, curveFor(std::move(cadEdges))};
    return {onBoundary ? Destination::FreeBoundary : Destination::SharpEdges, -1};
  }

  void buildSamples() {
    samples.emplace(mesh, options.subdivision);
    destinationCurves.clear();
    for (const std::vector<int>& curve : features.curves) curveFor(curve);
    const std::vector<std::vector<int>> vertexEdges = vertexEdgeLists(mesh);
    destinations.assign(static_cast<size_t>(samples->size()), {});
    for (int i = 0; i < samples->size(); ++i) {
      const SampleFeature feature = samples->features()[static_cast<size_t>(i)];
      const int source = samples->sourceIds()[i];
      switch (samples->elements()[static_cast<size_t>(i)]) {
        case SampleElement::Face:
          break;
        case SampleElement::Edge: {
          const int curve = features.edgeCurve[static_cast<size_t>(source)];
          if (curve >= 0) {
            destinations[static_cast<size_t>(i)] = {Destination::Curve, curveFor(features.curves[static_cast<size_t>(curve)])};
          } else if (feature == SampleFeature::Boundary) {
            destinations[static_cast<size_t>(i)] = {Destination::FreeBoundary, -1};
          } else if (feature == SampleFeature::Crease) {
            destinations[static_cast<size_t>(i)] = {Destination::SharpEdges, -1};
          }
          break;
        }
        case SampleElement::Vertex:
          destinations[static_cast<size_t>(i)] = vertexDestination(source, feature, vertexEdges);
          break;
      }
    }
    checkDestinationsExist();
  }

  // Features without an explicit CAD curve follow the target's sharp edges or free boundary:
  // say so clearly when the target has none.
  void checkDestinationsExist() const {
    bool followsSharpEdges = false;
    bool followsFreeBoundary = false;
    for (const SampleDestination& destination : destinations) {
      followsSharpEdges = followsSharpEdges || destination.kind == Destination::SharpEdges;
      followsFreeBoundary = followsFreeBoundary || destination.kind == Destination::FreeBoundary;
    }
    if (followsSharpEdges && target->sharpEdges(target->options().sharpAngleDeg).empty()) {
      throw InvalidInputError("the control mesh has crease edges without a CAD curve, and the target has no sharp "
                              "edges they could follow: map the creases to CAD edges or remove them");
    }
    if (followsFreeBoundary && target->freeEdges().empty()) {
      throw InvalidInputError("the control mesh has boundary edges without a CAD curve, and the target is closed "
                              "(no free boundary edges): map the boundary to CAD edges, or leave out the faces "
                              "that close the target (e.g. a symmetry-plane face)");
    }
  }

  std::vector<int> planeVertices() const {
    std::vector<int> result;
    if (!options.symmetryPlane) return result;
    const Eigen::Vector3d normal = options.symmetryPlane->normal.normalized();
    const double reach = options.relativePlaneTolerance * target->report().diagonal;
    std::vector<bool> taken(static_cast<size_t>(mesh.numVertices()), false);
    for (int edge : mesh.boundaryEdges()) {
      for (int end = 0; end < 2; ++end) {
        const int v = mesh.edges()(edge, end);
        const double offset = (mesh.vertices().row(v).transpose() - options.symmetryPlane->point).dot(normal);
        if (!taken[static_cast<size_t>(v)] && std::abs(offset) <= reach) {
          taken[static_cast<size_t>(v)] = true;
          result.push_back(v);
        }
      }
    }
    return result;
  }

  void buildSolver() {
    const SampleWeights& w = options.weights;
    Eigen::VectorXd weights(samples->size());
    for (int i = 0; i < samples->size(); ++i) {
      switch (samples->features()[static_cast<size_t>(i)]) {
        case SampleFeature::Smooth: weights[i] = w.smooth; break;
        case SampleFeature::Crease: weights[i] = w.crease; break;
        case SampleFeature::Boundary: weights[i] = w.boundary; break;
        case SampleFeature::Corner: weights[i] = w.corner; break;
      }
    }
    ApproximationConstraints constraints;
    for (int v : options.fixedVertices) {
      if (v >= 0 && v < mesh.numVertices()) constraints.fixedVertices.push_back(v);
    }
    if (options.symmetryPlane) {
      PlaneConstraint plane;
      plane.point = options.symmetryPlane->point;
      plane.normal = options.symmetryPlane->normal;
      plane.vertices = planeVertices();
      if (!plane.vertices.empty()) constraints.plane = std::move(plane);
    }
    solver = std::make_unique<ControlPointSolver>(samples->positionOperator(), weights, constraints, options.solver);
  }

  const target::Target& cad() const { return *target; }

  target::ProjectionResult projectGroup(Destination kind, int id, const RowMatrixX3d& points,
                                        const RowMatrixX3d& normals, const target::SurfaceHints* warmStart) const {
    switch (kind) {
      case Destination::Surface:
        return options.projectAlongNormals ? projectAlongNormals(points, normals, warmStart)
                                           : cad().project(points, warmStart);
      case Destination::Curve:
        return cad().projectToEdges(points, destinationCurves[static_cast<size_t>(id)]);
      case Destination::FreeBoundary:
        return cad().projectToFreeBoundary(points);
      case Destination::SharpEdges:
        return cad().projectToEdges(points, cad().sharpEdges(cad().options().sharpAngleDeg));
      case Destination::CadVertex:
        return cad().projectToVertices(points, {id});
    }
    return {};
  }

  // A hit along a normal farther than this many times the closest point drags the surface more
  // than the closest point would: the line passed a gap left open in the target (or grazed it)
  // and met its far side.
  static constexpr double kFarCast = 4.0;

  // Casts along the limit normals; where the hit is missing or far (kFarCast), the closest point.
  // Without this, samples next to a gap left open (a sphere's hemispheres 1e-3 apart) were cast
  // through it onto the far side and the fit ended in "face 0 is degenerate".
  target::ProjectionResult projectAlongNormals(const RowMatrixX3d& points, const RowMatrixX3d& normals,
                                               const target::SurfaceHints* warmStart) const {
    target::ProjectionResult cast = cad().projectAlong(points, normals);
    const target::ProjectionResult closest = cad().project(points, warmStart);
    for (Eigen::Index k = 0; k < points.rows(); ++k) {
      const auto status = cast.status[static_cast<size_t>(k)];
      if (status == target::ProjectionStatus::Fallback || status == target::ProjectionStatus::Failed ||
          cast.distances[k] > kFarCast * closest.distances[k])
        cast.setRow(k, closest, k);
    }
    return cast;
  }

  void projectAll() {
    ensurePositions();
    std::map<std::pair<int, int>, std::vector<int>> groups;
    for (size_t i = 0; i < destinations.size(); ++i) {
      groups[{static_cast<int>(destinations[i].kind), destinations[i].id}].push_back(static_cast<int>(i));
    }
    const RowMatrixX3d normals = options.projectAlongNormals ? samples->normals(mesh.vertices()) : RowMatrixX3d();
    target::ProjectionResult all;
    all.resize(samples->size());
    for (const auto& [key, members] : groups) {
      const auto count = static_cast<Eigen::Index>(members.size());
      RowMatrixX3d points(count, 3);
      RowMatrixX3d directions(options.projectAlongNormals ? count : 0, 3);
      target::SurfaceHints groupHints;
      groupHints.faces.resize(count);
      groupHints.uv.resize(count, 2);
      for (Eigen::Index k = 0; k < count; ++k) {
        const int i = members[static_cast<size_t>(k)];
        points.row(k) = positions.row(i);
        if (options.projectAlongNormals) directions.row(k) = normals.row(i);
        if (haveHints) {
          groupHints.faces[k] = hints.faces[i];
          groupHints.uv.row(k) = hints.uv.row(i);
        }
      }
      const auto kind = static_cast<Destination>(key.first);
      const target::ProjectionResult part =
          projectGroup(kind, key.second, points, directions, haveHints ? &groupHints : nullptr);
      for (Eigen::Index k = 0; k < count; ++k) all.setRow(members[static_cast<size_t>(k)], part, k);
    }
    if (!options.projectAlongNormals && options.rejectOpposingFeet) reprojectOpposingFeet(all);
    projections = std::move(all);
    projectionsValid = true;
    hints.faces = projections.faces;
    hints.uv = projections.params;
    haveHints = true;
  }

  // Surface samples whose foot normal opposes their limit normal are cast along the limit normal;
  // the hit replaces the foot when its normal agrees. The limit normals' orientation relative to
  // the target's is the one most surface samples agree on (the mesh may be oriented either way).
  void reprojectOpposingFeet(target::ProjectionResult& all) const {
    const RowMatrixX3d normals = samples->normals(mesh.vertices());
    std::vector<int> surface;
    Eigen::VectorXd dots(samples->size());
    double agreement = 0.0;
    for (int i = 0; i < samples->size(); ++i) {
      if (destinations[static_cast<size_t>(i)].kind != Destination::Surface ||
          all.status[static_cast<size_t>(i)] == target::ProjectionStatus::Failed) {
        continue;
      }
      surface.push_back(i);
      dots[i] = normals.row(i).dot(all.normals.row(i));
      agreement += dots[i] > 0.0 ? 1.0 : (dots[i] < 0.0 ? -1.0 : 0.0);
    }
    const double sign = agreement < 0.0 ? -1.0 : 1.0;
    std::vector<int> opposing;
    for (int i : surface) {
      if (sign * dots[i] < 0.0) opposing.push_back(i);
    }
    if (opposing.empty()) return;
    const auto count = static_cast<Eigen::Index>(opposing.size());
    RowMatrixX3d points(count, 3);
    RowMatrixX3d directions(count, 3);
    for (Eigen::Index k = 0; k < count; ++k) {
      points.row(k) = positions.row(opposing[static_cast<size_t>(k)]);
      directions.row(k) = normals.row(opposing[static_cast<size_t>(k)]);
    }
    const target::ProjectionResult cast = cad().projectAlong(points, directions);
    for (Eigen::Index k = 0; k < count; ++k) {
      const auto status = cast.status[static_cast<size_t>(k)];
      const int i = opposing[static_cast<size_t>(k)];
      // A far hit along a tilted normal would drag the surface more than the flip does.
      if (status == target::ProjectionStatus::Fallback || status == target::ProjectionStatus::Failed ||
          sign * directions.row(k).dot(cast.normals.row(k)) <= 0.0 || cast.distances[k] > kFarCast * all.distances[i]) {
        continue;
      }
      all.setRow(i, cast, k);
    }
  }

  void ensureSamples() {
    if (!samples) buildSamples();
  }
  void ensurePositions() {
    ensureSamples();
    if (!positionsValid) {
      positions = samples->positions(mesh.vertices());
      positionsValid = true;
    }
  }
  void ensureProjections() {
    if (!projectionsValid) projectAll();
  }
};

namespace {

// Every option in its range, NaN included, so a bad value is named here and not met later as
// an unrelated failure (a NaN CGLS tolerance used to read as a degenerate face).
void checkOptions(const FitOptions& options, int vertexCount) {
  if (options.maxLevel < 0 || options.maxLevel > 10) {
    throw InvalidInputError("max_level must be 0 .. 10 (each level has 4 times the faces), got " +
                            std::to_string(options.maxLevel));
  }
  if (options.maxControlPoints < 0) {
    throw InvalidInputError("max_control_points must be 0 (no limit) or more, got " +
                            std::to_string(options.maxControlPoints));
  }
  if (options.maxCorrections < 0 || options.maxCorrections > kMaxCorrectionPasses) {
    throw InvalidInputError("max_corrections must be 0 .. " + std::to_string(kMaxCorrectionPasses) +
                            ", got " + std::to_string(options.maxCorrections));
  }
  checkFiniteAtLeast(options.tolerance, 0.0, "tolerance");
  checkFiniteAtLeast(options.relativeTolerance, 0.0, "relative_tolerance");
  if (options.tolerance == 0.0 && options.relativeTolerance == 0.0) {
    throw InvalidInputError("the fitting tolerance must be positive (absolute or relative)");
  }
  checkFiniteAtLeast(options.stagnationRatio, 0.0, "stagnation_ratio", true);
  checkFiniteAtLeast(options.solver.cglsTolerance, 0.0, "cgls_tolerance", true);
  if (options.solver.cglsMaxIterations < 1) throw InvalidInputError("cgls_max_iterations must be at least 1");
  for (const auto& [weight, name] : {std::pair{options.weights.smooth, "weights['smooth']"},
                                     std::pair{options.weights.crease, "weights['crease']"},
                                     std::pair{options.weights.boundary, "weights['boundary']"},
                                     std::pair{options.weights.corner, "weights['corner']"}}) {
    checkFiniteAtLeast(weight, 0.0, name);
  }
  checkFiniteAtLeast(options.relativePlaneTolerance, 0.0, "relative_plane_tolerance");
  if (options.checkSamplesPerFace < 0 || options.checkSamplesPerFace > 64) {
    throw InvalidInputError("check_samples_per_face must be 0 .. 64 (samples per face side), got " +
                            std::to_string(options.checkSamplesPerFace));
  }
  if (options.checkTargetSubdivisions < 1 || options.checkTargetSubdivisions > 64) {
    throw InvalidInputError("check_target_subdivisions must be 1 .. 64 (per tessellation triangle side), got " +
                            std::to_string(options.checkTargetSubdivisions));
  }
  for (int v : options.fixedVertices) {
    if (v < 0 || v >= vertexCount) {
      throw InvalidInputError("fixed_vertices names vertex " + std::to_string(v) + ", but the control mesh has " +
                              std::to_string(vertexCount) + " vertices");
    }
  }
  if (options.symmetryPlane &&
      (!(options.symmetryPlane->normal.norm() > 0.0) || !options.symmetryPlane->point.allFinite() ||
       !options.symmetryPlane->normal.allFinite())) {
    throw InvalidInputError("the symmetry plane needs a finite point and a non-zero normal");
  }
}

double absoluteToleranceOf(const FitOptions& options, const target::Target& target) {
  return options.tolerance > 0.0 ? options.tolerance : options.relativeTolerance * target.report().diagonal;
}

}  // namespace

SurfaceFitter::SurfaceFitter(std::shared_ptr<const target::Target> target, ControlMesh mesh, FeatureMap features,
                             FitOptions options) {
  if (!target) throw InvalidInputError("the surface fitter needs a target");
  checkOptions(options, mesh.numVertices());
  checkFeatureMap(features, mesh, *target);
  state_ = std::make_unique<State>(std::move(target), std::move(mesh), std::move(features), std::move(options));
  state_->tolerance = absoluteToleranceOf(state_->options, *state_->target);
}

void SurfaceFitter::setOptions(FitOptions options) {
  State& s = *state_;
  checkOptions(options, s.mesh.numVertices());
  s.options = std::move(options);
  s.tolerance = absoluteToleranceOf(s.options, *s.target);
  // Same topology, so the last projections still warm-start the next ones.
  s.samples.reset();
  s.solver.reset();
  s.destinations.clear();
  s.dropGeometry();
}

SurfaceFitter::~SurfaceFitter() = default;
SurfaceFitter::SurfaceFitter(SurfaceFitter&&) noexcept = default;
SurfaceFitter& SurfaceFitter::operator=(SurfaceFitter&&) noexcept = default;

const ControlMesh& SurfaceFitter::mesh() const { return state_->mesh; }
const FeatureMap& SurfaceFitter::features() const { return state_->features; }
const FitOptions& SurfaceFitter::options() const { return state_->options; }
int SurfaceFitter::level() const { return state_->level; }
double SurfaceFitter::absoluteTolerance() const { return state_->tolerance; }

const ControlMesh& SurfaceFitter::meshAtLevel(int level) const {
  if (level < 0 || level > state_->level) {
    throw InvalidInputError("the fit is at level " + std::to_string(state_->level) +
                            ": there is no mesh at level " + std::to_string(level));
  }
  return level == state_->level ? state_->mesh : state_->lowerLevels[static_cast<size_t>(level)];
}
const std::vector<PassRecord>& SurfaceFitter::history() const { return state_->history; }

void SurfaceFitter::setVertices(const RowMatrixX3d& vertices) {
  state_->mesh.setVertices(vertices);
  state_->dropGeometry();
}

std::string SurfaceFitter::overBudget() const {
  const State& s = *state_;
  // Catmull-Clark makes a point per vertex, edge and face.
  const long long next = static_cast<long long>(s.mesh.numVertices()) + s.mesh.numEdges() + s.mesh.numFaces();
  if (s.options.maxControlPoints == 0 || next <= s.options.maxControlPoints) return "";
  return "level " + std::to_string(s.level + 1) + " would have " + std::to_string(next) +
         " control points, more than max_control_points (" + std::to_string(s.options.maxControlPoints) +
         ", the memory budget)";
}

void SurfaceFitter::subdivide() {
  State& s = *state_;
  // Each level has 4 times the faces: a workbench's Subdivide clicked on past the fit's own
  // bound would run the document's process out of memory.
  if (s.level >= s.options.maxLevel) {
    throw InvalidInputError("the fit is at its max_level " + std::to_string(s.options.maxLevel) +
                            ": raise max_level (at most 10) to subdivide further");
  }
  if (const std::string over = overBudget(); !over.empty()) throw InvalidInputError(over);
  SubdivisionResult refined = bvmesh::subdivide(s.mesh, s.options.subdivision);
  FeatureMap features = propagateFeatures(s.features, s.mesh, refined.mesh);
  const bool parentHints = s.haveHints;
  const target::SurfaceHints parent = std::move(s.hints);
  s.lowerLevels.push_back(std::move(s.mesh));
  s.mesh = std::move(refined.mesh);
  s.features = std::move(features);
  ++s.level;
  s.dropTopology();
  if (parentHints) s.inheritHints(parent);
}

const LimitSamples& SurfaceFitter::computeLimitSamples() {
  state_->ensurePositions();
  return *state_->samples;
}

const target::ProjectionResult& SurfaceFitter::project() {
  state_->projectAll();
  return state_->projections;
}

const RowMatrixX3d& SurfaceFitter::limitPositions() {
  state_->ensurePositions();
  return state_->positions;
}

void SurfaceFitter::approximate() {
  State& s = *state_;
  s.ensureProjections();
  if (!s.solver) s.buildSolver();
  // A sample that could not be projected keeps its place: it neither pulls nor pushes.
  RowMatrixX3d targets = s.projections.points;
  for (size_t i = 0; i < s.projections.status.size(); ++i) {
    if (s.projections.status[i] == target::ProjectionStatus::Failed) {
      targets.row(static_cast<Eigen::Index>(i)) = s.positions.row(static_cast<Eigen::Index>(i));
    }
  }
  s.mesh.setVertices(s.solver->solve(targets, s.mesh.vertices()));
  ++s.correction;
  s.dropGeometry();
}

void SurfaceFitter::correctParameters(int passes) {
  if (passes < 0 || passes > kMaxCorrectionPasses) {
    throw InvalidInputError("parameter-correction passes must be 0 .. " +
                            std::to_string(kMaxCorrectionPasses) + ", got " + std::to_string(passes));
  }
  for (int pass = 0; pass < passes; ++pass) approximate();
}

void SurfaceFitter::smooth(const TaubinOptions& options) {
  State& s = *state_;
  const ControlMesh& mesh = s.mesh;
  const std::vector<std::vector<int>> vertexEdges = vertexEdgeLists(mesh);
  std::vector<bool> pinned(static_cast<size_t>(mesh.numVertices()), false);
  for (int v : mesh.corners()) pinned[static_cast<size_t>(v)] = true;
  for (int v : s.options.fixedVertices) {
    if (v >= 0 && v < mesh.numVertices()) pinned[static_cast<size_t>(v)] = true;
  }
  // Smooth vertices average all their neighbours; a vertex on exactly two crease or boundary
  // edges only those two (it slides along the feature); at feature junctions it stays.
  std::vector<std::vector<int>> neighbours(static_cast<size_t>(mesh.numVertices()));
  for (int v = 0; v < mesh.numVertices(); ++v) {
    if (pinned[static_cast<size_t>(v)]) continue;
    std::vector<int> all;
    std::vector<int> along;
    for (int edge : vertexEdges[static_cast<size_t>(v)]) {
      all.push_back(otherEnd(mesh, edge, v));
      if (isFeatureEdge(mesh, edge)) along.push_back(otherEnd(mesh, edge, v));
    }
    if (along.size() == 2) {
      neighbours[static_cast<size_t>(v)] = std::move(along);
    } else if (along.size() < 2) {
      neighbours[static_cast<size_t>(v)] = std::move(all);
    }
  }
  RowMatrixX3d smoothed = taubinSmooth(mesh.vertices(), neighbours, options);
  // Plane vertices only have plane neighbours along the boundary, so they stay on the plane up to
  // rounding; put them back exactly.
  if (s.options.symmetryPlane) {
    const Eigen::Vector3d normal = s.options.symmetryPlane->normal.normalized();
    for (int v : s.planeVertices()) {
      const double offset = (smoothed.row(v).transpose() - s.options.symmetryPlane->point).dot(normal);
      smoothed.row(v) -= offset * normal.transpose();
    }
  }
  s.mesh.setVertices(smoothed);
  s.dropGeometry();
}

TwoSidedDistance SurfaceFitter::twoSidedDistance(int samplesPerFace, int targetSubdivisions) const {
  const State& s = *state_;
  const int subdivisions = targetSubdivisions > 0 ? targetSubdivisions : s.options.checkTargetSubdivisions;
  // On an all-quad mesh ptex face f is face f, whose centre sample comes after the vertex and
  // edge samples: its last projection warm-starts the face's grid.
  if (!s.haveHints || !s.mesh.isAllQuads()) {
    return measureTwoSidedDistance(s.mesh, s.options.subdivision, *s.target, samplesPerFace, nullptr, subdivisions);
  }
  const int firstFaceSample = s.mesh.numVertices() + s.mesh.numEdges();
  target::SurfaceHints faceHints;
  faceHints.faces = s.hints.faces.segment(firstFaceSample, s.mesh.numFaces());
  faceHints.uv = s.hints.uv.middleRows(firstFaceSample, s.mesh.numFaces());
  return measureTwoSidedDistance(s.mesh, s.options.subdivision, *s.target, samplesPerFace, &faceHints, subdivisions);
}

const PassRecord& SurfaceFitter::record(bool withCheck) {
  State& s = *state_;
  s.ensureProjections();
  PassRecord record;
  record.level = s.level;
  record.correction = s.correction;
  record.controlPoints = s.mesh.numVertices();
  record.samples = s.samples->size();
  double sumSquares = 0.0;
  int measured = 0;
  for (int i = 0; i < record.samples; ++i) {
    if (s.projections.status[static_cast<size_t>(i)] == target::ProjectionStatus::Failed) {
      ++record.failedProjections;
      continue;
    }
    const double distance = (s.positions.row(i) - s.projections.points.row(i)).norm();
    record.maxDistance = std::max(record.maxDistance, distance);
    sumSquares += distance * distance;
    ++measured;
  }
  record.rmsDistance = measured > 0 ? std::sqrt(sumSquares / measured) : 0.0;
  if (withCheck && s.options.checkSamplesPerFace > 0) record.check = twoSidedDistance(s.options.checkSamplesPerFace);
  const Clock::time_point now = Clock::now();
  record.seconds = std::chrono::duration<double>(now - s.lastRecord).count();
  s.lastRecord = now;
  s.history.push_back(record);
  s.historyIsCurrent = true;
  return s.history.back();
}

const char* stopReasonName(StopReason reason) {
  switch (reason) {
    case StopReason::Converged: return "converged";
    case StopReason::Stagnated: return "stagnated";
    case StopReason::MaxLevel: return "max_level";
    case StopReason::CheckFailed: return "check_failed";
    case StopReason::Cancelled: return "cancelled";
    case StopReason::MemoryLimit: return "memory_limit";
  }
  return "max_level";
}

std::string stopDetail(StopReason reason, double tolerance, const PassRecord& last) {
  if (reason == StopReason::Converged) return "";
  if (reason == StopReason::Cancelled) return "cancelled at level " + std::to_string(last.level);
  std::ostringstream text;
  text.precision(3);
  auto at = [&](const Eigen::Vector3d& p) {
    text << " at (" << std::fixed << std::setprecision(2) << p.x() << ", " << p.y() << ", " << p.z() << ")"
         << std::defaultfloat << std::setprecision(3);
  };
  text << "at level " << last.level << ": ";
  if (last.maxDistance > tolerance) {
    text << "samples up to " << last.maxDistance << " from the target, above the tolerance " << tolerance;
  } else {
    text << "samples within the tolerance " << tolerance << " (up to " << last.maxDistance << ")";
  }
  if (last.check) {
    const TwoSidedDistance& check = *last.check;
    if (check.within(tolerance)) {
      text << "; two-sided check within it";
    } else {
      text << "; two-sided check above it:";
      if (check.limitToTarget > tolerance) {
        text << " limit -> target " << check.limitToTarget;
        at(check.limitToTargetAt);
      }
      if (check.targetToLimitBeyondCad > tolerance) {
        if (check.limitToTarget > tolerance) text << ",";
        text << " target -> limit " << check.targetToLimitBeyondCad << " beyond the CAD's own tolerance";
        at(check.targetToLimitBeyondCadAt);
      }
    }
  }
  return text.str();
}

FitSummary SurfaceFitter::run(const ProgressCallback& progress, const std::atomic<bool>* cancel) {
  State& s = *state_;
  FitSummary summary;
  summary.tolerance = s.tolerance;
  const size_t firstRecord = s.history.size();
  auto cancelled = [cancel] { return cancel != nullptr && cancel->load(); };
  auto measure = [&](bool withCheck) {
    const PassRecord& latest = record(withCheck);
    if (progress) progress(latest);
    return latest.maxDistance;
  };
  // The two-sided check of the current state (the last record), measured once.
  auto check = [&]() -> const std::optional<TwoSidedDistance>& {
    PassRecord& last = s.history.back();
    if (s.options.checkSamplesPerFace > 0 && !last.check) {
      last.check = twoSidedDistance(s.options.checkSamplesPerFace);
      if (progress) progress(last);
    }
    return last.check;
  };
  auto finish = [&](StopReason reason) {
    if (reason != StopReason::Cancelled) check();
    summary.reason = reason;
    summary.detail = stopDetail(reason, s.tolerance, s.history.back());
    summary.history.assign(s.history.begin() + static_cast<std::ptrdiff_t>(firstRecord), s.history.end());
    return summary;
  };

  s.lastRecord = Clock::now();
  // The state as given, unless the last record already measured it.
  double distance = s.historyIsCurrent ? s.history.back().maxDistance : measure(false);
  const double modelSize = s.target->report().diagonal;
  if (distance > 0.5 * modelSize) {
    throw InvalidInputError("the control polyhedron lies far from the target: its limit surface is up to " +
                            numberText(distance) + " away, for a target of size " + numberText(modelSize) +
                            "; place the polyhedron around the target first");
  }
  double previousLevelBest = distance;
  while (true) {
    // Converged only when the independent check agrees with the samples; otherwise go on.
    const bool samplesWithin = distance <= s.tolerance;
    if (samplesWithin) {
      const std::optional<TwoSidedDistance>& checked = check();
      if (!checked || checked->within(s.tolerance)) return finish(StopReason::Converged);
    }
    if (s.level >= s.options.maxLevel) return finish(samplesWithin ? StopReason::CheckFailed : StopReason::MaxLevel);
    if (cancelled()) return finish(StopReason::Cancelled);
    if (const std::string over = overBudget(); !over.empty()) {
      FitSummary stopped = finish(StopReason::MemoryLimit);
      stopped.detail += "; " + over;
      return stopped;
    }
    subdivide();
    double levelBest = std::numeric_limits<double>::infinity();
    for (int pass = 0; pass < std::max(1, s.options.maxCorrections); ++pass) {
      if (cancelled()) return finish(StopReason::Cancelled);
      approximate();
      distance = measure(false);
      const bool stalled = distance > s.options.stagnationRatio * levelBest;
      levelBest = std::min(levelBest, distance);
      if (distance <= s.tolerance || stalled) break;
    }
    if (levelBest > s.options.stagnationRatio * previousLevelBest) return finish(StopReason::Stagnated);
    previousLevelBest = levelBest;
  }
}

}  // namespace bvmesh::fit

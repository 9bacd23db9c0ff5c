#include "core/polyhedron/feature_curves.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>

#include "core/common/math_constants.h"

namespace bvmesh::polyhedron {
namespace {

struct EdgeGeometry {
  std::array<int, 2> vertices{-1, -1};
  Eigen::Vector3d startTangent = Eigen::Vector3d::Zero();  // unit, along the edge at its first vertex
  Eigen::Vector3d endTangent = Eigen::Vector3d::Zero();    // unit, along the edge at its second vertex
  double length = 0.0;
};

EdgeGeometry edgeGeometry(const target::Target& target, int edge) {
  EdgeGeometry g;
  g.vertices = target.edgeVertices(edge);
  const target::Points polyline = target.edgePolyline(edge);
  const Eigen::Index n = polyline.rows();
  if (n < 2) return g;
  g.length = target.report().shape.edges[static_cast<size_t>(edge)].length;  // exact, not the polyline's
  g.startTangent = (polyline.row(1) - polyline.row(0)).transpose().normalized();
  g.endTangent = (polyline.row(n - 1) - polyline.row(n - 2)).transpose().normalized();
  return g;
}

// One use of an edge at a vertex: the edge and whether the chain leaves the vertex along it
// forwards (the vertex is the edge's first vertex).
struct Use {
  int edge;
  bool leavesForward;
};

}  // namespace

const char* featureCurveKindName(FeatureCurveKind kind) {
  switch (kind) {
    case FeatureCurveKind::Sharp:
      return "sharp";
    case FeatureCurveKind::Boundary:
      return "boundary";
    case FeatureCurveKind::Kink:
      return "kink";
  }
  return "?";
}

std::vector<int> kinkEdges(const target::Target& target, const FeatureCurveOptions& options) {
  std::vector<int> result;
  if (!options.includeKinks) return result;
  const double tolerance =
      options.kinkTolerance > 0.0 ? options.kinkTolerance : options.relativeKinkTolerance * target.report().diagonal;
  const std::vector<cad::EdgeInfo>& edges = target.report().shape.edges;
  for (size_t e = 0; e < edges.size(); ++e) {
    const cad::EdgeInfo& info = edges[e];
    if (info.kind != cad::EdgeKind::Smooth || info.maxDihedralDegrees >= options.sharpAngleDeg) continue;
    const double miss = info.meanDihedralDegrees * kPi / 180.0 * info.length / 4.0;
    if (miss > std::max(tolerance, target.edgeTolerance(static_cast<int>(e)))) result.push_back(static_cast<int>(e));
  }
  return result;
}

std::vector<FeatureCurve> detectFeatureCurves(const target::Target& target,
                                              const FeatureCurveOptions& options) {
  std::vector<FeatureCurveKind> kindOf(static_cast<size_t>(target.edgeCount()), FeatureCurveKind::Sharp);
  std::vector<bool> isFeature(static_cast<size_t>(target.edgeCount()), false);
  std::vector<int> featureEdges = target.sharpEdges(options.sharpAngleDeg);
  if (options.includeBoundary) {
    for (int e : target.freeEdges()) {
      kindOf[static_cast<size_t>(e)] = FeatureCurveKind::Boundary;
      featureEdges.push_back(e);
    }
  }
  for (int e : kinkEdges(target, options)) {
    kindOf[static_cast<size_t>(e)] = FeatureCurveKind::Kink;
    featureEdges.push_back(e);
  }
  std::vector<EdgeGeometry> geometry(static_cast<size_t>(target.edgeCount()));
  std::vector<std::vector<Use>> uses(static_cast<size_t>(target.vertexCount()));
  for (int e : featureEdges) {
    EdgeGeometry g = edgeGeometry(target, e);
    if (g.length <= 0.0) continue;  // collapsed: nothing to follow
    isFeature[static_cast<size_t>(e)] = true;
    if (g.vertices[0] >= 0) uses[static_cast<size_t>(g.vertices[0])].push_back({e, true});
    if (g.vertices[1] >= 0) uses[static_cast<size_t>(g.vertices[1])].push_back({e, false});
    geometry[static_cast<size_t>(e)] = std::move(g);
  }
  const double cosLimit = std::cos(options.continuityAngleDeg * kPi / 180.0);

  // Vertex reached along `edge` (forwards or not); the next edge of the chain there, or none.
  struct Step {
    int vertex;
    int edge = -1;
    bool forward = true;
  };
  const auto next = [&](int edge, bool forward) {
    const EdgeGeometry& g = geometry[static_cast<size_t>(edge)];
    Step step{forward ? g.vertices[1] : g.vertices[0]};
    if (step.vertex < 0) return step;
    // The uses of this kind of feature edge: a curve goes on through a vertex where it meets one
    // more, whatever edges of the other kinds end there (a kink along a wing's leading edge
    // ending on its root or tip section, which the CAD splits there). Three or more: a junction.
    std::vector<Use> at;
    for (const Use& use : uses[static_cast<size_t>(step.vertex)]) {
      if (kindOf[static_cast<size_t>(use.edge)] == kindOf[static_cast<size_t>(edge)]) at.push_back(use);
    }
    if (at.size() != 2) return step;
    // The other use: for a closed edge both uses are the edge itself.
    const bool firstIsThis = at[0].edge == edge && at[0].leavesForward != forward;
    const Use& other = firstIsThis ? at[1] : at[0];
    const Eigen::Vector3d in = forward ? g.endTangent : Eigen::Vector3d(-g.startTangent);
    const EdgeGeometry& o = geometry[static_cast<size_t>(other.edge)];
    const Eigen::Vector3d out = other.leavesForward ? o.startTangent : Eigen::Vector3d(-o.endTangent);
    if (in.dot(out) < cosLimit) return step;
    step.edge = other.edge;
    step.forward = other.leavesForward;
    return step;
  };

  std::vector<bool> used(static_cast<size_t>(target.edgeCount()), false);
  std::vector<FeatureCurve> curves;
  for (int seed : featureEdges) {
    if (!isFeature[static_cast<size_t>(seed)] || used[static_cast<size_t>(seed)]) continue;
    used[static_cast<size_t>(seed)] = true;
    std::deque<std::pair<int, bool>> chain{{seed, true}};
    bool smoothLoop = false;
    // Forwards from the seed's end.
    for (Step step = next(seed, true);; step = next(step.edge, step.forward)) {
      if (step.edge < 0) break;
      if (step.edge == seed) {
        smoothLoop = true;
        break;
      }
      if (used[static_cast<size_t>(step.edge)]) break;
      used[static_cast<size_t>(step.edge)] = true;
      chain.emplace_back(step.edge, step.forward);
    }
    // Backwards from the seed's start (walking the reversed chain).
    if (!smoothLoop) {
      for (Step step = next(seed, false);; step = next(step.edge, step.forward)) {
        if (step.edge < 0 || used[static_cast<size_t>(step.edge)]) break;
        used[static_cast<size_t>(step.edge)] = true;
        chain.emplace_front(step.edge, !step.forward);
      }
    }
    FeatureCurve curve;
    curve.kind = kindOf[static_cast<size_t>(seed)];
    for (const auto& [edge, forward] : chain) {
      curve.edges.push_back(edge);
      curve.reversed.push_back(!forward);
      curve.length += geometry[static_cast<size_t>(edge)].length;
    }
    const EdgeGeometry& first = geometry[static_cast<size_t>(chain.front().first)];
    const EdgeGeometry& last = geometry[static_cast<size_t>(chain.back().first)];
    curve.startVertex = chain.front().second ? first.vertices[0] : first.vertices[1];
    curve.endVertex = chain.back().second ? last.vertices[1] : last.vertices[0];
    curve.closed = curve.startVertex == curve.endVertex;
    curve.smoothLoop = smoothLoop;
    curves.push_back(std::move(curve));
  }
  const auto rank = [](FeatureCurveKind kind) {
    return kind == FeatureCurveKind::Sharp ? 0 : kind == FeatureCurveKind::Boundary ? 1 : 2;
  };
  std::stable_sort(curves.begin(), curves.end(), [&](const FeatureCurve& a, const FeatureCurve& b) {
    if (a.kind != b.kind) return rank(a.kind) < rank(b.kind);
    return a.length > b.length;
  });
  return curves;
}

target::Points curvePolyline(const target::Target& target, const FeatureCurve& curve) {
  std::vector<Eigen::Vector3d> points;
  for (size_t i = 0; i < curve.edges.size(); ++i) {
    target::Points polyline = target.edgePolyline(curve.edges[i]);
    if (curve.reversed[i]) polyline = polyline.colwise().reverse().eval();
    for (Eigen::Index k = points.empty() ? 0 : 1; k < polyline.rows(); ++k)
      points.push_back(polyline.row(k).transpose());
  }
  target::Points result(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t k = 0; k < points.size(); ++k) result.row(static_cast<Eigen::Index>(k)) = points[k].transpose();
  return result;
}

}  // namespace bvmesh::polyhedron

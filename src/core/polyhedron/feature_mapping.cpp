#include "core/polyhedron/feature_mapping.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include "core/common/errors.h"
#include "core/common/math_constants.h"

namespace bvmesh::polyhedron {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

enum class EdgeRole { None, Crease, Boundary };

std::vector<EdgeRole> edgeRoles(const ControlMesh& mesh) {
  std::vector<EdgeRole> roles(static_cast<size_t>(mesh.numEdges()), EdgeRole::None);
  for (int e = 0; e < mesh.numEdges(); ++e) {
    if (mesh.isBoundaryEdge(e)) {
      roles[static_cast<size_t>(e)] = EdgeRole::Boundary;
    } else if (mesh.edgeSharpness()(e) > 0.0) {
      roles[static_cast<size_t>(e)] = EdgeRole::Crease;
    }
  }
  return roles;
}

// Feature edges at each vertex.
std::vector<std::vector<int>> vertexFeatureEdges(const ControlMesh& mesh,
                                                 const std::vector<EdgeRole>& roles) {
  std::vector<std::vector<int>> result(static_cast<size_t>(mesh.numVertices()));
  for (int e = 0; e < mesh.numEdges(); ++e) {
    if (roles[static_cast<size_t>(e)] == EdgeRole::None) continue;
    result[static_cast<size_t>(mesh.edges()(e, 0))].push_back(e);
    result[static_cast<size_t>(mesh.edges()(e, 1))].push_back(e);
  }
  return result;
}

int otherEnd(const ControlMesh& mesh, int edge, int vertex) {
  return mesh.edges()(edge, 0) == vertex ? mesh.edges()(edge, 1) : mesh.edges()(edge, 0);
}

// Direction of the polyline segment nearest to p.
Eigen::Vector3d tangentNear(const target::Points& polyline, const Eigen::Vector3d& p) {
  double best = kInfinity;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  for (Eigen::Index k = 0; k + 1 < polyline.rows(); ++k) {
    const Eigen::Vector3d a = polyline.row(k).transpose();
    const Eigen::Vector3d ab = polyline.row(k + 1).transpose() - a;
    const double length2 = ab.squaredNorm();
    if (!(length2 > 0.0)) continue;
    const double t = std::clamp((p - a).dot(ab) / length2, 0.0, 1.0);
    const double d = (a + t * ab - p).squaredNorm();
    if (d < best) {
      best = d;
      direction = ab / std::sqrt(length2);
    }
  }
  return direction;
}

// The curve edges a chain follows, in curve order, from the curve edges its samples project to.
std::vector<int> followedEdges(const FeatureCurve& curve, const std::vector<int>& hitPositions,
                               bool chainIsLoop) {
  const int n = static_cast<int>(curve.edges.size());
  std::vector<bool> hit(static_cast<size_t>(n), false);
  for (int position : hitPositions) hit[static_cast<size_t>(position)] = true;
  int first = 0;
  int count = n;
  if (!(chainIsLoop && curve.closed)) {
    if (!curve.closed) {
      const auto [lo, hi] = std::minmax_element(hitPositions.begin(), hitPositions.end());
      first = *lo;
      count = *hi - *lo + 1;
    } else {
      // Closed curve, open chain: everything but the widest circular run of edges no sample hit.
      int gapStart = 0;
      int gapLength = 0;
      for (int start = 0; start < n; ++start) {
        if (hit[static_cast<size_t>(start)] || hit[static_cast<size_t>((start + n - 1) % n)] == false)
          continue;
        int length = 0;
        while (length < n && !hit[static_cast<size_t>((start + length) % n)]) ++length;
        if (length > gapLength) {
          gapLength = length;
          gapStart = start;
        }
      }
      first = (gapStart + gapLength) % n;
      count = n - gapLength;
    }
  }
  std::vector<int> edges;
  for (int k = 0; k < count; ++k) edges.push_back(curve.edges[static_cast<size_t>((first + k) % n)]);
  return edges;
}

std::string chainName(const MeshFeatureChain& chain, int index) {
  std::ostringstream out;
  out << (chain.kind == FeatureCurveKind::Sharp ? "crease chain " : "boundary chain ") << index
      << " (vertices ";
  const size_t shown = std::min<size_t>(chain.vertices.size(), 6);
  for (size_t i = 0; i < shown; ++i) out << (i ? " " : "") << chain.vertices[i];
  if (shown < chain.vertices.size()) out << " ... " << chain.vertices.back();
  out << "; " << chain.edges.size() << " edges" << (chain.closed ? ", closed" : "") << ")";
  return out.str();
}

}  // namespace

std::vector<MeshFeatureChain> meshFeatureChains(const ControlMesh& mesh) {
  const std::vector<EdgeRole> roles = edgeRoles(mesh);
  const std::vector<std::vector<int>> atVertex = vertexFeatureEdges(mesh, roles);
  std::vector<bool> isCorner(static_cast<size_t>(mesh.numVertices()), false);
  for (int v : mesh.corners()) isCorner[static_cast<size_t>(v)] = true;
  const auto ends = [&](int v) {
    const std::vector<int>& edges = atVertex[static_cast<size_t>(v)];
    return isCorner[static_cast<size_t>(v)] || edges.size() != 2 ||
           roles[static_cast<size_t>(edges[0])] != roles[static_cast<size_t>(edges[1])];
  };
  const auto otherEdge = [&](int v, int e) {
    const std::vector<int>& edges = atVertex[static_cast<size_t>(v)];
    return edges[0] == e ? edges[1] : edges[0];
  };

  std::vector<bool> used(static_cast<size_t>(mesh.numEdges()), false);
  std::vector<MeshFeatureChain> chains;
  for (int seed = 0; seed < mesh.numEdges(); ++seed) {
    if (roles[static_cast<size_t>(seed)] == EdgeRole::None || used[static_cast<size_t>(seed)]) continue;
    used[static_cast<size_t>(seed)] = true;
    std::deque<int> vertices{mesh.edges()(seed, 0), mesh.edges()(seed, 1)};
    std::deque<int> edges{seed};
    bool closed = false;
    for (int v = vertices.back(), e = seed; !ends(v);) {
      const int next = otherEdge(v, e);
      if (next == seed) {
        closed = true;
        vertices.pop_back();
        break;
      }
      if (used[static_cast<size_t>(next)]) break;
      used[static_cast<size_t>(next)] = true;
      v = otherEnd(mesh, next, v);
      e = next;
      edges.push_back(next);
      vertices.push_back(v);
    }
    if (!closed) {
      for (int v = vertices.front(), e = seed; !ends(v);) {
        const int next = otherEdge(v, e);
        if (used[static_cast<size_t>(next)]) break;
        used[static_cast<size_t>(next)] = true;
        v = otherEnd(mesh, next, v);
        e = next;
        edges.push_front(next);
        vertices.push_front(v);
      }
    }
    MeshFeatureChain chain;
    chain.kind = roles[static_cast<size_t>(seed)] == EdgeRole::Crease ? FeatureCurveKind::Sharp
                                                                      : FeatureCurveKind::Boundary;
    chain.vertices.assign(vertices.begin(), vertices.end());
    chain.edges.assign(edges.begin(), edges.end());
    chain.closed = closed;
    chains.push_back(std::move(chain));
  }
  return chains;
}

FeatureMapping mapFeatures(const ControlMesh& mesh, const target::Target& target,
                           const std::vector<FeatureCurve>& curves, const FeatureMappingOptions& options) {
  const double diagonal = target.report().diagonal;
  const double maxDistance = options.relativeMaxDistance * diagonal;
  const int perEdge = std::max(1, options.samplesPerEdge);
  FeatureMapping result;
  result.maxDistanceLimit = maxDistance;
  result.maxAngleLimitDeg = options.maxAngleDeg;
  result.relativeChainDistance = options.relativeChainDistance;
  result.cornerDistanceLimit = options.relativeCornerDistance * diagonal;
  result.chains = meshFeatureChains(mesh);
  result.map.edgeCurve.assign(static_cast<size_t>(mesh.numEdges()), -1);
  result.map.vertexCadVertex.assign(static_cast<size_t>(mesh.numVertices()), -1);
  std::vector<target::Points> polylines;
  for (const FeatureCurve& curve : curves) polylines.push_back(curvePolyline(target, curve));

  const RowMatrixX3d& x = mesh.vertices();
  for (size_t c = 0; c < result.chains.size(); ++c) {
    const MeshFeatureChain& chain = result.chains[c];
    const size_t edgeCount = chain.edges.size();
    const size_t sampleCount = edgeCount * static_cast<size_t>(perEdge) + (chain.closed ? 0 : 1);
    target::Points samples(static_cast<Eigen::Index>(sampleCount), 3);
    target::Points tangents(static_cast<Eigen::Index>(sampleCount), 3);
    for (size_t i = 0; i < edgeCount; ++i) {
      const Eigen::Vector3d a = x.row(chain.vertices[i]).transpose();
      const Eigen::Vector3d b = x.row(chain.vertices[(i + 1) % chain.vertices.size()]).transpose();
      for (int k = 0; k < perEdge; ++k) {
        const Eigen::Index row = static_cast<Eigen::Index>(i * static_cast<size_t>(perEdge)) + k;
        samples.row(row) = (a + (b - a) * (static_cast<double>(k) / perEdge)).transpose();
        tangents.row(row) = (b - a).normalized().transpose();
      }
    }
    if (!chain.closed) {
      samples.row(samples.rows() - 1) = x.row(chain.vertices.back());
      tangents.row(tangents.rows() - 1) = tangents.row(tangents.rows() - 2);
    }

    double chainLength = 0.0;
    for (size_t i = 0; i < edgeCount; ++i) {
      chainLength +=
          (x.row(chain.vertices[i]) - x.row(chain.vertices[(i + 1) % chain.vertices.size()])).norm();
    }
    const double reach = std::max(maxDistance, options.relativeChainDistance * chainLength);

    // A candidate: one curve, or the union of several; its samples' worst distance, mean angle,
    // and per curve the positions of the curve edges the samples project to.
    struct Candidate {
      std::vector<int> curves;
      double maxDistance = kInfinity;
      double meanAngleDeg = kInfinity;
      std::map<int, std::vector<int>> hits;
    };
    const auto evaluate = [&](const std::vector<int>& candidateCurves) {
      Candidate candidate;
      candidate.curves = candidateCurves;
      std::vector<int> edges;
      std::map<int, std::pair<int, int>> edgeOwner;  // edge -> (curve, position)
      for (int k : candidateCurves) {
        const std::vector<int>& own = curves[static_cast<size_t>(k)].edges;
        for (size_t pos = 0; pos < own.size(); ++pos) edgeOwner[own[pos]] = {k, static_cast<int>(pos)};
        edges.insert(edges.end(), own.begin(), own.end());
      }
      const target::ProjectionResult feet = target.projectToEdges(samples, edges);
      double worst = 0.0;
      double angleSum = 0.0;
      for (Eigen::Index i = 0; i < samples.rows(); ++i) {
        const auto owner = edgeOwner.find(feet.ids[i]);
        if (feet.status[static_cast<size_t>(i)] == target::ProjectionStatus::Failed ||
            owner == edgeOwner.end()) {
          return candidate;  // infinitely far
        }
        worst = std::max(worst, feet.distances[i]);
        const Eigen::Vector3d along =
            tangentNear(polylines[static_cast<size_t>(owner->second.first)], feet.points.row(i).transpose());
        const double cosine = std::min(1.0, std::abs(along.dot(tangents.row(i).transpose())));
        angleSum += std::acos(cosine) * 180.0 / kPi;
        candidate.hits[owner->second.first].push_back(owner->second.second);
      }
      candidate.maxDistance = worst;
      candidate.meanAngleDeg = angleSum / static_cast<double>(samples.rows());
      return candidate;
    };
    const auto acceptable = [&](const Candidate& candidate) {
      return candidate.maxDistance <= reach && candidate.meanAngleDeg <= options.maxAngleDeg;
    };

    ChainMapping mapping;
    mapping.distanceLimit = reach;
    std::optional<Candidate> best;
    Candidate nearest;
    std::vector<int> sameKind;
    for (size_t k = 0; k < curves.size(); ++k) {
      if (curves[k].kind != chain.kind) continue;
      sameKind.push_back(static_cast<int>(k));
      const Candidate candidate = evaluate({static_cast<int>(k)});
      if (candidate.maxDistance < nearest.maxDistance) nearest = candidate;
      if (acceptable(candidate) && (!best || candidate.maxDistance < best->maxDistance)) best = candidate;
    }
    // A chain may run along several curves (e.g. across a kink of the trailing edge).
    if (!best && sameKind.size() > 1) {
      const Candidate all = evaluate(sameKind);
      if (acceptable(all)) best = all;
    }
    // A crease may lie along a kink: a blunt trailing edge's base folding by a few degrees where a
    // swept wing's halves meet, which no sharp curve takes, or a sharp one's wedge there, 4.6 mm
    // long on the full M6 and ending where the sharp root seam begins, whose end the seam's
    // candidate lies within reach of. A kink takes the chain when no sharp curve does or when it
    // lies at less than half the sharp curve's distance.
    if (chain.kind == FeatureCurveKind::Sharp) {
      std::optional<Candidate> kink;
      for (size_t k = 0; k < curves.size(); ++k) {
        if (curves[k].kind != FeatureCurveKind::Kink) continue;
        const Candidate candidate = evaluate({static_cast<int>(k)});
        if (acceptable(candidate) && (!kink || candidate.maxDistance < kink->maxDistance)) kink = candidate;
      }
      if (kink && (!best || kink->maxDistance < 0.5 * best->maxDistance)) best = kink;
    }
    // Figures of the mapped candidate, or of the nearest one for the report.
    const Candidate& shown = best ? *best : nearest;
    mapping.nearestCurve = shown.curves.empty() ? -1 : shown.curves.front();
    mapping.maxDistance = shown.maxDistance;
    mapping.meanAngleDeg = shown.meanAngleDeg;
    if (best) {
      const bool chainIsLoop = chain.closed || chain.vertices.front() == chain.vertices.back();
      size_t most = 0;
      for (const auto& [k, positions] : best->hits) {
        // In a union, a curve that catches less than one chain edge's samples is only touched
        // where it meets the followed ones (e.g. a tiny ridge at a wing tip).
        if (best->hits.size() > 1 && static_cast<int>(positions.size()) < perEdge) continue;
        const std::vector<int> part = followedEdges(curves[static_cast<size_t>(k)], positions, chainIsLoop);
        mapping.cadEdges.insert(mapping.cadEdges.end(), part.begin(), part.end());
        mapping.curves.push_back(k);
        if (positions.size() > most) {
          most = positions.size();
          mapping.curve = k;
        }
      }
    }
    if (mapping.curve >= 0) {
      std::vector<int> sorted = mapping.cadEdges;
      std::sort(sorted.begin(), sorted.end());
      for (size_t m = 0; m < result.map.curves.size() && mapping.mapCurve < 0; ++m) {
        std::vector<int> existing = result.map.curves[m];
        std::sort(existing.begin(), existing.end());
        if (existing == sorted) mapping.mapCurve = static_cast<int>(m);
      }
      if (mapping.mapCurve < 0) {
        mapping.mapCurve = static_cast<int>(result.map.curves.size());
        result.map.curves.push_back(mapping.cadEdges);
      }
      for (int e : chain.edges) result.map.edgeCurve[static_cast<size_t>(e)] = mapping.mapCurve;
    } else {
      result.unmappedChains.push_back(static_cast<int>(c));
    }
    result.chainMappings.push_back(std::move(mapping));
  }

  // Corners: explicit corners must map; vertices where chains meet map when a CAD vertex is near.
  std::vector<std::vector<int>> vertexChains(static_cast<size_t>(mesh.numVertices()));
  for (size_t c = 0; c < result.chains.size(); ++c) {
    const MeshFeatureChain& chain = result.chains[c];
    if (chain.closed) continue;
    vertexChains[static_cast<size_t>(chain.vertices.front())].push_back(static_cast<int>(c));
    vertexChains[static_cast<size_t>(chain.vertices.back())].push_back(static_cast<int>(c));
  }
  std::vector<bool> isCorner(static_cast<size_t>(mesh.numVertices()), false);
  for (int v : mesh.corners()) isCorner[static_cast<size_t>(v)] = true;
  const double cornerReach = options.relativeCornerDistance * diagonal;
  for (int v = 0; v < mesh.numVertices(); ++v) {
    const std::vector<int>& incident = vertexChains[static_cast<size_t>(v)];
    if (!isCorner[static_cast<size_t>(v)] && incident.size() < 2) continue;
    // Candidates: the end vertices of the curves the incident chains follow, else every vertex.
    std::vector<int> candidates;
    for (int c : incident) {
      const int curve = result.chainMappings[static_cast<size_t>(c)].curve;
      if (curve < 0) continue;
      candidates.push_back(curves[static_cast<size_t>(curve)].startVertex);
      candidates.push_back(curves[static_cast<size_t>(curve)].endVertex);
      for (int e : result.chainMappings[static_cast<size_t>(c)].cadEdges) {
        const std::array<int, 2> ends = target.edgeVertices(e);
        candidates.insert(candidates.end(), ends.begin(), ends.end());
      }
    }
    candidates.erase(std::remove(candidates.begin(), candidates.end(), -1), candidates.end());
    if (candidates.empty()) {
      for (int w = 0; w < target.vertexCount(); ++w) candidates.push_back(w);
    }
    CornerMapping corner;
    corner.vertex = v;
    corner.required = isCorner[static_cast<size_t>(v)];
    corner.distance = kInfinity;
    for (int w : candidates) {
      const double d = (target.vertexPosition(w) - x.row(v).transpose()).norm();
      if (d < corner.distance) {
        corner.distance = d;
        corner.nearestCadVertex = w;
      }
    }
    if (corner.distance <= cornerReach) {
      corner.cadVertex = corner.nearestCadVertex;
      result.map.vertexCadVertex[static_cast<size_t>(v)] = corner.cadVertex;
    } else if (corner.required) {
      result.unmappedCorners.push_back(static_cast<int>(result.corners.size()));
    }
    result.corners.push_back(corner);
  }
  return result;
}

std::string FeatureMapping::describeUnmapped() const {
  std::ostringstream out;
  const auto withoutSharpCurves = [&](int c) {
    return chains[static_cast<size_t>(c)].kind == FeatureCurveKind::Sharp &&
           chainMappings[static_cast<size_t>(c)].nearestCurve < 0;
  };
  const auto creaseChains = std::count_if(unmappedChains.begin(), unmappedChains.end(), withoutSharpCurves);
  if (creaseChains > 0) {
    // A body whose edges are all rounded (a filleted box) under a creased template: say what to
    // do before the list of every chain and corner.
    out << "the target has no sharp edges (all its edges are smooth, as on a filleted body) for the " << creaseChains
        << " crease chain" << (creaseChains == 1 ? "" : "s")
        << " of this polyhedron: a template without creases fits it (sphere; capsule or fuselage with round ends)\n";
  }
  for (int c : unmappedChains) {
    const ChainMapping& m = chainMappings[static_cast<size_t>(c)];
    const MeshFeatureChain& chain = chains[static_cast<size_t>(c)];
    const char* kind = chain.kind == FeatureCurveKind::Sharp ? "sharp" : "free-boundary";
    out << chainName(chain, c) << " maps to no CAD " << kind << " curve: ";
    if (m.nearestCurve < 0) {
      out << "the target has no " << kind << " curves";
    } else {
      out << "the nearest is curve " << m.nearestCurve << " at max distance " << m.maxDistance << " (limit "
          << m.distanceLimit << "), mean angle " << m.meanAngleDeg << " deg (limit " << maxAngleLimitDeg
          << ")";
    }
    out << "\n";
  }
  for (int k : unmappedCorners) {
    const CornerMapping& corner = corners[static_cast<size_t>(k)];
    out << "corner vertex " << corner.vertex << " maps to no CAD vertex: the nearest candidate is vertex "
        << corner.nearestCadVertex << " at distance " << corner.distance << " (limit " << cornerDistanceLimit
        << ")\n";
  }
  return out.str();
}

void requireComplete(const FeatureMapping& mapping) {
  if (mapping.complete()) return;
  throw InvalidInputError("unmapped polyhedron features:\n" + mapping.describeUnmapped());
}

}  // namespace bvmesh::polyhedron

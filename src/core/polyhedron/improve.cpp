#include "core/polyhedron/improve.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>

#include "core/subdiv/limit_samples.h"

namespace bvmesh::polyhedron {
namespace {

enum class Role { Smooth, Chain, Fixed };

struct VertexRoles {
  std::vector<Role> roles;                   // #V
  std::vector<std::vector<int>> neighbours;  // #V: vertices the relaxation averages
  std::vector<std::vector<int>> curveEdges;  // #V: CAD edges a chain vertex follows (empty: any feature)
  std::vector<bool> onBoundary;              // #V
};

VertexRoles classify(const ControlMesh& mesh, const fit::FeatureMap& features) {
  const int nv = mesh.numVertices();
  VertexRoles r;
  r.roles.assign(static_cast<size_t>(nv), Role::Smooth);
  r.neighbours.resize(static_cast<size_t>(nv));
  r.curveEdges.resize(static_cast<size_t>(nv));
  r.onBoundary.assign(static_cast<size_t>(nv), false);
  std::vector<std::vector<int>> all(static_cast<size_t>(nv)), feature(static_cast<size_t>(nv));
  for (int e = 0; e < mesh.numEdges(); ++e) {
    const int a = mesh.edges()(e, 0);
    const int b = mesh.edges()(e, 1);
    all[static_cast<size_t>(a)].push_back(b);
    all[static_cast<size_t>(b)].push_back(a);
    const bool boundary = mesh.isBoundaryEdge(e);
    if (!boundary && !(mesh.edgeSharpness()(e) > 0.0)) continue;
    feature[static_cast<size_t>(a)].push_back(b);
    feature[static_cast<size_t>(b)].push_back(a);
    for (int v : {a, b}) {
      if (boundary) r.onBoundary[static_cast<size_t>(v)] = true;
      const int curve = features.edgeCurve.empty() ? -1 : features.edgeCurve[static_cast<size_t>(e)];
      if (curve >= 0) {
        const std::vector<int>& chain = features.curves[static_cast<size_t>(curve)];
        r.curveEdges[static_cast<size_t>(v)].insert(r.curveEdges[static_cast<size_t>(v)].end(), chain.begin(),
                                                    chain.end());
      }
    }
  }
  std::vector<bool> corner(static_cast<size_t>(nv), false);
  for (int v : mesh.corners()) corner[static_cast<size_t>(v)] = true;
  for (int v = 0; v < nv; ++v) {
    const size_t k = static_cast<size_t>(v);
    const bool cad = !features.vertexCadVertex.empty() && features.vertexCadVertex[k] >= 0;
    if (cad || corner[k] || feature[k].size() > 2) {
      r.roles[k] = Role::Fixed;
    } else if (!feature[k].empty()) {
      r.roles[k] = Role::Chain;
      r.neighbours[k] = feature[k];
    } else {
      r.roles[k] = Role::Smooth;
      r.neighbours[k] = all[k];
    }
    std::sort(r.curveEdges[k].begin(), r.curveEdges[k].end());
    r.curveEdges[k].erase(std::unique(r.curveEdges[k].begin(), r.curveEdges[k].end()), r.curveEdges[k].end());
  }
  return r;
}

// Area-weighted vertex normals (Newell normals of the polygons).
RowMatrixX3d vertexNormals(const ControlMesh& mesh, const RowMatrixX3d& x) {
  RowMatrixX3d normals = RowMatrixX3d::Zero(mesh.numVertices(), 3);
  for (int f = 0; f < mesh.numFaces(); ++f) {
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    const int size = mesh.faceSize(f);
    for (int c = 0; c < size; ++c) {
      const Eigen::Vector3d a = x.row(mesh.faceVertex(f, c)).transpose();
      const Eigen::Vector3d b = x.row(mesh.faceVertex(f, (c + 1) % size)).transpose();
      n += a.cross(b);
    }
    for (int c = 0; c < size; ++c) normals.row(mesh.faceVertex(f, c)) += 0.5 * n.transpose();
  }
  for (Eigen::Index v = 0; v < normals.rows(); ++v) {
    const double length = normals.row(v).norm();
    if (length > 0.0) normals.row(v) /= length;
  }
  return normals;
}

// Projects points by the role of the vertex they belong to.
RowMatrixX3d projectByRole(const target::Target& target, const VertexRoles& r,
                           const fit::FeatureMap& features, const RowMatrixX3d& points) {
  RowMatrixX3d result = points;
  std::map<std::vector<int>, std::vector<int>> curveGroups;
  std::vector<int> smooth, freeBoundary, sharp;
  for (int v = 0; v < static_cast<int>(points.rows()); ++v) {
    const size_t k = static_cast<size_t>(v);
    switch (r.roles[k]) {
      case Role::Fixed: {
        const int cad = features.vertexCadVertex.empty() ? -1 : features.vertexCadVertex[k];
        if (cad >= 0) {
          result.row(v) = target.vertexPosition(cad).transpose();
        } else if (!r.curveEdges[k].empty()) {
          curveGroups[r.curveEdges[k]].push_back(v);
        }
        break;
      }
      case Role::Chain:
        if (!r.curveEdges[k].empty()) {
          curveGroups[r.curveEdges[k]].push_back(v);
        } else if (r.onBoundary[k]) {
          freeBoundary.push_back(v);
        } else {
          sharp.push_back(v);
        }
        break;
      case Role::Smooth:
        smooth.push_back(v);
        break;
    }
  }
  const auto apply = [&](const std::vector<int>& ids, auto&& project) {
    if (ids.empty()) return;
    target::Points subset(static_cast<Eigen::Index>(ids.size()), 3);
    for (size_t i = 0; i < ids.size(); ++i) subset.row(static_cast<Eigen::Index>(i)) = points.row(ids[i]);
    const target::ProjectionResult feet = project(subset);
    for (size_t i = 0; i < ids.size(); ++i) {
      if (feet.status[i] != target::ProjectionStatus::Failed)
        result.row(ids[i]) = feet.points.row(static_cast<Eigen::Index>(i));
    }
  };
  apply(smooth, [&](const target::Points& p) { return target.project(p); });
  for (const auto& [edges, ids] : curveGroups)
    apply(ids, [&](const target::Points& p) { return target.projectToEdges(p, edges); });
  if (!target.freeEdges().empty())
    apply(freeBoundary, [&](const target::Points& p) { return target.projectToFreeBoundary(p); });
  const std::vector<int> sharpEdges = target.sharpEdges(target.options().sharpAngleDeg);
  if (!sharpEdges.empty())
    apply(sharp, [&](const target::Points& p) { return target.projectToEdges(p, sharpEdges); });
  return result;
}

}  // namespace

void improvePolyhedron(ControlMesh& mesh, const target::Target& target, const fit::FeatureMap& features,
                       const ImproveOptions& options) {
  const VertexRoles roles = classify(mesh, features);
  RowMatrixX3d x = mesh.vertices();
  const auto snap = [&](RowMatrixX3d& points) {
    if (!options.symmetryPlane) return;
    const Eigen::Vector3d n = options.symmetryPlane->normal.normalized();
    const double reach = options.relativeSnapDistance * target.report().diagonal;
    for (Eigen::Index v = 0; v < points.rows(); ++v) {
      if (!roles.onBoundary[static_cast<size_t>(v)]) continue;
      const double offset = (points.row(v).transpose() - options.symmetryPlane->point).dot(n);
      if (std::abs(offset) <= reach) points.row(v) -= offset * n.transpose();
    }
  };
  // At least one pass: without relaxation it only projects and snaps.
  for (int pass = 0; pass < std::max(1, options.relaxationPasses); ++pass) {
    const RowMatrixX3d normals = vertexNormals(mesh, x);
    RowMatrixX3d relaxed = x;
    for (Eigen::Index v = 0; v < x.rows() && pass < options.relaxationPasses; ++v) {
      const size_t k = static_cast<size_t>(v);
      if (roles.roles[k] == Role::Fixed || roles.neighbours[k].empty()) continue;
      Eigen::RowVector3d average = Eigen::RowVector3d::Zero();
      for (int w : roles.neighbours[k]) average += x.row(w);
      average /= static_cast<double>(roles.neighbours[k].size());
      Eigen::RowVector3d step = options.relaxation * (average - x.row(v));
      // Smooth vertices slide in their tangent plane, chain vertices along their chain (the
      // direction between their two chain neighbours), so that projecting back cannot make them
      // jump across a thin part (e.g. from a leading edge onto the upper side).
      if (roles.roles[k] == Role::Smooth) {
        step -= step.dot(normals.row(v)) * normals.row(v);
      } else {
        const std::vector<int>& ends = roles.neighbours[k];
        const Eigen::RowVector3d along = (x.row(ends.back()) - x.row(ends.front())).normalized();
        step = step.dot(along) * along;
      }
      relaxed.row(v) += step;
    }
    x = projectByRole(target, roles, features, relaxed);
    snap(x);
  }
  if (options.pushOutPasses > 0) {
    const LimitSamples samples(mesh);
    for (int pass = 0; pass < options.pushOutPasses; ++pass) {
      const RowMatrixX3d limit = samples.positions(x).topRows(x.rows());
      const RowMatrixX3d feet = projectByRole(target, roles, features, limit);
      RowMatrixX3d moved = x + (feet - limit);
      for (Eigen::Index v = 0; v < x.rows(); ++v) {
        if (roles.roles[static_cast<size_t>(v)] == Role::Fixed && !features.vertexCadVertex.empty() &&
            features.vertexCadVertex[static_cast<size_t>(v)] >= 0) {
          moved.row(v) = x.row(v);  // corners interpolate: their limit point is the vertex itself
        }
      }
      snap(moved);
      x = moved;
    }
  }
  mesh.setVertices(x);
}

}  // namespace bvmesh::polyhedron

// Target's public projections: onto the surface, onto edge chains, onto vertices and along
// given directions, each point on the configured threads (the steps: projection_steps.h).
#include <Standard_Failure.hxx>

#include <Eigen/Dense>

#include <algorithm>
#include <cstdint>

#include "core/common/errors.h"
#include "core/common/parallel.h"
#include "core/common/input_checks.h"
#include "core/target/projection_steps.h"
#include "core/target/target.h"

namespace bvmesh::target {
namespace {

// Interleaves the bits of three 21-bit integers: nearby points get nearby keys.
std::uint64_t mortonKey(const Eigen::Vector3d& unit) {
  std::uint64_t key = 0;
  for (int k = 0; k < 3; ++k) {
    const auto cell = static_cast<std::uint64_t>(clampTo(unit[k], 0.0, 1.0) * 2097151.0);
    for (int bit = 0; bit < 21; ++bit) key |= ((cell >> bit) & 1u) << (3 * bit + k);
  }
  return key;
}

// Runs work(context, i) for every point i on the configured number of threads, each with its
// own evaluation context. Points are visited in spatial (Morton) order: consecutive points then
// fall into the same B-spline spans, whose polynomial form the surface adaptors cache. An OCCT
// failure on one point marks that point failed (work's job); any other exception stops the
// call and is rethrown.
template <class Work>
void parallelFor(const Target::Data& data, const Eigen::Ref<const Points>& points, Work&& work) {
  constexpr Eigen::Index kChunk = 64;
  const Eigen::Index count = points.rows();
  const Eigen::Vector3d lo(data.report.shape.boundsMin[0], data.report.shape.boundsMin[1], data.report.shape.boundsMin[2]);
  const Eigen::Vector3d hi(data.report.shape.boundsMax[0], data.report.shape.boundsMax[1], data.report.shape.boundsMax[2]);
  const Eigen::Vector3d extent = (hi - lo).cwiseMax(1e-300);
  std::vector<std::pair<std::uint64_t, Eigen::Index>> order(static_cast<std::size_t>(count));
  for (Eigen::Index i = 0; i < count; ++i)
    order[static_cast<std::size_t>(i)] = {mortonKey((points.row(i).transpose() - lo).cwiseQuotient(extent)), i};
  std::sort(order.begin(), order.end());
  // parallelChunks takes fewer threads when the system refuses more (resource limits).
  parallelChunks(count, kChunk, [&](std::int64_t begin, std::int64_t end) {
    std::unique_ptr<ThreadContext> context = data.acquireContext();
    for (Eigen::Index k = begin; k < end; ++k) work(*context, order[static_cast<std::size_t>(k)].second);
    data.releaseContext(std::move(context));
  }, static_cast<unsigned>(std::max(0, data.options.threads)));
}

void checkPoints(const char* function, const Eigen::Ref<const Points>& points) {
  checkFinitePoints(points, std::string(function) + ": point");
}

// Unit bisector of the adjacent faces' normals at parameter t of an edge.
Eigen::Vector3d edgeNormal(const Target::Data& data, ThreadContext& context, int edgeId, double t, int& face,
                           double& u, double& v) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  face = -1;
  for (int faceId : data.edges[static_cast<std::size_t>(edgeId)].faces) {
    const FaceData& f = data.faces[static_cast<std::size_t>(faceId)];
    for (const FaceEdgeUse& use : f.edges) {
      if (use.edge != edgeId) continue;
      const gp_Pnt2d uv = use.pcurve->Value(t);
      if (face < 0) {
        face = faceId;
        u = uv.X();
        v = uv.Y();
      }
      sum += faceNormal(f, context.surface(faceId), uv.X(), uv.Y());
      break;
    }
  }
  const double length = sum.norm();
  return length > 1e-12 ? Eigen::Vector3d(sum / length) : Eigen::Vector3d::Zero();
}

// Unit mean of the adjacent faces' normals at a vertex (taken at the ends of their edges).
Eigen::Vector3d vertexNormal(const Target::Data& data, ThreadContext& context, int vertex) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int faceId : data.vertexFaces[static_cast<std::size_t>(vertex)]) {
    const FaceData& f = data.faces[static_cast<std::size_t>(faceId)];
    for (const FaceEdgeUse& use : f.edges) {
      const EdgeData& e = data.edges[static_cast<std::size_t>(use.edge)];
      if (e.vertex0 != vertex && e.vertex1 != vertex) continue;
      const gp_Pnt2d uv = use.pcurve->Value(e.vertex0 == vertex ? e.first : e.last);
      sum += faceNormal(f, context.surface(faceId), uv.X(), uv.Y());
      break;
    }
  }
  const double length = sum.norm();
  return length > 1e-12 ? Eigen::Vector3d(sum / length) : Eigen::Vector3d::Zero();
}

void storeFoot(const Target::Data& data, ThreadContext& context, const Foot& foot, Eigen::Index i,
               ProjectionResult& result) {
  if (foot.distance < 0 || foot.face < 0) return;
  result.points.row(i) = foot.point.transpose();
  result.distances[i] = foot.distance;
  result.ids[i] = foot.face;
  result.faces[i] = foot.face;
  result.params(i, 0) = foot.u;
  result.params(i, 1) = foot.v;
  result.normals.row(i) =
      (foot.normal.isZero()
           ? faceNormal(data.faces[static_cast<std::size_t>(foot.face)], context.surface(foot.face), foot.u, foot.v)
           : foot.normal)
          .transpose();
  result.status[static_cast<std::size_t>(i)] = foot.status;
}

}  // namespace

ProjectionResult Target::project(const Eigen::Ref<const Points>& points, const SurfaceHints* hints) const {
  checkPoints("Target::project", points);
  const Eigen::Index count = points.rows();
  if (hints != nullptr) {
    if (hints->faces.size() != count || hints->uv.rows() != count)
      throw InvalidInputError("Target::project: hints for " + std::to_string(hints->faces.size()) + " faces and " +
                              std::to_string(hints->uv.rows()) + " (u, v) pairs, expected " + std::to_string(count));
    for (Eigen::Index i = 0; i < count; ++i) {
      if (hints->faces[i] >= faceCount() || hints->faces[i] < -1)
        throw InvalidInputError("Target::project: hint face " + std::to_string(hints->faces[i]) + " of point " +
                                std::to_string(i) + " does not exist (" + std::to_string(faceCount()) + " faces)");
      if (hints->faces[i] >= 0 && !hints->uv.row(i).allFinite())
        throw InvalidInputError("Target::project: hint (u, v) of point " + std::to_string(i) + " is not finite");
    }
  }
  ProjectionResult result;
  result.resize(count);
  parallelFor(*data_, points, [&](ThreadContext& context, Eigen::Index i) {
    const Eigen::Vector3d q = points.row(i).transpose();
    const int hint = hints != nullptr ? hints->faces[i] : -1;
    try {
      const Foot foot = closestOnSurface(*data_, context, q, hint, hint >= 0 ? hints->uv(i, 0) : 0.0,
                                         hint >= 0 ? hints->uv(i, 1) : 0.0);
      storeFoot(*data_, context, foot, i, result);
    } catch (const Standard_Failure&) {
      // Left as Failed: the kernel could not evaluate this point.
    }
    if (result.status[static_cast<std::size_t>(i)] == ProjectionStatus::Failed) result.points.row(i) = q.transpose();
  });
  return result;
}

ProjectionResult Target::projectToEdges(const Eigen::Ref<const Points>& points, const std::vector<int>& edges) const {
  checkPoints("Target::projectToEdges", points);
  if (edges.empty()) throw InvalidInputError("Target::projectToEdges: no edges given");
  std::vector<Box3> boxes;
  std::vector<int> boxEdge;
  for (int id : edges) {
    if (id < 0 || id >= edgeCount())
      throw InvalidInputError("Target::projectToEdges: edge " + std::to_string(id) + " does not exist (" +
                              std::to_string(edgeCount()) + " edges)");
    const EdgeData& e = data_->edges[static_cast<std::size_t>(id)];
    if (e.degenerate) throw InvalidInputError("Target::projectToEdges: edge " + std::to_string(id) + " is degenerate");
    Box3 box;
    for (const Eigen::Vector3d& p : e.polyline) box.extend(p);
    boxes.push_back(box);
    boxEdge.push_back(id);
  }
  // The polyline lies within the deflection of its curve: grow the boxes by the margin.
  for (Box3& box : boxes) {
    box.lo.array() -= data_->margin;
    box.hi.array() += data_->margin;
  }
  ProjectionResult result;
  result.resize(points.rows());
  parallelFor(*data_, points, [&](ThreadContext& context, Eigen::Index i) {
    const Eigen::Vector3d q = points.row(i).transpose();
    try {
      // Nearest boxes first; a box farther than the best foot cannot hold a nearer point.
      std::vector<std::pair<double, std::size_t>> order(boxes.size());
      for (std::size_t b = 0; b < boxes.size(); ++b) order[b] = {boxes[b].squaredDistance(q), b};
      std::sort(order.begin(), order.end());
      Foot best;
      for (const auto& [boxSquared, b] : order) {
        if (best.distance >= 0 && boxSquared > best.distance * best.distance) break;
        const Foot foot = closestOnEdge(*data_, context, boxEdge[b], q, best.distance);
        if (foot.distance >= 0 && (best.distance < 0 || foot.distance < best.distance)) best = foot;
      }
      if (best.distance >= 0) {
        int face = -1;
        double u = 0, v = 0;
        const Eigen::Vector3d normal = edgeNormal(*data_, context, best.edge, best.t, face, u, v);
        result.points.row(i) = best.point.transpose();
        result.distances[i] = best.distance;
        result.ids[i] = best.edge;
        result.faces[i] = face;
        result.params(i, 0) = best.t;
        result.normals.row(i) = normal.transpose();
        result.status[static_cast<std::size_t>(i)] = ProjectionStatus::Ok;
      }
    } catch (const Standard_Failure&) {
      // Left as Failed.
    }
    if (result.status[static_cast<std::size_t>(i)] == ProjectionStatus::Failed) result.points.row(i) = q.transpose();
  });
  return result;
}

ProjectionResult Target::projectToFreeBoundary(const Eigen::Ref<const Points>& points) const {
  if (data_->report.freeEdges.empty()) {
    checkPoints("Target::projectToFreeBoundary", points);
    ProjectionResult result;
    result.resize(points.rows());
    result.points = points;
    return result;
  }
  return projectToEdges(points, data_->report.freeEdges);
}

ProjectionResult Target::projectToVertices(const Eigen::Ref<const Points>& points, const std::vector<int>& vertices) const {
  checkPoints("Target::projectToVertices", points);
  if (vertices.empty()) throw InvalidInputError("Target::projectToVertices: no vertices given");
  for (int id : vertices)
    if (id < 0 || id >= vertexCount())
      throw InvalidInputError("Target::projectToVertices: vertex " + std::to_string(id) + " does not exist (" +
                              std::to_string(vertexCount()) + " vertices)");
  ProjectionResult result;
  result.resize(points.rows());
  parallelFor(*data_, points, [&](ThreadContext& context, Eigen::Index i) {
    const Eigen::Vector3d q = points.row(i).transpose();
    int best = vertices.front();
    for (int id : vertices)
      if ((data_->vertices[static_cast<std::size_t>(id)] - q).squaredNorm() <
          (data_->vertices[static_cast<std::size_t>(best)] - q).squaredNorm())
        best = id;
    const Eigen::Vector3d& p = data_->vertices[static_cast<std::size_t>(best)];
    result.points.row(i) = p.transpose();
    result.distances[i] = (p - q).norm();
    result.ids[i] = best;
    try {
      result.normals.row(i) = vertexNormal(*data_, context, best).transpose();
    } catch (const Standard_Failure&) {
      result.normals.row(i).setZero();
    }
    result.status[static_cast<std::size_t>(i)] = ProjectionStatus::Ok;
  });
  return result;
}

ProjectionResult Target::projectAlong(const Eigen::Ref<const Points>& points, const Eigen::Ref<const Points>& directions) const {
  checkPoints("Target::projectAlong", points);
  if (directions.rows() != points.rows())
    throw InvalidInputError("Target::projectAlong: " + std::to_string(directions.rows()) + " directions for " +
                            std::to_string(points.rows()) + " points");
  for (Eigen::Index i = 0; i < directions.rows(); ++i)
    if (!directions.row(i).allFinite() || !(directions.row(i).norm() > 0))
      throw InvalidInputError("Target::projectAlong: direction " + std::to_string(i) + " is zero or not finite");
  ProjectionResult result;
  result.resize(points.rows());
  parallelFor(*data_, points, [&](ThreadContext& context, Eigen::Index i) {
    const Eigen::Vector3d q = points.row(i).transpose();
    try {
      storeFoot(*data_, context, alongLine(*data_, context, q, directions.row(i).transpose()), i, result);
    } catch (const Standard_Failure&) {
      // Left as Failed.
    }
    if (result.status[static_cast<std::size_t>(i)] == ProjectionStatus::Failed) result.points.row(i) = q.transpose();
  });
  return result;
}

}  // namespace bvmesh::target

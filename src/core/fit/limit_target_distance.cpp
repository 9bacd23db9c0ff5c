#include "core/fit/limit_target_distance.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/common/closest_point.h"
#include "core/common/errors.h"
#include "core/subdiv/limit_evaluator.h"
#include "core/target/aabb_tree.h"

namespace bvmesh::fit {

TwoSidedDistance measureTwoSidedDistance(const ControlMesh& mesh, const SubdivisionOptions& options,
                                         const target::Target& target, int samplesPerFace,
                                         const target::SurfaceHints* faceHints, int targetSubdivisions) {
  if (samplesPerFace < 1) {
    throw InvalidInputError("the distance check needs at least 1 sample per face, got " + std::to_string(samplesPerFace));
  }
  const int n = samplesPerFace;
  const LimitEvaluator evaluator(mesh, options);
  const int faces = evaluator.numPtexFaces();
  const int perFace = (n + 1) * (n + 1);
  std::vector<SurfaceLocation> locations;
  locations.reserve(static_cast<size_t>(faces) * static_cast<size_t>(perFace));
  for (int face = 0; face < faces; ++face) {
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i <= n; ++i) locations.push_back({face, static_cast<double>(i) / n, static_cast<double>(j) / n});
    }
  }
  const RowMatrixX3d grid = evaluator.evaluate(mesh.vertices(), locations).positions;

  TwoSidedDistance result;
  target::SurfaceHints gridHints;
  if (faceHints != nullptr) {
    if (faceHints->faces.size() != faces) {
      throw InvalidInputError("got " + std::to_string(faceHints->faces.size()) + " face hints for " +
                              std::to_string(faces) + " ptex faces");
    }
    gridHints.faces.resize(grid.rows());
    gridHints.uv.resize(grid.rows(), 2);
    for (Eigen::Index i = 0; i < grid.rows(); ++i) {
      gridHints.faces[i] = faceHints->faces[i / perFace];
      gridHints.uv.row(i) = faceHints->uv.row(i / perFace);
    }
  }
  const target::ProjectionResult onTarget = target.project(grid, faceHints != nullptr ? &gridHints : nullptr);
  for (Eigen::Index i = 0; i < onTarget.distances.size(); ++i) {
    if (onTarget.status[static_cast<size_t>(i)] != target::ProjectionStatus::Failed &&
        onTarget.distances[i] > result.limitToTarget) {
      result.limitToTarget = onTarget.distances[i];
      result.limitToTargetAt = grid.row(i).transpose();
    }
  }

  // Two triangles per grid cell.
  std::vector<Eigen::Vector3i> triangles;
  triangles.reserve(static_cast<size_t>(faces) * static_cast<size_t>(2 * n * n));
  for (int face = 0; face < faces; ++face) {
    const int base = face * perFace;
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const int a = base + j * (n + 1) + i;
        triangles.emplace_back(a, a + 1, a + n + 2);
        triangles.emplace_back(a, a + n + 2, a + n + 1);
      }
    }
  }
  std::vector<target::Box3> boxes(triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) boxes[t].extend(grid.row(triangles[t][k]).transpose());
  }
  const target::AabbTree tree(std::move(boxes));
  auto squaredDistance = [&](int t, const Eigen::Vector3d& p) {
    const Eigen::Vector3i& tri = triangles[static_cast<size_t>(t)];
    return (closestPointOnTriangle(p, grid.row(tri[0]).transpose(), grid.row(tri[1]).transpose(),
                                   grid.row(tri[2]).transpose()) - p).squaredNorm();
  };
  const target::SurfaceSamples samples = target.surfaceSamples(targetSubdivisions);
  const target::Points& nodes = samples.points;
  const Eigen::VectorXd& cadTolerance = samples.tolerances;
  result.targetPoints = static_cast<int>(nodes.rows());
  for (Eigen::Index i = 0; i < nodes.rows(); ++i) {
    double best = 0.0;
    tree.nearest(nodes.row(i).transpose(), squaredDistance, best);
    const double distance = std::sqrt(best);
    if (distance > result.targetToLimit) {
      result.targetToLimit = distance;
      result.targetToLimitAt = nodes.row(i).transpose();
      result.cadToleranceAtTargetToLimit = cadTolerance[i];
    }
    if (distance - cadTolerance[i] > result.targetToLimitBeyondCad) {
      result.targetToLimitBeyondCad = distance - cadTolerance[i];
      result.targetToLimitBeyondCadAt = nodes.row(i).transpose();
    }
  }
  return result;
}

}  // namespace bvmesh::fit

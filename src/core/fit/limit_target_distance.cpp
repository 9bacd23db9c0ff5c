#include "core/fit/limit_target_distance.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <string>

#include "core/common/closest_point.h"
#include "core/common/errors.h"
#include "core/common/parallel.h"
#include "core/subdiv/limit_evaluator.h"
#include "core/target/aabb_tree.h"

namespace bvmesh::fit {
namespace {

// The limit surface evaluated on an (n+1) x (n+1) grid per ptex face, two triangles per grid cell.
class LimitTessellation {
 public:
  LimitTessellation(const LimitEvaluator& evaluator, const RowMatrixX3d& controlPoints, int n) : n_(n) {
    const int faces = evaluator.numPtexFaces();
    std::vector<SurfaceLocation> locations;
    locations.reserve(static_cast<size_t>(faces) * static_cast<size_t>(perFace()));
    for (int face = 0; face < faces; ++face) {
      for (int j = 0; j <= n; ++j) {
        for (int i = 0; i <= n; ++i)
          locations.push_back({face, static_cast<double>(i) / n, static_cast<double>(j) / n});
      }
    }
    points_ = evaluator.evaluate(controlPoints, locations).positions;
    std::vector<target::Box3> boxes(static_cast<size_t>(faces) * static_cast<size_t>(2 * n * n));
    for (int t = 0; t < static_cast<int>(boxes.size()); ++t) {
      const Eigen::Vector3i corners = triangle(t);
      for (int k = 0; k < 3; ++k) boxes[static_cast<size_t>(t)].extend(points_.row(corners[k]).transpose());
    }
    tree_ = target::AabbTree(std::move(boxes));
  }

  int perFace() const { return (n_ + 1) * (n_ + 1); }
  int ptexFaceOf(int triangle) const { return triangle / (2 * n_ * n_); }
  const RowMatrixX3d& points() const { return points_; }
  const target::AabbTree& tree() const { return tree_; }

  // Grid point ids of triangle t: cell (i, j) of its ptex face split along its diagonal.
  Eigen::Vector3i triangle(int t) const {
    const int cell = t / 2;
    const int face = ptexFaceOf(t);
    const int i = cell % n_;
    const int j = (cell / n_) % n_;
    const int a = face * perFace() + j * (n_ + 1) + i;
    return t % 2 == 0 ? Eigen::Vector3i(a, a + 1, a + n_ + 2) : Eigen::Vector3i(a, a + n_ + 2, a + n_ + 1);
  }

  TriangleFoot closestFoot(int t, const Eigen::Vector3d& p) const {
    const Eigen::Vector3i c = triangle(t);
    return closestFootOnTriangle(p, corner(c[0]), corner(c[1]), corner(c[2]));
  }

  // The surface location whose grid parameters interpolate those of triangle t's corners with
  // the given barycentric weights.
  SurfaceLocation location(int t, const Eigen::Vector3d& weights) const {
    const Eigen::Vector3i c = triangle(t);
    SurfaceLocation result{c[0] / perFace(), 0.0, 0.0};
    for (int k = 0; k < 3; ++k) {
      const int local = c[k] % perFace();
      result.u += weights[k] * static_cast<double>(local % (n_ + 1)) / n_;
      result.v += weights[k] * static_cast<double>(local / (n_ + 1)) / n_;
    }
    result.u = std::clamp(result.u, 0.0, 1.0);
    result.v = std::clamp(result.v, 0.0, 1.0);
    return result;
  }

  // How far the triangles stray from the surface: the largest distance of a grid cell's centre
  // on the limit surface from that cell's two triangles (where a bicubic patch departs most from
  // its chords).
  double chordalDeviation(const LimitEvaluator& evaluator, const RowMatrixX3d& controlPoints) const {
    const int faces = static_cast<int>(points_.rows()) / perFace();
    std::vector<SurfaceLocation> centres;
    centres.reserve(static_cast<size_t>(faces) * static_cast<size_t>(n_ * n_));
    for (int face = 0; face < faces; ++face) {
      for (int j = 0; j < n_; ++j) {
        for (int i = 0; i < n_; ++i) centres.push_back({face, (i + 0.5) / n_, (j + 0.5) / n_});
      }
    }
    const RowMatrixX3d onSurface = evaluator.evaluate(controlPoints, centres).positions;
    double deviation = 0.0;
    for (Eigen::Index cell = 0; cell < onSurface.rows(); ++cell) {
      const Eigen::Vector3d p = onSurface.row(cell).transpose();
      const int t = 2 * static_cast<int>(cell);
      const double toTriangles =
          std::min((closestFoot(t, p).point - p).norm(), (closestFoot(t + 1, p).point - p).norm());
      deviation = std::max(deviation, toTriangles);
    }
    return deviation;
  }

 private:
  Eigen::Vector3d corner(int id) const { return points_.row(id).transpose(); }

  int n_;
  RowMatrixX3d points_;
  target::AabbTree tree_;
};

// Gauss-Newton steps on the limit surface per start location (clamped to its ptex face), from
// which the nearest surface point seen to the start's target point is kept: its distance is a
// true distance to the surface, without the tessellation's chordal error.
constexpr int kSurfaceNewtonSteps = 8;

Eigen::VectorXd distancesOnSurface(const LimitEvaluator& evaluator, const RowMatrixX3d& controlPoints,
                                   std::vector<SurfaceLocation> starts, const RowMatrixX3d& targets) {
  Eigen::VectorXd best = Eigen::VectorXd::Constant(targets.rows(), std::numeric_limits<double>::infinity());
  for (int step = 0; step <= kSurfaceNewtonSteps; ++step) {
    const LimitEvaluation at = evaluator.evaluate(controlPoints, starts);
    for (Eigen::Index k = 0; k < targets.rows(); ++k) {
      const Eigen::Vector3d residual = (targets.row(k) - at.positions.row(k)).transpose();
      best[k] = std::min(best[k], residual.norm());
      const Eigen::Vector3d du = at.derivativesU.row(k).transpose();
      const Eigen::Vector3d dv = at.derivativesV.row(k).transpose();
      Eigen::Matrix2d normal;
      normal << du.dot(du), du.dot(dv), du.dot(dv), dv.dot(dv);
      // A little damping where du and dv are parallel (a limit surface's cone points).
      normal.diagonal().array() += 1e-12 * normal.trace() + 1e-300;
      Eigen::Vector2d move = normal.ldlt().solve(Eigen::Vector2d(du.dot(residual), dv.dot(residual)));
      // At most half a face per step: a Gauss-Newton step far out has left the quadratic model.
      if (const double length = move.lpNorm<Eigen::Infinity>(); length > 0.5) move *= 0.5 / length;
      SurfaceLocation& location = starts[static_cast<size_t>(k)];
      location.u = std::clamp(location.u + move[0], 0.0, 1.0);
      location.v = std::clamp(location.v + move[1], 0.0, 1.0);
    }
  }
  return best;
}

}  // namespace

TwoSidedDistance measureTwoSidedDistance(const ControlMesh& mesh, const SubdivisionOptions& options,
                                         const target::Target& target, int samplesPerFace,
                                         const target::SurfaceHints* faceHints, int targetSubdivisions) {
  if (samplesPerFace < 1) {
    throw InvalidInputError("the distance check needs at least 1 sample per face, got " +
                            std::to_string(samplesPerFace));
  }
  const LimitEvaluator evaluator(mesh, options);
  const int faces = evaluator.numPtexFaces();
  const LimitTessellation tessellation(evaluator, mesh.vertices(), samplesPerFace);
  const RowMatrixX3d& grid = tessellation.points();
  const int perFace = tessellation.perFace();

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

  // Target side: each point's distance to the tessellation first, which is within the chordal
  // deviation c of its distance to the surface. Only points whose distance could still raise a
  // maximum (tessellation distance + c above the best known lower bound) are measured on the
  // surface itself, from every ptex face with a triangle within their tessellation distance + 2c.
  const target::SurfaceSamples samples = target.surfaceSamples(targetSubdivisions);
  const target::Points& nodes = samples.points;
  const Eigen::VectorXd& cadTolerance = samples.tolerances;
  result.targetPoints = static_cast<int>(nodes.rows());
  if (nodes.rows() == 0) return result;
  const double chordal = tessellation.chordalDeviation(evaluator, mesh.vertices());
  Eigen::VectorXd onTessellation(nodes.rows());
  std::vector<int> nearestTriangle(static_cast<size_t>(nodes.rows()));
  parallelChunks(nodes.rows(), 1024, [&](std::int64_t begin, std::int64_t end) {
    for (auto i = static_cast<Eigen::Index>(begin); i < end; ++i) {
      double best = 0.0;
      nearestTriangle[static_cast<size_t>(i)] = tessellation.tree().nearest(
          nodes.row(i).transpose(),
          [&](int t, const Eigen::Vector3d& p) {
            return (tessellation.closestFoot(t, p).point - p).squaredNorm();
          },
          best);
      onTessellation[i] = std::sqrt(best);
    }
  });

  Eigen::VectorXd exact = Eigen::VectorXd::Constant(nodes.rows(), -1.0);  // -1: not measured on the surface
  auto measureExactly = [&](const std::vector<Eigen::Index>& batch) {
    std::vector<SurfaceLocation> starts;
    std::vector<Eigen::Index> owners;
    for (Eigen::Index i : batch) {
      const Eigen::Vector3d p = nodes.row(i).transpose();
      std::map<int, std::pair<double, SurfaceLocation>> nearestPerFace;
      // Triangle t's foot, kept as its face's start where it is the nearest of that face's
      // triangles and within `reach`.
      auto consider = [&](int t, double reach) {
        const TriangleFoot foot = tessellation.closestFoot(t, p);
        const double distance = (foot.point - p).norm();
        if (distance > reach) return;
        const int face = tessellation.ptexFaceOf(t);
        auto found = nearestPerFace.find(face);
        if (found == nearestPerFace.end() || distance < found->second.first) {
          nearestPerFace[face] = {distance, tessellation.location(t, foot.weights)};
        }
      };
      consider(nearestTriangle[static_cast<size_t>(i)], std::numeric_limits<double>::infinity());
      const double reach = onTessellation[i] + 2.0 * chordal;
      tessellation.tree().withinRadius(p, reach, [&](int t) { consider(t, reach); });
      for (const auto& [face, start] : nearestPerFace) {
        starts.push_back(start.second);
        owners.push_back(i);
      }
    }
    RowMatrixX3d targets(static_cast<Eigen::Index>(owners.size()), 3);
    for (size_t k = 0; k < owners.size(); ++k)
      targets.row(static_cast<Eigen::Index>(k)) = nodes.row(owners[k]);
    const Eigen::VectorXd distances =
        distancesOnSurface(evaluator, mesh.vertices(), std::move(starts), targets);
    for (Eigen::Index i : batch) exact[i] = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < owners.size(); ++k) {
      exact[owners[k]] = std::min(exact[owners[k]], distances[static_cast<Eigen::Index>(k)]);
    }
  };
  // The largest exact distance less a per-point offset, and its point: the points in order of
  // their upper bound, measured in batches until no bound is above the best value measured (nor
  // the best lower bound).
  auto maximum = [&](const Eigen::VectorXd& offsets, Eigen::Index& at) {
    std::vector<Eigen::Index> order(static_cast<size_t>(nodes.rows()));
    std::iota(order.begin(), order.end(), Eigen::Index{0});
    const Eigen::VectorXd upper = onTessellation.array() + chordal - offsets.array();
    std::sort(order.begin(), order.end(),
              [&](Eigen::Index a, Eigen::Index b) { return upper[a] > upper[b]; });
    const double lower = (onTessellation.array() - chordal - offsets.array()).maxCoeff();
    double best = -std::numeric_limits<double>::infinity();
    at = -1;
    constexpr size_t kBatch = 512;
    for (size_t first = 0;
         first < order.size() && (first == 0 || upper[order[first]] > std::max(lower, best));
         first += kBatch) {
      const size_t last = std::min(order.size(), first + kBatch);
      std::vector<Eigen::Index> batch;
      for (size_t k = first; k < last; ++k) {
        if (exact[order[k]] < 0.0) batch.push_back(order[k]);
      }
      if (!batch.empty()) measureExactly(batch);
      for (size_t k = first; k < last; ++k) {
        if (exact[order[k]] - offsets[order[k]] > best) {
          best = exact[order[k]] - offsets[order[k]];
          at = order[k];
        }
      }
    }
    return std::max(0.0, best);
  };
  Eigen::Index at = -1;
  result.targetToLimit = maximum(Eigen::VectorXd::Zero(nodes.rows()), at);
  if (at >= 0) {
    result.targetToLimitAt = nodes.row(at).transpose();
    result.cadToleranceAtTargetToLimit = cadTolerance[at];
  }
  result.targetToLimitBeyondCad = maximum(cadTolerance, at);
  if (at >= 0) result.targetToLimitBeyondCadAt = nodes.row(at).transpose();
  return result;
}

}  // namespace bvmesh::fit

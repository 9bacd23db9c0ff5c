#include "core/surface/limit_points.h"

#include <cmath>
#include <string>

#include "core/common/errors.h"

namespace bvmesh::surface {

ControlMesh toControlMesh(const QuadControlMesh& mesh) {
  const auto faceCount = static_cast<size_t>(mesh.faces.rows());
  std::vector<int> faceIndices(mesh.faces.data(), mesh.faces.data() + 4 * faceCount);
  return ControlMesh(mesh.vertices, std::vector<int>(faceCount, 4), std::move(faceIndices), mesh.creases,
                     Eigen::VectorXd(), mesh.corners);
}

QuadControlMesh toQuadControlMesh(const ControlMesh& mesh) {
  QuadControlMesh quads;
  quads.vertices = mesh.vertices();
  quads.faces.resize(mesh.numFaces(), 4);
  for (int f = 0; f < mesh.numFaces(); ++f) {
    if (mesh.faceSize(f) != 4) {
      throw InvalidInputError("face " + std::to_string(f) + " has " + std::to_string(mesh.faceSize(f)) +
                              " vertices; the B-spline conversion needs quads (subdivide once)");
    }
    for (int k = 0; k < 4; ++k) quads.faces(f, k) = mesh.faceVertex(f, k);
  }
  for (Eigen::Index c = 0; c < mesh.creaseSharpness().size(); ++c) {
    if (!std::isinf(mesh.creaseSharpness()(c))) {
      throw InvalidInputError("crease " + std::to_string(c) +
                              " is semi-sharp; only infinitely sharp creases " + "can be chart borders");
    }
  }
  for (Eigen::Index c = 0; c < mesh.cornerSharpness().size(); ++c) {
    if (!std::isinf(mesh.cornerSharpness()(c))) {
      throw InvalidInputError("corner " + std::to_string(c) +
                              " is semi-sharp; only infinitely sharp corners " + "are supported");
    }
  }
  quads.creases = mesh.creases();
  quads.corners = mesh.corners();
  return quads;
}

LimitPointsFunction limitPoints(const LimitEvaluator& evaluator, const RowMatrixX3d& controlPoints) {
  return [&evaluator, &controlPoints](const std::vector<SurfaceLocation>& locations, RowMatrixX3d& points,
                                      RowMatrixX3d* normals) {
    LimitEvaluation evaluation = evaluator.evaluate(controlPoints, locations);
    points = std::move(evaluation.positions);
    if (normals != nullptr) *normals = std::move(evaluation.normals);
  };
}

}  // namespace bvmesh::surface

#include "core/subdiv/surface_location.h"

#include <array>

namespace bvmesh {
namespace {

constexpr std::array<std::array<double, 2>, 4> kQuadCorners{{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};

int ptexFace(const std::vector<int>& ptexOffsets, int face) {
  return ptexOffsets[static_cast<size_t>(face)];
}

}  // namespace

std::vector<int> ptexFaceOffsets(const ControlMesh& mesh) {
  std::vector<int> offsets(static_cast<size_t>(mesh.numFaces()) + 1, 0);
  for (int f = 0; f < mesh.numFaces(); ++f) {
    const int size = mesh.faceSize(f);
    offsets[static_cast<size_t>(f) + 1] = offsets[static_cast<size_t>(f)] + (size == 4 ? 1 : size);
  }
  return offsets;
}

SurfaceLocation cornerLocation(const ControlMesh& mesh, const std::vector<int>& ptexOffsets,
                               int face, int corner) {
  if (mesh.faceSize(face) != 4) return {ptexFace(ptexOffsets, face) + corner, 0.0, 0.0};
  const auto& uv = kQuadCorners[static_cast<size_t>(corner)];
  return {ptexFace(ptexOffsets, face), uv[0], uv[1]};
}

SurfaceLocation edgeMidpointLocation(const ControlMesh& mesh, const std::vector<int>& ptexOffsets,
                                     int face, int corner) {
  if (mesh.faceSize(face) != 4) return {ptexFace(ptexOffsets, face) + corner, 1.0, 0.0};
  const auto& a = kQuadCorners[static_cast<size_t>(corner)];
  const auto& b = kQuadCorners[static_cast<size_t>((corner + 1) % 4)];
  return {ptexFace(ptexOffsets, face), 0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])};
}

SurfaceLocation faceCentreLocation(const ControlMesh& mesh, const std::vector<int>& ptexOffsets,
                                   int face) {
  if (mesh.faceSize(face) != 4) return {ptexFace(ptexOffsets, face), 1.0, 1.0};
  return {ptexFace(ptexOffsets, face), 0.5, 0.5};
}

}  // namespace bvmesh

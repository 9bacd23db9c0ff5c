// The byte layout fuzz_control_mesh decodes into ControlMesh's raw arrays, and its encoder (for
// the seed corpus). Every byte string decodes (missing bytes read as 0):
//   u8 #V, #V x 3 coordinate bytes        b <= 250: (b - 125) / 4; 251..255: NaN, inf, -inf,
//                                          1e300, 1e-300
//   u8 #F, #F face sizes (id bytes)        u8 #I, #I face indices (id bytes)
//   u8 #C, #C x 2 crease ids (id bytes)    u8 #S, #S sharpness bytes (coordinate bytes / 4)
//   u8 #K, #K corner ids (id bytes)        u8 #T, #T sharpness bytes
// An id byte is an int8; -128 and 127 stand for INT_MIN and INT_MAX.
#pragma once

#include <climits>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/mesh/control_mesh.h"

namespace bvmesh::fuzz {

struct RawMesh {
  RowMatrixX3d vertices;
  std::vector<int> faceSizes, faceIndices, corners;
  RowMatrixX2i creases;
  Eigen::VectorXd creaseSharpness, cornerSharpness;
};

class RawMeshDecoder {
public:
  RawMeshDecoder(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  RawMesh decode() {
    RawMesh mesh;
    mesh.vertices.resize(byte(), 3);
    for (Eigen::Index i = 0; i < mesh.vertices.size(); ++i) mesh.vertices.data()[i] = coordinate();
    mesh.faceSizes = ids(byte());
    mesh.faceIndices = ids(byte());
    const std::vector<int> creaseIds = ids(2 * byte());
    mesh.creases.resize(static_cast<Eigen::Index>(creaseIds.size() / 2), 2);
    for (size_t i = 0; i < creaseIds.size(); ++i) mesh.creases.data()[i] = creaseIds[i];
    mesh.creaseSharpness = sharpness(byte());
    mesh.corners = ids(byte());
    mesh.cornerSharpness = sharpness(byte());
    return mesh;
  }

  static double coordinateOf(uint8_t b) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const double special[] = {std::numeric_limits<double>::quiet_NaN(), kInf, -kInf, 1e300, 1e-300};
    return b <= 250 ? (b - 125) / 4.0 : special[b - 251];
  }
  static int idOf(uint8_t b) {
    const int value = static_cast<int8_t>(b);
    return value == -128 ? INT_MIN : value == 127 ? INT_MAX : value;
  }

private:
  uint8_t byte() { return offset_ < size_ ? data_[offset_++] : 0; }
  double coordinate() { return coordinateOf(byte()); }
  std::vector<int> ids(int count) {
    std::vector<int> result;
    for (int i = 0; i < count; ++i) result.push_back(idOf(byte()));
    return result;
  }
  Eigen::VectorXd sharpness(int count) {
    Eigen::VectorXd result(count);
    for (int i = 0; i < count; ++i) result(i) = coordinate() / 4.0;
    return result;
  }

  const uint8_t* data_;
  size_t size_;
  size_t offset_ = 0;
};

// Bytes that decode to `mesh` when its coordinates are multiples of 1/4 in -31.25 .. 31.25, its
// ids in -127 .. 126 and its counts below 256 (the seed meshes are).
inline std::vector<uint8_t> encodeRawMesh(const ControlMesh& mesh) {
  std::vector<uint8_t> out;
  const auto count = [&](Eigen::Index n) { out.push_back(static_cast<uint8_t>(n)); };
  const auto value = [&](double x) { out.push_back(static_cast<uint8_t>(std::lround(4.0 * x) + 125)); };
  const auto id = [&](int v) { out.push_back(static_cast<uint8_t>(static_cast<int8_t>(v))); };
  count(mesh.numVertices());
  for (Eigen::Index i = 0; i < mesh.vertices().size(); ++i) value(mesh.vertices().data()[i]);
  count(mesh.numFaces());
  for (int s : mesh.faceSizes()) id(s);
  count(static_cast<Eigen::Index>(mesh.faceIndices().size()));
  for (int v : mesh.faceIndices()) id(v);
  count(mesh.creases().rows());
  for (Eigen::Index i = 0; i < mesh.creases().size(); ++i) id(mesh.creases().data()[i]);
  count(mesh.creaseSharpness().size());
  const auto sharpness = [&](double s) {
    if (std::isinf(s)) out.push_back(252);
    else value(4.0 * s);
  };
  for (double s : mesh.creaseSharpness()) sharpness(s);
  count(static_cast<Eigen::Index>(mesh.corners().size()));
  for (int v : mesh.corners()) id(v);
  count(mesh.cornerSharpness().size());
  for (double s : mesh.cornerSharpness()) sharpness(s);
  return out;
}

}  // namespace bvmesh::fuzz

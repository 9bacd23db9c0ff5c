// Small control meshes shared by the mesh and subdivision tests.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "core/mesh/control_mesh.h"

namespace bvmesh::testing {

struct MeshData {
  RowMatrixX3d vertices;
  std::vector<int> sizes;
  std::vector<int> indices;
};

// Unit cube, outward-oriented quads. Vertices 4..7 are the top (z = 1).
inline MeshData cubeData() {
  MeshData d;
  d.vertices.resize(8, 3);
  d.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1;
  d.sizes = {4, 4, 4, 4, 4, 4};
  d.indices = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};
  return d;
}

// Closed prism over a regular n-gon: two n-gon caps and n quads. After one subdivision the cap
// centres are vertices of valence n.
inline MeshData prismData(int n) {
  MeshData d;
  d.vertices.resize(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    const double angle = 2.0 * M_PI * i / n;
    d.vertices.row(i) << std::cos(angle), std::sin(angle), 0.0;
    d.vertices.row(n + i) << std::cos(angle), std::sin(angle), 1.0;
  }
  d.sizes.push_back(n);
  for (int i = n - 1; i >= 0; --i) d.indices.push_back(i);  // bottom, facing -z
  d.sizes.push_back(n);
  for (int i = 0; i < n; ++i) d.indices.push_back(n + i);  // top, facing +z
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    d.sizes.push_back(4);
    d.indices.insert(d.indices.end(), {i, j, n + j, n + i});
  }
  return d;
}

// Open grid of nx x ny quads in the plane z = 0; vertex (i, j) has index j * (nx + 1) + i.
inline MeshData gridData(int nx, int ny) {
  MeshData d;
  d.vertices.resize((nx + 1) * (ny + 1), 3);
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) d.vertices.row(j * (nx + 1) + i) << i, j, 0.0;
  }
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i;
      d.sizes.push_back(4);
      d.indices.insert(d.indices.end(), {a, a + 1, a + nx + 2, a + nx + 1});
    }
  }
  return d;
}

inline ControlMesh makeMesh(const MeshData& d, RowMatrixX2i creases = RowMatrixX2i(0, 2),
                            Eigen::VectorXd sharpness = Eigen::VectorXd(),
                            std::vector<int> corners = {}) {
  return ControlMesh(d.vertices, d.sizes, d.indices, std::move(creases), std::move(sharpness),
                     std::move(corners));
}

// Random displacement of every vertex by up to `amplitude` per coordinate.
inline RowMatrixX3d perturbed(const RowMatrixX3d& vertices, double amplitude, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> offset(-amplitude, amplitude);
  RowMatrixX3d result = vertices;
  for (Eigen::Index i = 0; i < result.size(); ++i) result.data()[i] += offset(generator);
  return result;
}

}  // namespace bvmesh::testing

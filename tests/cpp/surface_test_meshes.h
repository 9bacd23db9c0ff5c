// Control meshes for the surface tests: grids, an L-shape, a torus, a tube and Catmull-Clark
// refinements of a cube (the core's subdivision, the same rules as the limit evaluator).
#pragma once

#include <cmath>
#include <functional>
#include <vector>

#include "core/subdiv/subdivision.h"
#include "core/surface/limit_points.h"

namespace bvmesh::surface::testing {

// An (nx x ny)-quad grid over [0, nx] x [0, ny] with height z(x, y), counter-clockwise seen from
// +z. Vertex (i, j) is i * (ny + 1) + j; faces for which `keep(i, j)` is false are left out and
// the vertices they leave unused are dropped (later ids shift down).
inline QuadControlMesh grid(int nx, int ny, const std::function<double(double, double)>& z,
                            const std::function<bool(int, int)>& keep = nullptr) {
  auto id = [ny](int i, int j) { return i * (ny + 1) + j; };
  std::vector<std::array<int, 4>> quads;
  std::vector<int> newId(static_cast<size_t>((nx + 1) * (ny + 1)), -1);
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      if (keep && !keep(i, j)) continue;
      quads.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      for (int v : quads.back()) newId[static_cast<size_t>(v)] = 0;
    }
  }
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i <= nx; ++i) {
    for (int j = 0; j <= ny; ++j) {
      if (newId[static_cast<size_t>(id(i, j))] < 0) continue;
      newId[static_cast<size_t>(id(i, j))] = static_cast<int>(points.size());
      points.emplace_back(i, j, z(i, j));
    }
  }
  for (auto& quad : quads) {
    for (int& v : quad) v = newId[static_cast<size_t>(v)];
  }
  return makeQuadControlMesh(points, quads);
}

// A regular closed torus mesh of n x m quads (all vertices valence 4), outward oriented.
inline QuadControlMesh torus(int n, int m, double major = 3.0, double minor = 1.0) {
  std::vector<Eigen::Vector3d> points;
  const double pi = std::acos(-1.0);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) {
      const double a = 2 * pi * i / n;
      const double b = 2 * pi * j / m;
      points.emplace_back((major + minor * std::cos(b)) * std::cos(a),
                          (major + minor * std::cos(b)) * std::sin(a), minor * std::sin(b));
    }
  }
  std::vector<std::array<int, 4>> quads;
  auto id = [n, m](int i, int j) { return ((i + n) % n) * m + (j + m) % m; };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) quads.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  }
  return makeQuadControlMesh(points, quads);
}

// An open tube of n x m quads around the z axis: two boundary loops, all vertices regular.
inline QuadControlMesh tube(int n, int m) {
  std::vector<Eigen::Vector3d> points;
  const double pi = std::acos(-1.0);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j <= m; ++j) points.emplace_back(std::cos(2 * pi * i / n), std::sin(2 * pi * i / n), j);
  }
  std::vector<std::array<int, 4>> quads;
  auto id = [n, m](int i, int j) { return ((i + n) % n) * (m + 1) + j; };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) quads.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  }
  return makeQuadControlMesh(points, quads);
}

// tube(8, 3) with a crease ring at height 1 and the faces listed with a shift of 3 per row, so
// the two bands' loop cuts (which start at their first face) land at different angles: each
// crease-ring node is then passed straight by the chart on the other side, a closed chain.
inline QuadControlMesh staggeredCreasedTube() {
  const int n = 8;
  const int m = 3;
  QuadControlMesh mesh = tube(n, m);
  const RowMatrixX4i faces = mesh.faces;
  for (int j = 0; j < m; ++j) {
    for (int k = 0; k < n; ++k) mesh.faces.row(j * n + k) = faces.row(((k + 3 * j) % n) * m + j);
  }
  mesh.creases.resize(n, 2);
  for (int i = 0; i < n; ++i) mesh.creases.row(i) << i * (m + 1) + 1, ((i + 1) % n) * (m + 1) + 1;
  return mesh;
}

// The cube [-1, 1]^3 as six outward quads.
inline QuadControlMesh cube() {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 8; ++i)
    points.emplace_back(2 * (i & 1) - 1, 2 * ((i >> 1) & 1) - 1, 2 * ((i >> 2) & 1) - 1);
  return makeQuadControlMesh(points,
                   {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}});
}

// `levels` Catmull-Clark steps with the core's subdivision (thesis rules); creases and corners
// carry over to the refined mesh.
inline QuadControlMesh subdivide(const QuadControlMesh& mesh, int levels) {
  ControlMesh refined = toControlMesh(mesh);
  for (int level = 0; level < levels; ++level) refined = bvmesh::subdivide(refined).mesh;
  return toQuadControlMesh(refined);
}

// The half of a mesh on the positive side of the plane x[axis] = 0 (faces whose vertices' sum of
// that coordinate is >= 0), with its creases there: open on the plane, its open boundary's
// vertices put exactly on it.
inline QuadControlMesh halfOf(const QuadControlMesh& whole, int axis) {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 4>> quads;
  std::vector<int> id(static_cast<size_t>(whole.vertices.rows()), -1);
  for (Eigen::Index f = 0; f < whole.faces.rows(); ++f) {
    double side = 0;
    for (int k = 0; k < 4; ++k) side += whole.vertices(whole.faces(f, k), axis);
    if (side < 0) continue;
    std::array<int, 4> quad{};
    for (int k = 0; k < 4; ++k) {
      int& v = id[static_cast<size_t>(whole.faces(f, k))];
      if (v < 0) {
        v = static_cast<int>(points.size());
        Eigen::Vector3d x = whole.vertices.row(whole.faces(f, k)).transpose();
        if (std::abs(x[axis]) < 1e-12) x[axis] = 0.0;
        points.push_back(x);
      }
      quad[static_cast<size_t>(k)] = v;
    }
    quads.push_back(quad);
  }
  QuadControlMesh half = makeQuadControlMesh(points, quads);
  std::vector<std::array<int, 2>> creases;
  for (Eigen::Index c = 0; c < whole.creases.rows(); ++c) {
    const int a = id[static_cast<size_t>(whole.creases(c, 0))], b = id[static_cast<size_t>(whole.creases(c, 1))];
    if (a >= 0 && b >= 0) creases.push_back({a, b});
  }
  half.creases.resize(static_cast<Eigen::Index>(creases.size()), 2);
  for (size_t c = 0; c < creases.size(); ++c) half.creases.row(static_cast<Eigen::Index>(c)) << creases[c][0], creases[c][1];
  return half;
}

// The cube refined twice, its upper half (faces with z >= 0): open on the plane z = 0, its open
// boundary's vertices exactly on it.
inline QuadControlMesh upperHalfOfRefinedCube() { return halfOf(subdivide(cube(), 2), 2); }

// The cube refined once with the equator loop (z = 0) made an infinitely sharp crease.
inline QuadControlMesh cubeWithCreasedEquator() {
  QuadControlMesh mesh = subdivide(cube(), 1);
  std::vector<std::array<int, 2>> creases;
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    for (int k = 0; k < 4; ++k) {
      const int a = mesh.faces(f, k);
      const int b = mesh.faces(f, (k + 1) % 4);
      if (a < b && std::abs(mesh.vertices(a, 2)) < 1e-12 && std::abs(mesh.vertices(b, 2)) < 1e-12) {
        creases.push_back({a, b});
      }
    }
  }
  mesh.creases.resize(static_cast<Eigen::Index>(creases.size()), 2);
  for (size_t c = 0; c < creases.size(); ++c) {
    mesh.creases(static_cast<Eigen::Index>(c), 0) = creases[c][0];
    mesh.creases(static_cast<Eigen::Index>(c), 1) = creases[c][1];
  }
  return mesh;
}

}  // namespace bvmesh::surface::testing

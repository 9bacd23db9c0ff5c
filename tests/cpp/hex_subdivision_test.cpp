// Volumetric Catmull-Clark against independent truths: the tensor-product rules of uniform
// tricubic B-spline subdivision on a structured block, element counts, the surface stage's
// subdivision of the boundary, Jacobians and mirror symmetry on a sphere shell with valence-3
// and valence-5 edges, and refinement of a block mesh placed back on its blocks' grids.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <map>
#include <set>

#include "block_fixtures.h"
#include "core/common/errors.h"
#include "core/grid/subdivision_refinement.h"
#include "core/mesh/control_mesh.h"
#include "core/subdiv/subdivision.h"
#include "core/volume/hex_subdivision.h"

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

// The unit sphere as quads: an icosahedron's triangles each split into 3 quads (vertex, edge
// midpoint, centre, edge midpoint), projected on the sphere; icosahedron vertices have 5 quads,
// triangle centres 3. Extruded radially into `layers` layers between the radii, with an
// x-symmetric bend so the input is not a set of spheres. Inner boundary wall, outer far field.
HexMesh icosahedralShell(int layers, double inner, double outer) {
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vector3d> sphere;
  for (double s : {-1.0, 1.0}) {
    for (double t : {-1.0, 1.0}) {
      sphere.emplace_back(0.0, s, t * phi);
      sphere.emplace_back(s, t * phi, 0.0);
      sphere.emplace_back(t * phi, 0.0, s);
    }
  }
  const int icosahedronVertices = static_cast<int>(sphere.size());
  std::map<std::pair<int, int>, int> midpoint;
  auto midpointOf = [&](int a, int b) {
    const auto key = std::minmax(a, b);
    const auto [it, added] = midpoint.try_emplace(key, static_cast<int>(sphere.size()));
    if (added) sphere.push_back((sphere[static_cast<size_t>(a)] + sphere[static_cast<size_t>(b)]) / 2.0);
    return it->second;
  };
  std::vector<std::array<int, 4>> quads;
  for (int a = 0; a < icosahedronVertices; ++a) {
    for (int b = a + 1; b < icosahedronVertices; ++b) {
      for (int c = b + 1; c < icosahedronVertices; ++c) {
        auto edge = [&](int x, int y) {
          return std::abs((sphere[static_cast<size_t>(x)] - sphere[static_cast<size_t>(y)]).squaredNorm() - 4.0) < 1e-9;
        };
        if (!edge(a, b) || !edge(b, c) || !edge(a, c)) continue;
        std::array<int, 3> triangle{a, b, c};
        const Vector3d& p = sphere[static_cast<size_t>(a)];
        const Vector3d normal = (sphere[static_cast<size_t>(b)] - p).cross(sphere[static_cast<size_t>(c)] - p);
        if (normal.dot(p) < 0.0) std::swap(triangle[1], triangle[2]);
        const int centre = static_cast<int>(sphere.size());
        sphere.push_back((sphere[static_cast<size_t>(a)] + sphere[static_cast<size_t>(b)] + sphere[static_cast<size_t>(c)]) / 3.0);
        for (size_t i = 0; i < 3; ++i) {
          quads.push_back({triangle[i], midpointOf(triangle[i], triangle[(i + 1) % 3]), centre,
                           midpointOf(triangle[(i + 2) % 3], triangle[i])});
        }
      }
    }
  }
  const int perLayer = static_cast<int>(sphere.size());
  HexMesh mesh;
  mesh.points.resize(perLayer * (layers + 1), 3);
  for (int layer = 0; layer <= layers; ++layer) {
    const double radius = inner + (outer - inner) * layer / layers;
    for (int s = 0; s < perLayer; ++s) {
      const Vector3d x = radius * sphere[static_cast<size_t>(s)].normalized();
      const Vector3d bent(x.x() * (1.0 + 0.05 * x.y()), x.y() + 0.1 * std::cos(x.x()) * x.z(), x.z() + 0.05 * x.x() * x.x());
      mesh.points.row(layer * perLayer + s) = bent.transpose();
    }
  }
  for (int layer = 0; layer < layers; ++layer) {
    for (const auto& q : quads) {
      const int low = layer * perLayer, high = (layer + 1) * perLayer;
      // The quad runs counter-clockwise seen from outside, and outwards is the cells' z.
      mesh.cells.push_back({low + q[0], low + q[1], low + q[2], low + q[3], high + q[0], high + q[1], high + q[2], high + q[3]});
    }
  }
  for (const auto& q : quads) {
    mesh.boundaryFaces.push_back(q);
    mesh.boundaryConditions.push_back(BoundaryCondition::Wall);
    const int top = layers * perLayer;
    mesh.boundaryFaces.push_back({top + q[0], top + q[1], top + q[2], top + q[3]});
    mesh.boundaryConditions.push_back(BoundaryCondition::Farfield);
  }
  return mesh;
}

// The mesh's boundary as the surface stage's input, built here from geometry: each boundary quad
// kept from its first corner and turned to face away from the cell holding it; creases where the
// condition changes.
ControlMesh boundaryControlMesh(const HexMesh& mesh) {
  std::map<int, int> local;
  std::vector<int> indices;
  std::map<std::pair<int, int>, BoundaryCondition> edgeCondition;
  std::vector<std::array<int, 2>> creases;
  for (size_t f = 0; f < mesh.boundaryFaces.size(); ++f) {
    std::array<int, 4> quad = mesh.boundaryFaces[f];
    const std::set<int> corners(quad.begin(), quad.end());
    Vector3d cellCentre = Vector3d::Zero();
    for (const auto& cell : mesh.cells) {
      int shared = 0;
      for (int p : cell) shared += static_cast<int>(corners.count(p));
      if (shared < 4) continue;
      for (int p : cell) cellCentre += mesh.points.row(p).transpose() / 8.0;
      break;
    }
    auto at = [&](int k) { return Vector3d(mesh.points.row(quad[static_cast<size_t>(k)]).transpose()); };
    const Vector3d normal = (at(2) - at(0)).cross(at(3) - at(1));
    if (normal.dot((at(0) + at(1) + at(2) + at(3)) / 4.0 - cellCentre) < 0.0) std::swap(quad[1], quad[3]);
    for (size_t k = 0; k < 4; ++k) {
      indices.push_back(local.try_emplace(quad[k], static_cast<int>(local.size())).first->second);
      const auto key = std::minmax(quad[k], quad[(k + 1) % 4]);
      const auto [it, added] = edgeCondition.try_emplace(key, mesh.boundaryConditions[f]);
      if (!added && it->second != mesh.boundaryConditions[f]) creases.push_back({local.at(key.first), local.at(key.second)});
    }
  }
  RowMatrixX3d vertices(static_cast<Eigen::Index>(local.size()), 3);
  for (const auto& [point, v] : local) vertices.row(v) = mesh.points.row(point);
  RowMatrixX2i creasePairs(static_cast<Eigen::Index>(creases.size()), 2);
  for (size_t c = 0; c < creases.size(); ++c) creasePairs.row(static_cast<Eigen::Index>(c)) << creases[c][0], creases[c][1];
  return ControlMesh(vertices, std::vector<int>(mesh.boundaryFaces.size(), 4), indices, creasePairs);
}

// Corner Jacobians from the usual hexahedron table (each corner's three neighbours, right-handed).
double minCornerJacobian(const RowMatrixX3d& points, const std::array<int, 8>& cell) {
  static const int neighbours[8][3] = {{1, 3, 4}, {2, 0, 5}, {3, 1, 6}, {0, 2, 7}, {7, 5, 0}, {4, 6, 1}, {5, 7, 2}, {6, 4, 3}};
  double smallest = std::numeric_limits<double>::infinity();
  for (int c = 0; c < 8; ++c) {
    const Vector3d x = points.row(cell[static_cast<size_t>(c)]).transpose();
    auto edge = [&](int k) {
      return Vector3d(points.row(cell[static_cast<size_t>(neighbours[c][k])]).transpose() - x).normalized();
    };
    smallest = std::min(smallest, edge(0).cross(edge(1)).dot(edge(2)));
  }
  return smallest;
}

std::set<int> boundaryPoints(const HexMesh& mesh) {
  std::set<int> points;
  for (const auto& quad : mesh.boundaryFaces) points.insert(quad.begin(), quad.end());
  return points;
}

// Uniform cubic B-spline subdivision in 1-D: weight of old point i in new point n.
double curveWeight(int n, int i) {
  if (n % 2 == 1) return i == n / 2 || i == n / 2 + 1 ? 0.5 : 0.0;
  const int centre = n / 2;
  return i == centre ? 0.75 : std::abs(i - centre) == 1 ? 0.125 : 0.0;
}

TEST(HexSubdivision, StructuredBlockEqualsTricubicBsplineSubdivision) {
  // The 2 x 2 x 2 box blocks merge into a 9 x 9 x 9 lattice: every interior edge has 4 cells.
  const HexMesh flat = grid::hexMeshOfBlocks(test::boxBlocks(0.0).mesh);
  const HexMesh warped = grid::hexMeshOfBlocks(test::boxBlocks(0.15).mesh);
  ASSERT_EQ(flat.points.rows(), 729);
  // Lattice index of each point: the blocks' Greville points, in sixths, are 0 1 3 5 6 7 9 11 12.
  const std::map<int, int> indexOfSixths{{0, 0}, {1, 1}, {3, 2}, {5, 3}, {6, 4}, {7, 5}, {9, 6}, {11, 7}, {12, 8}};
  RowMatrixX3d index(729, 3);
  std::map<std::array<int, 3>, int> pointAt;
  for (int p = 0; p < 729; ++p) {
    std::array<int, 3> ijk{};
    for (int d = 0; d < 3; ++d) {
      ijk[static_cast<size_t>(d)] = indexOfSixths.at(static_cast<int>(std::lround(6.0 * flat.points(p, d))));
      index(p, d) = ijk[static_cast<size_t>(d)];
    }
    pointAt[ijk] = p;
  }
  ASSERT_EQ(pointAt.size(), 729u);

  const HexSubdivisionResult result = subdivideHexMesh(warped);
  // The operator reproduces linear functions, so applied to the lattice indices it gives each
  // interior new point's position on the refined lattice.
  const RowMatrixX3d refinedIndex = result.subdivisionOperator * index;
  const std::set<int> boundary = boundaryPoints(result.mesh);
  int checked = 0;
  double worst = 0.0;
  for (int row = 0; row < result.mesh.points.rows(); ++row) {
    if (boundary.count(row)) continue;
    std::array<int, 3> refined{};
    for (int d = 0; d < 3; ++d) {
      const double twice = 2.0 * refinedIndex(row, d);
      refined[static_cast<size_t>(d)] = static_cast<int>(std::lround(twice));
      ASSERT_NEAR(twice, refined[static_cast<size_t>(d)], 1e-12) << "row " << row;
    }
    Vector3d expected = Vector3d::Zero();
    for (const auto& [ijk, p] : pointAt) {
      const double w = curveWeight(refined[0], ijk[0]) * curveWeight(refined[1], ijk[1]) * curveWeight(refined[2], ijk[2]);
      if (w != 0.0) expected += w * warped.points.row(p).transpose();
    }
    worst = std::max(worst, (expected - result.mesh.points.row(row).transpose()).norm());
    ++checked;
  }
  EXPECT_EQ(checked, 15 * 15 * 15);  // the refined 17^3 lattice without its boundary
  EXPECT_LT(worst, 1e-13);
}

TEST(HexSubdivision, CountsOnAnIrregularShell) {
  const HexMesh mesh = icosahedralShell(2, 1.0, 2.0);
  std::set<std::pair<int, int>> edges;
  std::set<std::array<int, 4>> faces;
  static const int cellEdges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  static const int cellFaces[6][4] = {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  for (const auto& cell : mesh.cells) {
    for (const auto& e : cellEdges) edges.insert(std::minmax(cell[static_cast<size_t>(e[0])], cell[static_cast<size_t>(e[1])]));
    for (const auto& f : cellFaces) {
      std::array<int, 4> key{};
      for (size_t k = 0; k < 4; ++k) key[k] = cell[static_cast<size_t>(f[k])];
      std::sort(key.begin(), key.end());
      faces.insert(key);
    }
  }
  const HexSubdivisionResult result = subdivideHexMesh(mesh);
  const auto expectedPoints = static_cast<Eigen::Index>(mesh.points.rows() + static_cast<Eigen::Index>(edges.size()) +
                                                        static_cast<Eigen::Index>(faces.size()) +
                                                        static_cast<Eigen::Index>(mesh.cells.size()));
  EXPECT_EQ(result.mesh.points.rows(), expectedPoints);
  EXPECT_EQ(result.subdivisionOperator.rows(), expectedPoints);
  EXPECT_EQ(result.subdivisionOperator.cols(), mesh.points.rows());
  EXPECT_EQ(result.mesh.cells.size(), 8 * mesh.cells.size());
  EXPECT_EQ(result.mesh.boundaryFaces.size(), 4 * mesh.boundaryFaces.size());
  // Every new point is a corner of some child, and every row is an affine combination.
  std::vector<int> used(static_cast<size_t>(expectedPoints), 0);
  for (const auto& cell : result.mesh.cells) {
    for (int p : cell) used[static_cast<size_t>(p)] = 1;
  }
  EXPECT_EQ(std::count(used.begin(), used.end(), 1), expectedPoints);
  const Eigen::VectorXd rowSums = result.subdivisionOperator * Eigen::VectorXd::Ones(mesh.points.rows());
  EXPECT_LT((rowSums.array() - 1.0).abs().maxCoeff(), 1e-14);
}

// The refined boundary, child face by child face, against the surface stage's own subdivision of
// the boundary quads, over two steps.
void expectBoundaryIsSurfaceSubdivision(const HexMesh& input) {
  HexMesh mesh = input;
  ControlMesh surface = boundaryControlMesh(mesh);
  for (int step = 0; step < 2; ++step) {
    const HexSubdivisionResult volume = subdivideHexMesh(mesh);
    const SubdivisionResult expected = subdivide(surface);
    const HexMesh& refined = volume.mesh;
    ASSERT_EQ(static_cast<int>(refined.boundaryFaces.size()), expected.mesh.numFaces());
    const double scale = mesh.points.cwiseAbs().maxCoeff();
    double worst = 0.0;
    for (int f = 0; f < expected.mesh.numFaces(); ++f) {
      for (int k = 0; k < 4; ++k) {
        const auto ours = refined.points.row(refined.boundaryFaces[static_cast<size_t>(f)][static_cast<size_t>(k)]);
        const auto theirs = expected.mesh.vertices().row(expected.mesh.faceVertex(f, k));
        worst = std::max(worst, (ours - theirs).norm());
      }
    }
    EXPECT_LT(worst, 1e-14 * scale) << "step " << step + 1;
    mesh = refined;
    surface = expected.mesh;
  }
}

TEST(HexSubdivision, BoundaryIsTheSurfaceSubdivisionOfTheBoundary) {
  // Box: wall, symmetry plane and far field meet along creases, at the box corners in corners.
  expectBoundaryIsSurfaceSubdivision(grid::hexMeshOfBlocks(test::boxBlocks(0.15).mesh));
  // Shell: closed smooth boundaries with valence-3 and valence-5 vertices.
  expectBoundaryIsSurfaceSubdivision(icosahedralShell(2, 1.0, 2.0));
}

TEST(HexSubdivision, SymmetryPlaneAndPlanarWallStayPlanar) {
  const HexMesh box = grid::hexMeshOfBlocks(test::boxBlocks(0.15).mesh);
  const HexMesh twice = subdivideHexMesh(subdivideHexMesh(box).mesh).mesh;
  int symmetryFaces = 0;
  for (size_t f = 0; f < twice.boundaryFaces.size(); ++f) {
    const BoundaryCondition condition = twice.boundaryConditions[f];
    for (int p : twice.boundaryFaces[f]) {
      if (condition == BoundaryCondition::Symmetry) {
        EXPECT_LE(std::abs(twice.points(p, 0)), 1e-14) << "point " << p;
      }
      if (condition == BoundaryCondition::Wall) {
        EXPECT_LE(std::abs(twice.points(p, 2)), 1e-14) << "point " << p;
      }
    }
    symmetryFaces += condition == BoundaryCondition::Symmetry;
  }
  EXPECT_EQ(symmetryFaces, 64 * 16);  // 2 x 2 block faces of 4 x 4 control quads, 16 children each
}

TEST(HexSubdivision, ShellStaysValidOverThreeLevels) {
  HexMesh mesh = icosahedralShell(2, 1.0, 2.0);
  for (int level = 1; level <= 3; ++level) {
    mesh = subdivideHexMesh(mesh).mesh;
    double smallest = std::numeric_limits<double>::infinity();
    for (const auto& cell : mesh.cells) smallest = std::min(smallest, minCornerJacobian(mesh.points, cell));
    EXPECT_GT(smallest, 0.0) << "level " << level;
  }
  EXPECT_EQ(mesh.cells.size(), 120u * 512u);
}

TEST(HexSubdivision, MirrorSymmetricInputGivesMirrorSymmetricOutput) {
  // The shell is symmetric under x -> -x (icosahedron, split and bend alike).
  const HexMesh mesh = icosahedralShell(2, 1.0, 2.0);
  const HexMesh refined = subdivideHexMesh(subdivideHexMesh(mesh).mesh).mesh;
  auto worstMirrorDistance = [](const RowMatrixX3d& points) {
    // Points sorted by y, so the partner of each mirrored point is searched in a narrow band.
    std::multimap<double, Eigen::Index> byY;
    for (Eigen::Index p = 0; p < points.rows(); ++p) byY.emplace(points(p, 1), p);
    double worst = 0.0;
    for (Eigen::Index p = 0; p < points.rows(); ++p) {
      const Vector3d mirrored(-points(p, 0), points(p, 1), points(p, 2));
      double nearest = std::numeric_limits<double>::infinity();
      for (auto it = byY.lower_bound(mirrored.y() - 1e-9); it != byY.end() && it->first <= mirrored.y() + 1e-9; ++it) {
        nearest = std::min(nearest, (points.row(it->second).transpose() - mirrored).norm());
      }
      worst = std::max(worst, nearest);
    }
    return worst;
  };
  ASSERT_LT(worstMirrorDistance(mesh.points), 1e-15);
  EXPECT_LT(worstMirrorDistance(refined.points), 1e-14);
}

// Two unit cubes side by side along x, wall below, far field elsewhere.
HexMesh twoCubes() {
  HexMesh mesh;
  mesh.points.resize(12, 3);
  for (int k = 0; k < 2; ++k) {
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 3; ++i) mesh.points.row(i + 3 * j + 6 * k) << i, j, k;
    }
  }
  auto at = [](int i, int j, int k) { return i + 3 * j + 6 * k; };
  for (int i = 0; i < 2; ++i) {
    mesh.cells.push_back({at(i, 0, 0), at(i + 1, 0, 0), at(i + 1, 1, 0), at(i, 1, 0), at(i, 0, 1), at(i + 1, 0, 1),
                          at(i + 1, 1, 1), at(i, 1, 1)});
  }
  auto face = [&](std::array<int, 4> quad, BoundaryCondition condition) {
    mesh.boundaryFaces.push_back(quad);
    mesh.boundaryConditions.push_back(condition);
  };
  for (int i = 0; i < 2; ++i) {
    face({at(i, 0, 0), at(i + 1, 0, 0), at(i + 1, 1, 0), at(i, 1, 0)}, BoundaryCondition::Wall);
    face({at(i, 0, 1), at(i + 1, 0, 1), at(i + 1, 1, 1), at(i, 1, 1)}, BoundaryCondition::Farfield);
    face({at(i, 0, 0), at(i + 1, 0, 0), at(i + 1, 0, 1), at(i, 0, 1)}, BoundaryCondition::Farfield);
    face({at(i, 1, 0), at(i + 1, 1, 0), at(i + 1, 1, 1), at(i, 1, 1)}, BoundaryCondition::Farfield);
  }
  face({at(0, 0, 0), at(0, 1, 0), at(0, 1, 1), at(0, 0, 1)}, BoundaryCondition::Farfield);
  face({at(2, 0, 0), at(2, 1, 0), at(2, 1, 1), at(2, 0, 1)}, BoundaryCondition::Farfield);
  return mesh;
}

void expectRefused(const HexMesh& mesh, const std::string& words) {
  try {
    subdivideHexMesh(mesh);
    ADD_FAILURE() << "accepted a mesh that should be refused with: " << words;
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find(words), std::string::npos) << error.what();
  }
}

TEST(HexSubdivision, RefusesBadInputNamingTheElement) {
  ASSERT_NO_THROW(subdivideHexMesh(twoCubes()));
  HexMesh outOfRange = twoCubes();
  outOfRange.cells[1][6] = 12;
  expectRefused(outOfRange, "cell 1 corner 6 is point 12, out of range");
  HexMesh repeated = twoCubes();
  repeated.cells[0][7] = repeated.cells[0][0];
  expectRefused(repeated, "cell 0 has point 0 at corners 0 and 7");
  HexMesh inverted = twoCubes();
  std::swap(inverted.cells[1][0], inverted.cells[1][4]);
  std::swap(inverted.cells[1][1], inverted.cells[1][5]);
  std::swap(inverted.cells[1][2], inverted.cells[1][6]);
  std::swap(inverted.cells[1][3], inverted.cells[1][7]);
  expectRefused(inverted, "cell 1 is inverted");
  HexMesh nonManifold = twoCubes();
  nonManifold.cells.push_back(nonManifold.cells[1]);
  expectRefused(nonManifold, "of cell 2 is also a face of cells 0 and 1");
  HexMesh untagged = twoCubes();
  untagged.boundaryFaces.pop_back();
  untagged.boundaryConditions.pop_back();
  expectRefused(untagged, "cell 1 face u_max (2 5 11 8) lies on the boundary but has no boundary condition");
  HexMesh interior = twoCubes();
  interior.boundaryFaces.push_back({1, 4, 10, 7});
  interior.boundaryConditions.push_back(BoundaryCondition::Wall);
  expectRefused(interior, "boundary face 10 (1 4 10 7) lies between cells 0 and 1");
  HexMesh crease = twoCubes();
  crease.creases.resize(1, 2);
  crease.creases << 0, 7;
  expectRefused(crease, "crease 0 (0, 7) is not an edge of a boundary face");
}

TEST(HexSubdivision, CreasesAndCornersAreKept) {
  HexMesh mesh = twoCubes();
  mesh.points(4, 2) = -0.3;  // the wall folds along the edge (1, 4) between its two faces
  mesh.creases.resize(1, 2);
  mesh.creases << 1, 4;
  mesh.corners = {0};
  const HexSubdivisionResult result = subdivideHexMesh(mesh);
  // A given corner stays, and so does point 1, where the crease meets the wall's edge (a crease
  // too, the condition changes there): three creases make a corner.
  EXPECT_EQ(result.mesh.points.row(0), mesh.points.row(0));
  EXPECT_EQ(result.mesh.points.row(1), mesh.points.row(1));
  EXPECT_EQ(result.mesh.corners, std::vector<int>{0});
  // The crease's halves are creases of the refined mesh, meeting at the edge's midpoint.
  const Eigen::RowVector3d midpoint = (mesh.points.row(1) + mesh.points.row(4)) / 2.0;
  int halves = 0, mid = -1;
  for (Eigen::Index c = 0; c < result.mesh.creases.rows(); ++c) {
    const int a = result.mesh.creases(c, 0), b = result.mesh.creases(c, 1);
    for (int end : {1, 4}) {
      if (a != end && b != end) continue;
      mid = a == end ? b : a;
      halves += (result.mesh.points.row(mid) - midpoint).norm() < 1e-15;
    }
  }
  EXPECT_EQ(halves, 2);
  // Without the crease the wall's smooth rule pulls the edge point off the fold.
  mesh.creases.resize(0, 2);
  ASSERT_GE(mid, 0);
  EXPECT_GT((subdivideHexMesh(mesh).mesh.points.row(mid) - midpoint).norm(), 1e-3);
}

TEST(HexSubdivision, BlockMeshRefinementPlacesPointsOnTheBlockGrids) {
  const test::BoxBlocks box = test::boxBlocks(0.15);
  const grid::StructuredGrid grid = grid::subdivideBlockMesh(box.mesh, 1);
  ASSERT_EQ(grid.blockCount(), 8);
  const HexSubdivisionResult refined = subdivideHexMesh(grid::hexMeshOfBlocks(box.mesh));
  const VolumeControlMesh control = volumeControlMesh(box.mesh);
  for (int b = 0; b < 8; ++b) {
    const grid::GridBlock& block = grid.blocks()[static_cast<size_t>(b)];
    const BsplineVolume& volume = box.mesh.blocks()[static_cast<size_t>(b)].volume;
    ASSERT_EQ(block.size, (std::array<int, 3>{9, 9, 9}));
    for (int k = 0; k < 4; ++k) {
      for (int j = 0; j < 4; ++j) {
        for (int i = 0; i < 4; ++i) {
          // Even positions: the moved pole; odd ones in every direction: the centroid of its cell.
          const int pole = control.pointOfPole[static_cast<size_t>(control.blockPointOffset[static_cast<size_t>(b)] + volume.poleIndex(i, j, k))];
          EXPECT_EQ(block.points.row(block.index(2 * i, 2 * j, 2 * k)), refined.mesh.points.row(pole));
          Vector3d centroid = Vector3d::Zero();
          for (int corner = 0; corner < 8; ++corner) {
            centroid += volume.poles().row(volume.poleIndex(i + (corner & 1), j + (corner >> 1 & 1), k + (corner >> 2 & 1))).transpose() / 8.0;
          }
          EXPECT_LT((block.points.row(block.index(2 * i + 1, 2 * j + 1, 2 * k + 1)).transpose() - centroid).norm(), 1e-14);
        }
      }
    }
  }
  EXPECT_EQ(grid::mergePoints(grid).points.rows(), refined.mesh.points.rows());
  EXPECT_EQ(grid::subdivideBlockMesh(box.mesh, 2).cellCount(), 8 * 16 * 16 * 16);
  EXPECT_THROW(grid::subdivideBlockMesh(box.mesh, -1), InvalidInputError);
}

}  // namespace
}  // namespace bvmesh::volume

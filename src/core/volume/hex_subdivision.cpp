#include "core/volume/hex_subdivision.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <utility>

#include "core/common/errors.h"
#include "core/common/input_checks.h"
#include "core/mesh/control_mesh.h"

namespace bvmesh::volume {
namespace {

// The corner at (x, y, z), at index x + 2 y + 4 z: kHexCornerBits inverted.
constexpr std::array<int, 8> kCornerOfBits{0, 1, 3, 2, 4, 5, 7, 6};

// The 6 faces (x min, x max, y min, y max, z min, z max: BlockFaceSide order), counter-clockwise
// seen from outside a right-handed cell.
constexpr std::array<std::array<int, 4>, 6> kCellFaces{
    {{0, 4, 7, 3}, {1, 2, 6, 5}, {0, 1, 5, 4}, {3, 7, 6, 2}, {0, 3, 2, 1}, {4, 5, 6, 7}}};

enum class ElementKind { Vertex, Edge, Face, Cell };

// The old cell's 3 x 3 x 3 lattice of new points: lattice coordinate 0 or 2 on an axis is the
// cell's min or max side, 1 the middle. Position l = lx + 3 ly + 9 lz is the new point of a
// corner, edge, face or the cell itself; `weights` is the cell's trilinear map at the centre of
// the children touching that point (1/4 or 3/4 towards a side, 1/2 across), over the 8 corners.
struct LatticePosition {
  ElementKind kind = ElementKind::Cell;
  int local = 0;  // corner, edge or face of the cell
  std::array<double, 8> weights{};
};

std::array<LatticePosition, 27> makeLattice() {
  std::array<LatticePosition, 27> lattice{};
  for (int l = 0; l < 27; ++l) {
    const std::array<int, 3> at{l % 3, (l / 3) % 3, l / 9};
    LatticePosition& position = lattice[static_cast<size_t>(l)];
    const auto middle = static_cast<int>(std::count(at.begin(), at.end(), 1));
    position.kind = static_cast<ElementKind>(middle);
    if (middle == 0) {
      position.local = kCornerOfBits[static_cast<size_t>(at[0] / 2 + 2 * (at[1] / 2) + 4 * (at[2] / 2))];
    } else if (middle == 1) {
      // The edge's two corners: the middle coordinate taken to either side.
      std::array<int, 2> ends{};
      for (int side = 0; side < 2; ++side) {
        std::array<int, 3> bits{};
        for (size_t d = 0; d < 3; ++d) bits[d] = at[d] == 1 ? side : at[d] / 2;
        ends[static_cast<size_t>(side)] = kCornerOfBits[static_cast<size_t>(bits[0] + 2 * bits[1] + 4 * bits[2])];
      }
      for (int e = 0; e < 12; ++e) {
        const auto& edge = kHexCellEdges[static_cast<size_t>(e)];
        if ((edge[0] == ends[0] && edge[1] == ends[1]) || (edge[0] == ends[1] && edge[1] == ends[0])) position.local = e;
      }
    } else if (middle == 2) {
      for (int d = 0; d < 3; ++d) {
        if (at[static_cast<size_t>(d)] != 1) position.local = 2 * d + at[static_cast<size_t>(d)] / 2;
      }
    }
    for (size_t c = 0; c < 8; ++c) {
      double weight = 1.0;
      for (size_t d = 0; d < 3; ++d) {
        const int coordinate = at[d];
        const int bit = kHexCornerBits[c][d];
        weight *= coordinate == 1 ? 0.5 : (coordinate / 2 == bit ? 0.75 : 0.25);
      }
      position.weights[c] = weight;
    }
  }
  return lattice;
}

const std::array<LatticePosition, 27>& lattice() {
  static const std::array<LatticePosition, 27> table = makeLattice();
  return table;
}

std::uint64_t edgeKey(int a, int b) {
  const auto low = static_cast<std::uint64_t>(std::min(a, b));
  const auto high = static_cast<std::uint64_t>(std::max(a, b));
  return low << 32 | high;
}

using FaceKey = std::array<int, 4>;  // the face's points, sorted

struct FaceKeyHash {
  size_t operator()(const FaceKey& key) const {
    std::uint64_t h = 1469598103934665603ull;
    for (int v : key) h = (h ^ static_cast<std::uint64_t>(static_cast<std::uint32_t>(v))) * 1099511628211ull;
    return static_cast<size_t>(h);
  }
};

FaceKey faceKey(std::array<int, 4> quad) {
  std::sort(quad.begin(), quad.end());
  return quad;
}

std::string quadText(const std::array<int, 4>& quad) {
  return "(" + std::to_string(quad[0]) + " " + std::to_string(quad[1]) + " " + std::to_string(quad[2]) + " " +
         std::to_string(quad[3]) + ")";
}

// Whether quad b runs round the same cycle as quad a (same points), rather than the reverse one.
bool sameCycle(const std::array<int, 4>& a, const std::array<int, 4>& b) {
  const auto start = static_cast<size_t>(std::find(b.begin(), b.end(), a[0]) - b.begin());
  return b[(start + 1) % 4] == a[1];
}

void validateCells(const HexMesh& mesh) {
  const auto pointCount = static_cast<int>(mesh.points.rows());
  checkFinitePoints(mesh.points, "hex mesh point");
  for (size_t c = 0; c < mesh.cells.size(); ++c) {
    const auto& cell = mesh.cells[c];
    for (size_t k = 0; k < 8; ++k) {
      if (cell[k] < 0 || cell[k] >= pointCount) {
        throw InvalidInputError("cell " + std::to_string(c) + " corner " + std::to_string(k) + " is point " +
                                std::to_string(cell[k]) + ", out of range (" + std::to_string(pointCount) + " points)");
      }
      for (size_t j = 0; j < k; ++j) {
        if (cell[j] == cell[k]) {
          throw InvalidInputError("cell " + std::to_string(c) + " has point " + std::to_string(cell[k]) +
                                  " at corners " + std::to_string(j) + " and " + std::to_string(k));
        }
      }
    }
    const std::array<double, 8> jacobians = cornerJacobians(mesh.points, cell);
    double volume = 0.0;
    for (double j : jacobians) volume += j;
    if (!(volume > 0.0)) {
      throw InvalidInputError("cell " + std::to_string(c) + " is inverted or flat (its corner Jacobians sum to " +
                              std::to_string(volume) + "): corners must be right-handed, 000 100 110 010 001 101 111 011");
    }
  }
}

// Edges and faces numbered in order of first use, per cell its 12 edges and 6 faces, per face its
// cells (the second -1 on the boundary) and its outward quad as seen from the first cell.
struct Topology {
  std::vector<int> cellEdges;  // 12 per cell
  std::vector<int> cellFaces;  // 6 per cell
  std::unordered_map<std::uint64_t, int> edgeOfKey;
  std::unordered_map<FaceKey, int, FaceKeyHash> faceOfKey;
  std::vector<std::array<int, 2>> faceCells;
  std::vector<int> faceLocal;  // the face's side in its first cell
  int edgeCount() const { return static_cast<int>(edgeOfKey.size()); }
  int faceCount() const { return static_cast<int>(faceCells.size()); }
};

std::array<int, 4> outwardQuad(const HexMesh& mesh, int cell, int side) {
  const auto& corners = kCellFaces[static_cast<size_t>(side)];
  const auto& points = mesh.cells[static_cast<size_t>(cell)];
  return {points[static_cast<size_t>(corners[0])], points[static_cast<size_t>(corners[1])],
          points[static_cast<size_t>(corners[2])], points[static_cast<size_t>(corners[3])]};
}

Topology buildTopology(const HexMesh& mesh) {
  Topology topology;
  const size_t cellCount = mesh.cells.size();
  topology.cellEdges.resize(12 * cellCount);
  topology.cellFaces.resize(6 * cellCount);
  topology.edgeOfKey.reserve(3 * cellCount + 64);
  topology.faceOfKey.reserve(3 * cellCount + 64);
  for (size_t c = 0; c < cellCount; ++c) {
    const auto& cell = mesh.cells[c];
    for (size_t e = 0; e < 12; ++e) {
      const auto key = edgeKey(cell[static_cast<size_t>(kHexCellEdges[e][0])], cell[static_cast<size_t>(kHexCellEdges[e][1])]);
      topology.cellEdges[12 * c + e] = topology.edgeOfKey.try_emplace(key, topology.edgeCount()).first->second;
    }
    for (int side = 0; side < 6; ++side) {
      const std::array<int, 4> quad = outwardQuad(mesh, static_cast<int>(c), side);
      const auto [it, added] = topology.faceOfKey.try_emplace(faceKey(quad), topology.faceCount());
      const int face = it->second;
      topology.cellFaces[6 * c + static_cast<size_t>(side)] = face;
      if (added) {
        topology.faceCells.push_back({static_cast<int>(c), -1});
        topology.faceLocal.push_back(side);
        continue;
      }
      auto& cells = topology.faceCells[static_cast<size_t>(face)];
      if (cells[1] >= 0) {
        throw TopologyError("face " + quadText(quad) + " of cell " + std::to_string(c) + " is also a face of cells " +
                            std::to_string(cells[0]) + " and " + std::to_string(cells[1]) + ": the mesh is not manifold");
      }
      const std::array<int, 4> first = outwardQuad(mesh, cells[0], topology.faceLocal[static_cast<size_t>(face)]);
      if (sameCycle(first, quad)) {
        throw TopologyError("cells " + std::to_string(cells[0]) + " and " + std::to_string(c) + " both see their face " +
                            quadText(quad) + " with the same orientation: one of them is inverted");
      }
      cells[1] = static_cast<int>(c);
    }
  }
  return topology;
}

// Runs `work`, prefixing the message of what the surface stage throws with `context` (same type).
template <class Work>
auto withContext(const std::string& context, Work&& work) {
  try {
    return work();
  } catch (const TopologyError& error) {
    throw TopologyError(context + error.what());
  } catch (const InvalidInputError& error) {
    throw InvalidInputError(context + error.what());
  }
}

// The boundary as the surface stage's control mesh: quads pointing out, points renumbered
// (local vertex v is mesh point `points[v]`), creases as given plus condition changes.
struct BoundarySurface {
  std::vector<int> points;
  std::vector<int> faces;                 // per boundary face, its global face id
  std::vector<std::array<int, 4>> quads;  // outward, starting at the given first corner
  ControlMesh controlMesh;
};

struct BoundaryFaces {
  std::vector<int> faces;
  std::vector<std::array<int, 4>> quads;
};

int edgeIdOf(const Topology& topology, int a, int b) {
  const auto it = topology.edgeOfKey.find(edgeKey(a, b));
  return it == topology.edgeOfKey.end() ? -1 : it->second;
}

BoundarySurface buildBoundary(const HexMesh& mesh, const Topology& topology) {
  const size_t boundaryCount = mesh.boundaryFaces.size();
  if (mesh.boundaryConditions.size() != boundaryCount) {
    throw InvalidInputError(std::to_string(boundaryCount) + " boundary faces but " +
                            std::to_string(mesh.boundaryConditions.size()) + " boundary conditions");
  }
  BoundaryFaces boundary;
  std::vector<int> boundaryOfFace(static_cast<size_t>(topology.faceCount()), -1);
  for (size_t b = 0; b < boundaryCount; ++b) {
    const std::array<int, 4>& given = mesh.boundaryFaces[b];
    const std::string name = "boundary face " + std::to_string(b) + " " + quadText(given);
    if (mesh.boundaryConditions[b] == BoundaryCondition::Connected) throw InvalidInputError(name + " is tagged connected");
    const auto it = topology.faceOfKey.find(faceKey(given));
    if (it == topology.faceOfKey.end()) throw InvalidInputError(name + " is not a face of any cell");
    const int face = it->second;
    const auto& cells = topology.faceCells[static_cast<size_t>(face)];
    if (cells[1] >= 0) {
      throw InvalidInputError(name + " lies between cells " + std::to_string(cells[0]) + " and " +
                              std::to_string(cells[1]) + ", inside the mesh");
    }
    if (boundaryOfFace[static_cast<size_t>(face)] >= 0) {
      throw InvalidInputError(name + " repeats boundary face " + std::to_string(boundaryOfFace[static_cast<size_t>(face)]));
    }
    boundaryOfFace[static_cast<size_t>(face)] = static_cast<int>(b);
    const std::array<int, 4> outward = outwardQuad(mesh, cells[0], topology.faceLocal[static_cast<size_t>(face)]);
    boundary.faces.push_back(face);
    boundary.quads.push_back(sameCycle(outward, given) ? given : std::array<int, 4>{given[0], given[3], given[2], given[1]});
  }
  for (int f = 0; f < topology.faceCount(); ++f) {
    const auto& cells = topology.faceCells[static_cast<size_t>(f)];
    if (cells[1] < 0 && boundaryOfFace[static_cast<size_t>(f)] < 0) {
      throw InvalidInputError("cell " + std::to_string(cells[0]) + " face " + blockFaceName(topology.faceLocal[static_cast<size_t>(f)]) +
                              " " + quadText(outwardQuad(mesh, cells[0], topology.faceLocal[static_cast<size_t>(f)])) +
                              " lies on the boundary but has no boundary condition");
    }
  }

  std::vector<int> points;
  std::vector<int> localOf(static_cast<size_t>(mesh.points.rows()), -1);
  std::vector<int> faceIndices;
  faceIndices.reserve(4 * boundaryCount);
  for (const auto& quad : boundary.quads) {
    for (int p : quad) {
      if (localOf[static_cast<size_t>(p)] < 0) {
        localOf[static_cast<size_t>(p)] = static_cast<int>(points.size());
        points.push_back(p);
      }
      faceIndices.push_back(localOf[static_cast<size_t>(p)]);
    }
  }
  RowMatrixX3d vertices(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t v = 0; v < points.size(); ++v) vertices.row(static_cast<Eigen::Index>(v)) = mesh.points.row(points[v]);

  // Creases: the given ones (checked to be boundary edges) and every boundary edge whose two
  // faces carry different conditions, each once.
  std::unordered_map<std::uint64_t, BoundaryCondition> firstCondition;
  std::unordered_map<std::uint64_t, bool> creaseOfKey;
  std::vector<std::array<int, 2>> creases;
  auto addCrease = [&](int a, int b) {
    if (creaseOfKey.emplace(edgeKey(a, b), true).second) creases.push_back({localOf[static_cast<size_t>(a)], localOf[static_cast<size_t>(b)]});
  };
  for (size_t b = 0; b < boundaryCount; ++b) {
    const auto& quad = boundary.quads[b];
    for (size_t k = 0; k < 4; ++k) {
      const int from = quad[k], to = quad[(k + 1) % 4];
      const auto [it, added] = firstCondition.try_emplace(edgeKey(from, to), mesh.boundaryConditions[b]);
      if (!added && it->second != mesh.boundaryConditions[b]) addCrease(from, to);
    }
  }
  for (Eigen::Index c = 0; c < mesh.creases.rows(); ++c) {
    const int a = mesh.creases(c, 0), b = mesh.creases(c, 1);
    if (a < 0 || b < 0 || a >= mesh.points.rows() || b >= mesh.points.rows() ||
        firstCondition.find(edgeKey(a, b)) == firstCondition.end()) {
      throw InvalidInputError("crease " + std::to_string(c) + " (" + std::to_string(a) + ", " + std::to_string(b) +
                              ") is not an edge of a boundary face");
    }
    addCrease(a, b);
  }
  RowMatrixX2i creasePairs(static_cast<Eigen::Index>(creases.size()), 2);
  for (size_t c = 0; c < creases.size(); ++c) creasePairs.row(static_cast<Eigen::Index>(c)) << creases[c][0], creases[c][1];
  std::vector<int> corners;
  for (size_t k = 0; k < mesh.corners.size(); ++k) {
    const int p = mesh.corners[k];
    if (p < 0 || p >= mesh.points.rows() || localOf[static_cast<size_t>(p)] < 0) {
      throw InvalidInputError("corner " + std::to_string(k) + " (point " + std::to_string(p) + ") is not a boundary point");
    }
    corners.push_back(localOf[static_cast<size_t>(p)]);
  }
  return withContext("the boundary surface (face f = boundary face f): ", [&]() -> BoundarySurface {
    return {std::move(points), std::move(boundary.faces), std::move(boundary.quads),
            ControlMesh(std::move(vertices), std::vector<int>(boundaryCount, 4), std::move(faceIndices),
                        std::move(creasePairs), Eigen::VectorXd(), std::move(corners))};
  });
}

}  // namespace

std::array<double, 8> cornerJacobians(const RowMatrixX3d& points, const std::array<int, 8>& cell, bool scaled) {
  std::array<double, 8> result{};
  for (size_t c = 0; c < 8; ++c) {
    const auto& bits = kHexCornerBits[c];
    std::array<Eigen::Vector3d, 3> edges;
    for (size_t d = 0; d < 3; ++d) {
      std::array<int, 3> other = bits;
      other[d] = 1 - other[d];
      const int neighbour = cell[static_cast<size_t>(kCornerOfBits[static_cast<size_t>(other[0] + 2 * other[1] + 4 * other[2])])];
      // Along +x, +y, +z whichever side the corner is on, so every corner measures the same frame.
      const double sign = bits[d] == 0 ? 1.0 : -1.0;
      edges[d] = sign * (points.row(neighbour) - points.row(cell[c])).transpose();
      if (scaled) edges[d].normalize();
    }
    result[c] = edges[0].cross(edges[1]).dot(edges[2]);
  }
  return result;
}

HexSubdivisionResult subdivideHexMesh(const HexMesh& mesh, const SubdivisionOptions& options) {
  validateCells(mesh);
  const Topology topology = buildTopology(mesh);
  const BoundarySurface boundary = buildBoundary(mesh, topology);
  const SubdivisionResult surface = withContext("the refined boundary surface (face f = refined boundary face f): ",
                                                [&] { return subdivide(boundary.controlMesh, options); });

  const int pointCount = static_cast<int>(mesh.points.rows());
  const int edgeBase = pointCount;
  const int faceBase = edgeBase + topology.edgeCount();
  const int cellBase = faceBase + topology.faceCount();
  const int cellCount = static_cast<int>(mesh.cells.size());
  const int newCount = cellBase + cellCount;
  auto latticePoint = [&](int cell, int l) {
    const LatticePosition& position = lattice()[static_cast<size_t>(l)];
    const auto c = static_cast<size_t>(cell);
    switch (position.kind) {
      case ElementKind::Vertex:
        return mesh.cells[c][static_cast<size_t>(position.local)];
      case ElementKind::Edge:
        return edgeBase + topology.cellEdges[12 * c + static_cast<size_t>(position.local)];
      case ElementKind::Face:
        return faceBase + topology.cellFaces[6 * c + static_cast<size_t>(position.local)];
      case ElementKind::Cell:
        break;
    }
    return cellBase + cell;
  };

  // The surface stage's refined vertex r is new point newOfSurface[r]; boundary new points take
  // their row of the surface operator, the others the volume rule.
  const ControlMesh& surfaceMesh = boundary.controlMesh;
  std::vector<int> newOfSurface(static_cast<size_t>(surface.subdivisionOperator.rows()));
  std::vector<int> surfaceRowOf(static_cast<size_t>(newCount), -1);
  for (int v = 0; v < surfaceMesh.numVertices(); ++v) newOfSurface[static_cast<size_t>(v)] = boundary.points[static_cast<size_t>(v)];
  for (int e = 0; e < surfaceMesh.numEdges(); ++e) {
    const int a = boundary.points[static_cast<size_t>(surfaceMesh.edges()(e, 0))];
    const int b = boundary.points[static_cast<size_t>(surfaceMesh.edges()(e, 1))];
    newOfSurface[static_cast<size_t>(surfaceMesh.numVertices() + e)] = edgeBase + edgeIdOf(topology, a, b);
  }
  for (int f = 0; f < surfaceMesh.numFaces(); ++f) {
    newOfSurface[static_cast<size_t>(surfaceMesh.numVertices() + surfaceMesh.numEdges() + f)] =
        faceBase + boundary.faces[static_cast<size_t>(f)];
  }
  for (size_t r = 0; r < newOfSurface.size(); ++r) surfaceRowOf[static_cast<size_t>(newOfSurface[r])] = static_cast<int>(r);

  // Interior new points: the (cell, lattice position) pairs that make them, in CSR form.
  std::vector<int> incidenceStart(static_cast<size_t>(newCount) + 1, 0);
  for (int c = 0; c < cellCount; ++c) {
    for (int l = 0; l < 27; ++l) {
      const int p = latticePoint(c, l);
      if (surfaceRowOf[static_cast<size_t>(p)] < 0) ++incidenceStart[static_cast<size_t>(p) + 1];
    }
  }
  for (size_t p = 0; p < static_cast<size_t>(newCount); ++p) incidenceStart[p + 1] += incidenceStart[p];
  std::vector<int> incidence(static_cast<size_t>(incidenceStart.back()));
  {
    std::vector<int> fill(incidenceStart.begin(), incidenceStart.end() - 1);
    for (int c = 0; c < cellCount; ++c) {
      for (int l = 0; l < 27; ++l) {
        const int p = latticePoint(c, l);
        if (surfaceRowOf[static_cast<size_t>(p)] < 0) incidence[static_cast<size_t>(fill[static_cast<size_t>(p)]++)] = 27 * c + l;
      }
    }
  }

  RowSparseMatrix op(newCount, pointCount);
  // Exact for a structured mesh (27, 18, 12 and 8 entries for vertex, edge, face and cell points).
  op.reserve(27 * static_cast<Eigen::Index>(pointCount) + 18 * static_cast<Eigen::Index>(topology.edgeCount()) +
             12 * static_cast<Eigen::Index>(topology.faceCount()) + 8 * static_cast<Eigen::Index>(cellCount));
  std::vector<double> dense(static_cast<size_t>(pointCount), 0.0);
  std::vector<char> marked(static_cast<size_t>(pointCount), 0);
  std::vector<int> touched;
  auto add = [&](int column, double weight) {
    if (!marked[static_cast<size_t>(column)]) {
      marked[static_cast<size_t>(column)] = 1;
      touched.push_back(column);
    }
    dense[static_cast<size_t>(column)] += weight;
  };
  for (int p = 0; p < newCount; ++p) {
    const int surfaceRow = surfaceRowOf[static_cast<size_t>(p)];
    if (surfaceRow >= 0) {
      for (RowSparseMatrix::InnerIterator it(surface.subdivisionOperator, surfaceRow); it; ++it) {
        add(boundary.points[static_cast<size_t>(it.col())], it.value());
      }
    } else {
      const int first = incidenceStart[static_cast<size_t>(p)];
      const int last = incidenceStart[static_cast<size_t>(p) + 1];
      const double share = 1.0 / (last - first);
      for (int k = first; k < last; ++k) {
        const int entry = incidence[static_cast<size_t>(k)];
        const auto& cell = mesh.cells[static_cast<size_t>(entry / 27)];
        const auto& weights = lattice()[static_cast<size_t>(entry % 27)].weights;
        for (size_t q = 0; q < 8; ++q) add(cell[q], share * weights[q]);
      }
    }
    std::sort(touched.begin(), touched.end());
    op.startVec(p);
    for (int column : touched) {
      op.insertBack(p, column) = dense[static_cast<size_t>(column)];
      dense[static_cast<size_t>(column)] = 0.0;
      marked[static_cast<size_t>(column)] = 0;
    }
    touched.clear();
  }
  op.finalize();

  HexSubdivisionResult result;
  HexMesh& refined = result.mesh;
  refined.points = op * mesh.points;
  refined.cells.resize(8 * static_cast<size_t>(cellCount));
  for (int c = 0; c < cellCount; ++c) {
    for (int child = 0; child < 8; ++child) {
      std::array<int, 8>& corners = refined.cells[8 * static_cast<size_t>(c) + static_cast<size_t>(child)];
      for (size_t q = 0; q < 8; ++q) {
        const auto& bits = kHexCornerBits[q];
        const int l = (child & 1) + bits[0] + 3 * ((child >> 1 & 1) + bits[1]) + 9 * ((child >> 2 & 1) + bits[2]);
        corners[q] = latticePoint(c, l);
      }
    }
  }
  // The surface stage's children of face f are its faces 4 f .. 4 f + 3, in our order already.
  const std::vector<int>& childIndices = surface.mesh.faceIndices();
  refined.boundaryFaces.resize(childIndices.size() / 4);
  refined.boundaryConditions.resize(refined.boundaryFaces.size());
  for (size_t f = 0; f < refined.boundaryFaces.size(); ++f) {
    for (size_t k = 0; k < 4; ++k) refined.boundaryFaces[f][k] = newOfSurface[static_cast<size_t>(childIndices[4 * f + k])];
    refined.boundaryConditions[f] = mesh.boundaryConditions[f / 4];
  }
  const RowMatrixX2i& childCreases = surface.mesh.creases();
  refined.creases.resize(childCreases.rows(), 2);
  for (Eigen::Index c = 0; c < childCreases.rows(); ++c) {
    refined.creases.row(c) << newOfSurface[static_cast<size_t>(childCreases(c, 0))],
        newOfSurface[static_cast<size_t>(childCreases(c, 1))];
  }
  refined.corners = mesh.corners;
  result.subdivisionOperator = std::move(op);
  return result;
}

HexBlock refineHexBlock(const HexBlock& old, const HexMesh& refined) {
  HexBlock next;
  next.reversed = old.reversed;
  for (size_t d = 0; d < 3; ++d) next.size[d] = 2 * old.size[d] - 1;
  next.pointAt.assign(static_cast<size_t>(next.size[0]) * static_cast<size_t>(next.size[1]) * static_cast<size_t>(next.size[2]), -1);
  next.cellAt.assign(old.cellAt.size() * 8, -1);
  for (int k = 0; k + 1 < old.size[2]; ++k) {
    for (int j = 0; j + 1 < old.size[1]; ++j) {
      for (int i = 0; i + 1 < old.size[0]; ++i) {
        const int cell = old.cellAt[old.cell(i, j, k)];
        for (int child = 0; child < 8; ++child) {
          const std::array<int, 3> octant{child & 1, child >> 1 & 1, child >> 2 & 1};
          const int blockX = old.reversed ? 1 - octant[0] : octant[0];
          const int childCell = 8 * cell + child;
          next.cellAt[next.cell(2 * i + blockX, 2 * j + octant[1], 2 * k + octant[2])] = childCell;
          const std::array<int, 8>& corners = refined.cells[static_cast<size_t>(childCell)];
          for (int q = 0; q < 8; ++q) {
            // Corner q of the child at (x, y, z) = octant + corner bits in the cell's frame.
            const auto& bits = kHexCornerBits[static_cast<size_t>(q)];
            const int x = octant[0] + bits[0];
            const int y = octant[1] + bits[1];
            const int z = octant[2] + bits[2];
            next.pointAt[next.point(2 * i + (old.reversed ? 2 - x : x), 2 * j + y, 2 * k + z)] = corners[static_cast<size_t>(q)];
          }
        }
      }
    }
  }
  return next;
}



WallControlMesh wallControlMesh(const HexMesh& mesh) {
  std::vector<int> localOf(static_cast<size_t>(mesh.points.rows()), -1);
  std::vector<int> points;
  std::vector<int> indices;
  for (size_t f = 0; f < mesh.boundaryFaces.size(); ++f) {
    if (mesh.boundaryConditions[f] != BoundaryCondition::Wall) continue;
    // Refined boundary faces point out of the mesh, into the body; the surface fit's wall points
    // out of the body (its limit normals meet the target's), so each quad is taken reversed.
    const std::array<int, 4>& quad = mesh.boundaryFaces[f];
    for (int p : {quad[0], quad[3], quad[2], quad[1]}) {
      if (localOf[static_cast<size_t>(p)] < 0) {
        localOf[static_cast<size_t>(p)] = static_cast<int>(points.size());
        points.push_back(p);
      }
      indices.push_back(localOf[static_cast<size_t>(p)]);
    }
  }
  if (indices.empty()) throw InvalidInputError("continued fitting needs wall faces; the hex mesh has none");
  RowMatrixX3d vertices(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t v = 0; v < points.size(); ++v) vertices.row(static_cast<Eigen::Index>(v)) = mesh.points.row(points[v]);
  const std::vector<int> sizes(indices.size() / 4, 4);
  // The mesh's creases that are edges of the wall (those along its border with another condition
  // are its boundary, sharp anyway) and its corners on the wall.
  const ControlMesh plain(vertices, sizes, indices);
  std::vector<std::array<int, 2>> creases;
  for (Eigen::Index c = 0; c < mesh.creases.rows(); ++c) {
    const int a = localOf[static_cast<size_t>(mesh.creases(c, 0))], b = localOf[static_cast<size_t>(mesh.creases(c, 1))];
    if (a >= 0 && b >= 0 && plain.findEdge(a, b) >= 0 && !plain.isBoundaryEdge(plain.findEdge(a, b))) creases.push_back({a, b});
  }
  RowMatrixX2i creasePairs(static_cast<Eigen::Index>(creases.size()), 2);
  for (size_t c = 0; c < creases.size(); ++c) creasePairs.row(static_cast<Eigen::Index>(c)) << creases[c][0], creases[c][1];
  std::vector<int> corners;
  for (int p : mesh.corners) {
    if (localOf[static_cast<size_t>(p)] >= 0) corners.push_back(localOf[static_cast<size_t>(p)]);
  }
  return {std::move(points), ControlMesh(std::move(vertices), sizes, std::move(indices), std::move(creasePairs),
                                         Eigen::VectorXd(), std::move(corners))};
}

}  // namespace bvmesh::volume

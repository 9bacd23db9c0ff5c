#include "core/mesh/control_mesh.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <utility>

#include "core/common/disjoint_sets.h"
#include "core/common/errors.h"
#include "core/common/input_checks.h"
#include "core/common/number_text.h"

namespace bvmesh {
namespace {

std::string pairText(int a, int b) {
  return "(" + std::to_string(a) + ", " + std::to_string(b) + ")";
}

size_t at(int index) { return static_cast<size_t>(index); }

}  // namespace

ControlMesh::ControlMesh(RowMatrixX3d vertices, std::vector<int> faceSizes,
                         std::vector<int> faceIndices, RowMatrixX2i creases,
                         Eigen::VectorXd creaseSharpness, std::vector<int> corners,
                         Eigen::VectorXd cornerSharpness)
    : vertices_(std::move(vertices)),
      faceSizes_(std::move(faceSizes)),
      faceIndices_(std::move(faceIndices)),
      creases_(std::move(creases)),
      creaseSharpness_(std::move(creaseSharpness)),
      corners_(std::move(corners)),
      cornerSharpness_(std::move(cornerSharpness)) {
  checkFinitePoints(vertices_);
  if (faceSizes_.empty()) throw InvalidInputError("the control mesh has no faces");
  if (faceSizes_.size() > static_cast<size_t>(std::numeric_limits<int>::max()) ||
      faceIndices_.size() > static_cast<size_t>(std::numeric_limits<int>::max())) {
    throw InvalidInputError("the control mesh has more faces or face corners than the core's 32-bit ids can number");
  }
  // Offsets summed in 64 bits and checked against the indices given before any index is read.
  faceOffsets_.assign(faceSizes_.size() + 1, 0);
  long long offset = 0;
  for (int f = 0; f < numFaces(); ++f) {
    if (faceSizes_[at(f)] < 3) {
      throw InvalidInputError("face " + std::to_string(f) + " has " +
                              std::to_string(faceSizes_[at(f)]) +
                              " vertices (a face needs at least 3)");
    }
    offset += faceSizes_[at(f)];
    if (offset > static_cast<long long>(faceIndices_.size())) {
      throw InvalidInputError("the face sizes of faces 0.." + std::to_string(f) + " already add up to " +
                              std::to_string(offset) + ", but only " + std::to_string(faceIndices_.size()) +
                              " face vertex indices were given");
    }
    faceOffsets_[at(f) + 1] = static_cast<int>(offset);
  }
  if (at(faceOffsets_.back()) != faceIndices_.size()) {
    throw InvalidInputError("the face sizes add up to " + std::to_string(faceOffsets_.back()) +
                            " but " + std::to_string(faceIndices_.size()) +
                            " face vertex indices were given");
  }
  std::vector<int> sorted;
  for (int f = 0; f < numFaces(); ++f) {
    for (int i = 0; i < faceSize(f); ++i) {
      const int v = faceVertex(f, i);
      if (v < 0 || v >= numVertices()) {
        throw InvalidInputError("face " + std::to_string(f) + " refers to vertex " +
                                std::to_string(v) + ", but the mesh has " +
                                std::to_string(numVertices()) + " vertices");
      }
    }
    // Repeated vertices: pairwise for small faces, by sorting for large polygons (linear-log).
    const int n = faceSize(f);
    sorted.assign(faceIndices_.begin() + faceOffsets_[at(f)], faceIndices_.begin() + faceOffsets_[at(f) + 1]);
    if (n > 16) std::sort(sorted.begin(), sorted.end());
    for (int i = 1; i < n; ++i) {
      const int v = sorted[static_cast<size_t>(i)];
      const bool repeated = n > 16 ? sorted[static_cast<size_t>(i - 1)] == v
                                   : std::find(sorted.begin(), sorted.begin() + i, v) != sorted.begin() + i;
      if (repeated) throw TopologyError("face " + std::to_string(f) + " repeats vertex " + std::to_string(v));
    }
  }
  buildConnectivity();
  validateGeometry(vertices_);
  validateCreases();
  validateCorners();
}

void ControlMesh::buildConnectivity() {
  const size_t numCorners = faceIndices_.size();
  // Bucket every half-edge under its smaller end point; edges are found by scanning a bucket.
  std::vector<int> bucketOffsets(at(numVertices()) + 1, 0);
  for (int f = 0; f < numFaces(); ++f) {
    for (int i = 0; i < faceSize(f); ++i) {
      const int a = faceVertex(f, i), b = faceVertex(f, (i + 1) % faceSize(f));
      ++bucketOffsets[at(std::min(a, b)) + 1];
    }
  }
  std::partial_sum(bucketOffsets.begin(), bucketOffsets.end(), bucketOffsets.begin());
  std::vector<int> bucketFill(bucketOffsets.begin(), bucketOffsets.end() - 1);
  std::vector<int> bucketEdges(numCorners);

  std::vector<std::array<int, 2>> edges;
  std::vector<std::array<int, 2>> edgeFaces;
  std::vector<int> edgeFirstCorner;  // global corner index where the first face starts the edge
  edges.reserve(numCorners / 2 + 1);
  edgeFaces.reserve(numCorners / 2 + 1);
  edgeFirstCorner.reserve(numCorners / 2 + 1);
  faceEdges_.assign(numCorners, -1);
  // Two corners of one vertex are joined when the faces meet at an edge through that vertex, so a
  // manifold vertex ends with a single set (one fan).
  DisjointSets fans(numCorners);
  vertexFirstCorner_ = RowMatrixX2i::Constant(numVertices(), 2, -1);

  for (int f = 0; f < numFaces(); ++f) {
    const int size = faceSize(f);
    const int offset = faceOffsets_[at(f)];
    for (int i = 0; i < size; ++i) {
      const int a = faceVertex(f, i), b = faceVertex(f, (i + 1) % size);
      if (vertexFirstCorner_(a, 0) < 0) vertexFirstCorner_.row(a) << f, i;
      const int lo = std::min(a, b), hi = std::max(a, b);
      int edge = -1;
      for (int k = bucketOffsets[at(lo)]; k < bucketFill[at(lo)]; ++k) {
        const int candidate = bucketEdges[at(k)];
        if (edges[at(candidate)][0] + edges[at(candidate)][1] - lo == hi) {
          edge = candidate;
          break;
        }
      }
      if (edge < 0) {
        edge = static_cast<int>(edges.size());
        edges.push_back({a, b});
        edgeFaces.push_back({f, -1});
        edgeFirstCorner.push_back(offset + i);
        bucketEdges[at(bucketFill[at(lo)]++)] = edge;
      } else {
        auto& faces = edgeFaces[at(edge)];
        if (faces[1] >= 0) {
          throw TopologyError("edge " + std::to_string(edge) + " " + pairText(a, b) +
                              " is shared by more than two faces (faces " +
                              std::to_string(faces[0]) + ", " + std::to_string(faces[1]) + " and " +
                              std::to_string(f) + ")");
        }
        if (edges[at(edge)][0] == a) {
          throw TopologyError("faces " + std::to_string(faces[0]) + " and " + std::to_string(f) +
                              " are inconsistently oriented: both traverse edge " + pairText(a, b) +
                              " from vertex " + std::to_string(a) + " to " + std::to_string(b));
        }
        faces[1] = f;
        // First face has a at its corner c and b at c+1; this face has b at i and a at i+1.
        const int first = edgeFirstCorner[at(edge)];
        const int firstFace = faces[0];
        const int firstNext = faceOffsets_[at(firstFace)] +
                              (first - faceOffsets_[at(firstFace)] + 1) % faceSize(firstFace);
        fans.join(first, offset + (i + 1) % size);
        fans.join(firstNext, offset + i);
      }
      faceEdges_[at(offset + i)] = edge;
    }
  }

  const int numEdgesFound = static_cast<int>(edges.size());
  edges_.resize(numEdgesFound, 2);
  edgeFaces_.resize(numEdgesFound, 2);
  for (int e = 0; e < numEdgesFound; ++e) {
    edges_.row(e) << edges[at(e)][0], edges[at(e)][1];
    edgeFaces_.row(e) << edgeFaces[at(e)][0], edgeFaces[at(e)][1];
  }

  for (int v = 0; v < numVertices(); ++v) {
    if (vertexFirstCorner_(v, 0) < 0) {
      throw TopologyError("vertex " + std::to_string(v) + " is not used by any face");
    }
  }
  std::vector<int> vertexFan(at(numVertices()), -1);
  for (int f = 0; f < numFaces(); ++f) {
    for (int i = 0; i < faceSize(f); ++i) {
      const int v = faceVertex(f, i);
      const int fan = fans.find(faceOffsets_[at(f)] + i);
      if (vertexFan[at(v)] < 0) {
        vertexFan[at(v)] = fan;
      } else if (vertexFan[at(v)] != fan) {
        throw TopologyError("vertex " + std::to_string(v) +
                            " is non-manifold: its faces form more than one fan (e.g. faces " +
                            std::to_string(vertexFirstCorner_(v, 0)) + " and " + std::to_string(f) +
                            " meet only at this vertex)");
      }
    }
  }

  vertexEdgeOffsets_.assign(at(numVertices()) + 1, 0);
  for (int e = 0; e < numEdgesFound; ++e) {
    ++vertexEdgeOffsets_[at(edges_(e, 0)) + 1];
    ++vertexEdgeOffsets_[at(edges_(e, 1)) + 1];
  }
  std::partial_sum(vertexEdgeOffsets_.begin(), vertexEdgeOffsets_.end(),
                   vertexEdgeOffsets_.begin());
  std::vector<int> fill(vertexEdgeOffsets_.begin(), vertexEdgeOffsets_.end() - 1);
  vertexEdges_.resize(at(vertexEdgeOffsets_.back()));
  for (int e = 0; e < numEdgesFound; ++e) {
    vertexEdges_[at(fill[at(edges_(e, 0))]++)] = e;
    vertexEdges_[at(fill[at(edges_(e, 1))]++)] = e;
  }
}

void ControlMesh::validateGeometry(const RowMatrixX3d& vertices) const {
  // Measured in coordinates centred on the mesh and divided by its largest extent, so that
  // neither units nor scale matter (a mesh at 1e154 or 1e-160 would overflow or underflow the
  // cross products otherwise); tolerances are relative to that extent.
  const Eigen::RowVector3d lo = vertices.colwise().minCoeff(), hi = vertices.colwise().maxCoeff();
  const double extent = (hi - lo).lpNorm<Eigen::Infinity>();
  const double scale = extent > 0.0 && std::isfinite(extent) ? extent : 1.0;
  const Eigen::Vector3d centre = (0.5 * lo + 0.5 * hi).transpose();
  const double lengthTolerance = 1e-12;
  for (int f = 0; f < numFaces(); ++f) {
    const int size = faceSize(f);
    // The area is judged against the face's own size (a small face far from a large mesh's
    // centre, e.g. a boundary-layer face in a far-field mesh, is not degenerate), with the
    // corners taken relative to the first one so that rounding scales with the face too.
    const Eigen::Vector3d origin = (vertices.row(faceVertex(f, 0)).transpose() - centre) / scale;
    Eigen::Vector3d areaVector = Eigen::Vector3d::Zero();
    double squaredEdges = 0.0;
    for (int i = 0; i < size; ++i) {
      const int a = faceVertex(f, i), b = faceVertex(f, (i + 1) % size);
      const Eigen::Vector3d pa = (vertices.row(a).transpose() - centre) / scale - origin;
      const Eigen::Vector3d pb = (vertices.row(b).transpose() - centre) / scale - origin;
      if ((pb - pa).norm() <= lengthTolerance) {
        throw InvalidInputError("face " + std::to_string(f) + " is degenerate: vertices " +
                                std::to_string(a) + " and " + std::to_string(b) + " coincide");
      }
      areaVector += pa.cross(pb);
      squaredEdges += (pb - pa).squaredNorm();
    }
    if (0.5 * areaVector.norm() <= 1e-12 * squaredEdges) {
      throw InvalidInputError("face " + std::to_string(f) + " is degenerate: its area is zero");
    }
  }
}

void ControlMesh::validateCreases() {
  const int count = static_cast<int>(creases_.rows());
  if (creaseSharpness_.size() == 0) {
    creaseSharpness_ = Eigen::VectorXd::Constant(count, kInfiniteSharpness);
  }
  if (creaseSharpness_.size() != count) {
    throw InvalidInputError("got " + std::to_string(count) + " creases but " +
                            std::to_string(creaseSharpness_.size()) + " sharpness values");
  }
  edgeSharpness_ = Eigen::VectorXd::Zero(numEdges());
  creaseEdges_.assign(at(count), -1);
  for (int c = 0; c < count; ++c) {
    const int a = creases_(c, 0), b = creases_(c, 1);
    const std::string name = "crease " + std::to_string(c) + " " + pairText(a, b);
    if (a < 0 || a >= numVertices() || b < 0 || b >= numVertices()) {
      throw InvalidInputError(name + " refers to a vertex outside 0.." +
                              std::to_string(numVertices() - 1));
    }
    const double sharpness = creaseSharpness_(c);
    if (!(sharpness > 0.0)) {
      throw InvalidInputError(name + " has sharpness " + numberText(sharpness) + " (must be > 0)");
    }
    const int edge = findEdge(a, b);
    if (edge < 0) throw TopologyError(name + " is not an edge of the mesh");
    if (edgeSharpness_(edge) > 0.0) {
      throw InvalidInputError(name + " repeats edge " + std::to_string(edge));
    }
    edgeSharpness_(edge) = sharpness;
    creaseEdges_[at(c)] = edge;
  }
}

void ControlMesh::validateCorners() {
  const int count = static_cast<int>(corners_.size());
  if (cornerSharpness_.size() == 0) {
    cornerSharpness_ = Eigen::VectorXd::Constant(count, kInfiniteSharpness);
  }
  if (cornerSharpness_.size() != count) {
    throw InvalidInputError("got " + std::to_string(count) + " corners but " +
                            std::to_string(cornerSharpness_.size()) + " sharpness values");
  }
  std::vector<bool> seen(at(numVertices()), false);
  for (int c = 0; c < count; ++c) {
    const int v = corners_[at(c)];
    const std::string name = "corner " + std::to_string(c) + " (vertex " + std::to_string(v) + ")";
    if (v < 0 || v >= numVertices()) {
      throw InvalidInputError(name + " is outside 0.." + std::to_string(numVertices() - 1));
    }
    if (!(cornerSharpness_(c) > 0.0)) {
      throw InvalidInputError(name + " has sharpness " + numberText(cornerSharpness_(c)) + " (must be > 0)");
    }
    if (seen[at(v)]) throw InvalidInputError(name + " is listed twice");
    seen[at(v)] = true;
  }
}

void ControlMesh::setVertices(const RowMatrixX3d& vertices) {
  checkPointCount(vertices, numVertices(), "vertex positions");
  validateGeometry(vertices);
  vertices_ = vertices;
}

bool ControlMesh::isAllQuads() const {
  return std::all_of(faceSizes_.begin(), faceSizes_.end(), [](int size) { return size == 4; });
}

int ControlMesh::findEdge(int v0, int v1) const {
  if (v0 < 0 || v0 >= numVertices() || v1 < 0 || v1 >= numVertices()) return -1;
  for (int k = vertexEdgeOffsets_[at(v0)]; k < vertexEdgeOffsets_[at(v0) + 1]; ++k) {
    const int e = vertexEdges_[at(k)];
    if (edges_(e, 0) + edges_(e, 1) - v0 == v1) return e;
  }
  return -1;
}

std::vector<int> ControlMesh::boundaryEdges() const {
  std::vector<int> result;
  for (int e = 0; e < numEdges(); ++e) {
    if (isBoundaryEdge(e)) result.push_back(e);
  }
  return result;
}

}  // namespace bvmesh

// ControlMesh: the control polyhedron of a Catmull-Clark surface. Vertex positions, polygon
// faces of any size, crease edges and corner vertices with sharpness, and the derived edge and
// boundary connectivity. The constructor validates everything and throws InvalidInputError
// (bad values or indices) or TopologyError (unusable connectivity) naming the offending element.
#pragma once

#include <Eigen/Core>

#include <limits>
#include <vector>

namespace bvmesh {

using RowMatrixX3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using RowMatrixX2i = Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor>;

// Sharpness of a crease edge or corner vertex that stays sharp at every level.
inline constexpr double kInfiniteSharpness = std::numeric_limits<double>::infinity();

class ControlMesh {
public:
  // vertices:          #V x 3 positions (finite)
  // faceSizes:         #F vertex counts per face (each >= 3)
  // faceIndices:       sum(faceSizes) vertex indices, the faces one after the other,
  //                    counter-clockwise seen from the side the normal points to
  // creases:           #C x 2 vertex pairs; every pair must be an edge of a face
  // creaseSharpness:   #C sharpness values > 0 (infinite = kInfiniteSharpness), or empty for
  //                    all infinite
  // corners:           #K corner vertex indices
  // cornerSharpness:   #K sharpness values > 0, or empty for all infinite
  ControlMesh(RowMatrixX3d vertices, std::vector<int> faceSizes, std::vector<int> faceIndices,
              RowMatrixX2i creases = RowMatrixX2i(0, 2),
              Eigen::VectorXd creaseSharpness = Eigen::VectorXd(), std::vector<int> corners = {},
              Eigen::VectorXd cornerSharpness = Eigen::VectorXd());

  int numVertices() const { return static_cast<int>(vertices_.rows()); }
  int numFaces() const { return static_cast<int>(faceSizes_.size()); }
  int numEdges() const { return static_cast<int>(edges_.rows()); }

  // #V x 3 vertex positions.
  const RowMatrixX3d& vertices() const { return vertices_; }
  // Replaces the positions (same topology): #V x 3, finite, no face may become degenerate.
  void setVertices(const RowMatrixX3d& vertices);

  const std::vector<int>& faceSizes() const { return faceSizes_; }
  const std::vector<int>& faceIndices() const { return faceIndices_; }
  // #F + 1 offsets into faceIndices(): face f is faceIndices()[faceOffsets()[f] ..
  // faceOffsets()[f+1]).
  const std::vector<int>& faceOffsets() const { return faceOffsets_; }
  int faceSize(int face) const { return faceSizes_[static_cast<size_t>(face)]; }
  int faceVertex(int face, int corner) const {
    return faceIndices_[static_cast<size_t>(faceOffsets_[static_cast<size_t>(face)] + corner)];
  }
  bool isAllQuads() const;

  // #E x 2 edge end points. Edges are numbered in order of first use when walking the faces
  // (face 0 corner 0, face 0 corner 1, ...), oriented as in the first face that uses them.
  const RowMatrixX2i& edges() const { return edges_; }
  // #E x 2 faces on either side of each edge: the first face using it, then the second or -1.
  const RowMatrixX2i& edgeFaces() const { return edgeFaces_; }
  // sum(faceSizes) edge ids parallel to faceIndices(): entry offset(f)+i is the edge from
  // corner i to corner i+1 of face f.
  const std::vector<int>& faceEdges() const { return faceEdges_; }
  int faceEdge(int face, int corner) const {
    return faceEdges_[static_cast<size_t>(faceOffsets_[static_cast<size_t>(face)] + corner)];
  }
  // Edge id of the vertex pair (either order), or -1.
  int findEdge(int v0, int v1) const;
  bool isBoundaryEdge(int edge) const { return edgeFaces_(edge, 1) < 0; }
  // Ids of the edges with a single face, ascending.
  std::vector<int> boundaryEdges() const;

  // The first (face, corner) that uses each vertex, in face order: #V x 2.
  const RowMatrixX2i& vertexFirstCorner() const { return vertexFirstCorner_; }

  // #C x 2 crease vertex pairs, as given.
  const RowMatrixX2i& creases() const { return creases_; }
  // #C crease sharpness values (kInfiniteSharpness for infinitely sharp creases).
  const Eigen::VectorXd& creaseSharpness() const { return creaseSharpness_; }
  // #C edge ids of the creases.
  const std::vector<int>& creaseEdges() const { return creaseEdges_; }
  // #E sharpness per edge (0 for smooth edges; boundary edges report 0 as well).
  const Eigen::VectorXd& edgeSharpness() const { return edgeSharpness_; }

  const std::vector<int>& corners() const { return corners_; }
  const Eigen::VectorXd& cornerSharpness() const { return cornerSharpness_; }

private:
  void validateGeometry(const RowMatrixX3d& vertices) const;
  void buildConnectivity();
  void validateCreases();
  void validateCorners();

  RowMatrixX3d vertices_;
  std::vector<int> faceSizes_;
  std::vector<int> faceIndices_;
  std::vector<int> faceOffsets_;
  RowMatrixX2i edges_;
  RowMatrixX2i edgeFaces_;
  std::vector<int> faceEdges_;
  // Vertex -> incident edges in CSR form, for findEdge.
  std::vector<int> vertexEdgeOffsets_;
  std::vector<int> vertexEdges_;
  RowMatrixX2i vertexFirstCorner_;
  RowMatrixX2i creases_;
  Eigen::VectorXd creaseSharpness_;
  std::vector<int> creaseEdges_;
  Eigen::VectorXd edgeSharpness_;
  std::vector<int> corners_;
  Eigen::VectorXd cornerSharpness_;
};

}  // namespace bvmesh

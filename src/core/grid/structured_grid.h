// The discrete volume grid a flow solver reads: per block a structured (ni, nj, nk) array of
// points, evaluated from the B-spline blocks, with the block mesh's face connectivity and
// boundary conditions. Connected faces are point-matched: their points are identical bit for bit.
#pragma once

#include <array>
#include <vector>

#include "core/common/types.h"
#include "core/volume/block_mesh.h"

namespace bvmesh::grid {

struct GridBlock {
  std::array<int, 3> size{0, 0, 0};  // points along i, j, k (the B-spline block's u, v, w)
  RowMatrixX3d points;               // point (i, j, k) at row i + ni * (j + nj * k)
  // Per face (volume::BlockFaceSide order) its condition or its connection; a connection maps
  // face point positions (a, b) as volume::BlockMesh::mapFacePosition does for poles.
  std::array<volume::BlockFace, 6> faces;
  // Per face, empty (every quad has the face's condition) or the condition of each quad (a, b),
  // at a + (na - 1) b for the face's point counts (na, nb): an outer face of a box or cylinder
  // domain that bends over the domain's edges is inlet, outlet or side quad by quad.
  std::array<std::vector<volume::BoundaryCondition>, 6> quadConditions;

  Eigen::Index index(int i, int j, int k) const {
    return i + static_cast<Eigen::Index>(size[0]) * (j + static_cast<Eigen::Index>(size[1]) * k);
  }
  Eigen::Index pointCount() const { return static_cast<Eigen::Index>(size[0]) * size[1] * size[2]; }
  Eigen::Index cellCount() const { return static_cast<Eigen::Index>(size[0] - 1) * (size[1] - 1) * (size[2] - 1); }
  // The row of face point (a, b) of `face`.
  Eigen::Index facePoint(int face, int a, int b) const;
  // The condition of quad (a, b) of a boundary face.
  volume::BoundaryCondition quadCondition(int face, int a, int b) const;
};

class StructuredGrid {
 public:
  StructuredGrid() = default;
  // Validates: at least 2 points per direction, point rows matching the sizes, finite points,
  // connections as volume::checkFaceConnections requires, connected faces' points identical bit
  // for bit, collapsed faces one point along the axes their collapsedAlong names (found from the
  // points where it names none). Throws InvalidInputError naming the block, face and point.
  // viscousWall: the grid resolves the boundary layer (wall spacing for y+ ~ 1), so solver files
  // call the wall viscous (CGNS BCWallViscous) rather than inviscid (BCWall).
  explicit StructuredGrid(std::vector<GridBlock> blocks, bool viscousWall = false);

  const std::vector<GridBlock>& blocks() const { return blocks_; }
  int blockCount() const { return static_cast<int>(blocks_.size()); }
  bool viscousWall() const { return viscousWall_; }
  Eigen::Index pointCount() const;  // over all blocks, shared points counted once per block
  Eigen::Index cellCount() const;

 private:
  // Throws unless block b's face f has the points of the neighbour face it is connected to.
  void checkPointMatching(size_t b, int f) const;
  // Sets block b's face f's collapsedAlong: for a collapsed face from its points (throws when
  // they are not one point along either axis), none otherwise.
  void findCollapsedAxes(size_t b, int f);

  std::vector<GridBlock> blocks_;
  bool viscousWall_ = false;
};

// Every distinct point of the grid once: connected faces' points merged (unstructured writers
// such as OpenFOAM's polyMesh number points this way).
struct MergedPoints {
  RowMatrixX3d points;                    // distinct points, in order of first appearance
  std::vector<Eigen::Index> blockOffset;  // block b's point r is pointOf[blockOffset[b] + r]
  std::vector<Eigen::Index> pointOf;
};

MergedPoints mergePoints(const StructuredGrid& grid);

}  // namespace bvmesh::grid

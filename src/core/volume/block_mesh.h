// The block-structured volume mesh: B-spline volume blocks, the face-to-face connectivity between
// them (with orientation) and a boundary condition on every other block face; and the volume
// control mesh, the blocks' control nets merged into one hexahedral mesh.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/volume/bspline_volume.h"

namespace bvmesh::volume {

// Block faces: u = min, u = max, v = min, v = max, w = min, w = max (G+Smo's sides 1..6). A face's
// pole grid is indexed (a, b) along its two other directions in increasing order: (v, w) on u
// faces, (u, w) on v faces, (u, v) on w faces.
enum class BlockFaceSide { UMin = 0, UMax = 1, VMin = 2, VMax = 3, WMin = 4, WMax = 5 };

// Collapsed: the face is no surface but a curve or a point (an axis or a sharp edge that the
// block fans out from): its grid is one point along one or both of its directions, so it
// bounds nothing and its cells are prisms there (tetrahedral wedges where two meet, pyramids on a point).
enum class BoundaryCondition { Connected, Wall, Symmetry, Farfield, Inlet, Outlet, Side, Collapsed };

const char* boundaryConditionName(BoundaryCondition condition);
// The condition boundaryConditionName calls `name`, if any.
std::optional<BoundaryCondition> findBoundaryCondition(const std::string& name);
const char* blockFaceName(int face);

// Face indexing shared by pole grids and point grids of `counts` (per direction): the two
// directions along a face, the face grid's sizes, and the (i, j, k) of face position (a, b).
std::array<int, 2> faceDirections(int face);
std::array<int, 2> faceGridCounts(const std::array<int, 3>& counts, int face);
std::array<int, 3> faceGridPosition(const std::array<int, 3>& counts, int face, int a, int b);

// Rows (i fastest, then j, then k) of a face's grid positions as a linear function of (a, b):
// base + a * first + b * second, so a loop over a face needs no per-position lookup.
struct FaceRows {
  Eigen::Index base = 0, first = 0, second = 0;
  Eigen::Index at(int a, int b) const { return base + a * first + b * second; }
};
FaceRows faceRows(const std::array<int, 3>& counts, int face);

// Where a connected face continues: face pole (a, b) is neighbour face pole (a', b'), where
// (a', b') = swapped ? (b, a) : (a, b), then a' -> n'_a - 1 - a' if reverseFirst and
// b' -> n'_b - 1 - b' if reverseSecond (n' the neighbour face's pole counts).
struct FaceConnection {
  int block = -1;
  int face = -1;
  bool swapped = false;
  bool reverseFirst = false;
  bool reverseSecond = false;
};

struct BlockFace {
  BoundaryCondition condition = BoundaryCondition::Farfield;
  FaceConnection neighbour;  // used when condition == Connected
  // With condition Collapsed: per face axis (a, b), whether the face's grid is one point along it
  // (every row along that axis); found from the poles by BlockMesh.
  std::array<bool, 2> collapsedAlong{false, false};
};

// Per face axis, whether `grid` (poles or points of a block with `counts` per direction, row i
// fastest) is one point along it on `face`: every row along that axis identical bit for bit.
std::array<bool, 2> coincidentAlongFace(const RowMatrixX3d& grid, const std::array<int, 3>& counts, int face);

// The axes along which a face with condition Collapsed is one point (coincidentAlongFace); throws
// InvalidInputError naming it (`faceName`, e.g. "block 3 face w_min") and what `grid` holds
// (`pointsName`: "poles", "points") when it is one along neither.
std::array<bool, 2> collapsedFaceAxes(const RowMatrixX3d& grid, const std::array<int, 3>& counts, int face,
                                      const std::string& faceName, const std::string& pointsName);

struct Block {
  BsplineVolume volume;
  std::array<BlockFace, 6> faces;
};

// Checks every connected face among blocks with these faces and grid sizes (poles or points per
// direction): the neighbour exists, links back with the inverse orientation, and has the same
// number of `unit` ("poles", "points") along the shared face. Throws InvalidInputError naming
// the block and face.
void checkFaceConnections(const std::vector<std::array<BlockFace, 6>>& faces,
                          const std::vector<std::array<int, 3>>& counts, const char* unit);

// Positions of block grids (poles or points; sizes per direction in `counts`) that connected faces
// join, or that a collapsed face makes one: position r of block b has the global number
// offset[b] + r (offset: the running sum of the blocks' sizes, row r = i + n_i * (j + n_j * k)).
// Returns for every global number the smallest global number it is shared with (itself when
// unshared).
std::vector<Eigen::Index> sharedGridRoots(const std::vector<std::array<BlockFace, 6>>& faces,
                                          const std::vector<std::array<int, 3>>& counts);

class BlockMesh {
 public:
  BlockMesh() = default;
  // Validates: connections in range and mutual (the neighbour's face points back with the inverse
  // orientation), matching pole counts and knot vectors (mirrored where reversed) along connected
  // faces, connected faces' poles identical bit for bit, and collapsed faces' poles one point
  // along at least one direction (which it records in their collapsedAlong). Throws
  // InvalidInputError naming the block and face.
  explicit BlockMesh(std::vector<Block> blocks);

  const std::vector<Block>& blocks() const { return blocks_; }
  int blockCount() const { return static_cast<int>(blocks_.size()); }

  // Pole counts of a face's grid (a, b), and the pole row of face position (a, b).
  static std::array<int, 2> facePoleCounts(const BsplineVolume& volume, int face);
  static Eigen::Index facePole(const BsplineVolume& volume, int face, int a, int b);
  // The neighbour face position of face position (a, b) under `connection`.
  static std::array<int, 2> mapFacePosition(const FaceConnection& connection, const std::array<int, 2>& neighbourCounts,
                                            int a, int b);
  // The neighbour's rows of face position (a, b) under `connection` (`neighbourCounts` the
  // neighbour block's grid sizes): mapFacePosition followed by faceRows, as one linear function.
  static FaceRows neighbourFaceRows(const FaceConnection& connection,
                                    const std::array<int, 3>& neighbourCounts);

 private:
  std::vector<Block> blocks_;
};

// The blocks' control nets as one mesh of hexahedral control cells: poles shared by connected faces
// (or made one by a collapsed face) merged into one point, every boundary face of a cell tagged
// with its block face's condition (a collapsed face has none).
struct VolumeControlMesh {
  RowMatrixX3d points;                           // #P x 3
  std::vector<std::array<int, 8>> cells;         // corners (i, j, k) order: 000 100 110 010 001 101 111 011
  std::vector<int> cellBlock;                    // block of each cell
  std::vector<std::array<int, 4>> boundaryFaces; // quads of cell corners on block faces that are not connected
  std::vector<BoundaryCondition> boundaryConditions;
  std::vector<int> blockPointOffset;             // pole (block b, row r) -> points row pointOfPole[offset[b] + r]
  std::vector<int> pointOfPole;
};

VolumeControlMesh volumeControlMesh(const BlockMesh& mesh);

}  // namespace bvmesh::volume

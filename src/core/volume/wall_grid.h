// The wall patches' marching surface grid: their Greville points, merged where patches meet, with
// the corners of three or more wall faces and the points on the boundary planes marked.
#pragma once

#include <Eigen/Core>

#include <array>
#include <utility>
#include <vector>

#include "core/volume/block_mesh.h"
#include "core/volume/marching.h"
#include "core/volume/volume_options.h"
#include "core/volume/wall_patches.h"

namespace bvmesh::volume {

// The marching surface grid: every patch's Greville points, merged where patches meet.
struct WallGrid {
  MarchingFront front;
  std::vector<std::vector<int>> pointOf;  // per patch: (i, j) -> front point, at i * vPoles + j
  // Per point: three or more faces of the wall meet there (their normals more than 30 degrees apart),
  // a corner without a normal to leave the wall along (a tip's trailing-edge corner).
  std::vector<char> corner;
  double size = 0.0;                      // bounding-box diagonal
  Eigen::Vector3d lo, hi;
};

// A side's identity: the canonical (lexicographically smaller direction) vertex chain, and which
// copy of it the side lies on where a knife edge's chain is cut open (edge_fans.h).
struct SideKey {
  std::pair<std::vector<int>, int> id;  // (chain, copy)
  bool reversed = false;                // the patch runs against the canonical direction
};

SideKey sideKey(const WallPatch& patch, ChartSide side);

WallGrid wallGrid(const std::vector<WallPatch>& patches);

// Marks the wall grid's points on open patch sides with the boundary planes they lie on (the
// symmetry plane, the outflow plane; a point where the wall's boundary turns from one to the other
// lies on both) and returns per patch side the condition of an open side's block face (symmetry or
// outlet; connected for the others). Throws when the wall is open without a plane or an open side
// lies off the planes, and when a plane is given but the wall does not end on it or reaches across it.
std::vector<std::array<BoundaryCondition, 4>> markPlanePoints(const std::vector<WallPatch>& patches,
                                                              WallGrid& grid,
                                                              const VolumeMeshOptions& options);

}  // namespace bvmesh::volume

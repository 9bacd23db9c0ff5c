// Cell quality of a volume grid, with OpenFOAM's definitions where a solver user will compare
// against checkMesh: face and cell centres by OpenFOAM's triangle / pyramid decomposition, face
// non-orthogonality (angle between the face's area vector and the line joining the two cell
// centres), face skewness (OpenFOAM's normalised distance from the face centre to where that line
// crosses the face); plus the scaled Jacobian (minimum over the 8 corners), the aspect ratio
// (longest over shortest mean edge length of the cell's three directions), the growth ratio
// (largest volume ratio to a face neighbour), OpenFOAM's cell determinant, and at the wall the
// angle of the wall cells' normal direction to the wall's normal and the first cell height.
#pragma once

#include <string>
#include <vector>

#include "core/grid/hex_topology.h"

namespace bvmesh::quality {

struct CellQuality {
  // Per cell, in HexTopology order (block by block, i fastest).
  std::vector<double> scaledJacobian;
  std::vector<double> nonOrthogonality;  // degrees, worst face of the cell (internal faces)
  std::vector<double> skewness;          // worst face of the cell (all faces)
  std::vector<double> aspectRatio;
  std::vector<double> growthRatio;       // >= 1; 1 for a cell without neighbours
  // OpenFOAM's cell determinant ("wellposedness", checkMesh -allGeometry fails a cell below
  // 1e-3): det of the sum of a a^T over the cell's internal faces' area vectors a, each over
  // their mean length, divided by 8 (1 for a cube; a thin h x a x a cell ~ 729 (h / a)^4).
  std::vector<double> determinant;
  std::vector<double> volume;
  // Per wall cell (block wall faces in order, cell by cell): the angle in degrees between the
  // wall face's normal and the mean of the cell's four edges off the wall. Per wall point (block
  // wall faces, point by point): the length of the first grid line off the wall.
  std::vector<double> wallAngle;
  std::vector<double> firstCellHeight;
};

CellQuality measureCellQuality(const grid::HexTopology& topology);

struct MetricSummary {
  std::string name;
  Eigen::Index count = 0;
  double min = 0.0, p01 = 0.0, median = 0.0, p99 = 0.0, max = 0.0;
};

// Per metric (scaled_jacobian, non_orthogonality, skewness, aspect_ratio, growth_ratio, determinant,
// and with a wall wall_angle, first_cell_height): over all cells, and per block (block = -1: all).
std::vector<MetricSummary> summarizeQuality(const grid::HexTopology& topology, const CellQuality& quality, int block = -1);

// Per cell, the scaled Jacobian alone (what the writers check).
std::vector<double> cellScaledJacobians(const grid::HexTopology& topology);

// Throws InvalidInputError naming the block and cell (i, j, k) of the first cell with a
// non-positive scaled Jacobian: grids with inverted cells are not written unless forced.
void requirePositiveCells(const grid::HexTopology& topology);

}  // namespace bvmesh::quality

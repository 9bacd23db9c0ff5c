#include "core/grid/subdivision_refinement.h"

#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/common/errors.h"
#include "core/grid/point_budget.h"
#include "core/subdiv/limit_evaluator.h"

namespace bvmesh::grid {
namespace {

using volume::HexMesh;

// Corner order of a cell whose i direction is reversed: corner (x, y, z) becomes (1 - x, y, z).
constexpr std::array<size_t, 8> kReversedCorners{1, 0, 3, 2, 5, 4, 7, 6};

struct BlockHexMesh {
  HexMesh mesh;
  std::vector<volume::HexBlock> lattices;
};

BlockHexMesh blockHexMesh(const volume::BlockMesh& blocks) {
  for (int b = 0; b < blocks.blockCount(); ++b) {
    for (int f = 0; f < 6; ++f) {
      if (blocks.blocks()[static_cast<size_t>(b)].faces[static_cast<size_t>(f)].condition ==
          volume::BoundaryCondition::Collapsed) {
        throw InvalidInputError("block " + std::to_string(b) + " face " + volume::blockFaceName(f) +
                                " is collapsed: volumetric subdivision takes hexahedral control cells only "
                                "(refine such blocks by evaluation)");
      }
    }
  }
  const volume::VolumeControlMesh control = volume::volumeControlMesh(blocks);
  BlockHexMesh result;
  result.mesh.points = control.points;
  result.mesh.boundaryFaces = control.boundaryFaces;
  result.mesh.boundaryConditions = control.boundaryConditions;
  int cellBase = 0;
  for (int b = 0; b < blocks.blockCount(); ++b) {
    const volume::BsplineVolume& volume = blocks.blocks()[static_cast<size_t>(b)].volume;
    volume::HexBlock lattice;
    lattice.size = {volume.poleCount(0), volume.poleCount(1), volume.poleCount(2)};
    const size_t cellCount = static_cast<size_t>(lattice.size[0] - 1) * static_cast<size_t>(lattice.size[1] - 1) *
                             static_cast<size_t>(lattice.size[2] - 1);
    // Handedness from the summed corner Jacobians of its cells, as grid::HexTopology decides it.
    double volumeSum = 0.0;
    for (size_t c = 0; c < cellCount; ++c) {
      for (double j : volume::cornerJacobians(control.points, control.cells[static_cast<size_t>(cellBase) + c])) volumeSum += j;
    }
    if (!(volumeSum != 0.0)) throw InvalidInputError("block " + std::to_string(b) + ": its control net has no volume");
    lattice.reversed = volumeSum < 0.0;
    lattice.pointAt.resize(static_cast<size_t>(volume.poles().rows()));
    for (size_t r = 0; r < lattice.pointAt.size(); ++r) {
      lattice.pointAt[r] = control.pointOfPole[static_cast<size_t>(control.blockPointOffset[static_cast<size_t>(b)]) + r];
    }
    lattice.cellAt.resize(cellCount);
    for (size_t c = 0; c < cellCount; ++c) {
      const std::array<int, 8>& corners = control.cells[static_cast<size_t>(cellBase) + c];
      std::array<int, 8> cell = corners;
      if (lattice.reversed) {
        for (size_t q = 0; q < 8; ++q) cell[q] = corners[kReversedCorners[q]];
      }
      result.mesh.cells.push_back(cell);
      // volumeControlMesh lists a block's cells i fastest, as volume::HexBlock::cell numbers them.
      lattice.cellAt[c] = cellBase + static_cast<int>(c);
    }
    cellBase += static_cast<int>(cellCount);
    result.lattices.push_back(std::move(lattice));
  }
  return result;
}

// Limit positions at a control mesh's vertices, for any control points on its topology.
class VertexLimits {
 public:
  explicit VertexLimits(const ControlMesh& mesh) : evaluator_(mesh) {
    const std::vector<int> ptex = ptexFaceOffsets(mesh);
    const RowMatrixX2i& first = mesh.vertexFirstCorner();
    for (Eigen::Index v = 0; v < first.rows(); ++v) locations_.push_back(cornerLocation(mesh, ptex, first(v, 0), first(v, 1)));
  }
  RowMatrixX3d operator()(const RowMatrixX3d& controlPoints) const {
    return evaluator_.evaluate(controlPoints, locations_).positions;
  }

 private:
  LimitEvaluator evaluator_;
  std::vector<SurfaceLocation> locations_;
};

// `steps` subdivision steps of `mesh`, its blocks followed through them, as a grid with the given
// block faces. With `wallDirections` (#P x 3, the direction each point's wall-normal line leaves
// the wall in; empty: none) the wall points end on the wall's limit surface and the first point
// off the wall on each wall-normal line is put along the limit of those directions, at its
// distance: the subdivided directions are those of the marching (along the normals, splayed at
// sharp edges) where the interior rules alone tilt the first cells.
StructuredGrid subdivideHexBlocks(HexMesh mesh, std::vector<volume::HexBlock> lattices,
                                  const std::vector<std::array<volume::BlockFace, 6>>& faces, int steps,
                                  RowMatrixX3d wallDirections, long long maxPoints) {
  if (steps < 0) throw InvalidInputError("subdivision steps must be >= 0, got " + std::to_string(steps));
  const double pointsAfter = static_cast<double>(mesh.points.rows()) * std::pow(8.0, steps);
  checkPointBudget(pointsAfter, maxPoints);
  if (pointsAfter > static_cast<double>(std::numeric_limits<int>::max())) {
    throw InvalidInputError(std::to_string(steps) + " subdivision steps would make about " + std::to_string(pointsAfter) +
                            " points, more than the 2^31 a hex mesh can number");
  }
  const bool shapeWall = wallDirections.rows() > 0;
  for (int step = 0; step < steps; ++step) {
    volume::HexSubdivisionResult refined = volume::subdivideHexMesh(mesh);
    for (volume::HexBlock& lattice : lattices) lattice = volume::refineHexBlock(lattice, refined.mesh);
    if (shapeWall) wallDirections = refined.subdivisionOperator * wallDirections;
    mesh = std::move(refined.mesh);
  }
  if (shapeWall) {
    const volume::WallControlMesh wall = volume::wallControlMesh(mesh);
    RowMatrixX3d wallPoints(static_cast<Eigen::Index>(wall.points.size()), 3);
    RowMatrixX3d wallFieldPoints(static_cast<Eigen::Index>(wall.points.size()), 3);
    for (size_t v = 0; v < wall.points.size(); ++v) {
      wallPoints.row(static_cast<Eigen::Index>(v)) = mesh.points.row(wall.points[v]);
      wallFieldPoints.row(static_cast<Eigen::Index>(v)) = wallDirections.row(wall.points[v]);
    }
    const VertexLimits limits(wall.mesh);
    const RowMatrixX3d limit = limits(wallPoints);
    const RowMatrixX3d direction = limits(wallFieldPoints);
    std::vector<Eigen::Index> localOf(static_cast<size_t>(mesh.points.rows()), -1);
    for (size_t v = 0; v < wall.points.size(); ++v) {
      localOf[static_cast<size_t>(wall.points[v])] = static_cast<Eigen::Index>(v);
      mesh.points.row(wall.points[v]) = limit.row(static_cast<Eigen::Index>(v));
    }
    // The first point off the wall on every wall-normal line (blocks standing on the wall at k = 0).
    for (size_t b = 0; b < lattices.size(); ++b) {
      if (faces[b][static_cast<size_t>(volume::BlockFaceSide::WMin)].condition != volume::BoundaryCondition::Wall) continue;
      const volume::HexBlock& lattice = lattices[b];
      for (int j = 0; j < lattice.size[1]; ++j) {
        for (int i = 0; i < lattice.size[0]; ++i) {
          const int onWall = lattice.pointAt[lattice.point(i, j, 0)];
          const int above = lattice.pointAt[lattice.point(i, j, 1)];
          const Eigen::Index v = localOf[static_cast<size_t>(onWall)];
          if (v < 0) continue;
          const Eigen::RowVector3d d = direction.row(v);
          if (!(d.norm() > 0.0)) continue;
          const double height = (mesh.points.row(above) - mesh.points.row(onWall)).norm();
          mesh.points.row(above) = mesh.points.row(onWall) + height * d.normalized();
        }
      }
    }
  }
  std::vector<GridBlock> gridBlocks;
  for (size_t b = 0; b < lattices.size(); ++b) {
    const volume::HexBlock& lattice = lattices[b];
    GridBlock block;
    block.size = lattice.size;
    block.points.resize(static_cast<Eigen::Index>(lattice.pointAt.size()), 3);
    for (size_t r = 0; r < lattice.pointAt.size(); ++r) {
      block.points.row(static_cast<Eigen::Index>(r)) = mesh.points.row(lattice.pointAt[r]);
    }
    block.faces = faces[b];
    gridBlocks.push_back(std::move(block));
  }
  return StructuredGrid(std::move(gridBlocks));
}

}  // namespace

HexMesh hexMeshOfBlocks(const volume::BlockMesh& blocks) { return blockHexMesh(blocks).mesh; }

StructuredGrid subdivideBlockMesh(const volume::BlockMesh& blocks, int steps, long long maxPoints) {
  BlockHexMesh current = blockHexMesh(blocks);
  std::vector<std::array<volume::BlockFace, 6>> faces;
  for (const volume::Block& block : blocks.blocks()) faces.push_back(block.faces);
  return subdivideHexBlocks(std::move(current.mesh), std::move(current.lattices), faces, steps, RowMatrixX3d(),
                            maxPoints);
}

StructuredGrid subdivideControlVolume(const volume::ControlVolume& volume, int steps, long long maxPoints) {
  // Every point's wall-normal direction: its column's marched direction off the wall.
  RowMatrixX3d directions(volume.mesh.points.rows(), 3);
  const int wall = volume.wallVertices;
  for (Eigen::Index p = 0; p < directions.rows(); ++p) {
    const Eigen::Index v = p % wall;
    directions.row(p) = (volume.mesh.points.row(wall + v) - volume.mesh.points.row(v)).normalized();
  }
  return subdivideHexBlocks(volume.mesh, volume.blocks, volume.blockFaces, steps, std::move(directions), maxPoints);
}

}  // namespace bvmesh::grid

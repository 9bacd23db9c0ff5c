#include "core/volume/control_volume.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "core/common/errors.h"
#include "core/common/number_text.h"
#include "core/subdiv/limit_evaluator.h"
#include "core/surface/limit_points.h"
#include "core/volume/wall_patches.h"
#include "core/volume/wall_topology.h"

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

// Per wall vertex the mean of the unit limit normals of its faces at it: one normal where the
// limit surface is smooth, the mean of both sides' at a crease (the grid line then leaves along
// it, as the B-spline blocks' lines do at chart borders on creases). A face whose limit normal
// vanishes at the vertex (a corner with a single crease, where the limit tangents are parallel)
// gives its control face's normal instead.
RowMatrixX3d meanLimitNormals(const surface::QuadControlMesh& wall, const ControlMesh& mesh) {
  const LimitEvaluator evaluator(mesh);
  const std::vector<int> ptex = ptexFaceOffsets(mesh);
  const auto faces = static_cast<int>(wall.faces.rows());
  std::vector<SurfaceLocation> locations;
  locations.reserve(static_cast<size_t>(4 * faces));
  for (int f = 0; f < faces; ++f) {
    for (int k = 0; k < 4; ++k) locations.push_back(cornerLocation(mesh, ptex, f, k));
  }
  const LimitEvaluation limit = evaluator.evaluate(wall.vertices, locations);
  RowMatrixX3d normals = RowMatrixX3d::Zero(wall.vertices.rows(), 3);
  for (int f = 0; f < faces; ++f) {
    const Vector3d a = wall.vertices.row(wall.faces(f, 0)), b = wall.vertices.row(wall.faces(f, 1));
    const Vector3d c = wall.vertices.row(wall.faces(f, 2)), d = wall.vertices.row(wall.faces(f, 3));
    const Vector3d faceNormal = (c - a).cross(d - b).normalized();
    for (int k = 0; k < 4; ++k) {
      const Vector3d n = limit.normals.row(4 * f + k);
      normals.row(wall.faces(f, k)) += (n.norm() > 0.5 && n.allFinite() ? n : faceNormal).transpose();
    }
  }
  for (Eigen::Index v = 0; v < normals.rows(); ++v) {
    const double length = normals.row(v).norm();
    if (!(length > 1e-12)) {
      const Vector3d x = wall.vertices.row(v);
      throw SolverError("the wall has no normal at control vertex " + std::to_string(v) + " (" +
                        coordinatesText(x) + "): its faces' normals cancel (a folded wall)");
    }
    normals.row(v) /= length;
  }
  return normals;
}

}  // namespace

ControlVolume controlVolumeMesh(const surface::QuadControlMesh& wall, const VolumeMeshOptions& options) {
  surface::validateQuadControlMesh(wall);
  requireMarchableWall(wall, options.hasSymmetryPlane || options.hasOutflowPlane);
  const BoundaryPlanes planes = boundaryPlanesOf(options);
  const auto wallVertices = static_cast<int>(wall.vertices.rows());
  const auto quads = static_cast<int>(wall.faces.rows());

  const ControlMesh wallMesh = surface::toControlMesh(wall);
  MarchingFront front;
  front.points = wall.vertices;
  front.normals = meanLimitNormals(wall, wallMesh);
  front.onPlanes.assign(static_cast<size_t>(wallVertices), 0);
  for (int f = 0; f < quads; ++f) {
    front.quads.push_back({wall.faces(f, 0), wall.faces(f, 1), wall.faces(f, 2), wall.faces(f, 3)});
    front.quadNames.push_back("wall control face " + std::to_string(f));
  }
  // The open boundary must lie on the symmetry plane or the outflow plane; its vertices are put on
  // them exactly, so that the faces swept from it are planar (volumetric subdivision keeps them so).
  std::vector<std::pair<int, int>> openEdges;  // as their face runs them
  for (int e : wallMesh.boundaryEdges()) openEdges.emplace_back(wallMesh.edges()(e, 0), wallMesh.edges()(e, 1));
  const double size = (front.points.colwise().maxCoeff() - front.points.colwise().minCoeff()).norm();
  std::vector<int> facesAt(static_cast<size_t>(wallVertices), 0);
  for (int f = 0; f < quads; ++f) {
    for (int k = 0; k < 4; ++k) ++facesAt[static_cast<size_t>(wall.faces(f, k))];
  }
  std::vector<BoundaryCondition> openEdgeCondition;  // per open edge, the plane it lies on
  for (const auto& [a, b] : openEdges) {
    const size_t k =
        openSidePlane(options, planes, {front.points.row(a).transpose(), front.points.row(b).transpose()},
                      1e-6 * size, "control vertex " + std::to_string(a));
    for (int v : {a, b}) front.onPlanes[static_cast<size_t>(v)] |= static_cast<unsigned char>(1u << k);
    openEdgeCondition.push_back(k == 0 ? BoundaryCondition::Symmetry : BoundaryCondition::Outlet);
  }
  for (int v = 0; v < wallVertices; ++v) {
    const unsigned on = front.onPlanes[static_cast<size_t>(v)];
    if (on != 0) front.points.row(v) = planes.onto(front.points.row(v).transpose(), on).transpose();
  }

  const ResolvedVolumeOptions resolved = resolveVolumeOptions(options, front);
  const MarchingResult marched = marchLayers(front, resolved.marching);
  const auto layers = static_cast<int>(marched.layers.size());

  ControlVolume result;
  result.wallVertices = wallVertices;
  result.layerDistance = marched.layerDistance;
  result.layerMinScaledJacobian = marched.layerMinScaledJacobian;
  result.referenceLength = resolved.referenceLength;
  result.boundaryLayerThickness = resolved.boundaryLayerThickness;
  result.farfieldDistance = resolved.farfieldDistance;

  HexMesh& mesh = result.mesh;
  mesh.points.resize(static_cast<Eigen::Index>(layers) * wallVertices, 3);
  for (int k = 0; k < layers; ++k) {
    mesh.points.middleRows(static_cast<Eigen::Index>(k) * wallVertices, wallVertices) = marched.layers[static_cast<size_t>(k)];
  }
  auto at = [wallVertices](int layer, int vertex) { return layer * wallVertices + vertex; };
  // One block of cells per conforming wall patch, i fastest: a chart cell's corners run
  // counter-clockwise seen from the side marched to, so every cell is right-handed.
  const surface::ChartLayout layout = surface::buildChartLayout(wall);
  const std::vector<WallPatch> patches = conformingPatchLayout(layout, wall);
  for (const WallPatch& patch : patches) {
    const surface::QuadChart& chart = layout.charts[static_cast<size_t>(patch.chart)];
    HexBlock block;
    block.size = {patch.uRange[1] - patch.uRange[0] + 1, patch.vRange[1] - patch.vRange[0] + 1, layers};
    block.pointAt.resize(static_cast<size_t>(block.size[0]) * static_cast<size_t>(block.size[1]) * static_cast<size_t>(layers));
    for (int k = 0; k < layers; ++k) {
      for (int j = 0; j < block.size[1]; ++j) {
        for (int i = 0; i < block.size[0]; ++i) {
          block.pointAt[block.point(i, j, k)] = at(k, chart.vertex(patch.uRange[0] + i, patch.vRange[0] + j));
        }
      }
    }
    for (int k = 0; k + 1 < layers; ++k) {
      for (int j = 0; j + 1 < block.size[1]; ++j) {
        for (int i = 0; i + 1 < block.size[0]; ++i) {
          std::array<int, 8> cell{};
          for (size_t q = 0; q < 8; ++q) {
            const auto& bits = kHexCornerBits[q];
            cell[q] = block.pointAt[block.point(i + bits[0], j + bits[1], k + bits[2])];
          }
          block.cellAt.push_back(static_cast<int>(mesh.cells.size()));
          mesh.cells.push_back(cell);
        }
      }
    }
    std::array<BlockFace, 6> faces;
    faces[static_cast<size_t>(BlockFaceSide::WMin)].condition = BoundaryCondition::Wall;
    const Vector3d middle = mesh.points.row(block.pointAt[block.point(block.size[0] / 2, block.size[1] / 2, layers - 1)]);
    faces[static_cast<size_t>(BlockFaceSide::WMax)].condition = resolved.marching.domain.conditionAt(middle);
    // An open side takes the condition of the plane all its vertices lie on.
    std::array<BoundaryCondition, 4> openSides{};
    for (size_t side = 0; side < 4; ++side) {
      unsigned common = kSymmetryPlaneBit | kOutflowPlaneBit;
      for (int v : patch.sideVertices[side]) common &= front.onPlanes[static_cast<size_t>(v)];
      openSides[side] =
          (common & kSymmetryPlaneBit) != 0 ? BoundaryCondition::Symmetry : BoundaryCondition::Outlet;
    }
    setLateralFaces(patch, openSides, faces);
    result.blocks.push_back(std::move(block));
    result.blockFaces.push_back(faces);
    result.blockChart.push_back(patch.chart);
  }
  for (const auto& q : front.quads) {
    mesh.boundaryFaces.push_back(q);
    mesh.boundaryConditions.push_back(BoundaryCondition::Wall);
  }
  // The outer faces carry their block's condition, as the block faces do.
  for (size_t b = 0; b < result.blocks.size(); ++b) {
    const HexBlock& block = result.blocks[b];
    for (int j = 0; j + 1 < block.size[1]; ++j) {
      for (int i = 0; i + 1 < block.size[0]; ++i) {
        auto corner = [&](int x, int y) { return block.pointAt[block.point(i + x, j + y, layers - 1)]; };
        mesh.boundaryFaces.push_back({corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)});
        mesh.boundaryConditions.push_back(result.blockFaces[b][static_cast<size_t>(BlockFaceSide::WMax)].condition);
      }
    }
  }
  for (int k = 0; k + 1 < layers; ++k) {
    for (size_t e = 0; e < openEdges.size(); ++e) {
      const auto& [a, b] = openEdges[e];
      mesh.boundaryFaces.push_back({at(k, a), at(k, b), at(k + 1, b), at(k + 1, a)});
      mesh.boundaryConditions.push_back(openEdgeCondition[e]);
    }
  }
  mesh.creases = wall.creases;
  mesh.corners = wall.corners;
  // The surface stage makes a boundary vertex of one face a corner (OpenSubdiv's edge-and-corner
  // boundary rule); on the volume's closed boundary it has only the two wall / symmetry creases,
  // so it is made one explicitly for the wall to refine as the fit does.
  for (const auto& [a, b] : openEdges) {
    if (facesAt[static_cast<size_t>(a)] == 1 && std::find(mesh.corners.begin(), mesh.corners.end(), a) == mesh.corners.end()) {
      mesh.corners.push_back(a);
    }
  }
  return result;
}

}  // namespace bvmesh::volume

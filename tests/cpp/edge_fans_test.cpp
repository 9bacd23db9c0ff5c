// Fans of prisms round knife edges (edge_fans.h), on a lens: the cube with its equator an
// infinitely sharp crease, refined twice and squashed to a tenth in z, so that its upper and
// lower halves meet at the equator at a few tens of degrees (their normals more than 120 degrees
// apart). The knife edge is a closed loop, cut where the wall's patches are: fans end to end all
// round it. Its upper half on the plane y = 0 ends the knife edge on the symmetry plane. Where a
// knife edge ends inside the wall (its fan closes) is the M6's trailing edge at the tip:
// tests/python/test_volume.py.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"
#include "core/grid/hex_topology.h"
#include "core/grid/refinement.h"
#include "core/quality/cell_quality.h"
#include "core/surface/limit_bsplines.h"
#include "core/volume/edge_fans.h"
#include "core/volume/turning.h"
#include "core/volume/volume_blocks.h"
#include "core/volume/wall_patches.h"
#include "surface_test_meshes.h"

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

surface::QuadControlMesh lens() {
  surface::QuadControlMesh wall = surface::testing::subdivide(surface::testing::cubeWithCreasedEquator(), 2);
  for (Eigen::Index v = 0; v < wall.vertices.rows(); ++v) wall.vertices(v, 2) *= 0.1;
  return wall;
}

VolumeMesh marched(bool fans) {
  VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.05;
  options.farfieldDistance = 100.0;
  options.knifeEdgeFans = fans;
  return generateVolumeMesh(lens(), options);
}

// The cube refined once with the three faces round its corner (1, 1, 1) a cap: the hexagon of
// edges round them creased and laid on the unit circle of z = 0 (in the order the cap's faces run
// round it, so that the cap faces +z), the corner lifted to z = 0.15 and the rest of the cube (a
// disc round the hexagon, embedded by Tutte's barycentric mapping) bulged to z = -0.2 (1 - r^2).
// A lens whose knife edge turns at three of its six vertices (the cube's face centres): there the
// cap has one face and the rest three, the middle one touching the edge at its corner alone.
surface::QuadControlMesh cappedLens() {
  surface::QuadControlMesh mesh = surface::testing::subdivide(surface::testing::cube(), 1);
  Eigen::Index corner = 0;
  mesh.vertices.rowwise().sum().maxCoeff(&corner);  // the refined cube's corner, moved inwards
  std::map<std::pair<int, int>, int> capEdges;      // directed edge -> uses by the cap's faces
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    if ((mesh.faces.row(f).array() != corner).all()) continue;
    for (int k = 0; k < 4; ++k) ++capEdges[{mesh.faces(f, k), mesh.faces(f, (k + 1) % 4)}];
  }
  std::map<int, int> next;  // the hexagon, in the cap faces' direction
  for (const auto& [edge, uses] : capEdges) {
    if (capEdges.count({edge.second, edge.first}) == 0) next[edge.first] = edge.second;
  }
  std::vector<int> hexagon{next.begin()->first};
  while (next[hexagon.back()] != hexagon.front()) hexagon.push_back(next[hexagon.back()]);
  std::vector<char> fixed(static_cast<size_t>(mesh.vertices.rows()), 0);
  RowMatrixX3d& x = mesh.vertices;
  x.setZero();
  for (size_t k = 0; k < hexagon.size(); ++k) {
    const double angle = 2.0 * M_PI * static_cast<double>(k) / static_cast<double>(hexagon.size());
    x.row(hexagon[k]) << std::cos(angle), std::sin(angle), 0.0;
    fixed[static_cast<size_t>(hexagon[k])] = 1;
  }
  x.row(corner) << 0.0, 0.0, 0.15;
  if (hexagon.size() != 6) throw std::logic_error("the cap is not bounded by a hexagon");
  fixed[static_cast<size_t>(corner)] = 1;
  std::vector<std::set<int>> neighbours(static_cast<size_t>(x.rows()));
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    for (int k = 0; k < 4; ++k) {
      neighbours[static_cast<size_t>(mesh.faces(f, k))].insert(mesh.faces(f, (k + 1) % 4));
      neighbours[static_cast<size_t>(mesh.faces(f, (k + 1) % 4))].insert(mesh.faces(f, k));
    }
  }
  for (int sweep = 0; sweep < 500; ++sweep) {
    for (Eigen::Index v = 0; v < x.rows(); ++v) {
      if (fixed[static_cast<size_t>(v)] != 0) continue;
      Eigen::RowVector3d mean = Eigen::RowVector3d::Zero();
      for (int n : neighbours[static_cast<size_t>(v)]) mean += x.row(n);
      x.row(v) = mean / static_cast<double>(neighbours[static_cast<size_t>(v)].size());
    }
  }
  for (Eigen::Index v = 0; v < x.rows(); ++v) {
    if (fixed[static_cast<size_t>(v)] == 0) x(v, 2) = -0.2 * (1.0 - x.row(v).head<2>().squaredNorm());
  }
  mesh.creases.resize(static_cast<Eigen::Index>(hexagon.size()), 2);
  for (size_t k = 0; k < hexagon.size(); ++k) {
    mesh.creases.row(static_cast<Eigen::Index>(k)) << hexagon[k], hexagon[(k + 1) % hexagon.size()];
  }
  return surface::testing::subdivide(mesh, 2);
}

bool isFan(const Block& block) {
  return block.faces[static_cast<size_t>(BlockFaceSide::WMin)].condition == BoundaryCondition::Collapsed;
}

TEST(EdgeFans, AKnifeEdgeLoopGetsFansEndToEnd) {
  const VolumeMesh mesh = marched(true);
  const VolumeMesh plain = marched(false);
  int fans = 0;
  for (size_t b = 0; b < mesh.blocks.blocks().size(); ++b) {
    const Block& block = mesh.blocks.blocks()[b];
    if (!isFan(block)) continue;
    ++fans;
    EXPECT_EQ(mesh.blockChart[b], -1);
    EXPECT_TRUE(block.faces[static_cast<size_t>(BlockFaceSide::WMin)].collapsedAlong[1]);  // round the edge
    // The next fans along the loop at both ends, the edge's faces' blocks at both sides.
    for (BlockFaceSide side : {BlockFaceSide::UMin, BlockFaceSide::UMax}) {
      const BlockFace& end = block.faces[static_cast<size_t>(side)];
      ASSERT_EQ(end.condition, BoundaryCondition::Connected);
      EXPECT_TRUE(isFan(mesh.blocks.blocks()[static_cast<size_t>(end.neighbour.block)]));
    }
    for (BlockFaceSide side : {BlockFaceSide::VMin, BlockFaceSide::VMax}) {
      const BlockFace& face = block.faces[static_cast<size_t>(side)];
      ASSERT_EQ(face.condition, BoundaryCondition::Connected);
      EXPECT_FALSE(isFan(mesh.blocks.blocks()[static_cast<size_t>(face.neighbour.block)]));
    }
    // Half way round the fan its lines leave the edge outwards in the equator's plane.
    const BsplineVolume& v = block.volume;
    RowMatrixX3d middle(1, 3), x, du, dv, dw;
    middle << 0.5 * (v.lower(0) + v.upper(0)), 0.5 * (v.lower(1) + v.upper(1)), v.lower(2);
    v.evaluate(middle, x, &du, &dv, &dw);
    const Vector3d outward(x(0, 0), x(0, 1), 0.0);
    EXPECT_GT(dw.row(0).normalized().dot(outward.normalized().transpose()), 0.99);
  }
  EXPECT_EQ(fans, 4);  // the loop runs along four patch sides
  EXPECT_EQ(plain.blocks.blockCount(), mesh.blocks.blockCount() - fans);
}

TEST(EdgeFans, TheEdgesFacesLeaveTheWallAlongTheirNormals) {
  // The blocks standing on the lens's halves, at the knife edge: their wall-normal derivative
  // against their wall's normal. With fans each face keeps its own normal there; the O-grid's
  // splay band runs its lines at the edge along the bisector, nearly square to either face
  // (measured: 0.58 and 75.7 degrees at worst).
  for (bool fans : {true, false}) {
    const VolumeMesh mesh = marched(fans);
    double worst = 0.0;
    int samples = 0;
    for (const Block& block : mesh.blocks.blocks()) {
      if (isFan(block)) continue;
      const BsplineVolume& v = block.volume;
      const std::vector<double> u = grevilleAbscissae(v.knots(0), 3), w = grevilleAbscissae(v.knots(1), 3);
      RowMatrixX3d x, du, dv, dw;
      v.evaluateGrid(u, w, {v.lower(2)}, x, &du, &dv, &dw);
      for (Eigen::Index p = 0; p < x.rows(); ++p) {
        if (std::abs(x(p, 2)) > 1e-12) continue;
        const Vector3d normal = du.row(p).cross(dv.row(p)).normalized().transpose();
        const double cosine = std::min(1.0, std::abs(dw.row(p).normalized().dot(normal.transpose())));
        worst = std::max(worst, std::acos(cosine) * 180.0 / M_PI);
        ++samples;
      }
    }
    EXPECT_GT(samples, 40);
    if (fans) {
      EXPECT_LT(worst, 1.0);
    } else {
      EXPECT_GT(worst, 45.0);
    }
  }
}

TEST(EdgeFans, TheGridsCellsAtTheKnifeEdgeArePrismsBetterThanTheOGrids) {
  // Cells with a corner on the knife edge: the fans' prisms, at most 30 degrees each round the
  // edge, against the O-grid's cells there, whose corner at the edge is wide (measured: 0.489 and
  // 0.241, each the grid's minimum); every cell positive either way.
  for (bool fans : {true, false}) {
    grid::RefinementOptions options;
    options.targetCells = 100000;
    const grid::RefinedGrid refined = grid::refineBlockMesh(marched(fans).blocks, options);
    const grid::HexTopology topology(refined.grid);
    const std::vector<double> jacobians = quality::cellScaledJacobians(topology);
    const RowMatrixX3d& points = topology.points().points;
    double atEdge = 1.0;
    for (Eigen::Index c = 0; c < topology.cellCount(); ++c) {
      EXPECT_GT(jacobians[static_cast<size_t>(c)], 0.0) << "cell " << c << (fans ? " with fans" : "");
      bool onEdge = false;
      for (Eigen::Index p : topology.cellCorners(c)) onEdge = onEdge || std::abs(points(p, 2)) < 1e-12;
      if (onEdge) atEdge = std::min(atEdge, jacobians[static_cast<size_t>(c)]);
    }
    if (fans) {
      EXPECT_GT(atEdge, 0.4);
    } else {
      EXPECT_LT(atEdge, 0.3);
    }
  }
}

TEST(EdgeFans, PatchesTouchingTheKnifeEdgeAtACornerAloneTakeTheirSidesCopy) {
  // The capped lens's knife edge turns at three vertices, where a patch of the lower part meets
  // it at its corner alone: that corner must be the lower face's copy of the vertex (the grid
  // torn there otherwise: blocks whose shared faces differ). Fans all round the hexagon, and
  // every refined cell positive.
  VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.05;
  options.farfieldDistance = 100.0;
  options.knifeEdgeFans = true;
  const VolumeMesh mesh = generateVolumeMesh(cappedLens(), options);
  int fans = 0;
  for (const Block& block : mesh.blocks.blocks()) fans += isFan(block);
  EXPECT_GE(fans, 6);
  grid::RefinementOptions refinement;
  refinement.targetCells = 50000;
  const grid::RefinedGrid refined = grid::refineBlockMesh(mesh.blocks, refinement);
  quality::requirePositiveCells(grid::HexTopology(refined.grid));
}

TEST(EdgeFans, AConcaveCreaseIsNoKnifeEdge) {
  // The lens inside out: its equator a narrow groove, the faces' normals as far apart.
  const surface::QuadControlMesh outside = lens();
  surface::QuadControlMesh inside = outside;
  for (Eigen::Index f = 0; f < inside.faces.rows(); ++f) inside.faces.row(f) = outside.faces.row(f).reverse();
  std::vector<WallPatch> convex = conformingWallPatches(surface::limitSurfaceToBSplines(outside), outside);
  std::vector<WallPatch> concave = conformingWallPatches(surface::limitSurfaceToBSplines(inside), inside);
  EXPECT_EQ(insertEdgeFans(convex), 4);
  EXPECT_EQ(insertEdgeFans(concave), 0);
}

TEST(EdgeFans, AFanTurnsRoundTheOutsideOfItsEdgeEvenAtACusp) {
  const Vector3d up(0, 0, 1), down(0, 0, -1), back(1, 0, 0);
  // Opposite normals (a cusp): half way round is the outside.
  EXPECT_LT((turnedBetween(up, down, 0.5, back) - back).norm(), 1e-12);
  EXPECT_LT((turnedBetween(up, down, 0.5, -back) + back).norm(), 1e-12);
  EXPECT_LT(
      (turnedBetween(up, down, 1.0 / 3.0, back) - Vector3d(std::sin(M_PI / 3), 0, std::cos(M_PI / 3))).norm(),
      1e-12);
  // A trailing edge's normals 160 degrees apart: the short way round, through the outside.
  const double half = 80.0 * M_PI / 180.0;
  const Vector3d upper(std::sin(half), 0, std::cos(half)), lower(std::sin(half), 0, -std::cos(half));
  EXPECT_LT((turnedBetween(upper, lower, 0.5, back) - back).norm(), 1e-12);
  EXPECT_LT((turnedBetween(upper, lower, 0.5) - back).norm(), 1e-12);
  EXPECT_LT((turnedBetween(upper, lower, 1.0, back) - lower).norm(), 1e-12);
  // A normal off the plane of the turn: reached at the end all the same.
  const Vector3d skew = Vector3d(0.1, 0.2, -1.0).normalized();
  EXPECT_LT((turnedBetween(up, skew, 1.0, back) - skew).norm(), 1e-12);
}

TEST(EdgeFans, AKnifeEdgeEndingOnTheSymmetryPlaneEndsItsFanThere) {
  // The lens's half y >= 0: the knife edge runs from the plane y = 0 round to it again, its fans'
  // ends there symmetry faces whose points lie on the plane.
  const surface::QuadControlMesh half = surface::testing::halfOf(lens(), 1);
  VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.05;
  options.farfieldDistance = 100.0;
  options.knifeEdgeFans = true;
  options.hasSymmetryPlane = true;
  const VolumeMesh mesh = generateVolumeMesh(half, options);
  int ends = 0;
  for (const Block& block : mesh.blocks.blocks()) {
    if (!isFan(block)) continue;
    for (BlockFaceSide side : {BlockFaceSide::UMin, BlockFaceSide::UMax}) {
      if (block.faces[static_cast<size_t>(side)].condition != BoundaryCondition::Symmetry) continue;
      ++ends;
      const BsplineVolume& v = block.volume;
      const int i = side == BlockFaceSide::UMin ? 0 : v.poleCount(0) - 1;
      for (int k = 0; k < v.poleCount(2); ++k) {
        for (int j = 0; j < v.poleCount(1); ++j)
          EXPECT_LT(std::abs(v.poles()(v.poleIndex(i, j, k), 1)), 1e-12);
      }
    }
  }
  EXPECT_EQ(ends, 2);
}

TEST(EdgeFans, AFanTurnsRoundItsEdgeEvenWhereItsSidesLeanAlongIt) {
  // The edge along y, the outside +x; the upper and lower lines leaning alike along the edge (as
  // where a fan closes towards a corner whose line runs along the edge).
  const Vector3d edge(0, 2, 0), back(1, 0, 0);
  const double lean = 0.8, square = std::sqrt(1.0 - lean * lean);
  const Vector3d upper(0, lean, square), lower(0, lean, -square);
  for (double fraction : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    const Vector3d d = turnedRound(upper, lower, edge, fraction, back);
    const double angle = fraction * M_PI;  // from up through back to down, about the edge
    EXPECT_LT((d - Vector3d(square * std::sin(angle), lean, square * std::cos(angle))).norm(), 1e-12)
        << fraction;
  }
  // turnedBetween turns such lines in their own plane, which holds the edge: half way round, the
  // line runs along the edge instead of leaving it towards the outside.
  EXPECT_LT((turnedBetween(upper, lower, 0.5, back) - Vector3d(0, 1, 0)).norm(), 1e-12);
  // Lines square to the edge: the turn is turnedBetween's.
  const Vector3d up(0, 0, 1), down(0, 0, -1);
  EXPECT_LT((turnedRound(up, down, edge, 1.0 / 3.0, back) - turnedBetween(up, down, 1.0 / 3.0, back)).norm(),
            1e-12);
  // Without an edge direction, or with a line along it: turnedBetween.
  EXPECT_LT((turnedRound(upper, lower, Vector3d::Zero(), 0.5, back) - turnedBetween(upper, lower, 0.5, back))
                .norm(),
            1e-12);
  EXPECT_LT((turnedRound(Vector3d(0, 1, 0), lower, edge, 0.5, back) -
             turnedBetween(Vector3d(0, 1, 0), lower, 0.5, back))
                .norm(),
            1e-12);
}

TEST(EdgeFans, AKnifeEdgeOnOneOfTheWallAndTheMarchingWallAloneIsRefusedByName) {
  // The lens's equator is a knife edge; the unsquashed cube's (normals 90 degrees apart) is none.
  // Marched from a wall a level coarser, only one of the two would have a fan there.
  const auto squashed = [](surface::QuadControlMesh wall) {
    for (Eigen::Index v = 0; v < wall.vertices.rows(); ++v) wall.vertices(v, 2) *= 0.1;
    return wall;
  };
  const surface::QuadControlMesh coarse = surface::testing::subdivide(surface::testing::cubeWithCreasedEquator(), 1);
  const surface::QuadControlMesh fine = surface::testing::subdivide(coarse, 1);
  VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.05;
  options.farfieldDistance = 100.0;
  options.knifeEdgeFans = true;
  const auto refusal = [&](const surface::QuadControlMesh& wall, const surface::QuadControlMesh& marching) {
    try {
      generateVolumeMesh(wall, options, &marching);
    } catch (const InvalidInputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  const std::string wallOnly = refusal(squashed(fine), coarse);
  EXPECT_NE(wallOnly.find("the wall's crease from control vertex"), std::string::npos) << wallOnly;
  EXPECT_NE(wallOnly.find("is a knife edge"), std::string::npos) << wallOnly;
  const std::string marchingOnly = refusal(fine, squashed(coarse));
  EXPECT_NE(marchingOnly.find("the marching wall's crease from control vertex"), std::string::npos) << marchingOnly;
  EXPECT_NE(marchingOnly.find("march from the wall itself or without knife_edge_fans"), std::string::npos)
      << marchingOnly;
  // The same walls without fans march (the lens from the cube would lie too far off it: both as is).
  options.knifeEdgeFans = false;
  EXPECT_NO_THROW(generateVolumeMesh(fine, options, &coarse));
}

}  // namespace
}  // namespace bvmesh::volume

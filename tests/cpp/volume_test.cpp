// The volume stage's core: B-spline volumes against closed forms, block-mesh validation and the
// block file, and the volume mesh generated around Catmull-Clark limit surfaces.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <sstream>
#include <string>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"
#include "core/volume/block_mesh_io.h"
#include "core/volume/control_volume.h"
#include "core/volume/domain.h"
#include "core/volume/volume_blocks.h"
#include "core/volume/wall_patches.h"
#include "core/volume/wall_topology.h"
#include "surface_test_meshes.h"

namespace bvmesh::volume {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// A tricubic volume with poles at the Greville points of an affine map x = A (u, v, w) + b: by
// linear precision the volume is that map.
BsplineVolume affineVolume(const Matrix3d& a, const Vector3d& b, std::array<int, 3> spans) {
  std::array<std::vector<double>, 3> knots;
  std::array<std::vector<double>, 3> greville;
  for (int d = 0; d < 3; ++d) {
    knots[static_cast<size_t>(d)] = uniformClampedKnots(3, spans[static_cast<size_t>(d)]);
    greville[static_cast<size_t>(d)] = grevilleAbscissae(knots[static_cast<size_t>(d)], 3);
  }
  const int nu = spans[0] + 3, nv = spans[1] + 3, nw = spans[2] + 3;
  RowMatrixX3d poles(nu * nv * nw, 3);
  for (int k = 0; k < nw; ++k) {
    for (int j = 0; j < nv; ++j) {
      for (int i = 0; i < nu; ++i) {
        const Vector3d x(greville[0][static_cast<size_t>(i)], greville[1][static_cast<size_t>(j)], greville[2][static_cast<size_t>(k)]);
        poles.row(i + nu * (j + nv * k)) = (a * x + b).transpose();
      }
    }
  }
  return BsplineVolume({3, 3, 3}, knots, poles);
}

TEST(BsplineVolume, ReproducesAnAffineMapWithItsDerivatives) {
  Matrix3d a;
  a << 2.0, 0.3, -0.1, 0.2, 1.5, 0.4, -0.3, 0.1, 0.7;
  const Vector3d b(1.0, -2.0, 0.5);
  const BsplineVolume volume = affineVolume(a, b, {4, 3, 5});
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  RowMatrixX3d parameters(200, 3);
  for (int p = 0; p < 200; ++p) parameters.row(p) << 4 * unit(random), 3 * unit(random), 5 * unit(random);
  parameters.row(0) << 0, 0, 0;
  parameters.row(1) << 4, 3, 5;
  RowMatrixX3d points, du, dv, dw;
  volume.evaluate(parameters, points, &du, &dv, &dw);
  for (int p = 0; p < 200; ++p) {
    const Vector3d x = parameters.row(p).transpose();
    EXPECT_LT((points.row(p).transpose() - (a * x + b)).norm(), 1e-12) << p;
    EXPECT_LT((du.row(p).transpose() - a.col(0)).norm(), 1e-11);
    EXPECT_LT((dv.row(p).transpose() - a.col(1)).norm(), 1e-11);
    EXPECT_LT((dw.row(p).transpose() - a.col(2)).norm(), 1e-11);
  }
}

TEST(BsplineVolume, GridEvaluationEqualsPointEvaluation) {
  Matrix3d a = Matrix3d::Identity();
  BsplineVolume affine = affineVolume(a, Vector3d::Zero(), {3, 4, 2});
  // Bend the poles so the volume is not affine.
  RowMatrixX3d bent = affine.poles();
  for (Eigen::Index r = 0; r < bent.rows(); ++r) bent(r, 2) += 0.1 * std::sin(bent(r, 0)) * bent(r, 1) * bent(r, 1);
  const BsplineVolume volume({3, 3, 3}, {affine.knots(0), affine.knots(1), affine.knots(2)}, bent);
  const std::vector<double> u{0.0, 0.4, 1.5, 2.999, 3.0}, v{0.0, 1.0, 2.2, 4.0}, w{0.0, 0.7, 2.0};
  RowMatrixX3d grid, gu, gv, gw;
  volume.evaluateGrid(u, v, w, grid, &gu, &gv, &gw);
  RowMatrixX3d parameters(static_cast<Eigen::Index>(u.size() * v.size() * w.size()), 3);
  for (size_t c = 0; c < w.size(); ++c) {
    for (size_t b = 0; b < v.size(); ++b) {
      for (size_t i = 0; i < u.size(); ++i) parameters.row(static_cast<Eigen::Index>(i + u.size() * (b + v.size() * c))) << u[i], v[b], w[c];
    }
  }
  RowMatrixX3d points, du, dv, dw;
  volume.evaluate(parameters, points, &du, &dv, &dw);
  EXPECT_LT((grid - points).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LT((gu - du).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_LT((gv - dv).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_LT((gw - dw).cwiseAbs().maxCoeff(), 1e-13);
  // A clamped face is its boundary pole grid's surface: at w = 0 the corner is the corner pole.
  EXPECT_EQ(grid.row(0), volume.poles().row(0));
}

TEST(BsplineVolume, RejectsInconsistentDataByName) {
  const BsplineVolume good = affineVolume(Matrix3d::Identity(), Vector3d::Zero(), {2, 2, 2});
  RowMatrixX3d poles = good.poles();
  EXPECT_THROW(BsplineVolume({3, 3, 3}, {good.knots(0), good.knots(1), good.knots(2)}, poles.topRows(10), "block 4"),
               InvalidInputError);
  try {
    poles(7, 1) = std::nan("");
    BsplineVolume({3, 3, 3}, {good.knots(0), good.knots(1), good.knots(2)}, poles, "block 4");
    FAIL();
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("block 4: pole (2, 1, 0) is not finite"), std::string::npos) << error.what();
  }
  std::vector<double> unclamped = good.knots(0);
  unclamped[1] = -0.5;
  EXPECT_THROW(BsplineVolume({3, 3, 3}, {unclamped, good.knots(1), good.knots(2)}, good.poles()), InvalidInputError);
  RowMatrixX3d outside(1, 3);
  outside << 0.5, 0.5, 2.5;
  RowMatrixX3d out;
  EXPECT_THROW(good.evaluate(outside, out), InvalidInputError);
}

// Two affine blocks side by side: block 0 on [0, 1] x [0, 1] x [0, 1], block 1 on [1, 2] x ...,
// joined through block 0's u_max and block 1's u_min.
std::vector<Block> twoBlocks() {
  Matrix3d a = Matrix3d::Identity() / 2.0;
  std::vector<Block> blocks(2);
  blocks[0].volume = affineVolume(a, Vector3d::Zero(), {2, 2, 2});
  blocks[1].volume = affineVolume(a, Vector3d(1, 0, 0), {2, 2, 2});
  blocks[0].faces[static_cast<size_t>(BlockFaceSide::UMax)] = {BoundaryCondition::Connected, {1, 0, false, false, false}};
  blocks[1].faces[static_cast<size_t>(BlockFaceSide::UMin)] = {BoundaryCondition::Connected, {0, 1, false, false, false}};
  blocks[0].faces[static_cast<size_t>(BlockFaceSide::WMin)].condition = BoundaryCondition::Wall;
  return blocks;
}

TEST(BlockMesh, ValidatesConnectionsAndSharedPoles) {
  const BlockMesh mesh(twoBlocks());
  const VolumeControlMesh control = volumeControlMesh(mesh);
  EXPECT_EQ(control.points.rows(), 2 * 125 - 25);  // the shared 5 x 5 face once
  EXPECT_EQ(control.cells.size(), 2u * 64u);
  EXPECT_EQ(control.boundaryFaces.size(), 2u * 5u * 16u);

  std::vector<Block> moved = twoBlocks();
  const Eigen::Index shared = moved[1].volume.poleIndex(0, 2, 3);
  moved[1].volume.setPole(shared, moved[1].volume.poles().row(shared).transpose() + Vector3d(0.0, 0.0, 1e-9));
  try {
    BlockMesh bad(moved);
    FAIL();
  } catch (const InvalidInputError& error) {
    // The gap in significant digits (std::to_string printed "0.000000").
    EXPECT_NE(std::string(error.what())
                  .find("block 0 face u_max pole (2, 3) differs from its neighbour's in block 1 face u_min "
                        "by 1e-09 "),
              std::string::npos)
        << error.what();
  }
  std::vector<Block> oneWay = twoBlocks();
  oneWay[1].faces[static_cast<size_t>(BlockFaceSide::UMin)].condition = BoundaryCondition::Farfield;
  EXPECT_THROW(BlockMesh{oneWay}, InvalidInputError);
  std::vector<Block> flipped = twoBlocks();
  flipped[0].faces[static_cast<size_t>(BlockFaceSide::UMax)].neighbour.reverseFirst = true;
  flipped[1].faces[static_cast<size_t>(BlockFaceSide::UMin)].neighbour.reverseFirst = true;
  EXPECT_THROW(BlockMesh{flipped}, InvalidInputError);  // the poles no longer meet
}

TEST(BlockMesh, FaceRowsAreThePositionLookupsAsLinearFunctions) {
  // Every face of a 3 x 4 x 5 grid, and every orientation of a connection to every face of a
  // 5 x 3 x 4 grid whose face sizes fit: the linear rows equal the position-by-position lookup.
  const std::array<int, 3> mine{3, 4, 5}, theirs{5, 3, 4};
  auto row = [](const std::array<int, 3>& counts, const std::array<int, 3>& ijk) {
    return ijk[0] +
           static_cast<Eigen::Index>(counts[0]) * (ijk[1] + static_cast<Eigen::Index>(counts[1]) * ijk[2]);
  };
  int connections = 0;
  for (int f = 0; f < 6; ++f) {
    const std::array<int, 2> counts = volume::faceGridCounts(mine, f);
    const volume::FaceRows rows = volume::faceRows(mine, f);
    for (int a = 0; a < counts[0]; ++a) {
      for (int b = 0; b < counts[1]; ++b)
        EXPECT_EQ(rows.at(a, b), row(mine, volume::faceGridPosition(mine, f, a, b)));
    }
    for (int g = 0; g < 6; ++g) {
      const std::array<int, 2> other = volume::faceGridCounts(theirs, g);
      for (int orientation = 0; orientation < 8; ++orientation) {
        volume::FaceConnection connection;
        connection.block = 1;
        connection.face = g;
        connection.swapped = (orientation & 1) != 0;
        connection.reverseFirst = (orientation & 2) != 0;
        connection.reverseSecond = (orientation & 4) != 0;
        const std::array<int, 2> seen = connection.swapped ? std::array<int, 2>{other[1], other[0]} : other;
        if (seen != counts) continue;
        ++connections;
        const volume::FaceRows there = volume::BlockMesh::neighbourFaceRows(connection, theirs);
        for (int a = 0; a < counts[0]; ++a) {
          for (int b = 0; b < counts[1]; ++b) {
            const std::array<int, 2> mapped = volume::BlockMesh::mapFacePosition(connection, other, a, b);
            EXPECT_EQ(there.at(a, b), row(theirs, volume::faceGridPosition(theirs, g, mapped[0], mapped[1])))
                << f << " " << g << " " << orientation << " " << a << " " << b;
          }
        }
      }
    }
  }
  EXPECT_GT(connections, 40);
}

TEST(BlockMeshFile, RoundTripsAndNamesTheBadLine) {
  const BlockMesh mesh(twoBlocks());
  std::stringstream text;
  writeBlockMesh(mesh, text);
  const BlockMesh back = readBlockMesh(text);
  ASSERT_EQ(back.blockCount(), 2);
  for (int b = 0; b < 2; ++b) {
    EXPECT_EQ(back.blocks()[static_cast<size_t>(b)].volume.poles(), mesh.blocks()[static_cast<size_t>(b)].volume.poles());
    for (int d = 0; d < 3; ++d) {
      EXPECT_EQ(back.blocks()[static_cast<size_t>(b)].volume.knots(d), mesh.blocks()[static_cast<size_t>(b)].volume.knots(d));
    }
    for (int f = 0; f < 6; ++f) {
      EXPECT_EQ(back.blocks()[static_cast<size_t>(b)].faces[static_cast<size_t>(f)].condition,
                mesh.blocks()[static_cast<size_t>(b)].faces[static_cast<size_t>(f)].condition);
    }
  }
  const std::string full = text.str();
  std::stringstream cut(full.substr(0, full.size() / 2));
  EXPECT_THROW(readBlockMesh(cut, "cut.blocks"), InvalidInputError);
  std::string wrong = full;
  wrong.replace(wrong.find("farfield"), 8, "farfeld");
  std::stringstream typo(wrong);
  try {
    readBlockMesh(typo, "typo.blocks");
    FAIL();
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("typo.blocks, line "), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("'farfeld'"), std::string::npos);
  }
  EXPECT_THROW(writeBlockMeshFile(mesh, "/nonexistent-folder/x.blocks"), InvalidInputError);
}

// Determinant of the Jacobian over |du| |dv| |dw| at the sample points of every control cell
// (4 x 4 x 4 per cell), and the wall angles (dw against du x dv at w = 0), per block.
struct VolumeQuality {
  double minScaledJacobian = 1.0;
  std::vector<double> wallAnglesDegrees;
};

VolumeQuality sampleQuality(const BlockMesh& mesh) {
  VolumeQuality quality;
  for (const Block& block : mesh.blocks()) {
    const BsplineVolume& v = block.volume;
    std::array<std::vector<double>, 3> at;
    for (int d = 0; d < 3; ++d) {
      std::vector<double> knots = v.knots(d);
      knots.erase(std::unique(knots.begin(), knots.end()), knots.end());
      for (size_t k = 0; k + 1 < knots.size(); ++k) {
        for (int s = 0; s < 4; ++s) at[static_cast<size_t>(d)].push_back(knots[k] + (knots[k + 1] - knots[k]) * s / 4.0);
      }
      at[static_cast<size_t>(d)].push_back(knots.back());
    }
    RowMatrixX3d x, du, dv, dw;
    v.evaluateGrid(at[0], at[1], at[2], x, &du, &dv, &dw);
    const Eigen::Index layer = static_cast<Eigen::Index>(at[0].size() * at[1].size());
    for (Eigen::Index p = 0; p < x.rows(); ++p) {
      const Vector3d a = du.row(p).transpose(), b = dv.row(p).transpose(), c = dw.row(p).transpose();
      quality.minScaledJacobian = std::min(quality.minScaledJacobian, a.cross(b).dot(c) / (a.norm() * b.norm() * c.norm()));
      if (p < layer) {
        const double cosine = a.cross(b).normalized().dot(c.normalized());
        quality.wallAnglesDegrees.push_back(std::acos(std::min(1.0, cosine)) * 180.0 / std::acos(-1.0));
      }
    }
  }
  return quality;
}

TEST(VolumeMesh, AroundTheLimitSurfaceOfARefinedCube) {
  const surface::QuadControlMesh wall = surface::testing::subdivide(surface::testing::cube(), 2);
  VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.05;
  options.farfieldDistance = 30.0;
  const VolumeMesh result = generateVolumeMesh(wall, options);
  const BlockMesh& mesh = result.blocks;
  ASSERT_EQ(mesh.blockCount(), 6);  // one chart per cube face: the valence-3 corners split it so
  // The wall face of every block is its chart surface, pole for pole.
  const surface::LimitBSplines charts = surface::limitSurfaceToBSplines(wall);
  for (int b = 0; b < mesh.blockCount(); ++b) {
    const BsplineVolume& v = mesh.blocks()[static_cast<size_t>(b)].volume;
    const cad::BSplineSurfaceData& chart = charts.surfaces[static_cast<size_t>(result.blockChart[static_cast<size_t>(b)])];
    ASSERT_EQ(v.poleCount(0), chart.uPoleCount);
    for (int i = 0; i < v.poleCount(0); ++i) {
      for (int j = 0; j < v.poleCount(1); ++j) {
        const size_t q = 3 * static_cast<size_t>(i * chart.vPoleCount + j);
        EXPECT_LT((v.poles().row(v.poleIndex(i, j, 0)).transpose() -
                   Vector3d(chart.poles[q], chart.poles[q + 1], chart.poles[q + 2])).norm(), 1e-12);
      }
    }
    const auto& faces = mesh.blocks()[static_cast<size_t>(b)].faces;
    EXPECT_EQ(faces[static_cast<size_t>(BlockFaceSide::WMin)].condition, BoundaryCondition::Wall);
    EXPECT_EQ(faces[static_cast<size_t>(BlockFaceSide::WMax)].condition, BoundaryCondition::Farfield);
    for (int f = 0; f < 4; ++f) EXPECT_EQ(faces[static_cast<size_t>(f)].condition, BoundaryCondition::Connected);
    // The outer face interpolates the last layer, which lies on the far-field sphere.
    const std::vector<double> gu = grevilleAbscissae(v.knots(0), 3), gv = grevilleAbscissae(v.knots(1), 3);
    RowMatrixX3d outer;
    v.evaluateGrid(gu, gv, {1.0}, outer);
    for (Eigen::Index p = 0; p < outer.rows(); ++p) {
      EXPECT_NEAR((outer.row(p).transpose() - result.domainCentre).norm(), 30.0, 1e-9 * 30.0);
    }
  }
  const VolumeQuality quality = sampleQuality(mesh);
  EXPECT_GT(quality.minScaledJacobian, 0.3);
  std::vector<double> angles = quality.wallAnglesDegrees;
  std::sort(angles.begin(), angles.end());
  EXPECT_LT(angles[angles.size() * 99 / 100], 2.0);
  for (double q : result.layerMinScaledJacobian) EXPECT_GT(q, 0.3);
  // Shared faces meet: block faces evaluated from both sides coincide.
  for (int b = 0; b < mesh.blockCount(); ++b) {
    const Block& block = mesh.blocks()[static_cast<size_t>(b)];
    const BlockFace& face = block.faces[static_cast<size_t>(BlockFaceSide::UMax)];
    const BsplineVolume& other = mesh.blocks()[static_cast<size_t>(face.neighbour.block)].volume;
    for (double t : {0.0, 0.3, 0.77, 1.0}) {
      for (double s : {0.0, 0.5, 1.0}) {
        RowMatrixX3d mine, theirs;
        RowMatrixX3d at(1, 3);
        at << block.volume.upper(0), s * block.volume.upper(1), t;
        block.volume.evaluate(at, mine);
        const int along = face.neighbour.face / 2 == 0 ? 1 : 0;
        const double position = face.neighbour.reverseFirst ? (1 - s) * other.upper(along) : s * other.upper(along);
        RowMatrixX3d there(1, 3);
        there(0, 2) = t;
        there(0, along) = position;
        there(0, 1 - along) = face.neighbour.face % 2 == 0 ? 0.0 : other.upper(1 - along);
        other.evaluate(there, theirs);
        EXPECT_LT((mine - theirs).norm(), 1e-12 * 30.0) << "block " << b;
      }
    }
  }
}

// The cube stretched five times along x, every edge a crease and every corner sharp, refined
// `levels` times.
surface::QuadControlMesh stretchedSharpBox(int levels = 3) {
  surface::QuadControlMesh box = surface::testing::cube();
  for (Eigen::Index v = 0; v < box.vertices.rows(); ++v) box.vertices(v, 0) *= 5.0;
  std::vector<std::array<int, 2>> edges;
  for (Eigen::Index f = 0; f < box.faces.rows(); ++f) {
    for (int k = 0; k < 4; ++k) {
      const int a = box.faces(f, k), b = box.faces(f, (k + 1) % 4);
      if (a < b) edges.push_back({a, b});
    }
  }
  box.creases.resize(static_cast<Eigen::Index>(edges.size()), 2);
  for (size_t e = 0; e < edges.size(); ++e) box.creases.row(static_cast<Eigen::Index>(e)) << edges[e][0], edges[e][1];
  for (int v = 0; v < 8; ++v) box.corners.push_back(v);
  return surface::testing::subdivide(box, levels);
}

// `intervals` + 1 evenly spaced parameters over direction `direction` of a block.
std::vector<double> evenParameters(const BsplineVolume& v, int direction, int intervals) {
  std::vector<double> t(static_cast<size_t>(intervals) + 1);
  for (int k = 0; k <= intervals; ++k) {
    t[static_cast<size_t>(k)] =
        v.lower(direction) + (v.upper(direction) - v.lower(direction)) * k / intervals;
  }
  return t;
}

TEST(VolumeMesh, SplayBandLeavesAFaceNarrowerThanItsOwnNormals) {
  // The stretched box's end faces (half width 0.5) are narrower than the splay band at their rims
  // would be (two boundary-layer thicknesses, 0.8): the band covers half of them (0.25), so the
  // lines in their middle leave along the end face's normal instead of taking the long sides'
  // normals interpolated across the whole face (measured: 0.42 degrees off the end face's normal
  // within 0.2 of its centre; 6.4 with the band at full width).
  const surface::QuadControlMesh wall = stretchedSharpBox();
  VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.4;
  options.farfieldDistance = 100.0;
  options.farfieldScheme = FarfieldScheme::Smoothed;
  const VolumeMesh result = generateVolumeMesh(wall, options);
  // The wall-normal derivative at wall samples on the end faces within 0.2 of their centre.
  double worst = 0.0;
  int samples = 0;
  for (const Block& block : result.blocks.blocks()) {
    const BsplineVolume& v = block.volume;
    const std::vector<double> u = evenParameters(v, 0, 40), w = evenParameters(v, 1, 40);
    RowMatrixX3d x, du, dv, dw;
    v.evaluateGrid(u, w, {v.lower(2)}, x, &du, &dv, &dw);
    for (Eigen::Index p = 0; p < x.rows(); ++p) {
      if (std::abs(std::abs(x(p, 0)) - 5.0) > 1e-3 || std::hypot(x(p, 1), x(p, 2)) > 0.2) continue;
      const Vector3d normal(x(p, 0) > 0.0 ? 1.0 : -1.0, 0.0, 0.0);
      worst = std::max(worst, std::acos(std::min(1.0, dw.row(p).normalized().dot(normal.transpose()))) * 180.0 / M_PI);
      ++samples;
    }
  }
  EXPECT_GT(samples, 8);
  EXPECT_LT(worst, 1.0);
}

TEST(VolumeMesh, GridLinesLeaveTheWallAlongItsNormalInsideTheSplayBand) {
  // On the box's long faces (half width 1) the splay band reaches 0.5 from the sharp edges, where
  // the marched lines tilt towards the edge's bisector. The blocks' lines leave the wall along the
  // face's normal all the same at the wall's Greville points (the points the layers were marched
  // from) and bend into the marched lines above it. Between those points the offsets are
  // interpolated, which carries a little of the edge's bisector inwards, as does the halved turn
  // next to the edges (where a full one would invert a control cell). Greville points 0.2 to 0.45
  // from the edges, samples between them 0.25 to 0.45, two spans and more (measured: 0.24 and
  // 2.9 degrees off the normal at worst; with the marched lines interpolated as they are, 22.2 and
  // 22.7).
  const surface::QuadControlMesh wall = stretchedSharpBox(4);
  VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.4;
  options.farfieldDistance = 100.0;
  const VolumeMesh result = generateVolumeMesh(wall, options);
  const auto worstInBand = [&](bool atGrevillePoints) {
    double worst = 0.0;
    int samples = 0;
    for (const Block& block : result.blocks.blocks()) {
      const BsplineVolume& v = block.volume;
      const std::vector<double> u =
          atGrevillePoints ? grevilleAbscissae(v.knots(0), 3) : evenParameters(v, 0, 80);
      const std::vector<double> w =
          atGrevillePoints ? grevilleAbscissae(v.knots(1), 3) : evenParameters(v, 1, 80);
      RowMatrixX3d x, du, dv, dw;
      v.evaluateGrid(u, w, {v.lower(2)}, x, &du, &dv, &dw);
      for (Eigen::Index p = 0; p < x.rows(); ++p) {
        if (std::abs(x(p, 0)) > 4.0) continue;  // the long faces only
        const int face = std::abs(x(p, 1)) > std::abs(x(p, 2)) ? 1 : 2;
        const double fromEdge = 1.0 - std::abs(x(p, 3 - face));
        if (fromEdge < (atGrevillePoints ? 0.2 : 0.25) || fromEdge > 0.45) continue;
        Vector3d normal = Vector3d::Zero();
        normal[face] = x(p, face) > 0.0 ? 1.0 : -1.0;
        const double cosine = std::min(1.0, dw.row(p).normalized().dot(normal.transpose()));
        worst = std::max(worst, std::acos(cosine) * 180.0 / M_PI);
        ++samples;
      }
    }
    EXPECT_GT(samples, 100);
    return worst;
  };
  EXPECT_LT(worstInBand(true), 0.5);
  EXPECT_LT(worstInBand(false), 4.0);
}

TEST(VolumeMesh, AHyperbolicLayerThatWouldFoldTakesTheSmoothedStep) {
  // Above the stretched box's splayed corners (a boundary layer 0.4 thick on a 2 x 2 section) the
  // hyperbolic scheme's first far-field layer folds (measured: scaled Jacobian -0.57 next to an end
  // face's corner after the local repair); that layer takes the smoothed step and the far field
  // goes on hyperbolically (measured: 2 of its 20 far-field layers smoothed).
  const surface::QuadControlMesh wall = stretchedSharpBox();
  VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.4;
  options.farfieldDistance = 100.0;
  ASSERT_EQ(options.farfieldScheme, FarfieldScheme::Hyperbolic);
  const VolumeMesh result = generateVolumeMesh(wall, options);
  const int farfieldLayers = static_cast<int>(result.layerDistance.size()) - 1 - options.boundaryLayerLayers;
  EXPECT_GT(result.farfieldLayersSmoothed, 0);
  EXPECT_LT(result.farfieldLayersSmoothed, farfieldLayers);
  for (double worst : result.layerMinScaledJacobian) EXPECT_GT(worst, 0.0);
}

// An L-shaped prism, its section the L of legs 2 long and 1 thick in the x-z plane, 2 deep along
// y: every edge sharp, the inner one (x = z = 1) a concave crease.
surface::QuadControlMesh lShapedPrism(int levels) {
  const std::array<std::array<double, 2>, 8> outline{
      {{0, 0}, {1, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}, {0, 1}}};
  std::vector<Vector3d> points;
  for (const double y : {-1.0, 1.0}) {
    for (const auto& xz : outline) points.emplace_back(xz[0], y, xz[1]);
  }
  std::vector<std::array<int, 4>> quads;
  for (int k = 0; k < 8; ++k) quads.push_back({k, 8 + k, 8 + (k + 1) % 8, (k + 1) % 8});
  for (const std::array<int, 4>& cap :
       std::vector<std::array<int, 4>>{{0, 1, 4, 7}, {1, 2, 3, 4}, {7, 4, 5, 6}}) {
    quads.push_back(cap);
    quads.push_back({cap[3] + 8, cap[2] + 8, cap[1] + 8, cap[0] + 8});
  }
  std::vector<std::array<int, 2>> creases;
  std::vector<int> corners;
  for (int k = 0; k < 8; ++k) {
    creases.push_back({k, (k + 1) % 8});
    creases.push_back({8 + k, 8 + (k + 1) % 8});
    if (k == 1 || k == 7) continue;  // the middles of the long legs' outer faces
    creases.push_back({k, 8 + k});
    corners.push_back(k);
    corners.push_back(8 + k);
  }
  surface::QuadControlMesh prism = surface::makeQuadControlMesh(points, quads, creases);
  prism.corners = corners;
  return surface::testing::subdivide(prism, levels);
}

TEST(VolumeMesh, AConcaveCreaseMarchesAsTheWallsOffset) {
  // Along the L's inner edge the faces' normals cross: straight lines along them would fold the
  // cells above the edge within the boundary layer. The lines there turn towards the edge's
  // bisector, wholly at the edge and not at all four boundary-layer thicknesses away, and each is
  // as long as keeps its layers at their distance from its wall cells: the boundary layer's top
  // above the edge is the offset's corner, (1 + t, 1 + t), and the whole volume marches with
  // positive cells (before: the edge read as convex, its cells being long along it, the lines
  // next to it stopped at 0.45 of the thickness, the boundary layer's top dipped into the corner,
  // and the far field folded there at layer 7).
  const surface::QuadControlMesh wall = lShapedPrism(3);
  VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.1;
  options.farfieldDistance = 40.0;
  const VolumeMesh result = generateVolumeMesh(wall, options);
  for (double worst : result.layerMinScaledJacobian) EXPECT_GT(worst, 0.0);
  const double top = result.layerDistance[static_cast<size_t>(options.boundaryLayerLayers)];
  ASSERT_NEAR(top, 0.1, 1e-12);
  const double wTop = top / result.layerDistance.back();
  int samples = 0;
  for (const Block& block : result.blocks.blocks()) {
    const BsplineVolume& v = block.volume;
    const std::vector<double> u = grevilleAbscissae(v.knots(0), 3), w = grevilleAbscissae(v.knots(1), 3);
    RowMatrixX3d wallPoints, topPoints;
    v.evaluateGrid(u, w, {v.lower(2)}, wallPoints);
    v.evaluateGrid(u, w, {v.lower(2) + wTop * (v.upper(2) - v.lower(2))}, topPoints);
    for (Eigen::Index p = 0; p < wallPoints.rows(); ++p) {
      const Vector3d at = wallPoints.row(p).transpose();
      if (std::hypot(at.x() - 1.0, at.z() - 1.0) > 1e-6 || std::abs(at.y()) > 0.5) continue;
      EXPECT_LT((topPoints.row(p).transpose() - Vector3d(1.1, at.y(), 1.1)).norm(), 0.01) << at.transpose();
      ++samples;
    }
  }
  EXPECT_GT(samples, 4);
}

TEST(VolumeMesh, HalfModelKeepsTheSymmetryPlane) {
  const surface::QuadControlMesh half = surface::testing::upperHalfOfRefinedCube();
  VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.05;
  options.farfieldDistance = 20.0;
  EXPECT_THROW(generateVolumeMesh(half, options), InvalidInputError);  // open, and no plane given
  options.hasSymmetryPlane = true;
  options.planeNormal = Vector3d::UnitZ();
  const VolumeMesh result = generateVolumeMesh(half, options);
  int symmetryFaces = 0;
  for (const Block& block : result.blocks.blocks()) {
    for (int f = 0; f < 6; ++f) {
      if (block.faces[static_cast<size_t>(f)].condition != BoundaryCondition::Symmetry) continue;
      ++symmetryFaces;
      const std::array<int, 2> counts = BlockMesh::facePoleCounts(block.volume, f);
      for (int a = 0; a < counts[0]; ++a) {
        for (int b = 0; b < counts[1]; ++b) {
          EXPECT_LT(std::abs(block.volume.poles()(BlockMesh::facePole(block.volume, f, a, b), 2)), 1e-12 * 20.0);
        }
      }
    }
  }
  EXPECT_GT(symmetryFaces, 0);
  EXPECT_GT(sampleQuality(result.blocks).minScaledJacobian, 0.2);

  // In a half box: the symmetry faces stay on the plane; the top block's outer face lies on the
  // box's top. (The half model's limit surface is not symmetric in x and z, so the side blocks'
  // outer faces bend around the box's upper edges, where a smooth face cannot follow the box; the
  // mesh says how many do.)
  options.domain = DomainShape::Box;
  const VolumeMesh boxed = generateVolumeMesh(half, options);
  int onTop = 0;
  for (const Block& block : boxed.blocks.blocks()) {
    for (int f = 0; f < 6; ++f) {
      const BoundaryCondition condition = block.faces[static_cast<size_t>(f)].condition;
      if (condition == BoundaryCondition::Connected || condition == BoundaryCondition::Wall) continue;
      const std::array<int, 2> counts = BlockMesh::facePoleCounts(block.volume, f);
      const auto pole = [&](int a, int b) {
        return Vector3d(block.volume.poles().row(BlockMesh::facePole(block.volume, f, a, b)).transpose());
      };
      const bool top = condition != BoundaryCondition::Symmetry && boxed.domain.pieceAt(pole(counts[0] / 2, counts[1] / 2)) == 5;
      onTop += top ? 1 : 0;
      for (int a = 0; a < counts[0]; ++a) {
        for (int b = 0; b < counts[1]; ++b) {
          if (condition == BoundaryCondition::Symmetry) {
            EXPECT_LT(std::abs(pole(a, b).z()), 1e-12 * 20.0);
          }
          if (top) {
            EXPECT_NEAR(pole(a, b).z(), 20.0, 1e-11 * 20.0);
          }
        }
      }
    }
  }
  EXPECT_EQ(onTop, 1);
  EXPECT_LE(boxed.farfieldFacesAcrossDomainEdges, 4);
  EXPECT_GT(sampleQuality(boxed.blocks).minScaledJacobian, 0.2);
}

// The half of torus(n, m) with y >= 0 (n even): open on the plane y = 0 in two loops.
surface::QuadControlMesh halfTorus(int n, int m) {
  const surface::QuadControlMesh whole = surface::testing::torus(n, m);
  std::vector<Vector3d> points;
  for (int i = 0; i <= n / 2; ++i) {
    for (int j = 0; j < m; ++j) points.push_back(whole.vertices.row(i * m + j).transpose());
  }
  std::vector<std::array<int, 4>> quads;
  const auto id = [m](int i, int j) { return i * m + (j + m) % m; };
  for (int i = 0; i < n / 2; ++i) {
    for (int j = 0; j < m; ++j) quads.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  }
  return surface::makeQuadControlMesh(points, quads);
}

std::string refusal(const std::function<void()>& build) {
  try {
    build();
  } catch (const InvalidInputError& error) {
    return error.what();
  }
  return "accepted";
}

TEST(VolumeMesh, ARingOrAHalfRingIsRefusedBeforeMarching) {
  // Marched, the torus's hole closed at the axis and the marching stopped there with a fold and
  // advice about smoothing and growth; the domain boundary is one sphere, so no marching can work.
  VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.05;
  options.farfieldDistance = 40.0;
  const surface::QuadControlMesh ring = surface::testing::torus(8, 4);
  for (const std::string& message : {refusal([&] { generateVolumeMesh(ring, options); }),
                                     refusal([&] { controlVolumeMesh(ring, options); })}) {
    EXPECT_NE(message.find("the wall is a ring (genus 1"), std::string::npos) << message;
  }
  options.hasSymmetryPlane = true;
  options.planeNormal = Vector3d::UnitY();
  const surface::QuadControlMesh half = halfTorus(8, 4);
  for (const std::string& message : {refusal([&] { generateVolumeMesh(half, options); }),
                                     refusal([&] { controlVolumeMesh(half, options); })}) {
    EXPECT_NE(message.find("meets the symmetry plane in 2 separate loops"), std::string::npos) << message;
  }
  // A sphere's topology, whole or halved, passes.
  EXPECT_NO_THROW(requireMarchableWall(surface::testing::cube(), false));
  EXPECT_NO_THROW(requireMarchableWall(surface::testing::upperHalfOfRefinedCube(), true));
}

TEST(Domain, RaysMeetSphereBoxAndCylinderWhereTheClosedFormsSay) {
  Domain sphere;
  sphere.centre = Vector3d(1.0, 2.0, 3.0);
  sphere.size = 5.0;
  EXPECT_LT((sphere.onBoundary(Vector3d(1.0, 2.0, 4.0)) - Vector3d(1.0, 2.0, 8.0)).norm(), 1e-14);
  EXPECT_EQ(sphere.conditionAt(Vector3d(6.0, 2.0, 3.0)), BoundaryCondition::Farfield);

  Domain box;
  box.shape = DomainShape::Box;
  box.halfExtent = Vector3d(4.0, 2.0, 1.0);
  // (1, 0.5, 0.1) is (1, 0.5, 0.1) on the unit cube, scaled to the box (4, 1, 0.1); the cube's
  // diagonal x = y goes to the box's edge x = 4, y = 2.
  EXPECT_LT((box.onBoundary(Vector3d(1.0, 0.5, 0.1)) - Vector3d(4.0, 1.0, 0.1)).norm(), 1e-14);
  EXPECT_LT((box.onBoundary(Vector3d(0.3, 0.3, -0.1)) - Vector3d(4.0, 2.0, -1.0 / 3.0)).norm(), 1e-14);
  // Within 1e-6 of an edge a point is put on it.
  const Vector3d nearEdge = box.onBoundary(Vector3d(1.0, 1.0 - 1e-8, 0.3));
  EXPECT_EQ(nearEdge.x(), 4.0);
  EXPECT_EQ(nearEdge.y(), 2.0);
  EXPECT_EQ(box.conditionAt(Vector3d(-4.0, 0.5, 0.5)), BoundaryCondition::Inlet);
  EXPECT_EQ(box.conditionAt(Vector3d(4.0, 0.5, 0.5)), BoundaryCondition::Outlet);
  EXPECT_EQ(box.conditionAt(Vector3d(1.0, 0.5, -1.0)), BoundaryCondition::Side);
  EXPECT_EQ(box.pieceAt(Vector3d(1.0, 0.5, -1.0)), 4);
  EXPECT_DOUBLE_EQ(box.distanceToPiece(Vector3d(1.0, 0.5, -0.75), 4), 0.25);

  Domain cylinder;
  cylinder.shape = DomainShape::Cylinder;
  cylinder.size = 10.0;
  cylinder.flowDirection = Vector3d(0.0, 0.0, 1.0);
  // Along the flow axis z: through the downstream end, else through the side of radius 10.
  EXPECT_LT((cylinder.onBoundary(Vector3d(0.1, 0.0, 1.0)) - Vector3d(1.0, 0.0, 10.0)).norm(), 1e-13);
  EXPECT_LT((cylinder.onBoundary(Vector3d(3.0, 4.0, 1.0)) - Vector3d(6.0, 8.0, 2.0)).norm(), 1e-13);
  EXPECT_EQ(cylinder.conditionAt(Vector3d(0.0, 0.0, -10.0)), BoundaryCondition::Inlet);
  EXPECT_EQ(cylinder.conditionAt(Vector3d(6.0, 8.0, 2.0)), BoundaryCondition::Side);

  Domain bad = box;
  bad.halfExtent.y() = 0.0;
  EXPECT_THROW(bad.validate(), InvalidInputError);
  bad = cylinder;
  bad.flowDirection = Vector3d(0.0, 0.0, 2.0);
  EXPECT_THROW(bad.validate(), InvalidInputError);
  EXPECT_THROW(domainShapeOf("cone"), InvalidInputError);
}

TEST(VolumeMesh, RefinedCubeInABoxHasItsOuterFacesOnTheBoxPlanes) {
  // The refined cube's limit surface (symmetric about x = 0, y = 0, z = 0 and the diagonal planes,
  // in which its chart borders run) in a box of half sizes 20, 15, 12 around it: every block's
  // outer face on one face of the box.
  const surface::QuadControlMesh cube = surface::testing::subdivide(surface::testing::cube(), 2);
  VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.05;
  options.farfieldDistance = 15.0;
  options.domain = DomainShape::Box;
  options.boxHalfExtent = Vector3d(20.0, 0.0, 12.0);  // y: the far-field distance
  const VolumeMesh result = generateVolumeMesh(cube, options);
  EXPECT_DOUBLE_EQ(result.domain.halfExtent.y(), 15.0);
  std::map<BoundaryCondition, int> tags;
  for (const Block& block : result.blocks.blocks()) {
    const BoundaryCondition condition = block.faces[static_cast<size_t>(BlockFaceSide::WMax)].condition;
    ++tags[condition];
    const int f = static_cast<int>(BlockFaceSide::WMax);
    const std::array<int, 2> counts = BlockMesh::facePoleCounts(block.volume, f);
    const Vector3d middle = block.volume.poles().row(BlockMesh::facePole(block.volume, f, counts[0] / 2, counts[1] / 2)).transpose();
    const int piece = result.domain.pieceAt(middle);
    for (int a = 0; a < counts[0]; ++a) {
      for (int b = 0; b < counts[1]; ++b) {
        const Vector3d pole = block.volume.poles().row(BlockMesh::facePole(block.volume, f, a, b)).transpose();
        EXPECT_LT(result.domain.distanceToPiece(pole, piece), 1e-11 * 20.0);
      }
    }
  }
  EXPECT_EQ(result.farfieldFacesAcrossDomainEdges, 0);
  EXPECT_EQ(tags[BoundaryCondition::Inlet], tags[BoundaryCondition::Outlet]);
  EXPECT_GT(tags[BoundaryCondition::Inlet], 0);
  EXPECT_GT(tags[BoundaryCondition::Side], 0);
  EXPECT_EQ(tags[BoundaryCondition::Farfield], 0);
  EXPECT_GT(sampleQuality(result.blocks).minScaledJacobian, 0.2);

  options.boxHalfExtent = Vector3d(20.0, 0.04, 12.0);
  EXPECT_THROW(generateVolumeMesh(cube, options), InvalidInputError);  // inside the boundary layer
  options.boxHalfExtent = Vector3d(20.0, -1.0, 12.0);
  EXPECT_THROW(generateVolumeMesh(cube, options), InvalidInputError);
  options.boxHalfExtent = Vector3d::Zero();
  options.flowDirection = Vector3d::Zero();
  EXPECT_THROW(generateVolumeMesh(cube, options), InvalidInputError);
}

TEST(VolumeMesh, LayersMarchedFromACoarserWallAreCarriedOntoTheWall) {
  // The cube refined once is marched and its layers carried onto the cube refined three times:
  // the same limit surface (subdivision without refitting), so at every block corner (a control
  // vertex of both) each layer is where the coarse marching put it, while the wall faces are the
  // fine wall's charts, the same as when the fine wall is marched itself.
  const surface::QuadControlMesh coarse = surface::testing::subdivide(surface::testing::cube(), 1);
  const surface::QuadControlMesh fine = surface::testing::subdivide(surface::testing::cube(), 3);
  VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.05;
  const VolumeMesh marched = generateVolumeMesh(coarse, options);
  const VolumeMesh carried = generateVolumeMesh(fine, options, &coarse);
  const VolumeMesh own = generateVolumeMesh(fine, options);
  ASSERT_EQ(carried.blocks.blockCount(), own.blocks.blockCount());
  EXPECT_EQ(carried.layerDistance, marched.layerDistance);
  auto at = [](const BsplineVolume& volume, double u, double v, double w) {
    RowMatrixX3d parameters(1, 3), points;
    parameters << u, v, w;
    volume.evaluate(parameters, points);
    return Vector3d(points.row(0).transpose());
  };
  for (int b = 0; b < carried.blocks.blockCount(); ++b) {
    const BsplineVolume& mine = carried.blocks.blocks()[static_cast<size_t>(b)].volume;
    const BsplineVolume& theirs = own.blocks.blocks()[static_cast<size_t>(b)].volume;
    const int f = static_cast<int>(BlockFaceSide::WMin);
    const std::array<int, 2> counts = BlockMesh::facePoleCounts(mine, f);
    for (int a = 0; a < counts[0]; ++a) {
      for (int c = 0; c < counts[1]; ++c) {
        EXPECT_EQ(mine.poles().row(BlockMesh::facePole(mine, f, a, c)), theirs.poles().row(BlockMesh::facePole(theirs, f, a, c)));
      }
    }
    // Each wall corner: the coarse block corner at the same place, then layer by layer.
    for (double u : {mine.lower(0), mine.upper(0)}) {
      for (double v : {mine.lower(1), mine.upper(1)}) {
        const Vector3d corner = at(mine, u, v, 0.0);
        bool found = false;
        for (const Block& block : marched.blocks.blocks()) {
          const BsplineVolume& m = block.volume;
          for (double cu : {m.lower(0), m.upper(0)}) {
            for (double cv : {m.lower(1), m.upper(1)}) {
              if ((at(m, cu, cv, 0.0) - corner).norm() > 1e-9) continue;
              found = true;
              for (size_t k = 1; k < marched.layerDistance.size(); ++k) {
                const double w = marched.layerDistance[k] / marched.layerDistance.back();
                EXPECT_LT((at(mine, u, v, w) - at(m, cu, cv, w)).norm(), 1e-9 * 20.0) << "block " << b << " layer " << k;
              }
            }
          }
        }
        EXPECT_TRUE(found) << "block " << b;
      }
    }
  }
  EXPECT_GT(sampleQuality(carried.blocks).minScaledJacobian, 0.2);

  auto message = [&](const surface::QuadControlMesh& marching) {
    try {
      generateVolumeMesh(fine, options, &marching);
    } catch (const InvalidInputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(fine).find("is not a coarser level of the wall"), std::string::npos);
  // The same coarse mesh with its vertices numbered differently: the fine wall is not its refinement.
  surface::QuadControlMesh renumbered = coarse;
  const Eigen::Index n = coarse.vertices.rows();
  for (Eigen::Index v = 0; v < n; ++v) renumbered.vertices.row((v + 1) % n) = coarse.vertices.row(v);
  for (Eigen::Index q = 0; q < coarse.faces.rows(); ++q) {
    for (int c = 0; c < 4; ++c) renumbered.faces(q, c) = static_cast<int>((coarse.faces(q, c) + 1) % n);
  }
  EXPECT_NE(message(renumbered).find("has no patch of the marching wall with the same corners"), std::string::npos);
  surface::QuadControlMesh scaled = coarse;
  scaled.vertices *= 1.2;
  EXPECT_NE(message(scaled).find("from the marching wall at"), std::string::npos);
}

TEST(VolumeMesh, BadWallsAndOptionsGetClearErrors) {
  surface::QuadControlMesh wall = surface::testing::subdivide(surface::testing::cube(), 1);
  VolumeMeshOptions options;
  options.boundaryLayerThickness = 0.05;
  auto message = [&](const surface::QuadControlMesh& mesh, const VolumeMeshOptions& o) {
    try {
      generateVolumeMesh(mesh, o);
    } catch (const InvalidInputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  surface::QuadControlMesh inward = wall;
  for (Eigen::Index f = 0; f < inward.faces.rows(); ++f) std::swap(inward.faces(f, 1), inward.faces(f, 3));
  EXPECT_NE(message(inward, options).find("oriented inwards"), std::string::npos);
  VolumeMeshOptions close = options;
  close.farfieldDistance = 0.04;
  EXPECT_NE(message(wall, close).find("far-field distance"), std::string::npos);
  VolumeMeshOptions near = options;
  near.farfieldDistance = 0.85;
  EXPECT_NE(message(wall, near).find("leaves no room"), std::string::npos);
  VolumeMeshOptions growth = options;
  growth.farfieldGrowth = 1.0;
  EXPECT_NE(message(wall, growth).find("far-field growth"), std::string::npos);
  VolumeMeshOptions layers = options;
  layers.boundaryLayerLayers = 0;
  EXPECT_NE(message(wall, layers).find("boundary-layer layers"), std::string::npos);
  VolumeMeshOptions negative = options;
  negative.boundaryLayerThickness = -1.0;
  EXPECT_NE(message(wall, negative).find("boundary-layer thickness"), std::string::npos);
  VolumeMeshOptions nan = options;
  nan.reynoldsNumber = std::nan("");
  EXPECT_NE(message(wall, nan).find("Reynolds"), std::string::npos);
}

}  // namespace
}  // namespace bvmesh::volume

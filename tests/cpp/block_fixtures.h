// Hand-made block meshes for the grid, quality and writer tests: the box [0, 2]^3 as 2 x 2 x 2
// blocks, each a tricubic B-spline whose (u, v, w) axes are turned (and in one block mirrored)
// relative to x, y, z, so that connections need every orientation flag. Poles sit on a global
// integer lattice (Greville points of the blocks' knots, in sixths), mapped through a smooth
// warp, so shared faces are identical bit for bit; connections are found by matching lattice
// points, independently of the code under test.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <map>
#include <vector>

#include "core/common/bspline_basis.h"
#include "core/volume/block_mesh.h"
#include "core/volume/domain.h"

namespace bvmesh::test {

using Lattice = std::array<int, 3>;

// Signed axis permutations: column d is where parameter direction d points (+-x, +-y, +-z).
inline std::array<Lattice, 3> blockAxes(int block) {
  static const std::array<std::array<Lattice, 3>, 8> axes{{
      {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}},
      {{{0, 1, 0}, {-1, 0, 0}, {0, 0, 1}}},    // turned about z
      {{{-1, 0, 0}, {0, -1, 0}, {0, 0, 1}}},   // turned half round
      {{{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}},     // axes cycled
      {{{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}},    // turned about x
      {{{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}},    // mirrored (left-handed)
      {{{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}},
      {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}},
  }};
  return axes[static_cast<size_t>(block)];
}

// The warp applied to lattice positions (identity when `amplitude` is 0); it keeps the box's
// faces planar (a symmetry plane must be).
inline Eigen::Vector3d warp(const Eigen::Vector3d& x, double amplitude) {
  const double h = M_PI / 2.0;
  return x + amplitude * Eigen::Vector3d(std::sin(h * x.x()) * std::cos(2.0 * x.y()), std::sin(h * x.y()) * std::cos(1.5 * x.z()),
                                         std::sin(h * x.z()) * std::cos(x.x()));
}

struct BoxBlocks {
  volume::BlockMesh mesh;
  std::vector<std::vector<Lattice>> lattice;  // per block, per pole row: its lattice point
};

// The box [0, 2] x [0, 2] x [0, layers] as 2 x 2 x layers blocks (layers 1 or 2). Faces of the
// box: z = 0 wall, x = 0 symmetry, the others far field (or all far field).
inline BoxBlocks boxBlocks(double warpAmplitude, bool withWall = true, int layers = 2) {
  const std::vector<double> knots = uniformClampedKnots(3, 2);  // 0 0 0 0 1 2 2 2 2
  const std::array<int, 5> greville{0, 1, 3, 5, 6};             // Greville points 0 1/3 1 5/3 2, in sixths of a block
  BoxBlocks result;
  std::vector<volume::Block> blocks;
  const int blockCount = 4 * layers;
  for (int b = 0; b < blockCount; ++b) {
    const Lattice origin{6 * (b % 2), 6 * ((b / 2) % 2), 6 * (b / 4)};
    const std::array<Lattice, 3> axes = blockAxes(b);
    RowMatrixX3d poles(125, 3);
    std::vector<Lattice> points(125);
    for (int k = 0; k < 5; ++k) {
      for (int j = 0; j < 5; ++j) {
        for (int i = 0; i < 5; ++i) {
          const std::array<int, 3> local{greville[static_cast<size_t>(i)] - 3, greville[static_cast<size_t>(j)] - 3,
                                         greville[static_cast<size_t>(k)] - 3};
          Lattice global{};
          for (int x = 0; x < 3; ++x) {
            global[static_cast<size_t>(x)] = origin[static_cast<size_t>(x)] + 3;
            for (int d = 0; d < 3; ++d) {
              global[static_cast<size_t>(x)] += axes[static_cast<size_t>(d)][static_cast<size_t>(x)] * local[static_cast<size_t>(d)];
            }
          }
          const int row = i + 5 * (j + 5 * k);
          points[static_cast<size_t>(row)] = global;
          const Eigen::Vector3d position(global[0] / 6.0, global[1] / 6.0, global[2] / 6.0);
          poles.row(row) = warp(position, warpAmplitude).transpose();
        }
      }
    }
    volume::Block block;
    block.volume = volume::BsplineVolume({3, 3, 3}, {knots, knots, knots}, poles);
    result.lattice.push_back(points);
    blocks.push_back(block);
  }
  // Faces: on the box boundary a condition, else the neighbour face with the same corner points.
  auto corner = [&](int b, int face, int a, int c) {
    const std::array<int, 3> ijk = volume::faceGridPosition({5, 5, 5}, face, a, c);
    return result.lattice[static_cast<size_t>(b)][static_cast<size_t>(ijk[0] + 5 * (ijk[1] + 5 * ijk[2]))];
  };
  for (int b = 0; b < blockCount; ++b) {
    for (int f = 0; f < 6; ++f) {
      volume::BlockFace& face = blocks[static_cast<size_t>(b)].faces[static_cast<size_t>(f)];
      const Lattice p = corner(b, f, 2, 2);  // the face's middle point
      if (p[2] == 0) face.condition = withWall ? volume::BoundaryCondition::Wall : volume::BoundaryCondition::Farfield;
      else if (p[0] == 0) face.condition = withWall ? volume::BoundaryCondition::Symmetry : volume::BoundaryCondition::Farfield;
      else if (p[0] == 12 || p[1] == 0 || p[1] == 12 || p[2] == 6 * layers) face.condition = volume::BoundaryCondition::Farfield;
      else {
        face.condition = volume::BoundaryCondition::Connected;
        for (int o = 0; o < blockCount; ++o) {
          for (int g = 0; g < 6; ++g) {
            if ((o == b && g == f) || corner(o, g, 2, 2) != p) continue;
            // Where my face's (4, 0) and (0, 4) corners are on theirs gives the orientation.
            std::map<Lattice, std::array<int, 2>> theirs;
            for (int a = 0; a < 5; a += 4) {
              for (int c = 0; c < 5; c += 4) theirs[corner(o, g, a, c)] = {a, c};
            }
            const std::array<int, 2> origin = theirs.at(corner(b, f, 0, 0));
            const std::array<int, 2> alongFirst = theirs.at(corner(b, f, 4, 0));
            face.neighbour.block = o;
            face.neighbour.face = g;
            face.neighbour.swapped = alongFirst[0] == origin[0];
            const std::array<int, 2> alongSecond = theirs.at(corner(b, f, 0, 4));
            face.neighbour.reverseFirst = face.neighbour.swapped ? alongSecond[0] < origin[0] : alongFirst[0] < origin[0];
            face.neighbour.reverseSecond = face.neighbour.swapped ? alongFirst[1] < origin[1] : alongSecond[1] < origin[1];
          }
        }
      }
    }
  }
  result.mesh = volume::BlockMesh(std::move(blocks));
  return result;
}

// A box domain around the one-layer box: centre (1, 1.03, 0.5) (off the grid's diagonals, so that
// no quad centre lies where two box faces tie), half sizes (1, 0.5, 0.5), flow along +x. The volume stage's box takes a point along its ray onto the cube [-1, 1]^3 round the centre
// before scaling (so that a cube-like layout's diagonal planes end on the box's edges), so the
// box face a point lies on is the one of its largest |x - c|: the block box's top and bottom
// faces reach over the domain's edges (inlet and outlet at their ends in x, side elsewhere).
// That rule is worked out here on its own.
inline volume::Domain boxDomain() {
  volume::Domain domain;
  domain.shape = volume::DomainShape::Box;
  domain.centre = Eigen::Vector3d(1.0, 1.03, 0.5);
  domain.halfExtent = Eigen::Vector3d(1.0, 0.5, 0.5);
  domain.flowDirection = Eigen::Vector3d::UnitX();
  return domain;
}

inline volume::BoundaryCondition boxDomainPart(const Eigen::Vector3d& x) {
  const Eigen::Vector3d q = x - Eigen::Vector3d(1.0, 1.03, 0.5);
  Eigen::Index axis = 0;
  q.cwiseAbs().maxCoeff(&axis);
  if (axis != 0) return volume::BoundaryCondition::Side;
  return q.x() > 0.0 ? volume::BoundaryCondition::Outlet : volume::BoundaryCondition::Inlet;
}

// The one-layer box without a wall, each outer face tagged by where its middle lies in the box
// domain (as the volume stage tags far-field faces).
inline volume::BlockMesh boxInBoxDomain() {
  std::vector<volume::Block> blocks = boxBlocks(0.0, false, 1).mesh.blocks();
  for (volume::Block& block : blocks) {
    for (int f = 0; f < 6; ++f) {
      volume::BlockFace& face = block.faces[static_cast<size_t>(f)];
      if (face.condition == volume::BoundaryCondition::Connected) continue;
      const std::array<int, 3> n{block.volume.poleCount(0), block.volume.poleCount(1), block.volume.poleCount(2)};
      const std::array<int, 2> counts = volume::faceGridCounts(n, f);
      const std::array<int, 3> middle = volume::faceGridPosition(n, f, counts[0] / 2, counts[1] / 2);
      face.condition = boxDomainPart(block.volume.poles().row(block.volume.poleIndex(middle[0], middle[1], middle[2])).transpose());
    }
  }
  return volume::BlockMesh(std::move(blocks));
}

// How fanWedgeBlocks shapes its blocks off the wall: knot spans along w; the fan's lines gathering
// towards its upper side the farther out they are (at distance t, fraction along^(1 + gather t)
// of the turn: 0, evenly spaced and alike in every layer); and with `wallAtEnd` the same volume
// parametrised from the far field in (the walls and the edge at w_max).
struct FanWedgeShape {
  int normalSpans = 2;
  double gather = 0.0;
  bool wallAtEnd = false;
};

// A sharp edge as a fan: the y axis (y in [0, 1]) is the edge of a wedge of half angle `alpha`
// (radians) whose upper and lower faces run along -x; block 0 stands on the upper face (u = y,
// v from the edge along it to length 2, w along its normal to height 1), block 1 on the lower face
// (v towards the edge), and block 2 fans round the edge from the lower face's normal to the
// upper's through +x (u = y, v the angle, w the distance from the edge): its w_min face is the
// edge itself, collapsed along v. Its side faces are the other blocks' edge faces, poles computed
// by the same expression, so they are identical bit for bit. The face y = 0 is a symmetry plane,
// the other outer ones far field.
inline volume::BlockMesh fanWedgeBlocks(double alpha, const FanWedgeShape& shape = {}) {
  const std::vector<double> knots = uniformClampedKnots(3, 2);  // 5 poles, Greville 0 1/3 1 5/3 2 (in halves)
  const std::array<double, 5> greville{0.0, 1.0 / 6.0, 0.5, 5.0 / 6.0, 1.0};
  const std::vector<double> normalKnots = uniformClampedKnots(3, shape.normalSpans);
  const std::vector<double> normalGreville = grevilleAbscissae(normalKnots, 3);
  const int nw = static_cast<int>(normalGreville.size());
  const Eigen::Vector3d upper(std::sin(alpha), 0.0, std::cos(alpha)), lower(std::sin(alpha), 0.0, -std::cos(alpha));
  // A point of the line leaving the edge at span y, distance t along `direction`.
  auto offEdge = [](double y, double t, const Eigen::Vector3d& direction) -> Eigen::Vector3d {
    return Eigen::Vector3d(0.0, y, 0.0) + t * direction;
  };
  std::vector<volume::Block> blocks(3);
  for (int b = 0; b < 3; ++b) {
    RowMatrixX3d poles(25 * nw, 3);
    for (int k = 0; k < nw; ++k) {
      const double t = normalGreville[static_cast<size_t>(shape.wallAtEnd ? nw - 1 - k : k)] / shape.normalSpans;
      for (int j = 0; j < 5; ++j) {
        for (int i = 0; i < 5; ++i) {
          const double y = greville[static_cast<size_t>(i)];
          const double along = greville[static_cast<size_t>(j)];
          Eigen::Vector3d x;
          if (b == 0) {
            x = along == 0.0 ? offEdge(y, t, upper)
                             : Eigen::Vector3d(-2.0 * along * std::cos(alpha), y, 2.0 * along * std::sin(alpha)) + t * upper;
          } else if (b == 1) {
            const double s = 1.0 - along;  // towards the edge
            x = s == 0.0 ? offEdge(y, t, lower)
                         : Eigen::Vector3d(-2.0 * s * std::cos(alpha), y, -2.0 * s * std::sin(alpha)) + t * lower;
          } else {
            const double turned = std::pow(along, 1.0 + shape.gather * t);
            const double angle = (2.0 * turned - 1.0) * (M_PI / 2.0 - alpha);  // lower normal .. upper normal
            const Eigen::Vector3d direction = along == 0.0   ? lower
                                              : along == 1.0 ? upper
                                                             : Eigen::Vector3d(std::cos(angle), 0.0, std::sin(angle));
            x = offEdge(y, t, direction);
          }
          poles.row(i + 5 * (j + 5 * k)) = x.transpose();
        }
      }
    }
    volume::Block& block = blocks[static_cast<size_t>(b)];
    block.volume = volume::BsplineVolume({3, 3, 3}, {knots, knots, normalKnots}, poles);
    using volume::BoundaryCondition;
    for (volume::BlockFace& face : block.faces) face.condition = BoundaryCondition::Farfield;
    block.faces[static_cast<size_t>(volume::BlockFaceSide::UMin)].condition = BoundaryCondition::Symmetry;
    block.faces[static_cast<size_t>(shape.wallAtEnd ? volume::BlockFaceSide::WMax : volume::BlockFaceSide::WMin)]
        .condition = b == 2 ? BoundaryCondition::Collapsed : BoundaryCondition::Wall;
  }
  auto link = [&](int b, volume::BlockFaceSide side, int other, volume::BlockFaceSide otherSide) {
    volume::BlockFace& face = blocks[static_cast<size_t>(b)].faces[static_cast<size_t>(side)];
    face.condition = volume::BoundaryCondition::Connected;
    face.neighbour.block = other;
    face.neighbour.face = static_cast<int>(otherSide);
  };
  link(0, volume::BlockFaceSide::VMin, 2, volume::BlockFaceSide::VMax);
  link(2, volume::BlockFaceSide::VMax, 0, volume::BlockFaceSide::VMin);
  link(1, volume::BlockFaceSide::VMax, 2, volume::BlockFaceSide::VMin);
  link(2, volume::BlockFaceSide::VMin, 1, volume::BlockFaceSide::VMax);
  return volume::BlockMesh(std::move(blocks));
}

}  // namespace bvmesh::test

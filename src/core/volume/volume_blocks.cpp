#include "core/volume/volume_blocks.h"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <string>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"
#include "core/common/math_constants.h"
#include "core/surface/limit_bsplines.h"
#include "core/volume/edge_fans.h"
#include "core/volume/hex_scaled_jacobian.h"
#include "core/volume/layer_transfer.h"
#include "core/volume/turning.h"
#include "core/volume/wall_grid.h"
#include "core/volume/wall_topology.h"

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

// Values of the cubic basis on `knots` (one column per pole) at the parameters (one row each).
Eigen::MatrixXd collocationMatrix(const std::vector<double>& knots, const std::vector<double>& at) {
  Eigen::MatrixXd matrix = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(at.size()),
                                                 static_cast<Eigen::Index>(knots.size()) - 4);
  for (size_t r = 0; r < at.size(); ++r) {
    const int span = findKnotSpan(knots, 3, at[r]);
    double values[4];
    basisFunctions(knots, 3, span, at[r], values);
    for (int c = 0; c < 4; ++c) matrix(static_cast<Eigen::Index>(r), span - 3 + c) = values[c];
  }
  return matrix;
}

// Interpolation at the Greville abscissae of a clamped cubic with uniform knots (the patches'
// knot vectors): the square collocation matrix, factored once.
struct GrevilleInterpolation {
  explicit GrevilleInterpolation(const std::vector<double>& knots)
      : lu(collocationMatrix(knots, grevilleAbscissae(knots, 3))) {}
  // Poles for data rows (one row per abscissa); the end poles are the end data, exactly.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& data) const {
    Eigen::MatrixXd poles = lu.solve(data);
    poles.row(0) = data.row(0);
    poles.row(poles.rows() - 1) = data.row(data.rows() - 1);
    return poles;
  }
  Eigen::PartialPivLU<Eigen::MatrixXd> lu;
};

// Averaging knots for interpolation at increasing parameters t_0 = 0 ... t_K = 1 (de Boor).
std::vector<double> averagingKnots(const std::vector<double>& t) {
  const int n = static_cast<int>(t.size());
  std::vector<double> knots(4, 0.0);
  for (int j = 1; j + 3 < n; ++j) knots.push_back((t[static_cast<size_t>(j)] + t[static_cast<size_t>(j + 1)] + t[static_cast<size_t>(j + 2)]) / 3.0);
  knots.insert(knots.end(), 4, 1.0);
  return knots;
}

// The condition of a block's far-field face from where the middle of its outer poles lies on the
// domain boundary; counts the face in `acrossEdges` when some of its poles are off that piece's
// surface (the face bends around an edge of a box or cylinder, or cuts across it).
BoundaryCondition outerCondition(const Domain& domain, const Eigen::MatrixXd& outerPoles, int& acrossEdges) {
  const Eigen::Index middle = outerPoles.rows() / 2;
  const int piece = domain.pieceAt(outerPoles.row(middle).transpose());
  const double tolerance = 1e-9 * (domain.shape == DomainShape::Box ? domain.halfExtent.maxCoeff() : domain.size);
  for (Eigen::Index r = 0; r < outerPoles.rows() && domain.shape != DomainShape::Sphere; ++r) {
    if (domain.distanceToPiece(outerPoles.row(r).transpose(), piece) > tolerance) {
      ++acrossEdges;
      break;
    }
  }
  return domain.conditionAt(outerPoles.row(middle).transpose());
}

// Per patch and layer the poles of the bicubic surface interpolating the layer's points at the
// patch's Greville abscissae ((nu * nv) x 3, row i * nv + j); layer 0 keeps the patch poles. Sides
// and corners are solved once and shared, so neighbours agree bit for bit.
std::vector<std::vector<Eigen::MatrixXd>> layerPatchPoles(const std::vector<WallPatch>& patches, const WallGrid& grid,
                                                          const std::vector<RowMatrixX3d>& layers) {
  const int layerCount = static_cast<int>(layers.size());
  std::map<int, GrevilleInterpolation> interpolation;  // by pole count (uniform knots)
  auto interpolator = [&](const std::vector<double>& knots) -> const GrevilleInterpolation& {
    const int n = static_cast<int>(knots.size()) - 4;
    auto found = interpolation.find(n);
    if (found == interpolation.end()) found = interpolation.emplace(n, GrevilleInterpolation(knots)).first;
    return found->second;
  };
  std::vector<std::vector<Eigen::MatrixXd>> layerPoles(patches.size());
  for (size_t p = 0; p < patches.size(); ++p) {
    const PatchSurface& surface = patches[p].surface;
    const int nu = surface.uPoles, nv = surface.vPoles;
    const GrevilleInterpolation& iu = interpolator(surface.uKnots);
    const GrevilleInterpolation& iv = interpolator(surface.vKnots);
    layerPoles[p].resize(static_cast<size_t>(layerCount));
    for (int k = 0; k < layerCount; ++k) {
      Eigen::MatrixXd poles(nu * nv, 3);
      if (k == 0) {
        for (int q = 0; q < nu * nv; ++q) poles.row(q) = surface.poles[static_cast<size_t>(q)].transpose();
      } else {
        const RowMatrixX3d& points = layers[static_cast<size_t>(k)];
        for (int x = 0; x < 3; ++x) {
          Eigen::MatrixXd data(nu, nv);
          for (int i = 0; i < nu; ++i) {
            for (int j = 0; j < nv; ++j) data(i, j) = points(grid.pointOf[p][static_cast<size_t>(i * nv + j)], x);
          }
          const Eigen::MatrixXd alongU = iu.lu.solve(data);
          const Eigen::MatrixXd both = iv.lu.solve(alongU.transpose()).transpose();
          for (int i = 0; i < nu; ++i) {
            for (int j = 0; j < nv; ++j) poles(i * nv + j, x) = both(i, j);
          }
        }
      }
      layerPoles[p][static_cast<size_t>(k)] = std::move(poles);
    }
  }
  // Shared sides: the first patch on a side gives its poles (layer 0) or the side's own 1-D
  // interpolation (other layers) to every patch on it; corners are the layer points themselves.
  // Fans first: their poles on the wall are their edge's (one copy's), which their sides give to
  // the edge's faces, so that a fan's wall face is one curve bit for bit.
  std::map<std::pair<std::vector<int>, int>, bool> sideDone;
  std::vector<size_t> order(patches.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_partition(order.begin(), order.end(), [&](size_t p) { return patches[p].fan; });
  for (size_t p : order) {
    for (int s = 0; s < 4; ++s) {
      const ChartSide side = static_cast<ChartSide>(s);
      const WallPatch& patch = patches[p];
      const SideKey key = sideKey(patch, side);
      if (sideDone.count(key.id) > 0) continue;
      sideDone[key.id] = true;
      const int length = sidePoleCount(patch, side);
      const std::vector<double>& knots = side == ChartSide::VMin || side == ChartSide::VMax ? patch.surface.uKnots : patch.surface.vKnots;
      const GrevilleInterpolation& along = interpolator(knots);
      const PatchSideLink& link = patch.sides[static_cast<size_t>(s)];
      for (int k = 0; k < layerCount; ++k) {
        Eigen::MatrixXd row(length, 3);
        if (k == 0) {
          for (int t = 0; t < length; ++t) {
            const auto [i, j] = sidePolePosition(patch, side, t);
            row.row(t) = layerPoles[p][0].row(i * patch.surface.vPoles + j);
          }
        } else {
          Eigen::MatrixXd data(length, 3);
          for (int t = 0; t < length; ++t) {
            const auto [i, j] = sidePolePosition(patch, side, t);
            data.row(t) = layers[static_cast<size_t>(k)].row(grid.pointOf[p][static_cast<size_t>(i * patch.surface.vPoles + j)]);
          }
          row = along.solve(data);
        }
        auto write = [&](size_t target, ChartSide targetSide, bool reversed) {
          const WallPatch& other = patches[target];
          for (int t = 0; t < length; ++t) {
            const auto [i, j] = sidePolePosition(other, targetSide, reversed ? length - 1 - t : t);
            layerPoles[target][static_cast<size_t>(k)].row(i * other.surface.vPoles + j) = row.row(t);
          }
        };
        write(p, side, false);
        if (link.patch >= 0) write(static_cast<size_t>(link.patch), link.side, link.reversed);
      }
    }
  }
  // Corners: the point shared by every patch there, on the wall too, where three or more patches
  // meet and the sides above, written pair by pair, can leave them their own roundings of it; a
  // collapsed side (a fan's closed end) is its corner's point all along.
  for (size_t p = 0; p < patches.size(); ++p) {
    const WallPatch& patch = patches[p];
    const int nu = patch.surface.uPoles, nv = patch.surface.vPoles;
    for (int k = 0; k < layerCount; ++k) {
      Eigen::MatrixXd& poles = layerPoles[p][static_cast<size_t>(k)];
      for (const auto& [i, j] : {std::pair<int, int>{0, 0}, {nu - 1, 0}, {0, nv - 1}, {nu - 1, nv - 1}}) {
        poles.row(i * nv + j) =
            layers[static_cast<size_t>(k)].row(grid.pointOf[p][static_cast<size_t>(i * nv + j)]);
      }
      for (int s = 0; s < 4; ++s) {
        if (!patch.collapsedSide[static_cast<size_t>(s)]) continue;
        const ChartSide side = static_cast<ChartSide>(s);
        const auto [i0, j0] = sidePolePosition(patch, side, 0);
        for (int t = 1; t < sidePoleCount(patch, side); ++t) {
          const auto [i, j] = sidePolePosition(patch, side, t);
          poles.row(i * nv + j) = poles.row(i0 * nv + j0);
        }
      }
    }
  }
  return layerPoles;
}

// The blocks' second pole layer in w, set so that the wall-normal grid lines leave the wall along
// its normal: at every Greville point of the wall, where the columns' wall-normal derivative
// (their poles' offsets from the wall, blended by the patch basis) is turned onto the wall normal
// at its own length; the new offsets interpolate those (shared sides and corners once, as the
// layers'). Above the wall the lines bend into the marched ones within the first layer. Those are
// tilted by design in the splay band of a sharp edge, so that its cells fan out without folding;
// interpolated as they are, they left 5 % of the M6's wall cells more than 4 degrees off the normal.
// Where the marched lines are the normals the offsets are unchanged (turning them would move a
// sphere's layers off their radii by more than 1e-6: the offsets' interpolation carries some of
// the far field's lines too), and a corner of three or more wall faces, without a normal, keeps its own. At a
// sharp edge the normal is the mean of both sides', the bisector its line runs along.
void leaveAlongNormals(const std::vector<WallPatch>& patches, const WallGrid& grid,
                       const RowMatrixX3d& firstLayer, const BoundaryPlanes& planes,
                       std::vector<RowMatrixX3d>& blockPoles) {
  // A marched line this far off the normal or more is turned fully, one closer by its share; the
  // lines outside the band are the normals and keep the offsets exactly as interpolated.
  constexpr double kFullTurnDegrees = 1.0;
  const Eigen::Index count = grid.front.points.rows();
  RowMatrixX3d leaving = grid.front.points;  // per wall point: itself plus the turned offset
  std::vector<char> done(static_cast<size_t>(count), 0);
  for (size_t p = 0; p < patches.size(); ++p) {
    PatchSurface offsets = patches[p].surface;
    const int nu = offsets.uPoles, nv = offsets.vPoles;
    const RowMatrixX3d& poles = blockPoles[p];
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        const Eigen::Index wall = i + static_cast<Eigen::Index>(nu) * j;
        offsets.poles[static_cast<size_t>(i * nv + j)] =
            (poles.row(wall + nu * nv) - poles.row(wall)).transpose();
      }
    }
    const std::vector<double> gu = grevilleAbscissae(offsets.uKnots, 3),
                              gv = grevilleAbscissae(offsets.vKnots, 3);
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        const int id = grid.pointOf[p][static_cast<size_t>(i * nv + j)];
        if (done[static_cast<size_t>(id)] != 0) continue;
        done[static_cast<size_t>(id)] = 1;
        const Vector3d offset = offsets.point(gu[static_cast<size_t>(i)], gv[static_cast<size_t>(j)]);
        Vector3d normal = grid.front.normals.row(id).transpose();
        // On a boundary plane the wall meets the plane at a right angle: its normal lies in it.
        const unsigned onPlanes = grid.front.onPlanes[static_cast<size_t>(id)];
        if (onPlanes != 0) normal = planes.along(normal, onPlanes).normalized();
        const Vector3d line = (firstLayer.row(id) - grid.front.points.row(id)).transpose().normalized();
        const double tilt = std::acos(std::clamp(line.dot(normal), -1.0, 1.0)) * 180.0 / kPi;
        // A fan's lines leave no wall of their own: they turn with its sides' (below).
        const double share = grid.corner[static_cast<size_t>(id)] != 0 || patches[p].fan
                                 ? 0.0
                                 : std::min(1.0, tilt / kFullTurnDegrees);
        leaving.row(id) += (offset + share * (offset.norm() * normal - offset)).transpose();
      }
    }
  }
  // A fan's lines then turn round its edge between its sides' lines as these now leave (on the
  // symmetry plane, in it). Where the fan closes, its sides' lines turn back onto their faces'
  // normals from a lean along the edge that the fan's own would keep: its cells, spaced unevenly
  // round the edge, would taper unevenly along it (thin prisms whose cell centres shift along the
  // edge: faces of 90 degrees' non-orthogonality).
  for (const FanPoint& fan : grid.front.fanPoints) {
    const auto offset = [&](int point) -> Vector3d {
      return (leaving.row(point) - grid.front.points.row(point)).transpose();
    };
    const unsigned onPlanes = grid.front.onPlanes[static_cast<size_t>(fan.point)];
    const Vector3d axis =
        onPlanes != 0 ? planes.normal[(onPlanes & kSymmetryPlaneBit) != 0 ? 0 : 1]
                      : Vector3d(grid.front.normals.row(fan.from).cross(grid.front.normals.row(fan.to)));
    const Vector3d line = turnedRound(offset(fan.from).normalized(), offset(fan.to).normalized(), axis,
                                      fan.fraction, fan.outside);
    leaving.row(fan.point) = grid.front.points.row(fan.point) + offset(fan.point).norm() * line.transpose();
  }
  const std::vector<std::vector<Eigen::MatrixXd>> leavingPoles =
      layerPatchPoles(patches, grid, {grid.front.points, leaving});
  // Next to a sharp edge the turn can invert a control cell of the first two layers (its line
  // along the bisector beside lines along the sides' normals), which volumetric subdivision of the
  // blocks' control mesh refuses or turns into inverted cells: there the turn is halved until no
  // corner of the cell is flatter than kFairControlCell (or than the marched cell's), per wall
  // point, so that shared poles stay shared.
  constexpr double kFairControlCell = 1e-3;
  constexpr int kHalvings = 4;
  std::vector<RowMatrixX3d> marched;  // per patch the second pole layer as interpolated, row i + nu j
  std::vector<RowMatrixX3d> turned;
  for (size_t p = 0; p < patches.size(); ++p) {
    const int nu = patches[p].surface.uPoles, nv = patches[p].surface.vPoles;
    marched.push_back(
        blockPoles[p].middleRows(static_cast<Eigen::Index>(nu) * nv, static_cast<Eigen::Index>(nu) * nv));
    RowMatrixX3d& row = turned.emplace_back(static_cast<Eigen::Index>(nu) * nv, 3);
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        const Eigen::Index wall = i + static_cast<Eigen::Index>(nu) * j;
        row.row(wall) = blockPoles[p].row(wall) +
                        (leavingPoles[p][1].row(i * nv + j) - leavingPoles[p][0].row(i * nv + j));
      }
    }
  }
  std::vector<double> share(static_cast<size_t>(count), 1.0);
  for (bool halved = true; halved;) {  // ends: a cell whose four shares are 0 is the marched one
    halved = false;
    for (size_t p = 0; p < patches.size(); ++p) {
      const int nu = patches[p].surface.uPoles, nv = patches[p].surface.vPoles;
      const Eigen::Index layer = static_cast<Eigen::Index>(nu) * nv;
      RowMatrixX3d& poles = blockPoles[p];
      const auto id = [&](int i, int j) {
        return static_cast<size_t>(grid.pointOf[p][static_cast<size_t>(i * nv + j)]);
      };
      for (int i = 0; i < nu; ++i) {
        for (int j = 0; j < nv; ++j) {
          const Eigen::Index wall = i + static_cast<Eigen::Index>(nu) * j;
          poles.row(layer + wall) =
              marched[p].row(wall) + share[id(i, j)] * (turned[p].row(wall) - marched[p].row(wall));
        }
      }
      const auto cell = [&](int i, int j, int k, bool asMarched) {
        std::array<Vector3d, 8> corners;  // 000 100 110 010 001 101 111 011
        const int di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
        for (int c = 0; c < 8; ++c) {
          const int a = i + di[c % 4], b = j + dj[c % 4], level = k + c / 4;
          const Eigen::Index wall = a + static_cast<Eigen::Index>(nu) * b;
          corners[static_cast<size_t>(c)] =
              (level == 1 && asMarched ? marched[p].row(wall) : poles.row(layer * level + wall)).transpose();
        }
        return hexScaledJacobian(corners);
      };
      for (int i = 0; i + 1 < nu; ++i) {
        for (int j = 0; j + 1 < nv; ++j) {
          for (int k = 0; k < 2; ++k) {
            if (cell(i, j, k, false) >= std::min(cell(i, j, k, true), kFairControlCell)) continue;
            for (const auto& [a, b] : {std::pair<int, int>{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}}) {
              share[id(a, b)] = share[id(a, b)] > std::ldexp(1.0, -kHalvings) ? 0.5 * share[id(a, b)] : 0.0;
            }
            halved = true;
          }
        }
      }
    }
  }
}

}  // namespace

VolumeMesh generateVolumeMesh(const surface::QuadControlMesh& wall, const VolumeMeshOptions& options,
                              const surface::QuadControlMesh* marchingWall) {
  surface::validateQuadControlMesh(wall);
  requireMarchableWall(wall, options.hasSymmetryPlane || options.hasOutflowPlane);
  const surface::LimitBSplines bsplines = surface::limitSurfaceToBSplines(wall);
  std::vector<WallPatch> patches = conformingWallPatches(bsplines, wall);
  if (options.knifeEdgeFans) insertEdgeFans(patches);
  WallGrid grid = wallGrid(patches);
  const std::vector<std::array<BoundaryCondition, 4>> openSides = markPlanePoints(patches, grid, options);

  VolumeMesh result;
  for (double distance : bsplines.maxDistance) result.wallMaxDistance = std::max(result.wallMaxDistance, distance);

  // The layers: marched from this wall, or from the coarser marching wall and carried over.
  std::vector<WallPatch> coarsePatches;
  WallGrid coarseGrid;
  int steps = 0;
  if (marchingWall != nullptr) {
    surface::validateQuadControlMesh(*marchingWall);
    steps = refinementSteps(*marchingWall, wall);
    if (steps < 1) {
      throw InvalidInputError("the marching wall (" + std::to_string(marchingWall->faces.rows()) +
                              " faces) is not a coarser level of the wall (" + std::to_string(wall.faces.rows()) +
                              " faces): the wall must be its control mesh subdivided 1 to 8 times");
    }
    coarsePatches = conformingWallPatches(surface::limitSurfaceToBSplines(*marchingWall), *marchingWall);
    if (options.knifeEdgeFans) insertEdgeFans(coarsePatches);
    coarseGrid = wallGrid(coarsePatches);
    markPlanePoints(coarsePatches, coarseGrid, options);
  }
  const MarchingFront& front = marchingWall != nullptr ? coarseGrid.front : grid.front;
  const ResolvedVolumeOptions resolved = resolveVolumeOptions(options, front);
  result.referenceLength = resolved.referenceLength;
  result.boundaryLayerThickness = resolved.boundaryLayerThickness;
  result.farfieldDistance = resolved.farfieldDistance;
  result.domainCentre = resolved.domainCentre;
  result.domain = resolved.marching.domain;
  MarchingResult layers = marchLayers(front, resolved.marching);
  if (marchingWall != nullptr) {
    layers = transferLayers(layers, coarsePatches, layerPatchPoles(coarsePatches, coarseGrid, layers.layers), patches,
                            grid, steps, resolved.boundaryLayerThickness, resolved.marching.domain);
  }
  result.layerDistance = layers.layerDistance;
  result.layerMinScaledJacobian = layers.layerMinScaledJacobian;
  result.farfieldLayersSmoothed = layers.farfieldLayersSmoothed;

  // w: the layers' mean distance, normalised; interpolated by one cubic per pole column.
  const int layerCount = static_cast<int>(layers.layers.size());
  std::vector<double> w(static_cast<size_t>(layerCount));
  for (int k = 0; k < layerCount; ++k) w[static_cast<size_t>(k)] = layers.layerDistance[static_cast<size_t>(k)] / layers.layerDistance.back();
  w.back() = 1.0;
  const std::vector<double> wKnots = averagingKnots(w);
  const Eigen::PartialPivLU<Eigen::MatrixXd> wSolver(collocationMatrix(wKnots, w));
  const std::vector<std::vector<Eigen::MatrixXd>> layerPoles = layerPatchPoles(patches, grid, layers.layers);

  std::vector<RowMatrixX3d> blockPoles;  // per patch, pole (i, j, k) at i + nu (j + nv k)
  for (size_t p = 0; p < patches.size(); ++p) {
    const int nu = patches[p].surface.uPoles, nv = patches[p].surface.vPoles;
    RowMatrixX3d& poles = blockPoles.emplace_back(static_cast<Eigen::Index>(nu) * nv * layerCount, 3);
    Eigen::MatrixXd column(layerCount, 3);
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        for (int k = 0; k < layerCount; ++k) column.row(k) = layerPoles[p][static_cast<size_t>(k)].row(i * nv + j);
        Eigen::MatrixXd solved = wSolver.solve(column);
        solved.row(0) = column.row(0);
        solved.row(layerCount - 1) = column.row(layerCount - 1);
        for (int k = 0; k < layerCount; ++k) {
          poles.row(i + static_cast<Eigen::Index>(nu) * (j + static_cast<Eigen::Index>(nv) * k)) = solved.row(k);
        }
      }
    }
  }
  leaveAlongNormals(patches, grid, layers.layers[1], boundaryPlanesOf(options), blockPoles);
  std::vector<Block> blocks;
  for (size_t p = 0; p < patches.size(); ++p) {
    const WallPatch& patch = patches[p];
    Block block;
    block.volume = BsplineVolume({3, 3, 3}, {patch.surface.uKnots, patch.surface.vKnots, wKnots},
                                 std::move(blockPoles[p]), "block " + std::to_string(p));
    block.faces[static_cast<size_t>(BlockFaceSide::WMin)].condition =
        patch.fan ? BoundaryCondition::Collapsed : BoundaryCondition::Wall;
    block.faces[static_cast<size_t>(BlockFaceSide::WMax)].condition =
        outerCondition(result.domain, layerPoles[p].back(), result.farfieldFacesAcrossDomainEdges);
    setLateralFaces(patch, openSides[p], block.faces);
    blocks.push_back(std::move(block));
    result.blockChart.push_back(patch.chart);
  }
  result.blocks = BlockMesh(std::move(blocks));
  return result;
}

}  // namespace bvmesh::volume

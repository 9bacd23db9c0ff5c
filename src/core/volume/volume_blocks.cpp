#include "core/volume/volume_blocks.h"

#include <Eigen/Geometry>

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"
#include "core/surface/limit_bsplines.h"
#include "core/volume/wall_patches.h"

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

const char* sideName(ChartSide side) {
  static const char* names[] = {"v_min", "u_max", "v_max", "u_min"};
  return names[static_cast<int>(side)];
}

// Position (i, j) in a patch's pole grid of entry t along a side.
std::pair<int, int> sidePosition(const WallPatch& patch, ChartSide side, int t) {
  switch (side) {
    case ChartSide::VMin:
      return {t, 0};
    case ChartSide::VMax:
      return {t, patch.surface.vPoles - 1};
    case ChartSide::UMin:
      return {0, t};
    case ChartSide::UMax:
      return {patch.surface.uPoles - 1, t};
  }
  return {0, 0};
}

int sideLength(const WallPatch& patch, ChartSide side) {
  return side == ChartSide::VMin || side == ChartSide::VMax ? patch.surface.uPoles : patch.surface.vPoles;
}

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

// The marching surface grid: every patch's Greville points, merged where patches meet.
struct WallGrid {
  MarchingFront front;
  std::vector<std::vector<int>> pointOf;  // per patch: (i, j) -> front point, at i * vPoles + j
  double size = 0.0;                      // bounding-box diagonal
  Vector3d lo, hi;
};

// A side's identity: the canonical (lexicographically smaller direction) vertex chain.
struct SideKey {
  std::vector<int> chain;
  bool reversed = false;  // the patch runs against the canonical direction
};

SideKey sideKey(const WallPatch& patch, ChartSide side) {
  const std::vector<int>& chain = patch.sideVertices[static_cast<size_t>(side)];
  std::vector<int> reversed(chain.rbegin(), chain.rend());
  if (reversed < chain) return {reversed, true};
  return {chain, false};
}

WallGrid wallGrid(const std::vector<WallPatch>& patches) {
  WallGrid grid;
  std::vector<Vector3d> points, normals;
  std::vector<int> normalCount;
  std::map<int, int> cornerPoint;                               // control vertex -> point
  std::map<std::pair<std::vector<int>, int>, int> sidePoint;     // (canonical chain, entry) -> point
  for (size_t p = 0; p < patches.size(); ++p) {
    const WallPatch& patch = patches[p];
    const PatchSurface& surface = patch.surface;
    const std::vector<double> gu = grevilleAbscissae(surface.uKnots, 3);
    const std::vector<double> gv = grevilleAbscissae(surface.vKnots, 3);
    const int nu = surface.uPoles, nv = surface.vPoles;
    std::vector<int>& ids = grid.pointOf.emplace_back(static_cast<size_t>(nu * nv), -1);
    auto idAt = [&](int i, int j) -> int {
      const bool uEnd = i == 0 || i == nu - 1, vEnd = j == 0 || j == nv - 1;
      if (uEnd && vEnd) {
        const ChartSide side = j == 0 ? ChartSide::VMin : ChartSide::VMax;
        const int vertex = patch.sideVertices[static_cast<size_t>(side)][i == 0 ? 0 : patch.sideVertices[static_cast<size_t>(side)].size() - 1];
        const auto found = cornerPoint.find(vertex);
        if (found != cornerPoint.end()) return found->second;
        return cornerPoint[vertex] = static_cast<int>(points.size());
      }
      if (uEnd || vEnd) {
        const ChartSide side = vEnd ? (j == 0 ? ChartSide::VMin : ChartSide::VMax)
                                    : (i == 0 ? ChartSide::UMin : ChartSide::UMax);
        const int t = vEnd ? i : j;
        const SideKey key = sideKey(patch, side);
        const int entry = key.reversed ? sideLength(patch, side) - 1 - t : t;
        const auto found = sidePoint.find({key.chain, entry});
        if (found != sidePoint.end()) return found->second;
        return sidePoint[{key.chain, entry}] = static_cast<int>(points.size());
      }
      return static_cast<int>(points.size());
    };
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        const int id = idAt(i, j);
        Vector3d normal;
        const Vector3d x = surface.point(gu[static_cast<size_t>(i)], gv[static_cast<size_t>(j)], &normal);
        if (id == static_cast<int>(points.size())) {
          points.push_back(x);
          normals.push_back(Vector3d::Zero());
          normalCount.push_back(0);
        }
        normals[static_cast<size_t>(id)] += normal;
        ++normalCount[static_cast<size_t>(id)];
        ids[static_cast<size_t>(i * nv + j)] = id;
      }
    }
    for (int i = 0; i + 1 < nu; ++i) {
      for (int j = 0; j + 1 < nv; ++j) {
        grid.front.quads.push_back({ids[static_cast<size_t>(i * nv + j)], ids[static_cast<size_t>((i + 1) * nv + j)],
                                    ids[static_cast<size_t>((i + 1) * nv + j + 1)], ids[static_cast<size_t>(i * nv + j + 1)]});
        grid.front.quadNames.push_back("wall patch " + std::to_string(p) + " (chart " + std::to_string(patch.chart) +
                                       ") pole cell (" + std::to_string(i) + ", " + std::to_string(j) + ")");
      }
    }
  }
  const auto count = static_cast<Eigen::Index>(points.size());
  grid.front.points.resize(count, 3);
  grid.front.normals.resize(count, 3);
  grid.front.onSymmetryPlane.assign(static_cast<size_t>(count), 0);
  for (Eigen::Index k = 0; k < count; ++k) {
    grid.front.points.row(k) = points[static_cast<size_t>(k)].transpose();
    const Vector3d n = normals[static_cast<size_t>(k)];
    if (!(n.norm() > 1e-12)) {
      throw SolverError("the wall has no normal at point " + std::to_string(k) + " (" + std::to_string(points[static_cast<size_t>(k)].x()) +
                        ", " + std::to_string(points[static_cast<size_t>(k)].y()) + ", " +
                        std::to_string(points[static_cast<size_t>(k)].z()) + "): a degenerate or folded patch");
    }
    grid.front.normals.row(k) = n.normalized().transpose();
  }
  grid.lo = grid.front.points.colwise().minCoeff().transpose();
  grid.hi = grid.front.points.colwise().maxCoeff().transpose();
  grid.size = (grid.hi - grid.lo).norm();
  return grid;
}

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

}  // namespace

VolumeMesh generateVolumeMesh(const surface::QuadControlMesh& wall, const VolumeMeshOptions& options) {
  surface::validateQuadControlMesh(wall);
  const surface::LimitBSplines bsplines = surface::limitSurfaceToBSplines(wall);
  const std::vector<WallPatch> patches = conformingWallPatches(bsplines, wall);
  WallGrid grid = wallGrid(patches);
  MarchingFront& front = grid.front;

  VolumeMesh result;
  for (double deviation : bsplines.maxDeviation) result.wallMaxDeviation = std::max(result.wallMaxDeviation, deviation);
  const Vector3d planeNormal = symmetryPlaneNormal(options);
  // Open sides must lie on the symmetry plane.
  for (size_t p = 0; p < patches.size(); ++p) {
    for (int s = 0; s < 4; ++s) {
      const WallPatch& patch = patches[p];
      if (patch.sides[static_cast<size_t>(s)].patch >= 0) continue;
      const ChartSide side = static_cast<ChartSide>(s);
      const std::vector<int>& chain = patch.sideVertices[static_cast<size_t>(s)];
      const std::string where = "wall patch " + std::to_string(p) + " side " + sideName(side) + " (control vertices " +
                                std::to_string(chain.front()) + " ... " + std::to_string(chain.back()) + ")";
      if (!options.hasSymmetryPlane) {
        throw InvalidInputError("the wall is open at " + where +
                                ": close it, or give the symmetry plane it lies on (a half model)");
      }
      for (int t = 0; t < sideLength(patch, side); ++t) {
        const auto [i, j] = sidePosition(patch, side, t);
        const int id = grid.pointOf[p][static_cast<size_t>(i * patch.surface.vPoles + j)];
        const double off = std::abs((front.points.row(id).transpose() - options.planePoint).dot(planeNormal));
        if (off > 1e-6 * grid.size) {
          throw InvalidInputError("the wall's open boundary at " + where + " lies " + std::to_string(off) +
                                  " off the symmetry plane");
        }
        front.onSymmetryPlane[static_cast<size_t>(id)] = 1;
      }
    }
  }

  const ResolvedVolumeOptions resolved = resolveVolumeOptions(options, front);
  result.referenceLength = resolved.referenceLength;
  result.boundaryLayerThickness = resolved.boundaryLayerThickness;
  result.farfieldDistance = resolved.farfieldDistance;
  result.domainCentre = resolved.domainCentre;
  result.domain = resolved.marching.domain;
  const MarchingResult layers = marchLayers(front, resolved.marching);
  result.layerDistance = layers.layerDistance;
  result.layerMinScaledJacobian = layers.layerMinScaledJacobian;

  // w: the layers' mean distance, normalised; interpolated by one cubic per pole column.
  const int layerCount = static_cast<int>(layers.layers.size());
  std::vector<double> w(static_cast<size_t>(layerCount));
  for (int k = 0; k < layerCount; ++k) w[static_cast<size_t>(k)] = layers.layerDistance[static_cast<size_t>(k)] / layers.layerDistance.back();
  w.back() = 1.0;
  const std::vector<double> wKnots = averagingKnots(w);
  const Eigen::PartialPivLU<Eigen::MatrixXd> wSolver(collocationMatrix(wKnots, w));

  // Per layer and patch: poles interpolating the layer's points at the Greville abscissae. Layer
  // 0 keeps the patch poles. Sides and corners are solved once and shared, so neighbours agree.
  std::map<int, GrevilleInterpolation> interpolation;  // by pole count (uniform knots)
  auto interpolator = [&](const std::vector<double>& knots) -> const GrevilleInterpolation& {
    const int n = static_cast<int>(knots.size()) - 4;
    auto found = interpolation.find(n);
    if (found == interpolation.end()) found = interpolation.emplace(n, GrevilleInterpolation(knots)).first;
    return found->second;
  };
  std::vector<std::vector<Eigen::MatrixXd>> layerPoles(patches.size());  // [patch][layer]: (nu * nv) x 3, i * nv + j
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
        const RowMatrixX3d& points = layers.layers[static_cast<size_t>(k)];
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
  std::map<std::vector<int>, bool> sideDone;
  for (size_t p = 0; p < patches.size(); ++p) {
    for (int s = 0; s < 4; ++s) {
      const ChartSide side = static_cast<ChartSide>(s);
      const WallPatch& patch = patches[p];
      const SideKey key = sideKey(patch, side);
      if (sideDone.count(key.chain) > 0) continue;
      sideDone[key.chain] = true;
      const int length = sideLength(patch, side);
      const std::vector<double>& knots = side == ChartSide::VMin || side == ChartSide::VMax ? patch.surface.uKnots : patch.surface.vKnots;
      const GrevilleInterpolation& along = interpolator(knots);
      const PatchSideLink& link = patch.sides[static_cast<size_t>(s)];
      for (int k = 0; k < layerCount; ++k) {
        Eigen::MatrixXd row(length, 3);
        if (k == 0) {
          for (int t = 0; t < length; ++t) {
            const auto [i, j] = sidePosition(patch, side, t);
            row.row(t) = layerPoles[p][0].row(i * patch.surface.vPoles + j);
          }
        } else {
          Eigen::MatrixXd data(length, 3);
          for (int t = 0; t < length; ++t) {
            const auto [i, j] = sidePosition(patch, side, t);
            data.row(t) = layers.layers[static_cast<size_t>(k)].row(grid.pointOf[p][static_cast<size_t>(i * patch.surface.vPoles + j)]);
          }
          row = along.solve(data);
        }
        auto write = [&](size_t target, ChartSide targetSide, bool reversed) {
          const WallPatch& other = patches[target];
          for (int t = 0; t < length; ++t) {
            const auto [i, j] = sidePosition(other, targetSide, reversed ? length - 1 - t : t);
            layerPoles[target][static_cast<size_t>(k)].row(i * other.surface.vPoles + j) = row.row(t);
          }
        };
        write(p, side, false);
        if (link.patch >= 0) write(static_cast<size_t>(link.patch), link.side, link.reversed);
      }
    }
  }
  // Corners: the point shared by every patch there.
  for (size_t p = 0; p < patches.size(); ++p) {
    const int nu = patches[p].surface.uPoles, nv = patches[p].surface.vPoles;
    for (int k = 1; k < layerCount; ++k) {
      for (const auto& [i, j] : {std::pair<int, int>{0, 0}, {nu - 1, 0}, {0, nv - 1}, {nu - 1, nv - 1}}) {
        layerPoles[p][static_cast<size_t>(k)].row(i * nv + j) =
            layers.layers[static_cast<size_t>(k)].row(grid.pointOf[p][static_cast<size_t>(i * nv + j)]);
      }
    }
  }

  std::vector<Block> blocks;
  for (size_t p = 0; p < patches.size(); ++p) {
    const WallPatch& patch = patches[p];
    const int nu = patch.surface.uPoles, nv = patch.surface.vPoles;
    RowMatrixX3d poles(static_cast<Eigen::Index>(nu) * nv * layerCount, 3);
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
    Block block;
    block.volume = BsplineVolume({3, 3, 3}, {patch.surface.uKnots, patch.surface.vKnots, wKnots}, std::move(poles),
                                 "block " + std::to_string(p));
    block.faces[static_cast<size_t>(BlockFaceSide::WMin)].condition = BoundaryCondition::Wall;
    block.faces[static_cast<size_t>(BlockFaceSide::WMax)].condition =
        outerCondition(result.domain, layerPoles[p].back(), result.farfieldFacesAcrossDomainEdges);
    setLateralFaces(patch, block.faces);
    blocks.push_back(std::move(block));
    result.blockChart.push_back(patch.chart);
  }
  result.blocks = BlockMesh(std::move(blocks));
  return result;
}

}  // namespace bvmesh::volume

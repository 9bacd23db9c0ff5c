#include "core/volume/volume_blocks.h"

#include <Eigen/Geometry>

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <string>
#include <tuple>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"
#include "core/common/math_constants.h"
#include "core/common/number_text.h"
#include "core/surface/limit_bsplines.h"
#include "core/volume/edge_fans.h"
#include "core/volume/hex_scaled_jacobian.h"
#include "core/volume/turning.h"
#include "core/volume/wall_patches.h"
#include "core/volume/wall_topology.h"

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

const char* sideName(ChartSide side) {
  static const char* names[] = {"v_min", "u_max", "v_max", "u_min"};
  return names[static_cast<int>(side)];
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

// Patch normals more than this apart at a shared point are different faces of the wall.
constexpr double kFaceAngleDegrees = 30.0;

// The marching surface grid: every patch's Greville points, merged where patches meet.
struct WallGrid {
  MarchingFront front;
  std::vector<std::vector<int>> pointOf;  // per patch: (i, j) -> front point, at i * vPoles + j
  // Per point: three or more faces of the wall meet there (their normals kFaceAngleDegrees apart),
  // a corner without a normal to leave the wall along (a tip's trailing-edge corner).
  std::vector<char> corner;
  double size = 0.0;                      // bounding-box diagonal
  Vector3d lo, hi;
};

// A side's identity: the canonical (lexicographically smaller direction) vertex chain, and which
// copy of it the side lies on where a knife edge's chain is cut open (edge_fans.h).
struct SideKey {
  std::pair<std::vector<int>, int> id;  // (chain, copy)
  bool reversed = false;                // the patch runs against the canonical direction
};

SideKey sideKey(const WallPatch& patch, ChartSide side) {
  const std::vector<int>& chain = patch.sideVertices[static_cast<size_t>(side)];
  const int copy = patch.sideCopy[static_cast<size_t>(side)];
  std::vector<int> reversed(chain.rbegin(), chain.rend());
  if (reversed < chain) return {{reversed, copy}, true};
  return {{chain, copy}, false};
}

WallGrid wallGrid(const std::vector<WallPatch>& patches) {
  WallGrid grid;
  std::vector<Vector3d> points, normals;
  std::vector<int> normalCount;
  std::vector<std::vector<Vector3d>> faceNormals;  // per point, one normal per wall face there
  const double sameFace = std::cos(kFaceAngleDegrees * kPi / 180.0);
  std::map<std::pair<int, int>, int> cornerPoint;                   // (control vertex, copy) -> point
  std::map<std::tuple<std::vector<int>, int, int>, int> sidePoint;  // (canonical chain, copy, entry) -> point
  for (size_t p = 0; p < patches.size(); ++p) {
    const WallPatch& patch = patches[p];
    const PatchSurface& surface = patch.surface;
    const std::vector<double> gu = grevilleAbscissae(surface.uKnots, 3);
    const std::vector<double> gv = grevilleAbscissae(surface.vKnots, 3);
    const int nu = surface.uPoles, nv = surface.vPoles;
    std::vector<int>& ids = grid.pointOf.emplace_back(static_cast<size_t>(nu * nv), -1);
    auto cornerId = [&](int corner) {
      const std::pair<int, int> key{cornerVertex(patch, corner),
                                    patch.cornerCopy[static_cast<size_t>(corner)]};
      const auto found = cornerPoint.find(key);
      if (found != cornerPoint.end()) return found->second;
      return cornerPoint[key] = static_cast<int>(points.size());
    };
    auto idAt = [&](int i, int j) -> int {
      const bool uEnd = i == 0 || i == nu - 1, vEnd = j == 0 || j == nv - 1;
      if (uEnd && vEnd) return cornerId((i == 0 ? 0 : 1) + (j == 0 ? 0 : 2));
      if (uEnd || vEnd) {
        const ChartSide side = vEnd ? (j == 0 ? ChartSide::VMin : ChartSide::VMax)
                                    : (i == 0 ? ChartSide::UMin : ChartSide::UMax);
        // A fan's end inside the wall is its corner's point all along.
        if (patch.collapsedSide[static_cast<size_t>(side)]) return cornerId(sideEndCorner(side, 0));
        const int t = vEnd ? i : j;
        const SideKey key = sideKey(patch, side);
        const int entry = key.reversed ? sidePoleCount(patch, side) - 1 - t : t;
        const auto index = std::make_tuple(key.id.first, key.id.second, entry);
        const auto found = sidePoint.find(index);
        if (found != sidePoint.end()) return found->second;
        return sidePoint[index] = static_cast<int>(points.size());
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
          faceNormals.emplace_back();
        }
        ids[static_cast<size_t>(i * nv + j)] = id;
        if (patch.fan) continue;  // no wall of its own: its points' lines fan between the edge's faces'
        normals[static_cast<size_t>(id)] += normal;
        ++normalCount[static_cast<size_t>(id)];
        std::vector<Vector3d>& faces = faceNormals[static_cast<size_t>(id)];
        const Vector3d unit = normal.normalized();
        if (std::none_of(faces.begin(), faces.end(),
                         [&](const Vector3d& n) { return n.dot(unit) > sameFace; }))
          faces.push_back(unit);
      }
    }
    for (int i = 0; i + 1 < nu; ++i) {
      for (int j = 0; j + 1 < nv; ++j) {
        grid.front.quads.push_back({ids[static_cast<size_t>(i * nv + j)], ids[static_cast<size_t>((i + 1) * nv + j)],
                                    ids[static_cast<size_t>((i + 1) * nv + j + 1)], ids[static_cast<size_t>(i * nv + j + 1)]});
        grid.front.quadNames.push_back("wall patch " + std::to_string(p) +
                                       (patch.fan ? std::string(" (fan round a knife edge)")
                                                  : " (chart " + std::to_string(patch.chart) + ")") +
                                       " pole cell (" + std::to_string(i) + ", " + std::to_string(j) + ")");
      }
    }
  }
  // A fan's points between the edge's two copies: their lines turn from one copy's to the
  // other's by their share of the fan's parameter, round the outside of the edge's wedge, where
  // both faces leave the edge (the marching sets them; here their normals).
  std::vector<std::vector<int>> fanClosedEnds(patches.size());
  for (size_t p = 0; p < patches.size(); ++p) {
    const WallPatch& patch = patches[p];
    if (!patch.fan) continue;
    const std::vector<double> gv = grevilleAbscissae(patch.surface.vKnots, 3);
    const int nu = patch.surface.uPoles, nv = patch.surface.vPoles;
    for (int i = 0; i < nu; ++i) {
      const int from = grid.pointOf[p][static_cast<size_t>(i * nv)];
      const int to = grid.pointOf[p][static_cast<size_t>(i * nv + nv - 1)];
      if (from == to) {
        fanClosedEnds[p].push_back(from);
        continue;
      }
      grid.front.knifeCopies.push_back({from, to});
      Vector3d outside = Vector3d::Zero();
      for (const ChartSide side : {ChartSide::VMin, ChartSide::VMax}) {
        const PatchSideLink& face = patch.sides[static_cast<size_t>(side)];
        outside +=
            sideOutward(patches[static_cast<size_t>(face.patch)], face.side, face.reversed ? nu - 1 - i : i);
      }
      for (int j = 1; j + 1 < nv; ++j) {
        const int id = grid.pointOf[p][static_cast<size_t>(i * nv + j)];
        grid.front.fanPoints.push_back(
            {id, from, to, gv[static_cast<size_t>(j)] / gv.back(), outside.normalized()});
      }
    }
  }
  // On the wall a fan is its edge: its points and the edge's second copy sit exactly on the first
  // copy (their surfaces' evaluations differ by rounding), so its quads there have no area.
  for (const FanPoint& fan : grid.front.fanPoints) {
    points[static_cast<size_t>(fan.point)] = points[static_cast<size_t>(fan.from)];
    points[static_cast<size_t>(fan.to)] = points[static_cast<size_t>(fan.from)];
  }
  const auto count = static_cast<Eigen::Index>(points.size());
  grid.front.points.resize(count, 3);
  grid.front.normals.resize(count, 3);
  grid.corner.assign(static_cast<size_t>(count), 0);
  std::vector<char> onFan(static_cast<size_t>(count), 0);
  for (const FanPoint& fan : grid.front.fanPoints) onFan[static_cast<size_t>(fan.point)] = 1;
  for (Eigen::Index k = 0; k < count; ++k) {
    grid.corner[static_cast<size_t>(k)] = faceNormals[static_cast<size_t>(k)].size() >= 3;
    grid.front.points.row(k) = points[static_cast<size_t>(k)].transpose();
    if (onFan[static_cast<size_t>(k)] != 0) continue;
    const Vector3d n = normals[static_cast<size_t>(k)];
    if (!(n.norm() > 1e-12)) {
      throw SolverError("the wall has no normal at point " + std::to_string(k) + " (" +
                        coordinatesText(points[static_cast<size_t>(k)]) + "): a degenerate or folded patch");
    }
    grid.front.normals.row(k) = n.normalized().transpose();
  }
  for (const FanPoint& fan : grid.front.fanPoints) {
    grid.front.normals.row(fan.point) =
        turnedBetween(grid.front.normals.row(fan.from).transpose(),
                      grid.front.normals.row(fan.to).transpose(), fan.fraction, fan.outside)
            .transpose();
  }
  // Where fans close, the widest angle between their copies' normals.
  std::map<int, double> widest;
  for (size_t p = 0; p < patches.size(); ++p) {
    if (fanClosedEnds[p].empty()) continue;
    const int nu = patches[p].surface.uPoles, nv = patches[p].surface.vPoles;
    double angle = 0.0;
    for (int i = 0; i < nu; ++i) {
      const Vector3d from = grid.front.normals.row(grid.pointOf[p][static_cast<size_t>(i * nv)]).transpose();
      const Vector3d to =
          grid.front.normals.row(grid.pointOf[p][static_cast<size_t>(i * nv + nv - 1)]).transpose();
      angle = std::max(angle, std::atan2(from.cross(to).norm(), from.dot(to)));
    }
    for (int end : fanClosedEnds[p]) widest[end] = std::max(widest[end], angle);
  }
  for (const auto& [point, angle] : widest) grid.front.fanClosings.push_back({point, angle});
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

// Marks the wall grid's points on open patch sides with the boundary planes they lie on (the
// symmetry plane, the outflow plane; a point where the wall's boundary turns from one to the other
// lies on both) and returns per patch side the condition of an open side's block face (symmetry or
// outlet; connected for the others). Throws when the wall is open without a plane or an open side
// lies off the planes, and when a plane is given but the wall does not end on it or reaches across it.
std::vector<std::array<BoundaryCondition, 4>> markPlanePoints(const std::vector<WallPatch>& patches,
                                                              WallGrid& grid,
                                                              const VolumeMeshOptions& options) {
  const BoundaryPlanes planes = boundaryPlanesOf(options);
  const std::array<bool, 2> given{options.hasSymmetryPlane, options.hasOutflowPlane};
  for (size_t k = 0; k < 2; ++k) {
    if (!given[k]) continue;
    const Eigen::VectorXd side =
        (grid.front.points.rowwise() - planes.point[k].transpose()) * planes.normal[k];
    if (side.minCoeff() < -1e-6 * grid.size && side.maxCoeff() > 1e-6 * grid.size) {
      throw InvalidInputError(std::string("the wall reaches across the ") + kBoundaryPlaneNames[k] +
                              " (from " + numberText(side.minCoeff()) + " to " + numberText(side.maxCoeff()) +
                              " along its normal): the wall lies on one side of it");
    }
  }
  grid.front.onPlanes.assign(static_cast<size_t>(grid.front.points.rows()), 0);
  std::vector<std::array<BoundaryCondition, 4>> conditions(patches.size());
  for (size_t p = 0; p < patches.size(); ++p) {
    for (int s = 0; s < 4; ++s) {
      conditions[p][static_cast<size_t>(s)] = BoundaryCondition::Connected;
      const WallPatch& patch = patches[p];
      if (patch.sides[static_cast<size_t>(s)].patch >= 0 || patch.collapsedSide[static_cast<size_t>(s)])
        continue;
      const ChartSide side = static_cast<ChartSide>(s);
      const std::vector<int>& chain = patch.sideVertices[static_cast<size_t>(s)];
      const std::string where = "wall patch " + std::to_string(p) + " side " + sideName(side) + " (control vertices " +
                                std::to_string(chain.front()) + " ... " + std::to_string(chain.back()) + ")";
      std::vector<int> ids;
      std::vector<Vector3d> points;
      for (int t = 0; t < sidePoleCount(patch, side); ++t) {
        const auto [i, j] = sidePolePosition(patch, side, t);
        ids.push_back(grid.pointOf[p][static_cast<size_t>(i * patch.surface.vPoles + j)]);
        points.push_back(grid.front.points.row(ids.back()).transpose());
      }
      const size_t k = openSidePlane(options, planes, points, 1e-6 * grid.size, where);
      for (int id : ids) grid.front.onPlanes[static_cast<size_t>(id)] |= static_cast<unsigned char>(1u << k);
      conditions[p][static_cast<size_t>(s)] =
          k == 0 ? BoundaryCondition::Symmetry : BoundaryCondition::Outlet;
    }
  }
  const bool open = std::any_of(grid.front.onPlanes.begin(), grid.front.onPlanes.end(),
                                [](unsigned char on) { return on != 0; });
  for (size_t k = 0; k < 2; ++k) {
    if (given[k] && std::none_of(grid.front.onPlanes.begin(), grid.front.onPlanes.end(),
                                 [k](unsigned char on) { return (on & (1u << k)) != 0; })) {
      throw InvalidInputError(std::string("a ") + kBoundaryPlaneNames[k] + " is given, but the wall " +
                              (open ? "does not end on it" : "is closed and does not end on it") + ": " +
                              (k == 0
                                   ? "a closed body needs no symmetry plane (a half model is open on it)"
                                   : "only a wall that runs into the outflow boundary (a sting) needs it"));
    }
  }
  return conditions;
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

// Where a patch of the wall lies on a patch of the coarser marching wall: the coarse patch and the
// affine map of the fine patch's (u, v) onto the coarse one's.
struct CoarsePlace {
  int patch = -1;
  bool swapped = false;     // fine u runs along coarse v
  std::array<double, 2> scale{1.0, 1.0};   // coarse parameter per fine parameter (1 / 2^steps; 1 round a fan)
  std::array<double, 2> origin{0.0, 0.0};  // coarse (u, v) of fine (0, 0)
  std::array<double, 2> sign{1.0, 1.0};    // direction of coarse (u, v) along fine (u, v) (after the swap)

  std::pair<double, double> map(double u, double v) const {
    const double a = swapped ? v : u, b = swapped ? u : v;
    return {origin[0] + sign[0] * scale[0] * a, origin[1] + sign[1] * scale[1] * b};
  }
};

constexpr const char* kKnifeLevelsDisagree =
    " is a knife edge (convex, its faces' normals more than 120 degrees apart) on one of the wall and the "
    "marching wall and not on the other, so only one of them has a fan there: march from the wall itself or "
    "without knife_edge_fans";

// A fan's place on the coarse wall's fan round the same stretch of knife edge (the same end
// vertices): along the edge as the wall's patches, round it one to one.
CoarsePlace placeFan(const WallPatch& fine, size_t f, const std::vector<WallPatch>& coarse, double scale) {
  const std::vector<int>& chain = fine.sideVertices[static_cast<size_t>(ChartSide::VMin)];
  for (size_t c = 0; c < coarse.size(); ++c) {
    if (!coarse[c].fan) continue;
    const std::vector<int>& coarseChain = coarse[c].sideVertices[static_cast<size_t>(ChartSide::VMin)];
    const bool same = coarseChain.front() == chain.front() && coarseChain.back() == chain.back();
    const bool reversed = coarseChain.front() == chain.back() && coarseChain.back() == chain.front();
    if (!same && !reversed) continue;
    const double coarseU = coarse[c].surface.uKnots.back();
    if (fine.surface.uKnots.back() * scale != coarseU || fine.surface.vKnots != coarse[c].surface.vKnots) {
      throw InvalidInputError(
          "wall patch " + std::to_string(f) + " (the fan round the knife edge from control vertex " +
          std::to_string(chain.front()) + " to " + std::to_string(chain.back()) +
          ") does not refine the marching wall's fan round it (patch " + std::to_string(c) + ")");
    }
    CoarsePlace place;
    place.patch = static_cast<int>(c);
    place.scale = {scale, 1.0};
    place.origin = {same ? 0.0 : coarseU, 0.0};
    place.sign = {same ? 1.0 : -1.0, 1.0};
    return place;
  }
  throw InvalidInputError("the wall's crease from control vertex " + std::to_string(chain.front()) + " to " +
                          std::to_string(chain.back()) + kKnifeLevelsDisagree);
}

std::array<int, 4> patchCornerVertices(const WallPatch& patch) {
  const std::vector<int>& low = patch.sideVertices[static_cast<size_t>(ChartSide::VMin)];
  const std::vector<int>& high = patch.sideVertices[static_cast<size_t>(ChartSide::VMax)];
  return {low.front(), low.back(), high.front(), high.back()};  // (0, 0), (U, 0), (0, V), (U, V)
}

// Places every patch of `fine` (the wall, whose control mesh is the marching wall's refined
// `steps` times: the old vertices keep their ids) on the patch of `coarse` with the same corner
// vertices. Throws InvalidInputError when the two layouts do not correspond.
std::vector<CoarsePlace> placeOnCoarsePatches(const std::vector<WallPatch>& fine, const std::vector<WallPatch>& coarse,
                                              int steps) {
  std::map<std::array<int, 4>, int> coarseBySortedCorners;
  for (size_t c = 0; c < coarse.size(); ++c) {
    if (coarse[c].fan) continue;
    std::array<int, 4> corners = patchCornerVertices(coarse[c]);
    std::sort(corners.begin(), corners.end());
    coarseBySortedCorners[corners] = static_cast<int>(c);
  }
  const double scale = std::ldexp(1.0, -steps);
  std::vector<CoarsePlace> places;
  for (size_t f = 0; f < fine.size(); ++f) {
    if (fine[f].fan) {
      places.push_back(placeFan(fine[f], f, coarse, scale));
      continue;
    }
    const std::array<int, 4> corners = patchCornerVertices(fine[f]);
    std::array<int, 4> sorted = corners;
    std::sort(sorted.begin(), sorted.end());
    const auto found = coarseBySortedCorners.find(sorted);
    const std::string what = "wall patch " + std::to_string(f) + " (corner vertices " + std::to_string(corners[0]) + ", " +
                             std::to_string(corners[1]) + ", " + std::to_string(corners[2]) + ", " + std::to_string(corners[3]) + ")";
    if (found == coarseBySortedCorners.end() || std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
      throw InvalidInputError(what + " has no patch of the marching wall with the same corners: the wall must be the "
                              "marching wall's control mesh subdivided (and refitted), with charts that refine its charts");
    }
    const WallPatch& c = coarse[static_cast<size_t>(found->second)];
    const std::array<int, 4> coarseCorners = patchCornerVertices(c);
    auto cornerPosition = [&](int vertex) {
      const int at = static_cast<int>(std::find(coarseCorners.begin(), coarseCorners.end(), vertex) - coarseCorners.begin());
      return std::array<int, 2>{at & 1, at >> 1};  // which end of coarse u, of coarse v
    };
    const std::array<int, 2> p00 = cornerPosition(corners[0]), p10 = cornerPosition(corners[1]), p01 = cornerPosition(corners[2]);
    CoarsePlace place;
    place.patch = found->second;
    place.scale = {scale, scale};
    place.swapped = p10[0] == p00[0];  // moving along fine u keeps coarse u: it runs along coarse v
    const int along = place.swapped ? 1 : 0;  // the coarse direction fine u runs along
    const double coarseU = c.surface.uKnots.back(), coarseV = c.surface.vKnots.back();
    const double fineU = fine[f].surface.uKnots.back(), fineV = fine[f].surface.vKnots.back();
    const bool consistent = p10[1 - along] == p00[1 - along] && p10[along] != p00[along] && p01[along] == p00[along] &&
                            p01[1 - along] != p00[1 - along] &&
                            fineU * scale == (place.swapped ? coarseV : coarseU) && fineV * scale == (place.swapped ? coarseU : coarseV);
    if (!consistent) {
      throw InvalidInputError(what + " does not refine its patch " + std::to_string(place.patch) +
                              " of the marching wall " + std::to_string(steps) + " time(s)");
    }
    place.origin = {p00[0] == 0 ? 0.0 : coarseU, p00[1] == 0 ? 0.0 : coarseV};
    place.sign = {p00[0] == 0 ? 1.0 : -1.0, p00[1] == 0 ? 1.0 : -1.0};
    places.push_back(place);
  }
  for (size_t c = 0; c < coarse.size(); ++c) {
    const auto placed = [&](const CoarsePlace& place) { return place.patch == static_cast<int>(c); };
    if (!coarse[c].fan || std::any_of(places.begin(), places.end(), placed)) continue;
    const std::vector<int>& chain = coarse[c].sideVertices[static_cast<size_t>(ChartSide::VMin)];
    throw InvalidInputError("the marching wall's crease from control vertex " +
                            std::to_string(chain.front()) + " to " + std::to_string(chain.back()) +
                            kKnifeLevelsDisagree);
  }
  return places;
}

// The coarse marching's layers carried onto the wall's grid: each wall grid point takes the coarse
// layer surfaces at its place on the coarse patches, moved by its distance from the coarse wall
// (fully at the wall, fading to nothing at the top of the boundary layer, so the boundary layer's
// grid lines keep their direction and the far field is the coarse one).
MarchingResult transferLayers(const MarchingResult& coarse, const std::vector<WallPatch>& coarsePatches, const WallGrid& coarseGrid,
                              const std::vector<WallPatch>& patches, const WallGrid& grid, int steps,
                              double boundaryLayerThickness, const Domain& domain) {
  const std::vector<CoarsePlace> places = placeOnCoarsePatches(patches, coarsePatches, steps);
  const std::vector<std::vector<Eigen::MatrixXd>> coarsePoles = layerPatchPoles(coarsePatches, coarseGrid, coarse.layers);
  const int layerCount = static_cast<int>(coarse.layers.size());
  // The coarse layer surfaces, per coarse patch and layer (layer 0: the coarse wall).
  std::vector<std::vector<PatchSurface>> coarseLayers(coarsePatches.size());
  for (size_t c = 0; c < coarsePatches.size(); ++c) {
    for (int k = 0; k < layerCount; ++k) {
      PatchSurface& layer = coarseLayers[c].emplace_back(coarsePatches[c].surface);
      const Eigen::MatrixXd& poles = coarsePoles[c][static_cast<size_t>(k)];
      for (Eigen::Index q = 0; q < poles.rows(); ++q) layer.poles[static_cast<size_t>(q)] = poles.row(q).transpose();
    }
  }
  const Eigen::Index count = grid.front.points.rows();
  MarchingResult result;
  result.layerDistance = coarse.layerDistance;
  result.layerMinScaledJacobian = coarse.layerMinScaledJacobian;
  result.farfieldLayersSmoothed = coarse.farfieldLayersSmoothed;
  result.layers.assign(static_cast<size_t>(layerCount), RowMatrixX3d(count, 3));
  result.layers[0] = grid.front.points;
  std::vector<char> done(static_cast<size_t>(count), 0);
  const double firstLayer = coarse.layerDistance.size() > 1 ? coarse.layerDistance[1] : 0.0;
  for (size_t p = 0; p < patches.size(); ++p) {
    const PatchSurface& surface = patches[p].surface;
    const CoarsePlace& place = places[p];
    const std::vector<PatchSurface>& layers = coarseLayers[static_cast<size_t>(place.patch)];
    const std::vector<double> gu = grevilleAbscissae(surface.uKnots, 3), gv = grevilleAbscissae(surface.vKnots, 3);
    for (int i = 0; i < surface.uPoles; ++i) {
      for (int j = 0; j < surface.vPoles; ++j) {
        const int id = grid.pointOf[p][static_cast<size_t>(i * surface.vPoles + j)];
        if (done[static_cast<size_t>(id)]) continue;
        done[static_cast<size_t>(id)] = 1;
        const auto [u, v] = place.map(gu[static_cast<size_t>(i)], gv[static_cast<size_t>(j)]);
        const Vector3d wall = grid.front.points.row(id).transpose();
        const Vector3d shift = wall - layers[0].point(u, v);
        if (!(shift.norm() < 0.5 * firstLayer)) {
          throw InvalidInputError("the wall lies " + numberText(shift.norm()) +
                                  " from the marching wall at (" + coordinatesText(wall) +
                                  "), more than half the first control layer (" + numberText(firstLayer) +
                                  "): march a finer wall");
        }
        for (int k = 1; k < layerCount; ++k) {
          const double fade = std::max(0.0, 1.0 - coarse.layerDistance[static_cast<size_t>(k)] / boundaryLayerThickness);
          result.layers[static_cast<size_t>(k)].row(id) = (layers[static_cast<size_t>(k)].point(u, v) + fade * shift).transpose();
        }
        // The outer layer on the domain boundary, as the marching puts it (the coarse outer
        // surface meets the boundary only at its own grid).
        result.layers.back().row(id) = domain.onBoundary(result.layers.back().row(id).transpose()).transpose();
      }
    }
  }
  return result;
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

// How many times `coarse` must be refined to have `fine`'s face count (-1: never).
int refinementSteps(const surface::QuadControlMesh& coarse, const surface::QuadControlMesh& fine) {
  Eigen::Index faces = coarse.faces.rows();
  for (int steps = 1; steps <= 8; ++steps) {
    faces *= 4;
    if (faces == fine.faces.rows()) return steps;
  }
  return -1;
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
    layers = transferLayers(layers, coarsePatches, coarseGrid, patches, grid, steps, resolved.boundaryLayerThickness,
                            resolved.marching.domain);
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

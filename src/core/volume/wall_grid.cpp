#include "core/volume/wall_grid.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <tuple>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"
#include "core/common/math_constants.h"
#include "core/common/number_text.h"
#include "core/volume/boundary_planes.h"
#include "core/volume/turning.h"

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

const char* sideName(ChartSide side) {
  static const char* names[] = {"v_min", "u_max", "v_max", "u_min"};
  return names[static_cast<int>(side)];
}

// Patch normals more than this apart at a shared point are different faces of the wall.
constexpr double kFaceAngleDegrees = 30.0;

}  // namespace

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
      throw InvalidInputError(std::string("the ") + kBoundaryPlaneNames[k] + " is given, but the wall " +
                              (open ? "does not end on it" : "is closed and does not end on it") + ": " +
                              (k == 0
                                   ? "a closed body needs no symmetry plane (a half model is open on it)"
                                   : "only a wall that runs into the outflow boundary (a sting) needs it"));
    }
  }
  return conditions;
}

}  // namespace bvmesh::volume

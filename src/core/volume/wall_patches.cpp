#include "core/volume/wall_patches.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <map>
#include <set>
#include <string>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"

namespace bvmesh::volume {
namespace {

std::vector<double> fullKnots(const std::vector<double>& knots, const std::vector<int>& multiplicities) {
  std::vector<double> result;
  for (size_t k = 0; k < knots.size(); ++k) result.insert(result.end(), static_cast<size_t>(multiplicities[k]), knots[k]);
  return result;
}

PatchSurface patchOf(const cad::BSplineSurfaceData& data) {
  PatchSurface patch;
  patch.uKnots = fullKnots(data.uKnots, data.uMultiplicities);
  patch.vKnots = fullKnots(data.vKnots, data.vMultiplicities);
  patch.uPoles = data.uPoleCount;
  patch.vPoles = data.vPoleCount;
  for (int p = 0; p < data.uPoleCount * data.vPoleCount; ++p) {
    patch.poles.emplace_back(data.poles[3 * static_cast<size_t>(p)], data.poles[3 * static_cast<size_t>(p) + 1],
                             data.poles[3 * static_cast<size_t>(p) + 2]);
  }
  return patch;
}

// The patch restricted to [u0, u1] x [v0, v1] by knot insertion, one direction at a time.
PatchSurface restrictPatch(const PatchSurface& patch, double u0, double u1, double v0, double v1) {
  // Rows of u poles, each holding the v poles' coordinates.
  Eigen::MatrixXd alongU(patch.uPoles, 3 * patch.vPoles);
  for (int i = 0; i < patch.uPoles; ++i) {
    for (int j = 0; j < patch.vPoles; ++j) alongU.block<1, 3>(i, 3 * j) = patch.pole(i, j).transpose();
  }
  std::vector<double> uKnots = patch.uKnots;
  restrictToInterval(uKnots, 3, alongU, u0, u1);
  const int uPoles = static_cast<int>(alongU.rows());
  Eigen::MatrixXd alongV(patch.vPoles, 3 * uPoles);
  for (int i = 0; i < uPoles; ++i) {
    for (int j = 0; j < patch.vPoles; ++j) alongV.block<1, 3>(j, 3 * i) = alongU.block<1, 3>(i, 3 * j);
  }
  std::vector<double> vKnots = patch.vKnots;
  restrictToInterval(vKnots, 3, alongV, v0, v1);
  PatchSurface result;
  result.uKnots = std::move(uKnots);
  result.vKnots = std::move(vKnots);
  result.uPoles = uPoles;
  result.vPoles = static_cast<int>(alongV.rows());
  for (int i = 0; i < result.uPoles; ++i) {
    for (int j = 0; j < result.vPoles; ++j) result.poles.emplace_back(alongV.block<1, 3>(j, 3 * i).transpose());
  }
  // Back onto [0, m] x [0, n]: the volume's knot vectors start at 0 like the charts'.
  for (double& k : result.uKnots) k -= u0;
  for (double& k : result.vKnots) k -= v0;
  return result;
}

int blockFaceOf(ChartSide side) {
  switch (side) {
    case ChartSide::UMin:
      return static_cast<int>(BlockFaceSide::UMin);
    case ChartSide::UMax:
      return static_cast<int>(BlockFaceSide::UMax);
    case ChartSide::VMin:
      return static_cast<int>(BlockFaceSide::VMin);
    case ChartSide::VMax:
      return static_cast<int>(BlockFaceSide::VMax);
  }
  return 0;
}

bool alongU(ChartSide side) { return side == ChartSide::VMin || side == ChartSide::VMax; }

}  // namespace

Eigen::Vector3d PatchSurface::point(double u, double v, Eigen::Vector3d* normal) const {
  const int su = findKnotSpan(uKnots, 3, u);
  const int sv = findKnotSpan(vKnots, 3, v);
  double nu[4], du[4], nv[4], dv[4];
  basisFunctions(uKnots, 3, su, u, nu, du);
  basisFunctions(vKnots, 3, sv, v, nv, dv);
  Eigen::Vector3d x = Eigen::Vector3d::Zero(), xu = x, xv = x;
  for (int a = 0; a < 4; ++a) {
    for (int b = 0; b < 4; ++b) {
      const Eigen::Vector3d& p = pole(su - 3 + a, sv - 3 + b);
      x += nu[a] * nv[b] * p;
      xu += du[a] * nv[b] * p;
      xv += nu[a] * dv[b] * p;
    }
  }
  if (normal != nullptr) {
    *normal = xu.cross(xv);
    const double length = normal->norm();
    if (length > 0) *normal /= length;
  }
  return x;
}

std::vector<WallPatch> conformingPatchLayout(const surface::ChartLayout& layout, const surface::QuadControlMesh& mesh) {
  const size_t chartCount = layout.charts.size();
  // Cut positions per chart along u and v (chart cell lines), closed under propagation across
  // shared segments: a cut that ends inside a neighbour's side continues through the neighbour.
  std::vector<std::set<int>> cutsU(chartCount), cutsV(chartCount);
  for (size_t c = 0; c < chartCount; ++c) {
    cutsU[c] = {0, layout.charts[c].uCells};
    cutsV[c] = {0, layout.charts[c].vCells};
  }
  std::vector<std::pair<int, int>> pending;  // (chart, cut index encoded: +position along u, -position-1 along v)
  auto addCut = [&](int chart, ChartSide side, int position) {
    std::set<int>& cuts = alongU(side) ? cutsU[static_cast<size_t>(chart)] : cutsV[static_cast<size_t>(chart)];
    if (cuts.insert(position).second) pending.emplace_back(chart, alongU(side) ? position : -position - 1);
  };
  for (const surface::BorderSegment& segment : layout.segments) {
    const int length = static_cast<int>(segment.vertices.size()) - 1;
    for (const surface::SegmentUse& use : segment.uses) {
      addCut(use.chart, use.side, use.first);
      addCut(use.chart, use.side, use.reversed ? use.first - length : use.first + length);
    }
  }
  while (!pending.empty()) {
    const auto [chart, code] = pending.back();
    pending.pop_back();
    const bool u = code >= 0;
    const int position = u ? code : -code - 1;
    const std::array<ChartSide, 2> sides =
        u ? std::array<ChartSide, 2>{ChartSide::VMin, ChartSide::VMax} : std::array<ChartSide, 2>{ChartSide::UMin, ChartSide::UMax};
    for (ChartSide side : sides) {
      for (const surface::BorderSegment& segment : layout.segments) {
        const int length = static_cast<int>(segment.vertices.size()) - 1;
        for (size_t k = 0; k < segment.uses.size(); ++k) {
          const surface::SegmentUse& use = segment.uses[k];
          if (use.chart != chart || use.side != side) continue;
          const int along = use.reversed ? use.first - position : position - use.first;
          if (along <= 0 || along >= length || segment.uses.size() < 2) continue;
          const surface::SegmentUse& other = segment.uses[1 - k];
          addCut(other.chart, other.side, other.reversed ? other.first - along : other.first + along);
        }
      }
    }
  }

  std::set<std::pair<int, int>> creaseEdges;
  for (Eigen::Index c = 0; c < mesh.creases.rows(); ++c) {
    creaseEdges.emplace(std::min(mesh.creases(c, 0), mesh.creases(c, 1)), std::max(mesh.creases(c, 0), mesh.creases(c, 1)));
  }
  std::vector<WallPatch> patches;
  for (size_t c = 0; c < chartCount; ++c) {
    const surface::QuadChart& chart = layout.charts[c];
    const std::vector<int> us(cutsU[c].begin(), cutsU[c].end());
    const std::vector<int> vs(cutsV[c].begin(), cutsV[c].end());
    for (size_t a = 0; a + 1 < us.size(); ++a) {
      for (size_t b = 0; b + 1 < vs.size(); ++b) {
        WallPatch patch;
        patch.chart = static_cast<int>(c);
        patch.uRange = {us[a], us[a + 1]};
        patch.vRange = {vs[b], vs[b + 1]};
        for (int i = us[a]; i <= us[a + 1]; ++i) {
          patch.sideVertices[static_cast<size_t>(ChartSide::VMin)].push_back(chart.vertex(i, vs[b]));
          patch.sideVertices[static_cast<size_t>(ChartSide::VMax)].push_back(chart.vertex(i, vs[b + 1]));
        }
        for (int j = vs[b]; j <= vs[b + 1]; ++j) {
          patch.sideVertices[static_cast<size_t>(ChartSide::UMin)].push_back(chart.vertex(us[a], j));
          patch.sideVertices[static_cast<size_t>(ChartSide::UMax)].push_back(chart.vertex(us[a + 1], j));
        }
        for (size_t s = 0; s < 4; ++s) {
          const std::vector<int>& chain = patch.sideVertices[s];
          bool crease = true;
          for (size_t k = 0; k + 1 < chain.size(); ++k) {
            crease = crease && creaseEdges.count({std::min(chain[k], chain[k + 1]), std::max(chain[k], chain[k + 1])}) > 0;
          }
          patch.creaseSide[s] = crease;
        }
        patches.push_back(std::move(patch));
      }
    }
  }

  // Link sides through their vertex chains (a chain and its reverse are the same side).
  std::map<std::vector<int>, std::vector<std::pair<int, int>>> users;  // canonical chain -> (patch, side * 2 + reversed)
  for (size_t p = 0; p < patches.size(); ++p) {
    for (int s = 0; s < 4; ++s) {
      const std::vector<int>& chain = patches[p].sideVertices[static_cast<size_t>(s)];
      std::vector<int> reversed(chain.rbegin(), chain.rend());
      const bool useReversed = reversed < chain;
      users[useReversed ? reversed : chain].emplace_back(static_cast<int>(p), 2 * s + (useReversed ? 1 : 0));
    }
  }
  for (const auto& [chain, uses] : users) {
    if (uses.size() > 2) {
      throw TopologyError("the wall side through control-mesh vertices " + std::to_string(chain.front()) + " ... " +
                          std::to_string(chain.back()) + " is shared by " + std::to_string(uses.size()) +
                          " patches (the surface is not manifold there)");
    }
    if (uses.size() < 2) continue;
    for (int k = 0; k < 2; ++k) {
      const auto [patch, code] = uses[static_cast<size_t>(k)];
      const auto [other, otherCode] = uses[static_cast<size_t>(1 - k)];
      PatchSideLink& link = patches[static_cast<size_t>(patch)].sides[static_cast<size_t>(code / 2)];
      link.patch = other;
      link.side = static_cast<ChartSide>(otherCode / 2);
      link.reversed = (code % 2) != (otherCode % 2);
    }
  }
  return patches;
}

std::vector<WallPatch> conformingWallPatches(const surface::LimitBSplines& bsplines,
                                             const surface::QuadControlMesh& mesh) {
  std::vector<WallPatch> patches = conformingPatchLayout(bsplines.layout, mesh);
  std::vector<PatchSurface> charts;
  for (const cad::BSplineSurfaceData& surface : bsplines.surfaces) charts.push_back(patchOf(surface));
  for (WallPatch& patch : patches) {
    patch.surface = restrictPatch(charts[static_cast<size_t>(patch.chart)], patch.uRange[0], patch.uRange[1],
                                  patch.vRange[0], patch.vRange[1]);
  }
  return patches;
}

std::pair<int, int> sidePolePosition(const WallPatch& patch, ChartSide side, int t) {
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

int sidePoleCount(const WallPatch& patch, ChartSide side) {
  return alongU(side) ? patch.surface.uPoles : patch.surface.vPoles;
}

int cornerVertex(const WallPatch& patch, int corner) {
  const std::vector<int>& chain =
      patch.sideVertices[static_cast<size_t>(corner < 2 ? ChartSide::VMin : ChartSide::VMax)];
  return corner % 2 == 0 ? chain.front() : chain.back();
}

int sideEndCorner(ChartSide side, int end) {
  switch (side) {
    case ChartSide::VMin:
      return end;
    case ChartSide::UMax:
      return 1 + 2 * end;
    case ChartSide::VMax:
      return 2 + end;
    case ChartSide::UMin:
      return 2 * end;
  }
  return 0;
}

Eigen::Vector3d polePoint(const WallPatch& patch, int i, int j, Eigen::Vector3d* normal) {
  const std::vector<double> gu = grevilleAbscissae(patch.surface.uKnots, 3);
  const std::vector<double> gv = grevilleAbscissae(patch.surface.vKnots, 3);
  return patch.surface.point(gu[static_cast<size_t>(i)], gv[static_cast<size_t>(j)], normal);
}

Eigen::Vector3d sideOutward(const WallPatch& patch, ChartSide side, int t) {
  const auto [i, j] = sidePolePosition(patch, side, t);
  const int inward = side == ChartSide::VMin || side == ChartSide::UMin ? 1 : -1;
  const auto [ii, ji] = alongU(side) ? std::pair{i, j + inward} : std::pair{i + inward, j};
  return (polePoint(patch, i, j) - polePoint(patch, ii, ji)).normalized();
}

void setLateralFaces(const WallPatch& patch, const std::array<BoundaryCondition, 4>& openSides,
                     std::array<BlockFace, 6>& faces) {
  for (int s = 0; s < 4; ++s) {
    const PatchSideLink& link = patch.sides[static_cast<size_t>(s)];
    BlockFace& face = faces[static_cast<size_t>(blockFaceOf(static_cast<ChartSide>(s)))];
    if (patch.collapsedSide[static_cast<size_t>(s)]) {
      face.condition = BoundaryCondition::Collapsed;
      continue;
    }
    if (link.patch < 0) {
      face.condition = openSides[static_cast<size_t>(s)];
      continue;
    }
    face.condition = BoundaryCondition::Connected;
    face.neighbour.block = link.patch;
    face.neighbour.face = blockFaceOf(link.side);
    face.neighbour.reverseFirst = link.reversed;
  }
}

}  // namespace bvmesh::volume

#include "core/volume/layer_transfer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"
#include "core/common/number_text.h"

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

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

}  // namespace

int refinementSteps(const surface::QuadControlMesh& coarse, const surface::QuadControlMesh& fine) {
  Eigen::Index faces = coarse.faces.rows();
  for (int steps = 1; steps <= 8; ++steps) {
    faces *= 4;
    if (faces == fine.faces.rows()) return steps;
  }
  return -1;
}

MarchingResult transferLayers(const MarchingResult& coarse, const std::vector<WallPatch>& coarsePatches,
                              const std::vector<std::vector<Eigen::MatrixXd>>& coarsePoles,
                              const std::vector<WallPatch>& patches, const WallGrid& grid, int steps,
                              double boundaryLayerThickness, const Domain& domain) {
  const std::vector<CoarsePlace> places = placeOnCoarsePatches(patches, coarsePatches, steps);
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

}  // namespace bvmesh::volume

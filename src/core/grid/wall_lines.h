// Wall-normal lines: per column of a wall block the line along its wall-normal direction through
// the tangential parameters blended at the wall end; its points at the wall law's distances, placed
// by straight distances (geometric law, Newton) or along its arc length (tanh law). Columns are
// spread over the threads in chunks fixed whatever the threads, so the lines come out the same
// bit for bit.
#pragma once

#include <algorithm>
#include <limits>
#include <map>
#include <vector>

#include "core/grid/block_plan.h"
#include "core/grid/refinement.h"
#include "core/grid/structured_grid.h"
#include "core/volume/block_mesh.h"

namespace bvmesh::grid {

// What the wall-normal lines measure: the first point's distance from the wall, the largest
// ratio of consecutive spacings.
struct LineMeasures {
  double firstHeightMin = std::numeric_limits<double>::infinity();
  double firstHeightMax = 0.0;
  double growthMax = 0.0;

  void add(const LineMeasures& other) {
    firstHeightMin = std::min(firstHeightMin, other.firstHeightMin);
    firstHeightMax = std::max(firstHeightMax, other.firstHeightMax);
    growthMax = std::max(growthMax, other.growthMax);
  }
};

// How far each pole layer of the wall-normal lines slides towards the lines through the outer
// boundary's even points (RefinementOptions::evenFarField), by pole count along the lines, per
// layer counted from the wall; empty: the lines stay iso-parametric.
using SlideShares = std::map<int, std::vector<double>>;

// The shares with the even far field asked (`on`): a smooth step (3 r^2 - 2 r^3) in
// r = log(d / s) / log(D / s) of the layer's mean distance d from the wall along the pole columns
// of every wall block, D that of the outer layer and s a tenth of the wall's size (the wall faces'
// pole box diagonal): none closer than s, all at the outer boundary. One share per layer for
// every line, so neighbouring lines slide alike and a shared face's lines slide the same in both
// blocks. Empty when off, or when some block does not stand on the wall: such a block blends its
// parameters by index and would not meet the slid lines on a shared face.
SlideShares slideShares(const std::vector<volume::Block>& blocks, const std::vector<BlockPlan>& plans,
                        bool on);

// The fewest wall-normal points (at least 2) that keep every line of `plans`' wall blocks (slid
// by `shares`) within the growth ratio `growth` from the first cell height `firstHeight` (> 0).
int fewestWallNormalPoints(const std::vector<volume::Block>& blocks, const std::vector<BlockPlan>& plans,
                           double firstHeight, double growth, const SlideShares& shares);

// Places `points` points on every wall-normal line into `grids` (sized by `plans`), with the first
// cell height `firstHeight` (0: every line grows by exactly options.growth) and options' wall law;
// the lines slid by `shares`; returns what they measure (all 0 without a wall). Throws
// InvalidInputError for a line of zero length or one whose first height needs a growth above
// options.growth (saying how many points would do), SolverError for a line that folds back.
LineMeasures placeWallLines(const std::vector<volume::Block>& blocks, const std::vector<BlockPlan>& plans,
                            const RefinementOptions& options, const SlideShares& shares, double firstHeight,
                            int points, std::vector<GridBlock>& grids);

}  // namespace bvmesh::grid

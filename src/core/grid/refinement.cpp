#include "core/grid/refinement.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <future>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "core/common/errors.h"
#include "core/common/input_checks.h"
#include "core/common/number_text.h"
#include "core/common/parallel.h"
#include "core/grid/block_plan.h"
#include "core/grid/direction_sets.h"
#include "core/grid/distribution.h"
#include "core/grid/folded_cells.h"
#include "core/grid/outer_quads.h"
#include "core/grid/point_budget.h"
#include "core/grid/wall_lines.h"

namespace bvmesh::grid {
namespace {

using volume::BlockMesh;

void checkOptions(const RefinementOptions& options) {
  checkFiniteAtLeast(options.firstCellHeight, 0.0, "first_cell_height");
  checkFiniteAtLeast(options.yPlus, 0.0, "y_plus");
  checkFiniteAtLeast(options.reynoldsNumber, 0.0, "reynolds_number");
  checkFiniteAtLeast(options.referenceLength, 0.0, "reference_length");
  checkFiniteAtLeast(options.tangentialSpacing, 0.0, "tangential_spacing");
  checkFiniteAtLeast(options.edgeEndSpacing, 0.0, "edge_end_spacing");
  if (!std::isfinite(options.maxTurningDegrees) || options.maxTurningDegrees < 0.0 ||
      options.maxTurningDegrees > 90.0) {
    throw InvalidInputError("max_turning_angle must be 0 (none) or a number of degrees up to 90 (got " +
                            numberText(options.maxTurningDegrees) + ")");
  }
  if (!std::isfinite(options.maxSpacingJump) ||
      (options.maxSpacingJump != 0.0 && options.maxSpacingJump < 1.0)) {
    throw InvalidInputError("max_spacing_jump must be 0 (none) or a ratio >= 1 (got " +
                            numberText(options.maxSpacingJump) + ")");
  }
  for (size_t f = 0; f < options.featureSpacings.size(); ++f) {
    const FeatureSpacing& feature = options.featureSpacings[f];
    const std::string name = "feature spacing " + std::to_string(f);
    checkFiniteAtLeast(feature.spacing, 0.0, name + ": the spacing", true);
    checkFiniteAtLeast(feature.tolerance, 0.0, name + ": the tolerance");
    if (feature.points.rows() < 2) throw InvalidInputError(name + ": the line needs at least two points");
    checkFinitePoints(feature.points, name + " point");
    for (Eigen::Index k = 1; k < feature.points.rows(); ++k) {
      if (feature.points.row(k) == feature.points.row(k - 1)) {
        throw InvalidInputError(name + ": points " + std::to_string(k - 1) + " and " + std::to_string(k) +
                                " coincide");
      }
    }
  }
  if (!std::isfinite(options.growth) || options.growth <= 1.0 || options.growth > 3.0) {
    throw InvalidInputError("growth must be in (1, 3] (got " + numberText(options.growth) + ")");
  }
  if (options.normalPoints != 0 && (options.normalPoints < 2 || options.normalPoints > 100000)) {
    throw InvalidInputError("normal_points must be 0 (automatic) or 2 .. 100000 (got " +
                            std::to_string(options.normalPoints) + ")");
  }
  if (options.edgePoints < 2 || options.edgePoints > kMaxEdgePoints) {
    throw InvalidInputError("edge_points must be 2 .. " + std::to_string(kMaxEdgePoints) + " (got " +
                            std::to_string(options.edgePoints) + ")");
  }
  // 2e9 cells are 100 GB of points and topology: beyond any machine this runs on.
  if (options.targetCells < 0 || options.targetCells > 2000000000LL) {
    throw InvalidInputError("target_cells must be 0 (none) or up to 2e9, got " +
                            std::to_string(options.targetCells));
  }
  if (options.maxPoints < 0) {
    throw InvalidInputError("max_points must be 0 (no limit) or positive, got " + std::to_string(options.maxPoints));
  }
  if (options.normalPoints == 0 && options.firstCellHeight == 0.0 && options.yPlus == 0.0) {
    throw InvalidInputError("automatic normal_points (0) needs a first cell height or a y+ target");
  }
}

// The first cell height asked: absolute, or from y+ by the flat-plate estimate; 0: none.
double firstCellHeight(const RefinementOptions& options) {
  return options.firstCellHeight > 0.0 ? options.firstCellHeight
         : options.yPlus > 0.0
             ? flatPlateFirstCellHeight(options.yPlus, options.reynoldsNumber, options.referenceLength)
             : 0.0;
}

// A block's grid size: the plan's, with `normalPoints` along its wall-normal direction.
std::array<int, 3> plannedSize(const BlockPlan& plan, int normalPoints) {
  std::array<int, 3> size = plan.size;
  if (plan.normalDirection >= 0) size[static_cast<size_t>(plan.normalDirection)] = normalPoints;
  return size;
}

// Points of the grid the plans size, counted in floating point: a count asked far beyond any
// machine must not overflow before it is refused.
double plannedPoints(const std::vector<BlockPlan>& plans, int normalPoints) {
  double points = 0.0;
  for (const BlockPlan& plan : plans) {
    const std::array<int, 3> size = plannedSize(plan, normalPoints);
    points += static_cast<double>(size[0]) * size[1] * size[2];
  }
  return points;
}

// The grid blocks at the plans' sizes (`normalPoints` along wall-normal directions), their points
// still to be computed.
std::vector<GridBlock> sizedGrids(const std::vector<volume::Block>& blocks,
                                  const std::vector<BlockPlan>& plans, int normalPoints) {
  std::vector<GridBlock> grids(blocks.size());
  for (size_t b = 0; b < blocks.size(); ++b) {
    GridBlock& grid = grids[b];
    grid.size = plannedSize(plans[b], normalPoints);
    grid.faces = blocks[b].faces;
    grid.points.resize(grid.pointCount(), 3);
  }
  return grids;
}

// Which points are shared follows from the sizes alone: found on a thread of its own while the
// points are computed (per point, numbered block after block, the number of its first copy).
std::future<std::vector<Eigen::Index>> findSharedPoints(const std::vector<GridBlock>& grids) {
  std::vector<std::array<volume::BlockFace, 6>> faces;
  std::vector<std::array<int, 3>> sizes;
  for (const GridBlock& grid : grids) {
    faces.push_back(grid.faces);
    sizes.push_back(grid.size);
  }
  return std::async(std::launch::async, [faces = std::move(faces), sizes = std::move(sizes)] {
    return volume::sharedGridRoots(faces, sizes);
  });
}

// The points of the blocks without a wall-normal direction: every parameter blended from the
// block's edges.
void evaluateBlocksWithoutWall(const std::vector<volume::Block>& blocks, const std::vector<BlockPlan>& plans,
                               std::vector<GridBlock>& grids) {
  for (size_t b = 0; b < blocks.size(); ++b) {
    const BlockPlan& plan = plans[b];
    if (plan.normalDirection >= 0) continue;
    GridBlock& grid = grids[b];
    RowMatrixX3d parameters(grid.pointCount(), 3);
    for (int k = 0; k < grid.size[2]; ++k) {
      for (int j = 0; j < grid.size[1]; ++j) {
        for (int i = 0; i < grid.size[0]; ++i) {
          const std::array<int, 3> ijk{i, j, k};
          for (int d = 0; d < 3; ++d) parameters(grid.index(i, j, k), d) = pointParameter(plan, d, ijk);
        }
      }
    }
    blocks[b].volume.evaluate(parameters, grid.points);
  }
}

// The largest block's pole box (which holds its points): its diagonal, and the largest coordinate.
struct BlocksExtent {
  double diagonal = 0.0;
  double coordinateScale = 0.0;
};

BlocksExtent blocksExtent(const std::vector<volume::Block>& blocks) {
  BlocksExtent extent;
  for (const volume::Block& block : blocks) {
    const RowMatrixX3d& poles = block.volume.poles();
    extent.diagonal =
        std::max(extent.diagonal, (poles.colwise().maxCoeff() - poles.colwise().minCoeff()).norm());
    extent.coordinateScale = std::max(extent.coordinateScale, poles.cwiseAbs().maxCoeff());
  }
  return extent;
}

// How far shared points may lie apart: 1e-9 of the model, or what their coordinates resolve where
// that is coarser (a model far from the origin).
double sharedTolerance(const BlocksExtent& extent) {
  return std::max(1e-9 * extent.diagonal,
                  64.0 * std::numeric_limits<double>::epsilon() * extent.coordinateScale);
}

// Spacings asked for (or, for the first cell, computed from y+) must stay well above the
// shared-point tolerance (1e-9 of the blocks' extent): 1e-10 of it still takes a y+ of 1 at a
// Reynolds number of 1e9 in a far field of 20 lengths. Finer ones ended in "does it fold back?"
// or in points matched across the wrong blocks.
void checkSpacingsResolvable(const BlocksExtent& extent, const RefinementOptions& options,
                             double firstHeight) {
  const double finest = 1e-10 * extent.diagonal;
  const auto check = [&](double spacing, const std::string& what) {
    if (spacing > 0.0 && spacing < finest) {
      throw InvalidInputError(what + " " + numberText(spacing) + " is below 1e-10 of the blocks' size (" +
                              numberText(finest) + "): points that close cannot be told apart across blocks");
    }
  };
  check(firstHeight,
        options.firstCellHeight > 0.0 ? "first_cell_height" : "the first cell height from y_plus");
  check(options.tangentialSpacing, "tangential_spacing");
  check(options.edgeEndSpacing, "edge_end_spacing");
  for (size_t f = 0; f < options.featureSpacings.size(); ++f) {
    check(options.featureSpacings[f].spacing, "feature spacing " + std::to_string(f) + ": the spacing");
  }
}

// Shared points made identical (the first block's copy, its root, wins), after checking they agree
// to `tolerance`; throws SolverError naming the first pair apart.
void makeSharedPointsIdentical(const std::vector<Eigen::Index>& roots, double tolerance,
                               std::vector<GridBlock>& grids) {
  std::vector<Eigen::Index> offset{0};
  for (const GridBlock& grid : grids) offset.push_back(offset.back() + grid.pointCount());
  auto locate = [&](Eigen::Index global) {
    const size_t b =
        static_cast<size_t>(std::upper_bound(offset.begin(), offset.end(), global) - offset.begin()) - 1;
    return std::pair<size_t, Eigen::Index>{b, global - offset[b]};
  };
  // Each copy reads a root, which is never written: chunks run in parallel; the first
  // disagreement in point order is reported, whatever the threads' timing.
  std::atomic<Eigen::Index> firstApart{std::numeric_limits<Eigen::Index>::max()};
  parallelChunks(offset.back(), 1 << 16, [&](std::int64_t begin, std::int64_t end) {
    size_t b = locate(begin).first;
    for (Eigen::Index global = begin; global < end; ++global) {
      while (global >= offset[b + 1]) ++b;
      const Eigen::Index root = roots[static_cast<size_t>(global)];
      if (root == global) continue;
      const auto [rb, rrow] = locate(root);
      auto mine = grids[b].points.row(global - offset[b]);
      const auto theirs = grids[rb].points.row(rrow);
      if ((mine - theirs).norm() > tolerance) {
        Eigen::Index known = firstApart.load();
        while (global < known && !firstApart.compare_exchange_weak(known, global)) {
        }
        return;
      }
      mine = theirs;
    }
  });
  if (firstApart.load() == std::numeric_limits<Eigen::Index>::max()) return;
  const auto [b, row] = locate(firstApart.load());
  const auto [rb, rrow] = locate(roots[static_cast<size_t>(firstApart.load())]);
  const double gap = (grids[b].points.row(row) - grids[rb].points.row(rrow)).norm();
  throw SolverError(blockText(b) + " point " + std::to_string(row) + " and " + blockText(rb) + " point " +
                    std::to_string(rrow) + " are shared but " + numberText(gap) +
                    " apart: the distributions disagree across a shared face (block layout not supported)");
}

// The grid of refineBlockMesh with `options` as they are (and the sets' fewest points).
RefinedGrid refineOnce(const BlockMesh& mesh, const RefinementOptions& options, double firstHeight,
                       const BlocksExtent& extent, const std::vector<int>& minimumPoints) {
  const auto& blocks = mesh.blocks();
  const std::vector<BlockPlan> plans = planDirectionSets(blocks, options, firstHeight, minimumPoints);
  const SlideShares shares = slideShares(blocks, plans, options.evenFarField);
  // Automatic: the edges' estimate served the cell target; the wall-normal lines themselves decide.
  const int normalPoints = options.normalPoints == 0
                               ? fewestWallNormalPoints(blocks, plans, firstHeight, options.growth, shares)
                               : options.normalPoints;
  checkPointBudget(plannedPoints(plans, normalPoints), options.maxPoints);
  std::vector<GridBlock> grids = sizedGrids(blocks, plans, normalPoints);
  std::future<std::vector<Eigen::Index>> sharedRoots = findSharedPoints(grids);
  evaluateBlocksWithoutWall(blocks, plans, grids);
  const LineMeasures measured =
      placeWallLines(blocks, plans, options, shares, firstHeight, normalPoints, grids);
  makeSharedPointsIdentical(sharedRoots.get(), sharedTolerance(extent), grids);

  RefinedGrid result;
  result.normalPoints = normalPoints;
  result.firstCellHeightAsked = firstHeight;
  result.firstCellHeightMin = measured.firstHeightMin;
  result.firstCellHeightMax = measured.firstHeightMax;
  result.growthMax = measured.growthMax;
  result.evenFarFieldUsed = !shares.empty();
  if (options.outerDomain) result.outerFacesSplit = tagOuterQuads(grids, *options.outerDomain);
  result.grid = StructuredGrid(std::move(grids), firstHeight > 0.0);
  return result;
}

long long countOf(const std::vector<char>& flags) { return std::count(flags.begin(), flags.end(), 1); }

// A cell that folds where its block need not: the grid samples the block too coarsely for the way
// its lines turn (a corner block one or two cells across, whose layers wrap round a corner of the
// wall). The blocks a fold is in take twice, then four times their tangential cells (their sets
// with them; one doubling may leave a corner block folded that the next opens), and so do the
// blocks the first try folds; a try is kept when it leaves fewer blocks folded. Each try fits in
// the point budget beside the grid kept meanwhile; a grid whose blocks fold themselves comes back
// as it was.
constexpr int kFoldRefinements = 2;

RefinedGrid refinedWhereFolded(const BlockMesh& mesh, const RefinementOptions& options, double firstHeight,
                               const BlocksExtent& extent, RefinedGrid refined, std::vector<char> folded) {
  long long fewest = countOf(folded);
  std::vector<std::array<int, 3>> firstSize;
  for (const GridBlock& grid : refined.grid.blocks()) firstSize.push_back(grid.size);
  RefinementOptions finerOptions = options;
  std::vector<int> minimumPoints(3 * folded.size(), 0);
  for (int round = 1; round <= kFoldRefinements && fewest > 0; ++round) {
    for (size_t b = 0; b < folded.size(); ++b) {
      if (folded[b] == 0) continue;
      for (size_t d = 0; d < 3; ++d)  // the wall-normal one unused
        minimumPoints[3 * b + d] = (1 << round) * (firstSize[b][d] - 1) + 1;
    }
    if (options.maxPoints > 0)
      finerOptions.maxPoints =
          std::max(1LL, options.maxPoints - static_cast<long long>(refined.grid.pointCount()));
    std::optional<RefinedGrid> finer;
    try {
      finer = refineOnce(mesh, finerOptions, firstHeight, extent, minimumPoints);
    } catch (const InvalidInputError&) {
      break;  // beyond the point budget: the grid kept stands (a folded one the writers refuse)
    }
    const std::vector<char> stillFolded = foldedBlocks(finer->grid.blocks());
    for (size_t b = 0; b < folded.size(); ++b) folded[b] = static_cast<char>(folded[b] | stillFolded[b]);
    if (countOf(stillFolded) < fewest) {
      fewest = countOf(stillFolded);
      refined = std::move(*finer);
      refined.foldRefinements = round;
    }
  }
  return refined;
}

}  // namespace

RefinedGrid refineBlockMesh(const BlockMesh& mesh, const RefinementOptions& options) {
  checkOptions(options);
  const auto& blocks = mesh.blocks();
  if (blocks.empty()) throw InvalidInputError("the block mesh has no blocks to refine");
  const double firstHeight = firstCellHeight(options);
  const BlocksExtent extent = blocksExtent(blocks);
  checkSpacingsResolvable(extent, options, firstHeight);

  RefinedGrid refined = refineOnce(mesh, options, firstHeight, extent, {});
  std::vector<char> folded = foldedBlocks(refined.grid.blocks());
  RefinementOptions used = options;
  if (refined.evenFarFieldUsed && countOf(folded) > 0) {
    // Slid lines that fold a cell (neighbouring lines sliding far apart grow to different lengths,
    // and the wall law places their points at different heights): the grid without the slide.
    used.evenFarField = false;
    refined = refineOnce(mesh, used, firstHeight, extent, {});
    folded = foldedBlocks(refined.grid.blocks());
  }
  return refinedWhereFolded(mesh, used, firstHeight, extent, std::move(refined), std::move(folded));
}

}  // namespace bvmesh::grid

// Spacings asked at wall feature lines (RefinementOptions::featureSpacings): which ends of the
// wall blocks' tangential wall edges lie on a feature, how many cells a set then needs, and the
// clustering steps of each edge, fading block by block away from the feature.
#pragma once

#include <Eigen/Core>

#include <array>
#include <vector>

#include "core/grid/block_plan.h"
#include "core/grid/refinement.h"

namespace bvmesh::grid {

// The ends of the wall blocks' tangential wall edges: a clamped curve starts at its first pole,
// leaving towards its second.
struct EdgeEnd {
  std::array<double, 3> corner;
  Eigen::Vector3d outward;  // unit tangent from the corner into the edge
  double length;
  size_t node;  // its block direction, 3 b + d
  int edge;     // e = s1 + 2 s2 (BlockPlan)
  size_t root;
  int sharedEnd;  // 0: the set's start, 1: its end
};

// Per set end (indexed by its root), the spacing wall features ask there (0: none) and the
// longest wall edge of the set that ends on one of them, which gets that spacing exactly.
struct FeatureDemand {
  std::array<double, 2> spacing{0.0, 0.0};
  std::array<double, 2> length{0.0, 0.0};
};

struct FeatureMatches {
  std::vector<FeatureDemand> demands;  // per set root
  std::vector<char> onFeature;         // per edge end
};

// The edge ends on a feature line (within its tolerance, by default 1e-3 of the wall's size) that
// leave it (more than 45 degrees off the line's direction there), and what they ask of their sets
// (`nodes`: 3 x the block count).
FeatureMatches matchFeatures(const std::vector<EdgeEnd>& ends, const std::vector<FeatureSpacing>& features,
                             size_t nodes);

// The fewest cells on a line of length `length` that start at spacings s0 and s1 at its ends (0:
// none) and grow by at most `growth` to `spacing` (geometric, then uniform; where the two graded
// parts meet first, geometric from both ends to the middle).
int gradedCells(double length, double s0, double s1, double spacing, double growth);

// Per block direction (3 b + d) and edge, the steps at its set's two ends as fractions of the
// edge's length, in the set's sense (0: none).
using EdgeSteps = std::vector<std::array<std::array<double, 2>, 4>>;

// Feature clustering, graded along each set. The longest wall edge on a feature gets its spacing
// (step f of its length); a wall edge k blocks away from the feature's edges (through the other
// wall edge of a block, and the same edge shared by neighbours) gets u (f / u)^(1 / 2^k), u the
// uniform step, so the clustering fades block by block instead of running through the whole set:
// a wing's nose set runs on through the tip cap into the trailing edge's small corner blocks,
// which a full clustering squeezed. Neighbouring wall edges of a block differ by at most a
// square root of the cluster, which their blended inner lines take without shearing. A set that
// holds a block without a wall clusters every edge alike (its lines are not held at a wall).
// rootOf: each block direction's set root.
EdgeSteps featureEdgeSteps(const std::vector<BlockPlan>& plans, const std::vector<size_t>& rootOf,
                           const std::vector<EdgeEnd>& ends, const FeatureMatches& matches,
                           const std::vector<int>& counts);

}  // namespace bvmesh::grid

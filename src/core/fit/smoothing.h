// Taubin's nonshrinking smoothing (lambda|mu) of control points on a neighbour graph.
//
// The caller decides who smooths towards whom, which makes the smoothing feature-aware: a crease
// vertex lists only its two crease neighbours (it moves along the crease), a boundary vertex its
// boundary neighbours, a corner nobody (it stays). Umbrella weights (the plain neighbour average).
#pragma once

#include <Eigen/Core>

#include <vector>

#include "core/common/types.h"

namespace bvmesh::fit {

constexpr int kMaxTaubinIterations = 10000;
// The most a lambda|mu pair may scale any wavelength per iteration: Taubin's own pairs pass their
// band at about 1.001; a pair above this makes the points run away (1e27 after three iterations).
constexpr double kMaxTaubinPairGain = 1.05;

struct TaubinOptions {
  int iterations = 10;   // each iteration is one lambda step and one mu step
  double lambda = 0.6307;
  double mu = -0.6732;   // |mu| > lambda: the pair neither shrinks nor grows low frequencies
};

// points: #P x 3; neighbours: #P lists of vertex ids (an empty list keeps that point).
// Throws InvalidInputError for mismatched sizes, ids out of range, non-finite factors or a pair that
// amplifies some wavelength more than kMaxTaubinPairGain per iteration.
RowMatrixX3d taubinSmooth(const RowMatrixX3d& points, const std::vector<std::vector<int>>& neighbours,
                         const TaubinOptions& options = {});

}  // namespace bvmesh::fit

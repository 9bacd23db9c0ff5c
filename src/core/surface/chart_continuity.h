// Tangent-plane (G1) continuity of the B-spline charts across their shared smooth borders.
//
// Neighbouring charts share their border curve exactly (limit_bsplines.h), but each takes its
// derivative across the border from its own least-squares fit; near extraordinary vertices, where
// the limit surface is not in the spline space, the two tangent planes then differ by degrees.
// Both planes are the plane orthogonal to a unit vector N(x) wherever N(x) is orthogonal to the
// border tangent and to both cross-border derivatives. With N given along the border (the caller
// takes a weighted mean of the two charts' normals, see limit_bsplines.cpp) the condition is linear
// in one chart's poles, and only in the pole row next to the border: every chart is turned into
// the common planes on its own, and neighbours then agree without a coupled solve. N is no
// polynomial, so the condition enters as a heavily weighted least-squares term at samples along
// the border, against the change of the fitted surface. Where a chart is exact and N is its own
// normal, nothing moves. The pole count and knots stay; what it costs is distance from the limit
// surface next to extraordinary vertices (LimitBSplineOptions::tangentContinuity).
#pragma once

#include <Eigen/Core>

#include <array>
#include <vector>

#include "core/surface/quad_charts.h"

namespace bvmesh::surface {

// The limit surface's unit normal at a point of a chart side, orthogonal to the side's tangent.
struct BorderNormal {
  ChartSide side = ChartSide::VMin;
  double position = 0.0;  // along the side, in cells
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

// Unit normal (du x dv, zero where that vanishes) at (s, t) of a clamped bicubic chart with
// uniform knots, one span per cell; `poles[d]` holds coordinate d, (uCells + 3) x (vCells + 3).
Eigen::Vector3d chartNormal(const std::array<Eigen::MatrixXd, 3>& poles, double s, double t);

// Moves the second ring of poles of a clamped bicubic chart with uniform knots (one span per cell)
// so that its derivative across each side is orthogonal to the given normals: a least-squares
// term of weight `weight` per normal (over the sine of the chart's corner angle there, so that it
// measures the tangent plane's turn) against the change of the fitted surface, measured with the
// Gram matrices A^T A of the fit's basis matrices in u and v (#poles x #poles) with all other
// poles held. `poles[d]` holds coordinate d, (uCells + 3) x (vCells + 3); the outer ring (the
// border curves) and the inner poles stay.
void alignBorderTangentPlanes(std::array<Eigen::MatrixXd, 3>& poles, const std::vector<BorderNormal>& normals,
                              const Eigen::MatrixXd& uGram, const Eigen::MatrixXd& vGram, double weight);

}  // namespace bvmesh::surface

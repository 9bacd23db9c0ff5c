// A trivariate tensor-product B-spline volume: one block of the volume mesh, the mesh function
// of the thesis. Each direction has its own degree and full knot vector, clamped at both ends, so
// the six faces of the block are the B-spline surfaces of its boundary pole grids.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/common/bspline_curve.h"
#include "core/common/types.h"

namespace bvmesh::volume {

class BsplineVolume {
 public:
  BsplineVolume() = default;
  // degrees: per direction (u, v, w), 1..7; knots: full knot vectors, non-decreasing, finite, the
  // first and last degree + 1 knots equal, no knot repeated more than degree times inside;
  // poles: (#u poles * #v poles * #w poles) x 3, pole (i, j, k) at row i + nu * (j + nv * k) (u fastest).
  // Throws InvalidInputError naming `name` and what is inconsistent.
  BsplineVolume(std::array<int, 3> degrees, std::array<std::vector<double>, 3> knots, RowMatrixX3d poles,
                const std::string& name = "B-spline volume");

  int degree(int direction) const { return degrees_[static_cast<size_t>(direction)]; }
  const std::vector<double>& knots(int direction) const { return knots_[static_cast<size_t>(direction)]; }
  int poleCount(int direction) const { return counts_[static_cast<size_t>(direction)]; }
  double lower(int direction) const { return knots(direction).front(); }
  double upper(int direction) const { return knots(direction).back(); }
  Eigen::Index poleIndex(int i, int j, int k) const {
    return i + static_cast<Eigen::Index>(counts_[0]) * (j + static_cast<Eigen::Index>(counts_[1]) * k);
  }
  const RowMatrixX3d& poles() const { return poles_; }
  // Moves pole rows without changing the layout (the block mesh makes shared faces identical).
  void setPole(Eigen::Index row, const Eigen::Vector3d& position) { poles_.row(row) = position.transpose(); }

  // Points at #P x 3 parameters (u, v, w), each inside the knot ranges, and, for non-null
  // outputs, the first derivatives. Threaded for large batches.
  void evaluate(const RowMatrixX3d& parameters, RowMatrixX3d& points, RowMatrixX3d* du = nullptr,
                RowMatrixX3d* dv = nullptr, RowMatrixX3d* dw = nullptr) const;

  // The iso-parametric curve along `direction` (0 u, 1 v, 2 w) at parameters a, b of the two other
  // directions in increasing order: its poles are the block's poles summed over those directions.
  BsplineCurve isoCurve(int direction, double a, double b) const;
  // Only its poles, into `poles` (#poles along `direction` x 3; its storage is reused when the
  // size matches, so a loop over many lines allocates nothing).
  void isoCurvePoles(int direction, double a, double b, RowMatrixX3d& poles) const;

  // The tensor grid of parameters u x v x w: point (a, b, c) at row a + #u * (b + #v * c). The
  // basis is computed once per parameter and the sums are taken one direction at a time, which
  // is what makes grid evaluation fast (see bench_volume).
  void evaluateGrid(const std::vector<double>& u, const std::vector<double>& v, const std::vector<double>& w,
                    RowMatrixX3d& points, RowMatrixX3d* du = nullptr, RowMatrixX3d* dv = nullptr,
                    RowMatrixX3d* dw = nullptr) const;

 private:
  std::array<int, 3> degrees_{3, 3, 3};
  std::array<std::vector<double>, 3> knots_;
  std::array<int, 3> counts_{0, 0, 0};
  RowMatrixX3d poles_;
};

// Checks a full clamped knot vector of `degree` for `poleCount` poles; `what` names it in errors.
void validateClampedKnots(const std::vector<double>& knots, int degree, int poleCount, const std::string& what);

}  // namespace bvmesh::volume

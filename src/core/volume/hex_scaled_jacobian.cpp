#include "core/volume/hex_scaled_jacobian.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

int cornerIndex(int i, int j, int k) { return 4 * k + (j == 0 ? i : 3 - i); }

}  // namespace

double hexScaledJacobian(const std::array<Eigen::Vector3d, 8>& corners) {
  // Edge of the corner at (i, j, k) along `direction`, pointing towards increasing index.
  const auto edge = [&](int i, int j, int k, int direction) -> Vector3d {
    std::array<int, 3> at{i, j, k};
    std::array<int, 3> other = at;
    other[static_cast<size_t>(direction)] = 1 - other[static_cast<size_t>(direction)];
    const Vector3d& x = corners[static_cast<size_t>(cornerIndex(at[0], at[1], at[2]))];
    const Vector3d& y = corners[static_cast<size_t>(cornerIndex(other[0], other[1], other[2]))];
    return at[static_cast<size_t>(direction)] == 0 ? Vector3d(y - x) : Vector3d(x - y);
  };
  double worst = 1.0;
  bool measured = false;
  for (int k = 0; k < 2; ++k) {
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 2; ++i) {
        std::array<Vector3d, 3> e{edge(i, j, k, 0), edge(i, j, k, 1), edge(i, j, k, 2)};
        std::array<int, 3> ijk{i, j, k};
        int zero = -1, zeros = 0;
        for (int d = 0; d < 3; ++d) {
          if (e[static_cast<size_t>(d)].squaredNorm() == 0.0) {
            zero = d;
            ++zeros;
          }
        }
        double quality = 0.0;
        if (zeros == 0) {
          const double lengths = e[0].norm() * e[1].norm() * e[2].norm();
          quality = e[0].cross(e[1]).dot(e[2]) / lengths;
        } else if (zeros == 1) {
          // A corner merged with its neighbour along `zero` (a collapsed face): a prism's corner,
          // whose third edge is the neighbour's edge that differs from its own. Its sign is the
          // cell's orientation there: the zero edge replaced by the step between the two edges.
          std::array<int, 3> partner = ijk;
          partner[static_cast<size_t>(zero)] = 1 - partner[static_cast<size_t>(zero)];
          int differing = -1;
          for (int d = 0; d < 3; ++d) {
            if (d == zero) continue;
            if (edge(partner[0], partner[1], partner[2], d) != e[static_cast<size_t>(d)]) {
              differing = differing < 0 ? d : 3;
            }
          }
          // Its neighbour's other edges its own: the corner where two collapsed faces of a
          // tetrahedral wedge meet, measured at the wedge's other corners.
          if (differing < 0) continue;
          if (differing == 3) return -1.0;  // pinched to its neighbour without a collapsed face beside it
          const Vector3d mine = e[static_cast<size_t>(differing)];
          const Vector3d theirs = edge(partner[0], partner[1], partner[2], differing);
          // The step from this corner's edge's far end to the partner's, turned to point along
          // increasing `zero` (edges at the upper end of `differing` point into the corner).
          const bool flipped =
              (ijk[static_cast<size_t>(zero)] == 1) != (ijk[static_cast<size_t>(differing)] == 1);
          std::array<Vector3d, 3> oriented = e;
          oriented[static_cast<size_t>(zero)] = flipped ? Vector3d(mine - theirs) : Vector3d(theirs - mine);
          const int same = 3 - zero - differing;
          const double magnitude = std::abs(e[static_cast<size_t>(same)].cross(mine).dot(theirs)) /
                                   (e[static_cast<size_t>(same)].norm() * mine.norm() * theirs.norm());
          const double sign = oriented[0].cross(oriented[1]).dot(oriented[2]);
          quality = sign > 0.0 ? magnitude : (sign < 0.0 ? -magnitude : 0.0);
        } else {
          continue;  // a corner merged along two or three directions has no edges of its own to measure
        }
        measured = true;
        worst = std::min(worst, quality);
      }
    }
  }
  return measured ? worst : -1.0;
}

}  // namespace bvmesh::volume

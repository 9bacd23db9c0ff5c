#include "core/grid/outer_quads.h"

#include <algorithm>

namespace bvmesh::grid {

using volume::BoundaryCondition;

int tagOuterQuads(std::vector<GridBlock>& blocks, const volume::Domain& domain) {
  // A sphere's boundary is far field all round: its outlet faces lie in an outflow plane.
  if (domain.shape == volume::DomainShape::Sphere) return 0;
  int split = 0;
  for (GridBlock& block : blocks) {
    for (int f = 0; f < 6; ++f) {
      const BoundaryCondition condition = block.faces[static_cast<size_t>(f)].condition;
      if (condition != BoundaryCondition::Inlet && condition != BoundaryCondition::Outlet &&
          condition != BoundaryCondition::Side) {
        continue;
      }
      const std::array<int, 2> counts = volume::faceGridCounts(block.size, f);
      std::vector<BoundaryCondition> quads;
      quads.reserve(static_cast<size_t>(counts[0] - 1) * static_cast<size_t>(counts[1] - 1));
      for (int b = 0; b + 1 < counts[1]; ++b) {
        for (int a = 0; a + 1 < counts[0]; ++a) {
          const Eigen::Vector3d centre =
              0.25 * (block.points.row(block.facePoint(f, a, b)) + block.points.row(block.facePoint(f, a + 1, b)) +
                      block.points.row(block.facePoint(f, a, b + 1)) + block.points.row(block.facePoint(f, a + 1, b + 1)))
                         .transpose();
          quads.push_back(domain.conditionAt(domain.onBoundary(centre)));
        }
      }
      if (std::all_of(quads.begin(), quads.end(), [&](BoundaryCondition c) { return c == condition; })) continue;
      block.quadConditions[static_cast<size_t>(f)] = std::move(quads);
      ++split;
    }
  }
  return split;
}

}  // namespace bvmesh::grid

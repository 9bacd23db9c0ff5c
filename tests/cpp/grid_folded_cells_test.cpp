// The fold check on hand-made cells: every corner turned inside out, skewed and prism cells, and
// the blocks flagged one by one.
#include <gtest/gtest.h>

#include <Eigen/Core>

#include <vector>

#include "core/grid/folded_cells.h"
#include "grid_fixtures.h"

namespace bvmesh::grid {
namespace {

using Eigen::Vector3d;

TEST(GridFolds, EveryCornerTurnedInsideOutIsFoundAndASkewedOrPrismCellIsNot) {
  auto folds = [](const std::vector<GridBlock>& grids) { return foldedBlocks(grids)[0] == 1; };
  EXPECT_FALSE(folds(test::twoCellRow({0, 0, 0}, Vector3d::Zero())));
  // Each point of the row, whichever corner of its cells it is: pushed through them along the
  // diagonal, its corners turn inside out; a fifth as far, they are skewed but valid.
  for (int k = 0; k < 2; ++k) {
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 3; ++i) {
        const Vector3d inwards(i == 0 ? 1.0 : -1.0, j == 0 ? 1.0 : -1.0, k == 0 ? 1.0 : -1.0);
        EXPECT_TRUE(folds(test::twoCellRow({i, j, k}, 1.5 * inwards))) << i << " " << j << " " << k;
        EXPECT_FALSE(folds(test::twoCellRow({i, j, k}, 0.3 * inwards))) << i << " " << j << " " << k;
        // Across the diagonal of its own i-face: that face folds, and only the corners on it turn
        // (on the last face, only far corners: each cell's are checked, not only its near ones).
        const Vector3d acrossFace(0.0, inwards.y(), inwards.z());
        EXPECT_TRUE(folds(test::twoCellRow({i, j, k}, 1.5 * acrossFace))) << i << " " << j << " " << k;
      }
    }
  }
  // A prism: the second cell's far face (i = 2) merged into its edge at j = 0 (a collapsed face's
  // cells), valid though its merged corners have no triple product; the same with that edge
  // pulled back behind the cell's near face is folded.
  std::vector<GridBlock> prism = test::twoCellRow({2, 1, 0}, Vector3d(0.0, -1.0, 0.0));
  prism[0].points.row(prism[0].index(2, 1, 1)) << 2.0, 0.0, 1.0;
  EXPECT_FALSE(folds(prism));
  for (int k = 0; k < 2; ++k) {
    for (int j = 0; j < 2; ++j) prism[0].points.row(prism[0].index(2, j, k)) << 0.8, 0.0, k;
  }
  EXPECT_TRUE(folds(prism));
}

TEST(GridFolds, EachBlockIsFlaggedOnItsOwn) {
  std::vector<GridBlock> grids = test::twoCellRow({0, 0, 0}, Vector3d::Zero());
  grids.push_back(test::twoCellRow({1, 1, 1}, Vector3d(-1.5, 1.5, 1.5))[0]);
  grids.push_back(grids[0]);
  EXPECT_EQ(foldedBlocks(grids), (std::vector<char>{0, 1, 0}));
}

}  // namespace
}  // namespace bvmesh::grid

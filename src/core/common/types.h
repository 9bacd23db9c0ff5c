// The array types that cross the core's interfaces: row-major, so that an (n, 3) numpy array
// maps onto them without a copy, and sparse operators whose rows are output points.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace bvmesh {

using RowMatrixX3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;  // points, vectors
using RowMatrixX2d = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;  // (u, v) parameters
using RowMatrixX2i = Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor>;     // vertex pairs
using RowSparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;            // linear operators

}  // namespace bvmesh

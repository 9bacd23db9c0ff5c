// The scaled Jacobian of a hexahedral cell, collapsed faces (prisms) included: the marching's and
// the grid quality's measure of a cell.
#pragma once

#include <Eigen/Core>

#include <array>

namespace bvmesh::volume {

// Scaled Jacobian of the hexahedron with corners 000 100 110 010 001 101 111 011: the minimum
// over its corners of det(e1, e2, e3) / (|e1| |e2| |e3|) with the three edges leaving each corner.
// A cell on a collapsed face has corners merged with their neighbours (bit-identical points): a
// corner merged along one direction is a prism's, measured with its neighbour's differing edge as
// its third (signed by the cell's orientation there); one merged along more is no corner; a cell
// without any measurable corner, or pinched without a collapsed face, gets -1.
double hexScaledJacobian(const std::array<Eigen::Vector3d, 8>& corners);

}  // namespace bvmesh::volume

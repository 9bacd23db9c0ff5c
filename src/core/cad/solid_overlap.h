// Solids of one shape that run into each other: a wing and a fuselage written as two solids, the
// wing's root inside the fuselage. The faces of both then form no body's surface (the wing's root
// face lies inside the fuselage), and a template fitted over them misses the junction; they have
// to be fused into one solid first.
#pragma once

#include <TopoDS_Shape.hxx>

#include <array>
#include <vector>

namespace bvmesh::cad {

struct SolidOverlap {
  int solid = -1;  // TopExp order, 0-based
  int otherSolid = -1;
  std::array<double, 3> where{};  // a boundary point of one solid strictly inside the other
};

// Pairs of solids of which one has a boundary point (a vertex, an edge's or a face's middle; at
// most 2000 of them per solid, evenly spread) strictly inside the other. Solids that only touch
// are not overlaps. Shapes with more than
// kMostSolidsChecked solids are not checked (an assembly of many parts; empty result).
constexpr int kMostSolidsChecked = 32;
std::vector<SolidOverlap> overlappingSolids(const TopoDS_Shape& shape);

}  // namespace bvmesh::cad

// A CAD of the flow domain, as CFD pre-processors write it: a box or sphere (or its half on a
// symmetry plane) with the body cut out. Splits its faces into the body (the target to fit) and
// the domain's outer faces, and describes the domain for the volume stage's far field.
#pragma once

#include <TopoDS_Shape.hxx>

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

#include "core/fit/surface_fitter.h"

namespace bvmesh::polyhedron {

struct FlowDomain {
  std::vector<int> bodyFaces;   // face indices (TopExp order) of the body
  std::vector<int> outerFaces;  // those of the domain's boundary, the symmetry face included
  std::string shape;            // "sphere" or "box"
  // The far field for the volume stage: the sphere's centre and radius, or the box's centre and
  // half sizes. On a symmetry plane the centre lies on the plane and the sizes are the whole half
  // domain's (the volume stage keeps the body's side of it).
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;
  Eigen::Vector3d halfExtent = Eigen::Vector3d::Zero();
  int symmetryFace = -1;                       // the outer planar face the body's root lies on
  std::optional<fit::SymmetryPlane> symmetryPlane;  // its plane, the normal towards the domain
  // The outer planar face a body that runs into the outflow boundary (a sting) ends on, and its
  // plane (normal towards the domain); a sphere domain's only, its centre on that plane.
  int outflowFace = -1;
  std::optional<fit::SymmetryPlane> outflowPlane;
};

// A face bounds the domain when the whole shape lies on one side of its tangent plane at every
// sample of it (the domain is convex: a box or a sphere); the others are the body's. Throws
// InvalidInputError naming the problem: a null or face-less shape, no body inside, outer faces
// other than a sphere's or axis-aligned planes (naming the face and its surface type), spheres
// that differ, or a body touching more than two outer faces. A body touching two (perpendicular)
// planes of a sphere domain lies on the symmetry plane and runs into the outflow plane: the
// symmetry plane is the one where the body's footprint is the wider (a half body's whole profile
// against its sting's or tail's section), at least 1.5 times as wide, else the split is refused
// as ambiguous.
FlowDomain splitFlowDomain(const TopoDS_Shape& shape);

}  // namespace bvmesh::polyhedron

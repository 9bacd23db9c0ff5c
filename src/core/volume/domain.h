// The outer boundary of the flow domain: a sphere (the default), a box (a wind tunnel's or a
// solver's rectangular domain) or a cylinder along the flow, each around the body's centre (on the
// symmetry plane for a half model, which then makes the half sphere, half box or half cylinder).
// The marching's last layer is projected onto it along the ray from the centre, and each far-field
// block face is tagged by the part of the boundary it lies on and the flow direction.
#pragma once

#include <Eigen/Core>

#include <string>

#include "core/volume/block_mesh.h"

namespace bvmesh::volume {

enum class DomainShape { Sphere, Box, Cylinder };

struct Domain {
  DomainShape shape = DomainShape::Sphere;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  // Sphere: radius; cylinder: radius and half length along the flow direction.
  double size = 1.0;
  // Box: half sizes along x, y, z.
  Eigen::Vector3d halfExtent = Eigen::Vector3d::Ones();
  Eigen::Vector3d flowDirection = Eigen::Vector3d::UnitX();  // unit

  // Throws InvalidInputError naming a non-finite or non-positive size or flow direction.
  void validate() const;
  // The boundary point for x (which must differ from the centre): where the ray from the centre
  // through x meets a sphere or cylinder; for a box, that point on the cube [-1, 1]^3 scaled to the
  // box's half sizes.
  Eigen::Vector3d onBoundary(const Eigen::Vector3d& x) const;
  // The boundary's outward normal at a point on it (of the face it lies on for a box and at a
  // cylinder's ends).
  Eigen::Vector3d outwardNormal(const Eigen::Vector3d& boundaryPoint) const;
  // The smooth piece of the boundary a point lies on: 0 on a sphere; a box's face 0..5 (-x, +x,
  // -y, +y, -z, +z); a cylinder's side 0, downstream end 1, upstream end 2.
  int pieceAt(const Eigen::Vector3d& boundaryPoint) const;
  // Distance of x from the surface that carries piece `piece` (the face's plane, the cylinder's
  // side or the plane of its end, the sphere).
  double distanceToPiece(const Eigen::Vector3d& x, int piece) const;
  // Which part of the boundary a point on it is: Farfield on a sphere; on a box or cylinder Inlet
  // where the normal faces the flow (normal . flow < -1/2), Outlet where it faces away (> 1/2),
  // Side elsewhere.
  BoundaryCondition conditionAt(const Eigen::Vector3d& boundaryPoint) const;
};

DomainShape domainShapeOf(const std::string& name);  // "sphere", "box", "cylinder"
const char* domainShapeName(DomainShape shape);

}  // namespace bvmesh::volume

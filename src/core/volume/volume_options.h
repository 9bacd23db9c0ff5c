// The volume mesh's options and their resolution into the marching's: the defaults filled in
// from the wall (reference length, boundary-layer estimate, far-field distance), the domain set up
// around the wall's centre, every value checked. Shared by the B-spline blocks (volume_blocks.h)
// and the Catmull-Clark volume control mesh (control_volume.h), which march the same way.
#pragma once

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

#include "core/volume/domain.h"
#include "core/volume/marching.h"

namespace bvmesh::volume {

// The largest max_layers accepted.
constexpr int kMaxControlLayers = 2000;

struct VolumeMeshOptions {
  // Reference length (root chord of a wing, length of a body); 0: the wall's largest extent.
  double referenceLength = 0.0;
  // Boundary-layer estimate when its thickness is 0: turbulent flat plate at the reference length,
  // delta = 0.37 L Re^-0.2.
  double reynoldsNumber = 5e6;
  double boundaryLayerThickness = 0.0;
  int boundaryLayerLayers = 4;
  double boundaryLayerGrowth = 1.2;
  double sharpEdgeSplay = 2.0;  // MarchingOptions::sharpEdgeSplay
  // Knife edges of the wall (a sharp trailing edge) cut open, with a fan of prisms round them
  // (edge_fans.h); else their grid lines splay in the band. The B-spline blocks only.
  bool knifeEdgeFans = false;
  // Far-field boundary around the wall's centre (halved by a symmetry plane): a sphere of radius
  // farfieldDistance (0: 20 reference lengths), a box (half sizes boxHalfExtent, or farfieldDistance
  // along every axis where 0, at most 1e4 reference lengths; the layers are marched to its nearest
  // face), or a cylinder along the flow direction (radius and half length farfieldDistance). Box and cylinder faces are tagged inlet / outlet / side by flowDirection.
  double farfieldDistance = 0.0;
  double farfieldGrowth = 1.3;
  DomainShape domain = DomainShape::Sphere;
  Eigen::Vector3d boxHalfExtent = Eigen::Vector3d::Zero();
  Eigen::Vector3d flowDirection = Eigen::Vector3d::UnitX();
  double smoothing = 1.0;
  FarfieldScheme farfieldScheme = FarfieldScheme::Hyperbolic;  // MarchingOptions::farfieldScheme
  double minScaledJacobian = 0.05;
  int maxLayers = 400;  // at most kMaxControlLayers
  long long maxLayerPoints = 0;  // MarchingOptions::maxLayerPoints
  // The domain's centre when given (a flow domain's CAD: bvmesh's splitFlowDomain), else the
  // wall's bounding-box centre; on the symmetry plane of a half model.
  std::optional<Eigen::Vector3d> domainCentre;
  // Symmetry plane of a half model: the wall's open boundary must lie on it.
  bool hasSymmetryPlane = false;
  Eigen::Vector3d planePoint = Eigen::Vector3d::Zero();
  Eigen::Vector3d planeNormal = Eigen::Vector3d::UnitY();
  // Outflow plane of a body that runs into the domain's outflow boundary (a sting): the wall's
  // open boundary off the symmetry plane lies on it, the points there march in it and the blocks'
  // faces in it are tagged outlet. Perpendicular to the symmetry plane; the domain a sphere whose
  // centre lies on it (the domain is the part of the sphere on the wall's side).
  bool hasOutflowPlane = false;
  Eigen::Vector3d outflowPoint = Eigen::Vector3d::Zero();
  Eigen::Vector3d outflowNormal = Eigen::Vector3d::UnitX();
};

struct ResolvedVolumeOptions {
  MarchingOptions marching;
  double referenceLength = 0.0;
  double boundaryLayerThickness = 0.0;
  double farfieldDistance = 0.0;  // marched to: a box's nearest face
  Eigen::Vector3d domainCentre = Eigen::Vector3d::Zero();
};

// The turbulent flat-plate boundary-layer thickness 0.37 L Re^-0.2 (the volume mesh's default
// boundary layer; a RANS case's wall-damped start). Throws InvalidInputError unless both are
// finite and positive.
double flatPlateBoundaryLayerThickness(double reynoldsNumber, double length);

// The unit normal of the options' symmetry plane. Throws InvalidInputError when the model is a
// half model whose plane has a non-finite point or a zero normal.
Eigen::Vector3d symmetryPlaneNormal(const VolumeMeshOptions& options);

// The options' symmetry and outflow planes (unit normals). Throws InvalidInputError for a plane
// with a non-finite point or a zero normal, and for two planes that are not perpendicular.
BoundaryPlanes boundaryPlanesOf(const VolumeMeshOptions& options);

// The boundary plane (0: symmetry, 1: outflow) that an open side of the wall, `points`, lies on:
// of the options' planes the one nearer to the side's farthest point, within `tolerance`. Throws
// InvalidInputError naming `where` when the options give no plane or the side lies off it.
size_t openSidePlane(const VolumeMeshOptions& options, const BoundaryPlanes& planes,
                     const std::vector<Eigen::Vector3d>& points, double tolerance, const std::string& where);

// The marching set-up for `front` (the wall to march, its symmetry-plane points marked). Throws
// InvalidInputError naming the option for a bad value, and for a front oriented inwards.
ResolvedVolumeOptions resolveVolumeOptions(const VolumeMeshOptions& options, const MarchingFront& front);

}  // namespace bvmesh::volume

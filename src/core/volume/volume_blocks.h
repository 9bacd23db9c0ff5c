// From a fitted wall to the block-structured B-spline volume mesh: the wall's B-spline charts
// (conforming patches), the Greville points of their poles as the surface grid to march, the
// marched layers, and per patch one tricubic block whose w = 0 face is the patch surface, whose
// w direction interpolates the layers and whose faces shared with neighbours are identical.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/surface/quad_charts.h"
#include "core/volume/block_mesh.h"
#include "core/volume/marching.h"

namespace bvmesh::volume {

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
  double minScaledJacobian = 0.05;
  int maxLayers = 400;
  // Symmetry plane of a half model: the wall's open boundary must lie on it.
  bool hasSymmetryPlane = false;
  Eigen::Vector3d planePoint = Eigen::Vector3d::Zero();
  Eigen::Vector3d planeNormal = Eigen::Vector3d::UnitY();
};

struct VolumeMesh {
  BlockMesh blocks;
  std::vector<int> blockChart;           // chart of the wall surface each block stands on
  std::vector<double> layerDistance;     // mean marched distance of each control layer
  std::vector<double> layerMinScaledJacobian;
  // The options as resolved (defaults filled in).
  double referenceLength = 0.0;
  double boundaryLayerThickness = 0.0;
  double farfieldDistance = 0.0;
  Eigen::Vector3d domainCentre = Eigen::Vector3d::Zero();
  Domain domain;
  double wallMaxDeviation = 0.0;  // the charts' deviation from the limit surface
  // Far-field block faces whose poles lie on more than one face of a box or cylinder domain (they
  // bend around its edge; each is tagged by the part its middle lies on).
  int farfieldFacesAcrossDomainEdges = 0;
};

// The volume mesh around the limit surface of `wall` (an all-quad Catmull-Clark control mesh,
// outward oriented, closed or open only on the symmetry plane). Throws InvalidInputError for bad
// options or an inward / open wall, SolverError when the marching would fold.
VolumeMesh generateVolumeMesh(const surface::QuadControlMesh& wall, const VolumeMeshOptions& options = {});

}  // namespace bvmesh::volume

// Geometric analysis of a target's tessellation for placing templates: principal axes (PCA),
// plane sections (plane-triangle intersection) with line queries, the symmetry plane of a half
// model, and the removal of a symmetry-plane face from a CAD shape.
#pragma once

#include <TopoDS_Shape.hxx>

#include <Eigen/Core>

#include <optional>
#include <vector>

#include "core/fit/surface_fitter.h"
#include "core/polyhedron/feature_curves.h"
#include "core/target/target.h"

namespace bvmesh::polyhedron {

// Area-weighted principal axes of the tessellated surface.
struct PrincipalFrame {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();    // area centroid
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // columns: unit axes, largest extent first
  Eigen::Vector3d low = Eigen::Vector3d::Zero();       // extents of the nodes along each axis, from centre
  Eigen::Vector3d high = Eigen::Vector3d::Zero();
  Eigen::Vector3d variances = Eigen::Vector3d::Zero();  // per axis, decreasing
};

// Throws InvalidInputError when the target has no triangles (nothing to place a template on).
PrincipalFrame principalFrame(const target::Target& target);

// The segments where a plane cuts the tessellation.
class PlaneSection {
 public:
  // planePoint / planeNormal: the cutting plane (normal need not be unit).
  PlaneSection(const target::Target& target, const Eigen::Vector3d& planePoint,
               const Eigen::Vector3d& planeNormal);
  bool empty() const { return segments_.empty(); }
  int size() const { return static_cast<int>(segments_.size()); }
  // Parameters s of the points origin + s * direction where the line (in the plane) crosses the
  // section, ascending.
  std::vector<double> lineHits(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;
  // #2K x 3 segment end points (rows 2k, 2k + 1 form segment k).
  const target::Points& points() const { return points_; }

 private:
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> segments_;
  target::Points points_;
  Eigen::Vector3d normal_;
};

// The symmetry plane of a half model: the plane of the longest free-boundary curve that lies in
// a plane (within relativeFlatness of the diagonal) with the whole target on one side of it, or
// else the plane of all free-boundary curves together, which straight curves only span so (a half
// cylinder's). The normal points to the side the target lies on.
std::optional<fit::SymmetryPlane> detectSymmetryPlane(const target::Target& target,
                                                      const std::vector<FeatureCurve>& curves,
                                                      double relativeFlatness = 1e-5);

// A shape with its symmetry-plane face removed: the planar face, among those with the whole
// shape on one side of their plane, of the largest area. `face` is its index (TopExp order).
struct HalfModelShape {
  TopoDS_Shape shape;  // the other faces, as a compound
  int face = -1;
  fit::SymmetryPlane plane;  // normal pointing to the side the shape lies on
};
// Throws InvalidInputError when no face qualifies.
HalfModelShape removeSymmetryFace(const TopoDS_Shape& shape, double relativeFlatness = 1e-6);

// A compound of the given faces of a shape (TopExp order). Throws InvalidInputError for a bad index.
TopoDS_Shape selectFaces(const TopoDS_Shape& shape, const std::vector<int>& faces);

}  // namespace bvmesh::polyhedron

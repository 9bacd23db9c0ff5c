// Automatic placement of a template on a target: the generator's topology is built with the
// template's parameters and laid onto the target (principal axes and extents for bodies; span,
// trailing-edge curve, sections and chords for wings; the body's profile, the trailing edge and
// the wing-body intersection curve for a wing-fuselage model; the symmetry plane of a half model
// from a planar free boundary), then its creases, boundaries and corners are mapped onto the target's
// feature curves and vertices, and the polyhedron is improved (improve.h).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/fit/surface_fitter.h"
#include "core/mesh/control_mesh.h"
#include "core/polyhedron/feature_curves.h"
#include "core/polyhedron/feature_mapping.h"
#include "core/polyhedron/improve.h"
#include "core/polyhedron/template_library.h"
#include "core/target/target.h"

namespace bvmesh::polyhedron {

struct PlacementOptions {
  std::map<std::string, std::string> parameters;  // overrides of the template's defaults
  FeatureCurveOptions curves;
  FeatureMappingOptions mapping;
  bool improve = true;
  // Improvement options; unset: ImproveOptions' defaults with the template's passes. The
  // symmetry plane is always the detected one.
  std::optional<ImproveOptions> improvement;
};

// A wing's planform as the placement measured it on the target (sections at the ends of the
// trailing edge; a full wing's root half way between its tips). Chords run from the leading-edge point (farthest section point from the
// trailing edge) to the trailing edge; sweeps are measured in the plane of span and root chord.
struct WingPlanform {
  Eigen::Vector3d spanDirection = Eigen::Vector3d::Zero();
  double span = 0.0;       // from the root to the tip (a full wing's half span)
  double rootChord = 0.0;  // a half wing's first station, a full wing's middle
  double tipChord = 0.0;   // last station
  double leadingEdgeSweepDeg = 0.0;
  double trailingEdgeSweepDeg = 0.0;
};

struct PlacedPolyhedron {
  std::string templateName;
  ControlMesh mesh;
  FeatureMapping mapping;                           // mapping.map is the FeatureMap for SurfaceFitter
  std::vector<FeatureCurve> curves;                 // the target's feature curves the mapping refers to
  std::optional<fit::SymmetryPlane> symmetryPlane;  // for FitOptions::symmetryPlane
  std::map<std::string, std::string> parameters;    // the values used ("auto" resolved)
  std::optional<WingPlanform> planform;             // wing and wing-fuselage templates only
};

// Throws InvalidInputError when the target does not suit the template (e.g. a half wing on a
// target without a planar free boundary, or without a sharp trailing edge), naming what is
// missing. Unmapped features do not throw: see PlacedPolyhedron::mapping.
PlacedPolyhedron placeTemplate(const PolyhedronTemplate& polyhedronTemplate, const target::Target& target,
                               const PlacementOptions& options = {});

}  // namespace bvmesh::polyhedron

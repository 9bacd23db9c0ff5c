// Mapping of a control polyhedron's features onto the CAD target's feature curves: crease chains
// onto sharp curves, boundary chains onto free-boundary curves, corners onto CAD vertices, by
// proximity and direction. The result is the fit::FeatureMap SurfaceFitter takes, plus a report
// of what could not be mapped (with distances), so that a caller can stop with a clear message.
#pragma once

#include <string>
#include <vector>

#include "core/fit/surface_fitter.h"
#include "core/mesh/control_mesh.h"
#include "core/polyhedron/feature_curves.h"
#include "core/target/target.h"

namespace bvmesh::polyhedron {

// A maximal chain of crease edges or of boundary edges of a control mesh. Chains end at corners,
// at vertices where the number of feature edges is not two, and where a crease meets a boundary.
struct MeshFeatureChain {
  FeatureCurveKind kind = FeatureCurveKind::Sharp;  // Sharp: crease edges; Boundary: boundary edges
  std::vector<int> vertices;  // in chain order; a closed chain does not repeat its first vertex
  std::vector<int> edges;     // edges[i] joins vertices[i] and vertices[i + 1] (mod size when closed)
  bool closed = false;
};

std::vector<MeshFeatureChain> meshFeatureChains(const ControlMesh& mesh);

struct FeatureMappingOptions {
  // A chain maps to a curve when all its samples lie within this distance of it (relative to
  // the target's bounding-box diagonal, or to the chain's length if that allows more: control
  // points of a coarse polyhedron stand off small features by about their edge length) ...
  double relativeMaxDistance = 0.05;
  double relativeChainDistance = 0.25;
  // ... and its edges run along the curve: mean angle between chain and curve tangents (degrees).
  double maxAngleDeg = 30.0;
  // A corner maps to the nearest CAD vertex within this distance (relative to the diagonal).
  double relativeCornerDistance = 0.05;
  int samplesPerEdge = 4;  // points per chain edge compared with the curves
};

struct ChainMapping {
  int curve = -1;             // index into the detected curves (the one most followed), or -1 (unmapped)
  std::vector<int> curves;    // every curve the chain follows (several where it spans a kink or junction)
  int mapCurve = -1;          // index into FeatureMap::curves, or -1
  std::vector<int> cadEdges;  // the part of the curve the chain follows, in curve order
  // Best candidate's figures (also when unmapped; infinite when there was no candidate).
  int nearestCurve = -1;
  double maxDistance = 0.0;
  double meanAngleDeg = 0.0;
  double distanceLimit = 0.0;  // the max distance this chain was allowed
};

struct CornerMapping {
  int vertex = -1;     // control-mesh vertex (explicit corner or a junction of feature chains)
  int cadVertex = -1;  // mapped target vertex, or -1
  int nearestCadVertex = -1;
  double distance = 0.0;  // to the nearest candidate CAD vertex
  bool required = false;  // explicit corners must map; junctions map when a CAD vertex is near
};

struct FeatureMapping {
  fit::FeatureMap map;  // ready for SurfaceFitter
  std::vector<MeshFeatureChain> chains;
  std::vector<ChainMapping> chainMappings;  // parallel to chains
  std::vector<CornerMapping> corners;
  std::vector<int> unmappedChains;   // indices into chains
  std::vector<int> unmappedCorners;  // indices into corners
  // The limits used (for the report); a chain's distance limit is the larger of
  // maxDistanceLimit and relativeChainDistance times its length.
  double maxDistanceLimit = 0.0;
  double relativeChainDistance = 0.0;
  double maxAngleLimitDeg = 0.0;
  double cornerDistanceLimit = 0.0;

  bool complete() const { return unmappedChains.empty() && unmappedCorners.empty(); }
  // One line per unmapped chain / corner, naming vertices, distances and the nearest candidate.
  std::string describeUnmapped() const;
};

// Maps the mesh's crease chains, boundary chains and corners onto `curves` (detectFeatureCurves)
// and the target's vertices. Never throws for features that map to nothing: they are reported.
FeatureMapping mapFeatures(const ControlMesh& mesh, const target::Target& target,
                           const std::vector<FeatureCurve>& curves,
                           const FeatureMappingOptions& options = {});

// Throws InvalidInputError with describeUnmapped() when something is unmapped.
void requireComplete(const FeatureMapping& mapping);

}  // namespace bvmesh::polyhedron

// Feature curves of a CAD target: its sharp edges (dihedral angle above a threshold), its free
// boundary edges and its kinks (edges below the sharp angle that a tangent-continuous surface
// cannot round within a tolerance, see FeatureCurveOptions), each kind chained through shared CAD
// vertices into curves. A chain goes on through a vertex where exactly two edges of its kind meet and the curve continues with (nearly) the same
// tangent; a vertex where three or more feature edges meet, or where the chain turns sharply,
// ends a curve. Crease chains and boundary loops of a control polyhedron are mapped onto these
// curves (feature_mapping.h).
#pragma once

#include <Eigen/Core>

#include <vector>

#include "core/target/target.h"

namespace bvmesh::polyhedron {

enum class FeatureCurveKind {
  Sharp,     // chain of sharp edges between two faces
  Boundary,  // chain of free edges (one face)
  Kink,      // chain of edges below the sharp angle whose rounding costs more than the tolerance
};

struct FeatureCurve {
  FeatureCurveKind kind = FeatureCurveKind::Sharp;
  std::vector<int> edges;  // target edge ids in chain order
  // Per edge: true when the edge runs against the chain (from its second to its first vertex).
  std::vector<bool> reversed;
  int startVertex = -1;  // target vertex where the chain starts (-1 for a loop of one closed edge)
  int endVertex = -1;    // target vertex where it ends; equals startVertex for a closed curve
  double length = 0.0;
  bool closed = false;  // the chain returns to its start vertex
  // True when a closed curve passes its start vertex with tangent continuity (a smooth loop);
  // false when the start vertex is a corner of the loop.
  bool smoothLoop = false;
};

struct FeatureCurveOptions {
  // Edges whose faces meet at a normal angle of at least this are sharp (degrees).
  double sharpAngleDeg = 30.0;
  // A chain ends where consecutive edges' tangents differ by more than this (degrees).
  double continuityAngleDeg = 30.0;
  bool includeBoundary = true;  // also chain the free boundary edges
  // Kinks. A tangent-continuous surface rounds a kink of dihedral angle theta over a strip of some
  // half-width w, missing the CAD's edge by about w theta / 4 (a circular blend). An edge between
  // two faces below the sharp angle is a kink when that miss over its own length L (the widest
  // strip a rounding along it can take), with theta the mean angle along the edge
  // (cad::EdgeInfo::meanDihedralDegrees: a kink only at one end, where another kink edge meets
  // it, does not count), is above both the tolerance and the edge's own OCCT tolerance:
  // theta L / 4 > max(tolerance, edge tolerance). Below that, any surface finer than the edge
  // rounds it within the tolerance; above it, the fit has to resolve it, and a template can put
  // vertices where it ends (the wing templates' tip_kinks, docs/templates.md). Kinks are not
  // crease candidates for feature mapping.
  bool includeKinks = true;
  double kinkTolerance = 0.0;           // absolute; 0: relativeKinkTolerance of the target's diagonal
  double relativeKinkTolerance = 1e-5;  // the fit's default tolerance (fit::FitOptions::relativeTolerance)
};

// The target's feature curves: sharp curves first, then boundary curves, then kinks, each group
// ordered by decreasing length.
std::vector<FeatureCurve> detectFeatureCurves(const target::Target& target,
                                              const FeatureCurveOptions& options = {});

// The target's kink edges (see FeatureCurveOptions), by edge id.
std::vector<int> kinkEdges(const target::Target& target, const FeatureCurveOptions& options = {});

// #K x 3 points along a curve in chain order (the edges' polylines joined, duplicates dropped).
target::Points curvePolyline(const target::Target& target, const FeatureCurve& curve);

const char* featureCurveKindName(FeatureCurveKind kind);

}  // namespace bvmesh::polyhedron

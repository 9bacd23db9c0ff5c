// The Catmull-Clark limit surface of a quad control mesh as watertight bicubic B-spline surfaces,
// one per rectangular chart (see quad_charts.h), and as a sewn OCCT shell or solid.
//
// Every chart surface has uniform interior knots (one span per quad) and is clamped at the chart
// borders; its parameters run over [0, m] x [0, n] in the chart's cell grid. Border curves are
// fitted once per border line and imposed as the boundary poles of every surface that touches
// them, so neighbours share their borders exactly; the interior poles are a least-squares fit to
// limit samples. Where the limit surface lies in that spline space (regular faces, regular
// creases and boundaries) the fit reproduces it to rounding.
#pragma once

#include <TopoDS_Shape.hxx>

#include <vector>

#include "core/cad/bspline_face.h"
#include "core/surface/limit_points.h"
#include "core/surface/quad_charts.h"

namespace bvmesh::surface {

// A clamped B-spline curve in OCCT's knot/multiplicity form.
struct BSplineCurveData {
  int degree = 3;
  std::vector<double> poles;  // #poles x 3
  std::vector<double> knots;  // distinct, increasing
  std::vector<int> multiplicities;
};

struct LimitBSplineOptions {
  int samplesPerSpan = 4;       // fitting samples per quad and direction (at least 4)
  int checkSamplesPerSpan = 9;  // deviation check: points per quad edge, both ends included (>= 2)
  // One-shot conversion: OpenSubdiv isolation depth of the limit evaluator around extraordinary
  // features (Gregory end patches beyond it).
  int isolationLevel = 8;
};

struct LimitBSplines {
  ChartLayout layout;
  std::vector<cad::BSplineSurfaceData> surfaces;  // per chart: parameters [0, uCells] x [0, vCells]
  // Per chart on the check points: max |surface(s, t) - limit(s, t)|, the parametric deviation (an
  // upper bound of the distance between the two surfaces: next to a corner whose limit tangents
  // degenerate, the chart runs through the same surface at other speeds), and max of its
  // component along the limit normal, the distance between the surfaces to first order.
  std::vector<double> maxDeviation;
  std::vector<double> maxDistance;
  std::vector<BSplineCurveData> segmentCurves;    // per layout segment: from its vertex 0, on [0, #edges]
  double maxBorderGap = 0.0;                      // max distance between neighbours along shared segments
  // Max angle between the normals of neighbouring surfaces along shared smooth (non-crease)
  // borders, in degrees: 0 where the limit surface is regular; near extraordinary vertices the
  // surfaces meet with C0 only (G1 is not enforced), and the kink shrinks under subdivision.
  double maxKinkDegrees = 0.0;
};

// Fits the surfaces of a given layout to the limit surface given by `limit`.
LimitBSplines fitLimitBSplines(ChartLayout layout, const LimitPointsFunction& limit,
                               const LimitBSplineOptions& options = {});

// One shot: chart layout, the shared limit evaluator (default subdivision options: the thesis'
// rules) and the fit.
LimitBSplines limitSurfaceToBSplines(const QuadControlMesh& mesh, const LimitBSplineOptions& options = {});

struct SewingOptions {
  double relativeTolerance = 1e-7;  // sewing tolerance as a fraction of the bounding-box diagonal
  bool makeSolid = true;            // a closed shell becomes a solid (outward oriented)
};

struct SewnShape {
  TopoDS_Shape shape;  // a shell (or compound of shells), or a solid when closed
  bool solid = false;
  int freeEdges = 0;              // edges with a single face after sewing
  double tolerance = 0.0;         // the sewing tolerance used
  double maxEdgeTolerance = 0.0;  // largest edge/vertex tolerance of the result: the gap sewing had to close
  bool valid = false;             // BRepCheck_Analyzer
};

// Builds one face per surface (cad::makeBSplineFace) and sews them.
SewnShape sewBSplineSurfaces(const std::vector<cad::BSplineSurfaceData>& surfaces,
                             const SewingOptions& options = {});

}  // namespace bvmesh::surface

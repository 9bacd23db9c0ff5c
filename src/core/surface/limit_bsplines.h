// The Catmull-Clark limit surface of a quad control mesh as watertight bicubic B-spline surfaces,
// one per rectangular chart (see quad_charts.h), and as a sewn OCCT shell or solid.
//
// Every chart surface has uniform interior knots (one span per quad) and is clamped at the chart
// borders; its parameters run over [0, m] x [0, n] in the chart's cell grid. Border curves are
// fitted once per border line and imposed as the boundary poles of every surface that touches
// them, so neighbours share their borders exactly; the interior poles are a least-squares fit to
// limit samples. Where the limit surface lies in that spline space (regular faces, regular
// creases and boundaries) the fit reproduces it to rounding. Optionally (tangentContinuity) the
// pole rows next to the smooth borders are then turned so that neighbours share their tangent
// planes (chart_continuity.h).
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
  // Neighbouring charts share their tangent planes along smooth borders (chart_continuity.h): on
  // the refined cube, the sphere fit and the M6 fit at level 3 within 0.1 degree except next to
  // corners (see maxKinkDegrees), at the same pole count. It costs accuracy next to extraordinary
  // vertices, at second order: the cube's charts at levels 1 / 4 / 6 deviate 9.2 / 4.0 / 1.4
  // times as much from the limit surface, the M6's at level 3 are 3.6e-3 mm from it instead of
  // 1.1e-3 mm. Off by default: the deviation's convergence order (log2(1 / lambda_3)) shows only
  // from level 6 on.
  bool tangentContinuity = false;
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
  // borders at the check points, in degrees, except within the span next to a corner, a cone
  // point of the limit surface without a tangent plane (there the charts' normals, continuous up
  // to their corners, differ by the cone's angles: 4.3 degrees at the M6's trailing-edge tip).
  // 0 where the limit surface is regular. Near extraordinary vertices the surfaces meet with C0
  // only, and the kink shrinks under subdivision (cube levels 1 / 4 / 6: 4.0 / 0.32 / 0.052
  // degrees); with tangentContinuity they share their tangent planes to below 0.1 degree (cube
  // 0.005-0.046, sphere fit at level 4 0.017, M6 at level 3 0.072 outside 2 mm of the trailing
  // edge's tip corners, where four of them lie 0.3-2.6 mm apart, and 0.61 inside).
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

// Internals of Target shared by its construction (target.cpp) and its projections
// (projection_steps.h): per-face and per-edge geometry extracted once, the tessellation with its
// spatial index, the trim test (trim_classifier.cpp) and the per-thread evaluation context
// (face_evaluation.cpp).
#pragma once

#include <GeomAdaptor_Curve.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom_Curve.hxx>
#include <Geom_Surface.hxx>
#include <TopoDS_Face.hxx>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "core/target/aabb_tree.h"
#include "core/target/target.h"

namespace bvmesh::target {

// One use of an edge in a face's boundary; a seam edge appears twice with its two pcurves.
struct FaceEdgeUse {
  int edge = 0;
  Handle(Geom2d_Curve) pcurve;
};

// Trim test of one face in its parameter plane: the boundary pcurves as a dense polygon (within
// a 1e-8 fraction of the parameter box), and a grid whose cells away from the polygon are known
// to be inside or outside. A point in a cell the polygon crosses is classified by the crossings
// of a ray along u or v (whichever reaches a known cell first, or the box's end: outside) up to
// that cell: only the few segments listed in the cells in between are tested. Immutable after
// construction: shared by all threads.
class TrimClassifier {
public:
  TrimClassifier() = default;
  // uvBox: u0, u1, v0, v1 of the face; loops: polylines of its boundary pcurves.
  TrimClassifier(double u0, double u1, double v0, double v1, const std::vector<std::vector<Eigen::Vector2d>>& curves);
  bool inside(double u, double v) const;

private:
  enum Cell : std::uint8_t { Outside = 0, Inside = 1, Boundary = 2, Unknown = 3 };
  // Cell index of coordinate x along the grid's axis 0 (u) or 1 (v), clamped to the grid.
  int index(double x, int axis) const;
  // Whether an odd number of segments cross the ray from p along +axis (direction +1) or -axis
  // (-1) within `steps` cells from p's own.
  bool oddCrossings(const Eigen::Vector2d& p, int axis, int direction, int steps) const;

  static constexpr int kSize = 64;
  bool everywhere_ = true;  // a face without boundary curves
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d step_ = Eigen::Vector2d::Ones();  // cell size along u and v
  std::vector<std::uint8_t> cells_;        // kSize x kSize, v outer
  std::vector<Eigen::Vector4d> segments_;  // (ua, va, ub, vb)
  // Segments whose bounding box overlaps each cell: cellSegments_[cellStart_[c] .. cellStart_[c + 1]).
  std::vector<int> cellStart_;
  std::vector<int> cellSegments_;
};

// A polynomial (non-rational, non-periodic) B-spline surface as one polynomial per knot span,
// in powers of the span's local parameters scaled to [0, 1] (Taylor coefficients at the span's
// corner, from OCCT's derivatives of that span). Built once and shared by all threads; an
// evaluation with second derivatives costs about a third of GeomAdaptor_Surface's cached one.
class SpanPolynomials {
public:
  SpanPolynomials() = default;
  explicit SpanPolynomials(const Geom_BSplineSurface& surface);
  bool empty() const { return coefficients_.empty(); }
  void D2(double u, double v, gp_Pnt& p, gp_Vec& su, gp_Vec& sv, gp_Vec& suu, gp_Vec& svv, gp_Vec& suv) const;

private:
  int uDegree_ = 0, vDegree_ = 0;
  std::vector<double> uBreaks_, vBreaks_;  // distinct knots
  // Per span (u outer): (uDegree + 1) x (vDegree + 1) coefficients (u power outer) x 3.
  std::vector<double> coefficients_;
};

struct FaceData {
  TopoDS_Face face;
  Handle(Geom_Surface) surface;  // with the face's location applied
  // Distinct knots of a B-spline surface (empty for other surfaces): they delimit the spans
  // whose polynomial form an adaptor caches.
  std::vector<double> uKnots, vKnots;
  bool reversed = false;         // normals flip: the face is reversed relative to its surface
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;  // parameter box of the trimmed face
  // Newton stays inside the surface's own domain (infinite for planes, unbounded when periodic).
  double uMin = 0, uMax = 0, vMin = 0, vMax = 0;
  bool uPeriodic = false, vPeriodic = false;
  double uPeriod = 0, vPeriod = 0;
  std::vector<FaceEdgeUse> edges;                        // non-degenerate boundary edges
  TrimClassifier trim;
  SpanPolynomials polynomials;  // polynomial B-spline surfaces only (else empty)
};

struct EdgeData {
  Handle(Geom_Curve) curve;  // with the edge's location applied; null when degenerate
  double first = 0, last = 0;
  bool degenerate = false;
  double tolerance = 0;  // OCCT's tolerance of the edge: how far its faces and curves may be apart
  int vertex0 = -1, vertex1 = -1;
  std::vector<int> faces;
  // Polyline within the tessellation deflection of the curve: seeds for Newton.
  std::vector<Eigen::Vector3d> polyline;
  std::vector<double> polyParams;
  Box3 box;  // of the polyline, grown by the margin: no point of the edge lies outside
};

// A located point on the target.
struct Foot {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double distance = -1.0;  // < 0: none
  int face = -1;           // face whose (u, v) are given
  double u = 0, v = 0;
  int edge = -1;           // edge and curve parameter when the foot lies on an edge
  double t = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // the face's unit normal if known, else 0
  ProjectionStatus status = ProjectionStatus::Failed;
};

class ThreadContext;

struct Target::Data {
  TargetOptions options;
  TopoDS_Shape shape;
  TargetReport report;
  double diagonal = 0;
  double deflection = 0;
  double tolerance = 0;
  double margin = 0;         // how far the surface may lie from its tessellation (with safety)
  double convergence = 0;    // Newton stops when a step moves the point less than this

  std::vector<FaceData> faces;
  std::vector<EdgeData> edges;
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::vector<int>> vertexFaces;

  Points nodes;                                                // #N x 3
  Params nodeUV;                                               // #N x 2 (u, v) on the node's face
  Eigen::VectorXd nodeTolerance;                               // #N, see Target::meshNodeTolerances
  Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> triangles;  // #T x 3
  Eigen::VectorXi triangleFaces;                               // #T
  std::vector<double> triangleSize;                            // #T longest edge length
  AabbTree tree;

  // Evaluation contexts kept between calls, so that each worker thread reuses the surface
  // adaptors (and their span caches) built by earlier calls.
  std::unique_ptr<ThreadContext> acquireContext() const;
  void releaseContext(std::unique_ptr<ThreadContext> context) const;
  mutable std::mutex poolMutex;
  mutable std::vector<std::unique_ptr<ThreadContext>> pool;
};

// Evaluation of one face's surface by one thread: through the face's span polynomials where it
// has them, else GeomAdaptor_Surface. GeomAdaptor_Surface converts the B-spline span of (u, v)
// to polynomial form and keeps that one span; the evaluations for one point (Newton steps,
// seeds from several triangles) move back and forth between neighbouring spans, and each change
// rebuilds the cache, which costs more than an evaluation. So a (rational or periodic) B-spline
// face has up to kSlots adaptors, each keeping the span it last evaluated: evaluations go to the
// adaptor holding their span, a new span replaces the least recently used one (16 slots: 4
// rebuilt about one cache per M6 point).
class FaceSurface {
public:
  explicit FaceSurface(const FaceData& face) : face_(face) { spans_.fill(-1); }
  void D1(double u, double v, gp_Pnt& p, gp_Vec& su, gp_Vec& sv) {
    if (face_.polynomials.empty()) {
      adaptor(u, v).D1(u, v, p, su, sv);
    } else {
      gp_Vec suu, svv, suv;
      face_.polynomials.D2(u, v, p, su, sv, suu, svv, suv);
    }
  }
  void D2(double u, double v, gp_Pnt& p, gp_Vec& su, gp_Vec& sv, gp_Vec& suu, gp_Vec& svv, gp_Vec& suv) {
    if (face_.polynomials.empty()) adaptor(u, v).D2(u, v, p, su, sv, suu, svv, suv);
    else face_.polynomials.D2(u, v, p, su, sv, suu, svv, suv);
  }

private:
  static constexpr int kSlots = 16;
  GeomAdaptor_Surface& adaptor(double u, double v);
  const FaceData& face_;
  std::array<std::unique_ptr<GeomAdaptor_Surface>, kSlots> adaptors_;
  std::array<std::int64_t, kSlots> spans_;
  std::array<std::uint64_t, kSlots> used_{};
  std::uint64_t clock_ = 0;
};

// Per-thread evaluation state: each thread has its own face surfaces and edge curve adaptors
// (created on first use; a curve adaptor caches the polynomial form of the B-spline span it last
// evaluated, which Geom_BSplineCurve does not).
class ThreadContext {
public:
  explicit ThreadContext(const Target::Data& data)
      : data_(data), surfaces_(data.faces.size()), curves_(data.edges.size()) {}
  FaceSurface& surface(int face);
  // The 3D curve of a non-degenerate edge.
  GeomAdaptor_Curve& curve(int edge);
  // Whether (u, v) lies inside the face's trim.
  bool inside(int face, double u, double v) const { return data_.faces[static_cast<std::size_t>(face)].trim.inside(u, v); }

  struct Candidate {
    int triangle;
    double distance;
    Eigen::Vector3d point;
    double u, v;
  };
  struct Anchor {
    int face;
    Eigen::Vector3d point;
  };
  std::vector<Candidate> candidates;
  std::vector<Anchor> anchors;

private:
  const Target::Data& data_;
  std::vector<std::unique_ptr<FaceSurface>> surfaces_;
  std::vector<std::unique_ptr<GeomAdaptor_Curve>> curves_;
};

// Geometry kernels used by both construction and projection.
Eigen::Vector3d toEigen(const gp_Pnt& p);
Eigen::Vector3d toEigen(const gp_Vec& v);
// Unit normal of the face at (u, v) (orientation applied); zero where it is undefined.
Eigen::Vector3d faceNormal(const FaceData& face, FaceSurface& surface, double u, double v);
// Unit normal from the derivatives at a point (orientation applied); zero where |Su x Sv| is
// at most relativeTolerance (|Su| + |Sv|) (a pole: faceNormal then looks next to it).
Eigen::Vector3d unitNormal(const FaceData& face, const gp_Vec& su, const gp_Vec& sv, double relativeTolerance);
// Closest point on one edge (the nearest local minima of the polyline distance are refined).
// bound: a distance the foot must beat (< 0: none); no foot when no part of the edge can.
Foot closestOnEdge(const Target::Data& data, ThreadContext& context, int edge, const Eigen::Vector3d& q, double bound);

}  // namespace bvmesh::target

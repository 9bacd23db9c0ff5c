// Points of the Catmull-Clark limit surface of an all-quad control mesh at (face, u, v).
// The B-spline conversion takes the evaluator as a callback, so any exact evaluator (e.g. the
// shared one of the subdivision area) can replace the OpenSubdiv-based one below.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "core/surface/quad_charts.h"

namespace bvmesh::surface {

// A point on the limit surface: face id and the face's own parameters, (0, 0) at its vertex 0,
// (1, 0) at vertex 1, (1, 1) at vertex 2, (0, 1) at vertex 3 (OpenSubdiv's quad parametrization).
struct FaceLocation {
  int face = 0;
  double u = 0.0;
  double v = 0.0;
};

// Fills `points` (resized to #locations x 3) with limit points.
using LimitEvaluator = std::function<void(const std::vector<FaceLocation>& locations, RowMatrixX3d& points)>;

struct SubdivisionLimitOptions {
  // Adaptive isolation depth around extraordinary and irregular features; beyond it OpenSubdiv
  // closes the surface with Gregory patches (deviation from the exact limit shrinks ~8x per level).
  int maxIsolationLevel = 8;
};

// Catmull-Clark limit surface (Catmark, VTX_BOUNDARY_EDGE_AND_CORNER, uniform crease method,
// infinitely sharp creases and corners) evaluated with OpenSubdiv's adaptive patch table in double
// precision. Regular faces, also along regular creases and boundaries, are exact bicubic patches.
// Installs (once per process) an OpenSubdiv error callback that throws SolverError.
class SubdivisionLimitSurface {
 public:
  explicit SubdivisionLimitSurface(const QuadControlMesh& mesh, const SubdivisionLimitOptions& options = {});
  ~SubdivisionLimitSurface();
  SubdivisionLimitSurface(const SubdivisionLimitSurface&) = delete;
  SubdivisionLimitSurface& operator=(const SubdivisionLimitSurface&) = delete;

  void evaluate(const std::vector<FaceLocation>& locations, RowMatrixX3d& points) const;
  // Also the first derivatives with respect to the face's u and v (each #locations x 3).
  void evaluate(const std::vector<FaceLocation>& locations, RowMatrixX3d& points, RowMatrixX3d& du,
                RowMatrixX3d& dv) const;
  // A callback bound to this object (which must outlive it).
  LimitEvaluator evaluator() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bvmesh::surface

// Building OCCT B-spline surfaces and faces from plain arrays, the form in which the core's
// results (limit surfaces, block faces) leave it.
#pragma once

#include <Geom_BSplineSurface.hxx>
#include <TopoDS_Face.hxx>

#include <vector>

namespace bvmesh::cad {

// A tensor-product B-spline surface in OCCT's knot/multiplicity form.
struct BSplineSurfaceData {
  int uDegree = 3;
  int vDegree = 3;
  int uPoleCount = 0;              // poles along u
  int vPoleCount = 0;              // poles along v
  std::vector<double> poles;       // uPoleCount x vPoleCount x 3, v fastest: pole (i, j) at 3*(i*vPoleCount + j)
  std::vector<double> weights;     // empty (polynomial) or uPoleCount x vPoleCount, v fastest
  std::vector<double> uKnots;      // distinct, increasing
  std::vector<double> vKnots;
  std::vector<int> uMultiplicities;
  std::vector<int> vMultiplicities;
};

// Checks the data (degrees, counts, multiplicities, monotone knots, finite values) and builds the
// surface. Throws InvalidInputError naming what is inconsistent.
Handle(Geom_BSplineSurface) makeBSplineSurface(const BSplineSurfaceData& data);

// A face bounded by the surface's natural boundary; valid per BRepCheck or SolverError.
TopoDS_Face makeBSplineFace(const BSplineSurfaceData& data);

}  // namespace bvmesh::cad

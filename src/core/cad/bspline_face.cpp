#include "core/cad/bspline_face.h"

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <Precision.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>

#include <cmath>
#include <numeric>
#include <string>

#include "core/common/errors.h"
#include "core/common/occt_errors.h"

namespace bvmesh::cad {
namespace {

// One parametric direction's knot vector must describe exactly `poleCount` poles of `degree`.
void checkDirection(const char* name, int degree, int poleCount, const std::vector<double>& knots,
                    const std::vector<int>& multiplicities) {
  const std::string direction(name);
  if (degree < 1 || degree > Geom_BSplineSurface::MaxDegree()) {
    throw InvalidInputError(direction + " degree " + std::to_string(degree) + " is outside 1.." +
                            std::to_string(Geom_BSplineSurface::MaxDegree()));
  }
  if (poleCount < degree + 1) {
    throw InvalidInputError(direction + ": " + std::to_string(poleCount) + " poles are too few for degree " +
                            std::to_string(degree) + " (need at least degree + 1)");
  }
  if (knots.size() < 2 || knots.size() != multiplicities.size()) {
    throw InvalidInputError(direction + ": need at least 2 distinct knots and one multiplicity per knot (got " +
                            std::to_string(knots.size()) + " knots, " +
                            std::to_string(multiplicities.size()) + " multiplicities)");
  }
  for (size_t k = 0; k < knots.size(); ++k) {
    if (!std::isfinite(knots[k])) throw InvalidInputError(direction + " knot " + std::to_string(k) + " is not finite");
    if (k > 0 && !(knots[k] > knots[k - 1] + Precision::PConfusion())) {
      throw InvalidInputError(direction + " knots must increase strictly; knot " + std::to_string(k) +
                              " does not");
    }
    const bool endKnot = (k == 0 || k + 1 == knots.size());
    const int maxMultiplicity = endKnot ? degree + 1 : degree;
    if (multiplicities[k] < 1 || multiplicities[k] > maxMultiplicity) {
      throw InvalidInputError(direction + " multiplicity " + std::to_string(multiplicities[k]) + " of knot " +
                              std::to_string(k) + " is outside 1.." + std::to_string(maxMultiplicity));
    }
  }
  const int sum = std::accumulate(multiplicities.begin(), multiplicities.end(), 0);
  if (sum != poleCount + degree + 1) {
    throw InvalidInputError(direction + ": multiplicities add up to " + std::to_string(sum) + " but " +
                            std::to_string(poleCount) + " poles of degree " + std::to_string(degree) +
                            " need " + std::to_string(poleCount + degree + 1));
  }
}

TColStd_Array1OfReal toOcctReals(const std::vector<double>& values) {
  TColStd_Array1OfReal array(1, static_cast<int>(values.size()));
  for (size_t i = 0; i < values.size(); ++i) array(static_cast<int>(i) + 1) = values[i];
  return array;
}

TColStd_Array1OfInteger toOcctIntegers(const std::vector<int>& values) {
  TColStd_Array1OfInteger array(1, static_cast<int>(values.size()));
  for (size_t i = 0; i < values.size(); ++i) array(static_cast<int>(i) + 1) = values[i];
  return array;
}

}  // namespace

Handle(Geom_BSplineSurface) makeBSplineSurface(const BSplineSurfaceData& data) {
  checkDirection("u", data.uDegree, data.uPoleCount, data.uKnots, data.uMultiplicities);
  checkDirection("v", data.vDegree, data.vPoleCount, data.vKnots, data.vMultiplicities);
  const size_t poleCount = static_cast<size_t>(data.uPoleCount) * static_cast<size_t>(data.vPoleCount);
  if (data.poles.size() != 3 * poleCount) {
    throw InvalidInputError("poles hold " + std::to_string(data.poles.size()) + " values; " +
                            std::to_string(data.uPoleCount) + " x " + std::to_string(data.vPoleCount) +
                            " poles need " + std::to_string(3 * poleCount));
  }
  if (!data.weights.empty() && data.weights.size() != poleCount) {
    throw InvalidInputError("weights hold " + std::to_string(data.weights.size()) + " values; expected " +
                            std::to_string(poleCount) + " (one per pole) or none");
  }
  for (size_t i = 0; i < data.poles.size(); ++i) {
    if (!std::isfinite(data.poles[i])) {
      throw InvalidInputError("pole " + std::to_string(i / 3) + " has a non-finite coordinate");
    }
  }
  for (size_t i = 0; i < data.weights.size(); ++i) {
    if (!(data.weights[i] > 0.0) || !std::isfinite(data.weights[i])) {
      throw InvalidInputError("weight " + std::to_string(i) + " must be positive and finite");
    }
  }

  return translateOcctErrors("building a B-spline surface", [&] {
    TColgp_Array2OfPnt poles(1, data.uPoleCount, 1, data.vPoleCount);
    TColStd_Array2OfReal weights(1, data.uPoleCount, 1, data.vPoleCount);
    for (int i = 0; i < data.uPoleCount; ++i) {
      for (int j = 0; j < data.vPoleCount; ++j) {
        const size_t k = static_cast<size_t>(i) * static_cast<size_t>(data.vPoleCount) + static_cast<size_t>(j);
        poles(i + 1, j + 1) = gp_Pnt(data.poles[3 * k], data.poles[3 * k + 1], data.poles[3 * k + 2]);
        weights(i + 1, j + 1) = data.weights.empty() ? 1.0 : data.weights[k];
      }
    }
    return Handle(Geom_BSplineSurface)(new Geom_BSplineSurface(
        poles, weights, toOcctReals(data.uKnots), toOcctReals(data.vKnots),
        toOcctIntegers(data.uMultiplicities), toOcctIntegers(data.vMultiplicities), data.uDegree,
        data.vDegree));
  });
}

TopoDS_Face makeBSplineFace(const BSplineSurfaceData& data) {
  Handle(Geom_BSplineSurface) surface = makeBSplineSurface(data);
  return translateOcctErrors("building a B-spline face", [&] {
    BRepBuilderAPI_MakeFace maker(surface, Precision::Confusion());
    if (!maker.IsDone()) throw SolverError("OpenCASCADE could not build a face on the B-spline surface");
    TopoDS_Face face = maker.Face();
    if (!BRepCheck_Analyzer(face).IsValid()) {
      throw SolverError("the B-spline face built from the given poles is not valid (BRepCheck)");
    }
    return face;
  });
}

}  // namespace bvmesh::cad

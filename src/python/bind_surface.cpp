// The limit surface of a quad control mesh as B-spline surfaces: charts, poles and knots as
// numpy arrays, the sewn shell or solid as BREP text.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>

#include "arrays.h"
#include "bindings.h"
#include "core/cad/shape_io.h"
#include "core/surface/limit_bsplines.h"

namespace py = pybind11;

namespace bvmesh::python {
namespace {

using surface::BorderKind;
using surface::ChartSide;

// An integer array of shape (rows, columns); `columns` < 0 means one-dimensional.
py::array_t<int, py::array::c_style | py::array::forcecast> integerArray(const py::object& object,
                                                                         const char* name,
                                                                         py::ssize_t columns,
                                                                         const char* what) {
  const py::array array = py::array::ensure(object);
  if (!array) throw py::value_error(std::string(name) + " must be an array of shape " + what);
  const bool empty = array.size() == 0;
  if (!empty && array.dtype().kind() != 'i' && array.dtype().kind() != 'u') {
    throw py::value_error(std::string(name) + " must hold integers (vertex ids), got dtype " +
                          std::string(py::str(array.dtype())));
  }
  const bool shapeOk = columns < 0
                           ? array.ndim() == 1
                           : (array.ndim() == 2 && array.shape(1) == columns) || (empty && array.ndim() <= 2);
  if (!shapeOk) {
    throw py::value_error(std::string(name) + " must have shape " + what + ", got " + shapeText(array));
  }
  auto result = py::array_t<int, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!result) throw py::value_error(std::string(name) + " could not be read as integers");
  return result;
}

surface::QuadControlMesh meshFromArrays(const py::object& vertices, const py::object& faces,
                                        const py::object& creases, const py::object& corners) {
  auto points = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(vertices);
  if (!points || points.ndim() != 2 || points.shape(1) != 3) {
    throw py::value_error("vertices must have shape (#V, 3), got " +
                          (points ? shapeText(points) : std::string("a non-numeric object")));
  }
  const py::array faceObject = py::array::ensure(faces);
  if (faceObject && faceObject.ndim() == 2 && faceObject.shape(1) != 4) {
    throw py::value_error("faces must be quads, shape (#F, 4); got " + std::to_string(faceObject.shape(1)) +
                          " vertices per face");
  }
  if (faceObject && faceObject.dtype().kind() == 'O') {
    throw py::value_error("faces must be quads, shape (#F, 4); got faces of different sizes");
  }
  const auto faceArray = integerArray(faces, "faces", 4, "(#F, 4), quads only");
  surface::QuadControlMesh mesh;
  mesh.vertices.resize(points.shape(0), 3);
  std::copy(points.data(), points.data() + points.size(), mesh.vertices.data());
  mesh.faces.resize(faceArray.shape(0), 4);
  std::copy(faceArray.data(), faceArray.data() + faceArray.size(), mesh.faces.data());
  if (!creases.is_none()) {
    const auto creaseArray = integerArray(creases, "creases", 2, "(#C, 2)");
    mesh.creases.resize(creaseArray.size() / 2, 2);
    std::copy(creaseArray.data(), creaseArray.data() + creaseArray.size(), mesh.creases.data());
  }
  if (!corners.is_none()) {
    const auto cornerArray = integerArray(corners, "corners", -1, "(#corners,)");
    mesh.corners.assign(cornerArray.data(), cornerArray.data() + cornerArray.size());
  }
  return mesh;
}

const char* sideName(ChartSide side) {
  switch (side) {
    case ChartSide::VMin:
      return "v_min";
    case ChartSide::UMax:
      return "u_max";
    case ChartSide::VMax:
      return "v_max";
    case ChartSide::UMin:
      return "u_min";
  }
  return "";
}

const char* kindName(BorderKind kind) {
  switch (kind) {
    case BorderKind::Boundary:
      return "boundary";
    case BorderKind::Crease:
      return "crease";
    case BorderKind::Separatrix:
      return "separatrix";
  }
  return "";
}

py::array_t<int> gridArray(const std::vector<int>& values, py::ssize_t rows, py::ssize_t columns) {
  py::array_t<int> array({rows, columns});
  std::copy(values.begin(), values.end(), array.mutable_data());
  return array;
}

py::array_t<double> polesArray(const std::vector<double>& poles, py::ssize_t rows, py::ssize_t columns) {
  py::array_t<double> array(columns > 0 ? std::vector<py::ssize_t>{rows, columns, 3}
                                        : std::vector<py::ssize_t>{rows, 3});
  std::copy(poles.begin(), poles.end(), array.mutable_data());
  return array;
}

py::dict resultToDict(const surface::LimitBSplines& result, const surface::SewnShape* sewn,
                      const std::string& brep) {
  py::list charts;
  double maxDeviation = 0.0, maxDistance = 0.0;
  for (size_t c = 0; c < result.layout.charts.size(); ++c) {
    const surface::QuadChart& chart = result.layout.charts[c];
    const cad::BSplineSurfaceData& data = result.surfaces[c];
    py::dict item;
    item["u_cells"] = chart.uCells;
    item["v_cells"] = chart.vCells;
    item["faces"] = gridArray(chart.faces, chart.uCells, chart.vCells);
    item["rotations"] = gridArray(chart.rotations, chart.uCells, chart.vCells);
    item["vertices"] = gridArray(chart.vertices, chart.uCells + 1, chart.vCells + 1);
    py::dict sides;
    for (ChartSide side : {ChartSide::VMin, ChartSide::UMax, ChartSide::VMax, ChartSide::UMin}) {
      sides[sideName(side)] = chart.sideSegments[static_cast<size_t>(side)];
    }
    item["side_segments"] = sides;
    item["u_degree"] = data.uDegree;
    item["v_degree"] = data.vDegree;
    item["poles"] = polesArray(data.poles, data.uPoleCount, data.vPoleCount);
    item["u_knots"] = data.uKnots;
    item["v_knots"] = data.vKnots;
    item["u_multiplicities"] = data.uMultiplicities;
    item["v_multiplicities"] = data.vMultiplicities;
    item["max_deviation"] = result.maxDeviation[c];
    item["max_distance"] = result.maxDistance[c];
    maxDeviation = std::max(maxDeviation, result.maxDeviation[c]);
    maxDistance = std::max(maxDistance, result.maxDistance[c]);
    charts.append(item);
  }
  py::list segments;
  for (size_t s = 0; s < result.layout.segments.size(); ++s) {
    const surface::BorderSegment& segment = result.layout.segments[s];
    const surface::BSplineCurveData& curve = result.segmentCurves[s];
    py::dict item;
    item["vertices"] = segment.vertices;
    item["kind"] = kindName(segment.kind);
    py::list uses;
    for (const surface::SegmentUse& use : segment.uses) {
      uses.append(py::make_tuple(use.chart, sideName(use.side), use.first, use.reversed));
    }
    item["uses"] = uses;
    item["poles"] = polesArray(curve.poles, static_cast<py::ssize_t>(curve.poles.size() / 3), 0);
    item["knots"] = curve.knots;
    item["multiplicities"] = curve.multiplicities;
    segments.append(item);
  }
  py::dict out;
  out["charts"] = charts;
  out["segments"] = segments;
  out["junctions"] = result.layout.junctions;
  out["nodes"] = result.layout.nodes;
  out["face_chart"] = py::array_t<int>(static_cast<py::ssize_t>(result.layout.faceChart.size()),
                                       result.layout.faceChart.data());
  out["max_deviation"] = maxDeviation;
  out["max_distance"] = maxDistance;
  out["max_border_gap"] = result.maxBorderGap;
  out["max_kink_degrees"] = result.maxKinkDegrees;
  if (sewn != nullptr) {
    out["brep"] = brep;
    out["solid"] = sewn->solid;
    out["free_edges"] = sewn->freeEdges;
    out["sewing_tolerance"] = sewn->tolerance;
    out["max_edge_tolerance"] = sewn->maxEdgeTolerance;
    out["valid"] = sewn->valid;
  }
  return out;
}

// The conversion and, with `sew`, the sewn shape, without the GIL.
py::dict convert(const surface::QuadControlMesh& mesh, int samplesPerSpan, int checkSamplesPerSpan,
                 int isolationLevel, bool tangentContinuity, bool sew, double sewingTolerance, bool makeSolid) {
  surface::LimitBSplineOptions options;
  options.samplesPerSpan = samplesPerSpan;
  options.checkSamplesPerSpan = checkSamplesPerSpan;
  options.isolationLevel = isolationLevel;
  options.tangentContinuity = tangentContinuity;
  surface::SewingOptions sewing;
  sewing.relativeTolerance = sewingTolerance;
  sewing.makeSolid = makeSolid;
  surface::LimitBSplines result;
  surface::SewnShape sewn;
  std::string brep;
  {
    py::gil_scoped_release release;
    result = surface::limitSurfaceToBSplines(mesh, options);
    if (sew) {
      sewn = surface::sewBSplineSurfaces(result.surfaces, sewing);
      brep = cad::writeBrepString(sewn.shape);
    }
  }
  return resultToDict(result, sew ? &sewn : nullptr, brep);
}

}  // namespace

void bindSurface(py::module_& module) {
  // The ControlMesh overload comes first: numpy arrays fail its argument conversion and fall
  // through to the array overload.
  module.def(
      "limit_surface_to_bsplines",
      [](const ControlMesh& mesh, int samplesPerSpan, int checkSamplesPerSpan, int isolationLevel,
         bool tangentContinuity, bool sew, double sewingTolerance, bool makeSolid) {
        return convert(surface::toQuadControlMesh(mesh), samplesPerSpan, checkSamplesPerSpan, isolationLevel,
                       tangentContinuity, sew, sewingTolerance, makeSolid);
      },
      py::arg("control_mesh"), py::arg("samples_per_span") = 4, py::arg("check_samples_per_span") = 9,
      py::arg("isolation_level") = 8, py::arg("tangent_continuity") = false, py::arg("sew") = true,
      py::arg("sewing_tolerance") = 1e-7, py::arg("make_solid") = true,
      "Like the array form below, for a bvmesh.ControlMesh that is all quads with infinitely sharp "
      "creases and corners (e.g. a fitted control mesh).");
  module.def(
      "limit_surface_to_bsplines",
      [](const py::object& vertices, const py::object& faces, const py::object& creases,
         const py::object& corners, int samplesPerSpan, int checkSamplesPerSpan, int isolationLevel,
         bool tangentContinuity, bool sew, double sewingTolerance, bool makeSolid) {
        return convert(meshFromArrays(vertices, faces, creases, corners), samplesPerSpan, checkSamplesPerSpan,
                       isolationLevel, tangentContinuity, sew, sewingTolerance, makeSolid);
      },
      py::arg("vertices"), py::arg("faces"), py::arg("creases") = py::none(), py::arg("corners") = py::none(),
      py::arg("samples_per_span") = 4, py::arg("check_samples_per_span") = 9, py::arg("isolation_level") = 8,
      py::arg("tangent_continuity") = false, py::arg("sew") = true, py::arg("sewing_tolerance") = 1e-7,
      py::arg("make_solid") = true,
      R"doc(Converts the Catmull-Clark limit surface of an all-quad control mesh to bicubic B-spline surfaces.

vertices: (#V, 3) float; faces: (#F, 4) int, counter-clockwise; creases: (#C, 2) int vertex pairs of
infinitely sharp crease edges; corners: (#K,) int sharp corner vertices. Boundaries act as creases.
tangent_continuity: neighbouring charts share their tangent planes along smooth borders (to below
0.1 degree away from corners), at some cost in distance next to extraordinary vertices (see
LimitBSplineOptions in limit_bsplines.h).

Returns a dict: 'charts' (per chart: 'faces', 'vertices', 'rotations', 'poles' (n_u, n_v, 3),
'u_knots', 'v_knots', 'u_multiplicities', 'v_multiplicities', 'max_deviation', 'max_distance',
'side_segments'), 'segments' (shared border curves: 'vertices', 'kind', 'uses', 'poles', 'knots',
'multiplicities'), 'max_deviation' (largest |chart(s, t) - limit(s, t)| at check_samples_per_span^2
points per face: the parametric deviation, a bound of the distance), 'max_distance' (largest
component of that along the limit normal: the distance between the surfaces to first order),
'max_border_gap', 'max_kink_degrees' (largest normal jump across smooth borders, degrees, except
in the spans next to corners), 'junctions', 'nodes', 'face_chart' (#F,), and with sew=True:
'brep' (the sewn shell or solid as BREP text), 'solid', 'free_edges', 'sewing_tolerance' (absolute:
the sewing_tolerance argument times the bounding-box diagonal), 'max_edge_tolerance', 'valid'.)doc");
}

}  // namespace bvmesh::python

// CAD shapes cross the binding as BREP text (FreeCAD: Shape.exportBrepToString() and
// Part.Shape().importBrepFromString()), so no OCCT object is shared between the two processes'
// copies of the library.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>

#include "bindings.h"
#include "conversions.h"
#include "core/cad/bspline_face.h"
#include "core/cad/isolated_reader.h"
#include "core/cad/shape_io.h"
#include "core/cad/shape_summary.h"

namespace py = pybind11;

namespace bvmesh::python {
namespace {

cad::ShapeSummaryOptions summaryOptions(double sharpAngleDegrees) {
  cad::ShapeSummaryOptions options;
  options.sharpAngleDegrees = sharpAngleDegrees;
  return options;
}

// (n x m x 3) poles and optional (n x m) weights, checked here so the message names the argument.
cad::BSplineSurfaceData surfaceData(const py::array_t<double, py::array::c_style | py::array::forcecast>& poles,
                                    int uDegree, int vDegree, std::vector<double> uKnots,
                                    std::vector<double> vKnots, std::vector<int> uMultiplicities,
                                    std::vector<int> vMultiplicities, const py::object& weights) {
  if (poles.ndim() != 3 || poles.shape(2) != 3) {
    throw py::value_error("poles must have shape (n_u, n_v, 3)");
  }
  cad::BSplineSurfaceData data;
  data.uDegree = uDegree;
  data.vDegree = vDegree;
  data.uPoleCount = static_cast<int>(poles.shape(0));
  data.vPoleCount = static_cast<int>(poles.shape(1));
  data.poles.assign(poles.data(), poles.data() + poles.size());
  if (!weights.is_none()) {
    auto weightArray = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(weights);
    if (!weightArray || weightArray.ndim() != 2 || weightArray.shape(0) != poles.shape(0) ||
        weightArray.shape(1) != poles.shape(1)) {
      throw py::value_error("weights must have shape (n_u, n_v), the first two dimensions of poles");
    }
    data.weights.assign(weightArray.data(), weightArray.data() + weightArray.size());
  }
  data.uKnots = std::move(uKnots);
  data.vKnots = std::move(vKnots);
  data.uMultiplicities = std::move(uMultiplicities);
  data.vMultiplicities = std::move(vMultiplicities);
  return data;
}

}  // namespace

py::dict summaryToDict(const cad::ShapeSummary& summary) {
  py::list edges;
  for (const cad::EdgeInfo& edge : summary.edges) {
    py::dict item;
    item["kind"] = cad::edgeKindName(edge.kind);
    item["faces"] = edge.faces;
    item["max_dihedral_degrees"] = edge.maxDihedralDegrees;
    item["length"] = edge.length;
    edges.append(item);
  }
  py::dict result;
  result["solids"] = summary.solidCount;
  result["shells"] = summary.shellCount;
  result["faces"] = summary.faceCount();
  result["vertices"] = summary.vertexCount;
  result["surface_types"] = summary.faceSurfaceTypes;
  result["face_areas"] = summary.faceAreas;
  result["edges"] = edges;
  result["bounds"] = py::make_tuple(summary.boundsMin, summary.boundsMax);
  py::dict edgeCounts;
  for (cad::EdgeKind kind : {cad::EdgeKind::Smooth, cad::EdgeKind::Sharp, cad::EdgeKind::Free,
                             cad::EdgeKind::Seam, cad::EdgeKind::NonManifold, cad::EdgeKind::Degenerate}) {
    edgeCounts[cad::edgeKindName(kind)] = summary.countEdges(kind);
  }
  result["edge_counts"] = edgeCounts;
  return result;
}

void bindCad(py::module_& module) {
  module.def(
      "summarize_brep",
      [](const std::string& brep, double sharpAngleDegrees) {
        return summaryToDict(cad::summarizeShape(cad::readBrepStringSafely(brep), summaryOptions(sharpAngleDegrees)));
      },
      py::arg("brep"), py::arg("sharp_angle_degrees") = 30.0,
      "Faces, surface types, bounding box and classified edges of a shape given as BREP text.");
  module.def(
      "summarize_file",
      [](const std::filesystem::path& file, double sharpAngleDegrees) {
        const std::string path = file.string();
        return summaryToDict(cad::summarizeShape(cad::readShapeFileSafely(path), summaryOptions(sharpAngleDegrees)));
      },
      py::arg("path"), py::arg("sharp_angle_degrees") = 30.0,
      "Like summarize_brep, for a STEP, IGES or BREP file.");
  module.def(
      "read_cad_file_as_brep",
      [](const std::filesystem::path& file, double seconds, double megabytes) {
        const std::string path = file.string();
        py::gil_scoped_release release;
        return cad::readShapeFileIsolated(path, cad::ReaderLimits{seconds, megabytes});
      },
      py::arg("path"), py::arg("seconds") = cad::ReaderLimits{}.seconds,
      py::arg("megabytes") = cad::ReaderLimits{}.memoryMegabytes,
      "Reads a STEP, IGES or BREP file in a child process limited to `seconds` and `megabytes` (a corrupt "
      "file gives an error naming it, never a crash or a hang) and returns the shape as BREP text.");
  module.def(
      "check_brep_text",
      [](const std::string& brep, double seconds, double megabytes) {
        py::gil_scoped_release release;
        return cad::checkBrepStringIsolated(brep, cad::ReaderLimits{seconds, megabytes});
      },
      py::arg("brep"), py::arg("seconds") = 10.0, py::arg("megabytes") = cad::ReaderLimits{}.memoryMegabytes,
      "Parses BREP text in a child process under the limits and returns it as OpenCASCADE writes it back; "
      "what Target.from_brep and the other BREP-taking functions do first (their time limit: 10 s + 5 s per MB).");
  module.def(
      "bspline_face_brep",
      [](const py::array_t<double, py::array::c_style | py::array::forcecast>& poles, int uDegree, int vDegree,
         std::vector<double> uKnots, std::vector<double> vKnots, std::vector<int> uMultiplicities,
         std::vector<int> vMultiplicities, const py::object& weights) {
        return cad::writeBrepString(cad::makeBSplineFace(surfaceData(
            poles, uDegree, vDegree, std::move(uKnots), std::move(vKnots), std::move(uMultiplicities),
            std::move(vMultiplicities), weights)));
      },
      py::arg("poles"), py::arg("u_degree"), py::arg("v_degree"), py::arg("u_knots"), py::arg("v_knots"),
      py::arg("u_multiplicities"), py::arg("v_multiplicities"), py::arg("weights") = py::none(),
      "Builds a B-spline face (natural boundary) and returns it as BREP text.");
}

}  // namespace bvmesh::python

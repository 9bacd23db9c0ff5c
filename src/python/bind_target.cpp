// bvmesh.Target: the CAD target of the fitting iteration and its projections. Shapes arrive as
// BREP text (FreeCAD's Shape.exportBrepToString()) or as a STEP / IGES / BREP file path.
// Projection results are dicts of numpy arrays (see Target.project's docstring).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <string>

#include "arrays.h"
#include "bindings.h"
#include "conversions.h"
#include "core/cad/isolated_reader.h"
#include "core/cad/shape_io.h"
#include "core/common/errors.h"
#include "core/target/target.h"

namespace py = pybind11;

namespace bvmesh::python {
namespace {

using target::Points;
using target::ProjectionResult;
using target::Target;
using target::TargetOptions;
py::dict reportToDict(const target::TargetReport& report) {
  py::list gaps;
  for (const target::GapReport& gap : report.gaps)
    gaps.append(py::dict(py::arg("edge") = gap.edge, py::arg("other_edge") = gap.otherEdge, py::arg("width") = gap.width));
  py::dict dict = summaryToDict(report.shape);
  dict["diagonal"] = report.diagonal;
  dict["tolerance"] = report.tolerance;
  dict["deflection"] = report.deflection;
  dict["triangles"] = report.triangleCount;
  dict["sharp_edges"] = report.sharpEdges;
  dict["free_edges"] = report.freeEdges;
  dict["non_manifold_edges"] = report.nonManifoldEdges;
  dict["untessellated_faces"] = report.untessellatedFaces;
  dict["gaps"] = gaps;
  dict["repair"] = repairToDict(report.repair);
  return dict;
}

TargetOptions makeOptions(double relativeDeflection, double sharpAngleDeg, double relativeTolerance, int threads) {
  TargetOptions options;
  options.relativeDeflection = relativeDeflection;
  options.sharpAngleDeg = sharpAngleDeg;
  options.relativeTolerance = relativeTolerance;
  options.threads = threads;
  return options;
}

// Runs a projection without the GIL and converts its result with it.
template <class Work>
py::dict projectReleased(Work&& work) {
  ProjectionResult result;
  {
    py::gil_scoped_release release;
    result = work();
  }
  return projectionToDict(result);
}

// Building the index takes a while: without the GIL.
// The shape `read` gives (in a child process: slow, so without the GIL) made into a target.
template <class Read>
std::shared_ptr<Target> targetFrom(Read&& read, const TargetOptions& options) {
  py::gil_scoped_release release;
  return std::make_shared<Target>(read(), options);
}

constexpr const char* kResultDoc = R"(
Returns a dict of numpy arrays for the n points:
  points (n, 3) foot points; distances (n,); ids (n,) face / edge / vertex ids (-1: failed);
  faces (n,) face of params (-1: none); params (n, 2) (u, v) on faces[i], or (t, 0) on edge ids[i];
  normals (n, 3) unit normals (faces' orientation; bisector on edges; 0 if none);
  status (n,) uint8: 0 ok, 1 on trim boundary, 2 fallback, 3 failed (see ProjectionStatus).)";

}  // namespace

py::dict projectionToDict(const ProjectionResult& result) {
  py::array_t<std::uint8_t> status(static_cast<py::ssize_t>(result.status.size()));
  auto view = status.mutable_unchecked<1>();
  for (std::size_t i = 0; i < result.status.size(); ++i)
    view(static_cast<py::ssize_t>(i)) = static_cast<std::uint8_t>(result.status[i]);
  py::dict dict;
  dict["points"] = result.points;
  dict["distances"] = result.distances;
  dict["ids"] = result.ids;
  dict["faces"] = result.faces;
  dict["params"] = result.params;
  dict["normals"] = result.normals;
  dict["status"] = status;
  return dict;
}

void bindTarget(py::module_& module) {
  py::enum_<target::ProjectionStatus>(module, "ProjectionStatus", "Per-point outcome of a projection.")
      .value("OK", target::ProjectionStatus::Ok)
      .value("ON_TRIM_BOUNDARY", target::ProjectionStatus::OnTrimBoundary)
      .value("FALLBACK", target::ProjectionStatus::Fallback)
      .value("FAILED", target::ProjectionStatus::Failed);

  py::class_<Target, std::shared_ptr<Target>>(module, "Target",
                     "CAD target: trimmed faces, feature edges, vertices and a spatial index; projects "
                     "many points at once (closest point, onto edges / vertices, along directions).")
      .def_static(
          "from_brep",
          [](const std::string& brep, double relativeDeflection, double sharpAngleDeg, double relativeTolerance,
             int threads, bool sew, double sewTolerance) {
            return targetFrom([&] { return cad::readBrepStringRepaired(brep, cad::RepairOptions{sew, sewTolerance}); },
                              makeOptions(relativeDeflection, sharpAngleDeg, relativeTolerance, threads));
          },
          py::arg("brep"), py::arg("relative_deflection") = TargetOptions{}.relativeDeflection, py::arg("sharp_angle_deg") = TargetOptions{}.sharpAngleDeg,
          py::arg("relative_tolerance") = TargetOptions{}.relativeTolerance, py::arg("threads") = TargetOptions{}.threads,
          py::arg("sew") = true, py::arg("sew_tolerance") = 0.0,
          "Target from BREP text (FreeCAD: shape.exportBrepToString()), parsed first in a child process so "
          "that corrupt text cannot crash or hang the caller. Tolerances are relative to the bounding-box "
          "diagonal; threads=0 uses every hardware thread. sew: faces that share edges within sew_tolerance "
          "(absolute; 0: automatic) are sewn in that process first (report()['repair'] says what was done; a "
          "shape whose faces already share their edges is kept as it is, numbering included).")
      .def_static(
          "from_file",
          [](const std::filesystem::path& file, double relativeDeflection, double sharpAngleDeg, double relativeTolerance,
             int threads, bool sew, double sewTolerance) {
            return targetFrom([&] { return cad::readShapeFileRepaired(file.string(), cad::RepairOptions{sew, sewTolerance}); },
                              makeOptions(relativeDeflection, sharpAngleDeg, relativeTolerance, threads));
          },
          py::arg("path"), py::arg("relative_deflection") = TargetOptions{}.relativeDeflection, py::arg("sharp_angle_deg") = TargetOptions{}.sharpAngleDeg,
          py::arg("relative_tolerance") = TargetOptions{}.relativeTolerance, py::arg("threads") = TargetOptions{}.threads,
          py::arg("sew") = true, py::arg("sew_tolerance") = 0.0,
          "Target from a STEP (.step/.stp), IGES (.iges/.igs) or BREP (.brep/.brp) file, read in a child "
          "process under a time and memory limit (a corrupt file gives an error, never a crash or a hang). "
          "sew / sew_tolerance as for from_brep.")
      .def("report", [](const Target& self) { return reportToDict(self.report()); },
           "Faces, surface types, edges (kind, dihedral angle), sharp / free / non-manifold edges, "
           "gaps between faces wider than the tolerance, model size and tessellation; 'repair': what reading "
           "repaired (sewing, gaps closed and left open, watertight).")
      .def("sharp_edges", &Target::sharpEdges, py::arg("angle_deg") = 30.0,
           "Ids of edges between two faces whose normals meet at angle_deg or more.")
      .def("free_edges", &Target::freeEdges, "Ids of edges with one face (not seams).")
      .def_property_readonly("face_count", &Target::faceCount)
      .def_property_readonly("edge_count", &Target::edgeCount)
      .def_property_readonly("vertex_count", &Target::vertexCount)
      .def("vertex_position", &Target::vertexPosition, py::arg("vertex"))
      .def(
          "project",
          [](const Target& self, const py::object& points, const py::object& hintFaces, const py::object& hintUV) {
            const Points p = rowsOf(points, "points", 3);
            if (hintFaces.is_none() != hintUV.is_none())
              throw InvalidInputError("hint_faces and hint_uv must be given together");
            target::SurfaceHints hints;
            if (!hintFaces.is_none()) {
              const auto faces = py::array_t<int, py::array::c_style | py::array::forcecast>::ensure(hintFaces);
              if (!faces || faces.ndim() != 1 || faces.shape(0) != p.rows())
                throw InvalidInputError("hint_faces must have shape (" + std::to_string(p.rows()) + ",)");
              hints.faces = Eigen::Map<const Eigen::VectorXi>(faces.data(), faces.shape(0));
              hints.uv = rowsOf(hintUV, "hint_uv", 2);
              if (hints.uv.rows() != p.rows())
                throw InvalidInputError("hint_uv must have shape (" + std::to_string(p.rows()) + ", 2)");
            }
            const target::SurfaceHints* warm = hintFaces.is_none() ? nullptr : &hints;
            return projectReleased([&] { return self.project(p, warm); });
          },
          py::arg("points"), py::arg("hint_faces") = py::none(), py::arg("hint_uv") = py::none(),
          (std::string("Closest points on the trimmed surface. points: (n, 3). hint_faces (n,) and hint_uv "
                       "(n, 2): previous faces / params for a warm start (face -1: none); the result "
                       "equals a cold start.") + kResultDoc).c_str())
      .def(
          "project_to_edges",
          [](const Target& self, const py::object& points, const std::vector<int>& edges) {
            const Points p = rowsOf(points, "points", 3);
            return projectReleased([&] { return self.projectToEdges(p, edges); });
          },
          py::arg("points"), py::arg("edge_ids"),
          (std::string("Closest points on the union of the given edges (a crease chain).") + kResultDoc).c_str())
      .def(
          "project_to_free_boundary",
          [](const Target& self, const py::object& points) {
            const Points p = rowsOf(points, "points", 3);
            return projectReleased([&] { return self.projectToFreeBoundary(p); });
          },
          py::arg("points"), (std::string("Closest points on the free boundary edges.") + kResultDoc).c_str())
      .def(
          "project_to_vertex",
          [](const Target& self, const py::object& points, const py::object& vertices) {
            const Points p = rowsOf(points, "points", 3);
            const std::vector<int> ids = py::isinstance<py::int_>(vertices)
                                             ? std::vector<int>{vertices.cast<int>()}
                                             : vertices.cast<std::vector<int>>();
            return projectReleased([&] { return self.projectToVertices(p, ids); });
          },
          py::arg("points"), py::arg("vertex_ids"),
          (std::string("The nearest of the given vertices (one id or a list).") + kResultDoc).c_str())
      .def(
          "project_along",
          [](const Target& self, const py::object& points, const py::object& directions) {
            const Points p = rowsOf(points, "points", 3);
            const Points d = rowsOf(directions, "directions", 3);
            return projectReleased([&] { return self.projectAlong(p, d); });
          },
          py::arg("points"), py::arg("directions"),
          (std::string("Nearest intersection of the lines p + s d (either sign of s) with the trimmed "
                       "surface; lines that miss get the closest point with status FALLBACK.") + kResultDoc).c_str())
      .def_property_readonly("mesh_nodes", &Target::meshNodes, "(N, 3) nodes of the tessellation index")
      .def_property_readonly("mesh_node_tolerances", &Target::meshNodeTolerances,
                             "(N,) the CAD's own tolerance at each node: its edges' and vertices' where it lies on them")
      .def_property_readonly("mesh_triangles", &Target::meshTriangles, "(T, 3) node ids of its triangles")
      .def_property_readonly("mesh_triangle_faces", &Target::meshTriangleFaces, "(T,) face of each triangle");
}

}  // namespace bvmesh::python

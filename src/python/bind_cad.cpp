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
#include "core/cad/shape_repair.h"
#include "core/cad/shape_summary.h"
#include "core/cad/solid_overlap.h"

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

cad::RepairOptions repairOptions(bool sew, double tolerance) { return cad::RepairOptions{sew, tolerance}; }

// The summary of a repaired shape with its repair report under "repair".
py::dict repairedSummary(const cad::RepairedShape& repaired, double sharpAngleDegrees) {
  py::dict result = summaryToDict(cad::summarizeShape(repaired.shape, summaryOptions(sharpAngleDegrees)));
  result["repair"] = repairToDict(repaired.report);
  return result;
}

constexpr const char* kSewDoc =
    " sew: sew faces that share edges within sew_tolerance (0: automatic, from the file's own tolerances "
    "and the model size; see docs/cad_input.md); the result's 'repair' dict says what was sewn, the gaps "
    "left open and whether the shape is watertight.";

}  // namespace

py::dict repairToDict(const cad::RepairReport& r) {
  py::list gaps;
  for (const cad::OpenGap& g : r.openGaps)
    gaps.append(py::dict(py::arg("edge") = g.edge, py::arg("other_edge") = g.otherEdge, py::arg("face") = g.face,
                         py::arg("other_face") = g.otherFace, py::arg("width") = g.width,
                         py::arg("where") = g.where));
  py::list overlaps;
  for (const cad::FaceOverlap& o : r.overlaps)
    overlaps.append(py::dict(py::arg("face") = o.face, py::arg("other_face") = o.otherFace, py::arg("area") = o.area,
                             py::arg("where") = o.where));
  py::dict d;
  d["watertight"] = r.watertight();
  d["sewing_attempted"] = r.sewingAttempted;
  d["sewing_applied"] = r.sewingApplied;
  d["kept_reason"] = r.keptReason;
  d["tolerance"] = r.tolerance;
  d["file_tolerance"] = r.fileTolerance;
  d["model_size"] = r.modelSize;
  d["faces_read"] = r.facesRead;
  d["faces"] = r.faces;
  d["free_edges_read"] = r.freeEdgesRead;
  d["gaps_closed"] = r.gapsClosed;
  d["largest_gap_closed"] = r.largestGapClosed;
  d["degenerate_edges_removed"] = r.degenerateEdgesRemoved;
  d["faces_removed"] = r.facesRemoved;
  d["open_gaps"] = gaps;
  d["overlaps"] = overlaps;
  d["free_edges"] = r.freeEdges;
  d["non_manifold_edges"] = r.nonManifoldEdges;
  d["closed_free_loops"] = r.closedFreeLoops;
  d["open_free_chains"] = r.openFreeChains;
  d["made_solid"] = r.madeSolid;
  d["notes"] = r.notes;
  d["lines"] = cad::describeRepair(r);
  return d;
}

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
      [](const std::string& brep, double sharpAngleDegrees, bool sew, double sewTolerance) {
        cad::RepairedShape repaired;
        {
          py::gil_scoped_release release;
          repaired = cad::readBrepStringRepaired(brep, repairOptions(sew, sewTolerance));
        }
        return repairedSummary(repaired, sharpAngleDegrees);
      },
      py::arg("brep"), py::arg("sharp_angle_degrees") = 30.0, py::arg("sew") = false, py::arg("sew_tolerance") = 0.0,
      (std::string("Faces, surface types, bounding box and classified edges of a shape given as BREP text. By "
                   "default unsewn, so that indices are those of the shape given;") + kSewDoc).c_str());
  module.def(
      "summarize_file",
      [](const std::filesystem::path& file, double sharpAngleDegrees, bool sew, double sewTolerance) {
        const std::string path = file.string();
        cad::RepairedShape repaired;
        {
          py::gil_scoped_release release;
          repaired = cad::readShapeFileRepaired(path, repairOptions(sew, sewTolerance));
        }
        return repairedSummary(repaired, sharpAngleDegrees);
      },
      py::arg("path"), py::arg("sharp_angle_degrees") = 30.0, py::arg("sew") = true, py::arg("sew_tolerance") = 0.0,
      (std::string("Like summarize_brep, for a STEP, IGES or BREP file, sewn by default;") + kSewDoc).c_str());
  module.def(
      "read_cad_file_as_brep",
      [](const std::filesystem::path& file, double seconds, double megabytes, bool sew, double sewTolerance) {
        const std::string path = file.string();
        py::gil_scoped_release release;
        return cad::readShapeFileIsolated(path, cad::ReaderLimits{seconds, megabytes}, repairOptions(sew, sewTolerance));
      },
      py::arg("path"), py::arg("seconds") = cad::ReaderLimits{}.seconds,
      py::arg("megabytes") = cad::ReaderLimits{}.memoryMegabytes, py::arg("sew") = true, py::arg("sew_tolerance") = 0.0,
      (std::string("Reads a STEP, IGES or BREP file in a child process limited to `seconds` and `megabytes` (a "
                   "corrupt file gives an error naming it, never a crash or a hang) and returns the shape as BREP "
                   "text.") + kSewDoc).c_str());
  module.def(
      "write_iges_faces",
      [](const std::string& brep, const std::filesystem::path& file) {
        cad::writeIgesFaces(cad::readBrepStringSafely(brep), file.string());
      },
      py::arg("brep"), py::arg("path"),
      "Writes the faces of a shape (BREP text) to an IGES file each on its own, with no shared edges or "
      "topology (OpenCASCADE's faces mode), as many design tools write IGES.");
  module.def(
      "read_cad_file",
      [](const std::filesystem::path& file, bool sew, double sewTolerance) {
        const std::string path = file.string();
        std::string brep;
        cad::RepairReport report;
        {
          py::gil_scoped_release release;
          brep = cad::readShapeFileIsolated(path, cad::ReaderLimits{}, repairOptions(sew, sewTolerance), &report);
        }
        return py::make_tuple(brep, repairToDict(report));
      },
      py::arg("path"), py::arg("sew") = true, py::arg("sew_tolerance") = 0.0,
      (std::string("(brep, repair): read_cad_file_as_brep with the repair report.") + kSewDoc).c_str());
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
      "overlapping_solids",
      [](const std::string& brep) {
        const TopoDS_Shape shape = cad::readBrepStringSafely(brep);
        std::vector<cad::SolidOverlap> overlaps;
        {
          py::gil_scoped_release release;
          overlaps = cad::overlappingSolids(shape);
        }
        py::list result;
        for (const cad::SolidOverlap& overlap : overlaps) {
          py::dict item;
          item["solid"] = overlap.solid;
          item["other_solid"] = overlap.otherSolid;
          item["where"] = py::make_tuple(overlap.where[0], overlap.where[1], overlap.where[2]);
          result.append(item);
        }
        return result;
      },
      py::arg("brep"),
      "Pairs of solids of the shape (BREP text) that run into each other: one has a boundary point strictly "
      "inside the other (a wing and a fuselage written as two solids). Dicts: solid, other_solid (0-based, "
      "FreeCAD's Shape.Solids order), where (that point). Shapes of more than 32 solids are not checked.");
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

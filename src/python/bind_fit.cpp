// bvmesh.SurfaceFitter: the iterative surface fitting. Options are keyword arguments (checked
// here, unknown names rejected), records and summaries are dicts, arrays are numpy. Long steps
// run without the GIL; progress and cancel cross back as Python callables.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <atomic>
#include <mutex>
#include <string>

#include "arrays.h"
#include "bindings.h"
#include "conversions.h"
#include "core/fit/surface_fitter.h"
#include "core/fit/volume_fit.h"
#include "hex_mesh.h"

namespace py = pybind11;

namespace bvmesh::python {
namespace {

using fit::FitOptions;
using fit::SurfaceFitter;

Eigen::Vector3d vector3Of(const py::handle& object, const char* name) {
  const RowMatrixXd row = rowsOf(py::array(py::reinterpret_borrow<py::object>(object)).reshape({1, -1}), name, 3);
  return row.row(0).transpose();
}

// Sets the options named in `kwargs` and nothing else.
void applyOptions(FitOptions& options, const py::dict& kwargs) {
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    if (name == "tolerance") {
      options.tolerance = realOption(value, "tolerance");
    } else if (name == "relative_tolerance") {
      options.relativeTolerance = realOption(value, "relative_tolerance");
    } else if (name == "max_level") {
      options.maxLevel = integerOption(value, "max_level");
    } else if (name == "max_control_points") {
      options.maxControlPoints = integerOption(value, "max_control_points");
    } else if (name == "max_corrections") {
      options.maxCorrections = integerOption(value, "max_corrections");
    } else if (name == "stagnation_ratio") {
      options.stagnationRatio = realOption(value, "stagnation_ratio");
    } else if (name == "solver") {
      const std::string solver = py::str(value);
      if (solver == "cholesky") {
        options.solver.method = fit::LeastSquaresMethod::Cholesky;
      } else if (solver == "cgls") {
        options.solver.method = fit::LeastSquaresMethod::Cgls;
      } else {
        throw py::value_error("solver must be 'cholesky' or 'cgls', got '" + solver + "'");
      }
    } else if (name == "cgls_tolerance") {
      options.solver.cglsTolerance = realOption(value, "cgls_tolerance");
    } else if (name == "cgls_max_iterations") {
      options.solver.cglsMaxIterations = integerOption(value, "cgls_max_iterations");
    } else if (name == "weights") {
      for (const auto& [kind, weight] : value.cast<py::dict>()) {
        const std::string k = py::str(kind);
        double& slot = k == "smooth" ? options.weights.smooth
                       : k == "crease" ? options.weights.crease
                       : k == "boundary" ? options.weights.boundary
                       : k == "corner" ? options.weights.corner
                       : throw py::value_error("unknown weight '" + k + "'; known: smooth, crease, boundary, corner");
        slot = realOption(weight, "weights");
      }
    } else if (name == "fixed_vertices") {
      options.fixedVertices = intsOf(py::reinterpret_borrow<py::object>(value), "fixed_vertices");
    } else if (name == "symmetry_plane") {
      if (value.is_none()) {
        options.symmetryPlane.reset();
      } else {
        const py::sequence plane = value.cast<py::sequence>();
        if (plane.size() != 2) throw py::value_error("symmetry_plane must be (point, normal) or None");
        options.symmetryPlane = fit::SymmetryPlane{vector3Of(plane[0], "symmetry_plane point"),
                                                   vector3Of(plane[1], "symmetry_plane normal")};
      }
    } else if (name == "relative_plane_tolerance") {
      options.relativePlaneTolerance = realOption(value, "relative_plane_tolerance");
    } else if (name == "project_along_normals") {
      options.projectAlongNormals = flagOption(value, "project_along_normals");
    } else if (name == "reject_opposing_feet") {
      options.rejectOpposingFeet = flagOption(value, "reject_opposing_feet");
    } else if (name == "check_samples_per_face") {
      options.checkSamplesPerFace = integerOption(value, "check_samples_per_face");
    } else if (name == "check_target_subdivisions") {
      options.checkTargetSubdivisions = integerOption(value, "check_target_subdivisions");
    } else if (name == "subdivision") {
      options.subdivision = value.cast<SubdivisionOptions>();
    } else {
      throw py::value_error("unknown fitting option '" + name +
                            "'; known: tolerance, relative_tolerance, max_level, max_control_points, max_corrections, "
                            "stagnation_ratio, "
                            "solver, cgls_tolerance, cgls_max_iterations, weights, fixed_vertices, symmetry_plane, relative_plane_tolerance, "
                            "project_along_normals, reject_opposing_feet, check_samples_per_face, subdivision");
    }
  }
}

py::dict optionsToDict(const FitOptions& options) {
  py::dict dict;
  dict["tolerance"] = options.tolerance;
  dict["relative_tolerance"] = options.relativeTolerance;
  dict["max_level"] = options.maxLevel;
  dict["max_control_points"] = options.maxControlPoints;
  dict["max_corrections"] = options.maxCorrections;
  dict["stagnation_ratio"] = options.stagnationRatio;
  dict["solver"] = options.solver.method == fit::LeastSquaresMethod::Cholesky ? "cholesky" : "cgls";
  dict["cgls_tolerance"] = options.solver.cglsTolerance;
  dict["cgls_max_iterations"] = options.solver.cglsMaxIterations;
  dict["weights"] = py::dict(py::arg("smooth") = options.weights.smooth, py::arg("crease") = options.weights.crease,
                             py::arg("boundary") = options.weights.boundary, py::arg("corner") = options.weights.corner);
  dict["fixed_vertices"] = options.fixedVertices;
  if (options.symmetryPlane) {
    dict["symmetry_plane"] = py::make_tuple(options.symmetryPlane->point, options.symmetryPlane->normal);
  } else {
    dict["symmetry_plane"] = py::none();
  }
  dict["relative_plane_tolerance"] = options.relativePlaneTolerance;
  dict["project_along_normals"] = options.projectAlongNormals;
  dict["reject_opposing_feet"] = options.rejectOpposingFeet;
  dict["check_samples_per_face"] = options.checkSamplesPerFace;
  dict["check_target_subdivisions"] = options.checkTargetSubdivisions;
  dict["subdivision"] = options.subdivision;
  return dict;
}

py::dict recordToDict(const fit::PassRecord& record) {
  py::dict dict;
  dict["level"] = record.level;
  dict["correction"] = record.correction;
  dict["control_points"] = record.controlPoints;
  dict["samples"] = record.samples;
  dict["failed_projections"] = record.failedProjections;
  dict["max_distance"] = record.maxDistance;
  dict["rms_distance"] = record.rmsDistance;
  dict["limit_to_target"] = record.check ? py::cast(record.check->limitToTarget) : py::none();
  dict["target_to_limit"] = record.check ? py::cast(record.check->targetToLimit) : py::none();
  dict["target_to_limit_beyond_cad"] = record.check ? py::cast(record.check->targetToLimitBeyondCad) : py::none();
  dict["seconds"] = record.seconds;
  return dict;
}

py::list historyToList(const std::vector<fit::PassRecord>& history) {
  py::list list;
  for (const fit::PassRecord& record : history) list.append(recordToDict(record));
  return list;
}

// True when `cancel` (None, a callable, or an object with is_set() such as threading.Event) asks to stop.
bool cancelRequested(const py::object& cancel) {
  if (cancel.is_none()) return false;
  if (py::hasattr(cancel, "is_set")) return flagOption(cancel.attr("is_set")(), "cancel.is_set()");
  return flagOption(cancel(), "the result of cancel()");
}

// A SurfaceFitter shared by Python threads: every call takes the fitter's lock, waiting with the
// GIL released (so the thread that holds the lock can still call back into Python); calls from
// its own progress callback re-enter. Concurrent calls thus run one after the other.
struct SharedFitter : SurfaceFitter {
  explicit SharedFitter(SurfaceFitter&& fitter) : SurfaceFitter(std::move(fitter)) {}
  mutable std::recursive_mutex busy;
};

template <class Work>
auto exclusive(const SharedFitter& fitter, Work&& work) {
  py::gil_scoped_release release;
  const std::lock_guard<std::recursive_mutex> lock(fitter.busy);
  return work();
}

}  // namespace

fit::FeatureMap featureMapOf(const py::object& features) {
  fit::FeatureMap map;
  if (features.is_none()) return map;
  if (!py::isinstance<py::dict>(features)) {
    throw py::value_error("features must be a dict with curves, edge_curve and vertex_cad_vertex, or None");
  }
  for (const auto& [key, value] : features.cast<py::dict>()) {
    const std::string name = py::str(key);
    const py::object item = py::reinterpret_borrow<py::object>(value);
    if (name == "curves") {
      for (const py::handle curve : item) map.curves.push_back(intsOf(py::reinterpret_borrow<py::object>(curve), "each feature curve"));
    } else if (name == "edge_curve") {
      map.edgeCurve = intsOf(item, "edge_curve");
    } else if (name == "vertex_cad_vertex") {
      map.vertexCadVertex = intsOf(item, "vertex_cad_vertex");
    } else {
      throw py::value_error("unknown feature-map key '" + name + "'; known: curves, edge_curve, vertex_cad_vertex");
    }
  }
  return map;
}

py::dict featureMapToDict(const fit::FeatureMap& map) {
  py::dict dict;
  dict["curves"] = map.curves;
  dict["edge_curve"] = map.edgeCurve;
  dict["vertex_cad_vertex"] = map.vertexCadVertex;
  return dict;
}

void bindFit(py::module_& module) {
  py::class_<SharedFitter>(module, "SurfaceFitter",
      "The iterative surface fitting: subdivide, limit samples, projection onto the target,\n"
      "least-squares approximation, level after level. Every step can be called on its own.")
      .def(py::init([](std::shared_ptr<target::Target> target, const ControlMesh& mesh, const py::object& features,
                       const py::kwargs& kwargs) {
             FitOptions options;
             applyOptions(options, kwargs);
             return std::make_unique<SharedFitter>(
                 SurfaceFitter(std::move(target), mesh, featureMapOf(features), std::move(options)));
           }),
           py::arg("target"), py::arg("mesh"), py::arg("features") = py::none(),
           "target: bvmesh.Target; mesh: the initial bvmesh.ControlMesh; features: dict with\n"
           "curves (lists of target edge ids), edge_curve (#E curve index or -1) and\n"
           "vertex_cad_vertex (#V target vertex or -1), or None. Keyword options: tolerance,\n"
           "relative_tolerance (of the target's diagonal, default 1e-5), max_level (5),\n"
           "max_corrections (4), stagnation_ratio (0.9), solver ('cgls' (default) or 'cholesky'),\n"
           "cgls_tolerance, cgls_max_iterations, weights\n"
           "(dict smooth/crease/boundary/corner), fixed_vertices, symmetry_plane ((point, normal)),\n"
           "relative_plane_tolerance, project_along_normals, reject_opposing_feet (True),\n"
           "check_samples_per_face (4), subdivision.")
      .def_property_readonly("mesh", [](const SharedFitter& f) { return exclusive(f, [&] { return ControlMesh(f.mesh()); }); },
                             "the current control mesh (a copy: editing it leaves the fitter as it is)")
      .def("mesh_at_level", [](const SharedFitter& f, int level) {
             return exclusive(f, [&] { return ControlMesh(f.meshAtLevel(level)); });
           }, py::arg("level"),
           "the control mesh as the fit left `level` (0 .. level; a copy): what a fit with max_level `level`\n"
           "ends with (offset_and_farfield's marching_level)")
      .def_property_readonly("features", [](const SharedFitter& f) {
             return featureMapToDict(exclusive(f, [&] { return fit::FeatureMap(f.features()); }));
           })
      .def_property_readonly("options", [](const SharedFitter& f) {
             return optionsToDict(exclusive(f, [&] { return FitOptions(f.options()); }));
           })
      .def("set_options", [](SharedFitter& f, const py::kwargs& kwargs) {
             FitOptions options = exclusive(f, [&] { return FitOptions(f.options()); });
             applyOptions(options, kwargs);
             exclusive(f, [&] { f.setOptions(std::move(options)); return 0; });
           }, "Changes the named options, e.g. set_options(tolerance=1e-3, max_level=6)")
      .def_property_readonly("level", [](const SharedFitter& f) { return exclusive(f, [&] { return f.level(); }); })
      .def_property_readonly("absolute_tolerance",
                             [](const SharedFitter& f) { return exclusive(f, [&] { return f.absoluteTolerance(); }); })
      .def("set_vertices", [](SharedFitter& f, const py::object& vertices) {
             const RowMatrixXd points = rowsOf(vertices, "vertices", 3);
             exclusive(f, [&] { f.setVertices(points); return 0; });
           }, py::arg("vertices"), "Moves the control points (#V, 3); the topology stays")
      .def("subdivide", [](SharedFitter& f) { exclusive(f, [&] { f.subdivide(); return 0; }); },
           "Step 1: one Catmull-Clark level; crease and boundary features follow")
      .def("compute_limit_samples", [](SharedFitter& f) {
             return exclusive(f, [&] { return f.limitPositions(); });
           }, "Step 2: (#S, 3) limit samples (vertices, edge midpoints, face centres of the mesh)")
      .def("project", [](SharedFitter& f) {
             return projectionToDict(exclusive(f, [&] { return f.project(); }));
           }, "Step 3: projections of the limit samples onto the target, by sample kind")
      .def("approximate", [](SharedFitter& f) { exclusive(f, [&] { f.approximate(); return 0; }); },
           "Step 4: least-squares control points for the last projections")
      .def("correct_parameters", [](SharedFitter& f, int passes) {
             exclusive(f, [&] { f.correctParameters(passes); return 0; });
           }, py::arg("passes") = 1, "Steps 2-4 again at the same level")
      .def("smooth", [](SharedFitter& f, int iterations, double lambda, double mu) {
             fit::TaubinOptions options;
             options.iterations = iterations;
             options.lambda = lambda;
             options.mu = mu;
             exclusive(f, [&] { f.smooth(options); return 0; });
           }, py::arg("iterations") = 10, py::arg("lambda_") = 0.6307, py::arg("mu") = -0.6732,
           "Taubin lambda|mu smoothing, crease-, corner-, boundary- and plane-aware")
      .def("record", [](SharedFitter& f, bool check) {
             return recordToDict(exclusive(f, [&] { return f.record(check); }));
           }, py::arg("check") = false,
           "Measures the current state (and, with check, the two-sided distance) into the history")
      .def("two_sided_distance", [](const SharedFitter& f, int samplesPerFace, int targetSubdivisions) {
             const fit::TwoSidedDistance d =
                 exclusive(f, [&] { return f.twoSidedDistance(samplesPerFace, targetSubdivisions); });
             return py::dict(py::arg("limit_to_target") = d.limitToTarget, py::arg("target_to_limit") = d.targetToLimit,
                             py::arg("target_points") = d.targetPoints,
                             py::arg("limit_to_target_at") = d.limitToTargetAt,
                             py::arg("target_to_limit_at") = d.targetToLimitAt,
                             py::arg("cad_tolerance_at_target_to_limit") = d.cadToleranceAtTargetToLimit,
                             py::arg("target_to_limit_beyond_cad") = d.targetToLimitBeyondCad,
                             py::arg("target_to_limit_beyond_cad_at") = d.targetToLimitBeyondCadAt);
           }, py::arg("samples_per_face") = 4, py::arg("target_subdivisions") = 0,
           "The two-sided check now; target_subdivisions 0: the option check_target_subdivisions")
      .def_property_readonly("history", [](const SharedFitter& f) {
             return historyToList(exclusive(f, [&] { return f.history(); }));
           })
      .def("run", [](SharedFitter& f, const py::object& progress, const py::object& cancel, const py::kwargs& kwargs) {
             if (kwargs.size() > 0) {
               FitOptions options = exclusive(f, [&] { return FitOptions(f.options()); });
               applyOptions(options, kwargs);
               exclusive(f, [&] { f.setOptions(std::move(options)); return 0; });
             }
             std::atomic<bool> stop(cancelRequested(cancel));
             const fit::ProgressCallback report = [&](const fit::PassRecord& record) {
               py::gil_scoped_acquire acquire;
               if (!progress.is_none()) progress(recordToDict(record));
               if (cancelRequested(cancel)) stop = true;
             };
             const fit::FitSummary summary = exclusive(f, [&] { return f.run(report, &stop); });
             py::dict result;
             result["reason"] = fit::stopReasonName(summary.reason);
             result["tolerance"] = summary.tolerance;
             result["detail"] = summary.detail;
             result["history"] = historyToList(summary.history);
             return result;
           }, py::arg("progress") = py::none(), py::arg("cancel") = py::none(),
           "Fits to the tolerance: progress(record) is called after every pass; cancel (a callable\n"
           "returning True, or a threading.Event) stops after the current step. Keyword options\n"
           "override the fitter's (as set_options). Returns {reason: 'converged' | 'stagnated' |\n"
           "'max_level' | 'check_failed' | 'cancelled' | 'memory_limit', tolerance, detail: which distance is\n"
           "above the tolerance and where (empty when converged; for memory_limit also the next level's\n"
           "control points against max_control_points), history: [records]}. 'converged' needs the samples\n"
           "and the two-sided check (check_samples_per_face > 0) within the tolerance. One fitter may be used from several\n"
           "threads: its calls run one after the other.");

  module.def(
      "subdivide_and_fit_volume",
      [](const py::dict& mesh, std::shared_ptr<target::Target> target, int passes, const py::kwargs& kwargs) {
        FitOptions options;
        applyOptions(options, kwargs);
        for (const char* key : {"points", "cells", "boundary_faces", "boundary_conditions"}) {
          if (!mesh.contains(key)) throw py::value_error(std::string("the hex mesh has no ") + key);
        }
        auto get = [&](const char* key) { return mesh.contains(key) ? py::object(mesh[key]) : py::object(py::none()); };
        const volume::HexMesh hex = hexMeshOf(get("points"), get("cells"), get("boundary_faces"), get("boundary_conditions"),
                                              get("creases"), get("corners"));
        fit::VolumeFitResult result = [&] {
          py::gil_scoped_release release;
          return fit::subdivideAndFitVolume(hex, std::move(target), options, passes);
        }();
        py::dict out = hexMeshDict(result.mesh);
        out["operator"] = std::move(result.subdivisionOperator);
        out["wall"] = recordToDict(result.wall);
        out["min_scaled_jacobian"] = result.minScaledJacobian;
        return out;
      },
      py::arg("mesh"), py::arg("target"), py::arg("passes") = 3,
      "Fitting after the volume exists: one volumetric Catmull-Clark step of the hex mesh (a dict as\n"
      "bvmesh.volume.subdivide takes), `passes` passes of limit samples, projection onto `target` and\n"
      "least squares on its wall faces, the interior following harmonically. Keyword options: those\n"
      "of SurfaceFitter (symmetry_plane, weights, solver, ...). Returns the refined mesh dict with\n"
      "'operator' (the step's), 'wall' (the last pass's record) and 'min_scaled_jacobian'; raises\n"
      "bvmesh.SolverError naming the cell when one turns over.");
}

}  // namespace bvmesh::python

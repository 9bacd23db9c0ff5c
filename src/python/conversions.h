// Conversions of core results to Python objects that more than one binding returns.
#pragma once

#include <pybind11/pybind11.h>

#include "core/cad/shape_repair.h"
#include "core/cad/shape_summary.h"
#include "core/fit/surface_fitter.h"
#include "core/target/target.h"

namespace bvmesh::python {

// A shape summary as a dict: faces, surface types, areas, bounds, edges with kind and dihedral
// angle, edge counts per kind.
pybind11::dict summaryToDict(const cad::ShapeSummary& summary);
// What reading repaired (cad::RepairReport), with its readable lines under "lines".
pybind11::dict repairToDict(const cad::RepairReport& report);

// A feature map (what SurfaceFitter takes) from a dict with curves, edge_curve and
// vertex_cad_vertex (each optional), or None; and back.
fit::FeatureMap featureMapOf(const pybind11::object& features);
pybind11::dict featureMapToDict(const fit::FeatureMap& map);

// A projection result as a dict of numpy arrays (see Target.project's docstring).
pybind11::dict projectionToDict(const target::ProjectionResult& result);

}  // namespace bvmesh::python

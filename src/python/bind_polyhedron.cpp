// Initial polyhedra: template library, automatic placement on a Target, CAD feature curves,
// crease/boundary/corner mapping (FeatureMap as a dict) and improvement. Thin: dicts and lists
// in, dicts and lists out; values are checked by the core (InvalidInputError -> ValueError).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <optional>
#include <filesystem>
#include <string>

#include "bindings.h"
#include "conversions.h"
#include "core/cad/isolated_reader.h"
#include "core/cad/shape_io.h"
#include "core/common/errors.h"
#include "core/polyhedron/flow_domain.h"
#include "core/polyhedron/placement.h"
#include "core/polyhedron/target_analysis.h"

namespace py = pybind11;

namespace bvmesh::python {
namespace {

using namespace bvmesh::polyhedron;

py::dict templateDict(const PolyhedronTemplate& t) {
  py::list parameters;
  for (const TemplateParameter& p : t.parameters) {
    py::dict item;
    item["name"] = p.name;
    item["default"] = p.value;
    item["description"] = p.description;
    item["kind"] = p.isInteger ? "integer" : "choice";
    if (p.isInteger) {
      item["minimum"] = p.minimum;
      item["maximum"] = p.maximum;
    } else {
      item["choices"] = p.choices;
    }
    parameters.append(item);
  }
  py::dict dict;
  dict["name"] = t.name;
  dict["description"] = t.description;
  dict["generator"] = generatorName(t.generator);
  dict["parameters"] = parameters;
  dict["source"] = t.source;
  return dict;
}

py::list curveList(const std::vector<FeatureCurve>& curves) {
  py::list list;
  for (const FeatureCurve& c : curves) {
    py::dict item;
    item["kind"] = featureCurveKindName(c.kind);
    item["edges"] = c.edges;
    item["reversed"] = c.reversed;
    item["start_vertex"] = c.startVertex;
    item["end_vertex"] = c.endVertex;
    item["length"] = c.length;
    item["closed"] = c.closed;
    item["smooth_loop"] = c.smoothLoop;
    list.append(item);
  }
  return list;
}

py::dict mappingDict(const FeatureMapping& mapping) {
  py::list chains;
  for (size_t c = 0; c < mapping.chains.size(); ++c) {
    const MeshFeatureChain& chain = mapping.chains[c];
    const ChainMapping& m = mapping.chainMappings[c];
    py::dict item;
    item["kind"] = chain.kind == FeatureCurveKind::Sharp ? "crease" : "boundary";
    item["vertices"] = chain.vertices;
    item["edges"] = chain.edges;
    item["closed"] = chain.closed;
    item["curve"] = m.curve;
    item["curves"] = m.curves;
    item["map_curve"] = m.mapCurve;
    item["cad_edges"] = m.cadEdges;
    item["nearest_curve"] = m.nearestCurve;
    item["max_distance"] = m.maxDistance;
    item["mean_angle_deg"] = m.meanAngleDeg;
    chains.append(item);
  }
  py::list corners;
  for (const CornerMapping& c : mapping.corners) {
    corners.append(py::dict(py::arg("vertex") = c.vertex, py::arg("cad_vertex") = c.cadVertex,
                            py::arg("nearest_cad_vertex") = c.nearestCadVertex,
                            py::arg("distance") = c.distance, py::arg("required") = c.required));
  }
  py::dict dict;
  dict["feature_map"] = featureMapToDict(mapping.map);
  dict["chains"] = chains;
  dict["corners"] = corners;
  dict["unmapped_chains"] = mapping.unmappedChains;
  dict["unmapped_corners"] = mapping.unmappedCorners;
  dict["complete"] = mapping.complete();
  dict["report"] = mapping.describeUnmapped();
  return dict;
}

// Planes cross as (point, normal) tuples, as in bvmesh.SurfaceFitter's symmetry_plane option.
py::object planeObject(const std::optional<fit::SymmetryPlane>& plane) {
  if (!plane) return py::none();
  return py::make_tuple(Eigen::Vector3d(plane->point), Eigen::Vector3d(plane->normal));
}

std::optional<fit::SymmetryPlane> planeFrom(const py::object& object) {
  if (object.is_none()) return std::nullopt;
  const py::sequence pair = object.cast<py::sequence>();
  if (pair.size() != 2) throw py::value_error("symmetry_plane must be (point, normal) or None");
  fit::SymmetryPlane plane;
  plane.point = pair[0].cast<Eigen::Vector3d>();
  plane.normal = pair[1].cast<Eigen::Vector3d>();
  if (!(plane.normal.norm() > 0.0)) throw py::value_error("symmetry_plane normal must not be zero");
  return plane;
}

FeatureCurveOptions curveOptions(double sharpAngleDeg, double continuityAngleDeg) {
  FeatureCurveOptions options;
  options.sharpAngleDeg = sharpAngleDeg;
  options.continuityAngleDeg = continuityAngleDeg;
  return options;
}

}  // namespace

void bindPolyhedron(py::module_& module) {
  module.def(
      "read_template_library",
      [](const std::string& folder) {
        py::list list;
        for (const PolyhedronTemplate& t : readTemplateLibrary(folder)) list.append(templateDict(t));
        return list;
      },
      py::arg("folder"),
      "Every *.template file of a folder as dicts (name, description, generator, parameters, source).");

  module.def(
      "feature_curves",
      [](const target::Target& target, double sharpAngleDeg, double continuityAngleDeg) {
        std::vector<FeatureCurve> curves;
        {
          py::gil_scoped_release release;
          curves = detectFeatureCurves(target, curveOptions(sharpAngleDeg, continuityAngleDeg));
        }
        return curveList(curves);
      },
      py::arg("target"), py::arg("sharp_angle_deg") = 30.0, py::arg("continuity_angle_deg") = 30.0,
      "The target's sharp and free-boundary curves: dicts with kind ('sharp'/'boundary'), edges (target edge "
      "ids in "
      "chain order), reversed, start_vertex, end_vertex, length, closed, smooth_loop.");

  module.def(
      "map_features",
      [](const ControlMesh& mesh, const target::Target& target, double sharpAngleDeg,
         double continuityAngleDeg, double relativeMaxDistance, double maxAngleDeg,
         double relativeCornerDistance) {
        FeatureMappingOptions options;
        options.relativeMaxDistance = relativeMaxDistance;
        options.maxAngleDeg = maxAngleDeg;
        options.relativeCornerDistance = relativeCornerDistance;
        std::vector<FeatureCurve> curves;
        FeatureMapping mapping;
        {
          py::gil_scoped_release release;
          curves = detectFeatureCurves(target, curveOptions(sharpAngleDeg, continuityAngleDeg));
          mapping = mapFeatures(mesh, target, curves, options);
        }
        py::dict dict = mappingDict(mapping);
        dict["curves"] = curveList(curves);
        return dict;
      },
      py::arg("mesh"), py::arg("target"), py::arg("sharp_angle_deg") = 30.0,
      py::arg("continuity_angle_deg") = 30.0, py::arg("relative_max_distance") = 0.05,
      py::arg("max_angle_deg") = 30.0, py::arg("relative_corner_distance") = 0.05,
      "Maps the mesh's crease chains, boundary chains and corners onto the target's feature curves and "
      "vertices. "
      "Returns a dict: feature_map (curves, edge_curve, vertex_cad_vertex), chains, corners, "
      "unmapped_chains, "
      "unmapped_corners, complete, report (text naming what maps to nothing), curves.");

  module.def(
      "place_template",
      [](const std::filesystem::path& file, const target::Target& target,
         const std::map<std::string, std::string>& parameters, bool improve, bool includeKinks) {
        const std::string path = file.string();
        const PolyhedronTemplate polyhedronTemplate = readTemplate(path);
        PlacementOptions options;
        options.parameters = parameters;
        options.improve = improve;
        options.curves.includeKinks = includeKinks;
        std::optional<PlacedPolyhedron> placed;
        {
          py::gil_scoped_release release;
          placed.emplace(placeTemplate(polyhedronTemplate, target, options));
        }
        py::dict dict = mappingDict(placed->mapping);
        dict["mesh"] = placed->mesh;
        dict["template"] = placed->templateName;
        dict["curves"] = curveList(placed->curves);
        dict["symmetry_plane"] = planeObject(placed->symmetryPlane);
        dict["parameters"] = placed->parameters;
        dict["planform"] = py::none();
        if (placed->planform) {
          const WingPlanform& w = *placed->planform;
          dict["planform"] = py::dict(py::arg("span_direction") = w.spanDirection, py::arg("span") = w.span,
                                      py::arg("root_chord") = w.rootChord, py::arg("tip_chord") = w.tipChord,
                                      py::arg("leading_edge_sweep_deg") = w.leadingEdgeSweepDeg,
                                      py::arg("trailing_edge_sweep_deg") = w.trailingEdgeSweepDeg);
        }
        return dict;
      },
      py::arg("template_path"), py::arg("target"),
      py::arg("parameters") = std::map<std::string, std::string>(), py::arg("improve") = true,
      py::arg("include_kinks") = true,
      "Builds the template (a .template file) on the target; include_kinks=False leaves the target's kinks "
      "out of its feature curves (FeatureCurveOptions::includeKinks). Returns a dict: mesh (ControlMesh), "
      "feature_map, "
      "symmetry_plane ((point, normal) or None), parameters (values used), planform (wings: span, chords, "
      "sweeps; else None), curves, and the mapping report "
      "(chains, corners, unmapped_chains, unmapped_corners, complete, report).");

  module.def(
      "improve_polyhedron",
      [](const ControlMesh& mesh, const target::Target& target, const py::object& featureMap,
         int relaxationPasses, double relaxation, int pushOutPasses, const py::object& symmetryPlane) {
        ImproveOptions options;
        options.relaxationPasses = relaxationPasses;
        options.relaxation = relaxation;
        options.pushOutPasses = pushOutPasses;
        options.symmetryPlane = planeFrom(symmetryPlane);
        const fit::FeatureMap map = featureMapOf(featureMap);
        ControlMesh result = mesh;
        py::gil_scoped_release release;
        improvePolyhedron(result, target, map, options);
        return result;
      },
      py::arg("mesh"), py::arg("target"), py::arg("feature_map") = py::none(),
      py::arg("relaxation_passes") = 3, py::arg("relaxation") = 0.5, py::arg("push_out_passes") = 3,
      py::arg("symmetry_plane") = py::none(),
      "A copy of the mesh improved for fitting: tangential relaxation with projection by vertex role, limit "
      "push-out, "
      "boundary vertices snapped to the symmetry plane ((point, normal)).");

  module.def(
      "remove_symmetry_face",
      [](const std::string& brep) {
        const HalfModelShape half = removeSymmetryFace(cad::readBrepStringSafely(brep));
        return py::make_tuple(cad::writeBrepString(half.shape), half.face, planeObject(half.plane));
      },
      py::arg("brep"),
      "(brep, face, plane): the shape without its symmetry-plane face (the largest planar face with the "
      "whole shape on "
      "one side), that face's index and the plane ((point, normal), normal towards the shape).");

  module.def(
      "split_flow_domain",
      [](const std::string& brep) {
        const TopoDS_Shape shape = cad::readBrepStringSafely(brep);
        FlowDomain domain;
        {
          py::gil_scoped_release release;
          domain = splitFlowDomain(shape);
        }
        py::dict result;
        result["body_faces"] = domain.bodyFaces;
        result["outer_faces"] = domain.outerFaces;
        result["shape"] = domain.shape;
        result["centre"] = std::vector<double>{domain.centre.x(), domain.centre.y(), domain.centre.z()};
        result["radius"] = domain.radius;
        result["half_extent"] = std::vector<double>{domain.halfExtent.x(), domain.halfExtent.y(), domain.halfExtent.z()};
        result["symmetry_face"] = domain.symmetryFace < 0 ? py::object(py::none()) : py::object(py::int_(domain.symmetryFace));
        result["symmetry_plane"] = planeObject(domain.symmetryPlane);
        result["outflow_face"] =
            domain.outflowFace < 0 ? py::object(py::none()) : py::object(py::int_(domain.outflowFace));
        result["outflow_plane"] = planeObject(domain.outflowPlane);
        return result;
      },
      py::arg("brep"),
      "A flow domain's CAD (a box or sphere, or its half on a symmetry plane, with the body cut out) "
      "split into the body's faces and the domain's: dict with body_faces, outer_faces (0-based), shape "
      "('sphere' or 'box'), centre, radius (sphere), half_extent (box; on a symmetry plane the centre "
      "lies on it and the size normal to it is the half domain's whole), symmetry_face and "
      "symmetry_plane ((point, normal towards the domain) or None), outflow_face and outflow_plane (the "
      "sphere domain's plane that the body runs into, a sting; or None).");

  module.def(
      "symmetry_plane",
      [](const target::Target& target, double sharpAngleDeg, double continuityAngleDeg) {
        std::optional<fit::SymmetryPlane> plane;
        {
          py::gil_scoped_release release;
          plane = detectSymmetryPlane(
              target, detectFeatureCurves(target, curveOptions(sharpAngleDeg, continuityAngleDeg)));
        }
        return planeObject(plane);
      },
      py::arg("target"), py::arg("sharp_angle_deg") = 30.0, py::arg("continuity_angle_deg") = 30.0,
      "(point, normal) of a half model's symmetry plane (the plane of its longest flat free-boundary curve "
      "with the "
      "whole target on one side; normal towards the target), or None.");

  module.def(
      "select_faces",
      [](const std::string& brep, const std::vector<int>& faces) {
        return cad::writeBrepString(selectFaces(cad::readBrepStringSafely(brep), faces));
      },
      py::arg("brep"), py::arg("faces"),
      "BREP text of a compound of the given faces (0-based, FreeCAD's Face<i+1>).");
}

}  // namespace bvmesh::python

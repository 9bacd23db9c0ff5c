// Control meshes, subdivision (step 1) and limit samples (step 2). Arrays cross as numpy,
// operators as scipy.sparse.csr_matrix. Shapes are checked here (ValueError naming the
// argument); values and connectivity are checked by the core (InvalidInputError/TopologyError).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "arrays.h"
#include "bindings.h"
#include "core/mesh/control_mesh.h"
#include "core/mesh/mesh_io.h"
#include "core/subdiv/limit_evaluator.h"
#include "core/subdiv/limit_samples.h"
#include "core/subdiv/subdivision.h"

namespace py = pybind11;

namespace bvmesh::python {
namespace {

Eigen::VectorXd realVector(const py::object& object, const char* name, py::ssize_t size) {
  if (object.is_none()) return Eigen::VectorXd();
  const auto array = DoubleArray::ensure(object);
  if (!array || array.ndim() != 1 || array.shape(0) != size) {
    throw py::value_error(std::string(name) + " must have shape (" + std::to_string(size) + ",)");
  }
  return Eigen::Map<const Eigen::VectorXd>(array.data(), size);
}

// faces: a tuple (sizes, flat indices), or one sequence of vertex ids per face.
std::pair<std::vector<int>, std::vector<int>> faceLists(const py::object& faces) {
  std::vector<int> sizes, indices;
  if (py::isinstance<py::tuple>(faces)) {
    const auto pair = faces.cast<py::tuple>();
    if (pair.size() != 2) {
      throw py::value_error("faces given as a tuple must be (sizes, flat indices)");
    }
    return {intsOf(pair[0], "face sizes"), intsOf(pair[1], "face indices")};
  }
  for (const py::handle face : faces) {
    const std::vector<int> corners =
        intsOf(py::reinterpret_borrow<py::object>(face), "each face");
    sizes.push_back(static_cast<int>(corners.size()));
    indices.insert(indices.end(), corners.begin(), corners.end());
  }
  return {sizes, indices};
}

ControlMesh makeControlMesh(const py::object& vertices, const py::object& faces,
                            const py::object& creases, const py::object& creaseSharpness,
                            const py::object& corners, const py::object& cornerSharpness) {
  auto [sizes, indices] = faceLists(faces);
  RowMatrixX2i creasePairs(0, 2);
  py::object sharpnessObject = creaseSharpness;
  if (!creases.is_none()) {
    // (k, 2) vertex pairs, or (k, 3) rows (v0, v1, sharpness).
    const auto array = DoubleArray::ensure(creases);
    const bool empty = array && array.ndim() == 1 && array.size() == 0;
    if (!array || (!empty && (array.ndim() != 2 || (array.shape(1) != 2 && array.shape(1) != 3)))) {
      throw py::value_error("creases must have shape (k, 2) or (k, 3)" +
                            (array ? ", got " + shapeText(array) : std::string()));
    }
    const py::ssize_t rows = empty ? 0 : array.shape(0), columns = empty ? 2 : array.shape(1);
    creasePairs.resize(rows, 2);
    for (py::ssize_t c = 0; c < rows; ++c) {
      for (py::ssize_t k = 0; k < 2; ++k) {
        const double id = array.at(c, k);
        if (id != std::floor(id)) throw py::value_error("crease vertex ids must be integers");
        creasePairs(c, k) = static_cast<int>(id);
      }
    }
    if (columns == 3) {
      if (!creaseSharpness.is_none()) {
        throw py::value_error(
            "give crease sharpness either as a third column or as crease_sharpness");
      }
      py::array_t<double> column(rows);
      for (py::ssize_t c = 0; c < rows; ++c) column.mutable_at(c) = array.at(c, 2);
      sharpnessObject = column;
    }
  }
  std::vector<int> cornerList =
      corners.is_none() ? std::vector<int>() : intsOf(corners, "corners");
  Eigen::VectorXd creaseValues =
      realVector(sharpnessObject, "crease_sharpness", creasePairs.rows());
  Eigen::VectorXd cornerValues =
      realVector(cornerSharpness, "corner_sharpness", static_cast<py::ssize_t>(cornerList.size()));
  return ControlMesh(rowsOf(vertices, "vertices", 3), std::move(sizes), std::move(indices),
                     std::move(creasePairs), std::move(creaseValues), std::move(cornerList),
                     std::move(cornerValues));
}

SubdivisionOptions optionsOrDefault(const py::object& options) {
  return options.is_none() ? SubdivisionOptions() : options.cast<SubdivisionOptions>();
}

py::list faceList(const ControlMesh& mesh) {
  py::list faces;
  for (int f = 0; f < mesh.numFaces(); ++f) {
    py::list face;
    for (int i = 0; i < mesh.faceSize(f); ++i) face.append(mesh.faceVertex(f, i));
    faces.append(face);
  }
  return faces;
}

template <class T>
py::array_t<T> toArray(const std::vector<T>& values) {
  return py::array_t<T>(static_cast<py::ssize_t>(values.size()), values.data());
}

// Limit samples together with the control points they were made for.
struct PyLimitSamples {
  LimitSamples samples;
  RowMatrixX3d controlPoints;
};

std::vector<SurfaceLocation> locationList(const py::object& face, const py::object& u,
                                          const py::object& v) {
  const auto faces = IntArray::ensure(face);
  const auto us = DoubleArray::ensure(u);
  const auto vs = DoubleArray::ensure(v);
  if (!faces || !us || !vs) {
    throw py::value_error("face, u and v must be numbers or arrays of numbers");
  }
  const py::ssize_t count = std::max({faces.size(), us.size(), vs.size()});
  for (const py::array* array :
       {static_cast<const py::array*>(&faces), static_cast<const py::array*>(&us),
        static_cast<const py::array*>(&vs)}) {
    if (array->ndim() > 1 || (array->size() != 1 && array->size() != count)) {
      throw py::value_error("face, u and v must be scalars or 1-D arrays of one common length");
    }
  }
  std::vector<SurfaceLocation> locations(static_cast<size_t>(count));
  for (py::ssize_t i = 0; i < count; ++i) {
    locations[static_cast<size_t>(i)] = {faces.data()[faces.size() == 1 ? 0 : i],
                                         us.data()[us.size() == 1 ? 0 : i],
                                         vs.data()[vs.size() == 1 ? 0 : i]};
  }
  return locations;
}

py::tuple evaluationTuple(const LimitEvaluation& e) {
  return py::make_tuple(e.positions, e.derivativesU, e.derivativesV, e.normals);
}

}  // namespace

void bindMesh(py::module_& module) {
  py::class_<SubdivisionOptions> options(
      module, "SubdivisionOptions",
      "OpenSubdiv options that change the result; the defaults are the thesis' rules.");
  py::enum_<SubdivisionOptions::Boundary>(options, "Boundary")
      .value("EDGE_ONLY", SubdivisionOptions::Boundary::EdgeOnly)
      .value("EDGE_AND_CORNER", SubdivisionOptions::Boundary::EdgeAndCorner);
  py::enum_<SubdivisionOptions::CreaseMethod>(options, "CreaseMethod")
      .value("UNIFORM", SubdivisionOptions::CreaseMethod::Uniform)
      .value("CHAIKIN", SubdivisionOptions::CreaseMethod::Chaikin);
  py::enum_<SubdivisionOptions::TriangleRule>(options, "TriangleRule")
      .value("CATMULL_CLARK", SubdivisionOptions::TriangleRule::CatmullClark)
      .value("SMOOTH", SubdivisionOptions::TriangleRule::Smooth);
  options
      .def(py::init([](SubdivisionOptions::Boundary boundary,
                       SubdivisionOptions::CreaseMethod creaseMethod,
                       SubdivisionOptions::TriangleRule triangleRule) {
             return SubdivisionOptions{boundary, creaseMethod, triangleRule};
           }),
           py::arg("boundary") = SubdivisionOptions::Boundary::EdgeAndCorner,
           py::arg("crease_method") = SubdivisionOptions::CreaseMethod::Uniform,
           py::arg("triangle_rule") = SubdivisionOptions::TriangleRule::CatmullClark)
      .def_readwrite("boundary", &SubdivisionOptions::boundary)
      .def_readwrite("crease_method", &SubdivisionOptions::creaseMethod)
      .def_readwrite("triangle_rule", &SubdivisionOptions::triangleRule);

  py::enum_<SampleElement>(module, "SampleElement", "Mesh element a limit sample belongs to")
      .value("VERTEX", SampleElement::Vertex)
      .value("EDGE", SampleElement::Edge)
      .value("FACE", SampleElement::Face);
  py::enum_<SampleFeature>(module, "SampleFeature", "Kind of limit surface point at a sample")
      .value("SMOOTH", SampleFeature::Smooth)
      .value("CREASE", SampleFeature::Crease)
      .value("BOUNDARY", SampleFeature::Boundary)
      .value("CORNER", SampleFeature::Corner);

  py::class_<ControlMesh>(
      module, "ControlMesh",
      "Control polyhedron of a Catmull-Clark surface: vertices (#V, 3), polygon faces, crease "
      "edges\n"
      "and corner vertices with sharpness (infinite by default). Validated on construction.")
      .def(py::init(&makeControlMesh), py::arg("vertices"), py::arg("faces"),
           py::arg("creases") = py::none(), py::arg("crease_sharpness") = py::none(),
           py::arg("corners") = py::none(), py::arg("corner_sharpness") = py::none(),
           "vertices: (#V, 3); faces: list of vertex-id lists (counter-clockwise), or a tuple\n"
           "(sizes, flat indices); creases: (k, 2) vertex pairs or (k, 3) rows (v0, v1, "
           "sharpness);\n"
           "crease_sharpness: (k,) or None for infinitely sharp (numpy.inf is infinite too);\n"
           "corners: vertex ids; corner_sharpness: like crease_sharpness.")
      .def_property(
          "vertices", [](const ControlMesh& m) { return m.vertices(); },
          [](ControlMesh& m, const py::object& v) { m.setVertices(rowsOf(v, "vertices", 3)); },
          "(#V, 3) positions; assigning keeps the topology")
      .def_property_readonly("faces", &faceList, "list of vertex-id lists")
      .def_property_readonly("face_sizes",
                             [](const ControlMesh& m) { return toArray(m.faceSizes()); })
      .def_property_readonly("face_indices",
                             [](const ControlMesh& m) { return toArray(m.faceIndices()); })
      .def_property_readonly(
          "edges", [](const ControlMesh& m) { return m.edges(); },
          "(#E, 2) end points, numbered in order of first use by the faces")
      .def_property_readonly(
          "edge_faces", [](const ControlMesh& m) { return m.edgeFaces(); },
          "(#E, 2) faces on either side (-1: boundary)")
      .def_property_readonly("creases", [](const ControlMesh& m) { return m.creases(); })
      .def_property_readonly("crease_sharpness",
                             [](const ControlMesh& m) { return m.creaseSharpness(); })
      .def_property_readonly("corners", [](const ControlMesh& m) { return toArray(m.corners()); })
      .def_property_readonly("corner_sharpness",
                             [](const ControlMesh& m) { return m.cornerSharpness(); })
      .def_property_readonly("boundary_edge_ids",
                             [](const ControlMesh& m) { return toArray(m.boundaryEdges()); })
      .def_property_readonly(
          "boundary_edges",
          [](const ControlMesh& m) {
            const std::vector<int> ids = m.boundaryEdges();
            RowMatrixX2i pairs(static_cast<Eigen::Index>(ids.size()), 2);
            for (size_t i = 0; i < ids.size(); ++i) {
              pairs.row(static_cast<Eigen::Index>(i)) = m.edges().row(ids[i]);
            }
            return pairs;
          },
          "(#B, 2) vertex pairs of the edges with one face")
      .def_property_readonly("num_vertices", &ControlMesh::numVertices)
      .def_property_readonly("num_faces", &ControlMesh::numFaces)
      .def_property_readonly("num_edges", &ControlMesh::numEdges)
      .def_property_readonly("is_all_quads", &ControlMesh::isAllQuads)
      .def(
          "subdivide",
          [](const ControlMesh& m, const py::object& opts, bool returnOperator) -> py::object {
            const SubdivisionOptions o = optionsOrDefault(opts);
            SubdivisionResult result = [&] {
              py::gil_scoped_release release;
              return subdivide(m, o);
            }();
            if (!returnOperator) return py::cast(std::move(result.mesh));
            return py::make_tuple(std::move(result.mesh), std::move(result.subdivisionOperator));
          },
          py::arg("options") = py::none(), py::arg("return_operator") = false,
          "One Catmull-Clark step. Returns the new ControlMesh, or (mesh, S) with S the\n"
          "(#V', #V) scipy.sparse.csr_matrix such that mesh.vertices == S @ self.vertices.")
      .def(
          "limit_samples",
          [](const ControlMesh& m, const py::object& opts) {
            const SubdivisionOptions o = optionsOrDefault(opts);
            py::gil_scoped_release release;
            return PyLimitSamples{LimitSamples(m, o), m.vertices()};
          },
          py::arg("options") = py::none(),
          "Limit samples at every vertex, edge midpoint and face centre")
      .def(
          "evaluate",
          [](const ControlMesh& m, const py::object& face, const py::object& u, const py::object& v,
             const py::object& opts) {
            const std::vector<SurfaceLocation> locations = locationList(face, u, v);
            const SubdivisionOptions o = optionsOrDefault(opts);
            LimitEvaluation e = [&] {
              py::gil_scoped_release release;
              return LimitEvaluator(m, o).evaluate(m.vertices(), locations);
            }();
            return evaluationTuple(e);
          },
          py::arg("face"), py::arg("u"), py::arg("v"), py::arg("options") = py::none(),
          "Limit surface at (ptex face, u, v) (scalars or arrays): (positions, du, dv, normals),\n"
          "each (n, 3). Builds a LimitEvaluator each call; keep one for repeated use.")
      .def(
          "write", [](const ControlMesh& m, const std::filesystem::path& file) { writeControlMesh(m, file.string()); },
          py::arg("path"), "Writes the text format, or OBJ with crease/corner tags for '.obj'")
      .def("__repr__", [](const ControlMesh& m) {
        return "<bvmesh.ControlMesh " + std::to_string(m.numVertices()) + " vertices, " +
               std::to_string(m.numFaces()) + " faces, " + std::to_string(m.creases().rows()) +
               " creases, " + std::to_string(m.corners().size()) + " corners>";
      });

  py::class_<PyLimitSamples>(
      module, "LimitSamples",
      "Limit surface samples at every vertex, edge midpoint and face centre (in that order) with\n"
      "their operators: positions == operator @ control points.")
      .def(py::init([](const ControlMesh& m, const py::object& opts) {
             const SubdivisionOptions o = optionsOrDefault(opts);
             py::gil_scoped_release release;
             return PyLimitSamples{LimitSamples(m, o), m.vertices()};
           }),
           py::arg("mesh"), py::arg("options") = py::none())
      .def("__len__", [](const PyLimitSamples& s) { return s.samples.size(); })
      .def_property_readonly(
          "positions", [](const PyLimitSamples& s) { return s.samples.positions(s.controlPoints); },
          "(#S, 3) limit positions for the mesh's vertices")
      .def_property_readonly(
          "normals", [](const PyLimitSamples& s) { return s.samples.normals(s.controlPoints); },
          "(#S, 3) unit limit normals")
      .def(
          "positions_for",
          [](const PyLimitSamples& s, const py::object& p) {
            return s.samples.positions(rowsOf(p, "control points", 3));
          },
          py::arg("control_points"))
      .def(
          "normals_for",
          [](const PyLimitSamples& s, const py::object& p) {
            return s.samples.normals(rowsOf(p, "control points", 3));
          },
          py::arg("control_points"))
      .def_property_readonly(
          "operator", [](const PyLimitSamples& s) { return s.samples.positionOperator(); },
          "(#S, #V) scipy.sparse.csr_matrix A with positions = A @ control points")
      .def_property_readonly(
          "tangent_operators",
          [](const PyLimitSamples& s) {
            return py::make_tuple(s.samples.tangentOperatorU(), s.samples.tangentOperatorV());
          },
          "two (#S, #V) csr matrices; normals are the normalized cross product of their images")
      .def_property_readonly(
          "locations",
          [](const PyLimitSamples& s) {
            const auto count = static_cast<py::ssize_t>(s.samples.size());
            py::array_t<int> faces(count);
            py::array_t<double> us(count), vs(count);
            for (py::ssize_t i = 0; i < count; ++i) {
              const SurfaceLocation& at = s.samples.locations()[static_cast<size_t>(i)];
              faces.mutable_at(i) = at.face;
              us.mutable_at(i) = at.u;
              vs.mutable_at(i) = at.v;
            }
            return py::make_tuple(faces, us, vs);
          },
          "(faces, u, v): three (#S,) arrays, e.g. mesh.evaluate(*samples.locations)")
      .def_property_readonly(
          "location_faces",
          [](const PyLimitSamples& s) {
            std::vector<int> faces;
            for (const auto& l : s.samples.locations()) faces.push_back(l.face);
            return toArray(faces);
          },
          "(#S,) ptex face of each sample")
      .def_property_readonly(
          "location_uv",
          [](const PyLimitSamples& s) {
            Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor> uv(s.samples.size(), 2);
            for (int i = 0; i < s.samples.size(); ++i) {
              uv.row(i) << s.samples.locations()[static_cast<size_t>(i)].u,
                  s.samples.locations()[static_cast<size_t>(i)].v;
            }
            return uv;
          },
          "(#S, 2) (u, v) in the ptex face")
      .def_property_readonly(
          "elements",
          [](const PyLimitSamples& s) {
            std::vector<std::uint8_t> codes;
            for (SampleElement e : s.samples.elements()) {
              codes.push_back(static_cast<std::uint8_t>(e));
            }
            return toArray(codes);
          },
          "(#S,) SampleElement codes: 0 vertex, 1 edge, 2 face")
      .def_property_readonly(
          "features",
          [](const PyLimitSamples& s) {
            std::vector<std::uint8_t> codes;
            for (SampleFeature f : s.samples.features()) {
              codes.push_back(static_cast<std::uint8_t>(f));
            }
            return toArray(codes);
          },
          "(#S,) SampleFeature codes: 0 smooth, 1 crease, 2 boundary, 3 corner")
      .def_property_readonly(
          "source_ids", [](const PyLimitSamples& s) { return s.samples.sourceIds(); },
          "(#S,) vertex, edge or face id according to elements")
      .def_property_readonly(
          "source_vertices", [](const PyLimitSamples& s) { return s.samples.sourceVertices(); },
          "(#S, 2) (v, -1) for vertices, edge end points, (-1, -1) for faces");

  py::class_<LimitEvaluator>(
      module, "LimitEvaluator",
      "Limit surface evaluation at any (ptex face, u, v), built once per topology.")
      .def(py::init([](const ControlMesh& m, const py::object& opts, int isolationLevel) {
             const SubdivisionOptions o = optionsOrDefault(opts);
             py::gil_scoped_release release;
             return LimitEvaluator(m, o, isolationLevel);
           }),
           py::arg("mesh"), py::arg("options") = py::none(), py::arg("isolation_level") = 6)
      .def_property_readonly("num_ptex_faces", &LimitEvaluator::numPtexFaces)
      .def(
          "evaluate",
          [](const LimitEvaluator& ev, const py::object& controlPoints, const py::object& face,
             const py::object& u, const py::object& v) {
            const RowMatrixX3d p = rowsOf(controlPoints, "control points", 3);
            const std::vector<SurfaceLocation> locations = locationList(face, u, v);
            LimitEvaluation e = [&] {
              py::gil_scoped_release release;
              return ev.evaluate(p, locations);
            }();
            return evaluationTuple(e);
          },
          py::arg("control_points"), py::arg("face"), py::arg("u"), py::arg("v"),
          "(positions, du, dv, normals) at the locations for (#V, 3) control points");

  module.def(
      "read_control_mesh", [](const std::filesystem::path& file) { return readControlMesh(file.string()); },
      py::arg("path"),
      "Reads a control mesh: OBJ (with OpenSubdiv crease/corner tags) for '.obj', else the text "
      "format");
  module.def(
      "write_control_mesh",
      [](const ControlMesh& m, const std::filesystem::path& file) { writeControlMesh(m, file.string()); },
      py::arg("mesh"), py::arg("path"));
}

}  // namespace bvmesh::python

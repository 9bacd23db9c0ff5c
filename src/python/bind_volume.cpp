// The volume stage: the block mesh around a fitted wall (offset and far field by marching), its
// B-spline blocks as numpy arrays, their evaluation, the block file, and volumetric subdivision of
// hexahedral meshes.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>
#include <string>

#include "arrays.h"
#include "bindings.h"
#include "block_faces.h"
#include "hex_mesh.h"
#include "core/common/errors.h"
#include "core/mesh/control_mesh.h"
#include "core/surface/limit_points.h"
#include "core/grid/subdivision_refinement.h"
#include "core/volume/block_mesh_io.h"
#include "core/volume/control_volume.h"
#include "core/volume/hex_subdivision.h"
#include "core/volume/volume_blocks.h"
#include "core/volume/volume_options.h"

namespace py = pybind11;

namespace bvmesh::python {
namespace {

using volume::BlockMesh;
using volume::BsplineVolume;

const BsplineVolume& blockOf(const BlockMesh& mesh, int block) {
  if (block < 0 || block >= mesh.blockCount()) {
    throw py::index_error("block " + std::to_string(block) + " does not exist (" + std::to_string(mesh.blockCount()) +
                          " blocks)");
  }
  return mesh.blocks()[static_cast<size_t>(block)].volume;
}

std::vector<double> parametersOf(const py::object& object, const char* name) {
  const DoubleArray array = DoubleArray::ensure(object);
  if (!array || array.ndim() != 1) throw py::value_error(std::string(name) + " must be a 1-D sequence of numbers");
  return std::vector<double>(array.data(), array.data() + array.size());
}

// A plane argument, (point, normal) or None: false for None.
bool planeOf(const py::object& plane, const std::string& name, Eigen::Vector3d& point,
             Eigen::Vector3d& normal) {
  if (plane.is_none()) return false;
  if (!py::isinstance<py::sequence>(plane) || py::isinstance<py::str>(plane) || py::len(plane) != 2) {
    throw py::value_error(name + " must be (point, normal) or None, got " + std::string(py::repr(plane)));
  }
  const py::sequence pair = plane.cast<py::sequence>();
  point = vector3Of(pair[0], (name + " point").c_str());
  normal = vector3Of(pair[1], (name + " normal").c_str());
  return true;
}

// generate_volume_mesh and control_volume_mesh take the same marching options: one signature,
// `make(wall, options)` doing the work without the GIL.
template <typename Make>
void defineMarchingFunction(py::module_& module, const char* name, Make make, const char* doc) {
  module.def(
      name,
      [make](const ControlMesh& wall, const py::object& symmetryPlane, const py::object& outflowPlane,
             double referenceLength, double reynoldsNumber, double boundaryLayerThickness,
             int boundaryLayerLayers, double boundaryLayerGrowth, double sharpEdgeSplay,
             double farfieldDistance, double farfieldGrowth, double smoothing, double minScaledJacobian,
             int maxLayers, const std::string& domain, const py::object& boxHalfExtent,
             const py::object& flowDirection, const std::optional<ControlMesh>& marchingWall,
             const py::object& domainCentre, const std::string& farfieldScheme, bool knifeEdgeFans,
             long long maxLayerPoints) {
        volume::VolumeMeshOptions options;
        options.hasSymmetryPlane =
            planeOf(symmetryPlane, "symmetry_plane", options.planePoint, options.planeNormal);
        options.hasOutflowPlane =
            planeOf(outflowPlane, "outflow_plane", options.outflowPoint, options.outflowNormal);
        if (!domainCentre.is_none()) {
          options.domainCentre = vector3Of(domainCentre, "domain_centre");
        }
        options.domain = volume::domainShapeOf(domain);
        if (!boxHalfExtent.is_none()) {
          options.boxHalfExtent = vector3Of(boxHalfExtent, "box_half_extent");
        }
        options.flowDirection = vector3Of(flowDirection, "flow_direction");
        options.referenceLength = referenceLength;
        options.reynoldsNumber = reynoldsNumber;
        options.boundaryLayerThickness = boundaryLayerThickness;
        options.boundaryLayerLayers = boundaryLayerLayers;
        options.boundaryLayerGrowth = boundaryLayerGrowth;
        options.sharpEdgeSplay = sharpEdgeSplay;
        options.knifeEdgeFans = knifeEdgeFans;
        options.farfieldDistance = farfieldDistance;
        options.farfieldGrowth = farfieldGrowth;
        options.smoothing = smoothing;
        options.farfieldScheme = volume::farfieldSchemeOf(farfieldScheme);
        options.minScaledJacobian = minScaledJacobian;
        options.maxLayers = maxLayers;
        options.maxLayerPoints = maxLayerPoints;
        if (!marchingWall) return make(surface::toQuadControlMesh(wall), options, nullptr);
        const surface::QuadControlMesh coarse = surface::toQuadControlMesh(*marchingWall);
        return make(surface::toQuadControlMesh(wall), options, &coarse);
      },
      py::arg("wall"), py::arg("symmetry_plane") = py::none(), py::arg("outflow_plane") = py::none(),
      py::arg("reference_length") = 0.0, py::arg("reynolds_number") = 5e6,
      py::arg("boundary_layer_thickness") = 0.0, py::arg("boundary_layer_layers") = 4,
      py::arg("boundary_layer_growth") = 1.2, py::arg("sharp_edge_splay") = 2.0,
      py::arg("farfield_distance") = 0.0, py::arg("farfield_growth") = 1.3, py::arg("smoothing") = 1.0,
      py::arg("min_scaled_jacobian") = 0.05, py::arg("max_layers") = 400, py::arg("domain") = "sphere",
      py::arg("box_half_extent") = py::none(), py::arg("flow_direction") = std::vector<double>{1.0, 0.0, 0.0},
      py::arg("marching_wall") = py::none(), py::arg("domain_centre") = py::none(),
      py::arg("farfield_scheme") = "hyperbolic", py::arg("knife_edge_fans") = false,
      py::arg("max_layer_points") = 0, doc);
}

}  // namespace

void bindVolume(py::module_& module) {
  py::class_<BlockMesh>(module, "BlockMesh",
                        "Block-structured B-spline volume mesh: tricubic blocks, their face connections and "
                        "boundary conditions. Faces are named u_min, u_max, v_min, v_max, w_min, w_max; w_min is "
                        "the wall for blocks made by generate_volume_mesh.")
      .def_property_readonly("block_count", &BlockMesh::blockCount)
      .def(
          "poles", [](const BlockMesh& mesh, int block) {
            const BsplineVolume& v = blockOf(mesh, block);
            return gridArray(v.poles(), v.poleCount(0), v.poleCount(1), v.poleCount(2));
          },
          py::arg("block"), "The block's poles, shape (n_u, n_v, n_w, 3).")
      .def(
          "knots", [](const BlockMesh& mesh, int block) {
            const BsplineVolume& v = blockOf(mesh, block);
            return py::make_tuple(v.knots(0), v.knots(1), v.knots(2));
          },
          py::arg("block"), "Full knot vectors (u, v, w), clamped.")
      .def(
          "degrees", [](const BlockMesh& mesh, int block) {
            const BsplineVolume& v = blockOf(mesh, block);
            return py::make_tuple(v.degree(0), v.degree(1), v.degree(2));
          },
          py::arg("block"))
      .def(
          "faces", [](const BlockMesh& mesh, int block) {
            blockOf(mesh, block);
            return facesDict(mesh.blocks()[static_cast<size_t>(block)].faces);
          },
          py::arg("block"),
          "Per face: {'condition': wall / symmetry / farfield / ... / connected} and for connected faces the "
          "neighbour 'block', 'face' and the orientation flags 'swapped', 'reverse_first', 'reverse_second'.")
      .def(
          "evaluate",
          [](const BlockMesh& mesh, int block, const py::object& parameters, bool derivatives) -> py::object {
            const BsplineVolume& v = blockOf(mesh, block);
            const RowMatrixXd uvw = rowsOf(parameters, "parameters", 3);
            RowMatrixX3d points, du, dv, dw;
            {
              py::gil_scoped_release release;
              v.evaluate(uvw, points, derivatives ? &du : nullptr, derivatives ? &dv : nullptr,
                         derivatives ? &dw : nullptr);
            }
            if (!derivatives) return rowsArray(points);
            return py::make_tuple(rowsArray(points), rowsArray(du), rowsArray(dv), rowsArray(dw));
          },
          py::arg("block"), py::arg("parameters"), py::arg("derivatives") = false,
          "Points at (n, 3) parameters (u, v, w); with derivatives=True (points, d/du, d/dv, d/dw).")
      .def(
          "evaluate_grid",
          [](const BlockMesh& mesh, int block, const py::object& u, const py::object& v, const py::object& w,
             bool derivatives) -> py::object {
            const BsplineVolume& volume = blockOf(mesh, block);
            const std::vector<double> us = parametersOf(u, "u"), vs = parametersOf(v, "v"), ws = parametersOf(w, "w");
            RowMatrixX3d points, du, dv, dw;
            {
              py::gil_scoped_release release;
              volume.evaluateGrid(us, vs, ws, points, derivatives ? &du : nullptr, derivatives ? &dv : nullptr,
                                  derivatives ? &dw : nullptr);
            }
            const auto nu = static_cast<py::ssize_t>(us.size()), nv = static_cast<py::ssize_t>(vs.size()),
                       nw = static_cast<py::ssize_t>(ws.size());
            if (!derivatives) return gridArray(points, nu, nv, nw);
            return py::make_tuple(gridArray(points, nu, nv, nw), gridArray(du, nu, nv, nw), gridArray(dv, nu, nv, nw),
                                  gridArray(dw, nu, nv, nw));
          },
          py::arg("block"), py::arg("u"), py::arg("v"), py::arg("w"), py::arg("derivatives") = false,
          "The tensor grid u x v x w, shape (len(u), len(v), len(w), 3) (and its derivatives).")
      .def(
          "control_mesh",
          [](const BlockMesh& mesh) {
            const volume::VolumeControlMesh control = volume::volumeControlMesh(mesh);
            py::dict out;
            out["points"] = rowsArray(control.points);
            py::array_t<int> cells({static_cast<py::ssize_t>(control.cells.size()), py::ssize_t{8}});
            for (size_t c = 0; c < control.cells.size(); ++c) {
              std::copy(control.cells[c].begin(), control.cells[c].end(), cells.mutable_data() + 8 * c);
            }
            out["cells"] = cells;
            out["cell_block"] = control.cellBlock;
            py::array_t<int> faces({static_cast<py::ssize_t>(control.boundaryFaces.size()), py::ssize_t{4}});
            for (size_t f = 0; f < control.boundaryFaces.size(); ++f) {
              std::copy(control.boundaryFaces[f].begin(), control.boundaryFaces[f].end(), faces.mutable_data() + 4 * f);
            }
            out["boundary_faces"] = faces;
            py::list conditions;
            for (auto c : control.boundaryConditions) conditions.append(volume::boundaryConditionName(c));
            out["boundary_conditions"] = conditions;
            return out;
          },
          "The volume control mesh: 'points' (#P, 3) with shared poles merged, 'cells' (#C, 8) hexahedra "
          "(corners 000 100 110 010 001 101 111 011), 'cell_block', 'boundary_faces' (#B, 4) and their "
          "'boundary_conditions'.")
      .def(
          "write", [](const BlockMesh& mesh, const std::filesystem::path& file) { volume::writeBlockMeshFile(mesh, file.string()); },
          py::arg("path"), "Writes the block file (docs/volume.md).");
  module.def("flat_plate_boundary_layer_thickness", &volume::flatPlateBoundaryLayerThickness,
             py::arg("reynolds_number"), py::arg("length"),
             "The turbulent flat-plate boundary-layer thickness 0.37 L Re^-0.2 at L = length (the volume "
             "mesh's default boundary layer); ValueError unless both are finite and positive.");
  module.def("read_block_mesh", [](const std::filesystem::path& file) { return volume::readBlockMeshFile(file.string()); },
             py::arg("path"),
             "Reads a block file written by BlockMesh.write.");

  py::class_<volume::VolumeMesh>(module, "VolumeMesh", "A block mesh made by generate_volume_mesh, with its marching report.")
      .def_readonly("blocks", &volume::VolumeMesh::blocks)
      .def_readonly("block_chart", &volume::VolumeMesh::blockChart)
      .def_readonly("layer_distance", &volume::VolumeMesh::layerDistance)
      .def_readonly("layer_min_scaled_jacobian", &volume::VolumeMesh::layerMinScaledJacobian)
      .def_readonly("farfield_layers_smoothed", &volume::VolumeMesh::farfieldLayersSmoothed,
                    "Far-field layers the hyperbolic scheme would have folded, marched by the smoothed step.")
      .def_readonly("reference_length", &volume::VolumeMesh::referenceLength)
      .def_readonly("boundary_layer_thickness", &volume::VolumeMesh::boundaryLayerThickness)
      .def_readonly("farfield_distance", &volume::VolumeMesh::farfieldDistance)
      .def_property_readonly("domain_centre",
                             [](const volume::VolumeMesh& m) { return std::vector<double>{m.domainCentre.x(), m.domainCentre.y(), m.domainCentre.z()}; })
      .def_readonly("wall_max_distance", &volume::VolumeMesh::wallMaxDistance,
                    "Largest distance of the wall charts from the fitted limit surface (along its normal).")
      .def_property_readonly("domain", [](const volume::VolumeMesh& m) { return std::string(volume::domainShapeName(m.domain.shape)); })
      .def_property_readonly("box_half_extent",
                             [](const volume::VolumeMesh& m) { return std::vector<double>{m.domain.halfExtent.x(), m.domain.halfExtent.y(), m.domain.halfExtent.z()}; })
      .def_readonly("farfield_faces_across_domain_edges", &volume::VolumeMesh::farfieldFacesAcrossDomainEdges,
                    "Far-field block faces that bend around an edge of a box or cylinder domain.");

  defineMarchingFunction(
      module, "generate_volume_mesh",
      [](const surface::QuadControlMesh& wall, const volume::VolumeMeshOptions& options,
         const surface::QuadControlMesh* marchingWall) {
        py::gil_scoped_release release;
        return volume::generateVolumeMesh(wall, options, marchingWall);
      },
      R"doc(The block-structured B-spline volume mesh around the limit surface of a fitted wall.

wall: an all-quad bvmesh.ControlMesh (e.g. SurfaceFitter.mesh), outward oriented, closed or open only
on symmetry_plane ((point, normal) of a half model) and outflow_plane ((point, normal) of the domain's
outflow boundary that the wall runs into, a sting; perpendicular to symmetry_plane, the domain a
sphere centred on it, the blocks' faces in it 'outlet'). Boundary layer: boundary_layer_layers control
layers along the wall normals, total thickness boundary_layer_thickness (0: the turbulent flat-plate
estimate 0.37 L Re^-0.2 with L = reference_length, 0: the wall's largest extent); around sharp convex
edges the grid lines fan out over a band sharp_edge_splay boundary-layer thicknesses wide, or with
knife_edge_fans a knife edge (a sharp trailing edge: faces more than 120 degrees apart) is cut open,
its faces' lines leave along their own normals and a block of prisms fans round it (its wall face
the edge itself, collapsed; the B-spline blocks only, not control_volume_mesh). Far field: marched
(farfield_scheme 'hyperbolic', the default: Chan & Steger's orthogonality and cell-volume equations,
one sparse solve per pseudo-step, a layer it would fold marched by the smoothed step
(farfield_layers_smoothed counts them); 'smoothed': directions with growing implicit smoothing,
turning radial, 2-7 times faster, poorer far-field cells), layer thickness growing by farfield_growth, to the
domain boundary around domain_centre (default: the wall's centre; on the symmetry plane of a half
model, which halves the domain): domain 'sphere' of radius
farfield_distance (0: 20 L), 'box' of half sizes box_half_extent (x, y, z; farfield_distance where
0 or None), or 'cylinder' along flow_direction of radius and half length farfield_distance. The
blocks' outer faces are 'farfield' on a sphere, else 'inlet' / 'outlet' / 'side' by where they face
the flow. marching_wall: the same fit at a coarser level (wall is its control mesh subdivided and
refitted); the layers are marched from it and carried onto wall, whose charts are the blocks' wall
faces. max_layer_points (0: no limit): more layers times marched points is refused (ValueError) once
the layer count is known, before the far field is marched (bvmesh.volume sets it from the free
memory). Returns a VolumeMesh; its .blocks is a BlockMesh with one block per wall patch.)doc");

  py::class_<volume::ControlVolume>(module, "ControlVolume",
                                    "The volume control mesh marched from a fit's own control mesh (control_volume_mesh).")
      .def("hex_mesh", [](const volume::ControlVolume& v) { return hexMeshDict(v.mesh); },
           "The hex mesh as subdivide_hex_mesh and subdivide_and_fit_volume take it (points, cells, boundary_faces, "
           "boundary_conditions, creases, corners: the wall's creases and corners).")
      .def_readonly("wall_vertices", &volume::ControlVolume::wallVertices,
                    "Layer k's points are k * wall_vertices + v, v the wall's control vertex.")
      .def_property_readonly("block_count", [](const volume::ControlVolume& v) { return static_cast<int>(v.blocks.size()); })
      .def_property_readonly("cell_count", [](const volume::ControlVolume& v) { return static_cast<long long>(v.mesh.cells.size()); })
      .def_readonly("block_chart", &volume::ControlVolume::blockChart)
      .def_readonly("layer_distance", &volume::ControlVolume::layerDistance)
      .def_readonly("layer_min_scaled_jacobian", &volume::ControlVolume::layerMinScaledJacobian)
      .def_readonly("reference_length", &volume::ControlVolume::referenceLength)
      .def_readonly("boundary_layer_thickness", &volume::ControlVolume::boundaryLayerThickness)
      .def_readonly("farfield_distance", &volume::ControlVolume::farfieldDistance);

  defineMarchingFunction(
      module, "control_volume_mesh",
      [](const surface::QuadControlMesh& wall, const volume::VolumeMeshOptions& options,
         const surface::QuadControlMesh* marchingWall) {
        if (marchingWall != nullptr) {
          throw bvmesh::InvalidInputError("control_volume_mesh marches the wall's own control mesh; marching_wall is an "
                                  "option of generate_volume_mesh");
        }
        if (options.knifeEdgeFans) {
          throw bvmesh::InvalidInputError(
              "control_volume_mesh keeps its control cells hexahedral; knife_edge_fans is an "
              "option of generate_volume_mesh");
        }
        py::gil_scoped_release release;
        return volume::controlVolumeMesh(wall, options);
      },
      R"doc(The volume control mesh marched from the fitted wall's own Catmull-Clark control mesh (docs/volume.md).

Takes the wall and the options of generate_volume_mesh and marches the same way, from the wall's
control vertices along their mean limit normals; returns a ControlVolume. Its hex mesh's wall faces
are the fit's control faces with their creases and corners, so volumetric subdivision refines the
wall exactly as the surface fit does; its cells are grouped in blocks (the wall's charts, split to
meet side to side, times the layers) for subdivide_control_volume.)doc");

  module.def(
      "hex_mesh_of_blocks", [](const BlockMesh& blocks) { return hexMeshDict(grid::hexMeshOfBlocks(blocks)); },
      py::arg("blocks"),
      "The blocks' control mesh as subdivide_hex_mesh takes it: BlockMesh.control_mesh() with every cell "
      "right-handed (a left-handed block's cells with i reversed), plus empty 'creases' and 'corners'.");

  module.def(
      "subdivide_hex_mesh",
      [](const py::object& points, const py::object& cells, const py::object& boundaryFaces,
         const py::object& boundaryConditions, const py::object& creases, const py::object& corners) {
        const volume::HexMesh mesh = hexMeshOf(points, cells, boundaryFaces, boundaryConditions, creases, corners);
        volume::HexSubdivisionResult result = [&] {
          py::gil_scoped_release release;
          return volume::subdivideHexMesh(mesh);
        }();
        py::dict out = hexMeshDict(result.mesh);
        out["operator"] = std::move(result.subdivisionOperator);
        return out;
      },
      py::arg("points"), py::arg("cells"), py::arg("boundary_faces"), py::arg("boundary_conditions"),
      py::arg("creases") = py::none(), py::arg("corners") = py::none(),
      R"doc(One step of volumetric Catmull-Clark (docs/volume.md).

points (#P, 3); cells (#C, 8) right-handed, corners 000 100 110 010 001 101 111 011; boundary_faces
(#B, 4), every face of exactly one cell, with boundary_conditions (#B names: wall, symmetry,
farfield, inlet, outlet, side); creases (#K, 2) point pairs on the boundary and corners (ids) kept
sharp. Returns the refined mesh as a dict of the same keys, plus 'operator', the (#P', #P)
scipy.sparse.csr_matrix S with points' = S @ points. Children of cell c are cells 8c .. 8c+7,
of boundary face f faces 4f .. 4f+3.)doc");
}

}  // namespace bvmesh::python

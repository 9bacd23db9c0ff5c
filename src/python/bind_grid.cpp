// The volume grid: refinement of the B-spline blocks into stretched point-matched grids, cell
// quality, and the OpenFOAM polyMesh writer.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <optional>
#include <filesystem>
#include <string>

#include "arrays.h"
#include "bindings.h"
#include "block_faces.h"
#include "core/grid/plane_cut.h"
#include "core/grid/refinement.h"
#include "core/grid/subdivision_refinement.h"
#include "core/io/cgns_writer.h"
#include "core/io/gismo_writer.h"
#include "core/io/openfoam_writer.h"
#include "core/io/plot3d_io.h"
#include "core/io/vtk_writer.h"
#include "core/quality/cell_quality.h"
#include "core/volume/volume_blocks.h"

namespace py = pybind11;

namespace bvmesh::python {
namespace {

using grid::GridBlock;
using grid::StructuredGrid;

const GridBlock& gridBlockOf(const StructuredGrid& grid, int block) {
  if (block < 0 || block >= grid.blockCount()) {
    throw py::index_error("block " + std::to_string(block) + " does not exist (" + std::to_string(grid.blockCount()) +
                          " blocks)");
  }
  return grid.blocks()[static_cast<size_t>(block)];
}

// feature_spacings: a sequence of dicts {"points": (n, 3), "spacing": s, "tolerance": t (optional)}.
std::vector<grid::FeatureSpacing> featureSpacingsOf(const py::object& features) {
  std::vector<grid::FeatureSpacing> result;
  if (features.is_none()) return result;
  if (!py::isinstance<py::sequence>(features) || py::isinstance<py::str>(features)) {
    throw py::value_error("feature_spacings must be a sequence of dicts with 'points' and 'spacing'");
  }
  for (const py::handle item : features) {
    const std::string name = "feature_spacings[" + std::to_string(result.size()) + "]";
    if (!py::isinstance<py::dict>(item))
      throw py::value_error(name + " must be a dict with 'points' and 'spacing'");
    const py::dict entry = py::reinterpret_borrow<py::dict>(item);
    for (const auto& [key, value] : entry) {
      const std::string text = py::str(key);
      if (text != "points" && text != "spacing" && text != "tolerance") {
        throw py::value_error(name + " has an unknown key '" + text + "' (points, spacing, tolerance)");
      }
    }
    if (!entry.contains("points") || !entry.contains("spacing")) {
      throw py::value_error(name + " needs 'points' and 'spacing'");
    }
    grid::FeatureSpacing feature;
    feature.points = rowsOf(entry["points"], (name + "['points']").c_str(), 3);
    const auto number = [&](const char* key) {
      try {
        return py::cast<double>(entry[key]);
      } catch (const py::cast_error&) {
        throw py::value_error(name + "['" + key + "'] must be a number");
      }
    };
    feature.spacing = number("spacing");
    if (entry.contains("tolerance")) feature.tolerance = number("tolerance");
    result.push_back(std::move(feature));
  }
  return result;
}

py::array_t<double> valuesArray(const std::vector<double>& values) {
  py::array_t<double> array(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), array.mutable_data());
  return array;
}

py::dict summaryDict(const quality::MetricSummary& s) {
  py::dict item;
  item["count"] = s.count;
  item["min"] = s.min;
  item["p01"] = s.p01;
  item["median"] = s.median;
  item["p99"] = s.p99;
  item["max"] = s.max;
  return item;
}

py::dict summariesDict(const std::vector<quality::MetricSummary>& summaries) {
  py::dict result;
  for (const quality::MetricSummary& s : summaries) result[s.name.c_str()] = summaryDict(s);
  return result;
}

grid::WallDistribution distributionOf(const std::string& name) {
  if (name == "geometric") return grid::WallDistribution::Geometric;
  if (name == "tanh") return grid::WallDistribution::Tanh;
  throw py::value_error("distribution must be 'geometric' or 'tanh', got '" + name + "'");
}

// Grids with an inverted cell are written only when forced.
void requirePositive(const StructuredGrid& g, bool force) {
  if (force) return;
  const grid::HexTopology topology(g);
  quality::requirePositiveCells(topology);
}

// Per-cell arrays over the whole grid (block by block) split into the writer's per-block fields.
std::vector<io::CellField> cellFieldsOf(const StructuredGrid& g, const py::dict& fields) {
  std::vector<io::CellField> result;
  for (const auto& item : fields) {
    const std::string name = py::str(item.first);
    const DoubleArray values = DoubleArray::ensure(item.second);
    if (!values || values.ndim() != 1 || values.size() != g.cellCount()) {
      throw py::value_error("cell field '" + name + "' must be a 1-D array of " + std::to_string(g.cellCount()) +
                            " values (one per cell, block by block)");
    }
    io::CellField field{name, {}};
    const double* at = values.data();
    for (const GridBlock& block : g.blocks()) {
      field.perBlock.emplace_back(at, at + block.cellCount());
      at += block.cellCount();
    }
    result.push_back(std::move(field));
  }
  return result;
}

}  // namespace

void bindGrid(py::module_& module) {
  py::class_<StructuredGrid>(module, "StructuredGrid",
                             "A multi-block structured grid: per block (ni, nj, nk) points, faces point-matched "
                             "(shared points identical) with the block mesh's connections and boundary conditions.")
      .def_property_readonly("block_count", &StructuredGrid::blockCount)
      .def_property_readonly("cell_count", &StructuredGrid::cellCount)
      .def_property_readonly("point_count", &StructuredGrid::pointCount,
                             "Points over all blocks (shared points once per block).")
      .def_property_readonly("viscous_wall", &StructuredGrid::viscousWall,
                             "True when the wall spacing resolves the boundary layer (a y+ or first-height grid).")
      .def(
          "size", [](const StructuredGrid& g, int block) {
            const GridBlock& b = gridBlockOf(g, block);
            return py::make_tuple(b.size[0], b.size[1], b.size[2]);
          },
          py::arg("block"), "(ni, nj, nk) points.")
      .def(
          "points", [](const StructuredGrid& g, int block) {
            const GridBlock& b = gridBlockOf(g, block);
            return gridArray(b.points, b.size[0], b.size[1], b.size[2]);
          },
          py::arg("block"), "The block's points, shape (ni, nj, nk, 3).")
      .def(
          "faces", [](const StructuredGrid& g, int block) { return facesDict(gridBlockOf(g, block).faces); },
          py::arg("block"), "Per face its condition or connection, as BlockMesh.faces.")
      .def(
          "quad_conditions",
          [](const StructuredGrid& g, int block, const std::string& face) {
            const grid::GridBlock& b = gridBlockOf(g, block);
            const int f = faceIndexOf(face);
            const std::array<int, 2> counts = volume::faceGridCounts(b.size, f);
            std::vector<std::string> names;
            for (int qb = 0; qb + 1 < counts[1]; ++qb) {
              for (int qa = 0; qa + 1 < counts[0]; ++qa) names.emplace_back(volume::boundaryConditionName(b.quadCondition(f, qa, qb)));
            }
            return names;
          },
          py::arg("block"), py::arg("face"),
          "The condition of every quad of a boundary face (u_min .. w_max), quad (a, b) at a + (na - 1) b.")
      .def(
          "merged_points", [](const StructuredGrid& g) { return rowsArray(grid::mergePoints(g).points); },
          "Every distinct point once (shared faces merged), in the order OpenFOAM's points file has them.");

  py::class_<grid::RefinedGrid>(module, "RefinedGrid",
                                "A grid made by refine_blocks, with what its wall lines measure.")
      .def_readonly("grid", &grid::RefinedGrid::grid)
      .def_readonly("normal_points", &grid::RefinedGrid::normalPoints)
      .def_readonly("first_cell_height_asked", &grid::RefinedGrid::firstCellHeightAsked)
      .def_readonly("first_cell_height_min", &grid::RefinedGrid::firstCellHeightMin)
      .def_readonly("first_cell_height_max", &grid::RefinedGrid::firstCellHeightMax)
      .def_readonly("growth_max", &grid::RefinedGrid::growthMax)
      .def_readonly("outer_faces_split", &grid::RefinedGrid::outerFacesSplit)
      .def_readonly("even_far_field_used", &grid::RefinedGrid::evenFarFieldUsed)
      .def_readonly("fold_refinements", &grid::RefinedGrid::foldRefinements);

  module.def(
      "refine_blocks",
      [](const volume::BlockMesh& blocks, int normalPoints, double firstCellHeight, double yPlus,
         double reynoldsNumber, double referenceLength, double growth, const std::string& distribution,
         int edgePoints, double tangentialSpacing, long long targetCells, double edgeEndSpacing,
         double maxTurningAngle, double maxSpacingJump, bool evenFarField, const py::object& featureSpacings,
         const volume::VolumeMesh* outerDomainOf, long long maxPoints) {
        grid::RefinementOptions options;
        options.normalPoints = normalPoints;
        options.firstCellHeight = firstCellHeight;
        options.yPlus = yPlus;
        options.reynoldsNumber = reynoldsNumber;
        options.referenceLength = referenceLength;
        options.growth = growth;
        options.distribution = distributionOf(distribution);
        options.edgePoints = edgePoints;
        options.tangentialSpacing = tangentialSpacing;
        options.targetCells = targetCells;
        options.edgeEndSpacing = edgeEndSpacing;
        options.maxTurningDegrees = maxTurningAngle;
        options.maxSpacingJump = maxSpacingJump;
        options.evenFarField = evenFarField;
        options.featureSpacings = featureSpacingsOf(featureSpacings);
        if (outerDomainOf != nullptr) options.outerDomain = outerDomainOf->domain;
        options.maxPoints = maxPoints;
        py::gil_scoped_release release;
        return grid::refineBlockMesh(blocks, options);
      },
      py::arg("blocks"), py::arg("normal_points") = 49, py::arg("first_cell_height") = 0.0,
      py::arg("y_plus") = 0.0, py::arg("reynolds_number") = 0.0, py::arg("reference_length") = 0.0,
      py::arg("growth") = 1.2, py::arg("distribution") = "geometric", py::arg("edge_points") = 17,
      py::arg("tangential_spacing") = 0.0, py::arg("target_cells") = 0, py::arg("edge_end_spacing") = 0.0,
      py::arg("max_turning_angle") = 0.0, py::arg("max_spacing_jump") = 0.0,
      py::arg("even_far_field") = false, py::arg("feature_spacings") = py::none(),
      py::arg("outer_domain_of") = nullptr, py::arg("max_points") = 0,
      R"doc(Evaluates a BlockMesh on stretched, point-matched grids.

Wall-normal lines (from wall faces, and every direction a connection links to them): normal_points
points (0: the fewest keeping the growth ratio <= growth), first point at first_cell_height from the
wall (or from y_plus, reynolds_number, reference_length by the flat-plate estimate); with neither,
every line grows by exactly `growth`. distribution: 'geometric' or 'tanh'. Tangential lines:
edge_points per block edge, or the count tangential_spacing needs, or the spacing that gives about
target_cells cells; uniform in arc length, clustered to edge_end_spacing at block corners if > 0.
max_turning_angle (degrees, 0: none): wall cells along block edges turn at most this much; with a
spacing the counts grow to keep it, and the points gather where the wall bends (a wing's nose).
max_spacing_jump (0: none, else a ratio >= 1): a set of tangential edges whose wall edges are
continued across a block corner (within 45 degrees of straight on) by wall edges spaced more than
this many times finer is clustered at that end to this many times their spacing.
even_far_field: the far field's wall-normal lines slide, from a tenth of the wall's size out,
towards points uniform in arc length on the outer boundary's block edges (all the way there), so
its cells do not inherit the wall's clustering and the marching's fan-out (docs/grid.md); off
when some block does not stand on the wall, and the grid is refined without it where the slid
lines would fold a cell (RefinedGrid.even_far_field_used says which).
feature_spacings: [{"points": (n, 3) polyline, "spacing": s, "tolerance": t (optional)}, ...]: wall
edges that end on a feature line (within t; default 1e-3 of the wall's size) and leave it (more than
45 degrees off it) start there with a spacing of at most s (the longest exactly), by Vinokur's law,
the clustering fading block by block along their linked sets; with a spacing or cell target the sets
take the cells to grow back to their spacing by at most `growth`; the finer where a spacing jump
asks too.
outer_domain_of: the VolumeMesh the blocks come from; a box or cylinder domain's outer faces are
then inlet, outlet or side quad by quad (RefinedGrid.outer_faces_split counts the faces split).
max_points (0: no limit): a grid of more points is refused (ValueError) when its sizes are planned,
before any point is computed (bvmesh.grid.refine sets it from the free memory).
A grid with a folded cell (a non-positive scaled Jacobian) is refined again with twice, then four
times the tangential cells in the blocks a fold is in (their linked sets with them), each try kept
when it leaves fewer blocks folded and made only within max_points (less the grid kept meanwhile):
a block one or two cells across, whose layers wrap round a corner of the wall, can fold where it
is sampled that coarsely and not where it is sampled finer (RefinedGrid.fold_refinements: 1 for
twice, 2 for four times).
Returns a RefinedGrid.)doc");

  module.def(
      "subdivide_blocks",
      [](const volume::BlockMesh& blocks, int steps, long long maxPoints) {
        py::gil_scoped_release release;
        return grid::subdivideBlockMesh(blocks, steps, maxPoints);
      },
      py::arg("blocks"), py::arg("steps"), py::arg("max_points") = 0,
      "`steps` volumetric Catmull-Clark steps of the blocks' control mesh, as a StructuredGrid: each block of "
      "(n_u, n_v, n_w) poles becomes (2^steps (n_u - 1) + 1, ...) points, connections and conditions kept "
      "(docs/volume.md, 'Refinement of a block mesh by subdivision'). max_points (0: no limit): more points are "
      "refused before the first step.");

  module.def(
      "subdivide_control_volume",
      [](const volume::ControlVolume& volume, int steps, long long maxPoints) {
        py::gil_scoped_release release;
        return grid::subdivideControlVolume(volume, steps, maxPoints);
      },
      py::arg("volume"), py::arg("steps"), py::arg("max_points") = 0,
      "`steps` volumetric Catmull-Clark steps of a ControlVolume, as a StructuredGrid of its blocks, the wall "
      "points moved to their limit positions: the grid's wall lies on the fit's limit surface "
      "(docs/volume.md, 'The control volume'). max_points: as subdivide_blocks.");

  module.def(
      "grid_quality",
      [](const StructuredGrid& g) {
        std::optional<grid::HexTopology> topology;
        quality::CellQuality cells;
        std::vector<quality::MetricSummary> overall;
        py::list perBlock;
        std::vector<std::vector<quality::MetricSummary>> blockSummaries;
        {
          py::gil_scoped_release release;
          topology.emplace(g);
          cells = quality::measureCellQuality(*topology);
          overall = quality::summarizeQuality(*topology, cells);
          for (int b = 0; b < g.blockCount(); ++b)
            blockSummaries.push_back(quality::summarizeQuality(*topology, cells, b));
        }
        py::dict result;
        result["scaled_jacobian"] = valuesArray(cells.scaledJacobian);
        result["non_orthogonality"] = valuesArray(cells.nonOrthogonality);
        result["skewness"] = valuesArray(cells.skewness);
        result["aspect_ratio"] = valuesArray(cells.aspectRatio);
        result["growth_ratio"] = valuesArray(cells.growthRatio);
        result["determinant"] = valuesArray(cells.determinant);
        result["volume"] = valuesArray(cells.volume);
        result["wall_angle"] = valuesArray(cells.wallAngle);
        result["first_cell_height"] = valuesArray(cells.firstCellHeight);
        std::vector<int> cellBlock;
        for (int b = 0; b < g.blockCount(); ++b) {
          cellBlock.insert(cellBlock.end(), static_cast<size_t>(g.blocks()[static_cast<size_t>(b)].cellCount()), b);
        }
        result["cell_block"] = cellBlock;
        result["summary"] = summariesDict(overall);
        for (const auto& s : blockSummaries) perBlock.append(summariesDict(s));
        result["block_summary"] = perBlock;
        result["internal_faces"] = topology->internalFaceCount();
        return result;
      },
      py::arg("grid"),
      "Cell quality: per cell (block by block, i fastest) scaled_jacobian, non_orthogonality (degrees, "
      "OpenFOAM's), skewness (OpenFOAM's), aspect_ratio, growth_ratio, determinant (OpenFOAM's cell "
      "determinant: "
      "checkMesh -allGeometry fails a cell below 1e-3), volume; per wall point wall_angle "
      "(degrees) and first_cell_height; 'summary' and 'block_summary' (min / p01 / median / p99 / max).");

  module.def(
      "write_openfoam",
      [](const StructuredGrid& g, const std::string& caseDirectory, bool force) {
        py::gil_scoped_release release;
        const grid::HexTopology topology(g);
        if (!force) quality::requirePositiveCells(topology);
        io::writeOpenFoamCase(topology, caseDirectory);
      },
      py::arg("grid"), py::arg("case_directory"), py::arg("force") = false,
      "Writes constant/polyMesh (and a minimal system/ if missing) of an OpenFOAM case. Refuses a grid "
      "with a non-positive cell (naming it) unless force=True.");

  module.def(
      "write_cgns",
      [](const StructuredGrid& g, const std::filesystem::path& file, bool force) {
        const std::string path = file.string();
        py::gil_scoped_release release;
        requirePositive(g, force);
        io::writeCgns(g, path);
      },
      py::arg("grid"), py::arg("path"), py::arg("force") = false,
      "CGNS (HDF5): one structured zone per block, 1to1 connections, BCs with families wall / symmetry / "
      "farfield (BCWallViscous when the grid resolves the boundary layer, else BCWall).");

  module.def(
      "write_plot3d",
      [](const StructuredGrid& g, const std::filesystem::path& file, const std::string& format, bool force) {
        const std::string path = file.string();
        io::Plot3dFormat kind;
        if (format == "binary") kind = io::Plot3dFormat::Binary;
        else if (format == "ascii") kind = io::Plot3dFormat::Ascii;
        else throw py::value_error("format must be 'binary' or 'ascii', got '" + format + "'");
        py::gil_scoped_release release;
        requirePositive(g, force);
        io::writePlot3d(g, path, kind);
      },
      py::arg("grid"), py::arg("path"), py::arg("format") = "binary", py::arg("force") = false,
      "Plot3D multi-block whole grid: 'binary' (Fortran unformatted, double precision) or 'ascii' (17 digits).");

  module.def(
      "read_plot3d",
      [](const std::filesystem::path& file) {
        const std::string path = file.string();
        std::vector<io::Plot3dBlock> blocks;
        {
          py::gil_scoped_release release;
          blocks = io::readPlot3d(path);
        }
        py::list result;
        for (const io::Plot3dBlock& block : blocks) result.append(gridArray(block.points, block.size[0], block.size[1], block.size[2]));
        return result;
      },
      py::arg("path"), "The blocks of a Plot3D whole grid file (either format), each (ni, nj, nk, 3).");

  module.def(
      "write_vtk",
      [](const StructuredGrid& g, const std::filesystem::path& file, const py::dict& cellFields, bool force) {
        const std::string path = file.string();
        std::vector<io::CellField> fields = cellFieldsOf(g, cellFields);
        py::gil_scoped_release release;
        requirePositive(g, force);
        io::writeVtk(g, path, fields);
      },
      py::arg("grid"), py::arg("path"), py::arg("cell_fields") = py::dict(), py::arg("force") = false,
      "VTK XML multiblock: path (.vtm) and one .vts per block in '<stem>_blocks/'; cell_fields: name -> one "
      "value per cell of the grid (block by block, i fastest).");

  module.def(
      "write_gismo",
      [](const volume::BlockMesh& blocks, const std::filesystem::path& file) {
        const std::string path = file.string();
        py::gil_scoped_release release;
        io::writeGismo(blocks, path);
      },
      py::arg("blocks"), py::arg("path"),
      "The B-spline blocks as G+Smo XML (TensorBSpline3 patches, a MultiPatch with interfaces and boundaries).");

  module.def(
      "grid_plane_cut",
      [](const StructuredGrid& g, const py::object& point, const py::object& normal) {
        const Eigen::Vector3d p = vector3Of(point, "point");
        const Eigen::Vector3d n = vector3Of(normal, "normal");
        grid::PlaneCut cut;
        {
          py::gil_scoped_release release;
          cut = grid::cutByPlane(g, p, n);
        }
        py::dict result;
        result["start"] = rowsArray(cut.start);
        result["end"] = rowsArray(cut.end);
        result["cell"] = cut.cell;
        return result;
      },
      py::arg("grid"), py::arg("point"), py::arg("normal"),
      "The grid lines where the plane (point, normal) crosses the cells' faces: 'start' and 'end' (n, 3) of "
      "each segment and its 'cell' (numbered as grid_quality's arrays).");
}

}  // namespace bvmesh::python

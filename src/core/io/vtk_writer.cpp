#include "core/io/vtk_writer.h"

#include <filesystem>
#include <ostream>
#include <set>

#include "core/common/atomic_file.h"
#include "core/common/errors.h"
#include "core/io/io_common.h"

namespace bvmesh::io {
namespace {

namespace fs = std::filesystem;

std::string xmlEscaped(const std::string& text) {
  std::string result;
  for (char c : text) {
    switch (c) {
      case '&':
        result += "&amp;";
        break;
      case '<':
        result += "&lt;";
        break;
      case '>':
        result += "&gt;";
        break;
      case '"':
        result += "&quot;";
        break;
      default:
        result.push_back(c);
    }
  }
  return result;
}

void checkFields(const grid::StructuredGrid& grid, const std::vector<CellField>& fields, const std::string& path) {
  std::set<std::string> names;
  for (const CellField& field : fields) {
    const std::string what = "cannot write the VTK file \"" + path + "\": cell field '" + field.name + "'";
    if (field.name.empty()) throw InvalidInputError("cannot write the VTK file \"" + path + "\": a cell field has no name");
    if (!names.insert(field.name).second) throw InvalidInputError(what + " is given twice");
    if (field.perBlock.size() != grid.blocks().size()) {
      throw InvalidInputError(what + " has values for " + std::to_string(field.perBlock.size()) + " blocks, the grid has " +
                              std::to_string(grid.blocks().size()));
    }
    for (size_t b = 0; b < grid.blocks().size(); ++b) {
      const auto cells = static_cast<size_t>(grid.blocks()[b].cellCount());
      if (field.perBlock[b].size() != cells) {
        throw InvalidInputError(what + " has " + std::to_string(field.perBlock[b].size()) + " values on block " +
                                std::to_string(b) + ", which has " + std::to_string(cells) + " cells");
      }
    }
  }
}

std::string extent(const grid::GridBlock& block) {
  return "0 " + std::to_string(block.size[0] - 1) + " 0 " + std::to_string(block.size[1] - 1) + " 0 " +
         std::to_string(block.size[2] - 1);
}

// One appended array: its UInt64 byte count, then the Float64 values.
void writeArray(std::ostream& out, const double* values, size_t count) {
  std::string header;
  appendLittleEndian(header, 8 * count, 8);
  out << header;
  writeFloat64s(out, values, count);
}

void writeBlock(std::ostream& out, const grid::StructuredGrid& grid, size_t b, const std::vector<CellField>& fields) {
  const grid::GridBlock& block = grid.blocks()[b];
  const auto cells = static_cast<size_t>(block.cellCount());
  // Appended arrays in order: the fields, then the points; offsets count from after the '_'.
  size_t offset = 0;
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"StructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      << "  <StructuredGrid WholeExtent=\"" << extent(block) << "\">\n"
      << "    <Piece Extent=\"" << extent(block) << "\">\n"
      << "      <CellData>\n";
  for (const CellField& field : fields) {
    out << "        <DataArray type=\"Float64\" Name=\"" << xmlEscaped(field.name)
        << "\" NumberOfComponents=\"1\" format=\"appended\" offset=\"" << offset << "\"/>\n";
    offset += 8 + 8 * cells;
  }
  out << "      </CellData>\n"
      << "      <Points>\n"
      << "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"appended\" offset=\""
      << offset << "\"/>\n"
      << "      </Points>\n"
      << "    </Piece>\n"
      << "  </StructuredGrid>\n"
      << "  <AppendedData encoding=\"raw\">\n_";
  for (const CellField& field : fields) writeArray(out, field.perBlock[b].data(), cells);
  // Row-major points are already x0 y0 z0 x1 ..., the interleaving VTK wants.
  writeArray(out, block.points.data(), static_cast<size_t>(3 * block.pointCount()));
  out << "\n  </AppendedData>\n</VTKFile>\n";
}

void writeIndex(std::ostream& out, const grid::StructuredGrid& grid, const std::string& folder) {
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"vtkMultiBlockDataSet\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      << "  <vtkMultiBlockDataSet>\n";
  for (int b = 0; b < grid.blockCount(); ++b) {
    out << "    <DataSet index=\"" << b << "\" name=\"" << blockName(b) << "\" file=\"" << xmlEscaped(folder) << "/"
        << blockName(b) << ".vts\"/>\n";
  }
  out << "  </vtkMultiBlockDataSet>\n</VTKFile>\n";
}

}  // namespace

// The blocks go to a fresh "<stem>_blocks.partial" folder and the index to its temporary; only
// when both are complete does that folder replace the old one and the index move into place, so
// that a failed write leaves the earlier files (or none) under the final names.
void writeVtk(const grid::StructuredGrid& grid, const std::string& path, const std::vector<CellField>& cellFields) {
  const fs::path file(path);
  if (file.extension() != ".vtm") {
    throw InvalidInputError("the VTK multiblock file \"" + path + "\" must end in .vtm");
  }
  checkFields(grid, cellFields, path);
  const std::string folder = file.stem().string() + "_blocks";
  const fs::path folderPath = file.parent_path() / folder;
  const fs::path staging = folderPath.string() + ".partial";
  std::error_code error;
  if (fs::is_directory(file) || (fs::exists(folderPath) && !fs::is_directory(folderPath))) {
    throw InvalidInputError("cannot write the VTK file \"" + path + "\": \"" +
                            (fs::is_directory(file) ? file : folderPath).string() + "\" is in the way");
  }
  fs::remove_all(staging, error);  // a crashed write's (a link there is removed, not followed)
  fs::create_directory(staging, error);
  if (error || !fs::is_directory(staging)) {
    throw InvalidInputError("cannot write the VTK file \"" + path + "\": cannot create the folder \"" +
                            staging.string() + "\" (is the folder of the file missing or not writable?)");
  }
  try {
    for (size_t b = 0; b < grid.blocks().size(); ++b) {
      const std::string blockPath = (staging / (blockName(static_cast<int>(b)) + ".vts")).string();
      writeFileAtomically(blockPath, "the VTK block file",
                          [&](std::ostream& out) { writeBlock(out, grid, b, cellFields); });
    }
    writeFileAtomically(
        path, "the VTK multiblock file", [&](std::ostream& out) { writeIndex(out, grid, folder); },
        [&] {
          fs::remove_all(folderPath);
          fs::rename(staging, folderPath);
        });
  } catch (const fs::filesystem_error& failure) {
    fs::remove_all(staging, error);
    throw InvalidInputError("cannot write the VTK file \"" + path + "\": " + failure.what());
  } catch (...) {
    fs::remove_all(staging, error);
    throw;
  }
}

}  // namespace bvmesh::io

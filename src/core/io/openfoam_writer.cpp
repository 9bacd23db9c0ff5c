#include "core/io/openfoam_writer.h"

#include <charconv>
#include <filesystem>
#include <limits>
#include <system_error>
#include <vector>

#include "core/common/atomic_file.h"
#include "core/common/errors.h"

namespace bvmesh::io {
namespace {

namespace fs = std::filesystem;

// Buffered number formatting: std::to_chars gives the shortest text that reads back exactly.
class Output {
 public:
  explicit Output(std::ostream& out) : out_(out) { buffer_.reserve(kFlush + 256); }
  ~Output() { flush(); }
  Output(const Output&) = delete;
  Output& operator=(const Output&) = delete;
  Output& text(const std::string& value) {
    buffer_ += value;
    return maybeFlush();
  }
  Output& character(char value) {
    buffer_ += value;
    return maybeFlush();
  }
  template <class Number>
  Output& number(Number value) {
    char digits[64];
    const auto result = std::to_chars(digits, digits + sizeof(digits), value);
    buffer_.append(digits, result.ptr);
    return maybeFlush();
  }
  void flush() {
    out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    buffer_.clear();
  }

 private:
  static constexpr size_t kFlush = 1 << 20;
  Output& maybeFlush() {
    if (buffer_.size() >= kFlush) flush();
    return *this;
  }
  std::ostream& out_;
  std::string buffer_;
};

std::string header(const std::string& className, const std::string& location, const std::string& object,
                   const std::string& note = "") {
  std::string text =
      "/*--------------------------------*- C++ -*----------------------------------*\\\n"
      "  Written by BVMesh\n"
      "\\*---------------------------------------------------------------------------*/\n"
      "FoamFile\n{\n    version     2.0;\n    format      ascii;\n    class       " +
      className + ";\n";
  if (!note.empty()) text += "    note        \"" + note + "\";\n";
  text += "    location    \"" + location + "\";\n    object      " + object + ";\n}\n\n";
  return text;
}

void writeFile(const fs::path& path, const std::function<void(Output&)>& write) {
  writeFileAtomically(path.string(), "the OpenFOAM file", [&](std::ostream& stream) {
    Output out(stream);
    write(out);
  });
}

void createDirectory(const fs::path& directory) {
  std::error_code error;
  fs::create_directories(directory, error);
  if (error || !fs::is_directory(directory)) {
    throw InvalidInputError("cannot create the OpenFOAM case folder \"" + directory.string() + "\" (" +
                            error.message() + ")");
  }
}

const char* patchType(volume::BoundaryCondition condition) {
  switch (condition) {
    case volume::BoundaryCondition::Wall:
      return "wall";
    case volume::BoundaryCondition::Symmetry:
      return "symmetryPlane";
    default:
      return "patch";
  }
}

void writeSystemFile(const fs::path& path, const std::string& object, const std::string& body) {
  if (fs::exists(path)) return;  // the case's own settings stay
  writeFile(path, [&](Output& out) { out.text(header("dictionary", "system", object)).text(body); });
}

}  // namespace

void writeOpenFoamCase(const grid::HexTopology& topology, const std::string& caseDirectory) {
  const RowMatrixX3d& points = topology.points().points;
  Eigen::Index boundaryFaces = 0;
  for (const grid::BoundaryPatch& patch : topology.patches()) boundaryFaces += patch.size;
  const Eigen::Index faceCount = topology.internalFaceCount() + boundaryFaces;
  if (faceCount * 4 > std::numeric_limits<int>::max() || points.rows() > std::numeric_limits<int>::max()) {
    throw InvalidInputError("the grid is too large for OpenFOAM's 32-bit labels (" + std::to_string(faceCount) + " faces)");
  }
  // An empty name would write into the current folder.
  if (caseDirectory.empty()) throw InvalidInputError("no folder given for the OpenFOAM case");
  const fs::path root(caseDirectory);
  const fs::path mesh = root / "constant" / "polyMesh";
  createDirectory(mesh);
  createDirectory(root / "system");
  const std::string location = "constant/polyMesh";
  const std::string note = "nPoints:" + std::to_string(points.rows()) + " nCells:" + std::to_string(topology.cellCount()) +
                           " nFaces:" + std::to_string(faceCount) +
                           " nInternalFaces:" + std::to_string(topology.internalFaceCount());

  writeFile(mesh / "points", [&](Output& out) {
    out.text(header("vectorField", location, "points")).number(points.rows()).text("\n(\n");
    for (Eigen::Index p = 0; p < points.rows(); ++p) {
      out.character('(').number(points(p, 0)).character(' ').number(points(p, 1)).character(' ').number(points(p, 2)).text(")\n");
    }
    out.text(")\n");
  });
  writeFile(mesh / "faces", [&](Output& out) {
    out.text(header("faceList", location, "faces")).number(faceCount).text("\n(\n");
    auto face = [&](const grid::HexFace& f) {
      out.number(f.size).character('(').number(f.points[0]);
      for (size_t v = 1; v < static_cast<size_t>(f.size); ++v) out.character(' ').number(f.points[v]);
      out.text(")\n");
    };
    topology.forEachInternalFace(face);
    topology.forEachBoundaryFace([&](size_t, const grid::HexFace& f) { face(f); });
    out.text(")\n");
  });
  writeFile(mesh / "owner", [&](Output& out) {
    out.text(header("labelList", location, "owner", note)).number(faceCount).text("\n(\n");
    topology.forEachInternalFace([&](const grid::HexFace& f) { out.number(f.owner).character('\n'); });
    topology.forEachBoundaryFace([&](size_t, const grid::HexFace& f) { out.number(f.owner).character('\n'); });
    out.text(")\n");
  });
  writeFile(mesh / "neighbour", [&](Output& out) {
    out.text(header("labelList", location, "neighbour", note)).number(topology.internalFaceCount()).text("\n(\n");
    topology.forEachInternalFace([&](const grid::HexFace& f) { out.number(f.neighbour).character('\n'); });
    out.text(")\n");
  });
  writeFile(mesh / "boundary", [&](Output& out) {
    out.text(header("polyBoundaryMesh", location, "boundary")).number(topology.patches().size()).text("\n(\n");
    Eigen::Index start = topology.internalFaceCount();
    for (const grid::BoundaryPatch& patch : topology.patches()) {
      const std::string type = patchType(patch.condition);
      out.text("    " + patch.name + "\n    {\n        type            " + type + ";\n");
      if (type != "patch") out.text("        inGroups        List<word> 1(" + type + ");\n");
      out.text("        nFaces          ").number(patch.size).text(";\n        startFace       ").number(start).text(";\n    }\n");
      start += patch.size;
    }
    out.text(")\n");
  });
  writeSystemFile(root / "system" / "controlDict", "controlDict",
                  "application     rhoSimpleFoam;\nstartFrom       startTime;\nstartTime       0;\nstopAt          endTime;\n"
                  "endTime         1;\ndeltaT          1;\nwriteControl    timeStep;\nwriteInterval   1;\n"
                  "writeFormat     ascii;\nwritePrecision  17;\ntimeFormat      general;\nrunTimeModifiable false;\n");
  writeSystemFile(root / "system" / "fvSchemes", "fvSchemes",
                  "ddtSchemes { default steadyState; }\ngradSchemes { default Gauss linear; }\n"
                  "divSchemes { default none; }\nlaplacianSchemes { default Gauss linear corrected; }\n"
                  "interpolationSchemes { default linear; }\nsnGradSchemes { default corrected; }\n"
                  "wallDist { method meshWave; }\n");
  writeSystemFile(root / "system" / "fvSolution", "fvSolution", "solvers {}\n");
}

}  // namespace bvmesh::io

#include "core/mesh/mesh_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include "core/common/errors.h"
#include "core/common/input_file.h"

namespace bvmesh {
namespace {

constexpr const char* kTextMagic = "bvmesh-control-mesh";
constexpr double kObjInfiniteSharpness = 10.0;  // OpenSubdiv's SHARPNESS_INFINITE

struct Line {
  int number;
  std::vector<std::string> tokens;
};

// Non-empty lines split at white space, comments ('#' to the end of the line) removed.
std::vector<Line> tokenize(std::istream& in) {
  std::vector<Line> lines;
  std::string text;
  int number = 0;
  while (std::getline(in, text)) {
    ++number;
    const size_t hash = text.find('#');
    if (hash != std::string::npos) text.resize(hash);
    std::istringstream words(text);
    Line line{number, {}};
    for (std::string word; words >> word;) line.tokens.push_back(std::move(word));
    if (!line.tokens.empty()) lines.push_back(std::move(line));
  }
  return lines;
}

class Parser {
public:
  explicit Parser(std::string name) : name_(std::move(name)) {}

  [[noreturn]] void fail(int line, const std::string& what) const {
    throw InvalidInputError(name_ + " line " + std::to_string(line) + ": " + what);
  }
  [[noreturn]] void failAtEnd(const std::string& what) const {
    throw InvalidInputError(name_ + ": " + what + " (the file ends early)");
  }

  double real(const Line& line, const std::string& token) const {
    const char* begin = token.c_str();
    char* end = nullptr;
    errno = 0;
    const double value = std::strtod(begin, &end);
    if (end == begin || *end != '\0' || errno == ERANGE) {
      fail(line.number, "'" + token + "' is not a number");
    }
    return value;
  }
  int integer(const Line& line, const std::string& token) const {
    const char* begin = token.c_str();
    char* end = nullptr;
    errno = 0;
    const long value = std::strtol(begin, &end, 10);
    if (end == begin || *end != '\0' || errno == ERANGE || value < -2147483647L ||
        value > 2147483647L) {
      fail(line.number, "'" + token + "' is not an integer");
    }
    return static_cast<int>(value);
  }
  double sharpness(const Line& line, const std::string& token) const {
    const double value = real(line, token);
    if (!(value > 0.0)) fail(line.number, "sharpness '" + token + "' must be > 0");
    return value;
  }
  void expectCount(const Line& line, size_t count, const std::string& what) const {
    if (line.tokens.size() != count) {
      fail(line.number,
           "expected " + what + ", got " + std::to_string(line.tokens.size()) + " values");
    }
  }

  // Builds the mesh, naming the file in validation errors.
  ControlMesh build(RowMatrixX3d vertices, std::vector<int> sizes, std::vector<int> indices,
                    const std::vector<std::array<int, 2>>& creases,
                    const std::vector<double>& creaseSharpness, std::vector<int> corners,
                    const std::vector<double>& cornerSharpness) const {
    RowMatrixX2i pairs(static_cast<Eigen::Index>(creases.size()), 2);
    for (size_t c = 0; c < creases.size(); ++c) {
      pairs.row(static_cast<Eigen::Index>(c)) << creases[c][0], creases[c][1];
    }
    const auto toVector = [](const std::vector<double>& values) {
      return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(
          values.data(), static_cast<Eigen::Index>(values.size())));
    };
    try {
      return ControlMesh(std::move(vertices), std::move(sizes), std::move(indices),
                         std::move(pairs), toVector(creaseSharpness), std::move(corners),
                         toVector(cornerSharpness));
    } catch (const TopologyError& error) {
      throw TopologyError(name_ + ": " + error.what());
    } catch (const InvalidInputError& error) {
      throw InvalidInputError(name_ + ": " + error.what());
    }
  }

private:
  std::string name_;
};

std::string formatReal(double value) {
  if (value == kInfiniteSharpness) return "inf";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

bool isObjPath(const std::string& path) {
  if (path.size() < 4) return false;
  std::string extension = path.substr(path.size() - 4);
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension == ".obj";
}

ControlMeshFormat resolve(ControlMeshFormat format, const std::string& path) {
  if (format != ControlMeshFormat::Auto) return format;
  return isObjPath(path) ? ControlMeshFormat::Obj : ControlMeshFormat::Text;
}

}  // namespace

ControlMesh readControlMeshText(std::istream& in, const std::string& name) {
  const Parser parser(name);
  const std::vector<Line> lines = tokenize(in);
  size_t next = 0;
  const auto take = [&](const std::string& what) -> const Line& {
    if (next >= lines.size()) parser.failAtEnd("expected " + what);
    return lines[next++];
  };
  // "<keyword> <count>" section header.
  const auto section = [&](const std::string& keyword) {
    const Line& line = take("'" + keyword + " <count>'");
    if (line.tokens.size() != 2 || line.tokens[0] != keyword) {
      parser.fail(line.number, "expected '" + keyword + " <count>'");
    }
    const int count = parser.integer(line, line.tokens[1]);
    if (count < 0) parser.fail(line.number, "negative count");
    return count;
  };

  const Line& header = take("the header '" + std::string(kTextMagic) + " 1'");
  if (header.tokens.size() != 2 || header.tokens[0] != kTextMagic) {
    parser.fail(header.number,
                "not a BVMesh control mesh file (expected '" + std::string(kTextMagic) + " 1')");
  }
  if (header.tokens[1] != "1") {
    parser.fail(header.number, "unsupported version " + header.tokens[1]);
  }

  // Counts are the file's word: storage grows with the lines actually there, never with a count
  // alone ("vertices 2000000000" in a 60-byte file asked for 48 GB).
  const auto atMostRemaining = [&](int count) { return std::min(static_cast<size_t>(count), lines.size() - next); };
  const int numVertices = section("vertices");
  RowMatrixX3d vertices(static_cast<Eigen::Index>(atMostRemaining(numVertices)), 3);
  for (int v = 0; v < numVertices; ++v) {
    const Line& line = take("vertex " + std::to_string(v));
    parser.expectCount(line, 3, "3 coordinates for vertex " + std::to_string(v));
    for (int k = 0; k < 3; ++k) {
      vertices(v, k) = parser.real(line, line.tokens[static_cast<size_t>(k)]);
    }
  }
  const int numFaces = section("faces");
  std::vector<int> sizes, indices;
  sizes.reserve(atMostRemaining(numFaces));
  for (int f = 0; f < numFaces; ++f) {
    const Line& line = take("face " + std::to_string(f));
    const int size = parser.integer(line, line.tokens[0]);
    if (size < 0 || line.tokens.size() != static_cast<size_t>(size) + 1) {
      parser.fail(line.number, "face " + std::to_string(f) + " announces " + line.tokens[0] +
                                   " vertices but lists " + std::to_string(line.tokens.size() - 1));
    }
    sizes.push_back(size);
    for (int i = 1; i <= size; ++i) {
      indices.push_back(parser.integer(line, line.tokens[static_cast<size_t>(i)]));
    }
  }
  std::vector<std::array<int, 2>> creases;
  std::vector<double> creaseSharpness;
  if (next < lines.size() && lines[next].tokens[0] == "creases") {
    const int count = section("creases");
    for (int c = 0; c < count; ++c) {
      const Line& line = take("crease " + std::to_string(c));
      parser.expectCount(line, 3,
                         "'<vertex> <vertex> <sharpness>' for crease " + std::to_string(c));
      creases.push_back(
          {parser.integer(line, line.tokens[0]), parser.integer(line, line.tokens[1])});
      creaseSharpness.push_back(parser.sharpness(line, line.tokens[2]));
    }
  }
  std::vector<int> corners;
  std::vector<double> cornerSharpness;
  if (next < lines.size() && lines[next].tokens[0] == "corners") {
    const int count = section("corners");
    for (int c = 0; c < count; ++c) {
      const Line& line = take("corner " + std::to_string(c));
      parser.expectCount(line, 2, "'<vertex> <sharpness>' for corner " + std::to_string(c));
      corners.push_back(parser.integer(line, line.tokens[0]));
      cornerSharpness.push_back(parser.sharpness(line, line.tokens[1]));
    }
  }
  if (next < lines.size()) {
    parser.fail(lines[next].number, "unexpected '" + lines[next].tokens[0] + "'");
  }
  return parser.build(std::move(vertices), std::move(sizes), std::move(indices), creases,
                      creaseSharpness, std::move(corners), cornerSharpness);
}

ControlMesh readControlMeshObj(std::istream& in, const std::string& name) {
  const Parser parser(name);
  std::vector<double> coordinates;
  std::vector<int> sizes, indices;
  std::vector<std::array<int, 2>> creases;
  std::vector<double> creaseSharpness;
  std::vector<int> corners;
  std::vector<double> cornerSharpness;
  const auto objSharpness = [&](const Line& line, const std::string& token) {
    const double value = parser.sharpness(line, token);
    return value >= kObjInfiniteSharpness ? kInfiniteSharpness : value;
  };

  for (const Line& line : tokenize(in)) {
    const std::string& keyword = line.tokens[0];
    if (keyword == "v") {
      if (line.tokens.size() < 4) parser.fail(line.number, "a vertex needs 3 coordinates");
      for (size_t k = 1; k <= 3; ++k) coordinates.push_back(parser.real(line, line.tokens[k]));
    } else if (keyword == "f") {
      if (line.tokens.size() < 4) parser.fail(line.number, "a face needs at least 3 vertices");
      const int numVertices = static_cast<int>(coordinates.size() / 3);
      for (size_t k = 1; k < line.tokens.size(); ++k) {
        // "i", "i/t", "i//n" or "i/t/n"; only the vertex index matters.
        const std::string& token = line.tokens[k];
        const int index = parser.integer(line, token.substr(0, token.find('/')));
        if (index == 0) parser.fail(line.number, "OBJ vertex indices start at 1, got 0");
        indices.push_back(index > 0 ? index - 1 : numVertices + index);
      }
      sizes.push_back(static_cast<int>(line.tokens.size()) - 1);
    } else if (keyword == "t" && line.tokens.size() >= 3 &&
               (line.tokens[1] == "crease" || line.tokens[1] == "corner")) {
      // "t <name> <#ints>/<#floats>[/<#strings>] ints... floats..."
      const std::string& counts = line.tokens[2];
      const size_t slash = counts.find('/');
      if (slash == std::string::npos) {
        parser.fail(line.number, "malformed tag counts '" + counts + "'");
      }
      const size_t secondSlash = counts.find('/', slash + 1);
      const int numInts = parser.integer(line, counts.substr(0, slash));
      const int numFloats =
          parser.integer(line, counts.substr(slash + 1, secondSlash == std::string::npos
                                                            ? std::string::npos
                                                            : secondSlash - slash - 1));
      const bool isCrease = line.tokens[1] == "crease";
      const int perItem = isCrease ? 2 : 1;
      // Counts up to INT_MAX each: summed unsigned, after the signs are checked (int overflowed).
      if (numInts <= 0 || numFloats < 0 || numInts % perItem != 0 ||
          line.tokens.size() < 3 + static_cast<size_t>(numInts) + static_cast<size_t>(numFloats)) {
        parser.fail(line.number, "malformed '" + line.tokens[1] + "' tag");
      }
      const int items = numInts / perItem;
      if (numFloats != 1 && numFloats != items) {
        parser.fail(line.number, "a '" + line.tokens[1] + "' tag needs one sharpness or one per " +
                                     (isCrease ? "edge" : "vertex"));
      }
      for (int item = 0; item < items; ++item) {
        const size_t first = 3 + static_cast<size_t>(item * perItem);
        const double sharpness =
            objSharpness(line, line.tokens[3 + static_cast<size_t>(numInts) +
                                           static_cast<size_t>(numFloats == 1 ? 0 : item)]);
        if (isCrease) {
          creases.push_back({parser.integer(line, line.tokens[first]),
                             parser.integer(line, line.tokens[first + 1])});
          creaseSharpness.push_back(sharpness);
        } else {
          corners.push_back(parser.integer(line, line.tokens[first]));
          cornerSharpness.push_back(sharpness);
        }
      }
    }
    // Everything else (vt, vn, g, o, s, usemtl, other tags, ...) does not describe the polyhedron.
  }
  const auto numVertices = static_cast<Eigen::Index>(coordinates.size() / 3);
  RowMatrixX3d vertices = Eigen::Map<const RowMatrixX3d>(coordinates.data(), numVertices, 3);
  return parser.build(std::move(vertices), std::move(sizes), std::move(indices), creases,
                      creaseSharpness, std::move(corners), cornerSharpness);
}

void writeControlMeshText(const ControlMesh& mesh, std::ostream& out) {
  out << kTextMagic << " 1\n";
  out << "vertices " << mesh.numVertices() << '\n';
  for (int v = 0; v < mesh.numVertices(); ++v) {
    out << formatReal(mesh.vertices()(v, 0)) << ' ' << formatReal(mesh.vertices()(v, 1)) << ' '
        << formatReal(mesh.vertices()(v, 2)) << '\n';
  }
  out << "faces " << mesh.numFaces() << '\n';
  for (int f = 0; f < mesh.numFaces(); ++f) {
    out << mesh.faceSize(f);
    for (int i = 0; i < mesh.faceSize(f); ++i) out << ' ' << mesh.faceVertex(f, i);
    out << '\n';
  }
  out << "creases " << mesh.creases().rows() << '\n';
  for (Eigen::Index c = 0; c < mesh.creases().rows(); ++c) {
    out << mesh.creases()(c, 0) << ' ' << mesh.creases()(c, 1) << ' '
        << formatReal(mesh.creaseSharpness()(c)) << '\n';
  }
  out << "corners " << mesh.corners().size() << '\n';
  for (size_t c = 0; c < mesh.corners().size(); ++c) {
    out << mesh.corners()[c] << ' '
        << formatReal(mesh.cornerSharpness()(static_cast<Eigen::Index>(c))) << '\n';
  }
}

void writeControlMeshObj(const ControlMesh& mesh, std::ostream& out) {
  const auto objSharpness = [](double sharpness) {
    return formatReal(sharpness >= kObjInfiniteSharpness ? kObjInfiniteSharpness : sharpness);
  };
  out << "# BVMesh control mesh: creases and corners as OpenSubdiv tags (0-based vertex ids,\n"
         "# sharpness 10 = infinitely sharp)\n";
  for (int v = 0; v < mesh.numVertices(); ++v) {
    out << "v " << formatReal(mesh.vertices()(v, 0)) << ' ' << formatReal(mesh.vertices()(v, 1))
        << ' ' << formatReal(mesh.vertices()(v, 2)) << '\n';
  }
  for (int f = 0; f < mesh.numFaces(); ++f) {
    out << 'f';
    for (int i = 0; i < mesh.faceSize(f); ++i) out << ' ' << mesh.faceVertex(f, i) + 1;
    out << '\n';
  }
  for (Eigen::Index c = 0; c < mesh.creases().rows(); ++c) {
    out << "t crease 2/1/0 " << mesh.creases()(c, 0) << ' ' << mesh.creases()(c, 1) << ' '
        << objSharpness(mesh.creaseSharpness()(c)) << '\n';
  }
  for (size_t c = 0; c < mesh.corners().size(); ++c) {
    out << "t corner 1/1/0 " << mesh.corners()[c] << ' '
        << objSharpness(mesh.cornerSharpness()(static_cast<Eigen::Index>(c))) << '\n';
  }
}

ControlMesh readControlMesh(const std::string& path, ControlMeshFormat format) {
  std::ifstream in = openInputFile(path, "the control mesh file");
  return resolve(format, path) == ControlMeshFormat::Obj ? readControlMeshObj(in, path)
                                                         : readControlMeshText(in, path);
}

void writeControlMesh(const ControlMesh& mesh, const std::string& path, ControlMeshFormat format) {
  std::ofstream out(path);
  if (!out) throw InvalidInputError("cannot write control mesh file " + path);
  if (resolve(format, path) == ControlMeshFormat::Obj) {
    writeControlMeshObj(mesh, out);
  } else {
    writeControlMeshText(mesh, out);
  }
  out.flush();
  if (!out) throw InvalidInputError("writing control mesh file " + path + " failed");
}

}  // namespace bvmesh

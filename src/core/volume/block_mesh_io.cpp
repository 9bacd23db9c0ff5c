#include "core/volume/block_mesh_io.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>

#include "core/common/atomic_file.h"
#include "core/common/errors.h"
#include "core/common/input_file.h"

namespace bvmesh::volume {
namespace {

constexpr const char* kMagic = "bvmesh-blocks";
constexpr int kVersion = 1;

BoundaryCondition conditionOf(const std::string& word, const std::string& where) {
  const std::optional<BoundaryCondition> condition = findBoundaryCondition(word);
  if (!condition) throw InvalidInputError(where + ": unknown boundary condition '" + word + "'");
  return *condition;
}

// Reads whitespace-separated tokens and counts lines, for messages that say where.
class Reader {
 public:
  Reader(std::istream& in, std::string name) : in_(in), name_(std::move(name)) {}

  std::string where() const { return name_ + ", line " + std::to_string(line_); }

  std::string word() {
    std::string token;
    char c = 0;
    while (in_.get(c)) {
      if (c == '\n') ++line_;
      if (c == '#') {
        while (in_.get(c) && c != '\n') {
        }
        ++line_;
        continue;
      }
      if (!std::isspace(static_cast<unsigned char>(c))) {
        token.push_back(c);
        break;
      }
    }
    while (in_.get(c)) {
      if (std::isspace(static_cast<unsigned char>(c))) {
        in_.unget();
        break;
      }
      token.push_back(c);
    }
    if (token.empty()) throw InvalidInputError(where() + ": the file ends early");
    return token;
  }

  void expect(const std::string& keyword) {
    const std::string got = word();
    if (got != keyword) throw InvalidInputError(where() + ": expected '" + keyword + "', got '" + got + "'");
  }

  long integer(long lo, long hi, const char* what) {
    const std::string token = word();
    char* end = nullptr;
    const long value = std::strtol(token.c_str(), &end, 10);
    if (end == token.c_str() || *end != '\0' || value < lo || value > hi) {
      throw InvalidInputError(where() + ": " + what + " must be an integer in [" + std::to_string(lo) + ", " +
                              std::to_string(hi) + "], got '" + token + "'");
    }
    return value;
  }

  double number(const char* what) {
    const std::string token = word();
    char* end = nullptr;
    const double value = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0' || !std::isfinite(value)) {
      throw InvalidInputError(where() + ": " + what + " must be a finite number, got '" + token + "'");
    }
    return value;
  }

 private:
  std::istream& in_;
  std::string name_;
  int line_ = 1;
};

}  // namespace

void writeBlockMesh(const BlockMesh& mesh, std::ostream& out) {
  out << kMagic << ' ' << kVersion << '\n';
  out << "blocks " << mesh.blockCount() << '\n';
  out << std::setprecision(17);
  for (int b = 0; b < mesh.blockCount(); ++b) {
    const Block& block = mesh.blocks()[static_cast<size_t>(b)];
    const BsplineVolume& volume = block.volume;
    out << "block " << b << '\n';
    for (int d = 0; d < 3; ++d) {
      out << "knots " << "uvw"[d] << ' ' << volume.degree(d) << ' ' << volume.knots(d).size();
      for (double k : volume.knots(d)) out << ' ' << k;
      out << '\n';
    }
    out << "poles " << volume.poleCount(0) << ' ' << volume.poleCount(1) << ' ' << volume.poleCount(2)
        << "  # u fastest, then v, then w\n";
    for (Eigen::Index r = 0; r < volume.poles().rows(); ++r) {
      out << volume.poles()(r, 0) << ' ' << volume.poles()(r, 1) << ' ' << volume.poles()(r, 2) << '\n';
    }
    for (int f = 0; f < 6; ++f) {
      const BlockFace& face = block.faces[static_cast<size_t>(f)];
      out << "face " << blockFaceName(f) << ' ' << boundaryConditionName(face.condition);
      if (face.condition == BoundaryCondition::Connected) {
        out << ' ' << face.neighbour.block << ' ' << blockFaceName(face.neighbour.face) << ' '
            << int(face.neighbour.swapped) << ' ' << int(face.neighbour.reverseFirst) << ' '
            << int(face.neighbour.reverseSecond);
      }
      out << '\n';
    }
  }
  out << "end\n";
}

void writeBlockMeshFile(const BlockMesh& mesh, const std::string& path) {
  writeFileAtomically(path, "the block mesh file", [&](std::ostream& out) { writeBlockMesh(mesh, out); });
}

BlockMesh readBlockMesh(std::istream& in, const std::string& name) {
  Reader reader(in, name);
  reader.expect(kMagic);
  const long version = reader.integer(1, 1000, "the format version");
  if (version != kVersion) {
    throw InvalidInputError(reader.where() + ": format version " + std::to_string(version) + " (this build reads " +
                            std::to_string(kVersion) + ")");
  }
  reader.expect("blocks");
  const long count = reader.integer(0, 1000000, "the block count");
  std::vector<Block> blocks;
  for (long b = 0; b < count; ++b) {
    reader.expect("block");
    reader.integer(b, b, "the block number");
    std::array<int, 3> degrees{};
    std::array<std::vector<double>, 3> knots;
    for (int d = 0; d < 3; ++d) {
      reader.expect("knots");
      reader.expect(std::string(1, "uvw"[d]));
      degrees[static_cast<size_t>(d)] = static_cast<int>(reader.integer(1, 7, "the degree"));
      const long n = reader.integer(2, 100000, "the knot count");
      for (long k = 0; k < n; ++k) knots[static_cast<size_t>(d)].push_back(reader.number("a knot"));
    }
    reader.expect("poles");
    std::array<long, 3> counts{};
    for (long& c : counts) c = reader.integer(1, 100000, "a pole count");
    // Checked against the knots before the poles are allocated: a short file could otherwise
    // reserve gigabytes by its header alone.
    for (int d = 0; d < 3; ++d) {
      const long fromKnots =
          static_cast<long>(knots[static_cast<size_t>(d)].size()) - degrees[static_cast<size_t>(d)] - 1;
      if (counts[static_cast<size_t>(d)] != fromKnots) {
        throw InvalidInputError(reader.where() + ": block " + std::to_string(b) + " lists " +
                                std::to_string(counts[static_cast<size_t>(d)]) + " poles along " + "uvw"[d] +
                                ", its knots give " + std::to_string(fromKnots));
      }
    }
    const long total = counts[0] * counts[1] * counts[2];
    if (total > 50000000) throw InvalidInputError(reader.where() + ": " + std::to_string(total) + " poles in one block is too many");
    RowMatrixX3d poles(total, 3);
    for (long r = 0; r < total; ++r) {
      for (int x = 0; x < 3; ++x) poles(r, x) = reader.number("a pole coordinate");
    }
    Block block;
    block.volume =
        BsplineVolume(degrees, std::move(knots), std::move(poles), name + ", block " + std::to_string(b));
    for (int f = 0; f < 6; ++f) {
      reader.expect("face");
      reader.expect(blockFaceName(f));
      BlockFace& face = block.faces[static_cast<size_t>(f)];
      face.condition = conditionOf(reader.word(), reader.where());
      if (face.condition == BoundaryCondition::Connected) {
        face.neighbour.block = static_cast<int>(reader.integer(0, count - 1, "the neighbour block"));
        const std::string neighbourFace = reader.word();
        face.neighbour.face = -1;
        for (int g = 0; g < 6; ++g) {
          if (neighbourFace == blockFaceName(g)) face.neighbour.face = g;
        }
        if (face.neighbour.face < 0) throw InvalidInputError(reader.where() + ": unknown block face '" + neighbourFace + "'");
        face.neighbour.swapped = reader.integer(0, 1, "the swapped flag") == 1;
        face.neighbour.reverseFirst = reader.integer(0, 1, "the first reverse flag") == 1;
        face.neighbour.reverseSecond = reader.integer(0, 1, "the second reverse flag") == 1;
      }
    }
    blocks.push_back(std::move(block));
  }
  reader.expect("end");
  return BlockMesh(std::move(blocks));
}

BlockMesh readBlockMeshFile(const std::string& path) {
  std::ifstream in = openInputFile(path, "the block mesh file");
  return readBlockMesh(in, "\"" + path + "\"");
}

}  // namespace bvmesh::volume

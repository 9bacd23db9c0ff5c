#include "core/io/plot3d_io.h"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <limits>
#include <sstream>

#include "core/common/atomic_file.h"
#include "core/common/errors.h"
#include "core/common/input_file.h"
#include "core/io/io_common.h"

namespace bvmesh::io {
namespace {

// Bounds for reading, so that a damaged header fails with a message rather than an allocation.
constexpr long kMaxBlocks = 1000000;
constexpr long kMaxPointsPerBlock = std::numeric_limits<std::int32_t>::max() / 24;

std::string blockText(size_t b) { return "block " + std::to_string(b); }

// A Fortran record: its length before and after the payload.
void putRecord(std::ostream& out, const std::string& payload) {
  std::string marker;
  appendInt32(marker, static_cast<std::int32_t>(payload.size()));
  out << marker << payload << marker;
}

// A block's coordinate record, streamed rather than built whole.
void putCoordinateRecord(std::ostream& out, const grid::GridBlock& block) {
  std::string marker;
  appendInt32(marker, static_cast<std::int32_t>(24 * block.pointCount()));
  out << marker;
  for (int x = 0; x < 3; ++x) writeFloat64s(out, block.points.data() + x, static_cast<size_t>(block.pointCount()), 3);
  out << marker;
}

void writeBinary(const grid::StructuredGrid& grid, std::ostream& out) {
  std::string record;
  appendInt32(record, grid.blockCount());
  putRecord(out, record);
  record.clear();
  for (const grid::GridBlock& block : grid.blocks()) {
    for (int n : block.size) appendInt32(record, n);
  }
  putRecord(out, record);
  for (const grid::GridBlock& block : grid.blocks()) putCoordinateRecord(out, block);
}

void writeAscii(const grid::StructuredGrid& grid, std::ostream& out) {
  out << grid.blockCount() << '\n';
  for (const grid::GridBlock& block : grid.blocks()) out << block.size[0] << ' ' << block.size[1] << ' ' << block.size[2] << '\n';
  out << std::setprecision(17);
  for (const grid::GridBlock& block : grid.blocks()) {
    for (int x = 0; x < 3; ++x) {
      for (Eigen::Index r = 0; r < block.pointCount(); ++r) {
        out << block.points(r, x) << ((r + 1) % 4 == 0 || r + 1 == block.pointCount() ? '\n' : ' ');
      }
    }
  }
}

// Sizes as the header gives them, checked before anything is allocated.
Plot3dBlock emptyBlock(const std::array<long, 3>& size, size_t b, const std::string& name) {
  long points = 1;
  for (long n : size) {
    if (n < 1 || n > kMaxPointsPerBlock) {
      throw InvalidInputError(name + ": " + blockText(b) + " has a bad size " + std::to_string(n));
    }
    points *= n;
    if (points > kMaxPointsPerBlock) {
      throw InvalidInputError(name + ": " + blockText(b) + " has too many points (" + std::to_string(size[0]) + " x " +
                              std::to_string(size[1]) + " x " + std::to_string(size[2]) + ")");
    }
  }
  Plot3dBlock block;
  block.size = {static_cast<int>(size[0]), static_cast<int>(size[1]), static_cast<int>(size[2])};
  block.points.resize(points, 3);
  return block;
}

// Reads the Fortran records of a binary file in order, checking their frames.
class RecordReader {
 public:
  RecordReader(std::string bytes, std::string name) : bytes_(std::move(bytes)), name_(std::move(name)) {}

  // The payload of the next record, which must be `expected` bytes long.
  const unsigned char* next(size_t expected, const std::string& what) {
    if (bytes_.size() - position_ < 4) throw InvalidInputError(name_ + " is truncated: " + what + " is missing");
    const size_t length = static_cast<size_t>(readLittleEndian(data() + position_, 4));
    if (length != expected) {
      throw InvalidInputError(name_ + ": the record of " + what + " has " + std::to_string(length) +
                              " bytes, the header says " + std::to_string(expected));
    }
    if (bytes_.size() - position_ < length + 8) {
      throw InvalidInputError(name_ + " is truncated: " + what + " has " + std::to_string(bytes_.size() - position_ - 4) +
                              " of its " + std::to_string(length + 4) + " bytes");
    }
    const unsigned char* payload = data() + position_ + 4;
    if (readLittleEndian(payload + length, 4) != length) {
      throw InvalidInputError(name_ + ": the record of " + what + " does not end with its length (not a Plot3D file?)");
    }
    position_ += length + 8;
    return payload;
  }

  void expectEnd() const {
    if (position_ != bytes_.size()) {
      throw InvalidInputError(name_ + " has " + std::to_string(bytes_.size() - position_) + " bytes after the last block");
    }
  }

 private:
  const unsigned char* data() const { return reinterpret_cast<const unsigned char*>(bytes_.data()); }

  std::string bytes_;
  std::string name_;
  size_t position_ = 0;
};

std::vector<Plot3dBlock> readBinary(std::string bytes, const std::string& name) {
  RecordReader reader(std::move(bytes), name);
  const auto count = static_cast<std::int32_t>(readLittleEndian(reader.next(4, "the block count"), 4));
  if (count < 1 || count > kMaxBlocks) throw InvalidInputError(name + ": bad block count " + std::to_string(count));
  const unsigned char* dims = reader.next(static_cast<size_t>(12 * count), "the block sizes");
  std::vector<Plot3dBlock> blocks;
  for (size_t b = 0; b < static_cast<size_t>(count); ++b) {
    std::array<long, 3> size{};
    for (size_t d = 0; d < 3; ++d) size[d] = static_cast<std::int32_t>(readLittleEndian(dims + 4 * (3 * b + d), 4));
    blocks.push_back(emptyBlock(size, b, name));
  }
  for (size_t b = 0; b < blocks.size(); ++b) {
    RowMatrixX3d& points = blocks[b].points;
    const unsigned char* data = reader.next(static_cast<size_t>(24 * points.rows()), "the coordinates of " + blockText(b));
    for (int x = 0; x < 3; ++x) {
      for (Eigen::Index r = 0; r < points.rows(); ++r) {
        points(r, x) = readFloat64(data + 8 * (x * points.rows() + r));
      }
    }
  }
  reader.expectEnd();
  return blocks;
}

std::vector<Plot3dBlock> readAscii(const std::string& text, const std::string& name) {
  std::istringstream in(text);
  auto integer = [&](const std::string& what) {
    long value = 0;
    if (!(in >> value)) {
      throw InvalidInputError(name + (in.eof() ? " is truncated: " : ": cannot read ") + what + " (not a Plot3D file?)");
    }
    return value;
  };
  const long count = integer("the block count");
  if (count < 1 || count > kMaxBlocks) throw InvalidInputError(name + ": bad block count " + std::to_string(count));
  std::vector<Plot3dBlock> blocks;
  for (size_t b = 0; b < static_cast<size_t>(count); ++b) {
    std::array<long, 3> size{};
    for (long& n : size) n = integer("the size of " + blockText(b));
    blocks.push_back(emptyBlock(size, b, name));
  }
  for (size_t b = 0; b < blocks.size(); ++b) {
    RowMatrixX3d& points = blocks[b].points;
    for (int x = 0; x < 3; ++x) {
      for (Eigen::Index r = 0; r < points.rows(); ++r) {
        if (!(in >> points(r, x)) || !std::isfinite(points(r, x))) {
          throw InvalidInputError(name + (in.eof() ? " is truncated: " : ": bad number in ") + "the " + "xyz"[x] +
                                  " coordinates of " + blockText(b) + " after " + std::to_string(r) + " of " +
                                  std::to_string(points.rows()));
        }
      }
    }
  }
  if (in >> std::ws && !in.eof()) throw InvalidInputError(name + " has data after the last block");
  return blocks;
}

}  // namespace

void writePlot3d(const grid::StructuredGrid& grid, const std::string& path, Plot3dFormat format) {
  for (size_t b = 0; b < grid.blocks().size(); ++b) {
    if (grid.blocks()[b].pointCount() > kMaxPointsPerBlock) {
      throw InvalidInputError("cannot write the Plot3D file \"" + path + "\": " + blockText(b) + " has " +
                              std::to_string(grid.blocks()[b].pointCount()) + " points, more than an int32 record holds (" +
                              std::to_string(kMaxPointsPerBlock) + ")");
    }
  }
  writeFileAtomically(path, "the Plot3D file", [&](std::ostream& out) {
    if (format == Plot3dFormat::Binary) writeBinary(grid, out);
    else writeAscii(grid, out);
  });
}

std::vector<Plot3dBlock> readPlot3d(const std::string& path) {
  std::ifstream in = openInputFile(path, "the Plot3D file", std::ios::in | std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string name = "the Plot3D file \"" + path + "\"";
  // A binary file opens with the 4-byte length of the block-count record; no text starts so.
  const bool binary = bytes.size() >= 4 && readLittleEndian(reinterpret_cast<const unsigned char*>(bytes.data()), 4) == 4;
  return binary ? readBinary(std::move(bytes), name) : readAscii(bytes, name);
}

}  // namespace bvmesh::io

// The solver-file writers (src/core/io) on a 2 x 2 x 2 box of blocks turned and mirrored against
// each other, so that the connections use the swapped and reversed flags: every file is read back
// (CGNS through libcgns and cgnscheck, Plot3D through readPlot3d, VTK and G+Smo XML by small
// parsers here) and its connectivity checked point by point against the grid.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cgns_io.h>
#include <cgnslib.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <regex>
#include <sstream>

#include "core/common/bspline_basis.h"
#include "core/common/errors.h"
#include "block_fixtures.h"
#include "core/grid/refinement.h"
#include "core/io/cgns_writer.h"
#include "core/io/gismo_writer.h"
#include "core/io/io_common.h"
#include "core/io/plot3d_io.h"
#include "core/io/vtk_writer.h"
#include "core/mesh/mesh_io.h"
#include "core/volume/block_mesh_io.h"

namespace bvmesh::io {
namespace {

namespace fs = std::filesystem;
using grid::GridBlock;
using grid::StructuredGrid;
using volume::BlockFace;
using volume::BoundaryCondition;

std::string outputPath(const std::string& name) { return std::string(BVMESH_TEST_OUTPUT_DIR) + "/" + name; }

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// ---------------------------------------------------------------------------------------------
// The box: lattice cell (cx, cy, cz) holds one block whose local direction l runs along global
// axis axis[l], backwards when flip[l]. All turns are proper rotations except block 7, a mirror
// image, so that one block is left-handed.
struct Placement {
  std::array<int, 3> cell;
  std::array<int, 3> axis;
  std::array<bool, 3> flip;
};

const std::vector<Placement> kPlacements = {
    {{0, 0, 0}, {0, 1, 2}, {false, false, false}}, {{1, 0, 0}, {1, 0, 2}, {true, false, false}},
    {{0, 1, 0}, {2, 0, 1}, {false, false, false}}, {{1, 1, 0}, {0, 2, 1}, {false, true, false}},
    {{0, 0, 1}, {0, 1, 2}, {true, true, false}},   {{1, 0, 1}, {1, 2, 0}, {false, false, false}},
    {{0, 1, 1}, {2, 1, 0}, {true, false, false}},  {{1, 1, 1}, {0, 1, 2}, {false, false, true}},
};

// Integer global coordinates of a block's grid positions: equal keys are the same place, so shared
// faces are found by key and their points, computed from the key alone, are identical bit for bit.
using Key = std::array<long, 3>;

struct KeyedBlock {
  std::array<int, 3> size{};
  std::vector<Key> keys;  // row i + ni * (j + nj * k)
};

// `count(axis, cell)`: positions along a global axis in a cell; `along(axis, cell, t, flipped)`:
// the global key of local position t.
template <class Count, class Along>
std::vector<KeyedBlock> keyedBlocks(Count count, Along along) {
  std::vector<KeyedBlock> blocks;
  for (const Placement& place : kPlacements) {
    KeyedBlock block;
    for (size_t l = 0; l < 3; ++l) block.size[l] = count(place.axis[l], place.cell[static_cast<size_t>(place.axis[l])]);
    for (int k = 0; k < block.size[2]; ++k) {
      for (int j = 0; j < block.size[1]; ++j) {
        for (int i = 0; i < block.size[0]; ++i) {
          const std::array<int, 3> local{i, j, k};
          Key key{};
          for (size_t l = 0; l < 3; ++l) {
            const int a = place.axis[l];
            key[static_cast<size_t>(a)] = along(a, place.cell[static_cast<size_t>(a)], local[l], place.flip[l]);
          }
          block.keys.push_back(key);
        }
      }
    }
    blocks.push_back(std::move(block));
  }
  return blocks;
}

// Outer faces of the box by global axis and end: x = 0 wall, y = 0 symmetry, z = 0 inlet, z = max
// outlet, the rest far field.
BoundaryCondition outerCondition(int axis, int end) {
  if (axis == 0 && end == 0) return BoundaryCondition::Wall;
  if (axis == 1 && end == 0) return BoundaryCondition::Symmetry;
  if (axis == 2) return end == 0 ? BoundaryCondition::Inlet : BoundaryCondition::Outlet;
  return BoundaryCondition::Farfield;
}

Key faceKey(const KeyedBlock& block, int face, int a, int b) {
  const std::array<int, 3> ijk = volume::faceGridPosition(block.size, face, a, b);
  return block.keys[static_cast<size_t>(ijk[0] + block.size[0] * (ijk[1] + block.size[1] * ijk[2]))];
}

// The faces of every block: outer conditions, or the connection found by matching keys (the
// structured grid and block mesh constructors then check it independently).
std::vector<std::array<BlockFace, 6>> boxFaces(const std::vector<KeyedBlock>& blocks) {
  std::vector<std::array<BlockFace, 6>> faces(blocks.size());
  for (size_t b = 0; b < blocks.size(); ++b) {
    const Placement& place = kPlacements[b];
    for (int f = 0; f < 6; ++f) {
      const auto l = static_cast<size_t>(f / 2);
      const int axis = place.axis[l];
      const int end = (f % 2) ^ static_cast<int>(place.flip[l]);
      std::array<int, 3> cell = place.cell;
      cell[static_cast<size_t>(axis)] += end == 1 ? 1 : -1;
      BlockFace& face = faces[b][static_cast<size_t>(f)];
      if (cell[static_cast<size_t>(axis)] < 0 || cell[static_cast<size_t>(axis)] > 1) {
        face.condition = outerCondition(axis, end);
        continue;
      }
      size_t n = 0;
      while (kPlacements[n].cell != cell) ++n;
      const Placement& other = kPlacements[n];
      int m = 0;
      while (other.axis[static_cast<size_t>(m)] != axis) ++m;
      const int g = 2 * m + ((1 - end) ^ static_cast<int>(other.flip[static_cast<size_t>(m)]));
      // Where face positions (0, 0), (1, 0), (0, 1) land on the neighbour face.
      const std::array<int, 2> counts = volume::faceGridCounts(blocks[n].size, g);
      auto find = [&](int a, int c) {
        const Key key = faceKey(blocks[b], f, a, c);
        for (int x = 0; x < counts[0]; ++x) {
          for (int y = 0; y < counts[1]; ++y) {
            if (faceKey(blocks[n], g, x, y) == key) return std::array<int, 2>{x, y};
          }
        }
        ADD_FAILURE() << "no match for block " << b << " face " << f;
        return std::array<int, 2>{0, 0};
      };
      const std::array<int, 2> p00 = find(0, 0), p10 = find(1, 0), p01 = find(0, 1);
      volume::FaceConnection& link = face.neighbour;
      face.condition = BoundaryCondition::Connected;
      link.block = static_cast<int>(n);
      link.face = g;
      link.swapped = p10[0] == p00[0];
      link.reverseFirst = link.swapped ? p01[0] < p00[0] : p10[0] < p00[0];
      link.reverseSecond = link.swapped ? p10[1] < p00[1] : p01[1] < p00[1];
    }
  }
  return faces;
}

// A smooth, nearly identity map of the unit box, so every point is somewhere else.
Eigen::Vector3d boxMap(double s, double t, double r) {
  return {s + 0.1 * std::sin(2.0 * t) + 0.05 * r, t + 0.1 * std::sin(3.0 * r) - 0.02 * s, r + 0.1 * s * s + 0.03 * t};
}

// Points per cell along each global axis: different everywhere, so a swapped axis shows.
const std::array<std::array<int, 2>, 3> kPoints = {{{5, 6}, {4, 5}, {3, 5}}};

StructuredGrid boxGrid(bool viscousWall = true) {
  const auto count = [](int a, int c) { return kPoints[static_cast<size_t>(a)][static_cast<size_t>(c)]; };
  const auto along = [&](int a, int c, int t, bool flipped) {
    const int n = count(a, c);
    return static_cast<long>(c == 0 ? 0 : count(a, 0) - 1) + (flipped ? n - 1 - t : t);
  };
  const std::vector<KeyedBlock> keyed = keyedBlocks(count, along);
  const std::vector<std::array<BlockFace, 6>> faces = boxFaces(keyed);
  std::vector<GridBlock> blocks(keyed.size());
  for (size_t b = 0; b < keyed.size(); ++b) {
    blocks[b].size = keyed[b].size;
    blocks[b].faces = faces[b];
    blocks[b].points.resize(static_cast<Eigen::Index>(keyed[b].keys.size()), 3);
    for (size_t r = 0; r < keyed[b].keys.size(); ++r) {
      const Key& key = keyed[b].keys[r];
      blocks[b].points.row(static_cast<Eigen::Index>(r)) = boxMap(key[0] / 9.0, key[1] / 7.0, key[2] / 6.0).transpose();
    }
  }
  return StructuredGrid(std::move(blocks), viscousWall);
}

// Tricubic blocks on uniform knots, spans per cell along each global axis. A pole's key is three
// times its global Greville abscissa, an integer, so mirrored blocks agree on it exactly.
const std::array<std::array<int, 2>, 3> kSpans = {{{2, 3}, {3, 2}, {2, 4}}};

volume::BlockMesh boxBlockMesh() {
  const auto spans = [](int a, int c) { return kSpans[static_cast<size_t>(a)][static_cast<size_t>(c)]; };
  const auto count = [&](int a, int c) { return spans(a, c) + 3; };
  // Greville abscissa of pole t of uniformClampedKnots(3, s), times 3: the sum of knots t+1..t+3.
  const auto greville3 = [](int s, int t) {
    long sum = 0;
    for (int j = t + 1; j <= t + 3; ++j) sum += std::min(std::max(j - 3, 0), s);
    return sum;
  };
  const auto along = [&](int a, int c, int t, bool flipped) {
    const int s = spans(a, c);
    return 3L * (c == 0 ? 0 : spans(a, 0)) + (flipped ? 3L * s - greville3(s, t) : greville3(s, t));
  };
  const std::vector<KeyedBlock> keyed = keyedBlocks(count, along);
  const std::vector<std::array<BlockFace, 6>> faces = boxFaces(keyed);
  std::vector<volume::Block> blocks(keyed.size());
  for (size_t b = 0; b < keyed.size(); ++b) {
    RowMatrixX3d poles(static_cast<Eigen::Index>(keyed[b].keys.size()), 3);
    for (size_t r = 0; r < keyed[b].keys.size(); ++r) {
      const Key& key = keyed[b].keys[r];
      poles.row(static_cast<Eigen::Index>(r)) = boxMap(key[0] / 15.0, key[1] / 15.0, key[2] / 18.0).transpose();
    }
    std::array<std::vector<double>, 3> knots;
    for (size_t l = 0; l < 3; ++l) knots[l] = uniformClampedKnots(3, keyed[b].size[l] - 3);
    blocks[b].volume = volume::BsplineVolume({3, 3, 3}, knots, poles);
    blocks[b].faces = faces[b];
  }
  return volume::BlockMesh(std::move(blocks));
}

TEST(IoBox, ConnectionsUseEveryOrientationFlag) {
  const StructuredGrid grid = boxGrid();
  int swapped = 0, reversed = 0, connected = 0;
  for (const GridBlock& block : grid.blocks()) {
    for (const BlockFace& face : block.faces) {
      if (face.condition != BoundaryCondition::Connected) continue;
      ++connected;
      swapped += face.neighbour.swapped;
      reversed += face.neighbour.reverseFirst + face.neighbour.reverseSecond;
    }
  }
  EXPECT_EQ(connected, 24);  // 12 shared faces, each seen from both sides
  EXPECT_GT(swapped, 0);
  EXPECT_GT(reversed, 0);
  EXPECT_NO_THROW(boxBlockMesh());
}

// ---------------------------------------------------------------------------------------------
// CGNS

struct CgnsReader {
  explicit CgnsReader(const std::string& path) {
    if (cg_open(path.c_str(), CG_MODE_READ, &fn) != CG_OK) ADD_FAILURE() << cg_get_error();
  }
  ~CgnsReader() { cg_close(fn); }
  int fn = -1;
};

#define CG(call) ASSERT_EQ(call, CG_OK) << cg_get_error()

CGNS_ENUMT(BCType_t) expectedType(const std::string& family, bool viscous) {
  if (family == "wall") return viscous ? CGNS_ENUMV(BCWallViscous) : CGNS_ENUMV(BCWall);
  if (family == "symmetry") return CGNS_ENUMV(BCSymmetryPlane);
  if (family == "inlet") return CGNS_ENUMV(BCInflow);
  if (family == "outlet") return CGNS_ENUMV(BCOutflow);
  return CGNS_ENUMV(BCFarfield);
}

// One-based CGNS (i, j, k) to the row of a grid block.
Eigen::Index row(const GridBlock& block, const std::array<cgsize_t, 3>& ijk) {
  return block.index(static_cast<int>(ijk[0] - 1), static_cast<int>(ijk[1] - 1), static_cast<int>(ijk[2] - 1));
}

// A zone's BC_t node: its name, family, type and point set.
struct BocoInfo {
  std::string name, family;
  CGNS_ENUMT(BCType_t) type = CGNS_ENUMV(BCTypeNull);
  CGNS_ENUMT(PointSetType_t) pointSet = CGNS_ENUMV(PointSetTypeNull);
  cgsize_t pointCount = 0;
};

void readBoco(int fn, int zone, int bc, BocoInfo& info) {
  char name[64], family[64];
  CGNS_ENUMT(DataType_t) normalType;
  cgsize_t normalSize = 0;
  int normalIndex[3], datasets = 0;
  CG(cg_boco_info(fn, 1, zone, bc, name, &info.type, &info.pointSet, &info.pointCount, normalIndex, &normalSize,
                  &normalType, &datasets));
  CG(cg_goto(fn, 1, "Zone_t", zone, "ZoneBC_t", 1, "BC_t", bc, "end"));
  CG(cg_famname_read(family));
  info.name = name;
  info.family = family;
}

void checkCgnsFile(const StructuredGrid& grid, const std::string& path) {
  CgnsReader file(path);
  int bases = 0, cellDim = 0, physDim = 0, zones = 0;
  char name[64];
  CG(cg_nbases(file.fn, &bases));
  ASSERT_EQ(bases, 1);
  CG(cg_base_read(file.fn, 1, name, &cellDim, &physDim));
  EXPECT_EQ(cellDim, 3);
  EXPECT_EQ(physDim, 3);
  CG(cg_nzones(file.fn, 1, &zones));
  ASSERT_EQ(zones, grid.blockCount());
  std::map<std::string, int> zoneOfName;
  for (int z = 1; z <= zones; ++z) {
    cgsize_t size[9];
    CG(cg_zone_read(file.fn, 1, z, name, size));
    zoneOfName[name] = z - 1;
  }
  // Coordinates, bit for bit.
  std::vector<RowMatrixX3d> points(static_cast<size_t>(zones));
  for (int z = 1; z <= zones; ++z) {
    cgsize_t size[9];
    CG(cg_zone_read(file.fn, 1, z, name, size));
    ASSERT_EQ(zoneOfName.count(blockName(z - 1)), 1u);
    const GridBlock& block = grid.blocks()[static_cast<size_t>(zoneOfName[name])];
    for (int d = 0; d < 3; ++d) {
      EXPECT_EQ(size[d], block.size[static_cast<size_t>(d)]);
      EXPECT_EQ(size[d + 3], block.size[static_cast<size_t>(d)] - 1);
    }
    const cgsize_t rmin[3] = {1, 1, 1}, rmax[3] = {size[0], size[1], size[2]};
    RowMatrixX3d& zonePoints = points[static_cast<size_t>(zoneOfName[name])];
    zonePoints.resize(block.pointCount(), 3);
    const char* coordinates[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    for (int x = 0; x < 3; ++x) {
      std::vector<double> values(static_cast<size_t>(block.pointCount()));
      CG(cg_coord_read(file.fn, 1, z, coordinates[x], CGNS_ENUMV(RealDouble), rmin, rmax, values.data()));
      for (Eigen::Index r = 0; r < block.pointCount(); ++r) zonePoints(r, x) = values[static_cast<size_t>(r)];
    }
    EXPECT_TRUE(zonePoints == block.points) << name;
  }
  // Every 1to1 connection: each point of PointRange, carried by Transform onto PointRangeDonor,
  // is the donor's identical point; the range's end lands on the donor range's end.
  int connections = 0;
  for (int z = 1; z <= zones; ++z) {
    cgsize_t size[9];
    CG(cg_zone_read(file.fn, 1, z, name, size));
    const int b = zoneOfName[name];
    int count = 0;
    CG(cg_n1to1(file.fn, 1, z, &count));
    connections += count;
    for (int c = 1; c <= count; ++c) {
      char connectName[64], donorName[64];
      cgsize_t range[6], donorRange[6];
      int t[3];
      CG(cg_1to1_read(file.fn, 1, z, c, connectName, donorName, range, donorRange, t));
      ASSERT_EQ(zoneOfName.count(donorName), 1u) << donorName;
      const int donor = zoneOfName[donorName];
      auto image = [&](const std::array<cgsize_t, 3>& p) {
        std::array<cgsize_t, 3> q{donorRange[0], donorRange[1], donorRange[2]};
        for (size_t d = 0; d < 3; ++d) {
          const auto target = static_cast<size_t>(std::abs(t[d]) - 1);
          q[target] += (t[d] > 0 ? 1 : -1) * (p[d] - range[d]);
        }
        return q;
      };
      const std::array<cgsize_t, 3> end = image({range[3], range[4], range[5]});
      EXPECT_EQ(end, (std::array<cgsize_t, 3>{donorRange[3], donorRange[4], donorRange[5]})) << connectName;
      int matched = 0;
      for (cgsize_t k = std::min(range[2], range[5]); k <= std::max(range[2], range[5]); ++k) {
        for (cgsize_t j = std::min(range[1], range[4]); j <= std::max(range[1], range[4]); ++j) {
          for (cgsize_t i = std::min(range[0], range[3]); i <= std::max(range[0], range[3]); ++i) {
            const std::array<cgsize_t, 3> q = image({i, j, k});
            const GridBlock& there = grid.blocks()[static_cast<size_t>(donor)];
            for (size_t d = 0; d < 3; ++d) ASSERT_TRUE(q[d] >= 1 && q[d] <= there.size[d]) << connectName;
            matched += points[static_cast<size_t>(b)].row(row(grid.blocks()[static_cast<size_t>(b)], {i, j, k})) ==
                       points[static_cast<size_t>(donor)].row(row(there, q));
          }
        }
      }
      // Across the face: the layer outside this zone maps into the donor, on the far side of the face.
      const std::array<cgsize_t, 3> begin{range[0], range[1], range[2]};
      size_t normal = 0;
      while (range[normal] != range[normal + 3]) ++normal;
      const cgsize_t inward = range[normal] == 1 ? 1 : -1;
      std::array<cgsize_t, 3> inside = begin, outside = begin;
      inside[normal] += inward;
      outside[normal] -= inward;
      const std::array<cgsize_t, 3> across = image(outside);
      const GridBlock& donorBlock = grid.blocks()[static_cast<size_t>(donor)];
      for (size_t d = 0; d < 3; ++d) ASSERT_TRUE(across[d] >= 1 && across[d] <= donorBlock.size[d]) << connectName;
      const Eigen::RowVector3d onFace = points[static_cast<size_t>(b)].row(row(grid.blocks()[static_cast<size_t>(b)], begin));
      const Eigen::RowVector3d here = points[static_cast<size_t>(b)].row(row(grid.blocks()[static_cast<size_t>(b)], inside));
      const Eigen::RowVector3d there = points[static_cast<size_t>(donor)].row(row(donorBlock, across));
      EXPECT_LT((here - onFace).dot(there - onFace), 0.0) << connectName;
      const cgsize_t total = (std::abs(range[3] - range[0]) + 1) * (std::abs(range[4] - range[1]) + 1) *
                             (std::abs(range[5] - range[2]) + 1);
      EXPECT_EQ(matched, total) << name << " " << connectName;
    }
  }
  EXPECT_EQ(connections, 24);
  // Boundary conditions: one per outer face, its family the condition, its type the family's.
  std::map<std::string, int> facesOfFamily;
  for (int z = 1; z <= zones; ++z) {
    int count = 0;
    CG(cg_nbocos(file.fn, 1, z, &count));
    for (int bc = 1; bc <= count; ++bc) {
      BocoInfo info;
      readBoco(file.fn, z, bc, info);
      EXPECT_EQ(info.pointSet, CGNS_ENUMV(PointRange));
      EXPECT_EQ(info.pointCount, 2);
      EXPECT_EQ(info.type, expectedType(info.family, grid.viscousWall())) << info.name;
      ++facesOfFamily[info.family];
    }
  }
  const std::map<std::string, int> expected = {{"wall", 4}, {"symmetry", 4}, {"inlet", 4}, {"outlet", 4}, {"farfield", 8}};
  EXPECT_EQ(facesOfFamily, expected);
  int families = 0;
  CG(cg_nfamilies(file.fn, 1, &families));
  EXPECT_EQ(families, 5);
  for (int f = 1; f <= families; ++f) {
    int bcs = 0, geometries = 0;
    CG(cg_family_read(file.fn, 1, f, name, &bcs, &geometries));
    ASSERT_EQ(bcs, 1) << name;
    char bcName[64];
    CGNS_ENUMT(BCType_t) type;
    CG(cg_fambc_read(file.fn, 1, f, 1, bcName, &type));
    EXPECT_EQ(type, expectedType(name, grid.viscousWall())) << name;
  }
}

TEST(IoCgns, ReadsBackPointsConnectionsAndBoundaryFamilies) {
  const std::string path = outputPath("io_box.cgns");
  const StructuredGrid viscous = boxGrid(true);
  writeCgns(viscous, path);
  checkCgnsFile(viscous, path);
  const StructuredGrid inviscid = boxGrid(false);
  writeCgns(inviscid, path);
  checkCgnsFile(inviscid, path);
  EXPECT_FALSE(fs::exists(path + ".partial"));
}

// cgnscheck exits 0 whatever it finds; its output is what counts. It prints one "ERROR:..." or
// "WARNING:..." line per finding, "checking complete" at the end and, only when it found some,
// "N errors" / "N warnings (M shown)". -w3 asks for every warning level.
struct CheckReport {
  bool complete = false;
  int errors = 0;
  int warnings = 0;
  std::string text;
};

CheckReport cgnscheck(const std::string& path) {
  CheckReport report;
  FILE* pipe = popen(("cgnscheck -w3 \"" + path + "\" 2>&1").c_str(), "r");
  if (pipe == nullptr) return report;
  char buffer[4096];
  while (fgets(buffer, sizeof(buffer), pipe) != nullptr) report.text += buffer;
  pclose(pipe);
  std::istringstream lines(report.text);
  std::smatch match;
  for (std::string line; std::getline(lines, line);) {
    report.complete |= line == "checking complete";
    report.errors += line.rfind("ERROR", 0) == 0;
    report.warnings += line.rfind("WARNING", 0) == 0;
    if (std::regex_match(line, match, std::regex("(\\d+) errors?"))) {
      report.errors = std::max(report.errors, std::stoi(match[1]));
    }
    if (std::regex_match(line, match, std::regex("(\\d+) warnings?.*"))) {
      report.warnings = std::max(report.warnings, std::stoi(match[1]));
    }
  }
  return report;
}

TEST(IoCgns, CgnscheckFindsNoErrorsOrWarnings) {
  if (std::system("command -v cgnscheck > /dev/null 2>&1") != 0) GTEST_SKIP() << "cgnscheck is not installed";
  const std::string path = outputPath("io_box_check.cgns");
  writeCgns(boxGrid(), path);
  const CheckReport good = cgnscheck(path);
  ASSERT_TRUE(good.complete) << good.text;
  EXPECT_EQ(good.errors, 0) << good.text;
  EXPECT_EQ(good.warnings, 0) << good.text;
  // The same file with the first connection's Transform entries exchanged, written below the
  // library (which refuses such a Transform): the report must show it, or the zeros above would
  // prove nothing.
  char connection[64], donor[64];
  cgsize_t range[6], donorRange[6];
  int t[3];
  {
    CgnsReader file(path);
    ASSERT_EQ(cg_1to1_read(file.fn, 1, 1, 1, connection, donor, range, donorRange, t), CG_OK);
  }
  int cgio = 0;
  double node = 0;
  ASSERT_EQ(cgio_open_file(path.c_str(), CGIO_MODE_MODIFY, CGIO_FILE_NONE, &cgio), CG_OK);
  const std::string transformPath = "/Base/" + blockName(0) + "/ZoneGridConnectivity/" + connection + "/Transform";
  double root = 0;
  ASSERT_EQ(cgio_get_root_id(cgio, &root), CG_OK);
  ASSERT_EQ(cgio_get_node_id(cgio, root, transformPath.c_str(), &node), CG_OK) << transformPath;
  std::swap(t[0], t[1]);
  ASSERT_EQ(cgio_write_all_data(cgio, node, t), CG_OK);
  cgio_close_file(cgio);
  const CheckReport broken = cgnscheck(path);
  EXPECT_TRUE(broken.complete) << broken.text;
  EXPECT_GE(broken.errors, 1) << broken.text;
}

// One 3 x 3 x 3 block with a collapsed face, moved by `offset` along x: a pyramid whose w_max
// face is its apex (`point`), or a wedge whose u_min face is its edge along z.
GridBlock collapsedBlock(bool point, double offset) {
  GridBlock block;
  block.size = {3, 3, 3};
  block.points.resize(27, 3);
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) {
      for (int i = 0; i < 3; ++i) {
        const double shrink = point ? 1.0 - k / 2.0 : i / 2.0;
        block.points.row(block.index(i, j, k)) << offset + (point ? (i - 1) * shrink : i), (j - 1) * shrink,
            k;
      }
    }
  }
  block.faces[static_cast<size_t>(point ? volume::BlockFaceSide::WMax : volume::BlockFaceSide::UMin)]
      .condition = BoundaryCondition::Collapsed;
  block.faces[static_cast<size_t>(volume::BlockFaceSide::WMin)].condition = BoundaryCondition::Wall;
  return block;
}

TEST(IoCgns, CollapsedFacesAreDegeneratePointsOrLinesTheirFamilyTypedWhereTheyAgree) {
  const std::string path = outputPath("io_collapsed.cgns");
  for (bool both : {false, true}) {
    std::vector<GridBlock> blocks{collapsedBlock(true, 0.0)};
    if (both) blocks.push_back(collapsedBlock(false, 10.0));
    writeCgns(StructuredGrid(blocks), path);
    {
      CgnsReader file(path);
      int families = 0;
      CG(cg_nfamilies(file.fn, 1, &families));
      int found = 0;
      for (int f = 1; f <= families; ++f) {
        char name[64];
        int bcs = 0, geometries = 0;
        CG(cg_family_read(file.fn, 1, f, name, &bcs, &geometries));
        if (std::string(name) != "collapsed") continue;
        ++found;
        // A point and a line: the family has no type of its own.
        ASSERT_EQ(bcs, both ? 0 : 1);
        if (both) continue;
        char bcName[64];
        CGNS_ENUMT(BCType_t) type;
        CG(cg_fambc_read(file.fn, 1, f, 1, bcName, &type));
        EXPECT_EQ(type, CGNS_ENUMV(BCDegeneratePoint));
      }
      EXPECT_EQ(found, 1);
      for (int zone = 1; zone <= static_cast<int>(blocks.size()); ++zone) {
        int bocos = 0;
        CG(cg_nbocos(file.fn, 1, zone, &bocos));
        int collapsed = 0;
        for (int bc = 1; bc <= bocos; ++bc) {
          char name[64];
          CGNS_ENUMT(BCType_t) type;
          CGNS_ENUMT(PointSetType_t) pointSet;
          cgsize_t points = 0, normalListSize = 0;
          int normalIndex[3], datasets = 0;
          CGNS_ENUMT(DataType_t) normalType;
          CG(cg_boco_info(file.fn, 1, zone, bc, name, &type, &pointSet, &points, normalIndex, &normalListSize,
                          &normalType, &datasets));
          if (std::string(name).rfind("collapsed", 0) != 0) continue;
          ++collapsed;
          EXPECT_EQ(type, zone == 1 ? CGNS_ENUMV(BCDegeneratePoint) : CGNS_ENUMV(BCDegenerateLine)) << name;
        }
        EXPECT_EQ(collapsed, 1);
      }
    }
    if (std::system("command -v cgnscheck > /dev/null 2>&1") != 0) continue;
    const CheckReport report = cgnscheck(path);
    EXPECT_TRUE(report.complete) << report.text;
    EXPECT_EQ(report.errors, 0) << report.text;
    EXPECT_EQ(report.warnings, 0) << report.text;
  }
}

// ---------------------------------------------------------------------------------------------
// Plot3D

TEST(IoCgns, OuterFacesSplitQuadByQuadAreFaceCentreListsThatCgnscheckAccepts) {
  // The one-layer box in the box domain whose edges its top and bottom faces reach over
  // (block_fixtures.h): those faces become one BC per condition, listing their quads' face centres.
  grid::RefinementOptions options;
  options.edgePoints = 9;
  options.outerDomain = test::boxDomain();
  const StructuredGrid grid = grid::refineBlockMesh(test::boxInBoxDomain(), options).grid;
  std::map<std::string, cgsize_t> expected;
  for (const GridBlock& block : grid.blocks()) {
    for (int f = 0; f < 6; ++f) {
      if (block.faces[static_cast<size_t>(f)].condition == BoundaryCondition::Connected) continue;
      const std::array<int, 2> counts = volume::faceGridCounts(block.size, f);
      for (int b = 0; b + 1 < counts[1]; ++b) {
        for (int a = 0; a + 1 < counts[0]; ++a) ++expected[volume::boundaryConditionName(block.quadCondition(f, a, b))];
      }
    }
  }
  const std::string path = outputPath("io_box_domain.cgns");
  writeCgns(grid, path);
  std::map<std::string, cgsize_t> quads;
  int lists = 0;
  {
    CgnsReader file(path);
    for (int z = 1; z <= grid.blockCount(); ++z) {
      int count = 0;
      CG(cg_nbocos(file.fn, 1, z, &count));
      for (int bc = 1; bc <= count; ++bc) {
        BocoInfo info;
        readBoco(file.fn, z, bc, info);
        const char* name = info.name.c_str();
        const char* family = info.family.c_str();
        const CGNS_ENUMT(PointSetType_t) pointSet = info.pointSet;
        const cgsize_t pointCount = info.pointCount;
        CGNS_ENUMT(GridLocation_t) location;
        CG(cg_boco_gridlocation_read(file.fn, 1, z, bc, &location));
        EXPECT_EQ(info.type, expectedType(family, false)) << name;
        if (pointSet == CGNS_ENUMV(PointRange)) {
          std::vector<cgsize_t> range(6);
          CG(cg_boco_read(file.fn, 1, z, bc, range.data(), nullptr));
          cgsize_t faces = 1;
          for (int d = 0; d < 3; ++d) faces *= std::max<cgsize_t>(1, std::abs(range[static_cast<size_t>(d + 3)] - range[static_cast<size_t>(d)]));
          quads[family] += faces;
          continue;
        }
        ASSERT_EQ(pointSet, CGNS_ENUMV(PointList)) << name;
        // Named after its block face: u faces list i-face centres, v faces j, w faces k.
        const char direction = std::string(name).substr(std::string(name).rfind('_') - 1, 1)[0];
        EXPECT_EQ(location, direction == 'u'   ? CGNS_ENUMV(IFaceCenter)
                            : direction == 'v' ? CGNS_ENUMV(JFaceCenter)
                                               : CGNS_ENUMV(KFaceCenter))
            << name;
        quads[family] += pointCount;
        ++lists;
        // Every listed face centre is a quad of the block face that lies on that family's part.
        std::vector<cgsize_t> centres(static_cast<size_t>(3 * pointCount));
        CG(cg_boco_read(file.fn, 1, z, bc, centres.data(), nullptr));
        const GridBlock& block = grid.blocks()[static_cast<size_t>(z - 1)];
        const int across = direction == 'u' ? 0 : direction == 'v' ? 1 : 2;
        for (cgsize_t q = 0; q < pointCount; ++q) {
          Eigen::Vector3d centre = Eigen::Vector3d::Zero();
          for (int corner = 0; corner < 4; ++corner) {
            std::array<int, 3> ijk{};
            for (int d = 0; d < 3; ++d) ijk[static_cast<size_t>(d)] = static_cast<int>(centres[static_cast<size_t>(3 * q + d)]) - 1;
            int bit = 0;
            for (int d = 0; d < 3; ++d) {
              if (d != across) ijk[static_cast<size_t>(d)] += (corner >> bit++) & 1;
            }
            centre += 0.25 * block.points.row(block.index(ijk[0], ijk[1], ijk[2])).transpose();
          }
          EXPECT_STREQ(volume::boundaryConditionName(test::boxDomainPart(centre)), family) << name << " quad " << q;
        }
      }
    }
  }
  EXPECT_EQ(lists, 16);  // 8 faces, each with side quads and inlet or outlet quads
  EXPECT_EQ(quads, expected);
  if (std::system("command -v cgnscheck > /dev/null 2>&1") != 0) GTEST_SKIP() << "cgnscheck is not installed";
  const CheckReport report = cgnscheck(path);
  ASSERT_TRUE(report.complete) << report.text;
  EXPECT_EQ(report.errors, 0) << report.text;
  EXPECT_EQ(report.warnings, 0) << report.text;
}

void expectSameBlocks(const StructuredGrid& grid, const std::vector<Plot3dBlock>& blocks) {
  ASSERT_EQ(blocks.size(), grid.blocks().size());
  for (size_t b = 0; b < blocks.size(); ++b) {
    EXPECT_EQ(blocks[b].size, grid.blocks()[b].size) << b;
    EXPECT_TRUE(blocks[b].points == grid.blocks()[b].points) << b;
  }
}

void expectErrorNaming(const std::string& path, const std::string& words) {
  try {
    readPlot3d(path);
    ADD_FAILURE() << "no error for " << path;
  } catch (const InvalidInputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(words), std::string::npos) << message;
  }
}

TEST(IoPlot3d, BothFormatsRoundTripBitForBit) {
  const StructuredGrid grid = boxGrid();
  const std::string binary = outputPath("io_box.xyz"), ascii = outputPath("io_box_ascii.xyz");
  writePlot3d(grid, binary, Plot3dFormat::Binary);
  writePlot3d(grid, ascii, Plot3dFormat::Ascii);
  expectSameBlocks(grid, readPlot3d(binary));
  expectSameBlocks(grid, readPlot3d(ascii));
  // The Fortran layout: record markers around nblocks, the dimensions and each block.
  const std::string bytes = readText(binary);
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  EXPECT_EQ(readLittleEndian(data, 4), 4u);
  EXPECT_EQ(readLittleEndian(data + 4, 4), 8u);
  EXPECT_EQ(readLittleEndian(data + 12, 4), 96u);
  size_t expectedSize = 12 + 8 + 96;
  for (const GridBlock& block : grid.blocks()) expectedSize += 8 + 24 * static_cast<size_t>(block.pointCount());
  EXPECT_EQ(bytes.size(), expectedSize);
  std::istringstream text(readText(ascii));
  int count = 0, ni = 0, nj = 0, nk = 0;
  text >> count >> ni >> nj >> nk;
  EXPECT_EQ(count, 8);
  EXPECT_EQ((std::array<int, 3>{ni, nj, nk}), grid.blocks()[0].size);
}

TEST(IoPlot3d, DamagedFilesGetErrorsNamingThem) {
  const StructuredGrid grid = boxGrid();
  const std::string binary = outputPath("io_box.xyz"), ascii = outputPath("io_box_ascii.xyz");
  writePlot3d(grid, binary, Plot3dFormat::Binary);
  writePlot3d(grid, ascii, Plot3dFormat::Ascii);
  const std::string cutBinary = outputPath("io_cut.xyz"), cutAscii = outputPath("io_cut_ascii.xyz");
  const std::string bytes = readText(binary), text = readText(ascii);
  std::ofstream(cutBinary, std::ios::binary) << bytes.substr(0, bytes.size() - 100);
  expectErrorNaming(cutBinary, "truncated");
  std::ofstream(cutAscii, std::ios::binary) << text.substr(0, text.size() / 2);
  expectErrorNaming(cutAscii, "truncated");
  // A header that disagrees with the dimension record.
  std::string recount = bytes;
  recount[4] = 9;
  const std::string badCount = outputPath("io_bad_count.xyz");
  std::ofstream(badCount, std::ios::binary) << recount;
  expectErrorNaming(badCount, "the block sizes");
  std::ofstream(badCount, std::ios::binary) << "2\n3 3 3\n-1 2 2\n";
  expectErrorNaming(badCount, "block 1 has a bad size -1");
  std::ofstream(badCount, std::ios::binary) << text << "1.5\n";
  expectErrorNaming(badCount, "after the last block");
  expectErrorNaming(outputPath("io_missing.xyz"), "cannot open");
}

// ---------------------------------------------------------------------------------------------
// VTK

// The attribute `name` of the first element of `tag` in `xml` after `from`.
std::string attribute(const std::string& xml, const std::string& tag, const std::string& name, size_t from = 0) {
  const size_t start = xml.find("<" + tag + " ", from);
  if (start == std::string::npos) return "";
  const size_t stop = xml.find('>', start);
  const std::string element = xml.substr(start, stop - start);
  const size_t at = element.find(" " + name + "=\"");
  if (at == std::string::npos) return "";
  const size_t begin = at + name.size() + 3;
  return element.substr(begin, element.find('"', begin) - begin);
}

// Float64 values of the appended array at `offset` (UInt64 byte count first).
std::vector<double> appendedArray(const std::string& vts, size_t offset) {
  const size_t data = vts.find("<AppendedData encoding=\"raw\">");
  const size_t start = vts.find('_', data) + 1 + offset;
  const auto* bytes = reinterpret_cast<const unsigned char*>(vts.data() + start);
  const auto count = static_cast<size_t>(readLittleEndian(bytes, 8) / 8);
  std::vector<double> values(count);
  for (size_t v = 0; v < count; ++v) values[v] = readFloat64(bytes + 8 + 8 * v);
  return values;
}

std::vector<CellField> boxFields(const StructuredGrid& grid) {
  CellField block{"block", {}}, skew{"skew \"<&>\"", {}};
  for (size_t b = 0; b < grid.blocks().size(); ++b) {
    const auto cells = static_cast<size_t>(grid.blocks()[b].cellCount());
    block.perBlock.emplace_back(cells, static_cast<double>(b));
    std::vector<double> values(cells);
    for (size_t c = 0; c < cells; ++c) values[c] = std::sin(0.1 * static_cast<double>(c + 100 * b));
    skew.perBlock.push_back(values);
  }
  return {block, skew};
}

TEST(IoVtk, MultiblockListsEveryBlockWithExtentsPointsAndFields) {
  const StructuredGrid grid = boxGrid();
  const std::string path = outputPath("io_box.vtm");
  const std::vector<CellField> fields = boxFields(grid);
  writeVtk(grid, path, fields);
  const std::string vtm = readText(path);
  EXPECT_NE(vtm.find("type=\"vtkMultiBlockDataSet\""), std::string::npos);
  size_t at = 0;
  for (int b = 0; b < grid.blockCount(); ++b) {
    at = vtm.find("<DataSet ", at);
    ASSERT_NE(at, std::string::npos) << b;
    EXPECT_EQ(attribute(vtm, "DataSet", "index", at), std::to_string(b));
    const std::string file = attribute(vtm, "DataSet", "file", at);
    EXPECT_EQ(file, "io_box_blocks/" + blockName(b) + ".vts");
    ++at;
    const std::string vts = readText(outputPath(file));
    const GridBlock& block = grid.blocks()[static_cast<size_t>(b)];
    const std::string extent = "0 " + std::to_string(block.size[0] - 1) + " 0 " + std::to_string(block.size[1] - 1) +
                               " 0 " + std::to_string(block.size[2] - 1);
    EXPECT_EQ(attribute(vts, "StructuredGrid", "WholeExtent"), extent);
    EXPECT_EQ(attribute(vts, "Piece", "Extent"), extent);
    const size_t cellData = vts.find("<CellData>");
    EXPECT_EQ(attribute(vts, "DataArray", "Name", cellData), "block");
    const size_t second = vts.find("<DataArray", cellData) + 1;
    EXPECT_EQ(attribute(vts, "DataArray", "Name", second), "skew &quot;&lt;&amp;&gt;&quot;");
    for (size_t f = 0; f < 2; ++f) {
      const size_t element = f == 0 ? cellData : second;
      EXPECT_EQ(appendedArray(vts, std::stoul(attribute(vts, "DataArray", "offset", element))),
                fields[f].perBlock[static_cast<size_t>(b)]);
    }
    const std::vector<double> points =
        appendedArray(vts, std::stoul(attribute(vts, "DataArray", "offset", vts.find("<Points>"))));
    EXPECT_EQ(points, std::vector<double>(block.points.data(), block.points.data() + 3 * block.pointCount()));
  }
  EXPECT_EQ(vtm.find("<DataSet ", at), std::string::npos);
}

TEST(IoVtk, WrongFieldSizesNameFieldAndBlock) {
  const StructuredGrid grid = boxGrid();
  const std::string path = outputPath("io_bad_field.vtm");
  fs::remove_all(outputPath("io_bad_field_blocks"));
  std::vector<CellField> fields = boxFields(grid);
  fields[1].perBlock[3].pop_back();
  try {
    writeVtk(grid, path, fields);
    FAIL();
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("cell field 'skew \"<&>\"' has " +
                                             std::to_string(grid.blocks()[3].cellCount() - 1) + " values on block 3"),
              std::string::npos)
        << error.what();
  }
  fields = boxFields(grid);
  fields[0].perBlock.pop_back();
  EXPECT_THROW(writeVtk(grid, path, fields), InvalidInputError);
  EXPECT_THROW(writeVtk(grid, outputPath("io_box.vts"), {}), InvalidInputError);
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(outputPath("io_bad_field_blocks")));
}

// ---------------------------------------------------------------------------------------------
// G+Smo

// The text between the opening tag (starting at `from`) of `tag` and its closing tag.
std::string content(const std::string& xml, const std::string& tag, size_t from) {
  const size_t open = xml.find('>', xml.find("<" + tag, from)) + 1;
  return xml.substr(open, xml.find("</" + tag + ">", open) - open);
}

template <class T>
std::vector<T> numbers(const std::string& text) {
  std::istringstream in(text);
  std::vector<T> values;
  for (T value; in >> value;) values.push_back(value);
  return values;
}

TEST(IoGismo, PatchesEvaluateAsTheBlocksAndInterfacesJoinIdenticalPoles) {
  const volume::BlockMesh mesh = boxBlockMesh();
  const std::string path = outputPath("io_box_gismo.xml");
  writeGismo(mesh, path);
  const std::string xml = readText(path);
  // Patches: knots and coefficients read back, evaluated at random parameters.
  std::vector<volume::BsplineVolume> patches;
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  size_t at = 0;
  for (int b = 0; b < mesh.blockCount(); ++b) {
    at = xml.find("<Geometry type=\"TensorBSpline3\" id=\"" + std::to_string(b) + "\"", at);
    ASSERT_NE(at, std::string::npos) << b;
    std::array<int, 3> degrees{};
    std::array<std::vector<double>, 3> knots;
    size_t knotAt = at;
    for (size_t d = 0; d < 3; ++d) {
      knotAt = xml.find("<Basis type=\"BSplineBasis\" index=\"" + std::to_string(d) + "\"", knotAt);
      degrees[d] = std::stoi(attribute(xml, "KnotVector", "degree", knotAt));
      knots[d] = numbers<double>(content(xml, "KnotVector", knotAt));
    }
    EXPECT_EQ(attribute(xml, "coefs", "geoDim", at), "3");
    const std::vector<double> coefs = numbers<double>(content(xml, "coefs", at));
    const RowMatrixX3d poles = Eigen::Map<const RowMatrixX3d>(coefs.data(), static_cast<Eigen::Index>(coefs.size() / 3), 3);
    patches.emplace_back(degrees, knots, poles);
    const volume::BsplineVolume& written = mesh.blocks()[static_cast<size_t>(b)].volume;
    RowMatrixX3d parameters(50, 3), expected, got;
    for (Eigen::Index p = 0; p < 50; ++p) {
      for (int d = 0; d < 3; ++d) parameters(p, d) = written.lower(d) + unit(random) * (written.upper(d) - written.lower(d));
    }
    written.evaluate(parameters, expected);
    patches.back().evaluate(parameters, got);
    EXPECT_LT((expected - got).cwiseAbs().maxCoeff(), 1e-14) << b;
  }
  const size_t multiPatch = xml.find("<MultiPatch parDim=\"3\"");
  ASSERT_NE(multiPatch, std::string::npos);
  EXPECT_EQ(content(xml, "patches", multiPatch), "0 7");
  // Interfaces, with G+Smo's meaning (gsBoundary.h, boundaryInterface::mapCorner): direction d
  // of p1 runs along dirMap[d] of p2, the same way when dirOrientation[d]; sides 1..6.
  const std::vector<int> interfaces = numbers<int>(content(xml, "interfaces", multiPatch));
  ASSERT_EQ(interfaces.size(), 12u * 10u);
  for (size_t n = 0; n < interfaces.size(); n += 10) {
    const int* line = &interfaces[n];
    const volume::BsplineVolume& first = patches[static_cast<size_t>(line[0])];
    const volume::BsplineVolume& second = patches[static_cast<size_t>(line[2])];
    const int side1 = line[1] - 1, side2 = line[3] - 1;
    EXPECT_EQ(line[4 + side1 / 2], side2 / 2);
    const std::array<int, 3> counts1{first.poleCount(0), first.poleCount(1), first.poleCount(2)};
    const std::array<int, 3> counts2{second.poleCount(0), second.poleCount(1), second.poleCount(2)};
    const std::array<int, 2> faceCounts = volume::faceGridCounts(counts1, side1);
    for (int a = 0; a < faceCounts[0]; ++a) {
      for (int c = 0; c < faceCounts[1]; ++c) {
        const std::array<int, 3> p = volume::faceGridPosition(counts1, side1, a, c);
        std::array<int, 3> q{};
        for (int d = 0; d < 3; ++d) {
          const auto target = static_cast<size_t>(line[4 + d]);
          q[target] = line[7 + d] ? p[static_cast<size_t>(d)] : counts2[target] - 1 - p[static_cast<size_t>(d)];
        }
        q[static_cast<size_t>(side2 / 2)] = side2 % 2 == 0 ? 0 : counts2[static_cast<size_t>(side2 / 2)] - 1;
        EXPECT_EQ(first.poles().row(first.poleIndex(p[0], p[1], p[2])), second.poles().row(second.poleIndex(q[0], q[1], q[2])))
            << "interface " << n / 10 << " pole (" << a << ", " << c << ")";
      }
    }
  }
  // Boundary: every outer side once in the first list, then again grouped by condition.
  const std::vector<int> all = numbers<int>(content(xml, "boundary", multiPatch));
  EXPECT_EQ(all.size(), 2u * 24u);
  std::map<std::string, size_t> sidesOf;
  for (size_t named = xml.find("<boundary name=", multiPatch); named != std::string::npos;
       named = xml.find("<boundary name=", named + 1)) {
    const std::string condition = attribute(xml, "boundary", "name", named);
    const std::vector<int> sides = numbers<int>(content(xml, "boundary", named));
    for (size_t s = 0; s < sides.size(); s += 2) {
      const BlockFace& face = mesh.blocks()[static_cast<size_t>(sides[s])].faces[static_cast<size_t>(sides[s + 1] - 1)];
      EXPECT_STREQ(volume::boundaryConditionName(face.condition), condition.c_str());
    }
    sidesOf[condition] = sides.size() / 2;
  }
  const std::map<std::string, size_t> expected = {{"wall", 4}, {"symmetry", 4}, {"inlet", 4}, {"outlet", 4}, {"farfield", 8}};
  EXPECT_EQ(sidesOf, expected);
}

// ---------------------------------------------------------------------------------------------
// Failures leave no file behind.

template <class Write>
void expectUnwritable(const std::string& path, Write write) {
  try {
    write(path);
    ADD_FAILURE() << "no error for " << path;
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path + ".partial"));
}

TEST(IoFiles, UnwritablePathsNameThePathAndLeaveNothing) {
  const StructuredGrid grid = boxGrid();
  const volume::BlockMesh mesh = boxBlockMesh();
  const std::string missing = outputPath("no_such_folder");
  fs::remove_all(missing);
  expectUnwritable(missing + "/box.cgns", [&](const std::string& path) { writeCgns(grid, path); });
  expectUnwritable(missing + "/box.xyz", [&](const std::string& path) { writePlot3d(grid, path); });
  expectUnwritable(missing + "/box.xyz", [&](const std::string& path) { writePlot3d(grid, path, Plot3dFormat::Ascii); });
  expectUnwritable(missing + "/box.vtm", [&](const std::string& path) { writeVtk(grid, path); });
  expectUnwritable(missing + "/box.xml", [&](const std::string& path) { writeGismo(mesh, path); });
  EXPECT_FALSE(fs::exists(missing));
}

TEST(IoFiles, AWriteFailingMidwayLeavesNoFileUnderTheFinalName) {
  const StructuredGrid grid = boxGrid();
  const volume::BlockMesh mesh = boxBlockMesh();
  // VTK: the blocks are written, the multiblock file cannot be (a folder is in the way of its
  // temporary): the earlier write's files stay as they were, none of the new ones is left.
  const std::string vtm = outputPath("io_midway.vtm");
  const fs::path firstBlock = outputPath("io_midway_blocks/block_0001.vts");
  fs::remove_all(vtm + ".partial");
  writeVtk(grid, vtm);
  const fs::file_time_type written = fs::last_write_time(firstBlock);
  fs::create_directories(vtm + ".partial/keep");
  EXPECT_THROW(writeVtk(grid, vtm), InvalidInputError);
  EXPECT_EQ(fs::last_write_time(firstBlock), written);
  EXPECT_TRUE(fs::is_regular_file(vtm));
  EXPECT_FALSE(fs::exists(outputPath("io_midway_blocks.partial")));
  fs::remove_all(vtm + ".partial");
  // A new write replaces the blocks whole.
  writeVtk(grid, vtm);
  EXPECT_NE(fs::last_write_time(firstBlock), written);
  EXPECT_FALSE(fs::exists(outputPath("io_midway_blocks.partial")));
  // CGNS: libcgns cannot create its file.
  const std::string cgns = outputPath("io_midway.cgns");
  fs::remove(cgns);
  fs::remove_all(cgns + ".partial");
  fs::create_directories(cgns + ".partial/keep");
  EXPECT_THROW(writeCgns(grid, cgns), InvalidInputError);
  EXPECT_FALSE(fs::exists(cgns));
  // Plot3D and G+Smo: the complete file cannot be moved onto the final name (a folder is there).
  const auto blocked = [](const std::string& name, const std::function<void(const std::string&)>& write) {
    const std::string path = outputPath(name);
    fs::remove_all(path);
    fs::create_directories(path + "/keep");
    EXPECT_THROW(write(path), InvalidInputError) << name;
    EXPECT_TRUE(fs::is_directory(path));
    EXPECT_FALSE(fs::exists(path + ".partial"));
  };
  blocked("io_midway.xyz", [&](const std::string& path) { writePlot3d(grid, path); });
  blocked("io_midway.xml", [&](const std::string& path) { writeGismo(mesh, path); });
}

// A reader given a folder read nothing and said the file "ends early"; given a device or a pipe
// (/dev/zero, a FIFO) it read on until the memory ran out or hung waiting for a writer.
TEST(IoFiles, ReadersTakeRegularFilesOnly) {
  const std::string fifo = outputPath("io_reader.fifo");
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string loop = outputPath("io_reader_loop");  // a link to itself: it exists, but leads nowhere
  fs::remove(loop);
  fs::create_symlink(loop, loop);
  const std::string plot3d = outputPath("io_reader.xyz");
  writePlot3d(boxGrid(), plot3d);
  const std::vector<std::pair<std::string, std::string>> refused{
      {"/dev/zero", "it is not a regular file"}, {fifo, "it is not a regular file"},
      {testing::TempDir(), "it is a folder, not a file"}, {outputPath("io_reader_missing.xyz"), "it does not exist"},
      {loop, "symbolic links"}};
  for (const auto& [path, reason] : refused) {
    const auto expectRefused = [&](const std::string& what, const std::function<void()>& read) {
      try {
        read();
        ADD_FAILURE() << what << " read " << path;
      } catch (const InvalidInputError& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find("cannot open " + what + " \"" + path + "\": "), std::string::npos) << message;
        EXPECT_NE(message.find(reason), std::string::npos) << message;
      }
    };
    expectRefused("the Plot3D file", [&] { readPlot3d(path); });
    expectRefused("the block mesh file", [&] { volume::readBlockMeshFile(path); });
    expectRefused("the control mesh file", [&] { readControlMesh(path); });
  }
  EXPECT_EQ(readPlot3d(plot3d).size(), static_cast<size_t>(boxGrid().blockCount()));
  fs::remove(fifo);
  fs::remove(loop);
}

}  // namespace
}  // namespace bvmesh::io

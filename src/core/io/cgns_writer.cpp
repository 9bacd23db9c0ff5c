#include "core/io/cgns_writer.h"

#include <cgnslib.h>

#include <map>
#include <set>
#include <vector>

#include "core/common/atomic_file.h"
#include "core/common/errors.h"
#include "core/io/io_common.h"

namespace bvmesh::io {
namespace {

using volume::BoundaryCondition;

// Every cg_* call goes through this: libcgns reports failures by return code only.
void check(int status, const std::string& path, const std::string& what) {
  if (status != CG_OK) {
    throw SolverError("writing the CGNS file \"" + path + "\" failed (" + what + "): " + cg_get_error());
  }
}

CGNS_ENUMT(BCType_t) bcType(BoundaryCondition condition, bool viscousWall) {
  switch (condition) {
    case BoundaryCondition::Wall:
      return viscousWall ? CGNS_ENUMV(BCWallViscous) : CGNS_ENUMV(BCWall);
    case BoundaryCondition::Symmetry:
      return CGNS_ENUMV(BCSymmetryPlane);
    case BoundaryCondition::Inlet:
      return CGNS_ENUMV(BCInflow);
    case BoundaryCondition::Outlet:
      return CGNS_ENUMV(BCOutflow);
    case BoundaryCondition::Collapsed:
      return CGNS_ENUMV(BCDegenerateLine);
    case BoundaryCondition::Farfield:
    case BoundaryCondition::Side:
    case BoundaryCondition::Connected:
      break;
  }
  return CGNS_ENUMV(BCFarfield);
}

// A whole face's boundary type: a face collapsed to one point is a degenerate point, one
// collapsed to a curve a line.
CGNS_ENUMT(BCType_t) faceBcType(const volume::BlockFace& face, bool viscousWall) {
  if (face.condition == BoundaryCondition::Collapsed && face.collapsedAlong[0] && face.collapsedAlong[1])
    return CGNS_ENUMV(BCDegeneratePoint);
  return bcType(face.condition, viscousWall);
}

// One-based (i, j, k) of face position (a, b), as CGNS point ranges count.
std::array<cgsize_t, 3> cgnsIndex(const std::array<int, 3>& size, int face, int a, int b) {
  const std::array<int, 3> ijk = volume::faceGridPosition(size, face, a, b);
  return {ijk[0] + 1, ijk[1] + 1, ijk[2] + 1};
}

// PointRange / PointRangeDonor as cg_1to1_write and cg_boco_write take them: begin (i, j, k), end (i, j, k).
std::array<cgsize_t, 6> range(const std::array<cgsize_t, 3>& begin, const std::array<cgsize_t, 3>& end) {
  return {begin[0], begin[1], begin[2], end[0], end[1], end[2]};
}

std::array<cgsize_t, 6> faceRange(const grid::GridBlock& block, int face) {
  const std::array<int, 2> counts = volume::faceGridCounts(block.size, face);
  return range(cgnsIndex(block.size, face, 0, 0), cgnsIndex(block.size, face, counts[0] - 1, counts[1] - 1));
}

// The donor's range is the image of this face's begin and end corners, so it runs backwards
// along reversed directions, as CGNS expects.
std::array<cgsize_t, 6> donorRange(const grid::GridBlock& block, int face, const grid::GridBlock& donor) {
  const volume::FaceConnection& link = block.faces[static_cast<size_t>(face)].neighbour;
  const std::array<int, 2> counts = volume::faceGridCounts(block.size, face);
  const std::array<int, 2> donorCounts = volume::faceGridCounts(donor.size, link.face);
  const std::array<int, 2> begin = volume::BlockMesh::mapFacePosition(link, donorCounts, 0, 0);
  const std::array<int, 2> end = volume::BlockMesh::mapFacePosition(link, donorCounts, counts[0] - 1, counts[1] - 1);
  return range(cgnsIndex(donor.size, link.face, begin[0], begin[1]), cgnsIndex(donor.size, link.face, end[0], end[1]));
}

// CGNS Transform: index direction d of this zone runs along donor direction |t[d]| (one-based),
// backwards when t[d] < 0.
std::array<int, 3> transform(int face, const volume::FaceConnection& link) {
  const DirectionMap map = directionMap(face, link);
  std::array<int, 3> t{};
  for (size_t d = 0; d < 3; ++d) t[d] = (map.reversed[d] ? -1 : 1) * (map.direction[d] + 1);
  return t;
}

// Closes the file however the writer leaves, so the temporary can be removed on failure.
class CgnsFile {
 public:
  CgnsFile(const std::string& temporary, const std::string& path) : path_(path) {
    if (cg_open(temporary.c_str(), CG_MODE_WRITE, &fn_) != CG_OK) {
      throw InvalidInputError("cannot write the CGNS file \"" + path + "\" (its folder is missing or not writable): " +
                              cg_get_error());
    }
  }
  ~CgnsFile() {
    if (fn_ >= 0) cg_close(fn_);
  }
  CgnsFile(const CgnsFile&) = delete;
  CgnsFile& operator=(const CgnsFile&) = delete;

  int id() const { return fn_; }
  void close() {
    const int fn = fn_;
    fn_ = -1;
    check(cg_close(fn), path_, "closing");
  }

 private:
  std::string path_;
  int fn_ = -1;
};

// One BC_t of a zone in its condition's family, named after the condition and the block face, of
// `type`; `points` as cg_boco_write takes them (a point range, or a list of face centres).
// Returns its index.
int writeBoundary(int fn, int base, int zone, BoundaryCondition condition, CGNS_ENUMT(BCType_t) type,
                  const std::string& faceName, CGNS_ENUMT(PointSetType_t) setType, const std::vector<cgsize_t>& points,
                  const std::string& path, const std::string& zoneName) {
  const char* family = volume::boundaryConditionName(condition);
  const std::string bc = std::string(family) + "_" + faceName;
  const auto count = static_cast<cgsize_t>(setType == CGNS_ENUMV(PointRange) ? 2 : points.size() / 3);
  int index = 0;
  check(cg_boco_write(fn, base, zone, bc.c_str(), type, setType, count, points.data(), &index),
        path, zoneName + " " + bc);
  check(cg_goto(fn, base, "Zone_t", zone, "ZoneBC_t", 1, "BC_t", index, "end"), path, zoneName + " " + bc);
  check(cg_famname_write(family), path, zoneName + " " + bc + " family");
  return index;
}

void writeZone(int fn, int base, const grid::StructuredGrid& grid, int b, const std::string& path) {
  const grid::GridBlock& block = grid.blocks()[static_cast<size_t>(b)];
  const std::string name = blockName(b);
  const cgsize_t size[9] = {block.size[0],     block.size[1],     block.size[2], block.size[0] - 1, block.size[1] - 1,
                            block.size[2] - 1, 0,                 0,             0};
  int zone = 0;
  check(cg_zone_write(fn, base, name.c_str(), size, CGNS_ENUMV(Structured), &zone), path, name);
  // CGNS stores i fastest, as the grid's point rows are.
  std::vector<double> coordinate(static_cast<size_t>(block.pointCount()));
  const char* coordinateNames[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
  for (int x = 0; x < 3; ++x) {
    for (Eigen::Index r = 0; r < block.pointCount(); ++r) coordinate[static_cast<size_t>(r)] = block.points(r, x);
    int index = 0;
    check(cg_coord_write(fn, base, zone, CGNS_ENUMV(RealDouble), coordinateNames[x], coordinate.data(), &index), path,
          name + " " + coordinateNames[x]);
    // A length (mass, length, time, temperature, angle exponents), in the model's unknown unit.
    const float lengthExponents[5] = {0, 1, 0, 0, 0};
    check(cg_goto(fn, base, "Zone_t", zone, "GridCoordinates_t", 1, "DataArray_t", index, "end"), path, name);
    check(cg_exponents_write(CGNS_ENUMV(RealSingle), lengthExponents), path, name + " " + coordinateNames[x]);
  }
  for (int f = 0; f < 6; ++f) {
    const volume::BlockFace& face = block.faces[static_cast<size_t>(f)];
    const std::string faceName = std::string(volume::blockFaceName(f));
    const std::array<cgsize_t, 6> pointRange = faceRange(block, f);
    int index = 0;
    if (face.condition == BoundaryCondition::Connected) {
      const grid::GridBlock& donor = grid.blocks()[static_cast<size_t>(face.neighbour.block)];
      const std::array<cgsize_t, 6> donorPoints = donorRange(block, f, donor);
      const std::array<int, 3> t = transform(f, face.neighbour);
      const std::string connection = faceName + "_to_" + blockName(face.neighbour.block) + "_" +
                                     volume::blockFaceName(face.neighbour.face);
      check(cg_1to1_write(fn, base, zone, connection.c_str(), blockName(face.neighbour.block).c_str(),
                          pointRange.data(), donorPoints.data(), t.data(), &index),
            path, name + " " + connection);
      continue;
    }
    if (block.quadConditions[static_cast<size_t>(f)].empty()) {
      writeBoundary(fn, base, zone, face.condition, faceBcType(face, grid.viscousWall()), faceName,
                    CGNS_ENUMV(PointRange), {pointRange.begin(), pointRange.end()}, path, name);
      continue;
    }
    // A face whose quads lie on several parts of the domain: per condition, its quads as a list
    // of face centres (i, j, k: the face's own index across it, cell indices along it).
    const std::array<int, 2> along = volume::faceDirections(f);
    const std::array<int, 2> counts = volume::faceGridCounts(block.size, f);
    std::map<BoundaryCondition, std::vector<cgsize_t>> quads;
    for (int qb = 0; qb + 1 < counts[1]; ++qb) {
      for (int qa = 0; qa + 1 < counts[0]; ++qa) {
        std::array<cgsize_t, 3> ijk{};
        ijk[static_cast<size_t>(f / 2)] = f % 2 == 0 ? 1 : block.size[static_cast<size_t>(f / 2)];
        ijk[static_cast<size_t>(along[0])] = qa + 1;
        ijk[static_cast<size_t>(along[1])] = qb + 1;
        std::vector<cgsize_t>& list = quads[block.quadCondition(f, qa, qb)];
        list.insert(list.end(), ijk.begin(), ijk.end());
      }
    }
    const CGNS_ENUMT(GridLocation_t) location = f / 2 == 0   ? CGNS_ENUMV(IFaceCenter)
                                                : f / 2 == 1 ? CGNS_ENUMV(JFaceCenter)
                                                             : CGNS_ENUMV(KFaceCenter);
    for (const auto& [condition, list] : quads) {
      const int bcIndex = writeBoundary(fn, base, zone, condition, bcType(condition, grid.viscousWall()), faceName,
                                        CGNS_ENUMV(PointList), list, path, name);
      check(cg_boco_gridlocation_write(fn, base, zone, bcIndex, location), path, name + " " + faceName + " location");
    }
  }
}

void writeFile(const grid::StructuredGrid& grid, const std::string& temporary, const std::string& path) {
  CgnsFile file(temporary, path);
  const int fn = file.id();
  int base = 0;
  check(cg_base_write(fn, "Base", 3, 3, &base), path, "the base");
  // The geometry's length unit is whatever the CAD model used, which the grid does not record.
  check(cg_goto(fn, base, "end"), path, "the base");
  check(cg_dataclass_write(CGNS_ENUMV(NormalizedByUnknownDimensional)), path, "the base's data class");
  // Families first, in condition order, only for the conditions some face uses, each with the
  // boundary type its faces have (none where they differ: collapsed faces that are lines and
  // points; each face's own boundary node says which).
  std::map<BoundaryCondition, std::set<CGNS_ENUMT(BCType_t)>> used;
  for (const grid::GridBlock& block : grid.blocks()) {
    for (size_t f = 0; f < 6; ++f) {
      const volume::BlockFace& face = block.faces[f];
      if (block.quadConditions[f].empty()) {
        if (face.condition != BoundaryCondition::Connected)
          used[face.condition].insert(faceBcType(face, grid.viscousWall()));
        continue;
      }
      for (BoundaryCondition condition : block.quadConditions[f])
        used[condition].insert(bcType(condition, grid.viscousWall()));
    }
  }
  for (const auto& [condition, types] : used) {
    const char* family = volume::boundaryConditionName(condition);
    int index = 0, bc = 0;
    check(cg_family_write(fn, base, family, &index), path, std::string("family ") + family);
    if (types.size() != 1) continue;
    check(cg_fambc_write(fn, base, index, "FamBC", *types.begin(), &bc), path,
          std::string("family ") + family);
  }
  for (int b = 0; b < grid.blockCount(); ++b) writeZone(fn, base, grid, b, path);
  file.close();
}

}  // namespace

void writeCgns(const grid::StructuredGrid& grid, const std::string& path) {
  writeFileAtomicallyByPath(path, "the CGNS file",
                            [&](const std::string& temporary) { writeFile(grid, temporary, path); });
}

}  // namespace bvmesh::io

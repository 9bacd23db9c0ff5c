#include "core/io/gismo_writer.h"

#include <iomanip>
#include <ostream>

#include "core/common/atomic_file.h"
#include "core/io/io_common.h"

namespace bvmesh::io {
namespace {

using volume::BoundaryCondition;

void writePatch(std::ostream& out, const volume::BsplineVolume& volume, int b) {
  out << " <Geometry type=\"TensorBSpline3\" id=\"" << b << "\"><!-- " << blockName(b) << " -->\n"
      << "  <Basis type=\"TensorBSplineBasis3\">\n";
  for (int d = 0; d < 3; ++d) {
    out << "   <Basis type=\"BSplineBasis\" index=\"" << d << "\">\n"
        << "    <KnotVector degree=\"" << volume.degree(d) << "\">";
    for (size_t k = 0; k < volume.knots(d).size(); ++k) out << (k == 0 ? "" : " ") << volume.knots(d)[k];
    out << "</KnotVector>\n   </Basis>\n";
  }
  out << "  </Basis>\n  <coefs geoDim=\"3\">\n";
  const RowMatrixX3d& poles = volume.poles();
  for (Eigen::Index r = 0; r < poles.rows(); ++r) out << poles(r, 0) << ' ' << poles(r, 1) << ' ' << poles(r, 2) << '\n';
  out << "  </coefs>\n </Geometry>\n";
}

// G+Smo side number of block face f (BlockFaceSide order is G+Smo's, zero-based).
int side(int face) { return face + 1; }

void writeInterfaces(std::ostream& out, const volume::BlockMesh& mesh) {
  std::string lines;
  for (int b = 0; b < mesh.blockCount(); ++b) {
    for (int f = 0; f < 6; ++f) {
      const volume::BlockFace& face = mesh.blocks()[static_cast<size_t>(b)].faces[static_cast<size_t>(f)];
      const volume::FaceConnection& link = face.neighbour;
      // Once per pair, from the side that comes first.
      if (face.condition != BoundaryCondition::Connected || link.block < b || (link.block == b && link.face < f)) continue;
      const DirectionMap map = directionMap(f, link);
      lines += "   " + std::to_string(b) + " " + std::to_string(side(f)) + " " + std::to_string(link.block) + " " +
               std::to_string(side(link.face));
      for (int d : map.direction) lines += " " + std::to_string(d);
      for (bool reversed : map.reversed) lines += reversed ? " 0" : " 1";
      lines += "\n";
    }
  }
  if (!lines.empty()) out << "  <interfaces>\n" << lines << "  </interfaces>\n";
}

// The sides of the boundary faces whose condition `wanted` accepts.
template <class Wanted>
std::string boundarySides(const volume::BlockMesh& mesh, Wanted wanted) {
  std::string lines;
  for (int b = 0; b < mesh.blockCount(); ++b) {
    for (int f = 0; f < 6; ++f) {
      const BoundaryCondition c = mesh.blocks()[static_cast<size_t>(b)].faces[static_cast<size_t>(f)].condition;
      if (c == BoundaryCondition::Connected || !wanted(c)) continue;
      lines += "   " + std::to_string(b) + " " + std::to_string(side(f)) + "\n";
    }
  }
  return lines;
}

void writeMesh(std::ostream& out, const volume::BlockMesh& mesh) {
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<xml>\n"
      << " <!-- BVMesh block mesh: " << mesh.blockCount() << " trivariate B-spline blocks -->\n"
      << std::setprecision(17);
  for (int b = 0; b < mesh.blockCount(); ++b) writePatch(out, mesh.blocks()[static_cast<size_t>(b)].volume, b);
  out << " <MultiPatch parDim=\"3\" id=\"" << mesh.blockCount() << "\">\n";
  if (mesh.blockCount() > 0) out << "  <patches type=\"id_range\">0 " << mesh.blockCount() - 1 << "</patches>\n";
  writeInterfaces(out, mesh);
  const std::string all = boundarySides(mesh, [](BoundaryCondition) { return true; });
  if (!all.empty()) {
    out << "  <boundary>\n" << all << "  </boundary>\n";
    for (BoundaryCondition condition : {BoundaryCondition::Wall, BoundaryCondition::Symmetry, BoundaryCondition::Farfield,
                                        BoundaryCondition::Inlet, BoundaryCondition::Outlet, BoundaryCondition::Side,
                                        BoundaryCondition::Collapsed}) {
      const std::string sides = boundarySides(mesh, [condition](BoundaryCondition c) { return c == condition; });
      if (sides.empty()) continue;
      out << "  <boundary name=\"" << volume::boundaryConditionName(condition) << "\">\n" << sides << "  </boundary>\n";
    }
  }
  out << " </MultiPatch>\n</xml>\n";
}

}  // namespace

void writeGismo(const volume::BlockMesh& mesh, const std::string& path) {
  writeFileAtomically(path, "the G+Smo file", [&](std::ostream& out) { writeMesh(out, mesh); });
}

}  // namespace bvmesh::io

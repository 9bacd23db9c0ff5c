// bvmesh: command-line access to the core, for batch runs without FreeCAD.
//   bvmesh info FILE [SHARP_ANGLE_DEGREES [SEW_TOLERANCE|off]]
//     what a STEP / IGES / BREP file holds, after sewing (tolerance 0 or none: automatic)
#include <cstdlib>
#include <exception>
#include <iostream>
#include <stdexcept>
#include <string>

#include "core/cad/isolated_reader.h"
#include "core/cad/shape_io.h"
#include "core/cad/shape_repair.h"
#include "core/cad/shape_summary.h"

namespace {

int printUsage() {
  std::cerr << "usage: bvmesh info FILE [SHARP_ANGLE_DEGREES [SEW_TOLERANCE|off]]\n";
  return 2;
}

// A number argument, the whole of it ("30x" is no angle).
double numberArgument(const std::string& text, const std::string& what) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0') {
    throw std::invalid_argument(what + " must be a number, got \"" + text + "\"");
  }
  return value;
}

int info(const std::string& path, double sharpAngleDegrees, const bvmesh::cad::RepairOptions& repair) {
  bvmesh::cad::ShapeSummaryOptions options;
  options.sharpAngleDegrees = sharpAngleDegrees;
  const bvmesh::cad::RepairedShape read = bvmesh::cad::readShapeFileRepaired(path, repair);
  const bvmesh::cad::ShapeSummary summary = bvmesh::cad::summarizeShape(read.shape, options);
  std::cout << path << ": " << summary.solidCount << " solid(s), " << summary.faceCount() << " faces, "
            << summary.edges.size() << " edges, " << summary.vertexCount << " vertices\n";
  for (int i = 0; i < summary.faceCount(); ++i) {
    std::cout << "  Face" << i + 1 << ": " << summary.faceSurfaceTypes[i] << ", area " << summary.faceAreas[i] << "\n";
  }
  using bvmesh::cad::EdgeKind;
  std::cout << "  edges: " << summary.countEdges(EdgeKind::Sharp) << " sharp (>= " << sharpAngleDegrees
            << " deg), " << summary.countEdges(EdgeKind::Smooth) << " smooth, " << summary.countEdges(EdgeKind::Free)
            << " free, " << summary.countEdges(EdgeKind::Seam) << " seam, "
            << summary.countEdges(EdgeKind::NonManifold) << " non-manifold\n";
  std::cout << "  bounds: (" << summary.boundsMin[0] << ", " << summary.boundsMin[1] << ", " << summary.boundsMin[2]
            << ") .. (" << summary.boundsMax[0] << ", " << summary.boundsMax[1] << ", " << summary.boundsMax[2] << ")\n";
  for (const std::string& line : bvmesh::cad::describeRepair(read.report)) std::cout << "  " << line << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || std::string(argv[1]) != "info") return printUsage();
  try {
    bvmesh::cad::RepairOptions repair;
    if (argc > 4) {
      repair.sew = std::string(argv[4]) != "off";
      repair.tolerance = repair.sew ? numberArgument(argv[4], "SEW_TOLERANCE") : 0.0;
    }
    return info(argv[2], argc > 3 ? numberArgument(argv[3], "SHARP_ANGLE_DEGREES") : 30.0, repair);
  } catch (const std::exception& error) {
    std::cerr << "bvmesh: " << error.what() << "\n";
    return 1;
  }
}

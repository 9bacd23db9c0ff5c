#include "core/polyhedron/draft_check.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cstdio>
#include <map>
#include <optional>

#include "core/common/disjoint_sets.h"
#include "core/common/errors.h"

namespace bvmesh::polyhedron {
namespace {

// What about the target likely made vertices collapse, for the message.
std::string likelyCause(const target::Target& target) {
  const target::TargetReport& report = target.report();
  const cad::RepairReport& repair = report.repair;
  const int free = static_cast<int>(report.freeEdges.size());
  if (free == 0) return "the target is watertight, so the template's parameters do not suit its shape";
  std::string cause = "the target has " + std::to_string(free) + " free edges";
  if (repair.sewingAttempted && !repair.sewingApplied)
    cause += " and its faces could not be sewn (" + repair.keptReason + ")";
  else if (!repair.sewingAttempted && repair.freeEdgesRead > 0)
    cause += " and was read unsewn: read it with sewing on (the default)";
  if (!repair.openGaps.empty()) cause += "; " + std::to_string(repair.openGaps.size()) + " gaps are left open";
  // Templates find a body's ends, creases and symmetry plane from how its faces share edges.
  return cause + " (templates find ends, creases and symmetry planes from the edges faces share)";
}

}  // namespace

std::string placementFailure(const std::string& templateName, const std::string& what, const target::Target& target) {
  return "template '" + templateName + "' cannot be placed on this target: " + what + "; " + likelyCause(target);
}

void checkTargetHasVolume(const std::string& templateName, const PrincipalFrame& frame, const target::Target& target) {
  const Eigen::Vector3d extent = frame.high - frame.low;  // along the principal axes, largest first
  const double tolerance = target.report().tolerance;
  if (extent(1) > tolerance && extent(2) > tolerance) return;
  char what[256];
  if (extent(1) <= tolerance) {
    std::snprintf(what, sizeof(what),
                  "the target is a line: it is %.3g long but only %.3g across (its gap tolerance is %.3g)",
                  extent(0), extent(1), tolerance);
  } else {
    std::snprintf(what, sizeof(what),
                  "the target is flat: it is %.3g across but only %.3g thick (its gap tolerance is %.3g)",
                  target.report().diagonal, extent(2), tolerance);
  }
  throw InvalidInputError("template '" + templateName + "' cannot be placed on this target: " + what +
                          "; a template encloses a body, so the target must be the faces of a body with volume");
}

void checkTargetIsOneBody(const std::string& templateName, const target::Target& target) {
  const target::TargetReport& report = target.report();
  if (!report.freeEdges.empty()) return;
  const cad::ShapeSummary& shape = report.shape;
  // The faces joined by the edges they share.
  DisjointSets joined(static_cast<std::size_t>(shape.faceCount()));
  for (const cad::EdgeInfo& edge : shape.edges) {
    for (std::size_t k = 1; k < edge.faces.size(); ++k) joined.join(edge.faces[k], edge.faces[0]);
  }
  std::map<int, std::vector<int>> bodies;  // root -> its faces
  for (int f = 0; f < shape.faceCount(); ++f) bodies[joined.find(f)].push_back(f);
  if (bodies.size() <= 1) return;
  std::string groups;
  for (const auto& [first, faces] : bodies) {
    if (!groups.empty()) groups += ", ";
    groups += std::to_string(faces.size()) + (faces.size() == 1 ? " face" : " faces") + " from face " +
              std::to_string(faces.front());
    if (groups.size() > 200) {
      groups += ", ...";
      break;
    }
  }
  throw InvalidInputError("template '" + templateName + "' cannot be placed on this target: it is " +
                          std::to_string(bodies.size()) + " separate bodies (" + groups +
                          ") that share no edge; a template encloses one body, so fit each body with a target "
                          "of its own faces");
}

void checkTargetGenus(const std::string& templateName, int templateGenus, const target::Target& target) {
  const target::TargetReport& report = target.report();
  const cad::ShapeSummary& shape = report.shape;
  if (!report.freeEdges.empty() || shape.countEdges(cad::EdgeKind::NonManifold) > 0) return;
  const int characteristic = shape.eulerCharacteristic();
  if (characteristic % 2 != 0 || characteristic > 2) return;  // not one closed orientable surface
  const int genus = (2 - characteristic) / 2;
  if (genus == templateGenus) return;
  const std::string holes = genus == 0 ? "no hole" : std::to_string(genus) + (genus == 1 ? " hole" : " holes");
  std::string what = "it has " + holes + " through it (genus " + std::to_string(genus) + "), which the template's " +
                     (templateGenus == 0 ? "closed polyhedron" : "ring") + " (genus " + std::to_string(templateGenus) +
                     ") cannot wrap; ";
  if (genus == 0) {
    what += "a body without a hole takes the sphere, box or a revolution template";
  } else if (genus == 1) {
    what += "a tube or a ring takes the nacelle template (its surface: the volume stage takes bodies without holes)";
  } else {
    what += "no template wraps it";
  }
  throw InvalidInputError("template '" + templateName + "' cannot be placed on this target: " + what);
}

void checkNotAHalfModel(const std::string& templateName, const target::Target& target,
                        const std::vector<FeatureCurve>& curves) {
  const std::optional<fit::SymmetryPlane> plane = detectSymmetryPlane(target, curves);
  if (!plane) return;
  char where[200];
  std::snprintf(where, sizeof(where), "normal (%.3g, %.3g, %.3g) through (%.4g, %.4g, %.4g)", plane->normal.x(),
                plane->normal.y(), plane->normal.z(), plane->point.x(), plane->point.y(), plane->point.z());
  throw InvalidInputError("template '" + templateName +
                          "' cannot be placed on this target: it is open on a plane with the whole target on one "
                          "side (a half model on its symmetry plane, " + where +
                          "), and the template wraps a closed body; a half body takes a revolution template "
                          "(capsule, cylinder, fuselage) or a wing template");
}

void checkCornersOnDistinctVertices(const std::string& templateName, const std::vector<int>& vertexCadVertex,
                                    const target::Target& target) {
  std::map<int, int> cornerAt;  // target vertex -> the first corner mapped to it
  for (std::size_t v = 0; v < vertexCadVertex.size(); ++v) {
    const int cad = vertexCadVertex[v];
    if (cad < 0) continue;
    const auto [first, inserted] = cornerAt.emplace(cad, static_cast<int>(v));
    if (inserted) continue;
    const long corners = std::count_if(vertexCadVertex.begin(), vertexCadVertex.end(), [](int c) { return c >= 0; });
    const Eigen::Vector3d p = target.vertexPosition(cad);
    char what[320];
    std::snprintf(what, sizeof(what),
                  "it has %d vertices for the template's %ld corners: corners %d and %zu would both sit on its "
                  "vertex %d at (%.6g, %.6g, %.6g)",
                  target.vertexCount(), corners, first->second, v, cad, p.x(), p.y(), p.z());
    throw InvalidInputError("template '" + templateName + "' cannot be placed on this target: " + what +
                            "; choose a template whose corners the target has, or one without corners");
  }
}

void checkPlacedFaces(const std::string& templateName, const std::vector<Eigen::Vector3d>& vertices,
                      const std::vector<std::vector<int>>& faces, const target::Target& target) {
  // Tolerances relative to the target's size, as ControlMesh's own check is to the mesh's.
  const double size = target.report().diagonal > 0.0 ? target.report().diagonal : 1.0;
  const double lengthTolerance = 1e-9 * size;
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const std::vector<int>& face = faces[f];
    Eigen::Vector3d area = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < face.size(); ++i) {
      const int a = face[i], b = face[(i + 1) % face.size()];
      const Eigen::Vector3d& pa = vertices[static_cast<std::size_t>(a)];
      const Eigen::Vector3d& pb = vertices[static_cast<std::size_t>(b)];
      if ((pb - pa).norm() <= lengthTolerance) {
        char where[96];
        std::snprintf(where, sizeof(where), "(%.6g, %.6g, %.6g)", pa.x(), pa.y(), pa.z());
        throw InvalidInputError(placementFailure(templateName,
                                                 "its face " + std::to_string(f) + " collapses, vertices " +
                                                     std::to_string(a) + " and " + std::to_string(b) +
                                                     " land on the same target point " + where,
                                                 target));
      }
      area += (pa - vertices[static_cast<std::size_t>(face[0])]).cross(pb - vertices[static_cast<std::size_t>(face[0])]);
    }
    if (0.5 * area.norm() <= 1e-12 * size * size)
      throw InvalidInputError(placementFailure(
          templateName, "its face " + std::to_string(f) + " has no area (its vertices lie on a line)", target));
  }
}

}  // namespace bvmesh::polyhedron

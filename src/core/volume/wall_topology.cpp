#include "core/volume/wall_topology.h"

#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/common/disjoint_sets.h"
#include "core/common/errors.h"
#include "core/mesh/control_mesh.h"
#include "core/surface/limit_points.h"

namespace bvmesh::volume {
namespace {

// Per set (by its root) one of its members, over the given members.
std::map<int, int> setsOf(DisjointSets& sets, const std::vector<int>& members) {
  std::map<int, int> found;
  for (int v : members) found.emplace(sets.find(v), v);
  return found;
}

}  // namespace

void requireMarchableWall(const surface::QuadControlMesh& wall, bool halfModel) {
  DisjointSets bodies(static_cast<size_t>(wall.vertices.rows()));
  std::set<int> used;
  for (Eigen::Index f = 0; f < wall.faces.rows(); ++f) {
    for (int k = 0; k < 4; ++k) {
      used.insert(wall.faces(f, k));
      if (k > 0) bodies.join(wall.faces(f, k), wall.faces(f, 0));
    }
  }
  const std::vector<int> vertices(used.begin(), used.end());
  const std::map<int, int> parts = setsOf(bodies, vertices);
  if (parts.size() > 1) {
    throw InvalidInputError(
        "the wall has " + std::to_string(parts.size()) + " separate bodies (control vertices " +
        std::to_string(parts.begin()->second) + " and " + std::to_string(std::next(parts.begin())->second) +
        " lie on different ones): their volume meshes would overlap; mesh one body, or join them");
  }
  const ControlMesh mesh = surface::toControlMesh(wall);
  DisjointSets rims(static_cast<size_t>(wall.vertices.rows()));
  std::vector<int> rimVertices;
  for (int e : mesh.boundaryEdges()) {
    rims.join(mesh.edges()(e, 0), mesh.edges()(e, 1));
    rimVertices.push_back(mesh.edges()(e, 0));
  }
  const std::map<int, int> loops = setsOf(rims, rimVertices);
  // Euler characteristic V - E + F = 2 - 2 genus - loops for one connected surface.
  const long euler = static_cast<long>(vertices.size()) - static_cast<long>(mesh.edges().rows()) +
                     static_cast<long>(wall.faces.rows());
  const long genus = (2 - static_cast<long>(loops.size()) - euler) / 2;
  if (genus > 0) {
    throw InvalidInputError(
        "the wall is a ring (genus " + std::to_string(genus) +
        ", such as a nacelle or a torus): a front marched from it keeps its hole, which closes on itself "
        "before the far field; the volume stage takes a body of a sphere's topology (on a symmetry plane, "
        "half of one)");
  }
  if (halfModel && loops.size() > 1) {
    throw InvalidInputError(
        "the wall meets the symmetry plane in " + std::to_string(loops.size()) +
        " separate loops (control vertices " + std::to_string(loops.begin()->second) + " and " +
        std::to_string(std::next(loops.begin())->second) +
        " lie on different ones), like half a ring: the front's pieces on the plane would close the gap "
        "between them before the far field; the volume stage takes a half body that meets the plane in one "
        "loop");
  }
}

}  // namespace bvmesh::volume

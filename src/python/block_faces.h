// Block faces (boundary condition or connection) as Python dicts, shared by the B-spline block
// mesh and the structured grid bindings.
#pragma once

#include <pybind11/pybind11.h>

#include "core/volume/block_mesh.h"

namespace bvmesh::python {

inline pybind11::dict faceDict(const volume::BlockFace& face) {
  pybind11::dict item;
  item["condition"] = volume::boundaryConditionName(face.condition);
  if (face.condition == volume::BoundaryCondition::Connected) {
    item["block"] = face.neighbour.block;
    item["face"] = volume::blockFaceName(face.neighbour.face);
    item["swapped"] = face.neighbour.swapped;
    item["reverse_first"] = face.neighbour.reverseFirst;
    item["reverse_second"] = face.neighbour.reverseSecond;
  }
  return item;
}

// {'u_min': {...}, ..., 'w_max': {...}}
inline pybind11::dict facesDict(const std::array<volume::BlockFace, 6>& faces) {
  pybind11::dict result;
  for (int f = 0; f < 6; ++f) result[volume::blockFaceName(f)] = faceDict(faces[static_cast<size_t>(f)]);
  return result;
}

}  // namespace bvmesh::python

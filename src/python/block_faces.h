// Block faces (boundary condition or connection) as Python dicts, shared by the B-spline block
// mesh and the structured grid bindings.
#pragma once

#include <pybind11/pybind11.h>

#include <string>

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

// The face (0..5) named u_min .. w_max; ValueError otherwise.
inline int faceIndexOf(const std::string& name) {
  for (int f = 0; f < 6; ++f) {
    if (name == volume::blockFaceName(f)) return f;
  }
  throw pybind11::value_error("no block face '" + name + "' (u_min, u_max, v_min, v_max, w_min or w_max)");
}

}  // namespace bvmesh::python

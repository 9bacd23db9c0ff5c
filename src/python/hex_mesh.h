// Hexahedral meshes (volume::HexMesh) as Python dicts of numpy arrays, shared by the volume and
// the fitting bindings: 'points' (#P, 3), 'cells' (#C, 8), 'boundary_faces' (#B, 4),
// 'boundary_conditions' (#B names), 'creases' (#K, 2), 'corners' (ids).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "arrays.h"
#include "core/volume/hex_subdivision.h"

namespace bvmesh::python {

// An (n, columns) integer array as n rows of ids; an empty sequence is n = 0.
template <size_t columns>
std::vector<std::array<int, columns>> indexRowsOf(const pybind11::object& object, const char* name) {
  const pybind11::array array = pybind11::array::ensure(object);
  if (array && array.ndim() == 1 && array.shape(0) == 0) return {};
  if (!array || array.ndim() != 2 || array.shape(1) != static_cast<pybind11::ssize_t>(columns)) {
    throw pybind11::value_error(std::string(name) + " must be an integer array of shape (n, " +
                                std::to_string(columns) + ")" + (array ? ", got " + shapeText(array) : std::string()));
  }
  const std::vector<int> flat = intsOf(array.attr("reshape")(-1), name);
  std::vector<std::array<int, columns>> rows(flat.size() / columns);
  for (size_t r = 0; r < rows.size(); ++r) std::copy_n(flat.begin() + static_cast<std::ptrdiff_t>(columns * r), columns, rows[r].begin());
  return rows;
}

template <size_t columns>
pybind11::array_t<int> indexRowsArray(const std::vector<std::array<int, columns>>& rows) {
  pybind11::array_t<int> out({static_cast<pybind11::ssize_t>(rows.size()), static_cast<pybind11::ssize_t>(columns)});
  for (size_t r = 0; r < rows.size(); ++r) std::copy(rows[r].begin(), rows[r].end(), out.mutable_data() + columns * r);
  return out;
}

inline pybind11::dict hexMeshDict(const volume::HexMesh& mesh) {
  pybind11::dict out;
  out["points"] = rowsArray(mesh.points);
  out["cells"] = indexRowsArray(mesh.cells);
  out["boundary_faces"] = indexRowsArray(mesh.boundaryFaces);
  pybind11::list conditions;
  for (auto c : mesh.boundaryConditions) conditions.append(volume::boundaryConditionName(c));
  out["boundary_conditions"] = conditions;
  std::vector<std::array<int, 2>> creases(static_cast<size_t>(mesh.creases.rows()));
  for (size_t c = 0; c < creases.size(); ++c) creases[c] = {mesh.creases(static_cast<Eigen::Index>(c), 0), mesh.creases(static_cast<Eigen::Index>(c), 1)};
  out["creases"] = indexRowsArray(creases);
  out["corners"] = mesh.corners;
  return out;
}

inline volume::HexMesh hexMeshOf(const pybind11::object& points, const pybind11::object& cells, const pybind11::object& boundaryFaces,
                          const pybind11::object& boundaryConditions, const pybind11::object& creases, const pybind11::object& corners) {
  volume::HexMesh mesh;
  mesh.points = rowsOf(points, "points", 3);
  mesh.cells = indexRowsOf<8>(cells, "cells");
  mesh.boundaryFaces = indexRowsOf<4>(boundaryFaces, "boundary_faces");
  for (const pybind11::handle& name : boundaryConditions) {
    const std::string word = pybind11::str(name);
    const auto condition = volume::findBoundaryCondition(word);
    if (!condition) throw pybind11::value_error("boundary_conditions: unknown boundary condition '" + word + "'");
    mesh.boundaryConditions.push_back(*condition);
  }
  if (!creases.is_none()) {
    const auto pairs = indexRowsOf<2>(creases, "creases");
    mesh.creases.resize(static_cast<Eigen::Index>(pairs.size()), 2);
    for (size_t c = 0; c < pairs.size(); ++c) mesh.creases.row(static_cast<Eigen::Index>(c)) << pairs[c][0], pairs[c][1];
  }
  if (!corners.is_none()) mesh.corners = intsOf(corners, "corners");
  return mesh;
}

}  // namespace bvmesh::python

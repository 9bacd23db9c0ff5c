// One registration function per core area; module.cpp calls them all.
#pragma once

#include <pybind11/pybind11.h>

namespace bvmesh::python {

void bindErrors(pybind11::module_& module);
void bindCad(pybind11::module_& module);
void bindMesh(pybind11::module_& module);
void bindTarget(pybind11::module_& module);
void bindFit(pybind11::module_& module);
void bindSurface(pybind11::module_& module);
void bindPolyhedron(pybind11::module_& module);
void bindVolume(pybind11::module_& module);
void bindGrid(pybind11::module_& module);

}  // namespace bvmesh::python

#include "bindings.h"

PYBIND11_MODULE(_core, module) {
  module.doc() = "BVMesh compiled core: subdivision, projection and fitting for B-spline meshing";
  bvmesh::python::bindErrors(module);
  bvmesh::python::bindCad(module);
  bvmesh::python::bindMesh(module);
  bvmesh::python::bindTarget(module);
  bvmesh::python::bindFit(module);
  bvmesh::python::bindSurface(module);
  bvmesh::python::bindPolyhedron(module);
  bvmesh::python::bindVolume(module);
  bvmesh::python::bindGrid(module);
}

// Conversions of core results to Python objects that more than one binding returns.
#pragma once

#include <pybind11/pybind11.h>

#include "core/target/target.h"

namespace bvmesh::python {

// A projection result as a dict of numpy arrays (see Target.project's docstring).
pybind11::dict projectionToDict(const target::ProjectionResult& result);

}  // namespace bvmesh::python

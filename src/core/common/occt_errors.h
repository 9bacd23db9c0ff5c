// OCCT reports failures as Standard_Failure, which is not a std::exception.
// Core functions that call OCCT wrap the call in translateOcctErrors so that only
// bvmesh errors leave the core.
#pragma once

#include <Standard_Failure.hxx>

#include <string>
#include <utility>

#include "core/common/errors.h"

namespace bvmesh {

// Runs `work` and rethrows an OCCT failure as SolverError("<context>: <OCCT message>").
template <class Work>
decltype(auto) translateOcctErrors(const std::string& context, Work&& work) {
  try {
    return std::forward<Work>(work)();
  } catch (const Standard_Failure& failure) {
    const char* message = failure.GetMessageString();
    throw SolverError(context + ": OpenCASCADE " + failure.DynamicType()->Name() +
                      (message != nullptr && *message != '\0' ? std::string(": ") + message : ""));
  }
}

}  // namespace bvmesh

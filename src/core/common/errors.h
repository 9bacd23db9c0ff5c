// The core's exception hierarchy. Every failure the core reports is one of these,
// with a message that names the offending element (face 12, vertex 7, file "x.stp", ...).
// The Python bindings map InvalidInputError and TopologyError to ValueError subclasses
// and SolverError to a RuntimeError subclass.
#pragma once

#include <stdexcept>
#include <string>

namespace bvmesh {

// Input that cannot be used: wrong array shapes, NaN coordinates, unreadable files, null shapes.
class InvalidInputError : public std::invalid_argument {
public:
  using std::invalid_argument::invalid_argument;
};

// Input whose connectivity is unusable: non-manifold edges, inconsistent orientation,
// creases that are not edges, shapes without faces.
class TopologyError : public InvalidInputError {
public:
  using InvalidInputError::InvalidInputError;
};

// A computation that failed on valid input: a geometric kernel failure, a singular system,
// no convergence.
class SolverError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// A long computation stopped because the caller asked it to.
class CancelledError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

}  // namespace bvmesh

// Maps the core's exception hierarchy to Python classes:
//   InvalidInputError(ValueError), TopologyError(InvalidInputError),
//   SolverError(RuntimeError), CancelledError(RuntimeError).
#include "core/common/errors.h"

#include "bindings.h"

namespace py = pybind11;

namespace bvmesh::python {

void bindErrors(py::module_& module) {
  static py::exception<InvalidInputError> invalidInput(module, "InvalidInputError", PyExc_ValueError);
  static py::exception<TopologyError> topology(module, "TopologyError", invalidInput.ptr());
  static py::exception<SolverError> solver(module, "SolverError", PyExc_RuntimeError);
  static py::exception<CancelledError> cancelled(module, "CancelledError", PyExc_RuntimeError);
  // Most derived first: the first translator that matches wins.
  py::register_exception_translator([](std::exception_ptr pending) {
    try {
      if (pending) std::rethrow_exception(pending);
    } catch (const TopologyError& error) {
      topology(error.what());
    } catch (const InvalidInputError& error) {
      invalidInput(error.what());
    } catch (const SolverError& error) {
      solver(error.what());
    } catch (const CancelledError& error) {
      cancelled(error.what());
    }
  });
}

}  // namespace bvmesh::python

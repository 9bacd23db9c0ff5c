// Maps the core's exception hierarchy to Python classes:
//   InvalidInputError(ValueError), TopologyError(InvalidInputError),
//   SolverError(RuntimeError), CancelledError(RuntimeError).
#include <cstring>

#include "core/common/errors.h"

#include "bindings.h"

namespace py = pybind11;

namespace bvmesh::python {
namespace {

// Messages may quote a file's bytes or a path that are not UTF-8: those are escaped, so the
// message is never lost (PyErr_SetString would leave the exception without text).
void raise(const py::object& type, const char* message) {
  PyObject* text =
      PyUnicode_DecodeUTF8(message, static_cast<Py_ssize_t>(std::strlen(message)), "backslashreplace");
  if (text == nullptr) return;  // out of memory: that error stands
  PyErr_SetObject(type.ptr(), text);
  Py_DECREF(text);
}

}  // namespace

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
      raise(topology, error.what());
    } catch (const InvalidInputError& error) {
      raise(invalidInput, error.what());
    } catch (const SolverError& error) {
      raise(solver, error.what());
    } catch (const CancelledError& error) {
      raise(cancelled, error.what());
    }
  });
}

}  // namespace bvmesh::python

// The exception types of spacar._core and the translation of the core's C++ exceptions to them.
#include "bindings.hpp"

#include <string>

#include "spacar/errors.hpp"
#include "spacar/integrators/integrator.hpp"

namespace spacar::bindings {

namespace {

// The Python exception types, created once; the C++ exception of the same name maps to each.
struct PyErrors {
  py::handle base, input, kinematics, mass, integration, time_limit, statics;
};

PyErrors& py_errors() {
  static PyErrors e;
  return e;
}

// The Python exception type of a C++ exception of the core and its message; a null handle for
// any other exception (left to pybind11's own translation).
py::handle python_type(const std::exception_ptr& p, std::string& message) {
  const PyErrors& e = py_errors();
  try {
    std::rethrow_exception(p);
  } catch (const InputError& x) {
    message = x.what();
    return e.input;
  } catch (const KinematicsError& x) {
    message = x.what();
    return e.kinematics;
  } catch (const SingularMassError& x) {
    message = x.what();
    return e.mass;
  } catch (const Interrupted& x) {  // Ctrl-C: Python's own KeyboardInterrupt, with the results so far
    message = x.what();
    return py::handle(PyExc_KeyboardInterrupt);
  } catch (const StaticError& x) {
    message = x.what();
    return e.statics;
  } catch (const TimeLimitError& x) {
    message = x.what();
    return e.time_limit;
  } catch (const IntegrationError& x) {
    message = x.what();
    return e.integration;
  } catch (const StepRejected& x) {
    message = x.what();
    return e.integration;
  } catch (const Error& x) {
    message = x.what();
    return e.base;
  } catch (...) {
  }
  return py::handle();
}

}  // namespace

void bind_errors(py::module_& m) {
  PyErrors& e = py_errors();
  e.base = py::exception<Error>(m, "SpacarError").release();
  // Invalid input is also a ValueError, as Python code expects of a bad argument.
  e.input = py::exception<InputError>(m, "InputError", py::make_tuple(e.base, py::handle(PyExc_ValueError)))
                .release();
  e.kinematics = py::exception<KinematicsError>(m, "KinematicsError", e.base).release();
  e.mass = py::exception<SingularMassError>(m, "SingularMassError", e.base).release();
  e.integration = py::exception<IntegrationError>(m, "IntegrationError", e.base).release();
  e.time_limit = py::exception<TimeLimitError>(m, "TimeLimitError", e.base).release();
  e.statics = py::exception<StaticError>(m, "StaticError", e.base).release();
  py::register_exception_translator([](std::exception_ptr p) {
    if (!p) return;
    std::string message;
    const py::handle type = python_type(p, message);
    if (type) py::set_error(type, message.c_str());
    else std::rethrow_exception(p);
  });
}

[[noreturn]] void raise_with_results(const std::exception_ptr& p, py::object results) {
  std::string message;
  const py::handle type = python_type(p, message);
  if (!type) std::rethrow_exception(p);
  py::object exc = py::reinterpret_borrow<py::object>(type)(message);
  exc.attr("results") = std::move(results);
  PyErr_SetObject(type.ptr(), exc.ptr());
  throw py::error_already_set();
}

}  // namespace spacar::bindings

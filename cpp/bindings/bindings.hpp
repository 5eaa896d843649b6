// The parts of spacar._core, one unit per subject (module.cpp calls them), and the few helpers
// they share.
#pragma once

#include <pybind11/pybind11.h>

#include <exception>

#include "spacar/analyses/linearize.hpp"

namespace py = pybind11;

namespace spacar::bindings {

void bind_errors(py::module_& m);
void bind_catalogue(py::module_& m);
void bind_model(py::module_& m);
void bind_simulation(py::module_& m);
void bind_topology(py::module_& m);
void bind_statics(py::module_& m);
void bind_ode(py::module_& m);

// Raise the Python exception of a failed run with the results computed before the failure as
// its attribute `results`. Exceptions of Python code called by the run (the on_output callback)
// and foreign C++ exceptions propagate unchanged.
[[noreturn]] void raise_with_results(const std::exception_ptr& p, py::object results);

py::dict linearization_to_dict(const Linearization& l);
py::dict nodal_linearization_to_dict(NodalLinearization&& n);
py::tuple linearization_arrays();

}  // namespace spacar::bindings

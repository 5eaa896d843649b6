// The parts of spacar._core, one unit per subject (module.cpp calls them), and the few helpers
// they share.
#pragma once

#include <pybind11/pybind11.h>

#include <array>
#include <exception>
#include <utility>
#include <vector>

#include "spacar/analyses/linearize.hpp"

namespace py = pybind11;

namespace spacar::bindings {

void bind_errors(py::module_& m);
void bind_limits(py::module_& m);
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

// An analysis run without the GIL: work() fills `results`; the dict of the results (to_dict)
// is returned, or, if work() fails and partial(failure) says that the results computed before
// it are worth keeping, attached to the Python exception (raise_with_results); any other
// failure propagates as it is.
template <class Results, class Work, class ToDict, class Partial>
py::dict run_released(Results& results, Work&& work, ToDict&& to_dict, Partial&& partial) {
  std::exception_ptr failure;
  {
    py::gil_scoped_release release;
    try {
      work();
    } catch (...) {
      failure = std::current_exception();
    }
  }
  if (failure) {
    if (!partial(failure)) std::rethrow_exception(failure);
    raise_with_results(failure, to_dict(std::move(results)));
  }
  return to_dict(std::move(results));
}

// Labels (node or element, index) as an (n, 2) integer array: one conversion, where a list of
// pairs is a Python object per label (1 ms for the labels of 512 beams).
using LabelArray = Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor>;
LabelArray label_array(const std::vector<std::array<int, 2>>& labels);

py::dict linearization_to_dict(const Linearization& l);
py::dict nodal_linearization_to_dict(NodalLinearization&& n);
py::tuple linearization_arrays();

}  // namespace spacar::bindings

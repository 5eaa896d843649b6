// The linearized equations (linearize.hpp) as a dict of arrays.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.hpp"

namespace spacar::bindings {

// The arrays by the names of Linearization::for_each_array (the one list of them), with the
// labels and the time.
py::dict linearization_to_dict(const Linearization& l) {
  py::dict d;
  d["t"] = l.t;
  d["z_label"] = l.z_label;
  d["n_line"] = l.n_line;
  d["y_label"] = l.y_label;
  l.for_each_array([&d](const char* name, const auto& array) { d[name] = array; });
  return d;
}

py::dict nodal_linearization_to_dict(NodalLinearization&& n) {
  py::dict d;
  d["t"] = n.t;
  d["z_label"] = n.z_label;
  d["n_line"] = n.n_line;
  d["M"] = std::move(n.M);
  d["D"] = std::move(n.D);
  d["K"] = std::move(n.K);
  d["G"] = std::move(n.G);
  d["A"] = std::move(n.A);
  d["E"] = std::move(n.E);
  d["B"] = std::move(n.B);
  d["S"] = std::move(n.S);
  d["Dc"] = std::move(n.Dc);
  d["free"] = n.free;
  d["r0"] = std::move(n.r0);
  return d;
}

// The names of the arrays, in the order of for_each_array (spacar.linearize.MATRICES).
py::tuple linearization_arrays() {
  py::list names;
  Linearization().for_each_array([&names](const char* name, const auto&) { names.append(name); });
  return py::tuple(names);
}

}  // namespace spacar::bindings

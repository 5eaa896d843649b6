// The linearized equations (linearize.hpp) as a dict of arrays.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.hpp"

namespace spacar::bindings {

py::dict linearization_to_dict(const Linearization& l) {
  py::dict d;
  d["t"] = l.t;
  d["z_label"] = l.z_label;
  d["n_line"] = l.n_line;
  d["M0"] = l.M0;
  d["C0"] = l.C0;
  d["D0"] = l.D0;
  d["K0"] = l.K0;
  d["N0"] = l.N0;
  d["G0"] = l.G0;
  d["r0"] = l.r0;
  d["DFz"] = l.DFz;
  d["DFez"] = l.DFez;
  d["y_label"] = l.y_label;
  d["Kk"] = l.Kk;
  d["AK0"] = l.AK0;
  d["BK0"] = l.BK0;
  return d;
}

}  // namespace spacar::bindings

// spacar._core: thin pybind11 bindings of the C++ core, one unit per subject (bindings.hpp). No
// logic here: the Python package (python/spacar) builds the user-facing API on top.
#include "bindings.hpp"

using namespace spacar::bindings;

PYBIND11_MODULE(_core, m) {
  m.doc() = "spacar C++ core";
  bind_errors(m);
  bind_limits(m);
  bind_catalogue(m);
  bind_model(m);
  bind_simulation(m);
  bind_topology(m);
  bind_statics(m);
  bind_ode(m);
}

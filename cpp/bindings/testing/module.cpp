// spacar._testing: direct access to pieces of the core that the shipped API does not expose, for
// the tests: one element kernel, the integrators each on its own on a Python right-hand side, the
// sparse LU, the static forces, the explicit chain kinematics. Kept out of spacar._core; the
// shipped package (spacar.compare included) does not import it.
#include <pybind11/pybind11.h>

namespace py = pybind11;

void bind_kernels(py::module_& m);
void bind_integrator(py::module_& m);
void bind_sparse(py::module_& m);
void bind_statics(py::module_& m);
void bind_radau(py::module_& m);
void bind_chain(py::module_& m);

PYBIND11_MODULE(_testing, m) {
  m.doc() = "spacar core internals for tests and peer comparisons";
  // The core's exception types and their translation are registered by spacar._core.
  py::module_::import("spacar._core");
  bind_kernels(m);
  bind_integrator(m);
  bind_sparse(m);
  bind_statics(m);
  bind_radau(m);
  bind_chain(m);
}

// spacar._testing: the static forces and tangent stiffness at a solved state (statics.hpp), for
// the tests of the tangent against differences.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include "spacar/simulate.hpp"
#include "spacar/statics.hpp"

namespace py = pybind11;

void bind_statics(py::module_& m) {
  m.def(
      "static_forces",
      [](spacar::Simulation& sim, double lambda) {
        Eigen::VectorXd R;
        Eigen::MatrixXd K;
        spacar::static_forces(sim.system(), sim.data(), lambda, R, &K);
        return py::make_tuple(R, K);
      },
      py::arg("simulation"), py::arg("load_factor"),
      "(R, K) at the simulation's solved positions, at rest, under λ times the loads: the reduced "
      "generalized forces and the tangent stiffness K0 + G0.");
}

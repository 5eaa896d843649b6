// Binding of the static analysis (statics.hpp): spacar._core.solve_static and the Python
// exception StaticError (a SpacarError) carrying the converged load steps as `results`.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "spacar/statics.hpp"

namespace py = pybind11;
using namespace spacar;

namespace {

py::handle& static_error_type() {
  static py::handle type;
  return type;
}

py::dict static_results_to_dict(StaticResults&& r) {
  py::dict d;
  d["coord_label"] = r.coord_label;
  d["def_label"] = r.def_label;
  d["load"] = std::move(r.load);
  d["x"] = std::move(r.x);
  d["e"] = std::move(r.e);
  d["sigma"] = std::move(r.sigma);
  d["reaction"] = std::move(r.reaction);
  d["iterations"] = r.iterations;
  d["load_reached"] = r.load_reached;
  d["newton_iterations"] = r.newton_iterations;
  d["step_cuts"] = r.step_cuts;
  d["kinematic_iterations"] = r.kinematic_iterations;
  d["indefinite_at"] = r.indefinite_at;
  d["wall_time"] = r.wall_time;
  d["warnings"] = r.warnings;
  return d;
}

}  // namespace

void bind_statics(py::module_& m) {
  static_error_type() = py::exception<StaticError>(m, "StaticError", m.attr("SpacarError")).release();
  // Registered after the core's translator, so tried before it (a StaticError is also an Error).
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const StaticError& e) {
      py::set_error(static_error_type(), e.what());
    }
  });
  m.def(
      "solve_static",
      [](Model& model, int steps, int max_iterations, int max_cuts, double tolerance) {
        StaticOptions opt;
        opt.steps = steps;
        opt.max_iterations = max_iterations;
        opt.max_cuts = max_cuts;
        opt.tolerance = tolerance;
        StaticResults r;
        std::string failure;
        {
          py::gil_scoped_release release;
          try {
            solve_static(model, r, opt);
          } catch (const StaticError& e) {
            failure = e.what();
          }
        }
        if (!failure.empty()) {
          const py::handle type = static_error_type();
          py::object exc = py::reinterpret_borrow<py::object>(type)(failure);
          exc.attr("results") = static_results_to_dict(std::move(r));
          PyErr_SetObject(type.ptr(), exc.ptr());
          throw py::error_already_set();
        }
        return static_results_to_dict(std::move(r));
      },
      py::arg("model"), py::arg("steps") = 10, py::arg("max_iterations") = 30, py::arg("max_cuts") = 12,
      py::arg("tolerance") = 1e-10,
      "Static equilibrium of the model's block in load steps; StaticError (with `results`, the converged "
      "steps) if Newton fails beyond the smallest step.");
  m.def(
      "static_forces",
      [](Simulation& sim, double lambda) {
        Eigen::VectorXd R;
        Eigen::MatrixXd K;
        static_forces(sim.system(), sim.data(), lambda, R, &K);
        return py::make_tuple(R, K);
      },
      py::arg("simulation"), py::arg("load_factor"),
      "(R, K) at the simulation's solved positions, at rest, under λ times the loads: the reduced "
      "generalized forces and the tangent stiffness K0 + G0 (for tests against differences).");
}

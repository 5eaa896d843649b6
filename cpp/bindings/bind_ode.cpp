// spacar._core.solve_ode: any integration method of the table (stepper.hpp) on a Python
// right-hand side (and Jacobian), the stepper made as a run makes it: the generic checks of
// tests/core/test_steppers.py cover every method, a new one included, without a binding of its
// own, and spacar.compare integrates its peers' equations with spacar's own integrators.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <limits>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "spacar/integrators/stepper.hpp"

namespace py = pybind11;

namespace {

py::dict solve(const std::string& method, const py::function& f, const py::object& jac, double t0,
               const Eigen::VectorXd& y0, double t_end, const std::vector<double>& touts, double rtol, double atol,
               int positions, double hmax, double first_step, long max_steps) {
  const int n = static_cast<int>(y0.size());
  spacar::StepperSetup setup;
  setup.n = n;
  setup.positions = positions;
  setup.rate_offset = n - positions;
  if (!jac.is_none())
    setup.jacobian = [jac](double t, const Eigen::VectorXd& y, Eigen::MatrixXd& J) {
      J = jac(t, y).cast<Eigen::MatrixXd>();
    };
  const std::unique_ptr<spacar::Stepper> stepper = spacar::make_stepper(spacar::parse_method(method), setup);
  stepper->set_tolerances(Eigen::VectorXd::Constant(n, rtol), Eigen::VectorXd::Constant(n, atol));
  stepper->set_max_step(hmax);
  stepper->set_initial_step(first_step);
  stepper->set_max_steps(max_steps);
  const spacar::Stepper::Rhs rhs = [&f](double t, const Eigen::VectorXd& y, Eigen::VectorXd& dy) {
    dy = f(t, y).cast<Eigen::VectorXd>();
  };
  Eigen::MatrixXd ys = Eigen::MatrixXd::Constant(touts.size(), n, std::numeric_limits<double>::quiet_NaN());
  std::vector<double> times;
  const spacar::Stepper::Output out = [&](double t, const Eigen::VectorXd& y) {
    ys.row(static_cast<Eigen::Index>(times.size())) = y.transpose();
    times.push_back(t);
  };
  Eigen::VectorXd y = y0;
  const double t_reached = stepper->integrate(rhs, t0, t_end, y, touts, out);
  const spacar::StepperStats& s = stepper->stats();
  py::dict result;
  result["t"] = times;
  result["y"] = ys;
  result["y_end"] = y;
  result["t_reached"] = t_reached;
  result["last_step"] = stepper->last_step();
  for (const auto& [key, value] : {std::pair<const char*, long>{"nfev", s.nfev}, {"nsteps", s.nsteps},
                                   {"naccept", s.naccept}, {"nreject", s.nreject}, {"njev", s.njev},
                                   {"ndec", s.ndec}, {"nnewton", s.nnewton}})
    result[key] = value;
  return result;
}

}  // namespace

void spacar::bindings::bind_ode(py::module_& m) {
  m.def("solve_ode", &solve, py::arg("method"), py::arg("f"), py::arg("jac"), py::arg("t0"), py::arg("y0"),
        py::arg("t_end"), py::arg("touts"), py::arg("rtol"), py::arg("atol"), py::arg("positions") = 0,
        py::arg("hmax") = std::numeric_limits<double>::infinity(), py::arg("first_step") = 0.0,
        py::arg("max_steps") = spacar::Stepper::kMaxSteps,
        "Integrate dy/dt = f(t, y) (Jacobian jac(t, y), n x n, or None) from t0 to t_end with the "
        "stepper of `method` as a run makes it (make_stepper, without a run's floor of the Newton increments: "
        "set_newton_floor; the first `positions` states are positions whose "
        "rates are the last ones); returns t and y at touts, y_end, t_reached, last_step and the counters "
        "nfev, nsteps, naccept, nreject, njev, ndec, nnewton.");
}

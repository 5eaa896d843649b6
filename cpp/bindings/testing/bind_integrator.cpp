// Binding of the Runge-Kutta integrator (spacar._testing): integrates a Python rhs so that the tests can
// check accuracy, dense output and failure handling against exact solutions.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <limits>
#include <string>
#include <vector>

#include "spacar/integrators/integrator.hpp"

namespace py = pybind11;

namespace {

py::dict solve_explicit(const py::function& f, double t0, const Eigen::VectorXd& y0, double t_end,
               const std::vector<double>& touts, double rtol, double atol,
               const std::string& method, double hmax, bool detect_stiffness) {
  const int n = static_cast<int>(y0.size());
  spacar::Integrator integrator(n, spacar::parse_method(method));
  integrator.set_tolerances(Eigen::VectorXd::Constant(n, rtol),
                            Eigen::VectorXd::Constant(n, atol));
  integrator.set_max_step(hmax);
  integrator.set_stiffness_detection(detect_stiffness);

  const spacar::Integrator::Rhs rhs = [&f](double t, const Eigen::VectorXd& y,
                                           Eigen::VectorXd& dy) {
    dy = f(t, y).cast<Eigen::VectorXd>();
  };
  Eigen::MatrixXd ys = Eigen::MatrixXd::Constant(touts.size(), n, std::numeric_limits<double>::quiet_NaN());
  Eigen::Index row = 0;
  const spacar::Integrator::Output out = [&ys, &row](double, const Eigen::VectorXd& y) {
    ys.row(row++) = y.transpose();
  };
  Eigen::VectorXd y = y0;
  const double t_reached = integrator.integrate(rhs, t0, t_end, y, touts, out);

  const spacar::StepperStats& stats = integrator.stats();
  py::dict result;
  result["t"] = py::array_t<double>(static_cast<py::ssize_t>(touts.size()), touts.data());
  result["y"] = ys;
  result["nfev"] = stats.nfev;
  result["naccept"] = stats.naccept;
  result["nreject"] = stats.nreject;
  result["t_reached"] = t_reached;
  result["stiff"] = integrator.wants_switch();
  result["hlamb"] = integrator.stiffness_estimate();
  return result;
}

}  // namespace

void bind_integrator(py::module_& m) {
  m.def("explicit_rk_solve", &solve_explicit, py::arg("f"), py::arg("t0"), py::arg("y0"), py::arg("t_end"),
        py::arg("touts"), py::arg("rtol"), py::arg("atol"), py::arg("method") = "dop853",
        py::arg("hmax") = std::numeric_limits<double>::infinity(), py::arg("detect_stiffness") = false,
        "Test helper: integrate dy/dt = f(t, y) from t0 to t_end with the embedded Runge-Kutta "
        "method 'dop853' or 'dopri5' and return the dense output at touts as a dict with t, y "
        "(len(touts) x n), nfev, naccept, nreject; with detect_stiffness the run stops where the "
        "method detects stiffness: t_reached, stiff and hlamb (h|lambda| of the last step) say so "
        "(the rows of later output times are NaN).");
}

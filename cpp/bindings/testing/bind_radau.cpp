// Test-only binding of the implicit integrators (Radau IIA, generalized-α): integrate a Python rhs
// with a Python Jacobian so that the tests can check accuracy, order, dense output and the cost on
// stiff problems.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <limits>
#include <vector>

#include "spacar/integrators/generalized_alpha.hpp"
#include "spacar/integrators/radau5.hpp"

namespace py = pybind11;

namespace {

// The output times, the dense output at them and the counters of an implicit integrator.
py::dict outputs(const std::vector<double>& touts, const Eigen::MatrixXd& ys, const spacar::StepperStats& s) {
  py::dict result;
  result["t"] = py::array_t<double>(static_cast<py::ssize_t>(touts.size()), touts.data());
  result["y"] = ys;
  result["nfev"] = s.nfev;
  result["njev"] = s.njev;
  result["ndec"] = s.ndec;
  result["nnewton"] = s.nnewton;
  result["nresidual"] = s.nresidual;
  result["nsteps"] = s.nsteps;
  result["naccept"] = s.naccept;
  result["nreject"] = s.nreject;
  return result;
}

// y(t0) → y(t_end) by an implicit integrator (Radau5 or GeneralizedAlpha) on Python callbacks,
// the rows of ys filled at the output times.
template <class Integ>
double integrate_python(Integ& integrator, const py::function& f, const py::function& jac, double t0, Eigen::VectorXd& y,
                      double t_end, const std::vector<double>& touts, Eigen::MatrixXd& ys) {
  integrator.set_jacobian([&jac](double t, const Eigen::VectorXd& yy, Eigen::MatrixXd& J) {
    J = jac(t, yy).template cast<Eigen::MatrixXd>();
  });
  const spacar::Radau5::Rhs rhs = [&f](double t, const Eigen::VectorXd& yy, Eigen::VectorXd& dy) {
    dy = f(t, yy).template cast<Eigen::VectorXd>();
  };
  ys = Eigen::MatrixXd::Constant(touts.size(), y.size(), std::numeric_limits<double>::quiet_NaN());
  Eigen::Index row = 0;
  const spacar::Radau5::Output out = [&ys, &row](double, const Eigen::VectorXd& yy) { ys.row(row++) = yy.transpose(); };
  return integrator.integrate(rhs, t0, t_end, y, touts, out);
}

// The settings both implicit integrators take from the test helpers.
template <class Integ>
void configure(Integ& integrator, int n, double rtol, double atol, double hmax, double first_step) {
  integrator.set_tolerances(Eigen::VectorXd::Constant(n, rtol), Eigen::VectorXd::Constant(n, atol));
  integrator.set_max_step(hmax);
  integrator.set_initial_step(first_step);
}

py::dict solve_radau5(const py::function& f, const py::function& jac, double t0, const Eigen::VectorXd& y0,
               double t_end, const std::vector<double>& touts, double rtol, double atol, double hmax,
               double first_step, double nonstiff_bound) {
  const int n = static_cast<int>(y0.size());
  spacar::Radau5 integrator(n);
  configure(integrator, n, rtol, atol, hmax, first_step);
  integrator.set_nonstiffness_detection(nonstiff_bound);
  Eigen::VectorXd y = y0;
  Eigen::MatrixXd ys;
  const double t_reached = integrate_python(integrator, f, jac, t0, y, t_end, touts, ys);

  py::dict result = outputs(touts, ys, integrator.stats());
  result["t_reached"] = t_reached;
  result["nonstiff"] = integrator.wants_switch();
  result["rho"] = integrator.spectral_radius();
  return result;
}

py::dict solve_generalized_alpha(const py::function& f, const py::function& jac, double t0, const Eigen::VectorXd& y0,
                                 double t_end, const std::vector<double>& touts, double rtol, double atol, int m,
                                 int rate_offset, double rho_inf, double hmax, double first_step, double fixed_step,
                                 const py::object& residual, const py::object& weight) {
  const int n = static_cast<int>(y0.size());
  spacar::GeneralizedAlpha integrator(n, m, rate_offset < 0 ? n - m : rate_offset, rho_inf);
  configure(integrator, n, rtol, atol, hmax, first_step);
  integrator.set_fixed_step(fixed_step);
  if (!residual.is_none())
    integrator.set_residual(
        [residual](double t, const Eigen::VectorXd& y, const Eigen::VectorXd& D, Eigen::VectorXd& R) {
          R = residual(t, y, D).cast<Eigen::VectorXd>();
        },
        [weight](Eigen::MatrixXd& W) { W = weight().cast<Eigen::MatrixXd>(); });
  Eigen::VectorXd y = y0;
  Eigen::MatrixXd ys;
  integrate_python(integrator, f, jac, t0, y, t_end, touts, ys);
  return outputs(touts, ys, integrator.stats());
}

}  // namespace

void bind_radau(py::module_& m) {
  m.def("radau5_solve", &solve_radau5, py::arg("f"), py::arg("jac"), py::arg("t0"), py::arg("y0"), py::arg("t_end"),
        py::arg("touts"), py::arg("rtol"), py::arg("atol"),
        py::arg("hmax") = std::numeric_limits<double>::infinity(), py::arg("first_step") = 0.0,
        py::arg("nonstiff_bound") = 0.0,
        "Test helper: integrate dy/dt = f(t, y) with jacobian jac(t, y) (n x n) by Radau IIA of order 5 "
        "from t0 to t_end; returns the dense output at touts as a dict with t, y (len(touts) x n) and the "
        "counters nfev, njev, ndec, nnewton, nsteps, naccept, nreject; with nonstiff_bound > 0 the run stops "
        "where rho(J) h stays below it (t_reached, nonstiff, rho; later output rows NaN).");
  m.def("generalized_alpha_solve", &solve_generalized_alpha, py::arg("f"), py::arg("jac"), py::arg("t0"),
        py::arg("y0"), py::arg("t_end"), py::arg("touts"), py::arg("rtol"), py::arg("atol"), py::arg("m"),
        py::arg("rate_offset") = -1, py::arg("rho_inf") = 0.9,
        py::arg("hmax") = std::numeric_limits<double>::infinity(), py::arg("first_step") = 0.0,
        py::arg("fixed_step") = 0.0, py::arg("residual") = py::none(), py::arg("weight") = py::none(),
        "Test helper: integrate dy/dt = f(t, y) whose first m components are positions with rates at "
        "rate_offset (default: the last m) by generalized-alpha with spectral radius rho_inf (fixed_step > 0: "
        "fixed steps, no error control); returns the dense output at touts and the counters as radau5_solve. "
        "residual(t, y, D) -> R and weight() -> W_v: the residual form (GeneralizedAlpha::set_residual); "
        "weight is called after each call of jac.");
}

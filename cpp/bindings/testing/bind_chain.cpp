// spacar._testing: the explicit kinematics of open chains (chain.hpp) at a state, for the tests
// against the general path (Simulation.solve_state).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include "spacar/recursive/chain.hpp"
#include "spacar/kinematics/dynamics.hpp"
#include "spacar/errors.hpp"
#include "spacar/kinematics/kinematics.hpp"
#include "spacar/analyses/simulate.hpp"

namespace py = pybind11;

namespace {

// The chain's positions and velocities at (t, q, q̇), from the simulation's current positions;
// nullptr (nothing done) if the system is not an open chain.
std::unique_ptr<spacar::ExplicitChain> chain_motion(const char* what, spacar::Simulation& sim, double t,
                                                    const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  const spacar::System& sys = sim.system();
  if (q.size() != sys.n_dof() || qd.size() != sys.n_dof())
    throw spacar::InputError(std::string(what) + "(): q and qd must have one value per degree of freedom");
  std::unique_ptr<spacar::ExplicitChain> chain = spacar::ExplicitChain::detect(sys);
  if (!chain) return chain;
  spacar::Data& d = sim.data();
  spacar::set_inputs(sys, d, t);
  spacar::set_dofs(sys, d, q.data(), qd.data());
  chain->solve_positions(sys, d, sys.settings.maxiterat, sys.settings.epskin);
  chain->solve_velocities(sys, d);
  return chain;
}

}  // namespace

void bind_chain(py::module_& m) {
  m.def(
      "chain_state",
      [](spacar::Simulation& sim, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) -> py::object {
        const spacar::System& sys = sim.system();
        std::unique_ptr<spacar::ExplicitChain> chain = chain_motion("chain_state", sim, t, q, qd);
        if (!chain) return py::none();
        spacar::Data& d = sim.data();
        spacar::solve_dynamics_direct(sys, d);
        py::dict out;
        out["x"] = d.x;
        out["xd"] = d.xd;
        out["xdd"] = d.xdd;
        out["qdd"] = d.qdd;
        out["e"] = d.e;
        out["ed"] = d.ed;
        out["blocks"] = chain->blocks();
        out["closed_form_blocks"] = chain->closed_form_blocks();
        out["newton_iterations"] = d.newton_iterations;
        return out;
      },
      py::arg("simulation"), py::arg("t"), py::arg("q"), py::arg("qd"),
      "The right-hand side's state by the explicit chain at (t, q, q̇), starting from the simulation's "
      "current positions (a dict of x, xd, xdd, qdd, e, ed, blocks, closed_form_blocks, newton_iterations; None if the system "
      "is not an open chain). The simulation's data is left at that state.");
  m.def(
      "chain_residual",
      [](spacar::Simulation& sim, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
         const Eigen::VectorXd& qdd) -> py::object {
        const spacar::System& sys = sim.system();
        const int nd = sys.n_dof();
        if (qdd.size() != nd) throw spacar::InputError("chain_residual(): qdd must have one value per degree of freedom");
        std::unique_ptr<spacar::ExplicitChain> chain = chain_motion("chain_residual", sim, t, q, qd);
        if (!chain) return py::none();
        spacar::Data& d = sim.data();
        spacar::set_dof_accelerations(sys, d, qdd);
        Eigen::VectorXd R;
        spacar::reduced_residual_direct(sys, d, R, chain.get());
        py::dict out;
        out["residual"] = R;
        out["xdd"] = d.xdd;
        out["edd"] = d.edd;
        return out;
      },
      py::arg("simulation"), py::arg("t"), py::arg("q"), py::arg("qd"), py::arg("qdd"),
      "The residual of the reduced equations of motion at a trial q̈ by the explicit chain "
      "(generalized-α's residual form), from the simulation's current positions: a dict of residual "
      "(R = M̄ (q̈ − q̈(q, q̇))), xdd and edd at that q̈; None if the system is not an open chain.");
}

// Binding of the static analysis (statics.hpp): spacar._core.solve_static; a failure raises
// StaticError (bind_errors.cpp) carrying the converged load steps as `results`.
#include <algorithm>
#include <optional>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "spacar/kinematics.hpp"
#include "spacar/simulate.hpp"
#include "spacar/statics.hpp"

namespace spacar::bindings {

namespace {

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
  m.def(
      "solve_static",
      [](Model& model, int steps, int max_iterations, int max_cuts, double tolerance) {
        StaticOptions opt;
        opt.steps = steps;
        opt.max_iterations = max_iterations;
        opt.max_cuts = max_cuts;
        opt.tolerance = tolerance;
        StaticResults r;
        std::exception_ptr failure;
        {
          py::gil_scoped_release release;
          try {
            solve_static(model, r, opt);
          } catch (const StaticError&) {
            failure = std::current_exception();
          }
        }
        if (failure) raise_with_results(failure, static_results_to_dict(std::move(r)));
        return static_results_to_dict(std::move(r));
      },
      py::arg("model"), py::arg("steps") = 10, py::arg("max_iterations") = 30, py::arg("max_cuts") = 12,
      py::arg("tolerance") = 1e-10,
      "Static equilibrium of the model's block in load steps; StaticError (with `results`, the converged "
      "steps) if Newton fails beyond the smallest step.");

  // The tangent of the static solve for spacar.compliance, at the model's current state or, given
  // a row (x, e) of static results, at that row: the model is assembled as a simulation does (and
  // put there), then R, K0 + G0 under load_factor times the block's
  // loads and DF restricted to the degrees of freedom (∂x/∂q) are evaluated.
  m.def(
      "static_tangent",
      [](Model& model, double load_factor, std::optional<Eigen::VectorXd> x, std::optional<Eigen::VectorXd> e) {
        Simulation sim(model);
        sim.assemble();
        const System& sys = sim.system();
        if (x || e) {
          if (!x || !e || x->size() != sys.nx || e->size() != sys.ne)
            throw InputError("static_tangent: x and e must both be given, with " + std::to_string(sys.nx) + " and " +
                             std::to_string(sys.ne) + " values");
          // The row is a solved state: its positions, and the independent coordinates from them;
          // the kinematics then only refreshes the deformations and their derivatives there.
          Data& data = sim.data();
          data.x = *x;
          for (int g = 0; g < sys.nx; ++g)
            if (sys.qhat_col_x[g] >= 0) data.qhat[sys.qhat_col_x[g]] = (*x)[g];
          for (int k = 0; k < sys.ne; ++k)
            if (sys.qhat_col_e[k] >= 0) data.qhat[sys.qhat_col_e[k]] = (*e)[k];
          data.jacobian_reusable = false;
          solve_positions(sys, data, std::max(sys.settings.maxiterat, 50), std::min(sys.settings.epskin, 1e-10), false);
        }
        Eigen::VectorXd R;
        Eigen::MatrixXd K;
        static_forces(sys, sim.data(), load_factor, R, &K);
        std::vector<std::string> dofs;
        for (int j = 0; j < sys.n_dof(); ++j) dofs.push_back(dof_name(sys, j));
        py::dict d;
        d["K"] = K;
        d["R"] = R;
        d["DF"] = Eigen::MatrixXd(sim.data().DFq);
        d["x"] = Eigen::VectorXd(sim.data().x);
        d["coord_label"] = sys.coord_label;
        d["dof_names"] = dofs;
        return d;
      },
      py::arg("model"), py::arg("load_factor") = 1.0, py::arg("x") = py::none(), py::arg("e") = py::none(),
      "At the model's current state, or at the degrees of freedom of (x, e) (a row of static results): the "
      "reduced forces R and tangent stiffness K0 + G0 of the static solve under load_factor times the block's "
      "loads, DF of the degrees of freedom, x and the labels.");
}

}  // namespace spacar::bindings

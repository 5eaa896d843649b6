// Binding of the static analysis (statics.hpp): spacar._core.solve_static; a failure raises
// StaticError (bind_errors.cpp) carrying the converged load steps as `results`.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
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

  // The tangent of the static solve at the model's current state, for spacar.compliance: the
  // model is assembled as a simulation does, then R, K0 + G0 (λ = 1: the block's full loads) and
  // DF restricted to the degrees of freedom (∂x/∂q) are evaluated there.
  m.def(
      "static_tangent",
      [](Model& model) {
        Simulation sim(model);
        sim.assemble();
        const System& sys = sim.system();
        Eigen::VectorXd R;
        Eigen::MatrixXd K;
        static_forces(sys, sim.data(), 1.0, R, &K);
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
      py::arg("model"),
      "At the model's current state (assembled): the reduced forces R and tangent stiffness K0 + G0 of "
      "the static solve under the block's full loads, DF of the degrees of freedom, x and the labels.");
}

}  // namespace spacar::bindings

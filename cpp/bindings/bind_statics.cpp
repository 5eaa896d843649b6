// Binding of the static analysis (statics.hpp): spacar._core.solve_static (a failure raises
// StaticError, bind_errors.cpp, carrying the converged load steps as `results`) and
// static_compliance (for spacar.compliance).
#include <optional>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "spacar/analyses/sensitivity.hpp"
#include "spacar/analyses/statics.hpp"

namespace spacar::bindings {

LabelArray label_array(const std::vector<std::array<int, 2>>& labels) {
  LabelArray a(labels.size(), 2);
  for (size_t i = 0; i < labels.size(); ++i) a.row(static_cast<Eigen::Index>(i)) << labels[i][0], labels[i][1];
  return a;
}

namespace {

py::dict static_results_to_dict(StaticResults&& r) {
  py::dict d;
  d["coord_label"] = label_array(r.coord_label);
  d["def_label"] = label_array(r.def_label);
  d["x_dyn"] = r.x_dyn;
  d["e_dyn"] = r.e_dyn;
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
  d["limit_points"] = r.limit_points;
  d["wall_time"] = r.wall_time;
  d["warnings"] = r.warnings;
  return d;
}

StaticOptions static_options(int steps, int max_iterations, int max_cuts, double tolerance, bool arc_length,
                             int max_steps, double time_limit) {
  StaticOptions opt;
  opt.steps = steps;
  opt.max_iterations = max_iterations;
  opt.max_cuts = max_cuts;
  opt.tolerance = tolerance;
  opt.arc_length = arc_length;
  opt.max_steps = max_steps;
  opt.time_limit = time_limit;
  return opt;
}

// A static analysis without the GIL; a StaticError carries the converged steps as `results`, a
// TimeLimitError too once the rows exist (not in the set-up).
template <class Work>
py::dict run_static(StaticResults& r, Work&& work) {
  return run_released(r, std::forward<Work>(work), static_results_to_dict, [&r](const std::exception_ptr& failure) {
    try {
      std::rethrow_exception(failure);
    } catch (const StaticError&) {
      return true;
    } catch (const TimeLimitError&) {
      return r.x.cols() > 0;
    } catch (...) {
      return false;
    }
  });
}

// spacar.StaticSolver's core: a copy of the model, and the solver set up on it.
struct PreparedStatics {
  explicit PreparedStatics(const Model& m) : model(m), solver(model) {}
  Model model;
  StaticSolver solver;
};

}  // namespace

void bind_statics(py::module_& m) {
  m.def(
      "solve_static",
      [](Model& model, int steps, int max_iterations, int max_cuts, double tolerance, bool arc_length,
         int max_steps, double time_limit) {
        const StaticOptions opt = static_options(steps, max_iterations, max_cuts, tolerance, arc_length, max_steps,
                                                 time_limit);
        StaticResults r;
        return run_static(r, [&] { solve_static(model, r, opt); });
      },
      py::arg("model"), py::arg("steps") = 10, py::arg("max_iterations") = 30, py::arg("max_cuts") = 12,
      py::arg("tolerance") = 1e-10, py::arg("arc_length") = false, py::arg("max_steps") = 200,
      py::arg("time_limit") = 0.0,
      "Static equilibrium of the model's block in load steps (or by the arc-length method past limit "
      "points); StaticError (with `results`, the converged steps) if no equilibrium is found.");

  py::class_<PreparedStatics>(m, "StaticSolver",
                              "The static analysis of a copy of a model set up once (spacar.StaticSolver): "
                              "compiled, its open chain recognized, the tangent's pattern ordered.")
      .def(py::init<const Model&>(), py::arg("model"))
      .def(
          "solve",
          [](PreparedStatics& p, std::optional<Eigen::VectorXd> force, int steps, int max_iterations, int max_cuts,
             double tolerance, bool arc_length, int max_steps, double time_limit) {
            const StaticOptions opt = static_options(steps, max_iterations, max_cuts, tolerance, arc_length,
                                                     max_steps, time_limit);
            StaticResults r;
            return run_static(r, [&] { p.solver.solve(r, opt, force ? &*force : nullptr); });
          },
          py::arg("force") = py::none(), py::arg("steps") = 10, py::arg("max_iterations") = 30,
          py::arg("max_cuts") = 12, py::arg("tolerance") = 1e-10, py::arg("arc_length") = false,
          py::arg("max_steps") = 200, py::arg("time_limit") = 0.0,
          "solve_static's analysis from the model's state when the solver was made; force: the FORCE loads on "
          "every nodal coordinate in place of the model's (None: the model's).")
      .def_property_readonly(
          "model", [](PreparedStatics& p) -> const Model& { return p.model; },
          "The solver's copy of the model, prepared, at the state every solve starts from (not to be changed).")
      .def_property_readonly(
          "force", [](const PreparedStatics& p) { return Eigen::VectorXd(p.solver.system().force); },
          "The model's FORCE loads on every nodal coordinate (in the order of coordinate_labels).")
      .def_property_readonly(
          "coordinate_labels", [](const PreparedStatics& p) { return label_array(p.solver.system().coord_label); },
          "(node, component) of every nodal coordinate.");

  m.def(
      "static_compliance",
      [](Model& model, const std::vector<int>& nodes, double load_factor, std::optional<Eigen::VectorXd> x,
         std::optional<Eigen::VectorXd> e) {
        py::gil_scoped_release release;
        return static_compliance(model, nodes, load_factor, x ? &*x : nullptr, e ? &*e : nullptr);
      },
      py::arg("model"), py::arg("nodes"), py::arg("load_factor") = 1.0, py::arg("x") = py::none(),
      py::arg("e") = py::none(),
      "At the model's current state, or at the degrees of freedom of (x, e) (a row of static results): the "
      "compliance at the nodes (their coordinates; a LAMBDA node's rotation vector in global axes) under the "
      "tangent stiffness K0 + G0 of the static solve at load_factor times the block's loads (sparse); StaticError "
      "naming the direction if the stiffness is singular.");

  py::class_<StaticPoint>(m, "StaticPoint",
                          "A static equilibrium held for design sensitivities (spacar.sensitivity): the model put at "
                          "the positions x with the deformations e (a row of static results), the block's loads in full.")
      .def(py::init<Model&, const Eigen::VectorXd&, const Eigen::VectorXd&>(), py::arg("model"), py::arg("x"),
           py::arg("e"), py::keep_alive<1, 2>())
      .def_property_readonly("q", &StaticPoint::dofs, "The degrees of freedom at the current state.")
      .def_property_readonly("x", [](StaticPoint& p) { return Eigen::VectorXd(p.x()); })
      .def_property_readonly("e", [](StaticPoint& p) { return Eigen::VectorXd(p.e()); })
      .def_property_readonly("residual", &StaticPoint::residual,
                             "R = DF_qᵀ (Σ Bᵀσ − f) at the current state (zero at an equilibrium).")
      .def_property_readonly("load_scale", &StaticPoint::load_scale,
                             "The largest applied or elastic load on a coordinate (loads on lengths times the "
                             "mean element length): the scale of the residual.")
      .def_property_readonly("dof_scale", [](const StaticPoint& p) { return dof_scale(p.system()); },
                             "The size of each DOF: the mean element length for lengths, 1 for angles.")
      .def_property_readonly(
          "coordinate_labels", [](const StaticPoint& p) { return p.system().coord_label; },
          "(node, component) of every coordinate.")
      .def("symmetric", &StaticPoint::symmetric, "Whether the tangent K0 + G0 is symmetric (factorizes it).")
      .def("move_to", &StaticPoint::move_to, py::arg("q"), "Move the DOFs to q (positions and forces solved again).")
      .def("solve", &StaticPoint::solve, py::arg("r"), "K_T⁻¹ r, K_T = K0 + G0 at the current state (sparse).")
      .def("motion", &StaticPoint::motion, py::arg("dq"), "DF_q dq: the motion of every coordinate.")
      .def("energies", &StaticPoint::energies, py::arg("dq"),
           "(dqᵀK0dq, dqᵀG0dq, dqᵀM0dq, dqᵀD0dq) at the current state, element by element.")
      .def(
          "compliance",
          [](StaticPoint& p, const std::vector<int>& nodes) {
            Eigen::MatrixXd U;
            Eigen::MatrixXd C = p.compliance(nodes, &U);
            return py::make_tuple(C, U);
          },
          py::arg("nodes"),
          "(C, U): the compliance at the nodes under K_T at the current state, and U = K_T⁻¹ DF_qᵀ Tᵀ, the DOFs' "
          "response to each unit load.");
}

}  // namespace spacar::bindings

// The analysis of a block (simulate.hpp): the compiled system, its data, and the simulation
// with its stages and its run.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "spacar/kinematics/diagnosis.hpp"
#include "spacar/errors.hpp"
#include "spacar/limits.hpp"
#include "spacar/analyses/simulate.hpp"

namespace spacar::bindings {

namespace {

// Whether Python has a Ctrl-C pending for the main thread (InterruptScope's poll, called by a run
// without the GIL): Python's signal handler runs here; its KeyboardInterrupt is dropped, as the
// run raises its own with the results computed so far.
bool python_interrupt_pending() {
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() == 0) return false;
  PyErr_Clear();
  return true;
}

py::dict block_results_to_dict(BlockResults&& r) {
  py::dict d;
  d["t"] = std::move(r.t);
  for (const OutputArray& a : kOutputArrays) d[a.name] = std::move(r.*a.rows);
  py::list lins;
  for (const Linearization& l : r.linearizations) lins.append(linearization_to_dict(l));
  d["linearizations"] = lins;
  for (const RunCounter& c : kRunCounters) d[c.name] = r.*c.value;
  d["last_step"] = r.last_step;
  d["wall_time"] = r.wall_time;
  d["recursive"] = r.recursive;
  d["path"] = r.path;
  d["method"] = method_name(r.method);
  py::list switches;
  for (const MethodSwitch& w : r.switches)
    switches.append(py::make_tuple(w.t, method_name(w.from), method_name(w.to)));
  d["switches"] = switches;
  d["warnings"] = r.warnings;
  if (r.energy.size() || r.energy.cols()) {
    py::dict energy;
    for (size_t c = 0; c < std::size(kEnergyColumns); ++c)
      energy[kEnergyColumns[c]] = Eigen::VectorXd(r.energy.col(static_cast<Eigen::Index>(c)));
    d["energy"] = energy;
  }
  return d;
}

// The lists that cross into Python, from the core's tables: the output arrays (name, over
// "coordinate" or "deformation", what they hold), the energy columns, the run's counters (name,
// counted by the implicit methods only), the run options' defaults and the method names.
void bind_lists(py::module_& m) {
  m.attr("linearization_arrays") = linearization_arrays();
  m.attr("integration_methods") = py::tuple(py::cast(method_names()));
  m.attr("implicit_methods") = py::tuple(py::cast(implicit_method_names()));
  py::list arrays, counters;
  for (const OutputArray& a : kOutputArrays)
    arrays.append(py::make_tuple(a.name, a.per_deformation ? "deformation" : "coordinate", a.what));
  for (const RunCounter& c : kRunCounters) counters.append(py::make_tuple(c.name, c.implicit_only));
  m.attr("output_arrays") = py::tuple(arrays);
  m.attr("energy_columns") = py::tuple(py::cast(std::vector<std::string>(std::begin(kEnergyColumns), std::end(kEnergyColumns))));
  m.attr("run_counters") = py::tuple(counters);
  const RunOptions defaults;
  py::dict run_defaults;
  run_defaults["method"] = method_name(defaults.method);
  run_defaults["rho_inf"] = defaults.rho_inf;
  run_defaults["fixed_step"] = defaults.fixed_step;
  run_defaults["recursive"] = defaults.recursive;
  run_defaults["energy"] = defaults.energy;
  run_defaults["predictor_order"] = defaults.predictor_order;
  run_defaults["chord"] = defaults.chord;
  m.attr("run_defaults") = run_defaults;
}

void bind_table(py::module_& m) {
  py::class_<Table>(m, "Table", "Values over time interpolated in C++ (table.hpp); spacar.Table wraps it.")
      .def(py::init([](std::vector<double> t, Eigen::MatrixXd values, const std::string& kind) {
             return Table(std::move(t), std::move(values), Table::parse_kind(kind));
           }),
           py::arg("t"), py::arg("values"), py::arg("kind"))
      .def_property_readonly("components", &Table::components)
      .def("__call__", &Table::operator(), py::arg("t"), py::arg("component"), py::arg("derivative") = 0);
}

void bind_system(py::module_& m) {
  py::class_<System>(m, "System")
      .def_readonly("nx", &System::nx)
      .def_readonly("ne", &System::ne)
      .def_readonly("coord_label", &System::coord_label)
      .def_readonly("def_label", &System::def_label)
      .def_property_readonly("coord_label_array", [](const System& s) { return label_array(s.coord_label); },
                             "coord_label as an (nx, 2) integer array")
      .def_property_readonly("def_label_array", [](const System& s) { return label_array(s.def_label); },
                             "def_label as an (ne, 2) integer array")
      .def_readonly("coord_class", &System::coord_class)
      .def_readonly("def_class", &System::def_class)
      .def_readonly("x_calc", &System::x_calc)
      .def_readonly("x_input", &System::x_input)
      .def_readonly("x_dyn", &System::x_dyn)
      .def_readonly("x_fixed", &System::x_fixed)
      .def_readonly("e_input", &System::e_input)
      .def_readonly("e_dyn", &System::e_dyn)
      .def_readonly("defs_P", &System::defs_P)
      .def_readonly("defs_V", &System::defs_V)
      .def_readonly("dof_cols", &System::dof_cols)
      .def_readonly("input_cols", &System::input_cols)
      .def_readonly("q0", &System::q0)
      .def_readonly("y_defs", &System::y_defs)
      .def_readonly("y0", &System::y0)
      .def_readonly("qd0", &System::qd0)
      .def_readonly("warnings", &System::warnings)
      .def_property_readonly("n_dof", &System::n_dof)
      .def_property_readonly("n_qhat", &System::n_qhat);

}

void bind_data(py::module_& m) {
  py::class_<Data>(m, "Data")
      .def_readonly("t", &Data::t)
      .def_readonly("x", &Data::x)
      .def_readonly("xd", &Data::xd)
      .def_readonly("xdd", &Data::xdd)
      .def_readonly("e", &Data::e)
      .def_readonly("ed", &Data::ed)
      .def_readonly("edd", &Data::edd)
      .def_readonly("sigma", &Data::sigma)
      .def_readonly("e_integrated", &Data::e_integrated)
      .def_readonly("qhat", &Data::qhat)
      .def_readonly("qhat_d", &Data::qhat_d)
      .def_readonly("qhat_dd", &Data::qhat_dd)
      .def_readonly("DF", &Data::DF)
      .def_readonly("DFe", &Data::DFe)
      .def_readonly("acc0", &Data::acc0)
      .def_readonly("M", &Data::M)
      .def_readonly("Mbar", &Data::Mbar)
      .def_readonly("qdd", &Data::qdd)
      .def_readonly("reaction", &Data::reaction)
      .def_readonly("residual_load", &Data::residual_load)
      .def_readonly("sigma_equilibrium", &Data::sigma_equilibrium)
      .def_readonly("newton_iterations", &Data::newton_iterations);

}

// The set-up of a Simulation and its compiled system and data.
void bind_setup(py::class_<Simulation>& sim) {
  sim
      .def(py::init([](Model& model, double time_limit, double time_spent) {
             // The set-up (the model's preparation, compilation and work arrays) is bounded by
             // the analysis's time limit as the run is.
             const DeadlineScope deadline(time_limit, time_spent);
             return std::make_unique<Simulation>(model);
           }),
           py::arg("model"), py::arg("time_limit") = 0.0, py::arg("time_spent") = 0.0, py::keep_alive<1, 2>(),
           "Prepare and compile `model` for its analyses within `time_limit` seconds (0: no limit) of which "
           "`time_spent` are spent.")
      .def("renew", &Simulation::renew,
           "Ready for the model's next block without compiling it again, if the model has not changed since this "
           "simulation's last run, which took the recursive path; False (nothing done) otherwise.")
      .def_property_readonly("renewable", &Simulation::renewable, "Whether renew() would succeed now.")
      .def_property_readonly("system", &Simulation::system, py::return_value_policy::reference_internal)
      .def_property_readonly("data", &Simulation::data, py::return_value_policy::reference_internal)
      .def("assemble", [](Simulation& s) { s.assemble(); })
      .def("forces", &Simulation::forces)
      .def("reduced_accelerations", &Simulation::reduced_accelerations);
}

// Linearizations: about a state, and in the nodal coordinates at rest with their solves.
void bind_linearization(py::class_<Simulation>& sim) {
  sim
      .def("linearize",
           [](Simulation& s, bool differences) {
             return linearization_to_dict(
                 s.linearize(differences ? Linearizer::Differences::Precise : Linearizer::Differences::None));
           },
           py::arg("differences") = true,
           "The linearized equations at the state of the last evaluate(); differences=False at a state "
           "linearize_nodal accepted (at rest in static equilibrium: C0 = N0 = 0, no finite differences).")
      .def(
          "linearize_at_rest",
          [](Simulation& s, double t, const Eigen::VectorXd& q) { return linearization_to_dict(s.linearize_at_rest(t, q)); },
          py::arg("t"), py::arg("q"),
          "The dense linearized equations at the state of linearize_nodal (DOFs q at time t, at rest in static "
          "equilibrium) without the equations of motion: q̈ = 0 and the static stresses (a model without mass "
          "has K0, G0 and DF; M0 = 0).")
      .def("linearize_nodal",
           [](Simulation& s) -> py::object {
             NodalLinearization n;
             if (!s.linearize_nodal(n)) return py::none();
             return nodal_linearization_to_dict(std::move(n));
           },
           "The linearized equations at rest in the nodal coordinates (sparse M, D, K, G, the constraint rows "
           "A, the map E: δz = E δx) at the assembled state, or None if it is not at rest in static equilibrium.")
      .def("nodal_factorize",
           [](Simulation& s, double stiffness, double geometric, double mass, double damping) {
             NodalCoefficients c;
             c.stiffness = stiffness, c.geometric = geometric, c.mass = mass, c.damping = damping;
             Linearizer& lin = s.linearizer();
             py::dict d;
             d["ok"] = lin.nodal_factorize(c);
             const SaddlePoint& sp = lin.nodal_system();
             d["singular"] = sp.singular();
             d["sign"] = sp.sign_determinant();
             d["negative"] = sp.negative_eigenvalues();
             d["symmetric"] = sp.symmetric();
             return d;
           },
           py::arg("stiffness") = 1.0, py::arg("geometric") = 1.0, py::arg("mass") = 0.0, py::arg("damping") = 0.0,
           "Factorize H = stiffness·K + geometric·G + mass·M + damping·D of linearize_nodal's state in the "
           "saddle-point system; its reduced matrix's singularity, determinant sign and negative eigenvalues.")
      .def("nodal_solve",
           [](Simulation& s, const Eigen::VectorXd& b) {
             Linearizer& lin = s.linearizer();
             const int nf = lin.nodal_system().layout().n_free;
             if (b.size() != nf)
               throw InputError("nodal_solve: b needs " + std::to_string(nf) + " values, got " + std::to_string(b.size()));
             Eigen::VectorXd x(nf);
             lin.nodal_solve(b.data(), x.data());
             return x;
           },
           py::arg("b"),
           "x_f = Z (Zᵀ H Z)⁻¹ Zᵀ b_f over the free coordinates with the last nodal_factorize.")
      .def("nodal_energies",
           [](Simulation& s, const Eigen::VectorXd& v) { return s.linearizer().nodal_energies(v); },
           py::arg("v"),
           "(vᵀKv, vᵀGv, vᵀMv, vᵀDv) of linearize_nodal's state for v over the free coordinates, element by "
           "element (the Rayleigh quotients of the sparse eigen-analyses).");
}

// The state at a time on each path, and the constraint diagnosis.
void bind_states(py::class_<Simulation>& sim) {
  sim
      .def("diagnose",
           [](Simulation& s, double time_limit, double time_spent, bool release_dynamic) {
             const DeadlineScope deadline(time_limit, time_spent);
             const ConstraintDiagnosis d = diagnose(s.system(), s.data(), false, release_dynamic);
             const System& sys = s.system();
             py::dict out;
             out["n_constraints"] = d.n_constraints;
             out["n_calculable"] = d.n_calculable;
             out["rank"] = d.rank;
             py::list red, und, det;
             for (int k : d.redundant) red.append(py::make_tuple(sys.def_label[k][0], sys.def_label[k][1]));
             for (int g : d.undetermined) und.append(py::make_tuple(sys.coord_label[g][0], sys.coord_label[g][1]));
             for (int g : d.determined) det.append(py::make_tuple(sys.coord_label[g][0], sys.coord_label[g][1]));
             out["redundant"] = red;
             out["undetermined"] = und;
             out["determined"] = det;
             out["text"] = d.text;
             return out;
           },
           py::arg("time_limit") = 0.0, py::arg("time_spent") = 0.0, py::arg("release_dynamic") = false,
           "The constraint diagnosis at the current geometry, within `time_limit` seconds of which "
           "`time_spent` are spent; `release_dynamic`: the redundant rows named among the DYNE "
           "deformations where possible.")
      .def("evaluate", py::overload_cast<double, const Eigen::VectorXd&, const Eigen::VectorXd&>(&Simulation::evaluate))
      .def("solve_state",
           py::overload_cast<double, const Eigen::VectorXd&, const Eigen::VectorXd&>(&Simulation::solve_state),
           "The integration path: positions, velocities, q̈ and stresses without DF.")
      .def(
          "recursive_state",
          [](Simulation& s, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) -> py::object {
            Eigen::VectorXd qdd, x, xd, xdd;
            if (!s.recursive_state(q, qd, qdd, x, xd, xdd)) return py::none();
            py::dict out;
            out["qdd"] = qdd;
            out["x"] = x;
            out["xd"] = xd;
            out["xdd"] = xdd;
            return out;
          },
          "The recursive path of planar and spatial rigid trees at (q, q̇), its tree taken at the solved state "
          "of the first call: a dict of qdd, x, xd, xdd (None for other systems); a check of it against "
          "solve_state() and move_to().")
      .def(
          "inverse_dynamics",
          [](Simulation& s, const StateRows& q, const StateRows& qd, const StateRows& qdd) {
            std::string path;
            RowMatrix force = s.inverse_dynamics(q, qd, qdd, path);
            return py::make_tuple(force, path);
          },
          py::arg("q"), py::arg("qd"), py::arg("qdd"),
          "Inverse dynamics at the states in the rows of q, qd, qdd: (the generalized forces on the DOFs beyond "
          "the model's own loads, 'tree' or 'general'), spacar.inverse_dynamics.")
      .def(
          "dynamics_derivatives",
          [](Simulation& s, const StateRows& q, const StateRows& qd, const StateRows& tau) {
            RowMatrix qdd, dq, dqd, dtau;
            s.dynamics_derivatives(q, qd, tau, qdd, dq, dqd, dtau);
            // Moved into the arrays (a large batch is not copied).
            return py::make_tuple(py::cast(std::move(qdd)), py::cast(std::move(dq)), py::cast(std::move(dqd)),
                                  py::cast(std::move(dtau)));
          },
          py::arg("q"), py::arg("qd"), py::arg("tau"),
          "(qdd, dqdd/dq, dqdd/dqd, dqdd/dtau) at the states in the rows of q, qd, tau, each derivative a row of "
          "n·n values (row-major): spacar.dynamics_derivatives.")
      .def("recursive_refusal", &Simulation::recursive_refusal,
           "Why the system takes the general path rather than the recursive one ('' if it is a rigid tree).")
      .def("move_to", py::overload_cast<double, const Eigen::VectorXd&, const Eigen::VectorXd&>(&Simulation::move_to))
      .def("kinematic_state", &Simulation::kinematic_state, py::arg("t"), py::arg("q"),
           "The positions at (t, q), the rates zero, with DF and DFe: the kinematic analysis alone (no equations "
           "of motion), predicted from the last solved state by its DF (spacar.transfer).")
      .def(
          "second_order_transfer",
          [](Simulation& s) {
            Eigen::MatrixXd d2f, d2fe;
            s.second_order_transfer(d2f, d2fe);
            return py::make_tuple(d2f, d2fe);
          },
          "(D2F, D2Fe) at the state of the last evaluate(): column i·n + j holds ∂²x/∂q̂_i∂q̂_j, ∂²e/∂q̂_i∂q̂_j "
          "(q̂: the inputs and DOFs, DF's columns; spacar.transfer).")
      .def(
          "evaluate_state",
          [](Simulation& s, double t, const Eigen::VectorXd& Y) { s.evaluate_state(t, Y); },
          py::arg("t"), py::arg("Y"),
          "The state of the integrator, Y = (q, y, q̇) with y the integrated deformations (system.y_defs): "
          "positions, velocities, q̈ and stresses, the integrated values set from y (for differences over the "
          "kinematic coordinates of nonholonomic constraints).");
}

// The run of a block, with its time-dependent loads.
void bind_run(py::class_<Simulation>& sim) {
  sim
      .def(
          "set_time_loads",
          [](Simulation& s, const std::vector<std::pair<std::vector<int>, Table>>& load_tables,
             const std::vector<std::pair<int, Table>>& input_tables, py::object load_function) {
            TimeLoads loads;
            for (const auto& [coords, table] : load_tables) loads.load_tables.push_back({coords, table});
            for (const auto& [input, table] : input_tables) loads.input_tables.push_back({input, table});
            if (!load_function.is_none()) {
              loads.load_function = [load_function](double t, Eigen::VectorXd& load) {
                py::gil_scoped_acquire gil;
                const Eigen::VectorXd f = load_function(t).cast<Eigen::VectorXd>();
                if (f.size() != load.size()) throw InputError("the load function must return one load per coordinate");
                load += f;
              };
            }
            s.set_time_loads(std::move(loads));
          },
          py::arg("load_tables"), py::arg("input_tables"), py::arg("load_function") = py::none(),
          "Time-dependent loads ([(coordinates, Table)]), input motions ([(input index, Table)]) and a function "
          "load_function(t) -> loads (nx) called at every right-hand side.")
      .def(
          "run",
          [](Simulation& s, py::object on_output, double initial_step, const std::string& method,
             double time_limit, bool recursive, double sample_period, py::object on_sample, bool energy,
             double rho_inf, double fixed_step, double time_spent, int predictor_order, bool chord) {
            RunOptions opt;
            opt.predictor_order = predictor_order;
            opt.chord = chord;
            opt.energy = energy;
            opt.sample_period = sample_period;
            if (!on_sample.is_none()) {
              opt.on_sample = [on_sample](double t, const Data& d, Eigen::VectorXd& held) {
                py::gil_scoped_acquire gil;
                const Eigen::VectorXd f = on_sample(t, d.x, d.xd, d.xdd).cast<Eigen::VectorXd>();
                if (f.size() != held.size()) throw InputError("the controller must return one load per coordinate");
                held = f;
              };
            }
            opt.recursive = recursive;
            opt.initial_step = initial_step;
            opt.method = parse_method(method);
            opt.rho_inf = rho_inf;  // checked with the other options at the block's start (plan_block)
            opt.fixed_step = fixed_step;
            if (!on_output.is_none()) {
              opt.on_output = [on_output](int k, const Data& d, const Linearization* lin) {
                py::gil_scoped_acquire gil;
                py::dict state;
                state["t"] = d.t;
                for (const OutputArray& a : kOutputArrays) state[a.name] = d.*a.now;
                if (lin) state["linearization"] = linearization_to_dict(*lin);
                on_output(k, state);
              };
            }
            opt.time_limit = time_limit;
            opt.time_spent = time_spent;
            BlockResults r;
            // Ctrl-C reaches the run (without the GIL) through the deadline's checks.
            const InterruptScope interrupt(python_interrupt_pending);
            return run_released(r, [&] { s.run(r, opt); }, block_results_to_dict,
                                [](const std::exception_ptr&) { return true; });
          },
          py::arg("on_output") = py::none(), py::arg("initial_step") = RunOptions().initial_step,
          py::arg("method") = method_name(RunOptions().method), py::arg("time_limit") = RunOptions().time_limit,
          py::arg("recursive") = RunOptions().recursive, py::arg("sample_period") = RunOptions().sample_period,
          py::arg("on_sample") = py::none(), py::arg("energy") = RunOptions().energy,
          py::arg("rho_inf") = RunOptions().rho_inf, py::arg("fixed_step") = RunOptions().fixed_step,
          py::arg("time_spent") = RunOptions().time_spent, py::arg("predictor_order") = RunOptions().predictor_order,
          py::arg("chord") = RunOptions().chord,
          "Run the block (`time_spent`: seconds of the analysis spent before it, counted against `time_limit`); on "
          "failure the exception has the results up to the failure as `results`. `predictor_order` (2, 1, 0) and "
          "`chord` change the start and the matrix of Newton's iterations on the positions, for measurements "
          "(benchmarks/newton.py).");
}

py::dict rollout_results_to_dict(RolloutResults&& r) {
  py::dict d;
  d["q"] = std::move(r.q);
  d["qd"] = std::move(r.qd);
  d["x"] = r.x.cols() ? py::cast(std::move(r.x)) : py::none();  // asked for: (rows × nx), rows maybe 0
  d["rhs_evaluations"] = r.rhs_evaluations;
  d["steps"] = r.steps;
  d["rejected"] = r.rejected;
  d["path"] = r.path;
  d["warnings"] = r.warnings;
  d["wall_time"] = r.wall_time;
  d["failed"] = r.failed;
  return d;
}

void bind_rollout(py::class_<Simulation>& sim) {
  sim.def(
      "rollout",
      [](Simulation& s, const RowMatrix& q0, const RowMatrix& qd0, const std::vector<double>& times,
         const std::string& method, bool recursive, double rho_inf, double fixed_step, bool coordinates,
         double time_limit, double time_spent) {
        RunOptions opt;
        opt.method = parse_method(method);
        opt.recursive = recursive;
        opt.rho_inf = rho_inf;
        opt.fixed_step = fixed_step;
        opt.time_limit = time_limit;
        opt.time_spent = time_spent;
        RolloutResults r;
        const InterruptScope interrupt(python_interrupt_pending);
        return run_released(r, [&] { s.rollout(q0, qd0, times, opt, coordinates, r); }, rollout_results_to_dict,
                            [](const std::exception_ptr&) { return true; });
      },
      py::arg("q0"), py::arg("qd0"), py::arg("times"), py::arg("method") = method_name(RunOptions().method),
      py::arg("recursive") = RunOptions().recursive, py::arg("rho_inf") = RunOptions().rho_inf,
      py::arg("fixed_step") = RunOptions().fixed_step, py::arg("coordinates") = false,
      py::arg("time_limit") = RunOptions().time_limit, py::arg("time_spent") = RunOptions().time_spent,
      "Integrate the states in the rows of q0, qd0 through the output times (spacar.Rollout); the model is "
      "assembled at the first rollout and kept. On failure the exception has the states before the failing one "
      "as `results` (its `failed` the state's index).");
}

}  // namespace

void bind_simulation(py::module_& m) {
  bind_lists(m);
  bind_table(m);
  bind_system(m);
  bind_data(m);
  py::class_<Simulation> sim(m, "Simulation");
  bind_setup(sim);
  bind_linearization(sim);
  bind_states(sim);
  bind_run(sim);
  bind_rollout(sim);
}

}  // namespace spacar::bindings

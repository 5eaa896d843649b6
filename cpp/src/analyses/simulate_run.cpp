// Simulation's run of a block (simulate.hpp): the plan checked before any work, the results
// allocated, the block integrated segment by segment with the stepper of each (the method table,
// stepper.hpp), repartitions of free rotations, the explanation of a collapse and the state
// stored back into the model. The state at a time and the right-hand side are in simulate.cpp.
#include "spacar/analyses/simulate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "spacar/kinematics/diagnosis.hpp"
#include "spacar/kinematics/dynamics.hpp"
#include "spacar/errors.hpp"
#include "spacar/kinematics/kinematics.hpp"
#include "spacar/limits.hpp"
#include "spacar/integrators/stepper.hpp"

namespace spacar {

namespace {

// The smallest change of a state the implicit methods' Newton iterations resolve, times the
// model's length scale (at least 1): ten times the floor of the position solves
// (simulation_kinematic_tolerance), in each state's SI unit as the absolute tolerance
// 10⁻³ EPS is (formulation.md §8.1). A spinning 16-PLBEAM beam's iterates settle at about
// 2·10⁻¹² m/s in the rates of its deformations; with no floor EPS 10⁻¹⁰ stalled there.
constexpr double kNewtonFloor = 1e-12;

// Warnings for the position nodes that the first assembly moved far (more than 1e-3 of the
// model's size, the spread of the X positions) from where X put them: the X positions do not
// close a loop with the lengths given (LENGTHO), the targets of E or the inputs' start values.
// An X position meant exactly then changed the mechanism; a rough one was closed as intended.
// The first kMovedNodesNamed nodes are named one by one, the others summed up in one line (a
// turned ground moves every node: a warning per node would bury the others, and cost a run's
// fixed time in formatting).
void warn_of_assembly_moves(const System& sys, const Eigen::VectorXd& given, const Eigen::VectorXd& x,
                            std::vector<std::string>& warnings) {
  constexpr int kMovedNodesNamed = 3;
  auto is_position = [&](int g) {
    return sys.coord_node_kind[g] == NodeKind::XY || sys.coord_node_kind[g] == NodeKind::XYZ;
  };
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int g = 0; g < sys.nx; ++g)
    if (is_position(g)) {
      lo = std::min(lo, given[g]);
      hi = std::max(hi, given[g]);
    }
  if (!(hi >= lo)) return;  // no position nodes
  const double far = 1e-3 * (hi - lo);
  int moved = 0, farthest = -1;
  double largest = 0.0;
  for (int g = 0, end; g < sys.nx; g = end) {  // node by node: its coordinates are consecutive
    for (end = g + 1; end < sys.nx && sys.coord_label[end][0] == sys.coord_label[g][0];) ++end;
    if (!is_position(g)) continue;
    const double distance = (x.segment(g, end - g) - given.segment(g, end - g)).norm();
    if (!(distance > far)) continue;
    if (++moved > kMovedNodesNamed) {
      if (distance > largest) {
        largest = distance;
        farthest = sys.coord_label[g][0];
      }
      continue;
    }
    auto point = [&](const Eigen::VectorXd& v) {
      std::string s = "(";
      for (int i = g; i < end; ++i) s += (i > g ? ", " : "") + format_number(v[i], 6);
      return s + ")";
    };
    warnings.push_back("the assembly moved node " + std::to_string(sys.coord_label[g][0]) + " by " +
                       format_number(distance, 4) + " from its X position " + point(given) + " to " + point(x) +
                       ": the X positions do not close the loop with the lengths (LENGTHO), E targets and "
                       "input values given");
  }
  if (moved > kMovedNodesNamed)
    warnings.push_back("the assembly moved " + std::to_string(moved - kMovedNodesNamed) +
                       " more nodes from their X positions, the farthest node " + std::to_string(farthest) +
                       " by " + format_number(largest, 4));
}

// Keep the first `rows` rows of every time-indexed array (a run that failed midway).
void cut_rows(BlockResults& res, int rows) {
  res.t.conservativeResize(rows);
  for (const OutputArray& a : kOutputArrays) (res.*a.rows).conservativeResize(rows, (res.*a.rows).cols());
  if (res.energy.size()) res.energy.conservativeResize(rows, res.energy.cols());
}

}  // namespace

void Simulation::run(BlockResults& res, const RunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  // What renew() prepared, for this run only (also when the run fails before its block).
  std::unique_ptr<RhsPath> kept_tree = std::move(kept_tree_);
  const bool renewed = std::exchange(renewed_, false);
  res = BlockResults();
  res.warnings = sys_->warnings;
  rollout_ = RolloutStart();  // the run moves the data a rollout prepared
  const BlockPlan plan = plan_block(options, res.warnings);
  run_.n_energy = options.energy ? 2 : 0;
  run_.held.resize(0);
  run_.predictor_order = options.predictor_order;
  run_.chord = options.chord;
  run_.fixed_step = plan.fixed_step;
  // One deadline (limits.hpp), checked at every right-hand side and output time and inside the
  // sparse factorizations; the time the set-up took counts against it.
  const DeadlineScope deadline(options.time_limit, options.time_spent);
  allocate_results(res, plan);
  int k_out = 0;
  auto finish = [&]() {
    res.newton_iterations = data_->total_newton_iterations;
    res.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    path_ = std::make_unique<GeneralPath>();
    run_.held.resize(0);
    run_.predictor_order = RunOptions().predictor_order;
    run_.chord = RunOptions().chord;
    run_.fixed_step = 0.0;
  };
  try {
    integrate_block(res, options, plan, k_out, renewed, std::move(kept_tree));
  } catch (...) {
    cut_rows(res, k_out);
    finish();
    throw;
  }
  // The tree, kept for the next run of the unchanged model (renew()): not with free rotations
  // (their partition follows the state), nor a tree whose loop closure starts from the state it
  // was recognized at, nor if the model changed since the system was compiled or reloaded (from
  // on_output, another thread, between runs): then the revision has moved by more than
  // store_state's own change.
  const RecursiveTree* used = path_->tree();
  std::unique_ptr<RhsPath> tree =
      used && used->serves_any_state() && sys_->free_rotations.empty() ? std::move(path_) : nullptr;
  finish();
  store_state();
  if (model_.revision() == compiled_revision_ + 1) kept_tree_ = std::move(tree);
}

bool Simulation::renew() {
  if (!renewable()) return false;
  model_.prepare();  // as at every END: the Euler parameters normalized
  reload_state(model_, *sys_);
  predicted_.setZero();
  run_ = RunState();
  qhat_transfer_.resize(0);
  have_transfer_ = false;
  linearizer_.reset();
  timed_ = TimeLoads();
  rollout_ = RolloutStart();
  x_given_.resize(0);
  data_->total_newton_iterations = 0;
  renewed_ = true;  // the data still hold the last block's last output: see integrate_block
  compiled_revision_ = model_.revision();
  return true;
}

// The data hold the state the block starts in (time, DOFs and their rates): the last block's
// last output, unless something evaluated another state since (evaluate, a rollout, ...).
bool Simulation::data_holds_start() const {
  const System& sys = *sys_;
  const Data& d = *data_;
  if (d.t != sys.t0) return false;
  int j = 0;
  for (int g : sys.x_dyn) {
    if (d.x[g] != sys.q0[j] || d.xd[g] != sys.qd0[j]) return false;
    ++j;
  }
  for (int k : sys.e_dyn) {
    if (d.e[k] != sys.q0[j] || d.ed[k] != sys.qd0[j]) return false;
    ++j;
  }
  return true;
}

void Simulation::restart_data() {
  data_->reset_state(*sys_, /*keep_pivots=*/true);  // the last block's pivots replayed: no search
  positions_from_model();
}

// Requests that cannot be carried out are refused before any work (formulation.md §8.1).
void Simulation::check_options(const RunOptions& options) {
  if (!(options.time_limit >= 0.0)) throw InputError("the time limit must not be negative");
  if (!(options.time_spent >= 0.0)) throw InputError("the time spent before the run must not be negative");
  if (options.max_steps < 1) throw InputError("the step limit must be positive");
  if (options.predictor_order < 0 || options.predictor_order > 2)
    throw InputError("the predictor's order must be 0, 1 or 2, not " + std::to_string(options.predictor_order));
  if (!(options.sample_period >= 0.0) || !std::isfinite(options.sample_period))
    throw InputError("the controller's sample period must be a positive number of seconds");
  if (!(options.rho_inf >= 0.0 && options.rho_inf <= 1.0))
    throw InputError("rho_inf (the spectral radius of generalized_alpha) must be in [0, 1], not " +
                     std::to_string(options.rho_inf));
  if (!(options.fixed_step >= 0.0 && std::isfinite(options.fixed_step)))
    throw InputError("fixed_step must be a finite step size >= 0 (0: error control), not " +
                     std::to_string(options.fixed_step));
  if (options.fixed_step > 0.0 && options.method != Method::GENERALIZED_ALPHA)
    throw InputError("fixed_step is an option of method generalized_alpha only (the other methods control their error)");
}

Simulation::BlockPlan Simulation::plan_block(const RunOptions& options, std::vector<std::string>& warnings) const {
  check_options(options);
  // The system may be recompiled during the run (repartition): keep copies, not references.
  BlockPlan plan;
  plan.st = sys_->settings;
  const Settings& st = plan.st;
  const int n_out = st.timestep_n;
  const double t0 = sys_->t0, t_end = t0 + st.timestep_tp;
  plan.t0 = t0;
  plan.t_end = t_end;
  plan.linear = !sys_->e_line.empty() || st.linear.value_or(0) >= 1;
  if (!std::isfinite(t_end))
    throw InputError("TIMESTEP: the end time TIME + Tp = " + format_number(t0, 12) + " + " + format_number(st.timestep_tp, 12) +
                     " is not a finite number");
  if (n_out > 0 && st.timestep_tp > 0.0 && !(t0 + st.timestep_tp / n_out > t0))
    throw InputError("TIMESTEP: the output interval Tp/n = " + format_number(st.timestep_tp / n_out, 12) +
                     " is lost in the rounding of the time t = " + format_number(t0, 12) + " (TIME)");
  plan.integrate = (sys_->n_dof() > 0 || !sys_->y_defs.empty()) && n_out > 0 && t_end > t0;
  if (options.energy && !plan.integrate)
    throw InputError("the energy balance needs an integrated block (degrees of freedom and a TIMESTEP period)");
  if (options.sample_period > 0.0 && st.timestep_tp / options.sample_period > static_cast<double>(options.max_steps))
    throw InputError("the controller's sample period " + format_number(options.sample_period, 12) + " needs more than " +
                     std::to_string(options.max_steps) + " samples in the block");
  if (plan.integrate) plan_integration(options, plan, st.timestep_tp, st.timestep_tp / n_out, kBlockNames, warnings);
  const int nt = n_out + 1;
  plan.times.resize(nt);
  for (int k = 0; k < nt; ++k) plan.times[k] = n_out ? t0 + st.timestep_tp * k / n_out : t0;
  plan.times.back() = t_end;  // exactly the end of the block, whatever the rounding
  return plan;
}

// The checks of an integration from plan.t0 to plan.t_end with outputs `interval` apart (the
// shortest interval), before any work; generalized-α's fixed step and the tolerances into plan.
void Simulation::plan_integration(const RunOptions& options, BlockPlan& plan, double tp, double interval,
                                  const PeriodNames& names, std::vector<std::string>& warnings) const {
  Settings& st = plan.st;
  const double t0 = plan.t0, t_end = plan.t_end;
  refuse_large_massless(*sys_, t0);  // before the assembly, which can take seconds at that size
  const double h_min = Stepper::min_step(t_end);
  if (tp < h_min)
    throw InputError(std::string(names.period_is) + " " + format_number(tp, 12) +
                     " is shorter than the smallest integration step " + format_number(h_min, 12) + " at t = " + format_number(t_end, 12));
  if (st.hmax < Stepper::min_step(t0))
    throw InputError("HMAX " + format_number(st.hmax, 12) + " is below the smallest integration step " +
                     format_number(Stepper::min_step(t0), 12) + " at t = " + format_number(t0, 12));
  if (tp / st.hmax > static_cast<double>(options.max_steps))
    throw InputError("HMAX " + format_number(st.hmax, 12) + " needs at least " + names.period + "/HMAX = " +
                     format_number(tp / st.hmax, 12) + " steps, more than the limit of " +
                     std::to_string(options.max_steps) + " steps per " + names.run);
  plan.fixed_step = planned_fixed_step(options, t_end, tp, interval, names, warnings);
  for (auto [eps, name] : {std::pair<double*, const char*>{&st.epsint, "EPSINT"}, {&st.epsind, "EPSIND"}})
    if (*eps < kMinTolerance) {
      warnings.push_back(std::string(name) + " " + format_number(*eps, 12) +
                         " is below the attainable accuracy in double precision: " + format_number(kMinTolerance, 12) +
                         " (100 machine epsilons) is used");
      *eps = kMinTolerance;
    }
}

// Generalized-α's fixed step, checked against the period tp ending at t_end before any work: a
// step longer than the output interval would interpolate the outputs across whole periods of the
// motion (cut to the interval, with a warning); one so short that the period needs more steps
// than the limit, or below the smallest step, is refused as HMAX is.
double Simulation::planned_fixed_step(const RunOptions& options, double t_end, double tp, double interval,
                                      const PeriodNames& names, std::vector<std::string>& warnings) {
  double h = options.fixed_step;
  if (h == 0.0) return h;
  if (h > interval) {
    warnings.push_back("fixed_step " + format_number(h, 12) + " is longer than the output interval " +
                       names.interval + " = " + format_number(interval, 12) + ": the steps are cut to the output interval");
    h = interval;
  }
  const double h_min = Stepper::min_step(t_end);
  if (h < h_min)
    throw InputError("fixed_step " + format_number(h, 12) + " is below the smallest integration step " +
                     format_number(h_min, 12) + " at the end of the " + names.run);
  if (tp / h > static_cast<double>(options.max_steps))
    throw InputError("fixed_step " + format_number(h, 12) + " needs " + names.period + "/fixed_step = " +
                     format_number(tp / h, 12) + " steps, more than the limit of " + std::to_string(options.max_steps) +
                     " steps per " + names.run);
  return h;
}

void Simulation::allocate_results(BlockResults& res, const BlockPlan& plan) const {
  const int nt = static_cast<int>(plan.times.size());
  const double nx = sys_->nx, ne = sys_->ne, nz = sys_->n_dof() + static_cast<double>(sys_->e_line.size());
  double per_time = 8.0 * (1.0 + 4.0 * nx + 4.0 * ne);
  if (plan.linear) per_time += 8.0 * (6.0 * nz * nz + nz + (nx + ne) * nz);
  require_memory(per_time * nt,
                 "the results of " + std::to_string(nt) + " output times (" + std::to_string(sys_->nx) +
                     " coordinates, " + std::to_string(sys_->ne) + " deformations" +
                     (plan.linear ? ", linearized equations" : "") + ")",
                 "use fewer output intervals (TIMESTEP n) or split the period into blocks");
  res.t.resize(nt);
  for (const OutputArray& a : kOutputArrays) (res.*a.rows).resize(nt, a.per_deformation ? sys_->ne : sys_->nx);
  res.reaction.setZero();
  if (run_.n_energy) res.energy.resize(nt, std::size(kEnergyColumns));
}

void Simulation::integrate_block(BlockResults& res, const RunOptions& options, const BlockPlan& plan, int& k_out,
                                 bool renewed, std::unique_ptr<RhsPath> kept_tree) {
  // The recursive and explicit-chain paths know neither time-dependent loads nor the energy's
  // quadrature states.
  const bool plain = timed_.empty() && !options.energy && options.sample_period == 0.0;
  const bool recursive = plan.integrate && options.recursive && plain;
  // The next block of a renewed simulation on its kept tree continues from the data as the last
  // block left them: its last output solved the state this block starts in (the model holds
  // that state, unchanged since), so neither the assembly nor the first output solves it again.
  const bool continuing = renewed && recursive && kept_tree && !plan.linear && data_holds_start();
  if (continuing) {
    path_ = std::move(kept_tree);
    remember(run_.base);  // the state at t0, as the first output leaves it
  } else {
    if (renewed) restart_data();  // from the model's state, as a new simulation starts
    assemble();
    if (x_given_.size()) {
      warn_of_assembly_moves(*sys_, x_given_, data_->x, res.warnings);
      x_given_.resize(0);
    }
    path_ = RhsPath::choose(*sys_, *data_, recursive);
  }
  res.recursive = path_->tree() != nullptr;
  res.path = path_->name();
  if (res.recursive && !continuing) {
    run_.base.xd = run_.base.xdd = Eigen::VectorXd::Zero(sys_->nx);
    run_.base.t = plan.t0;
  }
  const Settings& st = plan.st;
  const int nd = sys_->n_dof(), ny = static_cast<int>(sys_->y_defs.size());
  bool first_solved = continuing;  // the first output's state is in the data already
  auto output = [&](double t, const Eigen::VectorXd& Y) {
    check_time(t);
    if (!std::exchange(first_solved, false)) {
      evaluate_state(t, Y);
      if (run_.n_energy) {
        res.energy.row(k_out) << kinetic_energy(*sys_, *data_), gravity_potential(*sys_, *data_),
            strain_energy(*sys_, *data_), Y[2 * nd + ny], Y[2 * nd + ny + 1];
      }
      if (st.forcemode >= 1 || plan.linear) forces();
      else constitutive_stresses(*sys_, *data_);  // FORCEMODE 0: no reaction stresses
    }
    require_finite_state(t);
    if (plan.linear) res.linearizations.push_back(linearize());
    record(res, k_out);
    if (options.on_output) options.on_output(k_out, *data_, plan.linear ? &res.linearizations.back() : nullptr);
    ++k_out;
  };
  // State Y = (q, y, q̇, w): DOFs, integrated deformations, DOF rates, and with the energy balance
  // the dissipated and external work (quadrature states: integrated with the motion, under the
  // same error control, from the power at every stage; nothing depends on them).
  Eigen::VectorXd Y(2 * nd + ny + run_.n_energy);
  Y << sys_->q0, sys_->y0, sys_->qd0, Eigen::VectorXd::Zero(run_.n_energy);
  if (!plan.integrate) {
    // Kinematic analysis (or a single analysis at the current time).
    for (double t : plan.times) output(t, Y);
    return;
  }
  integrate_segments(res, options, plan, Y, k_out, output);
}

void Simulation::integrate_segments(BlockResults& res, const RunOptions& options, const BlockPlan& plan,
                                    Eigen::VectorXd& Y, int& k_out, const Stepper::Output& output) {
  const Settings& st = plan.st;
  // A digital controller: its loads at a sample from the state there, held until the next.
  const bool sampled = options.sample_period > 0.0 && options.on_sample;
  long k_sample = 0;
  auto sample = [&](double ts) {
    evaluate_state(ts, Y);
    Eigen::VectorXd held = Eigen::VectorXd::Zero(sys_->nx);
    options.on_sample(ts, *data_, held);
    run_.held = held;
  };
  if (sampled) sample(plan.t0);
  double t = plan.t0, h = options.initial_step;
  run_.kinematic_failure.clear();
  // AUTO starts explicit: most mechanisms are not stiff, and DOP853 tells when one is. An
  // undamped structure goes on with generalized-α where DOP853's steps are set by its fastest
  // vibration (h|λ| > 1): generalized-α's are set by the motion EPSINT asks for, and it stays;
  // a stiff damped model goes on with Radau, which returns to DOP853 where the stiffness goes
  // (docs/stiff-integration.md).
  const bool auto_switch = options.method == Method::AUTO;
  const Method stiff_method = auto_takes_generalized_alpha() ? Method::GENERALIZED_ALPHA : Method::RADAU5;
  Method method = auto_switch ? Method::DOP853 : options.method;
  res.method = method;
  for (;;) {
    // One segment: integrate until the end (or the next sample of the controller), until a free
    // rotation must be repartitioned, or (AUTO) until the stiffness changes. The step limit
    // holds for the block, whatever the number of segments.
    if (res.steps >= options.max_steps)
      throw IntegrationError("Integrator: more than " + std::to_string(options.max_steps) +
                             " steps in the block at t = " + format_number(t, 12));
    double t_stop = plan.t_end;
    if (sampled) {
      const double next = plan.t0 + static_cast<double>(k_sample + 1) * options.sample_period;
      if (next < plan.t_end - Stepper::min_step(plan.t_end)) t_stop = next;
    }
    auto last = plan.times.begin() + k_out;
    while (last != plan.times.end() && *last <= t_stop) ++last;
    const std::vector<double> remaining(plan.times.begin() + k_out, last);
    const SegmentEnd end =
        integrate_segment(res, options, method, auto_switch, st, t, t_stop, h, Y, remaining, output);
    h = res.last_step;  // the other integrator continues with the step this one proposed
    if (end.t >= plan.t_end) break;
    t = end.t;
    if (end.t >= t_stop) {  // a sample of the controller
      ++k_sample;
      sample(t);
      continue;
    }
    if (end.switch_method) {
      const Method other = method == Method::DOP853 ? stiff_method : Method::DOP853;
      res.switches.push_back({t, method, other});
      method = other;
    }
    const int rotation = rotation_to_repartition(Y);
    if (rotation >= 0) repartition(rotation, t, Y);
  }
}

bool Simulation::auto_takes_generalized_alpha() const {
  const System& sys = *sys_;
  // Below 1e-6 generalized-α's steps grow as EPS^(-1/2) for its error to follow EPS (its
  // tolerance proportionality, docs/stiff-integration.md): radau5 and dop853 are the methods for
  // tight tolerances.
  if (std::min(sys.settings.epsint, sys.settings.epsind) < 1e-6) return false;
  bool elastic = false;
  for (const SystemElement& se : sys.elements) {
    if (!se.has_constitutive) continue;
    if (!se.D.isZero(0.0)) return false;
    for (int a = 0; a < se.nd; ++a)
      elastic = elastic || (sys.def_class[se.def_offset + a] == DefClass::Dynamic && (se.S.row(a).array() != 0.0).any());
  }
  return elastic;
}

// The motion dx of the coordinates the model moves (calculable, then dynamic) at the positions
// x, each divided by (10⁻³ + |x|): generalized-α's step control of the nodal positions.
void Simulation::scale_positions(const Eigen::VectorXd& dx, const Eigen::VectorXd& x, Eigen::VectorXd& scaled) const {
  const System& sys = *sys_;
  scaled.resize(static_cast<Eigen::Index>(sys.x_calc.size() + sys.x_dyn.size()));
  Eigen::Index k = 0;
  for (const std::vector<int>* list : {&sys.x_calc, &sys.x_dyn})
    for (int c : *list) scaled[k++] = dx[c] / (1e-3 + std::abs(x[c]));
}

StepperSetup Simulation::stepper_setup(const RunOptions& options, bool auto_switch, int n_states) {
  const int nd = sys_->n_dof(), ny = static_cast<int>(sys_->y_defs.size());
  StepperSetup setup;
  setup.n = n_states;
  setup.positions = nd;
  setup.rate_offset = nd + ny;
  setup.jacobian = [this](double tt, const Eigen::VectorXd& y, Eigen::MatrixXd& J) {
    jacobian(tt, y, J);
    if (J.rows() < y.size()) {  // the energy's quadrature states: nothing depends on them
      Eigen::MatrixXd full = Eigen::MatrixXd::Zero(y.size(), y.size());
      full.topLeftCorner(J.rows(), J.cols()) = J;
      J.swap(full);
    }
  };
  if (residual_form()) {
    setup.residual = [this](double tt, const Eigen::VectorXd& y, const Eigen::VectorXd& D, Eigen::VectorXd& R) {
      residual(tt, y, D, R);
    };
    setup.weight = [this](Eigen::MatrixXd& W) { W = run_.jacobian_mass; };
  }
  if (!path_->tree()) {  // the step control of the nodal positions (generalized-α)
    // v and dx: the lambda's own work space, sized at the first step.
    setup.position_error = [this, v = Eigen::VectorXd(), dx = Eigen::VectorXd()](const Eigen::VectorXd& dq,
                                                                                 Eigen::VectorXd& scaled) mutable {
      const System& sys = *sys_;
      v.setZero(sys.n_qhat());
      for (int j = 0; j < sys.n_dof(); ++j) v[sys.dof_cols[j]] = dq[j];
      path_->transfer(sys, *data_, v, dx);
      scale_positions(dx, data_->x, scaled);
    };
  }
  if (sparse_newton()) {
    run_.newton_data.reset();  // the system of this segment (a repartition recompiles it)
    run_.newton_system.reset();
    setup.newton.refresh = [this](double tt, const Eigen::VectorXd& y) { newton_refresh(tt, y); };
    setup.newton.factorize = [this](double gh, double bh2) {
      NodalCoefficients c;
      c.mass = 1.0, c.damping = gh, c.stiffness = bh2, c.geometric = bh2;
      // A new step size at the state of the last refresh: only the coefficients change.
      run_.newton_singular = !run_.newton_system->factorize(run_.newton_data->sigma, c, run_.newton_factorized) ||
                             run_.newton_system->saddle().singular();
      run_.newton_factorized = true;
    };
    setup.newton.solve = [this](const Eigen::VectorXd& r, Eigen::VectorXd& x) {
      if (run_.newton_singular) {  // the stepper reports a singular Newton matrix and halves the step
        x = Eigen::VectorXd::Constant(r.size(), std::numeric_limits<double>::quiet_NaN());
        return;
      }
      Eigen::VectorXd dx;
      run_.newton_system->solve(r, x, dx, 0);
    };
    setup.newton.solve_weighted = [this](const Eigen::VectorXd& v, Eigen::VectorXd& x, Eigen::VectorXd* scaled_dx) {
      if (run_.newton_singular) {
        x = Eigen::VectorXd::Constant(v.size(), std::numeric_limits<double>::quiet_NaN());
        if (scaled_dx) scale_positions(Eigen::VectorXd::Constant(sys_->nx, std::numeric_limits<double>::quiet_NaN()),
                                       data_->x, *scaled_dx);
        return;
      }
      Eigen::VectorXd dx;
      run_.newton_system->solve_mass(v, x, dx);
      // Z x from the saddle point's solution, not another transfer: Z at the Newton matrix's
      // state (its last refresh), which is kept only while Newton contracts by 0.1 or better, so
      // Z has changed about as little since; the coordinates' sizes |x| at the current state, as
      // every other scale of the estimate (at the refresh's sizes, the 64-element cantilever
      // released from y = 0 took 821 steps at EPSINT 1e-4 instead of 420).
      if (scaled_dx) scale_positions(dx, data_->x, *scaled_dx);
    };
  }
  setup.rho_inf = options.rho_inf;
  setup.fixed_step = run_.fixed_step;
  setup.auto_switch = auto_switch;
  if (auto_switch && auto_takes_generalized_alpha()) {
    setup.stiff_bound = 1.0;
    // Generalized-α's switch costs one factorization of its Newton matrix and its steps cost
    // about 2 right-hand sides against DOP853's 12: it pays ahead of far fewer steps than Radau's.
    // Not below 500: the manual's flexible slider-crank (about 200 steps of DOP853 in its 5 s)
    // keeps DOP853 and its published numbers; a 4-element steel cantilever over 0.2 s (650-1000
    // stability-limited steps) goes over (at EPSINT 1e-3: 26 -> 2.1 ms; to a tip error of 1e-6 m
    // with EPSINT alone: 26 -> 8.6 ms).
    setup.stiff_steps_ahead = 500.0;
    // Five stiff steps, not Hairer's fifteen: a structure's DOP853 steps sit at h|λ| of 2–5 from
    // the first, and at 64 elements each DOP853 step costs 12 right-hand sides of the run's
    // 2500 (the switch at 6e-6 s instead of 2e-5 s: 5 % of the run).
    setup.stiff_count = 5;
  }
  return setup;
}

Simulation::SegmentEnd Simulation::integrate_segment(BlockResults& res, const RunOptions& options, Method method,
                                                     bool auto_switch, const Settings& st, double t, double t_end,
                                                     double h, Eigen::VectorXd& Y, const std::vector<double>& times,
                                                     const Stepper::Output& output) {
  const std::unique_ptr<Stepper> stepper =
      make_stepper(method, stepper_setup(options, auto_switch, static_cast<int>(Y.size())));
  const int nd = sys_->n_dof(), ny = static_cast<int>(sys_->y_defs.size());
  Eigen::VectorXd rtol(Y.size());
  rtol.setConstant(st.epsint);
  rtol.segment(nd + ny, nd).setConstant(st.epsind);
  stepper->set_tolerances(rtol, 1e-3 * rtol);  // formulation.md §8.1: sc = EPS (10⁻³ + |y|)
  stepper->set_newton_floor(kNewtonFloor * std::max(1.0, sys_->length_scale));
  stepper->set_max_step(st.hmax);
  stepper->set_max_steps(options.max_steps - res.steps);
  if (h > 0.0) stepper->set_initial_step(h);
  // Stop to repartition a free rotation whose dependent Euler parameter became small.
  if (!sys_->free_rotations.empty())
    stepper->set_stop_condition([this](double, const Eigen::VectorXd& y) { return rotation_to_repartition(y) >= 0; });
  stepper->set_step_start([this](double tt, const Eigen::VectorXd& y) { step_start(tt, y); });
  run_.anchor.valid = false;
  auto f = [this](double tt, const Eigen::VectorXd& y, Eigen::VectorXd& dy) { rhs(tt, y, dy); };
  auto add_stats = [&]() {
    const StepperStats& s = stepper->stats();
    res.rhs_evaluations += s.nfev;
    res.steps += s.nsteps;
    res.accepted += s.naccept;
    res.rejected += s.nreject;
    res.jacobians += s.njev;
    res.decompositions += s.ndec;
  };
  double t_reached = t;
  try {
    t_reached = stepper->integrate(f, t, t_end, Y, times, output);
  } catch (const IntegrationError& err) {
    add_stats();
    explain_collapse(err, Y);
    throw;
  } catch (...) {
    add_stats();
    throw;
  }
  add_stats();
  res.last_step = stepper->last_step();
  return {t_reached, stepper->wants_switch()};
}

void Simulation::explain_collapse(const IntegrationError& err, const Eigen::VectorXd& Y) {
  std::string integrator = err.what();
  const size_t cut = integrator.find(" (last rejection");
  if (cut != std::string::npos) integrator.resize(cut);
  // At the last accepted state: is the velocity constraint block nearly singular (a dead point,
  // where the accelerations grow without bound)?
  std::string weak;
  if (!sys_->x_calc.empty() && sys_->x_calc.size() <= 2000) {
    try {
      evaluate_state(data_->t, Y);
      weak = weakest_constraint(*sys_, *data_);
      if (!weak.empty())
        weak = "\n  at t = " + std::to_string(data_->t) + " (max Newton residual " +
               std::to_string(data_->residual.size() ? data_->residual.cwiseAbs().maxCoeff() : 0.0) + "):\n" + weak;
    } catch (const Error&) {
    }
  }
  // The step collapsed because the kinematics has no (continuous) solution ahead: a right-hand
  // side failed in the Newton iteration since the last accepted step (formulation.md §2.2).
  if (!run_.kinematic_failure.empty())
    throw KinematicsError(run_.kinematic_failure + "\nNo kinematic solution down to the minimum step (" + integrator +
                          ")." + weak);
  if (!weak.empty())
    throw KinematicsError("the mechanism reaches a singular configuration (" + integrator + ")." + weak);
}

int Simulation::rotation_to_repartition(const Eigen::VectorXd& Y) const {
  for (size_t r = 0; r < sys_->free_rotations.size(); ++r) {
    const FreeRotation& fr = sys_->free_rotations[r];
    double others = 0.0;
    for (int j : fr.dofs) others += Y[j] * Y[j];
    // On the unit sphere the dependent parameter squared is 1 − others; below ¼ another
    // parameter is at least as large, and the normalisation row loses its strength.
    if (1.0 - others < 0.25) return static_cast<int>(r);
  }
  return -1;
}

void Simulation::recompile() {
  sys_ = compile(model_, dependent_);
  data_ = std::make_unique<Data>(*sys_);
  linearizer_.reset();
  have_transfer_ = false;
}

void Simulation::repartition(int which, double t, Eigen::VectorXd& Y) {
  evaluate_state(t, Y);
  const FreeRotation fr = sys_->free_rotations[which];
  int best = 0;
  for (int i = 1; i < 4; ++i)
    if (std::abs(data_->x[fr.coord + i]) > std::abs(data_->x[fr.coord + best])) best = i;
  dependent_[fr.node] = best;
  ++repartitions_;
  const Eigen::VectorXd x = data_->x, xd = data_->xd, e = data_->e, ed = data_->ed, angles = data_->angle_ref,
                        integrated = data_->e_integrated;
  const long newton = data_->total_newton_iterations;
  recompile();
  data_->x = x;
  data_->angle_ref = angles;
  data_->e_integrated = integrated;
  data_->total_newton_iterations = newton;
  run_.base = run_.anchor = Solved();  // the next evaluation starts from x (q̂ has another meaning)
  run_.base.x = x;
  run_.base.angle_ref = angles;
  // The chain of the recompiled system (residual_form(): the chain's path); a floating base's
  // tree is recognized again below, its DOFs being other Euler parameters now.
  const bool tree = path_->tree() != nullptr;
  if (path_->residual_form() || tree) path_ = RhsPath::chain_or_general(*sys_);
  // Same sizes: the new partition only exchanges which Euler parameter is calculable.
  const System& sys = *sys_;
  const int n = sys.n_dof(), ny = static_cast<int>(sys.y_defs.size());
  int j = 0;
  for (int c : sys.x_dyn) {
    Y[j] = x[c];
    Y[n + ny + j++] = xd[c];
  }
  for (int k : sys.e_dyn) {
    Y[j] = e[k];
    Y[n + ny + j++] = ed[k];
  }
  if (tree) {  // at the state solved in the new partition
    evaluate_state(t, Y);
    path_ = RhsPath::choose(sys, *data_, true);
  }
}

void Simulation::store_state() {
  model_.before_change();
  const System& sys = *sys_;
  int g = 0;
  for (auto& [id, n] : model_.nodes)
    for (size_t i = 0; i < n.x.size(); ++i, ++g) {
      n.x[i] = data_->x[g];
      n.xd[i] = data_->xd[g];
      n.xdd[i] = data_->xdd[g];
    }
  int k = 0;
  for (auto& [id, el] : model_.elements)
    for (size_t i = 0; i < el.e.size(); ++i, ++k) {
      const DefClass c = sys.def_class[k];
      const bool target = (c == DefClass::Fixed || c == DefClass::Linearization) && el.e_given[i];
      if (!target) el.e[i] = data_->e[k];  // a given target stays exact for the next block
      el.ed[i] = data_->ed[k];
      el.edd[i] = data_->edd[k];
      // Values that are states continue in the next block: inputs, DOFs, kinematic coordinates
      // and the integrated values of released velocity-level deformations (slips).
      if (c == DefClass::Input || c == DefClass::Dynamic || c == DefClass::Kinematic ||
          (c == DefClass::Released && sys.def_velocity_level[k]))
        el.e_given[i] = true;
    }
  model_.time = data_->t;
}

}  // namespace spacar

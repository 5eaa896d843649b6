// Simulation (simulate.hpp): the set-up, the assembly and the state at a time (positions,
// velocities, accelerations and stresses) on the general, tree and chain paths, the predictor of
// the positions and the right-hand side of the steppers. The run of a block is in simulate_run.cpp.
#include "spacar/analyses/simulate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <initializer_list>
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

// The stages of the set-up are each linear in the model's size; the deadline of the analysis
// (Simulation's binding, solve_static) is checked between them.
std::unique_ptr<System> prepare_and_compile(Model& model) {
  model.prepare();
  check_thread_deadline("(in the model's preparation)");
  std::unique_ptr<System> sys = compile(model);
  check_thread_deadline("(in the model's compilation)");
  require_memory(Data::estimate_bytes(*sys),
                 "the analysis of " + std::to_string(sys->nx) + " nodal coordinates and " + std::to_string(sys->ne) +
                     " deformations",
                 "");
  return sys;
}

}  // namespace

Simulation::Simulation(Model& model)
    : model_(model),
      x_given_(model.frozen() ? 0 : 1),  // a marker until the positions are known
      sys_(prepare_and_compile(model)),
      data_(std::make_unique<Data>(*sys_)) {
  check_thread_deadline("(in the allocation of the work arrays)");
  predicted_ = Eigen::VectorXd::Zero(sys_->nx);
  for (const FreeRotation& fr : sys_->free_rotations) dependent_[fr.node] = fr.dependent;
  positions_from_model();
  if (x_given_.size()) x_given_ = data_->x;
  compiled_revision_ = model_.revision();
}

void Simulation::positions_from_model() {
  int g = 0;
  for (const auto& [id, n] : model_.nodes)
    for (double v : n.x) data_->x[g++] = v;
}

void Simulation::remember(Solved& s) const {
  s.valid = true;
  s.exact = true;
  s.t = data_->t;
  s.x = data_->x;
  s.xd = data_->xd;
  s.xdd = data_->xdd;
  s.qhat = data_->qhat;
  s.angle_ref = data_->angle_ref;
}

void Simulation::predict_from(const Solved& s, double t, const double* q) {
  const System& sys = *sys_;
  data_->x = s.x;
  data_->angle_ref = s.angle_ref;
  for (int g : sys.x_input) data_->x[g] = data_->qhat[sys.qhat_col_x[g]];
  for (size_t j = 0; j < sys.x_dyn.size(); ++j) data_->x[sys.x_dyn[j]] = q[j];
  const double dt = t - s.t;
  const double first = run_.predictor_order >= 1 ? dt : 0.0, second = run_.predictor_order >= 2 ? 0.5 * dt * dt : 0.0;
  for (int c : sys.x_calc) data_->x[c] += first * s.xd[c] + second * s.xdd[c];
}

// The nonlinear part of the motion since the step start must not exceed the predicted motion
// (plus a small floor), in units of the element lengths for positions and of 1 for angles and
// Euler parameters: this rejects only steps that turn parts by radians, or jumps to another
// solution branch (a disc turned over, a linkage through its dead point).
bool Simulation::continuous_with_step_start(std::string& why) const {
  const System& sys = *sys_;
  const Solved& a = run_.anchor;
  const double dt = data_->t - a.t;
  double dev = 0.0, inc = 0.0;
  int worst = -1;
  for (int c : sys.x_calc) {
    const double w = sys.coord_is_length[c] ? 1.0 / sys.length_scale : 1.0;
    const double motion = dt * (a.xd[c] + 0.5 * dt * a.xdd[c]);
    const double d = std::abs(data_->x[c] - a.x[c] - motion) * w;
    inc = std::max(inc, std::abs(motion) * w);
    if (d > dev || worst < 0) {
      dev = d;
      worst = c;
    }
  }
  if (dev <= inc + 1e-6) return true;
  std::ostringstream os;
  os << "the positions at t = " << data_->t << " are not continuous with the start of the integration step at t = "
     << a.t << ": " << sys.coord_name(worst) << " differs by " << dev
     << " (scaled) from its prediction, while the predicted motion is " << inc
     << "; the step is too large for the kinematics here (or the mechanism is at a singular configuration)";
  why = os.str();
  return false;
}

bool Simulation::solved_dofs(const Solved& s, const Eigen::VectorXd& Y) const {
  const System& sys = *sys_;
  for (int j = 0; j < sys.n_dof(); ++j)
    if (s.qhat[sys.dof_cols[j]] != Y[j]) return false;
  return true;
}

void Simulation::step_start(double t, const Eigen::VectorXd& Y) {
  if (t > run_.kinematic_failure_t) run_.kinematic_failure.clear();  // passed: the failure is history
  if (!path_->anchors_steps()) return;  // the tree's explicit positions: no Newton start to anchor
  if (run_.anchor.valid && run_.anchor.t == t) {  // the same step again, smaller
    // A step from an approximate anchor failed: solve the accepted state itself, so that the
    // smaller steps are not held to a mismatch of the size of a Newton increment.
    if (!run_.anchor.exact) {
      evaluate_state(t, Y);
      run_.anchor = run_.base;
    }
    return;
  }
  // The integrator has just evaluated the right-hand side at the accepted state, unless an
  // output time was evaluated since: then solve it again. Generalized-α accepts its last Newton
  // iterate after the last update, next to the state last evaluated: that state is the anchor
  // (its positions differ by the size of that update, far below the motion of a step) until a
  // step fails.
  if (!(run_.base.valid && run_.base.t == t)) evaluate_state(t, Y);
  run_.anchor = run_.base;
  run_.anchor.exact = solved_dofs(run_.base, Y);
}

void Simulation::assemble(ExplicitChain* chain) {
  const System& sys = *sys_;
  set_inputs(sys, *data_, sys.t0);
  apply_time_loads(sys.t0);
  set_dofs(sys, *data_, sys.q0.data(), sys.qd0.data());
  check_constraint_counts(sys, *data_);
  const double tol = simulation_kinematic_tolerance(sys);
  bool solved = false;
  if (chain) {
    const Eigen::VectorXd start = data_->x, angles = data_->angle_ref;
    try {
      chain->solve_positions(sys, *data_, std::max(sys.settings.maxiterat, 50), tol);
      solved = true;
    } catch (const KinematicsError&) {
      // The general iteration from the given positions and angle branches, with its diagnosis.
      data_->x = start;
      data_->angle_ref = angles;
    }
  }
  if (!solved) solve_positions(sys, *data_, sys.settings.maxiterat, tol, true);
  run_.base = run_.anchor = Solved();
  run_.base.x = data_->x;  // positions only: no velocities yet for the predictor
  run_.base.angle_ref = data_->angle_ref;
  have_transfer_ = false;
}

void Simulation::solve_state(double t, const double* q, const double* qd, Start start,
                             const Eigen::VectorXd* known_qdd) {
  solve_motion(t, q, qd, start);
  if (!(known_qdd && solve_dynamics_known(*sys_, *data_, *known_qdd))) solve_dynamics_direct(*sys_, *data_);
  remember(run_.base);
  have_transfer_ = false;
}

void Simulation::solve_motion(double t, const double* q, const double* qd, Start start) {
  const System& sys = *sys_;
  set_inputs(sys, *data_, t);
  apply_time_loads(t);
  set_dofs(sys, *data_, q, qd);
  // Predictor of the positions: the first-order transfer function applied to the change of the
  // independent coordinates (states given by the user, when DF of the last state is known), or
  // the last solved state advanced by a second-order Taylor step in time (integration stages).
  predicted_.setZero();
  if (start == Start::Transfer && have_transfer_) {
    predict_from(run_.base, run_.base.t, q);
    predicted_.noalias() = data_->DF * (data_->qhat - qhat_transfer_);
    for (int c : sys.x_calc) data_->x[c] += predicted_[c];
  } else if (run_.base.valid) {
    predict_from(run_.base, t, q);
  } else {
    Solved positions = run_.base;  // after assembly: positions only
    positions.t = t;
    positions.xd = positions.xdd = Eigen::VectorXd::Zero(sys.nx);
    predict_from(positions, t, q);
  }
  // Inside the integrator the positions must continue those of the step start (the anchor), as
  // far as the path holds them to it (an open chain from an exact anchor only).
  const bool anchored = run_.in_rhs && run_.anchor.valid;
  const bool check = anchored && path_->held_to_step_start(run_.anchor.exact);
  const Solved& solved = anchored ? run_.anchor : run_.base;  // the chain's branches: of the step start
  auto positions = [&]() { path_->positions(sys, *data_, solved.valid ? &solved.x : nullptr, start == Start::Exact); };
  if (!run_.chord) data_->jacobian_reusable = false;
  std::string why;
  bool ok = false;
  try {
    positions();
    ok = !check || continuous_with_step_start(why);
  } catch (const KinematicsError& err) {
    if (!anchored && !run_.base.valid) throw;
    why = err.what();
  }
  if (!ok) {
    // The last solved state may be a stage up to a full step ahead, solved before the step
    // failed elsewhere: start again from the step start (or, outside the integrator, from the
    // last solution itself); if the result is still not continuous, reject the step.
    if (anchored) predict_from(run_.anchor, t, q);
    else predict_from(run_.base, run_.base.t, q);
    positions();
    if (check && !continuous_with_step_start(why)) throw KinematicsError(why);
  }
  path_->velocities(sys, *data_, run_.in_rhs);
}

void Simulation::evaluate(double t, const double* q, const double* qd) {
  solve_state(t, q, qd, Start::Transfer);
  // Transfer functions and the reduced mass matrix, for users, tests and teaching.
  const System& sys = *sys_;
  solve_transfer(sys, *data_);
  solve_velocities(sys, *data_);
  assemble_mass_matrix(sys, *data_);
  for (int j = 0; j < sys.n_dof(); ++j) data_->DFq.col(j) = data_->DF.col(sys.dof_cols[j]);
  data_->Mbar.noalias() = data_->DFq.transpose() * data_->M * data_->DFq;
  qhat_transfer_ = data_->qhat;
  have_transfer_ = true;
}

void Simulation::kinematic_state(double t, const Eigen::VectorXd& q) {
  const Eigen::VectorXd at_rest = Eigen::VectorXd::Zero(sys_->n_dof());
  require_dof_sizes("kinematic_state", q, at_rest);
  solve_motion(t, q.data(), at_rest.data(), Start::Transfer);
  solve_transfer(*sys_, *data_);
  solve_velocities(*sys_, *data_);
  remember(run_.base);
  qhat_transfer_ = data_->qhat;
  have_transfer_ = true;
}

void Simulation::second_order_transfer(Eigen::MatrixXd& d2f, Eigen::MatrixXd& d2fe) {
  if (!have_transfer_) throw InputError("second_order_transfer: evaluate() or kinematic_state() a state first");
  const System& sys = *sys_;
  Data& d = *data_;
  const int n = static_cast<int>(d.DF.cols());
  require_memory(8.0 * (sys.nx + sys.ne) * double(n) * n, "the second-order transfer functions",
                 "ask for them on a model with fewer inputs and degrees of freedom");
  const Eigen::VectorXd rates = d.qhat_d, xdd = d.xdd, edd = d.edd;
  // ẍ and ë at q̂̈ = 0 for the rates v: vᵀ D2F v, vᵀ D2Fe v.
  Eigen::VectorXd ax(sys.nx), ae(sys.ne);
  auto quadratic = [&](const Eigen::VectorXd& v) {
    check_thread_deadline("(in the second-order transfer functions)");
    d.qhat_d = v;
    solve_velocities(sys, d);
    d.xdd = d.acc0;
    deformation_accelerations(sys, d);
    ax = d.acc0;
    ae = d.edd;
  };
  d2f.resize(sys.nx, n * n);
  d2fe.resize(sys.ne, n * n);
  Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    v[i] = 1.0;
    quadratic(v);
    d2f.col(i * n + i) = ax;
    d2fe.col(i * n + i) = ae;
    v[i] = 0.0;
  }
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      v[i] = v[j] = 1.0;
      quadratic(v);
      v[i] = v[j] = 0.0;
      d2f.col(i * n + j) = 0.5 * (ax - d2f.col(i * n + i) - d2f.col(j * n + j));
      d2fe.col(i * n + j) = 0.5 * (ae - d2fe.col(i * n + i) - d2fe.col(j * n + j));
      d2f.col(j * n + i) = d2f.col(i * n + j);
      d2fe.col(j * n + i) = d2fe.col(i * n + j);
    }
  }
  d.qhat_d = rates;  // the state as it was
  solve_velocities(sys, d);
  d.xdd = xdd;
  d.edd = edd;
}

void Simulation::move_to(double t, const double* q, const double* qd) {
  const System& sys = *sys_;
  const int nd = sys.n_dof();
  const Eigen::Map<const Eigen::VectorXd> q1(q, nd), qd1(qd, nd);
  Eigen::VectorXd q0(nd), qd0(nd);
  for (int j = 0; j < nd; ++j) {
    q0[j] = data_->qhat[sys.dof_cols[j]];
    qd0[j] = data_->qhat_d[sys.dof_cols[j]];
  }
  const double t0 = data_->t;
  if (!have_transfer_) evaluate(t0, q0.data(), qd0.data());
  // A step is accepted when Newton only corrected the predicted positions by a small fraction
  // of the predicted change (the correction of a smooth path shrinks with the step squared; a
  // jump to another branch does not) or by a negligible amount.
  const double tiny = 1e-6 * sys.length_scale;
  double s = 0.0, ds = 1.0;
  Eigen::VectorXd qs(nd), qds(nd);
  auto at = [&](double u) {
    qs = q0 + u * (q1 - q0);
    qds = qd0 + u * (qd1 - qd0);
    return t0 + u * (t - t0);
  };
  while (s < 1.0) {
    const double s1 = ds >= 1.0 - s ? 1.0 : s + ds;
    const Solved from = run_.base;
    bool ok = true;
    try {
      evaluate(at(s1), qs.data(), qds.data());
      double predicted = 0.0, corrected = 0.0;
      for (int c : sys.x_calc) {
        predicted = std::max(predicted, std::abs(predicted_[c]));
        corrected = std::max(corrected, std::abs(data_->x[c] - from.x[c] - predicted_[c]));
      }
      ok = corrected <= 0.1 * predicted || corrected <= tiny;
    } catch (const KinematicsError&) {
      ok = false;
    }
    if (ok) {
      s = s1;
      ds *= 2.0;
      continue;
    }
    if (ds < 1e-6) {
      std::ostringstream os;
      os << "cannot follow the kinematic solution from t = " << t0 << " to t = " << t
         << ": the mechanism does not move continuously near t = " << at(s1);
      throw KinematicsError(os.str());
    }
    // Back to the last accepted state (exact positions, its DF for the predictor).
    run_.base = from;
    have_transfer_ = false;
    evaluate(at(s), qs.data(), qds.data());
    ds *= 0.5;
  }
}

void Simulation::forces() { nodal_reactions(*sys_, *data_); }

Linearizer& Simulation::linearizer() {
  if (!linearizer_) linearizer_ = std::make_unique<Linearizer>(model_, dependent_);
  return *linearizer_;
}

Linearization Simulation::linearize(Linearizer::Differences differences) {
  forces();
  return linearizer().compute(*sys_, *data_, differences);
}

bool Simulation::linearize_nodal(NodalLinearization& out) { return linearizer().compute_nodal(*sys_, *data_, out); }

Linearization Simulation::linearize_at_rest(double t, const Eigen::VectorXd& q) {
  const Eigen::VectorXd at_rest = Eigen::VectorXd::Zero(sys_->n_dof());
  require_dof_sizes("linearize_at_rest", q, at_rest);
  solve_motion(t, q.data(), at_rest.data(), Start::Transfer);  // positions and rates only
  have_transfer_ = false;
  return linearizer().compute_at_rest(*sys_, *data_);
}

void Simulation::evaluate_state(double t, const Eigen::VectorXd& Y) {
  const int nd = sys_->n_dof(), ny = static_cast<int>(sys_->y_defs.size());
  if (Y.size() != 2 * nd + ny + run_.n_energy)
    throw InputError("evaluate_state: the state (q, y, q̇) needs " + std::to_string(2 * nd + ny + run_.n_energy) +
                     " values, got " + std::to_string(Y.size()));
  // On the recursive path the last solved state may be a stage a whole (large) step away: start
  // Newton from the tree's exact positions at (q, q̇) instead.
  // Its q̈ is the general path's solution, which then needs no equations of motion, where the
  // tree knows all the loads (a run's tree; not with time-dependent or held loads set since
  // recursive_state).
  const bool known = path_->tree() && tree_state(t, Y, run_.tree_qdd) && timed_.empty() && run_.held.size() == 0;
  for (int i = 0; i < ny; ++i) data_->e_integrated[sys_->y_defs[i]] = Y[nd + i];
  if (known) solve_state(t, Y.data(), Y.data() + nd + ny, Start::Exact, &run_.tree_qdd);
  else solve_state(t, Y.data(), Y.data() + nd + ny);
}

bool Simulation::tree_state(double t, const Eigen::VectorXd& Y, Eigen::VectorXd& qdd) {
  const int nd = sys_->n_dof();
  qdd.resize(nd);
  // Outside a run (a tree kept from recursive_state) the last solved state may hold positions only.
  for (Eigen::VectorXd* v : {&run_.base.x, &run_.base.xd, &run_.base.xdd})
    if (v->size() != sys_->nx) v->setZero(sys_->nx);
  if (!path_->tree()->solve(Y.data(), Y.data() + nd, run_.base.x, run_.base.xd, run_.base.xdd, qdd.data())) return false;
  run_.base.valid = true;  // the start of Newton's iterations at the next general evaluation
  run_.base.t = t;
  return true;
}

template <class F>
void Simulation::in_rhs(double t, F&& evaluate) {
  struct InRhs {  // solve_motion() checks continuity with the step start only inside a right-hand side
    bool& flag;
    explicit InRhs(bool& f) : flag(f) { flag = true; }
    ~InRhs() { flag = false; }
  };
  try {
    const InRhs guard(run_.in_rhs);
    evaluate();
  } catch (const KinematicsError& err) {
    run_.kinematic_failure = err.what();
    run_.kinematic_failure_t = t;
    throw StepRejected(err.what());
  }
}

bool Simulation::residual_form() const {
  return (path_->residual_form() || sparse_newton()) && !path_->tree() && sys_->y_defs.empty() &&
         run_.n_energy == 0;
}

bool Simulation::sparse_newton() const {
  return !path_->tree() && sys_->y_defs.empty() && run_.n_energy == 0 && sys_->velocity_block_is_position_block &&
         sys_->n_dof() >= kSparseNewtonDofs;
}

void Simulation::newton_refresh(double t, const Eigen::VectorXd& Y) {
  try {
    evaluate_state(t, Y);  // positions, rates, masses and the complete stresses there
  } catch (const KinematicsError& err) {
    throw StepRejected(err.what());
  }
  if (!run_.newton_data) {
    run_.newton_data = std::make_unique<Data>(*data_);
    run_.newton_system = std::make_unique<ReducedSystem>(*sys_, *run_.newton_data);
  } else {
    *run_.newton_data = *data_;
  }
  run_.newton_factorized = false;
}

void Simulation::residual(double t, const Eigen::VectorXd& Y, const Eigen::VectorXd& qdd, Eigen::VectorXd& R) {
  const System& sys = *sys_;
  const int nd = sys.n_dof();
  check_time(t);
  in_rhs(t, [&] {
    solve_motion(t, Y.data(), Y.data() + nd, Start::Taylor);
    set_dof_accelerations(sys, *data_, qdd);
    path_->residual(sys, *data_, R);
  });
  remember(run_.base);  // the next positions' predictor, and the anchor of the next step
  have_transfer_ = false;
}

void Simulation::rhs(double t, const Eigen::VectorXd& Y, Eigen::VectorXd& dY) {
  const int nd = sys_->n_dof(), ny = static_cast<int>(sys_->y_defs.size());
  check_time(t);
  // The recursive path: q̈ only; the coordinates follow where a general evaluation needs them.
  // Y = (q, y, q̇[, energy]): trees have no integrated deformations and no energy states.
  RecursiveTree* tree = path_->tree();
  if (tree && tree->solve(Y.data(), Y.data() + nd + ny, dY.data() + nd + ny)) {
    dY.head(nd) = Y.segment(nd + ny, nd);
    return;
  }
  in_rhs(t, [&] { evaluate_state(t, Y); });
  dY.head(nd) = Y.segment(nd + ny, nd);
  for (int i = 0; i < ny; ++i) dY[nd + i] = data_->ed[sys_->y_defs[i]];
  dY.segment(nd + ny, nd) = data_->qdd;
  if (run_.n_energy) {  // the quadrature states: dissipated and external work
    const EnergyRates r = energy_rates(*sys_, *data_);
    dY[2 * nd + ny] = r.dissipated;
    dY[2 * nd + ny + 1] = r.external;
  }
}

void Simulation::set_time_loads(TimeLoads loads) {
  const System& sys = *sys_;
  for (const TimeLoads::LoadTable& l : loads.load_tables) {
    if (static_cast<int>(l.coords.size()) != l.table.components())
      throw InputError("a load table has " + std::to_string(l.table.components()) + " components for " +
                       std::to_string(l.coords.size()) + " coordinates");
    for (int g : l.coords)
      if (g < 0 || g >= sys.nx) throw InputError("a load table names coordinate " + std::to_string(g) + " of " +
                                                 std::to_string(sys.nx));
  }
  for (const TimeLoads::InputTable& in : loads.input_tables) {
    if (in.input < 0 || in.input >= sys.n_input())
      throw InputError("an input table names input " + std::to_string(in.input) + " of " +
                       std::to_string(sys.n_input()));
    if (in.table.components() != 1) throw InputError("an input table must have one component (the position)");
  }
  timed_ = std::move(loads);
  rollout_ = RolloutStart();  // the path a rollout chose may no longer hold
}

void Simulation::apply_time_loads(double t) {
  const System& sys = *sys_;
  Data& d = *data_;
  for (const TimeLoads::InputTable& in : timed_.input_tables)
    set_input(sys, d, in.input, in.table(t, 0, 0), in.table(t, 0, 1), in.table(t, 0, 2));
  if (timed_.load_tables.empty() && !timed_.load_function && run_.held.size() == 0) {
    d.time_load.resize(0);
    return;
  }
  d.time_load.setZero(sys.nx);
  for (const TimeLoads::LoadTable& l : timed_.load_tables)
    for (size_t j = 0; j < l.coords.size(); ++j) d.time_load[l.coords[j]] += l.table(t, static_cast<int>(j));
  if (timed_.load_function) timed_.load_function(t, d.time_load);
  if (run_.held.size()) d.time_load += run_.held;
}

RecursiveTree* Simulation::recursive_tree() {
  if (!path_->tree()) {
    std::unique_ptr<RecursiveTree> tree = RecursiveTree::detect(*sys_, *data_);
    if (!tree) return nullptr;
    path_ = std::make_unique<TreePath>(std::move(tree));
  }
  return path_->tree();
}

bool Simulation::recursive_state(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, Eigen::VectorXd& qdd,
                                 Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd) {
  require_dof_sizes("recursive_state", q, qd);
  if (!recursive_tree()) return false;
  Eigen::VectorXd x1 = data_->x, xd1 = Eigen::VectorXd::Zero(sys_->nx), xdd1 = xd1, qdd1(sys_->n_dof());
  if (!path_->tree()->solve(q.data(), qd.data(), x1, xd1, xdd1, qdd1.data())) return false;
  qdd = qdd1;
  x = x1;
  xd = xd1;
  xdd = xdd1;
  return true;
}

namespace {

// The states given to inverse_dynamics and dynamics_derivatives: finite (checked here, where it
// costs nanoseconds; in Python a check per array took a third of a call for one state).
void require_finite_states(const char* what, std::initializer_list<std::pair<const char*, const StateRows*>> arrays) {
  for (const auto& [name, a] : arrays)
    if (!a->allFinite())
      throw InputError(std::string(what) + ": " + name + " must be finite (NaN and infinity are not states)");
}

}  // namespace

RowMatrix Simulation::inverse_dynamics(const StateRows& q, const StateRows& qd, const StateRows& qdd,
                                       std::string& path) {
  const int nd = sys_->n_dof();
  if (q.cols() != nd || qd.cols() != nd || qdd.cols() != nd || qd.rows() != q.rows() || qdd.rows() != q.rows())
    throw InputError("inverse_dynamics(): q, qd and qdd must have the same number of states (rows) and one column "
                     "per degree of freedom (" + std::to_string(nd) + ")");
  require_finite_states("inverse_dynamics", {{"q", &q}, {"qd", &qd}, {"qdd", &qdd}});
  RowMatrix force(q.rows(), nd);
  if (RecursiveTree* tree = recursive_tree()) {
    path = "tree";
    for (Eigen::Index k = 0; k < q.rows(); ++k) {
      if ((k & 1023) == 1023) check_thread_deadline("(in inverse_dynamics)");  // a state takes about 1 µs
      tree->inverse_dynamics(q.row(k).data(), qd.row(k).data(), qdd.row(k).data(), force.row(k).data());
    }
    return force;
  }
  path = "general";
  for (Eigen::Index k = 0; k < q.rows(); ++k) {
    check_thread_deadline("(in inverse_dynamics)");
    evaluate(data_->t, q.row(k).data(), qd.row(k).data());
    force.row(k) = (data_->Mbar * (qdd.row(k).transpose() - data_->qdd)).transpose();
  }
  return force;
}

void Simulation::dynamics_derivatives(const StateRows& q, const StateRows& qd, const StateRows& tau, RowMatrix& qdd,
                                      RowMatrix& dq, RowMatrix& dqd, RowMatrix& dtau) {
  RecursiveTree* tree = recursive_tree();
  if (!tree) {
    throw InputError("dynamics_derivatives: the model is not a tree of rigid bodies of the recursive path (" +
                     recursive_refusal() + "); the derivatives are computed on planar and spatial trees of rigid "
                     "bodies (URDF robots, pendulums, branched linkages)");
  }
  const int nd = sys_->n_dof();
  if (q.cols() != nd || qd.cols() != nd || tau.cols() != nd || qd.rows() != q.rows() || tau.rows() != q.rows())
    throw InputError("dynamics_derivatives(): q, qd and tau must have the same number of states (rows) and one "
                     "column per degree of freedom (" + std::to_string(nd) + ")");
  require_finite_states("dynamics_derivatives", {{"q", &q}, {"qd", &qd}, {"tau", &tau}});
  require_memory(8.0 * double(q.rows()) * (3.0 * nd * nd + nd), "the dynamics derivatives",
                 "ask for fewer states at a time");
  qdd.resize(q.rows(), nd);
  dq.resize(q.rows(), nd * nd);
  dqd.resize(q.rows(), nd * nd);
  dtau.resize(q.rows(), nd * nd);
  for (Eigen::Index k = 0; k < q.rows(); ++k) {
    check_thread_deadline("(in dynamics_derivatives)");
    bool ok = false;
    try {
      ok = tree->dynamics_derivatives(nd, q.row(k).data(), qd.row(k).data(), tau.row(k).data(), qdd.row(k).data(),
                                      dq.row(k).data(), dqd.row(k).data(), dtau.row(k).data());
    } catch (const InputError& e) {  // the state itself (a floating base's Euler parameters): say which
      throw InputError(std::string(e.what()) + " at state " + std::to_string(k));
    }
    if (!ok) {
      throw InputError("dynamics_derivatives: the mass matrix is not positive definite at state " +
                       std::to_string(k) + " (e.g. a body that moves no mass)");
    }
  }
}

std::string Simulation::recursive_refusal() const {
  std::string why;
  return RecursiveTree::detect(*sys_, *data_, &why) ? std::string() : why;
}

Eigen::VectorXd Simulation::reduced_accelerations() {
  Data& d = *data_;
  const Eigen::VectorXd qdd = d.qdd, xdd = d.xdd, edd = d.edd, qhat_dd = d.qhat_dd;
  solve_transfer(*sys_, d);
  solve_velocities(*sys_, d);
  solve_dynamics(*sys_, d);
  Eigen::VectorXd reduced = d.qdd;
  d.qdd = qdd;
  d.xdd = xdd;
  d.edd = edd;
  d.qhat_dd = qhat_dd;
  return reduced;
}

void Simulation::require_dof_sizes(const char* what, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) const {
  if (q.size() != sys_->n_dof() || qd.size() != sys_->n_dof())
    throw InputError(std::string(what) + "(): q and qd must have one value per degree of freedom");
}

void Simulation::solve_state(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  require_dof_sizes("solve_state", q, qd);
  solve_state(t, q.data(), qd.data());
}

void Simulation::evaluate(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  require_dof_sizes("evaluate", q, qd);
  evaluate(t, q.data(), qd.data());
}

void Simulation::move_to(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  require_dof_sizes("move_to", q, qd);
  move_to(t, q.data(), qd.data());
}

void Simulation::record(BlockResults& res, int k) {
  res.t[k] = data_->t;
  for (const OutputArray& a : kOutputArrays) (res.*a.rows).row(k) = (*data_).*a.now;
}

BlockResults Simulation::run(const RunOptions& options) {
  BlockResults res;
  run(res, options);
  return res;
}

void Simulation::require_finite_state(double t) const {
  // Values beyond double precision (e.g. FORCE 8 1e308 on a support) must not reach the results
  // as infinities or NaNs: the run stops here and keeps the output times before.
  for (const OutputArray& a : kOutputArrays)
    if (!((*data_).*a.now).allFinite()) {
      std::ostringstream os;
      os << "the " << a.what << " at t = " << t
         << " are not finite: the model's values exceed double precision (check the magnitudes of loads, "
            "masses, stiffnesses and rates)";
      throw Error(os.str());
    }
}

void Simulation::check_time(double t) {
  check_thread_interrupt();
  if (!thread_deadline_passed()) return;
  std::ostringstream os;
  os << "at t = " << t;
  throw_time_limit(os.str());
}

}  // namespace spacar

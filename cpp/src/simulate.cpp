#include "spacar/simulate.hpp"

#include <chrono>
#include <cmath>
#include <sstream>

#include "spacar/dynamics.hpp"
#include "spacar/errors.hpp"
#include "spacar/forces.hpp"
#include "spacar/kinematics.hpp"

namespace spacar {

namespace {

std::unique_ptr<System> prepare_and_compile(Model& model) {
  model.prepare();
  return compile(model);
}

}  // namespace

Simulation::Simulation(Model& model)
    : model_(model), sys_(prepare_and_compile(model)), data_(*sys_) {
  for (const FreeRotation& fr : sys_->free_rotations) dependent_[fr.node] = fr.dependent;
  int g = 0;
  for (const auto& [id, n] : model_.nodes)
    for (double v : n.x) data_.x[g++] = v;
  forget_solutions();
}

void Simulation::forget_solutions() {
  recent_.clear();
  recent_next_ = 0;
  have_last_ = have_anchor_ = false;
  predictor_ = Eigen::VectorXd::Zero(sys_->nx);
}

Simulation::Solution Simulation::solution(double t, bool with_DF) const {
  return Solution{t, Eigen::VectorXd(), data_.x, data_.qhat, data_.angle_ref,
                  with_DF ? data_.DF : Eigen::MatrixXd()};
}

void Simulation::step_start(double t, const Eigen::VectorXd& Y) {
  if (t > kinematic_failure_t_) kinematic_failure_.clear();  // passed: the failure is history
  for (size_t i = 0; i < recent_.size(); ++i) {  // newest first
    const Solution& s = recent_[(recent_next_ + kRecent - 1 - i) % kRecent];
    if (s.t == t && s.Y.size() == Y.size() && s.Y == Y) {
      anchor_ = s;
      have_anchor_ = true;
      return;
    }
  }
  have_anchor_ = false;  // not found (should not happen): predict from the last solution
}

void Simulation::assemble() {
  const System& sys = *sys_;
  set_inputs(sys, data_, sys.t0);
  set_dofs(sys, data_, sys.q0.data(), sys.qd0.data());
  check_constraint_counts(sys, data_);
  solve_positions(sys, data_, sys.settings.maxiterat, sys.settings.epskin, true);
  forget_solutions();
  last_ = solution(sys.t0, false);  // DF not yet available for the predictor
  have_last_ = true;
}

void Simulation::evaluate(double t, const double* q, const double* qd) {
  const System& sys = *sys_;
  set_inputs(sys, data_, t);
  set_dofs(sys, data_, q, qd);
  // Newton starts from the last solution advanced with its first-order transfer function (the
  // predictor). The last solution may be a stage up to a full step ahead, solved before the step
  // failed elsewhere: predicting from it can fail, or converge to another branch of the
  // constraints (a disc turned over, a linkage through its dead point). In a right-hand side,
  // the result must therefore also be continuous with the start of the integration step; if it
  // is not, or Newton failed, Newton starts again from that step start, and if the result is
  // still not continuous, the step is rejected (KinematicsError → smaller step).
  const auto solve_from = [&](const Solution* base) {
    if (base) {
      data_.x = base->x;
      data_.angle_ref = base->angles;
      if (base->DF.size() > 0) {
        predictor_.noalias() = base->DF * (data_.qhat - base->qhat);
        for (int c : sys.x_calc) data_.x[c] += predictor_[c];
      }
    }
    for (size_t i = 0; i < sys.x_input.size(); ++i) data_.x[sys.x_input[i]] = data_.qhat[sys.qhat_col_x[sys.x_input[i]]];
    for (size_t j = 0; j < sys.x_dyn.size(); ++j) data_.x[sys.x_dyn[j]] = q[j];
    solve_positions(sys, data_, sys.settings.maxiterat, sys.settings.epskin, false);
  };
  const bool check = in_rhs_ && have_anchor_;
  std::string why;
  bool ok = false;
  try {
    solve_from(have_last_ ? &last_ : nullptr);
    ok = !check || continuous_with_step_start(why);
  } catch (const KinematicsError& err) {
    if (!have_anchor_) throw;
    why = err.what();
  }
  if (!ok) {
    solve_from(&anchor_);
    if (check && !continuous_with_step_start(why)) throw KinematicsError(why);
  }
  solve_transfer(sys, data_);
  solve_velocities(sys, data_);
  solve_dynamics(sys, data_);
  last_ = solution(t, true);
  have_last_ = true;
}

// The calculable coordinates just solved against the first-order prediction from the step start
// (anchor_): the nonlinear part of the motion must not exceed the linear part (plus a small
// floor), in units of the element lengths for positions and of 1 for angles and Euler
// parameters. For a rigid link turning by Δ the ratio is about Δ/2: this rejects only steps
// that turn parts by radians, or jumps to another solution branch.
bool Simulation::continuous_with_step_start(std::string& why) const {
  const System& sys = *sys_;
  predictor_anchor_.noalias() = anchor_.DF * (data_.qhat - anchor_.qhat);
  double dev = 0.0, inc = 0.0;
  int worst = -1;
  for (int c : sys.x_calc) {
    const double w = sys.coord_is_length[c] ? 1.0 / sys.length_scale : 1.0;
    const double d = std::abs(data_.x[c] - anchor_.x[c] - predictor_anchor_[c]) * w;
    inc = std::max(inc, std::abs(predictor_anchor_[c]) * w);
    if (d > dev || worst < 0) {
      dev = d;
      worst = c;
    }
  }
  if (dev <= inc + 1e-6) return true;
  std::ostringstream os;
  os << "the positions at t = " << data_.t << " are not continuous with the start of the integration step at t = "
     << anchor_.t << ": " << sys.coord_name(worst) << " differs by " << dev
     << " (scaled) from its first-order prediction, while the predicted motion is " << inc
     << "; the step is too large for the kinematics here (or the mechanism is at a singular configuration)";
  why = os.str();
  return false;
}

void Simulation::forces() { solve_reactions(*sys_, data_); }

Linearization Simulation::linearize() {
  forces();
  if (!linearizer_) linearizer_ = std::make_unique<Linearizer>(model_, dependent_);
  return linearizer_->compute(*sys_, data_);
}

void Simulation::evaluate_state(double t, const Eigen::VectorXd& Y) {
  const int nd = sys_->n_dof(), ny = static_cast<int>(sys_->y_defs.size());
  for (int i = 0; i < ny; ++i) data_.e_integrated[sys_->y_defs[i]] = Y[nd + i];
  evaluate(t, Y.data(), Y.data() + nd + ny);
}

void Simulation::rhs(double t, const Eigen::VectorXd& Y, Eigen::VectorXd& dY) {
  const int nd = sys_->n_dof(), ny = static_cast<int>(sys_->y_defs.size());
  struct InRhs {  // evaluate() checks continuity with the step start only inside a right-hand side
    bool& flag;
    explicit InRhs(bool& f) : flag(f) { flag = true; }
    ~InRhs() { flag = false; }
  };
  try {
    const InRhs in_rhs(in_rhs_);
    evaluate_state(t, Y);
  } catch (const KinematicsError& err) {
    kinematic_failure_ = err.what();
    kinematic_failure_t_ = t;
    throw StepRejected(err.what());
  }
  // Remember the solutions of the right-hand sides: one of them is the next step's start.
  Solution s = last_;
  s.Y = Y;
  if (recent_.size() < kRecent) recent_.push_back(std::move(s));
  else recent_[recent_next_] = std::move(s);
  recent_next_ = (recent_next_ + 1) % kRecent;
  dY.head(nd) = Y.tail(nd);
  for (int i = 0; i < ny; ++i) dY[nd + i] = data_.ed[sys_->y_defs[i]];
  dY.tail(nd) = data_.qdd;
}

void Simulation::record(BlockResults& res, int k) {
  res.t[k] = data_.t;
  res.x.row(k) = data_.x;
  res.xd.row(k) = data_.xd;
  res.xdd.row(k) = data_.xdd;
  res.e.row(k) = data_.e;
  res.ed.row(k) = data_.ed;
  res.edd.row(k) = data_.edd;
  res.sigma.row(k) = data_.sigma;
  res.reaction.row(k) = data_.reaction;
}

BlockResults Simulation::run(const RunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  // The system may be recompiled during the run (repartition): keep copies, not references.
  const Settings st = sys_->settings;
  const int n_out = st.timestep_n;
  const double t0 = sys_->t0, t_end = t0 + st.timestep_tp;
  BlockResults res;
  res.warnings = sys_->warnings;
  const int nt = n_out + 1;
  res.t.resize(nt);
  for (RowMatrix* m : {&res.x, &res.xd, &res.xdd, &res.reaction}) m->resize(nt, sys_->nx);
  res.reaction.setZero();
  const bool linear = !sys_->e_line.empty() || st.linear.value_or(0) >= 1;
  for (RowMatrix* m : {&res.e, &res.ed, &res.edd, &res.sigma}) m->resize(nt, sys_->ne);
  std::vector<double> times(nt);
  for (int k = 0; k < nt; ++k) times[k] = n_out ? t0 + st.timestep_tp * k / n_out : t0;
  times.back() = t_end;  // exactly the end of the block, whatever the rounding

  assemble();
  const int nd = sys_->n_dof(), ny = static_cast<int>(sys_->y_defs.size());
  int k_out = 0;
  auto output = [&](double t, const Eigen::VectorXd& Y) {
    evaluate_state(t, Y);
    if (st.forcemode >= 1 || linear) forces();
    if (linear) res.linearizations.push_back(linearize());
    record(res, k_out);
    if (options.on_output) options.on_output(k_out, data_);
    ++k_out;
  };
  // State Y = (q, y, q̇): DOFs, integrated deformations, DOF rates.
  Eigen::VectorXd Y(2 * nd + ny);
  Y << sys_->q0, sys_->y0, sys_->qd0;
  if ((nd == 0 && ny == 0) || n_out == 0 || !(t_end > t0)) {
    // Kinematic analysis (or a single analysis at the current time).
    for (double t : times) output(t, Y);
  } else {
    double t = t0, h = options.initial_step;
    kinematic_failure_.clear();
    for (;;) {
      // One segment: integrate until the end, or until a free rotation must be repartitioned.
      Integrator integ(static_cast<int>(Y.size()), options.method);
      Eigen::VectorXd rtol(Y.size());
      rtol.head(nd + ny).setConstant(st.epsint);
      rtol.tail(nd).setConstant(st.epsind);
      integ.set_tolerances(rtol, 1e-3 * rtol);  // formulation.md §8.1: sc = EPS (10⁻³ + |y|)
      integ.set_max_step(st.hmax);
      if (h > 0.0) integ.set_initial_step(h);
      if (!sys_->free_rotations.empty())
        integ.set_stop_condition([this](double, const Eigen::VectorXd& y) { return rotation_to_repartition(y) >= 0; });
      integ.set_step_start([this](double tt, const Eigen::VectorXd& y) { step_start(tt, y); });
      const std::vector<double> remaining(times.begin() + k_out, times.end());
      auto f = [this](double tt, const Eigen::VectorXd& y, Eigen::VectorXd& dy) { rhs(tt, y, dy); };
      double t_reached = t;
      try {
        t_reached = integ.integrate(f, t, t_end, Y, remaining, output);
      } catch (const IntegrationError& err) {
        // The step collapsed because the kinematics has no solution (the last right-hand side
        // failed in the Newton iteration): that is a KinematicsError (formulation.md §2.2).
        if (kinematic_failure_.empty()) throw;
        std::string integrator = err.what();
        const size_t cut = integrator.find(" (last rejection");
        if (cut != std::string::npos) integrator.resize(cut);
        throw KinematicsError(kinematic_failure_ + "\nNo kinematic solution down to the minimum step (" +
                              integrator + ").");
      }
      const IntegratorStats& s = integ.stats();
      res.rhs_evaluations += s.nfev;
      res.steps += s.nsteps;
      res.accepted += s.naccept;
      res.rejected += s.nreject;
      h = res.last_step = integ.last_step();
      if (t_reached >= t_end) break;
      t = t_reached;
      repartition(rotation_to_repartition(Y), t, Y);
    }
  }
  res.newton_iterations = data_.total_newton_iterations;
  res.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  store_state();
  return res;
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

void Simulation::repartition(int which, double t, Eigen::VectorXd& Y) {
  evaluate_state(t, Y);
  const FreeRotation fr = sys_->free_rotations[which];
  int best = 0;
  for (int i = 1; i < 4; ++i)
    if (std::abs(data_.x[fr.coord + i]) > std::abs(data_.x[fr.coord + best])) best = i;
  dependent_[fr.node] = best;
  linearizer_.reset();
  const Eigen::VectorXd x = data_.x, xd = data_.xd, e = data_.e, ed = data_.ed, angles = data_.angle_ref,
                        integrated = data_.e_integrated;
  const long newton = data_.total_newton_iterations;
  sys_ = compile(model_, dependent_);
  data_ = Data(*sys_);
  data_.x = x;
  data_.angle_ref = angles;
  data_.e_integrated = integrated;
  data_.total_newton_iterations = newton;
  forget_solutions();  // the next evaluation starts from x (the new q̂ has another meaning)
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
}

void Simulation::store_state() {
  const System& sys = *sys_;
  int g = 0;
  for (auto& [id, n] : model_.nodes)
    for (size_t i = 0; i < n.x.size(); ++i, ++g) {
      n.x[i] = data_.x[g];
      n.xd[i] = data_.xd[g];
      n.xdd[i] = data_.xdd[g];
    }
  int k = 0;
  for (auto& [id, el] : model_.elements)
    for (size_t i = 0; i < el.e.size(); ++i, ++k) {
      const DefClass c = sys.def_class[k];
      const bool target = (c == DefClass::Fixed || c == DefClass::Linearization) && el.e_given[i];
      if (!target) el.e[i] = data_.e[k];  // a given target stays exact for the next block
      el.ed[i] = data_.ed[k];
      el.edd[i] = data_.edd[k];
      // Values that are states continue in the next block: inputs, DOFs, kinematic coordinates
      // and the integrated values of released velocity-level deformations (slips).
      if (c == DefClass::Input || c == DefClass::Dynamic || c == DefClass::Kinematic ||
          (c == DefClass::Released && sys.def_velocity_level[k]))
        el.e_given[i] = true;
    }
  model_.time = data_.t;
}

}  // namespace spacar

#include "spacar/simulate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "spacar/dynamics.hpp"
#include "spacar/errors.hpp"
#include "spacar/kinematics.hpp"

namespace spacar {

namespace {

std::unique_ptr<System> prepare_and_compile(Model& model) {
  model.prepare();
  return compile(model);
}

}  // namespace

Simulation::Simulation(Model& model)
    : model_(model), sys_(prepare_and_compile(model)), data_(std::make_unique<Data>(*sys_)) {
  xd_base_ = xdd_base_ = predicted_ = Eigen::VectorXd::Zero(sys_->nx);
  for (const FreeRotation& fr : sys_->free_rotations) dependent_[fr.node] = fr.dependent;
  int g = 0;
  for (const auto& [id, n] : model_.nodes)
    for (double v : n.x) data_->x[g++] = v;
  x_base_ = data_->x;
}

void Simulation::assemble() {
  const System& sys = *sys_;
  set_inputs(sys, *data_, sys.t0);
  set_dofs(sys, *data_, sys.q0.data(), sys.qd0.data());
  check_constraint_counts(sys, *data_);
  solve_positions(sys, *data_, sys.settings.maxiterat, sys.settings.epskin, true);
  x_base_ = data_->x;
  have_base_ = false;  // no velocities yet for the predictor
}

void Simulation::solve_state(double t, const double* q, const double* qd, bool transfer_predictor) {
  const System& sys = *sys_;
  set_inputs(sys, *data_, t);
  set_dofs(sys, *data_, q, qd);
  // Predictor of the positions: from the last solved state, a second-order Taylor step in time
  // (integration stages), or the first-order transfer function applied to the change of the
  // independent coordinates (states given by the user, when DF of the last state is known).
  data_->x = x_base_;
  for (int g : sys.x_input) data_->x[g] = data_->qhat[sys.qhat_col_x[g]];
  for (size_t j = 0; j < sys.x_dyn.size(); ++j) data_->x[sys.x_dyn[j]] = q[j];
  bool predicted = true;
  predicted_.setZero();
  if (transfer_predictor && have_transfer_) {
    predicted_.noalias() = data_->DF * (data_->qhat - qhat_base_);
    for (int c : sys.x_calc) data_->x[c] += predicted_[c];
  } else if (have_base_ && t != t_base_) {
    const double dt = t - t_base_;
    for (int c : sys.x_calc) data_->x[c] += dt * (xd_base_[c] + 0.5 * dt * xdd_base_[c]);
  } else {
    predicted = false;
  }
  try {
    solve_positions(sys, *data_, sys.settings.maxiterat, sys.settings.epskin, false);
  } catch (const KinematicsError&) {
    if (!predicted) throw;
    // A long extrapolation (e.g. the integrator's trial of its first step) may overshoot: start
    // again from the last solved positions.
    for (int c : sys.x_calc) data_->x[c] = x_base_[c];
    solve_positions(sys, *data_, sys.settings.maxiterat, sys.settings.epskin, false);
  }
  solve_velocities_direct(sys, *data_);
  solve_dynamics_direct(sys, *data_);
  x_base_ = data_->x;
  xd_base_ = data_->xd;
  xdd_base_ = data_->xdd;
  qhat_base_ = data_->qhat;
  t_base_ = t;
  have_base_ = true;
  have_transfer_ = false;
}

void Simulation::evaluate(double t, const double* q, const double* qd) {
  solve_state(t, q, qd, true);
  // Transfer functions and the reduced mass matrix, for users, tests and teaching.
  const System& sys = *sys_;
  solve_transfer(sys, *data_);
  solve_velocities(sys, *data_);
  assemble_mass_matrix(sys, *data_);
  for (int j = 0; j < sys.n_dof(); ++j) data_->DFq.col(j) = data_->DF.col(sys.dof_cols[j]);
  data_->Mbar.noalias() = data_->DFq.transpose() * data_->M * data_->DFq;
  have_transfer_ = true;
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
  if (!have_base_) evaluate(t0, q0.data(), qd0.data());
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
    const Eigen::VectorXd x_from = x_base_, angles_from = data_->angle_ref;
    bool ok = true;
    try {
      evaluate(at(s1), qs.data(), qds.data());
      double predicted = 0.0, corrected = 0.0;
      for (int c : sys.x_calc) {
        predicted = std::max(predicted, std::abs(predicted_[c]));
        corrected = std::max(corrected, std::abs(data_->x[c] - x_from[c] - predicted_[c]));
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
    x_base_ = x_from;
    data_->angle_ref = angles_from;
    have_base_ = have_transfer_ = false;
    evaluate(at(s), qs.data(), qds.data());
    ds *= 0.5;
  }
}

void Simulation::forces() { nodal_reactions(*sys_, *data_); }

Linearization Simulation::linearize() {
  forces();
  if (!linearizer_) linearizer_ = std::make_unique<Linearizer>(model_, dependent_);
  return linearizer_->compute(*sys_, *data_);
}

void Simulation::evaluate_state(double t, const Eigen::VectorXd& Y) {
  const int nd = sys_->n_dof(), ny = static_cast<int>(sys_->y_defs.size());
  for (int i = 0; i < ny; ++i) data_->e_integrated[sys_->y_defs[i]] = Y[nd + i];
  solve_state(t, Y.data(), Y.data() + nd + ny, false);
}

void Simulation::rhs(double t, const Eigen::VectorXd& Y, Eigen::VectorXd& dY) {
  const int nd = sys_->n_dof(), ny = static_cast<int>(sys_->y_defs.size());
  try {
    evaluate_state(t, Y);
  } catch (const KinematicsError& err) {
    kinematic_failure_ = err.what();
    throw StepRejected(err.what());
  }
  dY.head(nd) = Y.tail(nd);
  for (int i = 0; i < ny; ++i) dY[nd + i] = data_->ed[sys_->y_defs[i]];
  dY.tail(nd) = data_->qdd;
}

void Simulation::record(BlockResults& res, int k) {
  res.t[k] = data_->t;
  res.x.row(k) = data_->x;
  res.xd.row(k) = data_->xd;
  res.xdd.row(k) = data_->xdd;
  res.e.row(k) = data_->e;
  res.ed.row(k) = data_->ed;
  res.edd.row(k) = data_->edd;
  res.sigma.row(k) = data_->sigma;
  res.reaction.row(k) = data_->reaction;
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
    else constitutive_stresses(*sys_, *data_);  // FORCEMODE 0: no reaction stresses
    if (linear) res.linearizations.push_back(linearize());
    record(res, k_out);
    if (options.on_output) options.on_output(k_out, *data_);
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
      // After every accepted step: forget kinematic failures of rejected trials; stop to
      // repartition a free rotation whose dependent Euler parameter became small.
      integ.set_stop_condition([this](double, const Eigen::VectorXd& y) {
        kinematic_failure_.clear();
        return !sys_->free_rotations.empty() && rotation_to_repartition(y) >= 0;
      });
      const std::vector<double> remaining(times.begin() + k_out, times.end());
      auto f = [this](double tt, const Eigen::VectorXd& y, Eigen::VectorXd& dy) { rhs(tt, y, dy); };
      double t_reached = t;
      try {
        t_reached = integ.integrate(f, t, t_end, Y, remaining, output);
      } catch (const IntegrationError& err) {
        explain_collapse(err, Y);
        throw;
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
  res.newton_iterations = data_->total_newton_iterations;
  res.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  store_state();
  return res;
}

void Simulation::explain_collapse(const IntegrationError& err, const Eigen::VectorXd& Y) {
  std::string integrator = err.what();
  const size_t cut = integrator.find(" (last rejection");
  if (cut != std::string::npos) integrator.resize(cut);
  // The step collapsed because the kinematics has no solution (a right-hand side since the last
  // accepted step failed in the Newton iteration): a KinematicsError (formulation.md §2.2).
  if (!kinematic_failure_.empty())
    throw KinematicsError(kinematic_failure_ + "\nNo kinematic solution down to the minimum step (" + integrator +
                          ").");
  // Or the mechanism runs into a singular configuration (a dead point): the accelerations grow
  // without bound as the velocity constraint block loses rank.
  if (sys_->x_calc.empty() || sys_->x_calc.size() > 2000) return;
  try {
    solve_state(data_->t, Y.data(), Y.data() + sys_->n_dof() + sys_->y_defs.size());
  } catch (const Error&) {
    return;
  }
  const std::string weak = weakest_constraint(*sys_, *data_);
  if (!weak.empty())
    throw KinematicsError("the mechanism reaches a singular configuration at t = " + std::to_string(data_->t) +
                          " (" + integrator + "); max Newton residual " +
                          std::to_string(data_->residual.size() ? data_->residual.cwiseAbs().maxCoeff() : 0.0) +
                          ".\n" + weak);
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
    if (std::abs(data_->x[fr.coord + i]) > std::abs(data_->x[fr.coord + best])) best = i;
  dependent_[fr.node] = best;
  linearizer_.reset();
  const Eigen::VectorXd x = data_->x, xd = data_->xd, e = data_->e, ed = data_->ed, angles = data_->angle_ref,
                        integrated = data_->e_integrated;
  const long newton = data_->total_newton_iterations;
  sys_ = compile(model_, dependent_);
  data_ = std::make_unique<Data>(*sys_);
  data_->x = x;
  data_->angle_ref = angles;
  data_->e_integrated = integrated;
  data_->total_newton_iterations = newton;
  x_base_ = x;
  have_base_ = have_transfer_ = false;
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
      if (c == DefClass::Input || c == DefClass::Dynamic || c == DefClass::Kinematic) el.e_given[i] = true;
    }
  model_.time = data_->t;
}

}  // namespace spacar

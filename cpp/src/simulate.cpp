#include "spacar/simulate.hpp"

#include <chrono>
#include <cmath>
#include <sstream>

#include "spacar/dynamics.hpp"
#include "spacar/errors.hpp"
#include "spacar/forces.hpp"
#include "spacar/kinematics.hpp"
#include "spacar/limits.hpp"

namespace spacar {

namespace {

std::unique_ptr<System> prepare_and_compile(Model& model) {
  model.prepare();
  std::unique_ptr<System> sys = compile(model);
  require_memory(Data::estimate_bytes(*sys),
                 "the analysis of " + std::to_string(sys->nx) + " nodal coordinates and " + std::to_string(sys->ne) +
                     " deformations (dense matrices)",
                 "");
  return sys;
}

}  // namespace

Simulation::Simulation(Model& model)
    : model_(model), sys_(prepare_and_compile(model)), data_(*sys_) {
  for (const FreeRotation& fr : sys_->free_rotations) dependent_[fr.node] = fr.dependent;
  int g = 0;
  for (const auto& [id, n] : model_.nodes)
    for (double v : n.x) data_.x[g++] = v;
  x_base_ = data_.x;
  qhat_base_ = data_.qhat;
  predictor_ = Eigen::VectorXd::Zero(sys_->nx);
}

void Simulation::assemble() {
  const System& sys = *sys_;
  set_inputs(sys, data_, sys.t0);
  set_dofs(sys, data_, sys.q0.data(), sys.qd0.data());
  check_constraint_counts(sys, data_);
  solve_positions(sys, data_, sys.settings.maxiterat, sys.settings.epskin, true);
  x_base_ = data_.x;
  qhat_base_ = data_.qhat;
  have_base_ = false;  // DF not yet available for the predictor
}

void Simulation::evaluate(double t, const double* q, const double* qd) {
  const System& sys = *sys_;
  set_inputs(sys, data_, t);
  set_dofs(sys, data_, q, qd);
  // Predictor: the last solved positions advanced with the first-order transfer function.
  data_.x = x_base_;
  for (size_t i = 0; i < sys.x_input.size(); ++i) data_.x[sys.x_input[i]] = data_.qhat[sys.qhat_col_x[sys.x_input[i]]];
  for (size_t j = 0; j < sys.x_dyn.size(); ++j) data_.x[sys.x_dyn[j]] = q[j];
  if (have_base_) {
    predictor_.noalias() = data_.DF * (data_.qhat - qhat_base_);
    for (int c : sys.x_calc) data_.x[c] += predictor_[c];
  }
  solve_positions(sys, data_, sys.settings.maxiterat, sys.settings.epskin, false);
  solve_transfer(sys, data_);
  solve_velocities(sys, data_);
  solve_dynamics(sys, data_);
  x_base_ = data_.x;
  qhat_base_ = data_.qhat;
  have_base_ = true;
}

void Simulation::forces() { solve_reactions(*sys_, data_); }

Linearization Simulation::linearize() {
  forces();
  if (!linearizer_) linearizer_ = std::make_unique<Linearizer>(model_, dependent_);
  return linearizer_->compute(*sys_, data_);
}

void Simulation::rhs(double t, const Eigen::VectorXd& Y, Eigen::VectorXd& dY) {
  const int nd = sys_->n_dof();
  check_time(t);
  try {
    evaluate(t, Y.data(), Y.data() + nd);
  } catch (const KinematicsError& err) {
    kinematic_failure_ = err.what();
    throw StepRejected(err.what());
  }
  kinematic_failure_.clear();
  dY.head(nd) = Y.segment(nd, nd);
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
  BlockResults res;
  run(res, options);
  return res;
}

void Simulation::require_finite_state(double t) const {
  // Values beyond double precision (e.g. FORCE 8 1e308 on a support) must not reach the results
  // as infinities or NaNs: the run stops here and keeps the output times before.
  const std::pair<const char*, const Eigen::VectorXd*> parts[] = {
      {"coordinates", &data_.x}, {"velocities", &data_.xd}, {"accelerations", &data_.xdd},
      {"deformations", &data_.e}, {"deformation rates", &data_.ed}, {"deformation accelerations", &data_.edd},
      {"stresses", &data_.sigma}, {"reactions", &data_.reaction}};
  for (const auto& [name, v] : parts)
    if (!v->allFinite()) {
      std::ostringstream os;
      os << "the " << name << " at t = " << t
         << " are not finite: the model's values exceed double precision (check the magnitudes of loads, "
            "masses, stiffnesses and rates)";
      throw Error(os.str());
    }
}

void Simulation::check_time(double t) {
  if (has_deadline_ && std::chrono::steady_clock::now() > deadline_) {
    std::ostringstream os;
    os << "the time limit of " << time_limit_ << " s was exceeded at t = " << t;
    throw TimeLimitError(os.str());
  }
}

namespace {

std::string num(double v) {
  std::ostringstream os;
  os.precision(12);
  os << v;
  return os.str();
}

// Keep the first `rows` rows of every time-indexed array (a run that failed midway).
void cut_rows(BlockResults& res, int rows) {
  res.t.conservativeResize(rows);
  for (RowMatrix* m : {&res.x, &res.xd, &res.xdd, &res.reaction, &res.e, &res.ed, &res.edd, &res.sigma})
    m->conservativeResize(rows, m->cols());
}

}  // namespace

void Simulation::run(BlockResults& res, const RunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (!(options.time_limit >= 0.0)) throw InputError("the time limit must not be negative");
  if (options.max_steps < 1) throw InputError("the step limit must be positive");
  has_deadline_ = options.time_limit > 0.0 && std::isfinite(options.time_limit);
  time_limit_ = options.time_limit;
  if (has_deadline_)
    deadline_ = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(options.time_limit));
  // The system may be recompiled during the run (repartition): keep copies, not references.
  Settings st = sys_->settings;
  const int n_out = st.timestep_n;
  const double t0 = sys_->t0, t_end = t0 + st.timestep_tp;
  res = BlockResults();
  res.warnings = sys_->warnings;
  const int nd0 = sys_->n_dof();
  const bool linear = !sys_->e_line.empty() || st.linear.value_or(0) >= 1;

  // Requests that cannot be carried out are refused before any work (formulation.md §8.1).
  if (!std::isfinite(t_end))
    throw InputError("TIMESTEP: the end time TIME + Tp = " + num(t0) + " + " + num(st.timestep_tp) +
                     " is not a finite number");
  if (n_out > 0 && st.timestep_tp > 0.0 && !(t0 + st.timestep_tp / n_out > t0))
    throw InputError("TIMESTEP: the output interval Tp/n = " + num(st.timestep_tp / n_out) +
                     " is lost in the rounding of the time t = " + num(t0) + " (TIME)");
  const bool integrate = nd0 > 0 && n_out > 0 && t_end > t0;
  if (integrate) {
    const double h_min = Integrator::min_step(t_end);
    if (st.timestep_tp < h_min)
      throw InputError("TIMESTEP: the period Tp = " + num(st.timestep_tp) +
                       " is shorter than the smallest integration step " + num(h_min) + " at t = " + num(t_end));
    if (st.hmax < Integrator::min_step(t0))
      throw InputError("HMAX " + num(st.hmax) + " is below the smallest integration step " +
                       num(Integrator::min_step(t0)) + " at t = " + num(t0));
    if (st.timestep_tp / st.hmax > static_cast<double>(options.max_steps))
      throw InputError("HMAX " + num(st.hmax) + " needs at least Tp/HMAX = " + num(st.timestep_tp / st.hmax) +
                       " steps, more than the limit of " + std::to_string(options.max_steps) + " steps per block");
    for (auto [eps, name] : {std::pair<double*, const char*>{&st.epsint, "EPSINT"}, {&st.epsind, "EPSIND"}})
      if (*eps < kMinTolerance) {
        res.warnings.push_back(std::string(name) + " " + num(*eps) +
                               " is below the attainable accuracy in double precision: " + num(kMinTolerance) +
                               " (100 machine epsilons) is used");
        *eps = kMinTolerance;
      }
  }
  const int nt = n_out + 1;
  {
    const double nx = sys_->nx, ne = sys_->ne, nz = nd0 + static_cast<double>(sys_->e_line.size());
    double per_time = 8.0 * (1.0 + 4.0 * nx + 4.0 * ne);
    if (linear) per_time += 8.0 * (6.0 * nz * nz + nz + (nx + ne) * nz);
    require_memory(per_time * nt,
                   "the results of " + std::to_string(nt) + " output times (" + std::to_string(sys_->nx) +
                       " coordinates, " + std::to_string(sys_->ne) + " deformations" +
                       (linear ? ", linearized equations" : "") + ")",
                   "use fewer output intervals (TIMESTEP n) or split the period into blocks");
  }
  res.t.resize(nt);
  for (RowMatrix* m : {&res.x, &res.xd, &res.xdd, &res.reaction}) m->resize(nt, sys_->nx);
  res.reaction.setZero();
  for (RowMatrix* m : {&res.e, &res.ed, &res.edd, &res.sigma}) m->resize(nt, sys_->ne);
  std::vector<double> times(nt);
  for (int k = 0; k < nt; ++k) times[k] = n_out ? t0 + st.timestep_tp * k / n_out : t0;
  times.back() = t_end;  // exactly the end of the block, whatever the rounding

  int k_out = 0;
  auto finish = [&]() {
    res.newton_iterations = data_.total_newton_iterations;
    res.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  try {
    assemble();
    const int nd = sys_->n_dof();
    auto output = [&](double t, const Eigen::VectorXd& Y) {
      check_time(t);
      evaluate(t, Y.data(), Y.data() + nd);
      if (st.forcemode >= 1 || linear) forces();
      require_finite_state(t);
      if (linear) res.linearizations.push_back(linearize());
      record(res, k_out);
      if (options.on_output) options.on_output(k_out, data_);
      ++k_out;
    };
    Eigen::VectorXd Y(2 * nd);
    Y << sys_->q0, sys_->qd0;
    if (!integrate) {
      // Kinematic analysis (or a single analysis at the current time).
      for (double t : times) output(t, Y);
    } else {
      double t = t0, h = options.initial_step;
      kinematic_failure_.clear();
      for (;;) {
        // One segment: integrate until the end, or until a free rotation must be repartitioned.
        // The step limit holds for the block, whatever the number of segments.
        if (res.steps >= options.max_steps)
          throw IntegrationError("Integrator: more than " + std::to_string(options.max_steps) +
                                 " steps in the block at t = " + num(t));
        Integrator integ(static_cast<int>(Y.size()), options.method);
        const int n = sys_->n_dof();
        Eigen::VectorXd rtol(2 * n);
        rtol.head(n).setConstant(st.epsint);
        rtol.tail(n).setConstant(st.epsind);
        integ.set_tolerances(rtol, 1e-3 * rtol);  // formulation.md §8.1: sc = EPS (10⁻³ + |y|)
        integ.set_max_step(st.hmax);
        integ.set_max_steps(options.max_steps - res.steps);
        if (h > 0.0) integ.set_initial_step(h);
        if (!sys_->free_rotations.empty())
          integ.set_stop_condition([this](double, const Eigen::VectorXd& y) { return rotation_to_repartition(y) >= 0; });
        const std::vector<double> remaining(times.begin() + k_out, times.end());
        auto f = [this](double tt, const Eigen::VectorXd& y, Eigen::VectorXd& dy) { rhs(tt, y, dy); };
        auto add_stats = [&]() {
          const IntegratorStats& s = integ.stats();
          res.rhs_evaluations += s.nfev;
          res.steps += s.nsteps;
          res.accepted += s.naccept;
          res.rejected += s.nreject;
        };
        double t_reached = t;
        try {
          t_reached = integ.integrate(f, t, t_end, Y, remaining, output);
        } catch (const IntegrationError& err) {
          add_stats();
          // The step collapsed because the kinematics has no solution (the last right-hand side
          // failed in the Newton iteration): that is a KinematicsError (formulation.md §2.2).
          if (kinematic_failure_.empty()) throw;
          std::string integrator = err.what();
          const size_t cut = integrator.find(" (last rejection");
          if (cut != std::string::npos) integrator.resize(cut);
          throw KinematicsError(kinematic_failure_ + "\nNo kinematic solution down to the minimum step (" +
                                integrator + ").");
        } catch (...) {
          add_stats();
          throw;
        }
        add_stats();
        h = res.last_step = integ.last_step();
        if (t_reached >= t_end) break;
        t = t_reached;
        repartition(rotation_to_repartition(Y), t, Y);
      }
    }
  } catch (...) {
    cut_rows(res, k_out);
    finish();
    has_deadline_ = false;
    throw;
  }
  has_deadline_ = false;
  finish();
  store_state();
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
  const int nd = sys_->n_dof();
  evaluate(t, Y.data(), Y.data() + nd);
  const FreeRotation fr = sys_->free_rotations[which];
  int best = 0;
  for (int i = 1; i < 4; ++i)
    if (std::abs(data_.x[fr.coord + i]) > std::abs(data_.x[fr.coord + best])) best = i;
  dependent_[fr.node] = best;
  linearizer_.reset();
  const Eigen::VectorXd x = data_.x, xd = data_.xd, e = data_.e, ed = data_.ed, angles = data_.angle_ref;
  const long newton = data_.total_newton_iterations;
  sys_ = compile(model_, dependent_);
  data_ = Data(*sys_);
  data_.x = x;
  data_.angle_ref = angles;
  data_.total_newton_iterations = newton;
  x_base_ = x;
  have_base_ = false;
  const System& sys = *sys_;
  const int n = sys.n_dof();
  Y.resize(2 * n);
  int j = 0;
  for (int c : sys.x_dyn) {
    Y[j] = x[c];
    Y[n + j++] = xd[c];
  }
  for (int k : sys.e_dyn) {
    Y[j] = e[k];
    Y[n + j++] = ed[k];
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
      if (c == DefClass::Input || c == DefClass::Dynamic || c == DefClass::Kinematic) el.e_given[i] = true;
    }
  model_.time = data_.t;
}

}  // namespace spacar

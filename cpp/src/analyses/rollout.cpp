// Simulation's rollouts (simulate.hpp, spacar.Rollout): many initial states integrated over the
// same output times with one assembly and one choice of path, so that a short run costs its
// integration and not the set-up of a block (the assembly, the recognition of a tree, the
// output times' complete states).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "spacar/analyses/simulate.hpp"
#include "spacar/errors.hpp"
#include "spacar/limits.hpp"

namespace spacar {

Simulation::BlockPlan Simulation::plan_rollout(const RowMatrix& q0, const RowMatrix& qd0,
                                               const std::vector<double>& times, const RunOptions& options,
                                               std::vector<std::string>& warnings) const {
  const System& sys = *sys_;
  const int nd = sys.n_dof();
  if (nd == 0) throw InputError("rollout: the model has no degrees of freedom to integrate");
  if (q0.cols() != nd || qd0.cols() != nd || qd0.rows() != q0.rows())
    throw InputError("rollout: q0 and qd0 must have the same number of states (rows) and one column per degree of "
                     "freedom (" + std::to_string(nd) + ")");
  if (times.empty()) throw InputError("rollout: no output times (the first is the start of every state's run)");
  double interval = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < times.size(); ++k) {
    if (!std::isfinite(times[k])) throw InputError("rollout: output time " + std::to_string(k) + " is not finite");
    if (k && !(times[k] > times[k - 1]))
      throw InputError("rollout: the output times must increase (time " + std::to_string(k) + " = " +
                       format_number(times[k], 12) + " follows " + format_number(times[k - 1], 12) + ")");
    if (k) interval = std::min(interval, times[k] - times[k - 1]);
  }
  check_options(options);
  if (options.energy || options.sample_period > 0.0 || options.on_sample || options.on_output)
    throw InputError("rollout: no energy balance, controller or output callback (spacar.simulate has them)");
  BlockPlan plan;
  plan.st = sys.settings;
  plan.t0 = times.front();
  plan.t_end = times.back();
  plan.times = times;
  plan.integrate = times.size() > 1;
  if (plan.integrate) plan_integration(options, plan, times.back() - times.front(), interval, kRolloutNames, warnings);
  return plan;
}

void Simulation::rollout(const RowMatrix& q0, const RowMatrix& qd0, const std::vector<double>& times,
                         const RunOptions& options, bool coordinates, RolloutResults& res) {
  const auto start = std::chrono::steady_clock::now();
  res = RolloutResults();
  const BlockPlan plan = plan_rollout(q0, qd0, times, options, res.warnings);
  // sys_ and data_ are recompiled where a state's run exchanges a dependent Euler parameter: no
  // references to them are held across a state.
  const int nd = sys_->n_dof(), ny = static_cast<int>(sys_->y_defs.size()), nt = static_cast<int>(times.size());
  const Eigen::Index states = q0.rows();
  require_memory(8.0 * double(states) * nt * (2.0 * nd + (coordinates ? sys_->nx : 0)),
                 "the rollout's " + std::to_string(states) + " states at " + std::to_string(nt) + " output times",
                 "roll out fewer states at a time");
  res.q.resize(states * nt, nd);
  res.qd.resize(states * nt, nd);
  if (coordinates) res.x.resize(states * nt, sys_->nx);
  run_.n_energy = 0;
  run_.held.resize(0);
  run_.predictor_order = options.predictor_order;
  run_.chord = options.chord;
  run_.fixed_step = plan.fixed_step;
  const DeadlineScope deadline(options.time_limit, options.time_spent);
  // The path of the rollouts to come, whatever this one's times: the tree knows no time loads.
  const bool recursive = options.recursive && timed_.empty();
  if (!rollout_.ready || rollout_.recursive != options.recursive) {
    assemble();
    rollout_.path = RhsPath::choose(*sys_, *data_, recursive);
    rollout_.assembled = run_.base;
    // Every state starts from the assembly's data, its factorizations included (Newton's chord
    // iterations reuse them): a state's run does not depend on the states rolled out before it.
    rollout_.data = std::make_unique<Data>(*data_);
    rollout_.dependent = dependent_;
    rollout_.x_dyn = sys_->x_dyn;
    rollout_.sign_of.assign(sys_->x_dyn.size(), -1);
    for (const FreeRotation& fr : sys_->free_rotations)
      for (size_t j = 0; j < sys_->x_dyn.size(); ++j)
        if (sys_->x_dyn[j] >= fr.coord && sys_->x_dyn[j] < fr.coord + 4) rollout_.sign_of[j] = fr.coord + fr.dependent;
    rollout_.recursive = options.recursive;
    rollout_.ready = true;
  }
  // The prepared path runs the rollout; the simulation's own comes back at the end, as after a run.
  struct Swap {
    std::unique_ptr<RhsPath>& a;
    std::unique_ptr<RhsPath>& b;
    Swap(std::unique_ptr<RhsPath>& x, std::unique_ptr<RhsPath>& y) : a(x), b(y) { std::swap(a, b); }
    ~Swap() { std::swap(a, b); }
  } swap(path_, rollout_.path);
  res.path = path_->name();
  Eigen::VectorXd Y(2 * nd + ny);
  long repartitions = repartitions_;  // a state whose run repartitioned leaves another system
  // After the last state, or a failed one: the rollout's partition again, the run's fixed step off.
  auto finish = [&]() {
    if (repartitions_ != repartitions) restore_rollout_partition(recursive);
    run_.fixed_step = 0.0;
    res.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  for (Eigen::Index s = 0; s < states; ++s) {
    if (repartitions_ != repartitions) restore_rollout_partition(recursive);
    repartitions = repartitions_;
    const bool tree = path_->tree() != nullptr;
    run_.base = rollout_.assembled;  // Newton's start on the general path: the assembly
    run_.anchor = Solved();
    run_.kinematic_failure.clear();
    if (tree) {
      run_.base.xd = run_.base.xdd = Eigen::VectorXd::Zero(sys_->nx);
      run_.base.t = plan.t0;
    } else {
      *data_ = *rollout_.data;
    }
    Y << q0.row(s).transpose(), sys_->y0, qd0.row(s).transpose();
    int k = 0;
    auto output = [&](double t, const Eigen::VectorXd& y) {
      check_time(t);
      const Eigen::Index row = s * nt + k;
      res.q.row(row) = y.head(nd).transpose();
      res.qd.row(row) = y.segment(nd + ny, nd).transpose();
      // The coordinates of every node, when asked for or when the state's DOFs are no longer
      // those it started with (another dependent Euler parameter): the tree's explicit
      // positions, else the general path's solved state.
      const bool repartitioned = repartitions_ != repartitions;
      if (coordinates || repartitioned) {
        const Eigen::VectorXd* x = &data_->x;
        const Eigen::VectorXd* xd = &data_->xd;
        if (path_->tree() && tree_state(t, y, run_.tree_qdd)) {
          x = &run_.base.x;
          xd = &run_.base.xd;
        } else {
          evaluate_state(t, y);
        }
        if (coordinates) res.x.row(row) = x->transpose();
        for (size_t j = 0; j < rollout_.x_dyn.size() && repartitioned; ++j) {
          const int dep = rollout_.sign_of[j];
          const double sign = dep >= 0 && (*x)[dep] < 0.0 ? -1.0 : 1.0;
          res.q(row, static_cast<Eigen::Index>(j)) = sign * (*x)[rollout_.x_dyn[j]];
          res.qd(row, static_cast<Eigen::Index>(j)) = sign * (*xd)[rollout_.x_dyn[j]];
        }
      }
      if (!res.q.row(row).allFinite() || !res.qd.row(row).allFinite())
        throw Error("rollout: state " + std::to_string(s) + " is not finite at t = " + format_number(t, 12) +
                    ": the model's values exceed double precision (check the magnitudes of loads, masses, "
                    "stiffnesses and rates)");
      ++k;
    };
    BlockResults counters;
    try {
      if (plan.integrate) integrate_segments(counters, options, plan, Y, k, output);
      else output(plan.t0, Y);
    } catch (...) {
      res.failed = static_cast<long>(s);
      for (RowMatrix* m : {&res.q, &res.qd, &res.x})
        if (m->size()) m->conservativeResize(s * nt, m->cols());
      finish();
      throw;
    }
    res.rhs_evaluations.push_back(counters.rhs_evaluations);
    res.steps.push_back(counters.steps);
    res.rejected.push_back(counters.rejected);
  }
  finish();
}

void Simulation::restore_rollout_partition(bool recursive) {
  dependent_ = rollout_.dependent;
  recompile();
  *data_ = *rollout_.data;
  // The tree of this partition, recognized again at the assembled state (repartition() left
  // the other partition's).
  path_ = RhsPath::choose(*sys_, *data_, recursive);
}

}  // namespace spacar

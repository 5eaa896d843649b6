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
  if (!sys.free_rotations.empty())
    throw InputError("rollout: not yet for a free rotation (a floating base's Euler parameters: a run changes which one "
                     "is dependent, and with it the meaning of q); spacar.simulate runs such a model");
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
  if (plan.integrate) plan_integration(options, plan, interval, kRolloutNames, warnings);
  return plan;
}

void Simulation::rollout(const RowMatrix& q0, const RowMatrix& qd0, const std::vector<double>& times,
                         const RunOptions& options, bool coordinates, RolloutResults& res) {
  const auto start = std::chrono::steady_clock::now();
  res = RolloutResults();
  const BlockPlan plan = plan_rollout(q0, qd0, times, options, res.warnings);
  const System& sys = *sys_;
  const int nd = sys.n_dof(), ny = static_cast<int>(sys.y_defs.size()), nt = static_cast<int>(times.size());
  const Eigen::Index states = q0.rows();
  require_memory(8.0 * double(states) * nt * (2.0 * nd + (coordinates ? sys.nx : 0)),
                 "the rollout's " + std::to_string(states) + " states at " + std::to_string(nt) + " output times",
                 "roll out fewer states at a time");
  res.q.resize(states * nt, nd);
  res.qd.resize(states * nt, nd);
  if (coordinates) res.x.resize(states * nt, sys.nx);
  run_.n_energy = 0;
  run_.held.resize(0);
  run_.predictor_order = options.predictor_order;
  run_.chord = options.chord;
  run_.fixed_step = plan.fixed_step;
  const DeadlineScope deadline(options.time_limit, options.time_spent);
  if (!rollout_.ready || rollout_.recursive != options.recursive) {
    assemble();
    // The recursive and explicit-chain paths know no time-dependent loads.
    rollout_.path = RhsPath::choose(sys, *data_, plan.integrate && options.recursive && timed_.empty());
    rollout_.assembled = run_.base;
    // Every state starts from the assembly's data, its factorizations included (Newton's chord
    // iterations reuse them): a state's run does not depend on the states rolled out before it.
    rollout_.data = rollout_.path->tree() ? nullptr : std::make_unique<Data>(*data_);
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
  const bool tree = path_->tree() != nullptr;
  Eigen::VectorXd Y(2 * nd + ny);
  for (Eigen::Index s = 0; s < states; ++s) {
    run_.base = rollout_.assembled;  // Newton's start on the general path: the assembly
    if (rollout_.data) *data_ = *rollout_.data;
    run_.anchor = Solved();
    run_.kinematic_failure.clear();
    if (tree) {
      run_.base.xd = run_.base.xdd = Eigen::VectorXd::Zero(sys.nx);
      run_.base.t = plan.t0;
    }
    Y << q0.row(s).transpose(), sys.y0, qd0.row(s).transpose();
    int k = 0;
    auto output = [&](double t, const Eigen::VectorXd& y) {
      check_time(t);
      const Eigen::Index row = s * nt + k;
      res.q.row(row) = y.head(nd).transpose();
      res.qd.row(row) = y.segment(nd + ny, nd).transpose();
      if (coordinates) {  // the tree's explicit positions, else the general path's solved state
        if (tree && tree_state(t, y, run_.tree_qdd)) res.x.row(row) = run_.base.x.transpose();
        else {
          evaluate_state(t, y);
          res.x.row(row) = data_->x.transpose();
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
      res.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      run_.fixed_step = 0.0;
      throw;
    }
    res.rhs_evaluations.push_back(counters.rhs_evaluations);
    res.steps.push_back(counters.steps);
    res.rejected.push_back(counters.rejected);
  }
  run_.fixed_step = 0.0;
  res.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace spacar

// The base of the time integrators and the method table (stepper.hpp).
#include "spacar/integrators/stepper.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "spacar/errors.hpp"
#include "spacar/integrators/generalized_alpha.hpp"
#include "spacar/integrators/integrator.hpp"
#include "spacar/integrators/radau5.hpp"

namespace spacar {

namespace {

// The methods: name and stepper. The order is that of the error message of parse_method.
struct MethodEntry {
  Method method;
  const char* name;
  bool implicit;  // takes a Jacobian (a run reports its Jacobians and factorizations)
  // The stepper for a segment of a run; none for AUTO, a choice between two of the others
  // (Simulation::integrate_block).
  std::unique_ptr<Stepper> (*make)(Method, const StepperSetup&);
};

const MethodEntry kMethods[] = {
    {Method::AUTO, "auto", false, nullptr},
    {Method::DOP853, "dop853", false, &Integrator::make},
    {Method::DOPRI5, "dopri5", false, &Integrator::make},
    {Method::RADAU5, "radau5", true, &Radau5::make},
    {Method::GENERALIZED_ALPHA, "generalized_alpha", true, &GeneralizedAlpha::make},
};

const MethodEntry& method_entry(Method m) {
  for (const MethodEntry& e : kMethods)
    if (e.method == m) return e;
  throw std::invalid_argument("unknown integration method");
}

}  // namespace

std::vector<std::string> method_names() {
  std::vector<std::string> names;
  for (const MethodEntry& e : kMethods) names.emplace_back(e.name);
  return names;
}

std::vector<std::string> implicit_method_names() {
  std::vector<std::string> names;
  for (const MethodEntry& e : kMethods)
    if (e.implicit) names.emplace_back(e.name);
  return names;
}

Method parse_method(const std::string& name) {
  std::string known;
  for (const MethodEntry& e : kMethods) {
    if (name == e.name) return e.method;
    known += (known.empty() ? "" : ", ") + std::string(e.name);
  }
  throw InputError("unknown integration method '" + name + "' (" + known + ")");
}

const char* method_name(Method m) { return method_entry(m).name; }

std::unique_ptr<Stepper> make_stepper(Method method, const StepperSetup& setup) {
  const MethodEntry& e = method_entry(method);
  if (!e.make) throw std::invalid_argument(std::string("method ") + e.name + " is a choice of steppers, not one");
  return e.make(method, setup);
}

std::string describe_step(double t, double h) {
  std::ostringstream s;
  s.precision(12);
  s << "t = " << t << ", step size h = " << h;
  return s.str();
}

Stepper::Stepper(const char* name, int n)
    : name_(name), n_(n), rtol_(Eigen::VectorXd::Constant(std::max(n, 0), 1e-6)),
      atol_(Eigen::VectorXd::Constant(std::max(n, 0), 1e-6)) {
  failure_.reserve(256);
}

void Stepper::set_tolerances(const Eigen::VectorXd& rtol, const Eigen::VectorXd& atol) {
  const std::string who(name_);
  if (rtol.size() != n_ || atol.size() != n_) throw std::invalid_argument(who + ": tolerances need one entry per state");
  for (int i = 0; i < n_; ++i) {
    const bool valid = std::isfinite(rtol[i]) && std::isfinite(atol[i]) && rtol[i] >= 0 && atol[i] >= 0 &&
                       rtol[i] + atol[i] > 0;
    if (!valid)
      throw std::invalid_argument(who + ": tolerances must be finite, non-negative and not both zero (state " +
                                  std::to_string(i) + ")");
  }
  rtol_ = rtol;
  atol_ = atol;
  tolerances_set();
}

void Stepper::set_max_step(double hmax) {
  if (!(hmax > 0)) throw std::invalid_argument(std::string(name_) + ": the maximum step must be positive");
  hmax_ = hmax;
}

void Stepper::set_newton_floor(double floor) {
  if (!(floor >= 0) || !std::isfinite(floor))
    throw std::invalid_argument(std::string(name_) + ": the Newton floor must be finite and >= 0");
  newton_floor_ = floor;
}

void Stepper::newton_divisors(const Eigen::VectorXd& scale, double tolerance, Eigen::VectorXd& divisors) const {
  if (newton_floor_ > 0 && tolerance > 0) divisors = scale.cwiseMax(newton_floor_ / tolerance);
  else divisors = scale;
}

void Stepper::set_max_steps(long n) {
  if (n < 1) throw std::invalid_argument(std::string(name_) + ": the step limit must be positive");
  max_steps_ = n;
}

double Stepper::min_step(double t) { return 1e-12 * std::max(1.0, std::abs(t)); }

void Stepper::set_initial_step(double h) {
  if (!(h >= 0) || !std::isfinite(h))
    throw std::invalid_argument(std::string(name_) + ": the initial step must be finite and >= 0");
  h_initial_ = h;
}

void Stepper::set_stop_condition(StopCondition stop) { stop_ = std::move(stop); }
void Stepper::set_step_start(StepStart start) { step_start_ = std::move(start); }
void Stepper::set_jacobian(Jacobian jac) { jac_ = std::move(jac); }

bool Stepper::eval(const Rhs& f, double t, const Eigen::VectorXd& y, Eigen::VectorXd& dy) {
  ++stats_.nfev;
  f(t, y, dy);
  if (dy.size() != n_)
    throw std::invalid_argument(std::string(name_) + ": the rhs returned " + std::to_string(dy.size()) +
                                " derivatives for " + std::to_string(n_) + " states");
  if (dy.allFinite()) return true;
  failure_ = "non-finite rhs value";
  return false;
}

Stepper::Contraction Stepper::newton_contraction(int it, double dn, double dn_old, double& thq_old,
                                                 double tolerance) {
  const double thq = dn / dn_old;
  theta_ = it == 2 ? thq : std::sqrt(thq * thq_old);
  thq_old = thq;
  if (!(theta_ < 0.99)) {
    failure_ = "Newton iterations diverge";
    return Contraction::Diverges;
  }
  faccon_ = theta_ / (1.0 - theta_);
  const double predicted = faccon_ * dn * std::pow(theta_, kMaxNewton - 1 - it) / tolerance;
  if (predicted >= 1.0) {
    // Not converged within the allowed iterations: a smaller step converges faster.
    slow_factor_ = 0.8 * std::pow(std::clamp(predicted, 1e-4, 20.0), -1.0 / (4.0 + kMaxNewton - 1 - it));
    failure_ = "Newton iterations converge too slowly";
    return Contraction::TooSlow;
  }
  return Contraction::Converging;
}

double Stepper::integrate(const Rhs& f, double t0, double t_end, Eigen::VectorXd& y, const std::vector<double>& touts,
                          const Output& out) {
  const std::string who(name_);
  if (y.size() != n_) throw std::invalid_argument(who + ": the state has the wrong size");
  if (!(t_end >= t0)) throw std::invalid_argument(who + ": t_end must not be before t0");
  for (size_t i = 0; i < touts.size(); ++i)
    if (!(touts[i] >= t0 && touts[i] <= t_end) || (i > 0 && touts[i] < touts[i - 1]))
      throw std::invalid_argument(who + ": output times must be sorted and within [t0, t_end]");
  if (!y.allFinite()) throw IntegrationError(who + ": non-finite initial state at " + describe_step(t0, 0.0));
  check_ready();

  failure_ = "none";
  switch_ = false;
  begin();
  Outputs outputs{touts, 0, out};
  for (; outputs.next < touts.size() && touts[outputs.next] == t0; ++outputs.next) out(t0, y);
  if (t_end == t0) return t0;

  // The right-hand side at the initial state: if it fails (non-finite values, or a StepRejected)
  // the integration cannot start.
  bool started = false;
  try {
    started = start(f, t0, y);
  } catch (const StepRejected& e) {
    failure_ = e.what();
  }
  if (!started)
    throw IntegrationError(who + ": cannot start, rhs failed at the initial state (" + failure_ + ") at " +
                           describe_step(t0, 0.0));

  double h = first_step(f, t0, t_end, y);
  double t = t0;
  bool retry = false;
  for (long steps = 0; t < t_end; ++steps) {
    if (steps >= max_steps_)
      throw IntegrationError(who + ": more than " + std::to_string(max_steps_) + " steps at " + describe_step(t, h));
    if (!(h >= min_step(t)))  // also a NaN step (from a non-finite error estimate)
      throw IntegrationError(who + ": step size underflow at " + describe_step(t, h) + " (last rejection: " +
                             failure_ + ")");
    // Stretch the step by up to 1% (within hmax) rather than leave a tiny last step before t_end.
    const bool last = t + std::min(1.01 * h, hmax_) >= t_end;
    const double h_try = last ? t_end - t : h;
    const double t_new = last ? t_end : t + h_try;
    if (!retry) {
      ++stats_.nsteps;
      if (step_start_) step_start_(t, y);
    }
    double h_next = h;
    const Outcome outcome = step(f, t, h_try, t_new, y, outputs, h_next);
    retry = outcome == Outcome::Retry;
    if (outcome == Outcome::Rejected) {
      ++stats_.nreject;
      h = h_next;
    }
    if (outcome != Outcome::Accepted) continue;
    ++stats_.naccept;
    // A last step shortened to reach t_end says little about the step the solution allows: keep
    // the planned step if larger, so that a continuation (RESTART 0) does not start too small.
    h = last ? std::max(h_next, std::min(h, hmax_)) : h_next;
    t = t_new;
    if (switch_after_step(t, t_end, h)) {
      switch_ = true;
      break;
    }
    if (stop_ && t < t_end && stop_(t, y)) break;
  }
  h_last_ = h;
  return t;
}

}  // namespace spacar

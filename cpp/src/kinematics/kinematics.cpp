#include "spacar/kinematics/kinematics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

#include "spacar/kinematics/diagnosis.hpp"
#include "spacar/errors.hpp"
#include "spacar/limits.hpp"

namespace spacar {

void set_input(const System& sys, Data& data, int i, double p, double pd, double pdd) {
  const int col = sys.input_cols[i];
  data.qhat[col] = p;
  data.qhat_d[col] = pd;
  data.qhat_dd[col] = pdd;
  if (i < static_cast<int>(sys.x_input.size())) data.x[sys.x_input[i]] = p;
}

void set_inputs(const System& sys, Data& data, double t) {
  const double tau = t - sys.t0;
  data.t = t;
  for (int i = 0; i < sys.n_input(); ++i)
    set_input(sys, data, i, sys.p0[i] + sys.pd0[i] * tau + 0.5 * sys.pdd0[i] * tau * tau,
              sys.pd0[i] + sys.pdd0[i] * tau, sys.pdd0[i]);
}

void set_dofs(const System& sys, Data& data, const double* q, const double* qd) {
  for (int j = 0; j < sys.n_dof(); ++j) {
    const int col = sys.dof_cols[j];
    data.qhat[col] = q[j];
    data.qhat_d[col] = qd[j];
  }
  for (size_t j = 0; j < sys.x_dyn.size(); ++j) data.x[sys.x_dyn[j]] = q[j];
}

void set_targets(const System& sys, Data& data) {
  for (size_t r = 0; r < sys.defs_P.size(); ++r) {
    const int k = sys.defs_P[r];
    const int col = sys.qhat_col_e[k];
    if (col >= 0) data.target[r] = data.qhat[col];
    else if (sys.def_class[k] == DefClass::Kinematic) data.target[r] = data.e_integrated[k];
    else data.target[r] = sys.e_target[k];
  }
}

namespace {

void compute_residual(const System& sys, Data& data) {
  for (size_t r = 0; r < sys.defs_P.size(); ++r) data.residual[r] = data.e[sys.defs_P[r]] - data.target[r];
}

// A number for a message: non-finite values are named as such, never printed as "nan".
std::string number(double v) { return std::isfinite(v) ? format_number(v) : "non-finite"; }

std::string worst_rows(const System& sys, const Data& data, int count) {
  std::vector<int> order(data.residual.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  // Non-finite residuals first (as the largest); NaN must not reach the comparison itself.
  auto size = [&](int r) {
    const double v = std::abs(data.residual[r]);
    return std::isfinite(v) ? v : std::numeric_limits<double>::infinity();
  };
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return size(a) > size(b); });
  std::ostringstream os;
  for (int i = 0; i < count && i < static_cast<int>(order.size()); ++i)
    os << (i ? "; " : "") << sys.def_name(sys.defs_P[order[i]]) << " residual " << number(data.residual[order[i]]);
  return os.str();
}

// Largest magnitude; +inf if any entry is not finite (maxCoeff alone may skip a NaN).
double max_abs(const Eigen::VectorXd& v) {
  if (!v.allFinite()) return std::numeric_limits<double>::infinity();
  return v.size() ? v.cwiseAbs().maxCoeff() : 0.0;
}

// Factorize a block; a (numerically) singular block raises the diagnosis.
void factorize(const System& sys, Data& data, const BlockMatrix& A, LinearSolver& lu, const char* what) {
  if (sys.x_calc.empty()) return;
  if (!lu.factorize(A.matrix())) {
    std::ostringstream os;
    os << "the " << what << " constraint block is singular at t = " << data.t << ".\n"
       << diagnose_constraints(sys, data, &A == &data.AV);
    throw KinematicsError(os.str());
  }
}

// Assemble and factorize the velocity block A_V at the current positions.
void factorize_velocity_block(const System& sys, Data& data) {
  assemble_block(sys, data, data.AV, data.AV_block);
  // Without nonholonomic rows A_V is A_P (same rows, same pattern): start from its pivots.
  if (sys.velocity_block_is_position_block) data.luV.adopt_pivots(data.luP, data.AV.matrix());
  factorize(sys, data, data.AV, data.luV, "velocity");
  // Without nonholonomic rows the velocity block is the position block: a Jacobian for the
  // next position solve.
  data.jacobian_reusable = sys.velocity_block_is_position_block;
}

}  // namespace

void assemble_block(const System& sys, Data& data, BlockMatrix& A, const std::vector<int>& block) {
  data.ensure_constraint_blocks(sys);  // (A and block are members of data: built in place)
  A.set_zero();
  for (size_t i = 0; i < sys.elements.size(); ++i) A.add(block[i], data.work[i].B);
}

namespace {
// Angles come from atan2 in (−π, π]: move each to the branch nearest to its target (position
// rows) or to its previous value, so that hinges can turn any number of times.
void unwrap_angle(const System& sys, Data& data, int k, double period) {
  const int r = sys.row_P[k];
  const double ref = r >= 0 ? data.target[r] : data.angle_ref[k];
  if (std::isfinite(ref)) data.e[k] += period * std::round((ref - data.e[k]) / period);
  data.angle_ref[k] = data.e[k];
}
}  // namespace

void evaluate_elements(const System& sys, Data& data) {
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    ElementWork& w = data.work[i];
    for (size_t j = 0; j < se.coords.size(); ++j) w.x[j] = data.x[se.coords[j]];
    se.kernel->first_derivatives(w.x.data(), data.e.data() + se.def_offset, w.B.data());
  }
  // Velocity-level deformations have no value as a function of x: theirs is integrated
  // (data.e_integrated).
  for (int k = 0; k < sys.ne; ++k)
    if (sys.def_velocity_level[k]) data.e[k] = data.e_integrated[k];
  for (const auto& [k, period] : sys.periodic_defs) unwrap_angle(sys, data, k, period);
}

void evaluate_element(const System& sys, Data& data, int i) {
  const SystemElement& se = sys.elements[i];
  ElementWork& w = data.work[i];
  for (size_t j = 0; j < se.coords.size(); ++j) w.x[j] = data.x[se.coords[j]];
  se.kernel->first_derivatives(w.x.data(), data.e.data() + se.def_offset, w.B.data());
  for (int a = 0; a < se.nd; ++a) {
    const int k = se.def_offset + a;
    if (sys.def_velocity_level[k]) data.e[k] = data.e_integrated[k];
    const double period = se.kernel->period(a);
    if (period > 0.0) unwrap_angle(sys, data, k, period);
  }
}

void check_constraint_counts(const System& sys, Data& data) {
  const size_t nc = sys.x_calc.size();
  if (sys.defs_P.size() != nc || sys.defs_V.size() != nc) {
    std::ostringstream os;
    os << "the kinematic constraints do not determine the calculable coordinates:\n"
       << diagnose_constraints(sys, data, sys.defs_P.size() == nc);
    throw KinematicsError(os.str());
  }
}

namespace {
// After an assembly's Newton iteration failed: whether the constraints can be met at all. The
// Levenberg–Marquardt iteration on the residuals of the position constraints finds the
// configuration closest to meeting them (least squares); where that still leaves residuals, no
// configuration meets them — the lengths (LENGTHO, the geometry of X) cannot close a loop, or a
// prescribed position is out of reach — and the message names the deformations that miss most
// there. Empty if the least-squares residual vanishes (then Newton failed for another reason: a
// poor start or a singular configuration) or the system is too large for the dense iteration.
std::string unclosable_constraints(const System& sys, Data& data, double tol) {
  constexpr int kMaxDense = 2000;  // calculable coordinates
  const int nc = static_cast<int>(sys.x_calc.size());
  if (nc == 0 || nc > kMaxDense) return "";
  const Eigen::VectorXd start = data.x;
  auto residual = [&]() {
    evaluate_elements(sys, data);
    compute_residual(sys, data);
    return data.residual.allFinite() ? data.residual.squaredNorm() : std::numeric_limits<double>::infinity();
  };
  double cost = residual(), mu = 1e-3;
  for (int it = 0; it < 200 && std::isfinite(cost); ++it) {
    check_thread_deadline("(in the assembly's diagnosis)");
    assemble_block(sys, data, data.AP, data.AP_block);
    const Eigen::MatrixXd J = data.AP.matrix();
    const Eigen::VectorXd r = data.residual, g = J.transpose() * r;
    const Eigen::MatrixXd H = J.transpose() * J;
    if (g.norm() <= 1e-12 * std::max(1.0, H.diagonal().maxCoeff()) * std::max(1.0, std::sqrt(cost))) break;
    bool improved = false;
    for (int tries = 0; tries < 30 && !improved; ++tries) {
      Eigen::MatrixXd A = H;
      A.diagonal() += mu * (H.diagonal().array() + 1e-12).matrix();
      const Eigen::VectorXd dx = A.ldlt().solve(g);
      for (int j = 0; j < nc; ++j) data.x[sys.x_calc[j]] -= dx[j];
      const double trial = residual();
      if (trial < cost) {
        improved = true;
        cost = trial;
        mu = std::max(mu / 3.0, 1e-12);
      } else {
        for (int j = 0; j < nc; ++j) data.x[sys.x_calc[j]] += dx[j];
        mu *= 4.0;
      }
    }
    if (!improved) break;
  }
  residual();
  const double worst = max_abs(data.residual);
  const double allowed = std::max(1e3 * tol, 1e-6 * std::max(1.0, sys.length_scale));
  std::string message;
  if (std::isfinite(worst) && worst > allowed) {
    std::ostringstream os;
    // A local minimum of the residuals (or a slow one near a singular assembly) looks the same:
    // the message says what was found, not that no assembly exists anywhere.
    os << "the assembly found no configuration that meets the constraints at t = " << data.t
       << ": the closest one (least squares, from the given positions) leaves the largest residuals "
       << worst_rows(sys, data, 3)
       << ". The lengths and geometry of these elements cannot close their loop (check their LENGTHO and LGEOMY, the "
          "positions given by X and the inputs' values), or the given positions are far from an assembly";
    message = os.str();
  }
  data.x = start;
  evaluate_elements(sys, data);
  compute_residual(sys, data);
  return message;
}
}  // namespace

void solve_positions(const System& sys, Data& data, int max_iter, double tol, bool assembly, bool exact_start) {
  const int nc = static_cast<int>(sys.x_calc.size());
  set_targets(sys, data);
  evaluate_elements(sys, data);
  compute_residual(sys, data);
  const int limit = assembly ? std::max(max_iter, 50) : max_iter;
  // Largest residual per iteration, for the message of a failure (no formatting in the loop).
  std::array<double, 64> history;
  int n_history = 0;
  auto note = [&](double r) {
    if (n_history < static_cast<int>(history.size())) history[n_history++] = r;
  };
  data.newton_iterations = 0;
  // Large systems reuse the factorization of the velocity block of the last solved state, the
  // same matrix at nearby positions: the iteration converges linearly but saves factorizations;
  // the iterates then go to 1e-3 EPSKIN (a polish of the same effect as the quadratic step) and
  // a fresh factorization is made as soon as the contraction is poor or slow. Small systems use
  // full Newton with one polish step after convergence: near a singular configuration it fails
  // with the residual that names the constraints. (benchmarks/newton.py: with a fresh
  // factorization in every iteration the runs of large systems take 1.01–1.12× the time.)
  constexpr int kChordMinimum = 31;  // calculable coordinates
  constexpr double kRoundOff = 1e-14;  // residuals of unit-size coordinates below it are noise
  const bool chord = !assembly && data.jacobian_reusable && nc >= kChordMinimum;
  LinearSolver* J = chord ? &data.luV : nullptr;
  // The chord's polish goes to 1e-3 EPSKIN, but not below round-off.
  const double polished = std::max(1e-3 * tol, kRoundOff * std::max(1.0, sys.length_scale));
  bool converged = false;
  double previous = std::numeric_limits<double>::infinity();
  for (int it = 0; it <= limit && nc > 0; ++it) {
    const double rmax = max_abs(data.residual);
    if (!std::isfinite(rmax)) {
      converged = false;
      note(rmax);
      break;
    }
    if (converged && (!chord || rmax <= polished)) break;
    if (exact_start && it == 0 && rmax <= tol) {  // exact up to round-off, not a prediction
      converged = true;
      break;
    }
    converged = converged || rmax <= tol;
    if (it == limit && !converged) break;
    note(rmax);
    // A fresh factorization when the chord contracts poorly, or so slowly that it would take
    // more than three more iterations to its target.
    const double rate = rmax / previous, target = converged ? polished : tol;
    if (!chord || rate > 0.25 || rmax * rate * rate * rate > target) {
      assemble_block(sys, data, data.AP, data.AP_block);
      factorize(sys, data, data.AP, data.luP, "position");
      J = &data.luP;
    }
    previous = rmax;
    J->solve(data.residual, data.sol_V);
    data.step.head(nc) = data.sol_V;
    double lambda = 1.0;
    const double norm0 = data.residual.norm();
    for (int back = 0;; ++back) {
      for (int j = 0; j < nc; ++j) data.x[sys.x_calc[j]] -= lambda * data.step[j];
      evaluate_elements(sys, data);
      compute_residual(sys, data);
      const double norm1 = data.residual.norm();
      // Backtracking only while assembling: in a time step a poor iterate means a too large step.
      if (!assembly || converged || (std::isfinite(norm1) && norm1 < norm0) || back >= 10) break;
      for (int j = 0; j < nc; ++j) data.x[sys.x_calc[j]] += lambda * data.step[j];
      lambda *= 0.5;
    }
    ++data.newton_iterations;
  }
  data.jacobian_reusable = false;  // the positions moved: the velocity block must be refactorized
  data.total_newton_iterations += data.newton_iterations;
  if (!converged && nc > 0) {
    std::ostringstream os;
    // An assembly that fails may be asked for the impossible: lengths that cannot close a loop.
    const std::string impossible = assembly ? unclosable_constraints(sys, data, tol) : std::string();
    if (!impossible.empty()) throw KinematicsError(impossible);
    os << "Newton iteration on the positions did not converge in " << limit << " iterations at t = " << data.t
       << " (EPSKIN " << tol << "); max residual per iteration:";
    for (int i = 0; i < n_history; ++i) os << (i ? ", " : " ") << number(history[i]);
    os << ".\nLargest residuals: "
       << worst_rows(sys, data, 3);
    throw KinematicsError(os.str());
  }
  check_auto_released(sys, data, tol);
}

double simulation_kinematic_tolerance(const System& sys) {
  const Settings& st = sys.settings;
  const double roundoff = 1e-13 * std::max(1.0, sys.length_scale);
  return std::min(st.epskin, std::max(1e-4 * std::min(st.epsint, st.epsind), roundoff));
}

void check_auto_released(const System& sys, const Data& data, double tol) {
  // Deformations without calculable coordinates are not in the block: check them directly.
  for (int k : sys.auto_released) {
    const double r = data.e[k] - sys.e_target[k];
    if (std::abs(r) > std::max(tol, 1e-9 * (1.0 + std::abs(sys.e_target[k])))) {
      std::ostringstream os;
      os << sys.def_name(k) << " is fixed but none of its coordinates can move, and its value " << data.e[k]
         << " differs from its target " << sys.e_target[k] << " at t = " << data.t;
      throw KinematicsError(os.str());
    }
  }
}

namespace {
// f(r, element, B, a) for every deformation a of an element that is the velocity row r.
template <class F>
void for_velocity_rows(const System& sys, const Data& data, F&& f) {
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    const Eigen::MatrixXd& B = data.work[i].B;
    for (int a = 0; a < se.nd; ++a) {
      const int r = sys.row_V[se.def_offset + a];
      if (r >= 0) f(r, se, B, a);
    }
  }
}
}  // namespace

void solve_transfer(const System& sys, Data& data) {
  data.ensure_dense(sys);
  const int nc = static_cast<int>(sys.x_calc.size());
  // Right-hand sides: −∂D^V/∂x̄ for the independent coordinates, unit rates of e^p and e^d.
  data.rhs_DF.setZero();
  for_velocity_rows(sys, data, [&](int r, const SystemElement& se, const Eigen::MatrixXd& B, int a) {
    for (size_t j = 0; j < se.coords.size(); ++j) {
      const int col = sys.qhat_col_x[se.coords[j]];
      if (col >= 0) data.rhs_DF(r, col) -= B(a, j);
    }
    const int ecol = sys.qhat_col_e[se.def_offset + a];
    if (ecol >= 0) data.rhs_DF(r, ecol) += 1.0;
  });
  data.DF.setZero();
  for (int g = 0; g < sys.nx; ++g)
    if (sys.qhat_col_x[g] >= 0) data.DF(g, sys.qhat_col_x[g]) = 1.0;
  if (nc > 0) {
    factorize_velocity_block(sys, data);
    Eigen::MatrixXd sol(nc, data.rhs_DF.cols());
    data.luV.solve(data.rhs_DF, sol);
    for (int j = 0; j < nc; ++j) data.DF.row(sys.x_calc[j]) = sol.row(j);
  }
  // DFe = B DF, element by element.
  data.DFe.setZero();
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    const Eigen::MatrixXd& B = data.work[i].B;
    for (size_t j = 0; j < se.coords.size(); ++j)
      data.DFe.middleRows(se.def_offset, se.nd).noalias() += B.col(j) * data.DF.row(se.coords[j]);
  }
}

namespace {
// Convective terms c of all deformations at the current positions and velocities.
void convective_terms(const System& sys, Data& data) {
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    ElementWork& w = data.work[i];
    for (size_t j = 0; j < se.coords.size(); ++j) w.v[j] = data.xd[se.coords[j]];
    se.kernel->convective(w.x.data(), w.v.data(), w.c.data());
    data.conv.segment(se.def_offset, se.nd) = w.c;
  }
}
}  // namespace

void solve_velocities(const System& sys, Data& data) {
  data.xd.noalias() = data.DF * data.qhat_d;
  data.ed.noalias() = data.DFe * data.qhat_d;
  convective_terms(sys, data);
  // acc0: accelerations at q̂̈ = 0; calculable rows from A_V ẍ^c = −c^V.
  data.acc0.setZero();
  const int nc = static_cast<int>(sys.x_calc.size());
  if (nc > 0) {
    for (size_t r = 0; r < sys.defs_V.size(); ++r) data.rhs_V[r] = -data.conv[sys.defs_V[r]];
    data.luV.solve(data.rhs_V, data.sol_V);
    for (int j = 0; j < nc; ++j) data.acc0[sys.x_calc[j]] = data.sol_V[j];
  }
}

void deformation_accelerations(const System& sys, Data& data) {
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    ElementWork& w = data.work[i];
    for (size_t j = 0; j < se.coords.size(); ++j) w.a[j] = data.xdd[se.coords[j]];
    // In two statements: B ẍ + c in one would evaluate the product into a heap temporary.
    auto edd = data.edd.segment(se.def_offset, se.nd);
    edd = w.c;
    edd.noalias() += w.B * w.a;
  }
}

namespace {

// Rates y of all coordinates from the rates of q̂ (inputs and DOF coordinates; fixed ones rest)
// with the factorized velocity block: A_V y^c = ė^V − s^V − B_{V,x̄} y_x̄, ė^V the q̂ rates of
// the rows (0 for the rest); s = 0 for velocities, the convective terms c for accelerations.
void calculable_rates(const System& sys, Data& data, const Eigen::VectorXd& qhat_rate, bool convective,
                      Eigen::VectorXd& y) {
  y.setZero();
  for (int g : sys.x_input) y[g] = qhat_rate[sys.qhat_col_x[g]];
  for (int g : sys.x_dyn) y[g] = qhat_rate[sys.qhat_col_x[g]];
  const int nc = static_cast<int>(sys.x_calc.size());
  if (nc == 0) return;
  for (size_t r = 0; r < sys.defs_V.size(); ++r) {
    const int k = sys.defs_V[r];
    const int col = sys.qhat_col_e[k];
    data.rhs_V[r] = (col >= 0 ? qhat_rate[col] : 0.0) - (convective ? data.conv[k] : 0.0);
  }
  for_velocity_rows(sys, data, [&](int r, const SystemElement& se, const Eigen::MatrixXd& B, int a) {
    for (size_t j = 0; j < se.coords.size(); ++j) data.rhs_V[r] -= B(a, j) * y[se.coords[j]];
  });
  data.luV.solve(data.rhs_V, data.sol_V);
  for (int j = 0; j < nc; ++j) y[sys.x_calc[j]] = data.sol_V[j];
}
}  // namespace

void solve_velocities_direct(const System& sys, Data& data) {
  if (!sys.x_calc.empty()) factorize_velocity_block(sys, data);
  calculable_rates(sys, data, data.qhat_d, false, data.xd);
  deformation_rates(sys, data);
}

void rest_velocities(const System& sys, Data& data, bool factorize) {
  if (factorize && !sys.x_calc.empty()) factorize_velocity_block(sys, data);
  data.xd.setZero();
  data.ed.setZero();
  data.conv.setZero();
  for (ElementWork& w : data.work) {
    w.v.setZero();
    w.c.setZero();
  }
}

void deformation_rates(const System& sys, Data& data) {
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    ElementWork& w = data.work[i];
    for (size_t j = 0; j < se.coords.size(); ++j) w.v[j] = data.xd[se.coords[j]];
    data.ed.segment(se.def_offset, se.nd).noalias() = w.B * w.v;
  }
  convective_terms(sys, data);
}

void solve_accelerations(const System& sys, Data& data) {
  data.xdd = data.acc0;
  data.xdd.noalias() += data.DF * data.qhat_dd;
  deformation_accelerations(sys, data);
}

void solve_accelerations_direct(const System& sys, Data& data) {
  calculable_rates(sys, data, data.qhat_dd, true, data.xdd);
  deformation_accelerations(sys, data);
}

void transfer_times(const System& sys, Data& data, const Eigen::VectorXd& v, Eigen::VectorXd& dx) {
  dx.resize(sys.nx);
  calculable_rates(sys, data, v, false, dx);
}

void transfer_transposed(const System& sys, Data& data, const Eigen::VectorXd& w, Eigen::VectorXd& out) {
  // DF = [unit rows of the coordinates in q̂; A_V⁻¹ rhs_DF on the calculable ones], so
  // DFᵀ w = (unit part)ᵀ w + rhs_DFᵀ μ with A_Vᵀ μ = w^c: one transposed solve.
  out = Eigen::VectorXd::Zero(sys.n_qhat());
  for (int g = 0; g < sys.nx; ++g)
    if (sys.qhat_col_x[g] >= 0) out[sys.qhat_col_x[g]] += w[g];
  const int nc = static_cast<int>(sys.x_calc.size());
  if (nc == 0) return;
  for (int j = 0; j < nc; ++j) data.rhs_V[j] = w[sys.x_calc[j]];
  data.luV.solve_transposed(data.rhs_V, data.sol_V);
  for (size_t i = 0; i < sys.elements.size(); ++i) {  // rhs_DFᵀ μ, as solve_transfer builds rhs_DF
    const SystemElement& se = sys.elements[i];
    const Eigen::MatrixXd& B = data.work[i].B;
    for (int a = 0; a < se.nd; ++a) {
      const int r = sys.row_V[se.def_offset + a];
      if (r < 0) continue;
      const double mu = data.sol_V[r];
      for (size_t j = 0; j < se.coords.size(); ++j) {
        const int col = sys.qhat_col_x[se.coords[j]];
        if (col >= 0) out[col] -= B(a, j) * mu;
      }
      const int ecol = sys.qhat_col_e[se.def_offset + a];
      if (ecol >= 0) out[ecol] += mu;
    }
  }
}

}  // namespace spacar

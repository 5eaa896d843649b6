// Explicit kinematics of open chains (chain.hpp).
#include "spacar/recursive/chain.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include "spacar/errors.hpp"
#include "spacar/kinematics/kinematics.hpp"

namespace spacar {

namespace {

// The distinct coordinates of element i not yet known, in u (its storage reused: the recognition
// of a long chain asks this of every element a few times).
void unknown_coords(const System& sys, const std::vector<char>& known, int i, std::vector<int>& u) {
  u.clear();
  for (int g : sys.elements[i].coords)
    if (!known[g] && std::find(u.begin(), u.end(), g) == u.end()) u.push_back(g);
}

// LU factors of A with partial pivoting, in place (the row swaps in piv), U's diagonal stored as
// its reciprocals (the solves, run for every block at every right-hand side, then multiply: a
// division's latency was a tenth of the adjoint sweep): the blocks have a few unknowns (3 for a
// planar beam, 7 for a spatial one), where a general LU's blocking and dispatch cost more than
// the arithmetic. False if A is singular (a zero or subnormal pivot).
bool small_factor(Eigen::MatrixXd& A, std::vector<int>& piv) {
  const int n = static_cast<int>(A.rows());
  piv.resize(n);
  for (int c = 0; c < n; ++c) {
    int p = c;
    for (int i = c + 1; i < n; ++i)
      if (std::abs(A(i, c)) > std::abs(A(p, c))) p = i;
    if (!(A(p, c) != 0.0)) return false;
    piv[c] = p;
    if (p != c) A.row(p).swap(A.row(c));
    const double inverse = 1.0 / A(c, c);
    if (!std::isfinite(inverse)) return false;  // a subnormal pivot: singular to working precision
    for (int i = c + 1; i < n; ++i) {
      const double f = A(i, c) *= inverse;
      for (int j = c + 1; j < n; ++j) A(i, j) -= f * A(c, j);
    }
    A(c, c) = inverse;
  }
  return true;
}

// x = A⁻¹ r from the factors (P A = L U, U's diagonal inverted).
void solve_factored(const Eigen::MatrixXd& LU, const std::vector<int>& piv, const Eigen::VectorXd& r, Eigen::VectorXd& x) {
  const int n = static_cast<int>(LU.rows());
  x = r;
  for (int c = 0; c < n; ++c) std::swap(x[c], x[piv[c]]);
  for (int c = 0; c < n; ++c)
    for (int i = c + 1; i < n; ++i) x[i] -= LU(i, c) * x[c];
  for (int c = n - 1; c >= 0; --c) {
    for (int j = c + 1; j < n; ++j) x[c] -= LU(c, j) * x[j];
    x[c] *= LU(c, c);
  }
}

// x = A⁻ᵀ r from the factors: Uᵀ Lᵀ (P x) = r.
void solve_factored_transposed(const Eigen::MatrixXd& LU, const std::vector<int>& piv, const Eigen::VectorXd& r,
                            Eigen::VectorXd& x) {
  const int n = static_cast<int>(LU.rows());
  x = r;
  for (int c = 0; c < n; ++c) {
    for (int j = 0; j < c; ++j) x[c] -= LU(j, c) * x[j];
    x[c] *= LU(c, c);
  }
  for (int c = n - 1; c >= 0; --c)
    for (int i = c + 1; i < n; ++i) x[c] -= LU(i, c) * x[i];
  for (int c = n - 1; c >= 0; --c) std::swap(x[c], x[piv[c]]);
}

// x = A⁻¹ r, A overwritten by its factors; false if A is singular.
bool small_solve(Eigen::MatrixXd& A, std::vector<int>& piv, const Eigen::VectorXd& r, Eigen::VectorXd& x) {
  if (!small_factor(A, piv)) return false;
  solve_factored(A, piv, r, x);
  return x.allFinite();
}

}  // namespace

KinematicsError ExplicitChain::singular(const System& sys, const Data& data, const Block& b, const char* what) {
  std::ostringstream os;
  os << "the " << what << " constraints of " << sys.def_name(b.rows.front().def) << " and the elements it reaches "
     << "are singular at t = " << data.t << " (explicit chain)";
  return KinematicsError(os.str());
}

namespace {

int position_rows(const System& sys, int i) {
  const SystemElement& se = sys.elements[i];
  int n = 0;
  for (int a = 0; a < se.nd; ++a) n += sys.row_P[se.def_offset + a] >= 0;
  return n;
}

}  // namespace

ExplicitChain::Block ExplicitChain::make_block(const System& sys, const std::vector<int>& group,
                                              const std::vector<int>& U) {
  Block b;
  b.elements = group;
  b.coords = U;
  size_t n_rows = 0, n_terms = 0;  // reserved: a long chain makes thousands of blocks
  for (int i : group) {
    const size_t rows = position_rows(sys, i);
    n_rows += rows;
    n_terms += rows * sys.elements[i].coords.size();
  }
  b.rows.reserve(n_rows);
  b.unknown_terms.reserve(n_terms);
  b.known_terms.reserve(n_terms);
  for (size_t s = 0; s < group.size(); ++s) {
    const SystemElement& se = sys.elements[group[s]];
    for (int a = 0; a < se.nd; ++a) {
      const int k = se.def_offset + a;
      if (sys.row_P[k] < 0) continue;
      const int j = static_cast<int>(b.rows.size());
      b.rows.push_back({k, sys.row_P[k]});
      for (size_t l = 0; l < se.coords.size(); ++l) {
        const auto at = std::find(U.begin(), U.end(), se.coords[l]);
        const Block::Term term{j, static_cast<int>(s), a, static_cast<int>(l),
                               at != U.end() ? static_cast<int>(at - U.begin()) : se.coords[l]};
        (at != U.end() ? b.unknown_terms : b.known_terms).push_back(term);
      }
    }
  }
  b.closed_end = closed_end(sys, b);
  if (b.closed_end >= 0) {
    const size_t nc = sys.elements[group.front()].coords.size();
    b.guess.resize(nc);
    b.local_x.resize(nc);
    b.local_e.resize(b.rows.size());
  }
  const int n = static_cast<int>(U.size());
  b.A.setZero(n, n);
  b.r.setZero(n);
  b.dx.setZero(n);
  return b;
}

std::unique_ptr<ExplicitChain> ExplicitChain::detect(const System& sys) {
  // Nonholonomic rows (velocity rows that are not position rows) and velocity-level values among
  // the position rows have no explicit position path.
  if (sys.defs_P != sys.defs_V || sys.defs_P.size() != sys.x_calc.size() || sys.x_calc.empty()) return nullptr;
  for (int k : sys.defs_P)
    if (sys.def_velocity_level[k]) return nullptr;
  std::vector<char> known(sys.nx, 1);
  for (int g : sys.x_calc) known[g] = 0;
  auto chain = std::unique_ptr<ExplicitChain>(new ExplicitChain());
  std::vector<int> pending;
  std::vector<char> is_pending(sys.elements.size(), 0);
  for (int i = 0; i < static_cast<int>(sys.elements.size()); ++i) {
    if (position_rows(sys, i) == 0) {
      chain->rest_.push_back(i);
      continue;
    }
    pending.push_back(i);
    is_pending[i] = 1;
  }
  // The pending elements on each coordinate g: touching[touching_start[g] ...] (one array, not
  // a vector per coordinate).
  std::vector<int> touching_start(sys.nx + 1, 0), touching;
  for (int i : pending)
    for (int g : sys.elements[i].coords) ++touching_start[g + 1];
  std::partial_sum(touching_start.begin(), touching_start.end(), touching_start.begin());
  touching.resize(touching_start.back());
  {
    std::vector<int> fill(touching_start.begin(), touching_start.end() - 1);
    for (int i : pending)
      for (int g : sys.elements[i].coords) touching[fill[g]++] = i;
  }
  // Greedy: an element whose rows, with those of the pending elements whose unknowns lie within
  // its own (the L2MIN1 of a rotation it reaches), are as many as its unknowns determines them.
  // None left while elements are pending means a closed loop or a group of elements that only
  // determine their coordinates together. group_of: whether there is that group (in `group`);
  // alone: the element by itself.
  std::vector<int> U, Uj, group;
  auto group_of = [&](int i, bool alone) {
    group.assign(1, i);
    int rows = position_rows(sys, i);
    for (int g : U)
      for (int t = touching_start[g]; t < touching_start[g + 1]; ++t) {
        const int j = touching[t];
        if (alone || j == i || !is_pending[j] || std::find(group.begin(), group.end(), j) != group.end()) continue;
        unknown_coords(sys, known, j, Uj);
        const bool inside = !Uj.empty() && std::all_of(Uj.begin(), Uj.end(), [&](int c) {
          return std::find(U.begin(), U.end(), c) != U.end();
        });
        if (inside) {
          group.push_back(j);
          rows += position_rows(sys, j);
        }
      }
    return rows == static_cast<int>(U.size());
  };
  // Elements that determine their unknowns alone are taken first: small blocks, and a beam after
  // the hinge that turns its end is solved in closed form.
  // Taken elements are marked (is_pending) and dropped from the list only when they are more than
  // half of it, and the scan starts after the taken ones at its front: linear in the number of
  // elements for a chain in any order (erasing each taken element at once made it quadratic).
  chain->blocks_.reserve(pending.size());
  size_t first = 0, taken = 0;
  for (bool progress = true; progress && first < pending.size();) {
    progress = false;
    for (int pass = 0; pass < 2 && !progress; ++pass)
      for (size_t p = first; p < pending.size() && !progress; ++p) {
        const int i = pending[p];
        if (!is_pending[i]) continue;
        unknown_coords(sys, known, i, U);
        if (U.empty()) return nullptr;  // rows on known coordinates only: a loop closes here
        if (!group_of(i, pass == 0)) continue;
        for (int g : U) known[g] = 1;
        for (int j : group) is_pending[j] = 0;
        chain->blocks_.push_back(make_block(sys, group, U));
        taken += group.size();
        progress = true;
      }
    while (first < pending.size() && !is_pending[pending[first]]) ++first, --taken;
    if (2 * taken > pending.size() - first) {
      pending.erase(std::remove_if(pending.begin() + first, pending.end(), [&](int j) { return !is_pending[j]; }),
                    pending.end());
      pending.erase(pending.begin(), pending.begin() + first);
      first = taken = 0;
    }
  }
  if (first < pending.size()) return nullptr;
  chain->all_closed_ = std::all_of(chain->blocks_.begin(), chain->blocks_.end(),
                                   [](const Block& b) { return b.closed_end >= 0; });
  for (int g : sys.x_calc)
    if (!known[g]) return nullptr;
  return chain;
}

void ExplicitChain::assemble(const Data& data, Block& b) const {
  b.A.setZero();
  for (const Block::Term& t : b.unknown_terms)
    b.A(t.j, t.target) += data.work[b.elements[t.slot]].B(t.local, t.coord);
}

void ExplicitChain::add_known(const Data& data, Block& b, const Eigen::VectorXd& v, double sign) const {
  for (const Block::Term& t : b.known_terms)
    b.r[t.j] += sign * data.work[b.elements[t.slot]].B(t.local, t.coord) * v[t.target];
}

int ExplicitChain::closed_end(const System& sys, const Block& b) {
  if (b.elements.size() != 1) return -1;
  const SystemElement& se = sys.elements[b.elements.front()];
  const int n = static_cast<int>(se.coords.size()), half = n / 2;
  if (!se.kernel->has_closed_form() || static_cast<int>(b.rows.size()) != se.nd || n != 2 * half ||
      static_cast<int>(b.coords.size()) != half)
    return -1;
  auto is_end = [&](int first) {
    return std::all_of(se.coords.begin() + first, se.coords.begin() + first + half, [&](int g) {
      return std::find(b.coords.begin(), b.coords.end(), g) != b.coords.end();
    });
  };
  return is_end(half) ? 1 : is_end(0) ? 0 : -1;
}

bool ExplicitChain::solve_closed(const System& sys, Data& data, Block& b) const {
  const int i = b.elements.front();
  const SystemElement& se = sys.elements[i];
  for (size_t l = 0; l < se.coords.size(); ++l) b.local_x[l] = data.x[se.coords[l]];
  for (size_t j = 0; j < b.rows.size(); ++j) b.local_e[j] = data.target[b.rows[j].row];  // rows in local order
  if (!se.kernel->solve_end(b.closed_end, b.local_e.data(), b.guess.data(), b.local_x.data())) return false;
  for (size_t l = 0; l < se.coords.size(); ++l) data.x[se.coords[l]] = b.local_x[l];
  evaluate_element(sys, data, i);
  return true;
}

void ExplicitChain::solve_positions(const System& sys, Data& data, int max_iter, double tol,
                                    const Eigen::VectorXd* reference) {
  set_targets(sys, data);
  rates_factorized_ = false;  // the positions move, and first_step and iterate use the blocks' A
  // The closed-form blocks keep the branches of a solved state, not of the starting positions
  // extrapolated from it: an extrapolation over a long trial step of an implicit integrator may
  // fold a beam, which Newton's method would not follow, and a closed form would.
  const Eigen::VectorXd& ref = reference ? *reference : data.x;
  for (Block& b : blocks_) {
    if (b.closed_end < 0) continue;
    const std::vector<int>& coords = sys.elements[b.elements.front()].coords;
    for (size_t l = 0; l < coords.size(); ++l) b.guess[l] = ref[coords[l]];
  }
  if (!all_closed_) first_step(sys, data);
  int most = 0;
  for (Block& b : blocks_) {
    if (b.closed_end >= 0 && solve_closed(sys, data, b)) continue;
    most = std::max(most, iterate(sys, data, b, max_iter, tol));
  }
  for (int i : rest_) evaluate_element(sys, data, i);
  for (size_t r = 0; r < sys.defs_P.size(); ++r) data.residual[r] = data.e[sys.defs_P[r]] - data.target[r];
  data.newton_iterations = (all_closed_ ? 0 : 1) + most;  // the first step counts as one
  data.total_newton_iterations += data.newton_iterations;
  data.jacobian_reusable = false;  // no factorization of the velocity block made
  check_auto_released(sys, data, tol);
}

void ExplicitChain::first_step(const System& sys, Data& data) {
  // First one Newton step of all calculable coordinates from the starting positions, as the
  // general path makes it: the Jacobian of an open chain is block triangular, so the step
  // follows block by block, each block's rows taking the steps of the coordinates before it.
  // It carries the motion of the coordinates a block starts from (a translation of the whole
  // rest of the chain, far larger than its elements) to the block's own coordinates; then each
  // block's Newton iterations start close to the solution.
  for (const Block& b : blocks_)
    for (int i : b.elements) evaluate_element(sys, data, i);
  step_.setZero(sys.nx);
  for (Block& b : blocks_) {
    for (size_t j = 0; j < b.rows.size(); ++j) b.r[static_cast<int>(j)] = data.e[b.rows[j].def] - data.target[b.rows[j].row];
    add_known(data, b, step_, 1.0);
    assemble(data, b);
    if (!small_solve(b.A, b.piv, b.r, b.dx)) throw singular(sys, data, b, "position");
    for (size_t j = 0; j < b.coords.size(); ++j) step_[b.coords[j]] = -b.dx[static_cast<int>(j)];
  }
  if (!step_.allFinite()) throw singular(sys, data, blocks_.front(), "position");
  for (int g : sys.x_calc) data.x[g] += step_[g];
}

// Newton on the block's coordinates until the residual is below tol, then one polish iteration,
// as solve_positions() on all of them; none if the residual is already a thousandth of tol (the
// general path's criterion when it reuses a factorization). Returns the iterations taken.
int ExplicitChain::iterate(const System& sys, Data& data, Block& b, int max_iter, double tol) const {
  bool converged = false;
  for (int it = 0;; ++it) {
    for (int i : b.elements) evaluate_element(sys, data, i);
    double rmax = 0.0;
    for (size_t j = 0; j < b.rows.size(); ++j) {
      b.r[static_cast<int>(j)] = data.e[b.rows[j].def] - data.target[b.rows[j].row];
      rmax = std::max(rmax, std::abs(b.r[static_cast<int>(j)]));
    }
    const bool finite = b.r.allFinite();
    if (finite && (converged || rmax <= 1e-3 * tol)) return it;  // polished
    converged = finite && rmax <= tol;
    if (!finite || (it >= max_iter && !converged)) {
      std::ostringstream os;
      os << "Newton iteration on the positions of " << sys.def_name(b.rows.front().def) << " and the "
         << b.coords.size() - 1 << " other coordinates it determines (explicit chain) did not converge in "
         << max_iter << " iterations at t = " << data.t << " (EPSKIN " << tol << "; residual "
         << (finite ? rmax : INFINITY) << ")";
      throw KinematicsError(os.str());
    }
    assemble(data, b);
    if (!small_solve(b.A, b.piv, b.r, b.dx)) throw singular(sys, data, b, "position");
    for (size_t j = 0; j < b.coords.size(); ++j) data.x[b.coords[j]] -= b.dx[static_cast<int>(j)];
  }
}

void ExplicitChain::rates(const System& sys, Data& data, const Eigen::VectorXd& qhat_rate, bool convective,
                          Eigen::VectorXd& y) {
  if (!rates_factorized_) factorize_rates(sys, data);
  y.setZero(sys.nx);
  for (int g : sys.x_input) y[g] = qhat_rate[sys.qhat_col_x[g]];
  for (int g : sys.x_dyn) y[g] = qhat_rate[sys.qhat_col_x[g]];
  for (Block& b : blocks_) {
    // B_u y_u = ė − s − B_k y_k over the block's rows, ė the q̂ rate of the row (0 if fixed),
    // s the convective term for accelerations.
    for (size_t j = 0; j < b.rows.size(); ++j) {
      const int k = b.rows[j].def, col = sys.qhat_col_e[k];
      b.r[static_cast<int>(j)] = (col >= 0 ? qhat_rate[col] : 0.0) - (convective ? data.conv[k] : 0.0);
    }
    add_known(data, b, y, -1.0);
    solve_factored(b.A, b.piv, b.r, b.dx);
    if (!b.dx.allFinite()) throw singular(sys, data, b, convective ? "acceleration" : "velocity");
    for (size_t j = 0; j < b.coords.size(); ++j) y[b.coords[j]] = b.dx[static_cast<int>(j)];
  }
}

void ExplicitChain::factorize_rates(const System& sys, const Data& data) {
  rates_factorized_ = false;  // until every block is
  for (Block& b : blocks_) {
    assemble(data, b);
    if (!small_factor(b.A, b.piv)) throw singular(sys, data, b, "velocity");
  }
  rates_factorized_ = true;
}

void ExplicitChain::solve_velocities(const System& sys, Data& data) {
  factorize_rates(sys, data);  // B at the positions just solved
  rates(sys, data, data.qhat_d, false, data.xd);
  deformation_rates(sys, data);
}

void ExplicitChain::solve_accelerations(const System& sys, Data& data) {
  rates(sys, data, data.qhat_dd, true, data.xdd);
  deformation_accelerations(sys, data);
}

void ExplicitChain::transfer_transposed(const System& sys, Data& data, const Eigen::VectorXd& w, Eigen::VectorXd& out) {
  // The velocities follow block by block, B_u ẋ_u = ė − B_k ẋ_k, so DFᵀ w is the adjoint sweep
  // in reverse order: each block's multipliers μ from B_uᵀ μ = w_u (with what the later blocks
  // passed on), μ to the q̂ columns of its rows, −B_kᵀ μ passed on to its known coordinates.
  if (!rates_factorized_) factorize_rates(sys, data);
  out.setZero(sys.n_qhat());
  adjoint_ = w;
  for (auto it = blocks_.rbegin(); it != blocks_.rend(); ++it) {
    Block& b = *it;
    for (size_t j = 0; j < b.coords.size(); ++j) b.r[static_cast<int>(j)] = adjoint_[b.coords[j]];
    solve_factored_transposed(b.A, b.piv, b.r, b.dx);
    if (!b.dx.allFinite()) throw singular(sys, data, b, "velocity");
    for (const Block::Term& t : b.known_terms)
      adjoint_[t.target] -= data.work[b.elements[t.slot]].B(t.local, t.coord) * b.dx[t.j];
    for (size_t j = 0; j < b.rows.size(); ++j) {
      const int col = sys.qhat_col_e[b.rows[j].def];
      if (col >= 0) out[col] += b.dx[static_cast<int>(j)];
      data.sol_V[sys.row_V[b.rows[j].def]] = b.dx[static_cast<int>(j)];
    }
  }
  for (int g = 0; g < sys.nx; ++g)
    if (sys.qhat_col_x[g] >= 0) out[sys.qhat_col_x[g]] += adjoint_[g];
}

}  // namespace spacar

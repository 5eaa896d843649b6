#include "spacar/analyses/linearize.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <sstream>
#include <utility>

#include <Eigen/Sparse>

#include "spacar/recursive/chain.hpp"
#include "spacar/kinematics/dynamics.hpp"
#include "spacar/errors.hpp"
#include "spacar/limits.hpp"
#include "spacar/kinematics/kinematics.hpp"
#include "spacar/analyses/nodal.hpp"
#include "spacar/analyses/statics.hpp"

namespace spacar {


Linearizer::Linearizer(const Model& model, const std::map<int, int>& dependent)
    : lin_(compile(model, dependent, true)), ld_(std::make_unique<Data>(*lin_)), chain_(ExplicitChain::detect(*lin_)) {}

void Linearizer::set_z(const Eigen::VectorXd& z, const Eigen::VectorXd& zd, bool transfer) {
  const System& L = *lin_;
  const int nz = L.n_dof();
  Eigen::VectorXd q(nz), qd(nz);
  for (int i = 0; i < nz; ++i) {
    q[order_[i]] = z[i];
    qd[order_[i]] = zd[i];
  }
  for (int i = 0; i < L.n_input(); ++i) set_input(L, *ld_, i, inputs_(i, 0), inputs_(i, 1), inputs_(i, 2));
  set_dofs(L, *ld_, q.data(), qd.data());
  const double tol = std::min(L.settings.epskin, 1e-10);
  // The perturbed positions of an open chain element by element (chain.hpp; the branches of the
  // nominal state, where ld_ starts); the nominal ones on the general path, for the transfer.
  // The velocities always factorize the velocity block: the residual's projection solves with it.
  if (chain_ && !transfer)
    chain_->solve_positions(L, *ld_, std::max(L.settings.maxiterat, 50), tol);
  else
    solve_positions(L, *ld_, std::max(L.settings.maxiterat, 50), tol, false);
  if (transfer) solve_transfer(L, *ld_);
  solve_velocities_direct(L, *ld_);
}

void Linearizer::residual(const Eigen::VectorXd& zdd, Eigen::VectorXd& R) {
  const System& L = *lin_;
  const int nz = L.n_dof();
  for (int i = 0; i < nz; ++i) ld_->qhat_dd[L.dof_cols[order_[i]]] = zdd[i];
  Eigen::VectorXd RL(nz);
  reduced_residual_direct(L, *ld_, RL);
  R.resize(nz);
  for (int i = 0; i < nz; ++i) R[i] = RL[order_[i]];
}

Linearizer::ZState Linearizer::z_state(const System& sys, const Data& data, std::vector<std::array<int, 3>>& labels,
                                       int& n_line) {
  const System& L = *lin_;
  const int nz = L.n_dof();
  const int nxd_L = static_cast<int>(L.x_dyn.size());
  // z = (q of the analysed system, then the LINE parameters); order_ maps z to L's DOFs.
  std::vector<int> dof_of_coord(L.nx, -1), dof_of_def(L.ne, -1);
  for (int i = 0; i < nxd_L; ++i) dof_of_coord[L.x_dyn[i]] = i;
  for (size_t i = 0; i < L.e_dyn.size(); ++i) dof_of_def[L.e_dyn[i]] = nxd_L + static_cast<int>(i);
  order_.clear();
  labels.clear();
  ZState zs;
  zs.z.resize(nz), zs.zd.resize(nz), zs.zdd.resize(nz), zs.scale.resize(nz);  // scale: finite-difference steps
  auto add = [&](int dof, std::array<int, 3> label, double v, double vd, double vdd, bool length) {
    const size_t i = order_.size();
    zs.scale[i] = length ? L.length_scale : 1.0;
    zs.z[i] = v;
    zs.zd[i] = vd;
    zs.zdd[i] = vdd;
    order_.push_back(dof);
    labels.push_back(label);
  };
  for (int g : sys.x_dyn) {
    const int col = sys.qhat_col_x[g];
    add(dof_of_coord[g], {0, sys.coord_label[g][0], sys.coord_label[g][1]}, data.qhat[col], data.qhat_d[col],
        data.qhat_dd[col], sys.coord_is_length[g]);
  }
  for (int k : sys.e_dyn) {
    const int col = sys.qhat_col_e[k];
    add(dof_of_def[k], {1, sys.def_label[k][0], sys.def_label[k][1]}, data.qhat[col], data.qhat_d[col],
        data.qhat_dd[col], sys.def_is_length[k]);
  }
  for (int k : sys.e_line)
    add(dof_of_def[k], {1, sys.def_label[k][0], sys.def_label[k][1]}, sys.e_target[k], 0.0, 0.0, sys.def_is_length[k]);
  n_line = static_cast<int>(sys.e_line.size());
  if (static_cast<int>(order_.size()) != nz) throw Error("linearize: the coordinates of the two systems differ");
  return zs;
}

void Linearizer::set_nominal(const System& sys, const Data& data, const ZState& zs, bool transfer) {
  // The inputs and the time-dependent loads of the analysis at its state (tables, load
  // functions, a controller's held loads: formulation.md's constant block motion otherwise).
  if (lin_->n_input() != sys.n_input()) throw Error("linearize: the inputs of the two systems differ");
  inputs_.resize(sys.n_input(), 3);
  for (int i = 0; i < sys.n_input(); ++i) {
    const int col = sys.input_cols[i];
    inputs_.row(i) << data.qhat[col], data.qhat_d[col], data.qhat_dd[col];
  }
  ld_->time_load = data.time_load;
  ld_->t = data.t;
  ld_->x = data.x;
  ld_->angle_ref = data.angle_ref;
  ld_->e_integrated = data.e_integrated;
  set_z(zs.z, zs.zd, transfer);
}

bool Linearizer::compute_nodal(const System& sys, const Data& data, NodalLinearization& out) {
  const System& L = *lin_;
  reduced_.reset();
  if (!sys.e_kinematic.empty()) return false;
  out = NodalLinearization();
  out.t = data.t;
  const ZState zs = z_state(sys, data, out.z_label, out.n_line);
  if (zs.zd.any()) return false;
  for (int col : sys.input_cols)
    if (data.qhat_d[col] != 0.0 || data.qhat_dd[col] != 0.0) return false;
  set_nominal(sys, data, zs, false);
  // In static equilibrium (then q̈ = 0 and N0 = 0): the reduced residual at rest, the complete
  // stresses with it, small against the loads it balances, or Newton's correction from the state
  // (K0 + G0)⁻¹ R below 1e-8 of the DOFs' sizes (an unloaded structure, whose residual is
  // rounding).
  Eigen::VectorXd R;
  const double force = static_forces(L, *ld_, 1.0, R);
  const int nz = L.n_dof(), nq = nz - out.n_line;
  nodal_sigma_ = ld_->sigma;
  reduced_ = std::make_unique<ReducedSystem>(L, *ld_);
  bool equilibrium = true;
  for (int i = 0; i < nq; ++i) equilibrium = equilibrium && std::abs(R[order_[i]]) * zs.scale[i] <= 1e-8 * force;
  if (!equilibrium) {
    Eigen::VectorXd Rq = R, dq, dx;
    for (int i = nq; i < nz; ++i) Rq[order_[i]] = 0.0;  // the LINE parameters are held
    equilibrium = reduced_->factorize(nodal_sigma_, NodalCoefficients()) && !reduced_->saddle().singular();
    if (equilibrium) reduced_->solve(Rq, dq, dx, 0);
    for (int i = 0; i < nq && equilibrium; ++i) equilibrium = std::abs(dq[order_[i]]) <= 1e-8 * zs.scale[i];
  }
  if (!equilibrium) {
    reduced_.reset();
    return false;
  }
  out.r0.resize(nz);
  for (int i = 0; i < nz; ++i) out.r0[i] = -R[order_[i]];
  out.M = nodal_part(L, *ld_, nodal_sigma_, kMass);
  out.D = nodal_part(L, *ld_, nodal_sigma_, kDamping);
  out.K = nodal_part(L, *ld_, nodal_sigma_, kStiffness);
  out.G = nodal_part(L, *ld_, nodal_sigma_, kGeometric);
  out.A = nodal_constraints(L, *ld_, reduced_->layout());
  out.free = reduced_->layout().free;
  // E in the order of z: row i is the row of L's DOF order_[i].
  Eigen::SparseMatrix<double> P(nz, nz);
  std::vector<Eigen::Triplet<double>> unit;
  for (int i = 0; i < nz; ++i) unit.emplace_back(i, order_[i], 1.0);
  P.setFromTriplets(unit.begin(), unit.end());
  out.E = P * nodal_dof_map(L, *ld_);
  out.B = nodal_deformation_jacobian(L, *ld_);
  out.S = nodal_constitutive(L, false);
  out.Dc = nodal_constitutive(L, true);
  return true;
}

bool Linearizer::nodal_factorize(const NodalCoefficients& c) {
  if (!reduced_) throw Error("linearize: no nodal linearization to factorize (compute_nodal first)");
  return reduced_->factorize(nodal_sigma_, c);
}

const SaddlePoint& Linearizer::nodal_system() const {
  if (!reduced_) throw Error("linearize: no nodal linearization (compute_nodal first)");
  return reduced_->saddle();
}

void Linearizer::nodal_solve(const double* b, double* x) {
  if (!reduced_) throw Error("linearize: no nodal linearization to solve with (compute_nodal first)");
  const NodalLayout& layout = reduced_->layout();
  Eigen::VectorXd bx = Eigen::VectorXd::Zero(lin_->nx), q, dx;
  for (int f = 0; f < layout.n_free; ++f) bx[layout.free[f]] = b[f];
  reduced_->solve(reduced_->reduce(bx), q, dx);
  for (int f = 0; f < layout.n_free; ++f) x[f] = dx[layout.free[f]];
}

Eigen::Vector4d Linearizer::nodal_energies(const Eigen::VectorXd& v_free) {
  if (!reduced_) throw Error("linearize: no nodal linearization (compute_nodal first)");
  const NodalLayout& layout = reduced_->layout();
  if (v_free.size() != layout.n_free)
    throw InputError("nodal_energies: v needs " + std::to_string(layout.n_free) + " values, got " +
                     std::to_string(v_free.size()));
  Eigen::VectorXd v = Eigen::VectorXd::Zero(lin_->nx);
  for (int f = 0; f < layout.n_free; ++f) v[layout.free[f]] = v_free[f];
  return spacar::nodal_energies(*lin_, *ld_, nodal_sigma_, v);
}

// The nominal state and the matrices that need no differences: r0, DF in z, Zᵀ M Z and Zᵀ G Z of
// the nodal matrices (nodal.hpp), the mass at the nominal velocities; K0 and D0 from the
// deformations, DFeᵀ S DFe: the same matrices, without the cancellation of the nodal
// stiffness's large entries along a fine mesh (the static compliance of a 100-beam cantilever
// stays at 1e-12 instead of 1e-9); AK0. Returns the nominal positions (and angles' branches),
// from which the differences start.
Linearizer::Nominal Linearizer::nominal_matrices(const System& sys, const Data& data, const ZState& zs,
                                                 Linearization& lin) {
  const System& L = *lin_;
  const int nz = L.n_dof();
  set_nominal(sys, data, zs, true);
  const Nominal nominal{ld_->x, ld_->angle_ref};
  residual(zs.zdd, lin.r0);
  lin.r0 = -lin.r0;
  lin.DFz.resize(L.nx, nz);
  lin.DFez.resize(L.ne, nz);
  for (int i = 0; i < nz; ++i) {
    lin.DFz.col(i) = ld_->DF.col(L.dof_cols[order_[i]]);
    lin.DFez.col(i) = ld_->DFe.col(L.dof_cols[order_[i]]);
  }
  compute_inertia_and_loads(L, *ld_);
  // Dense products of the model's size: the deadline of a time_limit is checked between them.
  const char* where = "(in the linearization)";
  check_thread_deadline(where);
  lin.M0 = lin.DFz.transpose() * (nodal_part(L, *ld_, data.sigma, kMass) * lin.DFz);
  check_thread_deadline(where);
  lin.G0 = lin.DFz.transpose() * (nodal_part(L, *ld_, data.sigma, kGeometric) * lin.DFz);
  check_thread_deadline(where);
  lin.K0 = lin.DFez.transpose() * (nodal_constitutive(L, false) * lin.DFez);
  check_thread_deadline(where);
  lin.D0 = lin.DFez.transpose() * (nodal_constitutive(L, true) * lin.DFez);
  const int nk = static_cast<int>(sys.e_kinematic.size());
  lin.AK0.resize(nk, nz);
  for (int j = 0; j < nk; ++j) lin.AK0.row(j) = lin.DFez.row(sys.e_kinematic[j]);
  return nominal;
}

// C0, N0, Kk and BK0 by differences of the residual R and of the kinematic rates ẏ^k at
// perturbed positions (kinematics re-solved), rates and kinematic coordinates y, about the
// nominal state (positions `at`) of nominal_matrices.
void Linearizer::differenced_matrices(const System& sys, const ZState& zs, const Nominal& at, const Eigen::VectorXd& y,
                                      const Eigen::VectorXd& yscale, bool precise, Linearization& lin) {
  const System& L = *lin_;
  const int nz = L.n_dof(), nk = static_cast<int>(y.size());
  const Eigen::VectorXd &z = zs.z, &zd = zs.zd, &zdd = zs.zdd, &scale = zs.scale;
  const Eigen::VectorXd &x_nominal = at.x, &angles_nominal = at.angles;
  auto response = [&](const Eigen::VectorXd& zz, const Eigen::VectorXd& zzd, const Eigen::VectorXd& yy) {
    check_thread_deadline("(in the linearization)");  // a time_limit of linearize or state_space
    ld_->x = x_nominal;
    ld_->angle_ref = angles_nominal;
    for (int j = 0; j < nk; ++j) ld_->e_integrated[sys.e_kinematic[j]] = yy[j];
    set_z(zz, zzd, false);
    Eigen::VectorXd R;
    residual(zdd, R);
    Eigen::VectorXd out(nz + nk);
    out.head(nz) = R;
    for (int j = 0; j < nk; ++j) out[nz + j] = ld_->ed[sys.e_kinematic[j]];
    return out;
  };
  // Central differences with one Richardson extrapolation: error O(h⁴) + round-off/h, so that
  // the matrices are accurate to about 1e-11 relative (formulation.md §7.2). An integrator's
  // Newton matrix (precise = false) needs far less: one-sided differences from the nominal
  // response, error about 1e-8 relative, 2 nz + 1 responses instead of 6 nz.
  const Eigen::VectorXd nominal = precise ? Eigen::VectorXd() : response(z, zd, y);
  auto derivative = [&](auto&& f, double h) -> Eigen::VectorXd {
    if (!precise) return (f(h) - nominal) / h;
    const Eigen::VectorXd d1 = (f(h) - f(-h)) / (2.0 * h);
    const Eigen::VectorXd d2 = (f(0.5 * h) - f(-0.5 * h)) / h;
    return (4.0 * d2 - d1) / 3.0;
  };
  const double eps = std::numeric_limits<double>::epsilon();
  const double step = precise ? std::pow(eps, 0.2) : std::sqrt(eps);
  Eigen::MatrixXd dzd(nz + nk, nz), dz(nz + nk, nz), dy(nz + nk, nk);
  for (int i = 0; i < nz; ++i) {
    // R is quadratic in ż: one central difference is exact up to round-off for any step.
    const double h = (precise ? 1e-3 : step) * std::max(scale[i], std::abs(zd[i]));
    auto at = [&](double d) { Eigen::VectorXd v = zd; v[i] += d; return response(z, v, y); };
    dzd.col(i) = precise ? Eigen::VectorXd((at(h) - at(-h)) / (2.0 * h)) : derivative(at, h);
  }
  for (int i = 0; i < nz; ++i) {
    const double h = step * std::max(scale[i], std::abs(z[i]));
    dz.col(i) = derivative([&](double d) { Eigen::VectorXd v = z; v[i] += d; return response(v, zd, y); }, h);
  }
  for (int j = 0; j < nk; ++j) {
    const double h = step * std::max(yscale[j], std::abs(y[j]));
    dy.col(j) = derivative([&](double d) { Eigen::VectorXd v = y; v[j] += d; return response(z, zd, v); }, h);
  }
  response(z, zd, y);  // leave the work data at the nominal state
  lin.C0 = dzd.topRows(nz) - lin.D0;
  lin.N0 = dz.topRows(nz) - lin.K0 - lin.G0;
  lin.Kk = dy.topRows(nz);
  lin.BK0.resize(nk, nz + nk);
  lin.BK0 << dz.bottomRows(nk), dy.bottomRows(nk);
}

Linearization Linearizer::compute_at_rest(const System& sys, Data& data) {
  if (!reduced_) throw Error("linearize: no state at rest in static equilibrium was linearized (compute_nodal)");
  // The static equilibrium's stresses and q̈ = 0 (at rest: compute_nodal refused moving inputs) in
  // place of the analysis' for this computation, swapped back whatever happens (data is not
  // copied: it holds factorizations that were never computed).
  Eigen::VectorXd sigma = nodal_sigma_, qhat_dd = Eigen::VectorXd::Zero(data.qhat_dd.size());
  data.sigma.swap(sigma);
  data.qhat_dd.swap(qhat_dd);
  struct SwapBack {
    Data& d;
    Eigen::VectorXd &sigma, &qhat_dd;
    ~SwapBack() {
      d.sigma.swap(sigma);
      d.qhat_dd.swap(qhat_dd);
    }
  } swap_back{data, sigma, qhat_dd};
  return compute(sys, data, Differences::None);
}

Linearization Linearizer::compute(const System& sys, const Data& data, Differences differences) {
  const System& L = *lin_;
  const int nz = L.n_dof();
  Linearization lin;
  lin.t = data.t;
  const ZState zs = z_state(sys, data, lin.z_label, lin.n_line);
  // Kinematic coordinates of nonholonomic constraints: y^k, integrated in the motion.
  Eigen::VectorXd y(sys.e_kinematic.size()), yscale(sys.e_kinematic.size());
  for (size_t j = 0; j < sys.e_kinematic.size(); ++j) {
    const int k = sys.e_kinematic[j];
    y[j] = data.e_integrated[k];
    yscale[j] = sys.def_is_length[k] ? L.length_scale : 1.0;
    lin.y_label.push_back({1, sys.def_label[k][0], sys.def_label[k][1]});
  }
  const Nominal nominal = nominal_matrices(sys, data, zs, lin);
  check_thread_deadline("(in the linearization)");
  if (differences == Differences::None) {  // at rest in static equilibrium (compute_nodal)
    if (y.size() > 0) throw Error("linearize: a state with kinematic coordinates needs the differences");
    lin.C0 = lin.N0 = Eigen::MatrixXd::Zero(nz, nz);
    lin.Kk.resize(nz, 0);
    lin.BK0.resize(0, nz);
  } else {
    differenced_matrices(sys, zs, nominal, y, yscale, differences == Differences::Precise, lin);
  }
  // Values beyond double precision (e.g. GRAVITY 1e308) give infinities and NaNs here: refuse them
  // rather than hand non-finite matrices to the eigen-analyses.
  lin.for_each_array([&](const char* name, const auto& m) {
    if (m.allFinite()) return;  // else the first non-finite array is named
    std::ostringstream os;
    os << "the linearized equations at t = " << data.t << " are not finite (" << name
       << " has infinite or NaN entries): the model's values exceed double precision";
    throw Error(os.str());
  });
  return lin;
}

}  // namespace spacar

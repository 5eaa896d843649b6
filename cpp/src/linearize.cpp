#include "spacar/linearize.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <sstream>
#include <utility>

#include <Eigen/Sparse>

#include "spacar/chain.hpp"
#include "spacar/dynamics.hpp"
#include "spacar/errors.hpp"
#include "spacar/kinematics.hpp"

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

Linearization Linearizer::compute(const System& sys, const Data& data, bool precise) {
  const System& L = *lin_;
  const int nz = L.n_dof();
  const int nxd_L = static_cast<int>(L.x_dyn.size());
  // z = (q of the analysed system, then the LINE parameters); order_ maps z to L's DOFs.
  std::vector<int> dof_of_coord(L.nx, -1), dof_of_def(L.ne, -1);
  for (int i = 0; i < nxd_L; ++i) dof_of_coord[L.x_dyn[i]] = i;
  for (size_t i = 0; i < L.e_dyn.size(); ++i) dof_of_def[L.e_dyn[i]] = nxd_L + static_cast<int>(i);
  Linearization lin;
  lin.t = data.t;
  order_.clear();
  Eigen::VectorXd z(nz), zd(nz), zdd(nz);
  Eigen::VectorXd scale(nz);  // characteristic size of each z: finite-difference steps
  auto add = [&](int dof, std::array<int, 3> label, double v, double vd, double vdd, bool length) {
    scale[order_.size()] = length ? L.length_scale : 1.0;
    z[order_.size()] = v;
    zd[order_.size()] = vd;
    zdd[order_.size()] = vdd;
    order_.push_back(dof);
    lin.z_label.push_back(label);
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
  lin.n_line = static_cast<int>(sys.e_line.size());
  if (static_cast<int>(order_.size()) != nz) throw Error("linearize: the coordinates of the two systems differ");

  // Kinematic coordinates of nonholonomic constraints: y^k, integrated in the motion.
  Eigen::VectorXd y(sys.e_kinematic.size()), yscale(sys.e_kinematic.size());
  for (size_t j = 0; j < sys.e_kinematic.size(); ++j) {
    const int k = sys.e_kinematic[j];
    y[j] = data.e_integrated[k];
    yscale[j] = sys.def_is_length[k] ? L.length_scale : 1.0;
    lin.y_label.push_back({1, sys.def_label[k][0], sys.def_label[k][1]});
  }
  const int nk = static_cast<int>(y.size());

  // Nominal state, with the inputs and the time-dependent loads of the analysis at it (tables,
  // load functions, a controller's held loads: formulation.md's constant block motion otherwise).
  if (L.n_input() != sys.n_input()) throw Error("linearize: the inputs of the two systems differ");
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
  set_z(z, zd, true);
  const Eigen::VectorXd x_nominal = ld_->x, angles_nominal = ld_->angle_ref;
  residual(zdd, lin.r0);
  lin.r0 = -lin.r0;
  lin.DFz.resize(L.nx, nz);
  lin.DFez.resize(L.ne, nz);
  for (int i = 0; i < nz; ++i) {
    lin.DFz.col(i) = ld_->DF.col(L.dof_cols[order_[i]]);
    lin.DFez.col(i) = ld_->DFe.col(L.dof_cols[order_[i]]);
  }
  assemble_mass_matrix(L, *ld_);
  lin.M0 = congruence(lin.DFz, ld_->M);
  lin.K0 = congruence(lin.DFez, global_constitutive(L, false));
  lin.D0 = congruence(lin.DFez, global_constitutive(L, true));
  lin.G0 = congruence(lin.DFz, geometric_stiffness(L, *ld_, data.sigma));
  lin.AK0.resize(nk, nz);
  for (int j = 0; j < nk; ++j) lin.AK0.row(j) = lin.DFez.row(sys.e_kinematic[j]);

  // Residual R and kinematic rates ẏ^k at perturbed positions (kinematics re-solved) or rates.
  auto response = [&](const Eigen::VectorXd& zz, const Eigen::VectorXd& zzd, const Eigen::VectorXd& yy) {
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
  // Values beyond double precision (e.g. GRAVITY 1e308) give infinities and NaNs here: refuse them
  // rather than hand non-finite matrices to the eigen-analyses.
  auto refuse = [&](const char* name) {
    std::ostringstream os;
    os << "the linearized equations at t = " << data.t << " are not finite (" << name
       << " has infinite or NaN entries): the model's values exceed double precision";
    throw Error(os.str());
  };
  lin.for_each_array([&](const char* name, const auto& m) {
    if (!m.allFinite()) refuse(name);  // throws: the first non-finite array is named
  });
  return lin;
}

}  // namespace spacar

#include "spacar/linearize.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "spacar/dynamics.hpp"
#include "spacar/errors.hpp"
#include "spacar/kinematics.hpp"

namespace spacar {

namespace {

bool constitutive_class(DefClass c) {
  return c == DefClass::Released || c == DefClass::Dynamic || c == DefClass::Kinematic;
}

// Block-diagonal constitutive matrix (stiffness or damping) over the deformations whose
// stresses are constitutive, as in constitutive_stresses().
Eigen::MatrixXd global_constitutive(const System& sys, bool damping) {
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(sys.ne, sys.ne);
  for (const SystemElement& se : sys.elements) {
    const Eigen::MatrixXd& Se = damping ? se.D : se.S;
    for (int a = 0; a < se.nd; ++a) {
      if (!constitutive_class(sys.def_class[se.def_offset + a])) continue;
      S.block(se.def_offset + a, se.def_offset, 1, se.nd) = Se.row(a);
    }
  }
  return S;
}

}  // namespace

Linearizer::Linearizer(const Model& model, const std::map<int, int>& dependent)
    : lin_(compile(model, dependent, true)), ld_(*lin_) {}

void Linearizer::set_z(const Eigen::VectorXd& z, const Eigen::VectorXd& zd) {
  const System& L = *lin_;
  const int nz = L.n_dof();
  Eigen::VectorXd q(nz), qd(nz);
  for (int i = 0; i < nz; ++i) {
    q[order_[i]] = z[i];
    qd[order_[i]] = zd[i];
  }
  set_inputs(L, ld_, ld_.t);
  set_dofs(L, ld_, q.data(), qd.data());
  const double tol = std::min(L.settings.epskin, 1e-10);
  solve_positions(L, ld_, std::max(L.settings.maxiterat, 50), tol, false);
  solve_transfer(L, ld_);
  solve_velocities(L, ld_);
}

void Linearizer::residual(const Eigen::VectorXd& zdd, Eigen::VectorXd& R) {
  const System& L = *lin_;
  const int nz = L.n_dof();
  for (int i = 0; i < nz; ++i) ld_.qhat_dd[L.dof_cols[order_[i]]] = zdd[i];
  Eigen::VectorXd RL(nz);
  reduced_residual(L, ld_, RL);
  R.resize(nz);
  for (int i = 0; i < nz; ++i) R[i] = RL[order_[i]];
}

Linearization Linearizer::compute(const System& sys, const Data& data) {
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

  // Nominal state.
  ld_.t = data.t;
  ld_.x = data.x;
  ld_.angle_ref = data.angle_ref;
  set_z(z, zd);
  const Eigen::VectorXd x_nominal = ld_.x;
  residual(zdd, lin.r0);
  lin.r0 = -lin.r0;
  lin.DFz.resize(L.nx, nz);
  lin.DFez.resize(L.ne, nz);
  for (int i = 0; i < nz; ++i) {
    lin.DFz.col(i) = ld_.DF.col(L.dof_cols[order_[i]]);
    lin.DFez.col(i) = ld_.DFe.col(L.dof_cols[order_[i]]);
  }
  lin.M0 = lin.DFz.transpose() * ld_.M * lin.DFz;
  lin.K0 = lin.DFez.transpose() * global_constitutive(L, false) * lin.DFez;
  lin.D0 = lin.DFez.transpose() * global_constitutive(L, true) * lin.DFez;
  lin.G0 = lin.DFz.transpose() * geometric_stiffness(L, ld_, data.sigma) * lin.DFz;

  // Velocity sensitivity: R is quadratic in ż, so central differences are exact to round-off.
  Eigen::MatrixXd dRdzd(nz, nz), dRdz(nz, nz);
  Eigen::VectorXd Rp, Rm;
  for (int i = 0; i < nz; ++i) {
    const double h = 1e-3 * std::max(scale[i], std::abs(zd[i]));
    const int col = L.dof_cols[order_[i]];
    ld_.qhat_d[col] = zd[i] + h;
    solve_velocities(L, ld_);
    residual(zdd, Rp);
    ld_.qhat_d[col] = zd[i] - h;
    solve_velocities(L, ld_);
    residual(zdd, Rm);
    ld_.qhat_d[col] = zd[i];
    dRdzd.col(i) = (Rp - Rm) / (2.0 * h);
  }
  // Position sensitivity, with the kinematics re-solved at every perturbation.
  const double eps3 = std::cbrt(std::numeric_limits<double>::epsilon());
  for (int i = 0; i < nz; ++i) {
    const double h = eps3 * std::max(scale[i], std::abs(z[i]));
    Eigen::VectorXd zp = z;
    zp[i] = z[i] + h;
    ld_.x = x_nominal;
    set_z(zp, zd);
    residual(zdd, Rp);
    zp[i] = z[i] - h;
    ld_.x = x_nominal;
    set_z(zp, zd);
    residual(zdd, Rm);
    dRdz.col(i) = (Rp - Rm) / (2.0 * h);
  }
  ld_.x = x_nominal;
  lin.C0 = dRdzd - lin.D0;
  lin.N0 = dRdz - lin.K0 - lin.G0;
  // Values beyond double precision (e.g. GRAVITY 1e308) give infinities and NaNs here: refuse them
  // rather than hand non-finite matrices to the eigen-analyses.
  auto refuse = [&](const char* name) {
    std::ostringstream os;
    os << "the linearized equations at t = " << data.t << " are not finite (" << name
       << " has infinite or NaN entries): the model's values exceed double precision";
    throw Error(os.str());
  };
  for (const auto& [name, m] : {std::pair<const char*, const Eigen::MatrixXd*>{"M0", &lin.M0}, {"C0", &lin.C0},
                                {"D0", &lin.D0}, {"K0", &lin.K0}, {"N0", &lin.N0}, {"G0", &lin.G0},
                                {"DF", &lin.DFz}, {"DFe", &lin.DFez}})
    if (!m->allFinite()) refuse(name);
  if (!lin.r0.allFinite()) refuse("r0");
  return lin;
}

}  // namespace spacar

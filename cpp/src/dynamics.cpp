#include "spacar/dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "spacar/elements/spatial.hpp"
#include "spacar/errors.hpp"
#include "spacar/kinematics.hpp"

namespace spacar {

namespace {

bool constitutive_class(DefClass c) {
  return c == DefClass::Released || c == DefClass::Dynamic || c == DefClass::Kinematic;
}

// Rigid bodies on LAMBDA nodes and body-fixed torques (formulation.md §3.2, §3.4).
void add_bodies(const System& sys, Data& data) {
  for (const BodyInertia& b : sys.bodies)
    add_rotational_inertia(sys.nx, data.x.data(), data.xd.data(), &b.coord, 1, &b.J, data.M.data(), data.h.data());
  for (const auto& [coord, T] : sys.torquel)
    data.f.segment<4>(coord) += 2.0 * euler_G(data.x.data() + coord).transpose() * T;
}

}  // namespace

void constitutive_stresses(const System& sys, Data& data) {
  data.sigma.setZero();
  for (const SystemElement& se : sys.elements) {
    if (!se.has_constitutive) continue;
    const auto e = data.e.segment(se.def_offset, se.nd);
    const auto ed = data.ed.segment(se.def_offset, se.nd);
    for (int a = 0; a < se.nd; ++a) {
      if (!constitutive_class(sys.def_class[se.def_offset + a])) continue;
      data.sigma[se.def_offset + a] = se.S.row(a).dot(e) + se.D.row(a).dot(ed);
    }
  }
}

void assemble_inertia_and_loads(const System& sys, Data& data) {
  data.M.setZero();
  data.h.setZero();
  data.f = sys.force;
  for (int g = 0; g < sys.nx; ++g) data.M(g, g) = sys.point_mass[g];
  // Gravity on point masses (position coordinates only).
  if (sys.gravity.squaredNorm() > 0.0) {
    for (int g = 0; g < sys.nx; ++g) {
      const NodeKind k = sys.coord_node_kind[g];
      if ((k == NodeKind::XY || k == NodeKind::XYZ) && sys.point_mass[g] != 0.0)
        data.f[g] += sys.point_mass[g] * sys.gravity[sys.coord_label[g][1] - 1];
    }
  }
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    if (!se.has_mass) continue;
    ElementWork& w = data.work[i];
    const int n = static_cast<int>(se.coords.size());
    se.kernel->mass(w.x.data(), w.v.data(), w.M.data(), w.h.data());
    for (int a = 0; a < n; ++a) {
      data.h[se.coords[a]] += w.h[a];
      for (int b = 0; b < n; ++b) data.M(se.coords[a], se.coords[b]) += w.M(a, b);
    }
    if (sys.gravity.squaredNorm() > 0.0) {
      se.kernel->gravity(w.x.data(), sys.gravity.data(), w.f.data());
      for (int a = 0; a < n; ++a) data.f[se.coords[a]] += w.f[a];
    }
  }
  add_bodies(sys, data);
}

void reduced_residual(const System& sys, Data& data, Eigen::VectorXd& R) {
  const int nd = sys.n_dof();
  solve_accelerations(sys, data);
  assemble_inertia_and_loads(sys, data);
  constitutive_stresses(sys, data);
  data.g.noalias() = data.M * data.xdd;
  data.g += data.h - data.f;
  for (int j = 0; j < nd; ++j) data.DFq.col(j) = data.DF.col(sys.dof_cols[j]);
  R.noalias() = data.DFq.transpose() * data.g;
  for (int j = 0; j < nd; ++j) R[j] += data.DFe.col(sys.dof_cols[j]).dot(data.sigma);
}

void solve_dynamics(const System& sys, Data& data) {
  const int nd = sys.n_dof();
  // The residual at q̈ = 0 holds the inputs' accelerations, convective, applied and elastic forces.
  for (int j = 0; j < nd; ++j) data.qhat_dd[sys.dof_cols[j]] = 0.0;
  reduced_residual(sys, data, data.rhs);
  data.rhs = -data.rhs;
  data.Mbar.noalias() = data.DFq.transpose() * data.M * data.DFq;
  if (!data.Mbar.allFinite()) {
    // Overflow (e.g. an enormous MASS or a state far out of range in a trial step): not a
    // singular matrix. Non-finite accelerations make the integrator reject the step and report
    // the non-finite values if no smaller step helps.
    data.qdd.setConstant(std::numeric_limits<double>::quiet_NaN());
    for (int j = 0; j < nd; ++j) data.qhat_dd[sys.dof_cols[j]] = data.qdd[j];
    solve_accelerations(sys, data);
    return;
  }
  data.llt.compute(data.Mbar);
  if (data.llt.info() != Eigen::Success || nd == 0) {
    if (nd == 0) return;
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(data.Mbar);
    const Eigen::VectorXd& lam = eig.eigenvalues();  // ascending
    // Every eigenvector of a (numerically) zero eigenvalue belongs to the null space; with
    // several massless DOFs the null space has several dimensions and any single eigenvector
    // names an arbitrary combination of them, so all of them are reported.
    const double null_tol = 1e-12 * std::max(std::abs(lam[nd - 1]), std::numeric_limits<double>::min());
    std::vector<bool> named(nd, false);
    for (int i = 0; i < nd && (i == 0 || lam[i] <= null_tol); ++i) {
      const Eigen::VectorXd v = eig.eigenvectors().col(i);
      const double vmax = v.cwiseAbs().maxCoeff();
      for (int j = 0; j < nd; ++j) named[j] = named[j] || std::abs(v[j]) >= 0.1 * vmax;
    }
    std::ostringstream os;
    os << "the reduced mass matrix is singular at t = " << data.t << " (smallest eigenvalue "
       << lam[0] << "): the degrees of freedom";
    for (int j = 0; j < nd; ++j) {
      if (!named[j]) continue;
      const int col = sys.dof_cols[j];
      os << " [";
      for (int g = 0; g < sys.nx; ++g)
        if (sys.qhat_col_x[g] == col) os << "DYNX " << sys.coord_name(g);
      for (int k = 0; k < sys.ne; ++k)
        if (sys.qhat_col_e[k] == col) os << "DYNE " << sys.def_name(k);
      os << "]";
    }
    os << " move no mass; add MASS or EMASS to the nodes or elements they move";
    throw SingularMassError(os.str());
  }
  data.qdd = data.llt.solve(data.rhs);
  for (int j = 0; j < nd; ++j) data.qhat_dd[sys.dof_cols[j]] = data.qdd[j];
  solve_accelerations(sys, data);
}

Eigen::MatrixXd geometric_stiffness(const System& sys, Data& data, const Eigen::VectorXd& sigma) {
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(sys.nx, sys.nx);
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    const ElementWork& w = data.work[i];
    const int n = static_cast<int>(se.coords.size());
    Eigen::VectorXd s = sigma.segment(se.def_offset, se.nd);
    if (s.any()) {
      Eigen::MatrixXd G(n, n);
      se.kernel->stress_hessian(w.x.data(), s.data(), G.data());
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) K(se.coords[a], se.coords[b]) += G(a, b);
    }
    // Position-dependent gravity loads of the element mass (beam tangent terms).
    if (se.has_mass && sys.gravity.squaredNorm() > 0.0) {
      Eigen::VectorXd xp = w.x, fp(n), fm(n);
      for (int b = 0; b < n; ++b) {
        const double h = 1e-6 * std::max(1.0, std::abs(w.x[b]));
        xp[b] = w.x[b] + h;
        se.kernel->gravity(xp.data(), sys.gravity.data(), fp.data());
        xp[b] = w.x[b] - h;
        se.kernel->gravity(xp.data(), sys.gravity.data(), fm.data());
        xp[b] = w.x[b];
        for (int a = 0; a < n; ++a) K(se.coords[a], se.coords[b]) -= (fp[a] - fm[a]) / (2.0 * h);
      }
    }
  }
  // Body-fixed torques: f_λ = 2 G(λ)ᵀ T' is linear in λ.
  for (const auto& [coord, T] : sys.torquel)
    for (int b = 0; b < 4; ++b) {
      double unit[4] = {0, 0, 0, 0};
      unit[b] = 1.0;
      K.block<4, 1>(coord, coord + b) -= 2.0 * euler_G(unit).transpose() * T;
    }
  return K;
}

double kinetic_energy(const System&, const Data& data) { return 0.5 * data.xd.dot(data.M * data.xd); }

double potential_energy(const System& sys, const Data& data) {
  double V = 0.0;
  for (const SystemElement& se : sys.elements) {
    if (!se.has_constitutive) continue;
    for (int a = 0; a < se.nd; ++a) {
      if (!constitutive_class(sys.def_class[se.def_offset + a])) continue;
      V += 0.5 * data.e[se.def_offset + a] * se.S.row(a).dot(data.e.segment(se.def_offset, se.nd));
    }
  }
  if (sys.gravity.squaredNorm() > 0.0) {
    // Gravity potential −Σ m g·x of point masses and of the element mass points.
    for (int g = 0; g < sys.nx; ++g) {
      const NodeKind k = sys.coord_node_kind[g];
      if (k == NodeKind::XY || k == NodeKind::XYZ)
        V -= sys.point_mass[g] * sys.gravity[sys.coord_label[g][1] - 1] * data.x[g];
    }
    for (size_t i = 0; i < sys.elements.size(); ++i) {
      const SystemElement& se = sys.elements[i];
      if (!se.has_mass) continue;
      V += se.kernel->gravity_potential(data.work[i].x.data(), sys.gravity.data());
    }
  }
  return V;
}

}  // namespace spacar

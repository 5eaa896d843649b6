#include "spacar/kinematics/dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "spacar/recursive/chain.hpp"
#include "spacar/kinematics/diagnosis.hpp"
#include "spacar/elements/spatial.hpp"
#include "spacar/errors.hpp"
#include "spacar/kinematics/kinematics.hpp"

namespace spacar {

void inertia_times(const System& sys, const Data& data, const Eigen::VectorXd& acc, Eigen::VectorXd& out) {
  out = sys.point_mass.cwiseProduct(acc);
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    if (!se.has_mass) continue;
    const ElementWork& w = data.work[i];
    const int n = static_cast<int>(se.coords.size());
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) out[se.coords[a]] += w.M(a, b) * acc[se.coords[b]];
  }
  for (size_t b = 0; b < sys.bodies.size(); ++b)
    out.segment<4>(sys.bodies[b].coord) += data.body_M[b] * acc.segment<4>(sys.bodies[b].coord);
}

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

void compute_inertia_and_loads(const System& sys, Data& data) {
  data.h.setZero();
  data.f = data.constant_load.size() ? data.constant_load : sys.force;
  if (data.time_load.size()) data.f += data.time_load;
  const bool gravity = sys.gravity.squaredNorm() > 0.0;
  if (gravity) {  // on point masses (position coordinates only)
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
    if (gravity) {
      se.kernel->mass_and_gravity(w.x.data(), w.v.data(), sys.gravity.data(), w.M.data(), w.h.data(), w.f.data());
      for (int a = 0; a < n; ++a) data.f[se.coords[a]] += w.f[a];
    } else {
      se.kernel->mass(w.x.data(), w.v.data(), w.M.data(), w.h.data());
    }
    for (int a = 0; a < n; ++a) data.h[se.coords[a]] += w.h[a];
  }
  // Rigid bodies on LAMBDA nodes and body-fixed torques (formulation.md §3.2, §3.4).
  const int four[1] = {0};
  for (size_t b = 0; b < sys.bodies.size(); ++b) {
    const int c = sys.bodies[b].coord;
    data.body_M[b].setZero();
    data.body_h[b].setZero();
    add_rotational_inertia(4, data.x.data() + c, data.xd.data() + c, four, 1, &sys.bodies[b].J,
                           data.body_M[b].data(), data.body_h[b].data());
    data.h.segment<4>(c) += data.body_h[b];
  }
  for (const Torque& t : sys.torques) data.f.segment<4>(t.coord) += t.force(data.x.data() + t.coord);
}

void inertia_force(const System& sys, Data& data) {
  inertia_times(sys, data, data.xdd, data.inertia_residual);
  data.inertia_residual += data.h - data.f;
}

void assemble_mass_matrix(const System& sys, Data& data) {
  data.ensure_dense(sys);
  data.M.setZero();
  data.M.diagonal() = sys.point_mass;
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    if (!se.has_mass) continue;
    const int n = static_cast<int>(se.coords.size());
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) data.M(se.coords[a], se.coords[b]) += data.work[i].M(a, b);
  }
  for (size_t b = 0; b < sys.bodies.size(); ++b)
    data.M.block<4, 4>(sys.bodies[b].coord, sys.bodies[b].coord) += data.body_M[b];
}

void reduced_residual(const System& sys, Data& data, Eigen::VectorXd& R) {
  const int nd = sys.n_dof();
  solve_accelerations(sys, data);
  compute_inertia_and_loads(sys, data);
  constitutive_stresses(sys, data);
  inertia_force(sys, data);
  for (int j = 0; j < nd; ++j) data.DFq.col(j) = data.DF.col(sys.dof_cols[j]);
  R.noalias() = data.DFq.transpose() * data.inertia_residual;
  for (int j = 0; j < nd; ++j) R[j] += data.DFe.col(sys.dof_cols[j]).dot(data.sigma);
}

namespace {
// Σ_k B_kᵀ σ_k added to out, over the deformations selected by `take`.
template <class Take>
void add_element_loads(const System& sys, const Data& data, Take take, Eigen::VectorXd& out) {
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    const ElementWork& w = data.work[i];
    for (int a = 0; a < se.nd; ++a) {
      const int k = se.def_offset + a;
      if (data.sigma[k] == 0.0 || !take(k)) continue;
      for (size_t j = 0; j < se.coords.size(); ++j) out[se.coords[j]] += w.B(a, j) * data.sigma[k];
    }
  }
}
}  // namespace

void reduced_residual_direct(const System& sys, Data& data, Eigen::VectorXd& R, ExplicitChain* chain) {
  if (chain) chain->solve_accelerations(sys, data);
  else solve_accelerations_direct(sys, data);
  compute_inertia_and_loads(sys, data);
  constitutive_stresses(sys, data);
  inertia_force(sys, data);
  // DFe = B DF element by element, so DF_qᵀ g + DFe_qᵀ σ = DF_qᵀ (g + Σ Bᵀ σ).
  data.residual_load = data.inertia_residual;
  add_element_loads(sys, data, [](int) { return true; }, data.residual_load);
  if (chain) chain->transfer_transposed(sys, data, data.residual_load, data.qhat_load);
  else transfer_transposed(sys, data, data.residual_load, data.qhat_load);
  const int nd = sys.n_dof();
  R.resize(nd);
  for (int j = 0; j < nd; ++j) R[j] = data.qhat_load[sys.dof_cols[j]];
}

void set_dof_accelerations(const System& sys, Data& data, const Eigen::VectorXd& qdd) {
  if (&qdd != &data.qdd) data.qdd = qdd;
  for (int j = 0; j < sys.n_dof(); ++j) data.qhat_dd[sys.dof_cols[j]] = data.qdd[j];
}

void solve_dynamics(const System& sys, Data& data) {
  const int nd = sys.n_dof();
  // The residual at q̈ = 0 holds the inputs' accelerations, convective, applied and elastic forces.
  data.qdd.setZero();
  set_dof_accelerations(sys, data, data.qdd);
  reduced_residual(sys, data, data.rhs);
  data.rhs = -data.rhs;
  assemble_mass_matrix(sys, data);
  data.Mbar.noalias() = data.DFq.transpose() * data.M * data.DFq;
  if (!data.Mbar.allFinite()) {
    // Overflow (e.g. an enormous MASS or a state far out of range in a trial step): not a
    // singular matrix. Non-finite accelerations make the integrator reject the step and report
    // the non-finite values if no smaller step helps.
    data.qdd.setConstant(std::numeric_limits<double>::quiet_NaN());
    set_dof_accelerations(sys, data, data.qdd);
    solve_accelerations(sys, data);
    return;
  }
  data.llt.compute(data.Mbar);
  if (nd == 0) return;
  if (data.llt.info() != Eigen::Success) throw_singular_mass(sys, data, data.Mbar);
  data.qdd = data.llt.solve(data.rhs);
  set_dof_accelerations(sys, data, data.qdd);
  solve_accelerations(sys, data);
}

void solve_dynamics_direct(const System& sys, Data& data) {
  data.ensure_equations_of_motion(sys);
  const int nf = data.n_free;
  compute_inertia_and_loads(sys, data);
  constitutive_stresses(sys, data);
  // Known accelerations: the inputs'. inertia_residual = M ẍ_known + h − f + B_Wᵀ σ^W on every coordinate.
  data.acc_known.setZero();
  for (int g : sys.x_input) data.acc_known[g] = data.qhat_dd[sys.qhat_col_x[g]];
  inertia_times(sys, data, data.acc_known, data.inertia_residual);
  data.inertia_residual += data.h - data.f;
  data.KKT.set_zero();
  data.kkt_rhs.setZero();
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    ElementWork& w = data.work[i];
    if (data.KKT_mass[i] >= 0) data.KKT.add(data.KKT_mass[i], w.M);
    for (int a = 0; a < se.nd; ++a) {
      const int k = se.def_offset + a;
      if (data.sigma[k] != 0.0)
        for (size_t j = 0; j < se.coords.size(); ++j) data.inertia_residual[se.coords[j]] += w.B(a, j) * data.sigma[k];
    }
    if (data.KKT_B[i] < 0) continue;
    data.KKT.add(data.KKT_B[i], w.B);
    data.KKT.add_transposed(data.KKT_Bt[i], w.B);
    // Constraint rows: B_C ẍ_f = ë^C − c^C − B_C ẍ_known, ë^C = p̈ for inputs, 0 otherwise.
    for (size_t j = 0; j < se.coords.size(); ++j) w.a[j] = data.acc_known[se.coords[j]];
    for (int a = 0; a < se.nd; ++a) {
      const int r = data.c_row[se.def_offset + a];
      if (r < 0) continue;
      const int col = sys.qhat_col_e[se.def_offset + a];
      data.kkt_rhs[nf + r] = (col >= 0 ? data.qhat_dd[col] : 0.0) - w.c[a] - w.B.row(a).dot(w.a);
    }
  }
  for (int g = 0; g < sys.nx; ++g)
    if (data.KKT_point[g] >= 0) data.KKT.add_value(data.KKT_point[g], 0, 0, sys.point_mass[g]);
  for (size_t b = 0; b < sys.bodies.size(); ++b) data.KKT.add(data.KKT_body[b], data.body_M[b]);
  for (int g = 0; g < sys.nx; ++g)
    if (data.free_index[g] >= 0) data.kkt_rhs[data.free_index[g]] = -data.inertia_residual[g];
  // Values beyond double precision (an enormous stiffness, load or mass) overflow here or in the
  // solution: that is not a singular mass matrix, and no smaller step can help.
  const Eigen::SparseMatrix<double>& K = data.KKT.matrix();
  const Eigen::Map<const Eigen::VectorXd> K_values(K.valuePtr(), K.nonZeros());
  auto overflow = [&]() {
    std::ostringstream os;
    os << "the accelerations at t = " << data.t
       << " are not finite: the model's values exceed double precision (check the magnitudes of loads, masses, "
          "stiffnesses and rates)";
    return Error(os.str());
  };
  if (!data.kkt_rhs.allFinite()) throw overflow();
  if (!data.luK.factorize(K)) {
    if (!K_values.allFinite()) throw overflow();
    explain_singular_equations(sys, data);
  }
  data.luK.solve(data.kkt_rhs, data.kkt_sol);
  data.xdd = data.acc_known;
  for (int g = 0; g < sys.nx; ++g)
    if (data.free_index[g] >= 0) data.xdd[g] = data.kkt_sol[data.free_index[g]];
  deformation_accelerations(sys, data);
  // Stresses of the constraint rows are the multipliers: the reactions of (6.1).
  for (int k = 0; k < sys.ne; ++k)
    if (data.c_row[k] >= 0) data.sigma[k] = data.kkt_sol[nf + data.c_row[k]];
  int j = 0;
  for (int g : sys.x_dyn) data.qdd[j++] = data.xdd[g];
  for (int k : sys.e_dyn) data.qdd[j++] = data.edd[k];
  set_dof_accelerations(sys, data, data.qdd);
  if (!data.qdd.allFinite() || !data.xdd.allFinite()) {
    constexpr double kHuge = 1e150;  // entries whose products overflow
    if (data.kkt_rhs.cwiseAbs().maxCoeff() > kHuge || K_values.cwiseAbs().maxCoeff() > kHuge) throw overflow();
    throw SingularMassError("the equations of motion have no finite solution at t = " + std::to_string(data.t));
  }
}

namespace {
// σ^V from A_Vᵀ σ^V = −[inertia_residual + Σ B_kᵀ σ_k]_c over the released and kinematic
// deformations (formulation.md §6): every velocity row's stress in equilibrium with the motion.
void equilibrium_stresses(const System& sys, Data& data, Eigen::VectorXd& sV) {
  data.residual_load = data.inertia_residual;
  add_element_loads(sys, data, [&](int k) {
    return sys.def_class[k] == DefClass::Released || sys.def_class[k] == DefClass::Kinematic; }, data.residual_load);
  const int nc = static_cast<int>(sys.x_calc.size());
  for (int j = 0; j < nc; ++j) data.rhs_V[j] = -data.residual_load[sys.x_calc[j]];
  data.luV.solve_transposed(data.rhs_V, sV);
}
}  // namespace

bool solve_dynamics_known(const System& sys, Data& data, const Eigen::VectorXd& qdd) {
  const int nd = sys.n_dof(), nc = static_cast<int>(sys.x_calc.size());
  if (static_cast<int>(sys.defs_V.size()) != nc || qdd.size() != nd) return false;
  compute_inertia_and_loads(sys, data);
  constitutive_stresses(sys, data);
  set_dof_accelerations(sys, data, qdd);
  solve_accelerations_direct(sys, data);
  inertia_force(sys, data);
  if (nc > 0) {
    equilibrium_stresses(sys, data, data.sol_V);
    for (int r = 0; r < nc; ++r)
      if (data.c_row[sys.defs_V[r]] >= 0) data.sigma[sys.defs_V[r]] = data.sol_V[r];
  }
  if (!data.xdd.allFinite() || !data.sigma.allFinite())
    throw SingularMassError("the accelerations at t = " + std::to_string(data.t) + " are not finite");
  return true;
}

void nodal_reactions(const System& sys, Data& data) {
  // r = M ẍ + h − f + Bᵀσ on fixed and input coordinates (6.2), σ complete.
  inertia_force(sys, data);
  // Consistency (formulation.md §6): σ of every velocity row from (6.1) with only the released
  // and kinematic stresses known, A_Vᵀ σ^V = −[g + B_Wᵀ σ^W]_c; its DOF rows equal the
  // constitutive stresses iff q̈ satisfies the equations of motion.
  data.sigma_equilibrium.setZero();
  const int nc = static_cast<int>(sys.x_calc.size());
  if (nc > 0 && static_cast<int>(sys.defs_V.size()) == nc) {
    equilibrium_stresses(sys, data, data.sol_V);
    for (int r = 0; r < nc; ++r) data.sigma_equilibrium[sys.defs_V[r]] = data.sol_V[r];
  }
  data.residual_load = data.inertia_residual;
  add_element_loads(sys, data, [](int) { return true; }, data.residual_load);
  data.reaction = data.residual_load;
  for (int g = 0; g < sys.nx; ++g) {
    const CoordClass c = sys.coord_class[g];
    if (c != CoordClass::Fixed && c != CoordClass::Input) data.reaction[g] = 0.0;
  }
}

double kinetic_energy(const System& sys, const Data& data) {
  Eigen::VectorXd Mv;
  inertia_times(sys, data, data.xd, Mv);
  return 0.5 * data.xd.dot(Mv);
}

double strain_energy(const System& sys, const Data& data) {
  double V = 0.0;
  for (const SystemElement& se : sys.elements) {
    if (!se.has_constitutive) continue;
    for (int a = 0; a < se.nd; ++a) {
      if (!constitutive_class(sys.def_class[se.def_offset + a])) continue;
      V += 0.5 * data.e[se.def_offset + a] * se.S.row(a).dot(data.e.segment(se.def_offset, se.nd));
    }
  }
  return V;
}

double gravity_potential(const System& sys, const Data& data) {
  if (sys.gravity.squaredNorm() == 0.0) return 0.0;
  double V = 0.0;
  // Gravity potential −Σ m g·x of point masses and of the element mass points.
  for (int g = 0; g < sys.nx; ++g) {
    const NodeKind k = sys.coord_node_kind[g];
    if (k == NodeKind::XY || k == NodeKind::XYZ) V -= sys.point_mass[g] * sys.gravity[sys.coord_label[g][1] - 1] * data.x[g];
  }
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    if (!se.has_mass) continue;
    V += se.kernel->gravity_potential(data.work[i].x.data(), sys.gravity.data());
  }
  return V;
}

double potential_energy(const System& sys, const Data& data) { return strain_energy(sys, data) + gravity_potential(sys, data); }

EnergyRates energy_rates(const System& sys, const Data& data) {
  EnergyRates r;
  for (const SystemElement& se : sys.elements) {
    if (!se.has_constitutive) continue;
    const auto ed = data.ed.segment(se.def_offset, se.nd);
    for (int a = 0; a < se.nd; ++a)
      if (constitutive_class(sys.def_class[se.def_offset + a])) r.dissipated += ed[a] * se.D.row(a).dot(ed);
  }
  // Applied loads: FORCE, the time-dependent loads and the torques.
  r.external = sys.force.dot(data.xd);
  if (data.time_load.size()) r.external += data.time_load.dot(data.xd);
  for (const Torque& t : sys.torques) r.external += t.force(data.x.data() + t.coord).dot(data.xd.segment<4>(t.coord));
  // Drivers of input deformations: their reaction stresses against the prescribed rates (fixed
  // deformations do not move).
  for (int k = 0; k < sys.ne; ++k)
    if (!constitutive_class(sys.def_class[k])) r.external -= data.sigma[k] * data.ed[k];
  // Drivers of input coordinates: the reaction M ẍ + h − f + Bᵀσ on them.
  if (!sys.x_input.empty()) {
    Eigen::VectorXd load;
    inertia_times(sys, data, data.xdd, load);
    load += data.h - data.f;
    add_element_loads(sys, data, [](int) { return true; }, load);
    for (int g : sys.x_input) r.external += load[g] * data.xd[g];
  }
  return r;
}

}  // namespace spacar

#include "spacar/kinematics/data.hpp"

#include <algorithm>
#include <limits>
#include <string>

#include "spacar/limits.hpp"

namespace spacar {

Data::Data(const System& sys) {
  const int nx = sys.nx, ne = sys.ne, nq = sys.n_qhat(), nd = sys.n_dof();
  const int nP = static_cast<int>(sys.defs_P.size()), nV = static_cast<int>(sys.defs_V.size());
  const int nc = static_cast<int>(sys.x_calc.size());
  for (Eigen::VectorXd* v : {&x, &xd, &xdd, &acc0, &h, &f, &inertia_residual, &reaction, &acc_known, &residual_load})
    v->resize(nx);
  for (Eigen::VectorXd* v : {&e, &ed, &edd, &sigma, &conv, &angle_ref, &sigma_equilibrium}) v->resize(ne);
  for (Eigen::VectorXd* v : {&qhat, &qhat_d, &qhat_dd, &qhat_load}) v->resize(nq);
  for (Eigen::VectorXd* v : {&rhs, &qdd}) v->resize(nd);
  target.resize(nP);
  residual.resize(nP);
  step.resize(std::max(nc, std::max(nP, nV)));
  rhs_V.resize(nV);
  sol_V.resize(nc);
  work.resize(sys.elements.size());
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const int n = static_cast<int>(sys.elements[i].coords.size()), m = sys.elements[i].nd;
    ElementWork& w = work[i];
    for (Eigen::VectorXd* v : {&w.x, &w.v, &w.a, &w.h, &w.f}) v->resize(n);
    w.B.resize(m, n);
    w.c.resize(m);
    w.M.resize(n, n);
  }
  body_M.resize(sys.bodies.size());
  body_h.resize(sys.bodies.size());
  reset_state(sys);
  number_equations_of_motion(sys);
}

void Data::reset_state(const System& sys, bool keep_pivots) {
  t = 0.0;
  for (Eigen::VectorXd* v : {&x, &xd, &xdd, &e, &ed, &edd, &sigma, &conv, &qhat, &qhat_d, &qhat_dd, &target, &residual,
                             &acc0, &step, &rhs_V, &sol_V, &h, &f, &inertia_residual, &reaction, &acc_known,
                             &residual_load, &sigma_equilibrium, &qhat_load, &rhs, &qdd})
    v->setZero();
  for (ElementWork& w : work) {
    for (Eigen::VectorXd* v : {&w.x, &w.v, &w.a, &w.h, &w.f, &w.c}) v->setZero();
    w.B.setZero();
    w.M.setZero();
  }
  e_integrated = sys.e_target;
  angle_ref.setConstant(std::numeric_limits<double>::quiet_NaN());
  for (Eigen::Matrix4d& m : body_M) m.setZero();
  for (Eigen::Vector4d& v : body_h) v.setZero();
  time_load.resize(0);
  constant_load.resize(0);
  jacobian_reusable = false;
  newton_iterations = 0;
  total_newton_iterations = 0;
  // The sparse LUs forget their pivot sequences (replayed from one factorization to the next),
  // so that a solve from here gives the same digits whatever was solved before.
  if (keep_pivots) return;
  if (constraint_blocks_ready) analyze_constraint_blocks(sys);
  if (equations_ready) luK.analyze(KKT.matrix());
}

void Data::ensure_constraint_blocks(const System& sys) {
  if (constraint_blocks_ready) return;
  AP_block.clear();
  AV_block.clear();
  build_constraint_blocks(sys);
  constraint_blocks_ready = true;
}

void Data::build_constraint_blocks(const System& sys) {
  const int nc = static_cast<int>(sys.x_calc.size());
  AP.reset(static_cast<int>(sys.defs_P.size()), nc);
  AV.reset(static_cast<int>(sys.defs_V.size()), nc);
  for (const SystemElement& se : sys.elements) {
    std::vector<int> rp(se.nd), rv(se.nd), cols(se.coords.size());
    for (int a = 0; a < se.nd; ++a) {
      rp[a] = sys.row_P[se.def_offset + a];
      rv[a] = sys.row_V[se.def_offset + a];
    }
    for (size_t j = 0; j < se.coords.size(); ++j) cols[j] = sys.calc_pos[se.coords[j]];
    AP_block.push_back(AP.add_block(rp, cols));
    AV_block.push_back(AV.add_block(rv, cols));
  }
  AP.finalize();
  AV.finalize();
  analyze_constraint_blocks(sys);
}

void Data::analyze_constraint_blocks(const System& sys) {
  const int nc = static_cast<int>(sys.x_calc.size());
  if (AP.rows() == nc) luP.analyze(AP.matrix());
  if (AV.rows() == nc) luV.analyze(AV.matrix());
}

void Data::number_equations_of_motion(const System& sys) {
  free_index.assign(sys.nx, -1);
  for (int g : sys.x_calc) free_index[g] = n_free++;
  for (int g : sys.x_dyn) free_index[g] = n_free++;
  c_row.assign(sys.ne, -1);
  for (int k : sys.defs_V)
    if (sys.def_class[k] != DefClass::Dynamic) c_row[k] = n_c_rows++;
}

void Data::ensure_equations_of_motion(const System& sys) {
  if (equations_ready) return;
  for (auto* ids : {&KKT_mass, &KKT_B, &KKT_Bt, &KKT_point, &KKT_body}) ids->clear();  // after a failed build
  const int n = n_free + n_c_rows;
  KKT.reset(n, n);
  for (const SystemElement& se : sys.elements) {
    std::vector<int> fi(se.coords.size()), cr(se.nd, -1);
    for (size_t j = 0; j < se.coords.size(); ++j) fi[j] = free_index[se.coords[j]];
    bool any_row = false;
    for (int a = 0; a < se.nd; ++a) {
      const int r = c_row[se.def_offset + a];
      cr[a] = r >= 0 ? n_free + r : -1;
      any_row = any_row || r >= 0;
    }
    KKT_mass.push_back(se.has_mass ? KKT.add_block(fi, fi) : -1);
    KKT_B.push_back(any_row ? KKT.add_block(cr, fi) : -1);
    KKT_Bt.push_back(any_row ? KKT.add_block(fi, cr) : -1);
  }
  for (int g = 0; g < sys.nx; ++g)
    KKT_point.push_back(sys.point_mass[g] != 0.0 ? KKT.add_block({free_index[g]}, {free_index[g]}) : -1);
  for (const BodyInertia& b : sys.bodies) {
    std::vector<int> fi(4);
    for (int i = 0; i < 4; ++i) fi[i] = free_index[b.coord + i];
    KKT_body.push_back(KKT.add_block(fi, fi));
  }
  KKT.finalize();
  luK.analyze(KKT.matrix());
  kkt_rhs = kkt_sol = Eigen::VectorXd::Zero(n);
  equations_ready = true;
}

void Data::ensure_dense(const System& sys) {
  if (dense_ready) return;
  require_memory(estimate_dense_bytes(sys),
                 "the dense transfer functions and mass matrices of " + std::to_string(sys.nx) +
                     " nodal coordinates and " + std::to_string(sys.ne) + " deformations",
                 "the linearization uses dense matrices, spacar.simulate does not");
  const int nx = sys.nx, ne = sys.ne, nq = sys.n_qhat(), nd = sys.n_dof();
  rhs_DF = Eigen::MatrixXd::Zero(static_cast<int>(sys.defs_V.size()), nq);
  DF = Eigen::MatrixXd::Zero(nx, nq);
  DFe = Eigen::MatrixXd::Zero(ne, nq);
  M = Eigen::MatrixXd::Zero(nx, nx);
  DFq = Eigen::MatrixXd::Zero(nx, nd);
  Mbar = Eigen::MatrixXd::Zero(nd, nd);
  dense_ready = true;
}

double Data::estimate_bytes(const System& sys) {
  const double nx = sys.nx, ne = sys.ne, nq = sys.n_qhat(), nd = sys.n_dof();
  double doubles = 30.0 * (nx + ne + nq + nd);  // vectors
  for (const SystemElement& se : sys.elements) {
    const double n = static_cast<double>(se.coords.size()), m = se.nd;
    // Work arrays, S, D and kernel; entries of A_P, A_V and the equations of motion, with ten
    // times the entries again for the fill of their sparse factors.
    doubles += 2.0 * m * n + n * n + 6.0 * n + 2.0 * m * m + 64.0 + 11.0 * (2.0 * m * n + 2.0 * m * n + n * n);
  }
  return 8.0 * doubles;
}

double Data::estimate_dense_bytes(const System& sys) {
  const double nx = sys.nx, ne = sys.ne, nq = sys.n_qhat(), nd = sys.n_dof();
  const double nV = static_cast<double>(sys.defs_V.size()), nc = static_cast<double>(sys.x_calc.size());
  const double doubles = nx * nx                  // M
                         + ne * ne                // global constitutive matrices of the linearization
                         + nV * nq + nc * nq      // rhs_DF and the solution of the transfer functions
                         + 2.0 * nx * nq + ne * nq  // DF (and the linearization's copy), DFe
                         + nx * nd + 2.0 * nd * nd;  // DFq, Mbar and its factor
  return 8.0 * doubles;
}

}  // namespace spacar

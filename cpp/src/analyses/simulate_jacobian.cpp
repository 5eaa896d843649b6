// Jacobian of the first-order equations of motion for the implicit integrator (radau5.hpp), from
// the linearized equations of formulation.md §7 at the current state (§8.2):
//   ∂(q̇, ẏ^k, q̈)/∂(q, y^k, q̇) = [[0, 0, I], [BK0_q, BK0_k, AK0_q],
//                                  [−M0⁻¹(K0 + N0 + G0), −M0⁻¹ K_k, −M0⁻¹(C0 + D0)]]
// in the q-rows and q-columns of the linearization (its LINE parameters are not states of the
// motion). The matrices are taken at fixed time with the inputs on their path, which is what ∂f/∂Y
// asks for: prescribed inputs need no special treatment.
#include <algorithm>

#include "spacar/errors.hpp"
#include "spacar/analyses/simulate.hpp"

namespace spacar {

void Simulation::jacobian(double t, const Eigen::VectorXd& Y, Eigen::MatrixXd& J) {
  const System& sys = *sys_;
  const int nd = sys.n_dof(), ny = static_cast<int>(sys.y_defs.size()), n = 2 * nd + ny;
  Linearization lin;
  try {
    evaluate_state(t, Y);
    lin = linearize(Linearizer::Differences::Fast);  // a Newton matrix: 1e-8 is plenty
  } catch (const KinematicsError& err) {
    throw StepRejected(err.what());
  }
  J.setZero(n, n);
  J.block(0, nd + ny, nd, nd).setIdentity();
  if (nd > 0) {
    run_.jacobian_mass = lin.M0.topLeftCorner(nd, nd);  // the weight of generalized-α's residual form
    const Eigen::LLT<Eigen::MatrixXd> mass(run_.jacobian_mass);
    if (mass.info() != Eigen::Success) throw Error("jacobian: the reduced mass matrix is not positive definite");
    J.block(nd + ny, 0, nd, nd) = -mass.solve((lin.K0 + lin.N0 + lin.G0).topLeftCorner(nd, nd));
    J.block(nd + ny, nd + ny, nd, nd) = -mass.solve((lin.C0 + lin.D0).topLeftCorner(nd, nd));
    // Kinematic coordinates of nonholonomic constraints: position of each in y.
    const int nz = static_cast<int>(lin.M0.rows());
    std::vector<int> pos(sys.e_kinematic.size());
    for (size_t j = 0; j < pos.size(); ++j)
      pos[j] = static_cast<int>(std::find(sys.y_defs.begin(), sys.y_defs.end(), sys.e_kinematic[j]) -
                                sys.y_defs.begin());
    for (size_t j = 0; j < pos.size(); ++j) {
      J.block(nd + ny, nd + pos[j], nd, 1) = -mass.solve(lin.Kk.block(0, j, nd, 1));
      J.block(nd + pos[j], 0, 1, nd) = lin.BK0.block(j, 0, 1, nd);
      J.block(nd + pos[j], nd + ny, 1, nd) = lin.AK0.block(j, 0, 1, nd);
      for (size_t i = 0; i < pos.size(); ++i) J(nd + pos[j], nd + pos[i]) = lin.BK0(j, nz + i);
    }
  }
  // The integrated values of released velocity-level deformations (slips) keep zero rows and
  // columns: an approximation that only slows the simplified Newton iterations down.
}

}  // namespace spacar

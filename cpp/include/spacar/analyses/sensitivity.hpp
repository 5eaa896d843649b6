// A static equilibrium held for design sensitivities (spacar.sensitivity, docs/sensitivity.md):
// the model's simulation put at given positions, with the reduced generalized forces R(q, p),
// the tangent stiffness K_T = ∂R/∂q and the quadratic forms of the reduced stiffness and mass
// there. The derivatives with respect to a parameter p (ESTIFF, EMASS, MASS) come from two such
// points of the model with p changed, at the same positions, where R and the quadratic forms are
// affine in p; the equilibrium's own change dq/dp = −K_T⁻¹ ∂R/∂p by one solve (the direct method).
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "spacar/analyses/nodal.hpp"
#include "spacar/analyses/simulate.hpp"
#include "spacar/model/model.hpp"

namespace spacar {

class StaticPoint {
 public:
  // The model (which must outlive the point) assembled and put at the positions x with the
  // deformations e (a row of static results: its independent coordinates taken from them), the
  // block's loads at full size; InputError if a size is wrong.
  StaticPoint(Model& model, const Eigen::VectorXd& x, const Eigen::VectorXd& e);

  const System& system() const { return sim_.system(); }
  // The degrees of freedom q, the positions and deformations of the current state.
  Eigen::VectorXd dofs() const;
  const Eigen::VectorXd& x() { return sim_.data().x; }
  const Eigen::VectorXd& e() { return sim_.data().e; }
  // R(q) = DF_qᵀ (Σ Bᵀσ − f) at the current state (zero at an equilibrium), and its scale: the
  // largest applied or elastic load on a coordinate (static_forces).
  const Eigen::VectorXd& residual() const { return R_; }
  double load_scale() const { return scale_; }
  // Whether K_T is symmetric (no body-fixed or global torques' load stiffness): factorizes it.
  bool symmetric();
  // Move the degrees of freedom to q (positions re-solved from the current ones, forces again).
  void move_to(const Eigen::VectorXd& q);
  // K_T⁻¹ r for a load r on the DOFs (the tangent K0 + G0 factorized at the current state on
  // first use); StaticError naming the direction if K_T is singular.
  Eigen::VectorXd solve(const Eigen::VectorXd& r);
  // δx = DF_q δq: the motion of every coordinate for a change δq of the DOFs.
  Eigen::VectorXd motion(const Eigen::VectorXd& dq);
  // (δqᵀ K0 δq, δqᵀ G0 δq, δqᵀ M0 δq, δqᵀ D0 δq) at the current state, element by element from
  // the motion DF_q δq (nodal_energies).
  Eigen::Vector4d energies(const Eigen::VectorXd& dq);
  // The compliance C = T DF_q K_T⁻¹ DF_qᵀ Tᵀ at the nodes (T: displacement_rows) at the current
  // state, and U = K_T⁻¹ DF_qᵀ Tᵀ (n_dof x m, the DOFs' response to each unit load) if given.
  Eigen::MatrixXd compliance(const std::vector<int>& nodes, Eigen::MatrixXd* U = nullptr);

 private:
  void forces();
  void factorize();
  ReducedSystem& reduced();

  Simulation sim_;
  Eigen::VectorXd R_;
  double scale_ = 0.0;
  std::unique_ptr<ReducedSystem> reduced_;
  bool factorized_ = false;
};

}  // namespace spacar

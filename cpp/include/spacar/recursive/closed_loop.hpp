// Closed loops on the recursive path (formulation.md §7): a spatial tree of rigid bodies
// (spatial_tree.hpp) whose passive joints (released HINGE or BEARING rotations and translations)
// the loops determine, closed by constraints at the points two bodies share and at the cut
// hinges' rigid misalignments.
//
// The tree's coordinates are θ = (q, θ_d): the DOFs and the dependent joints' coordinates. At
// (q, q̇) the loops are closed by Newton's method in θ_d (a few unknowns, warm-started from the
// last state), θ̇_d = −J_d⁺ J_q q̇ (J = ∂c/∂θ, the constraints' Jacobian, least squares where
// constraints are redundant, as for a planar loop closed by a ball joint), so θ̇ = T q̇ with
// T = [1; −J_d⁺ J_q] and θ̈ = T q̈ + g, g = [0; −J_d⁺ γ] (γ: the constraints' velocity-product
// accelerations). The equations of motion in q follow by virtual work,
//     Tᵀ M T q̈ = −Tᵀ τ_id(θ, θ̇, g),
// with τ_id the tree's inverse dynamics (the recursive Newton–Euler algorithm) and M T from one
// pass per DOF: the same equations as the constraint formulation, every loop exact, nothing
// stabilised or projected afterwards. Cost: one placement per Newton iteration and n + 3 linear
// passes over the tree, against the general path's Newton iterations over every coordinate.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>

#include "spacar/kinematics/data.hpp"
#include "spacar/model/system.hpp"
#include "spacar/recursive/spatial_tree.hpp"

namespace spacar {

class ClosedLoopTree : public RecursiveTree {
 public:
  // The tree with its loops closed, or nullptr and the reason if the loops do not determine the
  // dependent joints at the recognized state (data: the system's DOFs there).
  static std::unique_ptr<RecursiveTree> close(std::unique_ptr<SpatialTree> tree, const System& sys,
                                              const Data& data, std::string* why);

  bool solve(const double* q, const double* qd, double* qdd) override;
  // Tᵀ τ_id(θ, θ̇, T q̈ + g): the generalized forces on the DOFs.
  void inverse_dynamics(const double* q, const double* qd, const double* qdd, double* force) override;
  bool dynamics_derivatives(int n, const double* q, const double* qd, const double* tau, double* qdd, double* dq,
                            double* dqd, double* dtau) override;

 protected:
  void move_coordinates(Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd) const override;

 private:
  using Vec3 = Eigen::Vector3d;
  explicit ClosedLoopTree(std::unique_ptr<SpatialTree> tree);

  // θ at q with the loops closed (θ_d from the last closed state); false if Newton's method fails
  // or J_d loses rank. Leaves c_ and J_ (and its factorization) at θ.
  bool close_loops(const double* q);
  bool newton();                 // from θ: true if closed (c_, J_, qr_ at θ)
  bool closed(const double* q);  // q is the last closed state's: true
  // The constraints c_ and their Jacobian J_ at the tree's placement (outward() at θ).
  void constraints();
  // γ_: the constraints' accelerations at θ̈ = 0 without gravity (after the tree's velocity-product
  // accelerations).
  void constraint_bias();
  // At (q, q̇): θ, θ̇ and the tree placed and moving there (outward, applied loads), T_ and g_.
  bool prepare(const double* q, const double* qd);

  // The world rate of a point p (world) of body i, and of its angular velocity, per unit θ̇ of
  // the joints on its path: added to row block `rows` of J_ with the factor `scale`.
  void add_point_rows(int body, const Vec3& p, double scale, int row);
  void add_rotation_row(int body, const Eigen::Matrix<double, 1, 3>& w, int row);

  std::unique_ptr<SpatialTree> tree_;
  const SpatialTree::Loops& loops_;
  int nd_ = 0, nn_ = 0, m_ = 0;       // DOFs, dependent joints, constraint rows
  double length_ = 1.0;               // a length of the tree: the scale of the points' residuals
  Eigen::VectorXd theta_, theta_d_, theta_dd_, zero_, c_, gamma_, g_, col_;
  Eigen::VectorXd q_last_, start_, step_, rhs_;  // the last closed state's q; Newton's work; Tᵀ (−τ_id)
  Eigen::MatrixXd J_, T_, MT_, A_;               // A_ = Tᵀ M T
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr_;  // of J_d
  Eigen::LLT<Eigen::MatrixXd> llt_;                 // of A_
};

}  // namespace spacar

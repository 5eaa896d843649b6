// Closed loops on the recursive path (formulation.md §7): a tree of rigid bodies whose passive
// joints the loops determine (spatial_tree.hpp: released HINGE or BEARING rotations and
// translations; planar_tree.hpp: bodies turned by their own calculable rotation), closed by
// constraints at the points two bodies share and (spatial) at the cut hinges' rigid
// misalignments.
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
#include <vector>

#include "spacar/kinematics/data.hpp"
#include "spacar/model/system.hpp"
#include "spacar/recursive/articulated.hpp"

namespace spacar {
namespace rnea {
template <class S>
struct SpatialMotion;  // spatial_rnea.hpp
}  // namespace rnea

// The factorization of J_d, the constraints' Jacobian in the passive joints (m × n, m ≥ n): an LU
// with partial pivoting where J_d is square and not near singular (smallest / largest |U_ii| above
// 1e-10: every loop the general path assembles, which refuses redundant constraints; the LU takes
// a third of the time of the column-pivoted QR, which was 40 % of Newton's iterations at 3 × 3),
// else the column-pivoted QR,
// whose rank decides whether the loops determine the passive joints (its solutions least squares
// where rows are redundant). Near a singular J_d the QR decides, as before the LU.
class DependentJoints {
 public:
  void resize(int m, int n);
  bool compute(const Eigen::Ref<const Eigen::MatrixXd>& Jd);  // false: rank below n
  int rank() const { return lu_used_ ? n_ : static_cast<int>(qr_.rank()); }
  // x = J_d⁺ b (x: n × k, b: m × k).
  void solve(const Eigen::Ref<const Eigen::MatrixXd>& b, Eigen::Ref<Eigen::MatrixXd> x) const;

 private:
  int m_ = 0, n_ = 0;
  bool lu_used_ = false;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr_;
};

// Over the planar (planar_tree.hpp) and the spatial algebra (spatial_tree.hpp); the loops'
// kinematics (constraints, add_point_rows, constraint_bias) are written for each.
template <class Algebra>
class ClosedLoopTree : public RecursiveTree {
 public:
  using Tree = ArticulatedTree<Algebra>;
  using Point = typename Algebra::Point;

  // The tree with its loops closed, or nullptr and the reason if the loops do not determine the
  // passive joints at the recognized state (data: the system's DOFs there).
  static std::unique_ptr<RecursiveTree> close(std::unique_ptr<Tree> tree, const System& sys, const Data& data,
                                              std::string* why);

  bool solve(const double* q, const double* qd, double* qdd) override;
  // Tᵀ τ_id(θ, θ̇, T q̈ + g): the generalized forces on the DOFs.
  void inverse_dynamics(const double* q, const double* qd, const double* qdd, double* force) override;
  bool dynamics_derivatives(int n, const double* q, const double* qd, const double* tau, double* qdd, double* dq,
                            double* dqd, double* dtau) override;
  bool serves_any_state() const override { return false; }

 protected:
  void move_coordinates(Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd) override;

 private:
  explicit ClosedLoopTree(std::unique_ptr<Tree> tree);

  // θ at q with the loops closed, by continuation from the last closed state (or the recognized
  // one); false (θ and the tangent left at the last state) if that fails. Leaves the tree placed
  // at θ and c_ and J_ (and its factorization) there (or, after Newton's round-off exit, one
  // correction of round-off size before).
  bool close_loops(const double* q);
  bool continue_to(const double* q);  // from (q_last_, θ_d, T_d) along the straight path to q
  bool newton();  // from θ: true if closed (the tree placed at θ; c_, J_, qr_ as close_loops says)
  void dependent_tangent();  // T_d = −J_d⁺ J_q from J_ and its factorization
  // The constraints c_ and their Jacobian J_ at the tree's placement (place() at θ).
  void constraints();
  // The world position of point b of body i (the ground's: b).
  Point world_point(int body, const Point& b) const;
  // Adds the rates of point p (world) of body i per unit θ̇ of the joints on its path, times
  // `scale`, to the rows from `row` of J_.
  void add_point_rows(int body, const Point& p, double scale, int row);
  // γ_: the constraints' accelerations at θ̈ = 0 without gravity (after the tree's velocity-product
  // accelerations).
  void constraint_bias();
  Point point_acceleration(int body, const Point& b) const;  // world axes, at θ̈ = 0 without gravity
  // A spatial cut's rows of c_, J_ and γ_ from `row` (the planar tree has no cuts).
  void add_cut_rows(int row);
  void add_cut_bias(int row);
  void add_rotation_row(int body, const Eigen::Matrix<double, 1, 3>& w, int row);  // w · ω of the body
  // At (q, q̇): θ, θ̇ and the tree placed and moving there (outward, applied loads), T_ and g_.
  bool prepare(const double* q, const double* qd);
  // q̈ at (q, q̇) under τ on a scalar type S (dual numbers: its exact derivatives), at the state
  // prepare() closed, with Jd_inverse = J_d⁻¹ there; false if Tᵀ M T is not positive definite
  // (InputError if J_d is singular on the way).
  template <class S>
  bool loop_dynamics(const S* q, const S* qd, const S* tau, const Eigen::MatrixXd& Jd_inverse, S* qdd);
  // The rows c (m: the points', then the cuts'), J (m × θ) and the constraints' accelerations γ
  // at θ̈ = 0 on S, at θ and θ̇ (J, γ: if given); the kinematics of add_point_rows,
  // point_acceleration and add_cut_rows.
  template <class S>
  void loop_points(const std::vector<S>& theta, const std::vector<S>* rates, std::vector<S>& c, std::vector<S>* J,
                   std::vector<S>* gamma);
  // A spatial cut's row r into row `row` of c (J, γ: if given), on S, from the tree's motion.
  template <class S>
  void add_cut_row(const std::vector<rnea::SpatialMotion<S>>& motion, const typename Tree::Loops::Cut& cut, size_t r,
                   int row, std::vector<S>& c, std::vector<S>* J, std::vector<S>* gamma) const;
  template <class S>
  void tree_inverse_dynamics(const S* q, const S* qd, const S* qdd, S* force) const;  // the tree's, on S

  std::unique_ptr<Tree> tree_;
  const typename Tree::Loops& loops_;
  int nd_ = 0, nn_ = 0, m_ = 0;       // DOFs, passive joints, constraint rows
  int n_point_rows_ = 0;              // the first rows: the points'
  double length_ = 1.0;               // a length of the tree: the scale of the points' residuals
  Eigen::VectorXd theta_, theta_d_, theta_dd_, zero_, c_, gamma_, g_, col_;
  Eigen::VectorXd q_last_, rhs_, w_;  // the last closed state's q; Tᵀ (−τ_id); a planar row
  Eigen::VectorXd start_, from_, step_q_, delta_, predicted_, accepted_, step_, tangent_move_;  // close_loops', Newton's work
  Eigen::MatrixXd T_start_;                                                    // T_d at the last closed state
  Eigen::VectorXd q0_, theta0_;                                                // the recognized state
  Eigen::MatrixXd T0_;
  Eigen::MatrixXd J_, T_, MT_, A_;               // A_ = Tᵀ M T
  std::vector<int> path_;                            // a body's path to the root (planar rows)
  std::vector<double> rate_coefficients_;            // planar, on S: ∂ω_i/∂θ̇ of every body (row i), made once
  DependentJoints qr_;                              // of J_d
  Eigen::LLT<Eigen::MatrixXd> llt_;                 // of A_
};

}  // namespace spacar

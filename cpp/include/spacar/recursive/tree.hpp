// Recursive dynamics of open trees of rigid bodies (formulation.md §7): the interface of the
// recursive path; planar trees in planar_tree.hpp, spatial trees in spatial_tree.hpp, the
// articulated-body algorithm both run in articulated.hpp.
//
// For an open tree of rigid bodies the equations of motion are solved in O(N) by the
// articulated-body algorithm in the joint coordinates, with explicit positions instead of
// Newton's method: the same equations as the constraint formulation (the body inertias are the
// element and nodal mass matrices projected on the rigid motions), several times cheaper per
// right-hand side. Any other model, or a tree whose articulated inertia is not positive, takes
// the general path.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

#include "spacar/kinematics/data.hpp"
#include "spacar/model/system.hpp"

namespace spacar {

// The recursive right-hand side of an open tree of rigid bodies: planar (PlanarTree,
// planar_tree.hpp) or spatial (SpatialTree, spatial_tree.hpp).
class RecursiveTree {
 public:
  virtual ~RecursiveTree() = default;
  // The planar or spatial tree of the system if it is one, else nullptr and (if why is given)
  // the reason. Taken at the positions in data, which must satisfy the constraints.
  static std::unique_ptr<RecursiveTree> detect(const System& sys, const Data& data, std::string* why = nullptr);

  // At (q, q̇) (no inputs, no integrated deformations): the positions, velocities and
  // accelerations of every coordinate into x, xd, xdd (length nx; fixed coordinates are left as
  // they are) and the DOF accelerations into qdd. False if an articulated inertia is not
  // positive (a body that moves no mass): the general path names the DOFs.
  bool solve(const double* q, const double* qd, Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd,
             double* qdd);
  // The DOF accelerations only (nothing written if false).
  virtual bool solve(const double* q, const double* qd, double* qdd) = 0;
  // Inverse dynamics (the recursive Newton–Euler algorithm, as pinocchio.rnea): the generalized
  // forces on the DOFs, beyond the model's own loads, gravity and joint springs and dampers, under
  // which the tree has the accelerations qdd at (q, q̇).
  virtual void inverse_dynamics(const double* q, const double* qd, const double* qdd, double* force) = 0;
  // The forward dynamics at (q, q̇) under the extra generalized forces τ (those inverse_dynamics
  // gives) and its derivatives, as pinocchio.computeABADerivatives: q̈ (n) and ∂q̈/∂q, ∂q̈/∂q̇,
  // ∂q̈/∂τ = M⁻¹ (n × n, row major), n the DOFs (one per joint, a floating base's six). False if
  // this tree does not provide them or its mass matrix is not positive definite.
  virtual bool dynamics_derivatives(int /*n*/, const double* /*q*/, const double* /*qd*/, const double* /*tau*/,
                                    double* /*qdd*/, double* /*dq*/, double* /*dqd*/, double* /*dtau*/) {
    return false;
  }
  // Whether the tree may serve the next block of its model, recognized at another state
  // (Simulation::renew): an open tree's bodies, joints and inertias do not depend on the state; a
  // tree with loops closed keeps the state it was recognized at as the start of its loop closure
  // and its rank check, which a later block must make at its own start.
  virtual bool serves_any_state() const { return true; }

 protected:
  // The coordinates moving with the bodies, after solve() (which may leave the bodies'
  // accelerations to this call: a loop's solve() needs only q̈).
  virtual void move_coordinates(Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd) = 0;
};

}  // namespace spacar

// Recursive dynamics of planar open trees of rigid bodies (formulation.md §7).
//
// A planar model of rigid PLBEAMs (every deformation fixed) connected as an open tree is a
// kinematic tree of rigid bodies with revolute joints: beams sharing a BETA node are one body, a
// body hangs from its parent at a shared (or fixed) XY node, its pin, and turns about it by the
// rotation of a PLHINGE to the parent (DYNE) or by its own rotation (DYNX on one of its BETA
// nodes). Released PLHINGEs are springs and dampers between bodies; FORCE and gravity load it.
// For such models the equations of motion are solved in O(N) by the articulated-body algorithm
// in the hinge coordinates, with explicit positions instead of Newton's method: the same
// equations as the constraint formulation (the body inertias are the element and nodal mass
// matrices projected on the rigid motions), several times cheaper per right-hand side. Any other
// model, or a tree whose articulated inertia is not positive, takes the general path.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

#include "spacar/kinematics/data.hpp"
#include "spacar/model/system.hpp"

namespace spacar {

// The recursive right-hand side of an open tree of rigid bodies: planar (PlanarTree) or spatial
// (SpatialTree, spatial_tree.hpp).
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
  bool solve(const double* q, const double* qd, double* qdd);

 protected:
  // The phases of solve(), the articulated-body algorithm in the tree's algebra. Outwards: body
  // rotations, positions, velocities, bias accelerations and forces, joint torques;
  virtual void outward(const double* q, const double* qd) = 0;
  // the applied loads on the bodies;
  virtual void applied_loads() = 0;
  // inwards: articulated inertias and bias forces, false if a joint's inertia is not positive;
  virtual bool articulate() = 0;
  // outwards: joint and body accelerations, q̈;
  virtual void accelerations(double* qdd) = 0;
  // the coordinates moving with the bodies.
  virtual void move_coordinates(Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd) const = 0;
};

class PlanarTree : public RecursiveTree {
 public:
  // The tree of the system if it is one, else nullptr. The body geometry and inertia are taken
  // at the positions in data, which must satisfy the constraints (a solved state).
  static std::unique_ptr<PlanarTree> detect(const System& sys, const Data& data);

  int n_bodies() const { return static_cast<int>(bodies_.size()); }

 private:
  using Vec3 = Eigen::Vector3d;
  using Mat3 = Eigen::Matrix3d;
  // Spatial vectors are planar (ω, vx, vy) in body coordinates: origin at the body's pin, axes
  // those of the world rotated by the body's rotation φ since the reference state.
  struct Body {
    int parent = -1;              // index into bodies_ (parents first), −1: the ground
    int dof = 0;                  // position of the hinge rotation in q
    bool absolute = false;        // q is the body's rotation (DYNX), else a hinge's (DYNE)
    double sign = 1.0;            // DYNE: joint angle u = sign · q (the hinge may point to the parent)
    double offset = 0.0;          // DYNE: φ = φ_parent + u + offset; DYNX: φ = q − offset
    double stiffness = 0.0, damping = 0.0;  // hinge σ = S e + D ė, joint torque −σ
    Eigen::Vector2d r;            // pin in the parent's coordinates (ground: the world)
    Mat3 inertia;                 // about the pin, in body coordinates
    // Work of one evaluation.
    double c = 1.0, s = 0.0;      // cos, sin of the rotation relative to the parent
    double cw = 1.0, sw = 0.0;    // cos, sin of φ
    double phi = 0.0;             // rotation since the reference state
    double ud = 0.0;              // joint rate u̇
    double tau = 0.0;             // joint torque
    double u = 0.0;               // joint force left after the bias forces
    Eigen::Vector2d pin;          // world position of the pin
    Vec3 v, bias, pA, a, U;
    Mat3 IA;
    double d = 0.0;
  };
  // A coordinate moving with a body: XY components at body point b, or a BETA angle.
  struct Follower {
    int coord = 0, body = 0;
    int component = 0;            // 0: the XY node's x (and y, the next coordinate), 2: a rotation
    Eigen::Vector2d b;            // body coordinates of the point (XY)
    double value0 = 0.0;          // rotation at the reference state (BETA)
  };
  // A constant applied load (FORCE) on a coordinate moving with a body.
  struct Load {
    int body = 0, component = 0;
    Eigen::Vector2d b;
    double value = 0.0;
  };

  // A released PLHINGE with stiffness or damping: σ = S (β_b − β_a) + D (β̇_b − β̇_a) on bodies
  // a and b (index into bodies_, or the ground), β = β0 + φ.
  struct Spring {
    int body_a = -1, body_b = -1;
    double beta0_a = 0.0, beta0_b = 0.0, stiffness = 0.0, damping = 0.0;
  };
  class Builder;

  void outward(const double* q, const double* qd) override;
  void applied_loads() override;
  bool articulate() override;
  void accelerations(double* qdd) override;
  void move_coordinates(Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd) const override;

  // Transform of motion vectors from the parent's coordinates to the body's.
  static Vec3 to_child(const Body& bd, const Vec3& m);
  // Transform of force vectors from the body's coordinates to the parent's (the transpose).
  static Vec3 to_parent(const Body& bd, const Vec3& f);
  static Mat3 inertia_to_parent(const Body& bd, const Mat3& I);

  std::vector<Body> bodies_;
  std::vector<Follower> followers_;
  std::vector<Load> loads_;
  std::vector<Spring> springs_;
  Vec3 base_acceleration_ = Vec3::Zero();  // −gravity, the fictitious acceleration of the ground
};

}  // namespace spacar

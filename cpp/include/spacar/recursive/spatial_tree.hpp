// Recursive dynamics of spatial open trees of rigid bodies (formulation.md §7, the spatial
// counterpart of tree.hpp).
//
// A spatial model of rigid BEAMs (every deformation fixed) connected as an open tree is a
// kinematic tree of rigid bodies with revolute joints: beams sharing a LAMBDA node are one body,
// a body hangs from its parent at a shared (or fixed) XYZ node, its pin, and turns about it by
// the rotation e1 of a HINGE to the parent (DYNE, e2 and e3 fixed). MASS (point masses, inertia
// tensors on LAMBDA nodes), EMASS, FORCE on points, TORQUEL, GRAVITY and the hinges' ESTIFF and
// EDAMPP load it. The equations of motion are solved in O(N) by the articulated-body algorithm
// in spatial algebra, with explicit positions instead of Newton's method: the same equations as
// the constraint formulation (each body's spatial inertia is the element and nodal mass matrices
// projected on its rigid motions).
//
// Refused (the general path runs, and detect() says why): planar models (tree.hpp), DYNX
// rotations (free Euler parameters), spherical joints (a shared XYZ node without a DOF hinge),
// HINGEs with released or rigid e1, or released e2, e3 (unless all three are released, without
// stiffness: a measuring hinge), flexible or partly fixed beams, elements other than BEAM,
// BEAMNL, HINGE and L2MIN1, closed loops, prescribed motions, FORCE on LAMBDA nodes, partly
// fixed nodes, and mass models that do not move as a rigid body.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

#include "spacar/kinematics/data.hpp"
#include "spacar/model/system.hpp"
#include "spacar/recursive/tree.hpp"

namespace spacar {

class SpatialTree : public RecursiveTree {
 public:
  // The tree of the system if it is one, else nullptr and (if why is given) the reason. The
  // body geometry and inertia are taken at the positions in data, which must satisfy the
  // constraints (a solved state).
  static std::unique_ptr<SpatialTree> detect(const System& sys, const Data& data, std::string* why = nullptr);

 private:
  using Vec3 = Eigen::Vector3d;
  using Mat3 = Eigen::Matrix3d;
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  using Quat = Eigen::Vector4d;  // Euler parameters (λ0, λ1, λ2, λ3)
  // Spatial vectors are (angular; linear) in body coordinates: origin at the body's pin, axes
  // those of the world rotated by the body's rotation since the reference state.
  struct Body {
    int parent = -1;              // index into bodies_ (parents first), −1: the ground
    int dof = 0;                  // position of the hinge rotation in q
    double sign = 1.0;            // joint angle u = sign · (q − offset) (the hinge may point to the parent)
    double offset = 0.0;          // the hinge rotation at the reference state
    double stiffness = 0.0, damping = 0.0;  // hinge σ = S e + D ė, joint torque −σ
    Vec3 axis;                    // unit joint axis, the same in the parent's and the body's coordinates
    Vec3 r;                       // pin in the parent's coordinates (ground: the world)
    Mat6 inertia;                 // about the pin, in body coordinates
    Vec3 torque = Vec3::Zero();   // constant body-fixed torque (TORQUEL), body coordinates
    // Work of one evaluation.
    Mat3 E;                       // parent coordinates → body coordinates
    Mat3 R;                       // body coordinates → world
    Quat lambda;                  // Euler parameters of R
    Vec3 pin;                     // world position of the pin
    double ud = 0.0, tau = 0.0, u = 0.0, d = 0.0;
    Vec6 v, bias, pA, a, U;
    Mat6 IA;
  };
  // A coordinate moving with a body: an XYZ node at body point b, or a LAMBDA node turned by the
  // body from its reference parameters.
  struct Follower {
    int coord = 0, body = 0;
    bool point = true;
    Vec3 b = Vec3::Zero();        // body coordinates of the point (XYZ)
    Quat lambda0 = Quat::Zero();  // Euler parameters at the reference state (LAMBDA)
  };
  // A constant world-direction load (FORCE) at point b of a body.
  struct Load {
    int body = 0;
    Vec3 b, force;
  };
  class Builder;

  void outward(const double* q, const double* qd) override;
  void applied_loads() override;
  bool articulate() override;
  void accelerations(double* qdd) override;
  void move_coordinates(Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd) const override;

  // Motion vectors from the parent's coordinates to the body's; force vectors back (the transpose).
  static Vec6 to_child(const Body& bd, const Vec6& m);
  static Vec6 to_parent(const Body& bd, const Vec6& f);
  // The body's (articulated) inertia I, body coordinates, added to its parent's in the parent's.
  static void add_inertia_to_parent(const Body& bd, const Mat6& I, Mat6& parent);

  std::vector<Body> bodies_;
  std::vector<Follower> followers_;
  std::vector<Load> loads_;
  Vec6 base_acceleration_ = Vec6::Zero();  // −gravity, the fictitious acceleration of the ground
};

}  // namespace spacar

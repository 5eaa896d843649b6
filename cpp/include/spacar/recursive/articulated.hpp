// One articulated-body algorithm over two algebras (formulation.md §7).
//
// A tree of rigid bodies, each turned about its pin by one revolute joint, solved in O(N) by
// the articulated-body algorithm: outwards the bodies' placements, velocities and bias terms,
// inwards the articulated inertias, outwards the accelerations. The passes are written once;
// the algebra (planar_tree.hpp: 3-vectors (ω, vx, vy); spatial_tree.hpp: 6-vectors (ω; v))
// supplies the vectors, the transforms between a body's and its parent's coordinates, the cross
// products and the joint's motion subspace, as Pinocchio runs one ABA over its joint types.
//
// Each body is split, as Pinocchio's JointModel and JointData: BodyModel holds what detect()
// found (joint, pin, inertia), BodyData the work of one evaluation.
//
// An Algebra provides the types Point (a pin), Vector (motion and force vectors), Inertia and
// Frame (a body's rotation relative to its parent and in the world), and the static functions
//   joint_angle(m, parent, q, qd, d)   the joint's rotation; sets d.ud, d.tau
//   place(m, parent, theta, d, world)  d.frame relative to the parent; with `world` (or, in a
//                                      spatial tree without loads, floating base or loops, only
//                                      at its outputs) its world rotation and d.pin too
//   joint_motion(m, ud)                S u̇, the joint's motion in body coordinates
//   to_child(m, frame, v)              motion vectors, parent → body coordinates
//   to_parent(m, frame, f)             force vectors, body → parent coordinates
//   add_inertia_to_parent(m, frame, I, parent)
//   bias(m, v, ud)                     v ×ₘ S u̇
//   cross_force(v, f)                  v ×* f
//   joint_column(m, I), joint_component(m, f), add_joint_acceleration(m, udd, a)   I S, Sᵀ f, a += S ü
//   dof_acceleration(m, a, udd)        q̈ of the body's degree of freedom
//   joint_acceleration(m, a, qdd)      its inverse: ü from q̈ and the body's acceleration a before S ü
#pragma once

#include <Eigen/Dense>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "spacar/errors.hpp"
#include "spacar/recursive/tree.hpp"

namespace spacar {

// A body's constants: its joint to the parent, its pin and its inertia.
template <class Algebra>
struct BodyModel {
  using Vector = typename Algebra::Vector;
  int parent = -1;              // index into the bodies (parents first), −1: the ground
  int dof = 0;                  // position of the joint's coordinate in q
  bool absolute = false;        // q is the body's rotation (a planar DYNX), else a hinge's
  bool prismatic = false;       // the joint slides along its axis (spatial), else it turns
  bool free = false;            // the root of a floating base: no joint, six DOFs (ArticulatedTree's free_* hooks)
  double sign = 1.0;            // hinge: joint angle u = sign · q + offset (the hinge may point to the parent)
  double offset = 0.0;          // absolute: the body's rotation is q − offset
  double stiffness = 0.0, damping = 0.0;  // hinge σ = S e + D ė, joint torque −σ
  typename Algebra::Axis axis = Algebra::Axis::Zero();  // the joint's axis (in the plane: its normal)
  typename Algebra::Point r = Algebra::Point::Zero();  // pin in the parent's coordinates (ground: the world)
  typename Algebra::Inertia inertia = Algebra::Inertia::Zero();  // about the pin, in body coordinates
  Vector load = Vector::Zero();  // constant body-fixed force vector (TORQUEL), body coordinates
};

// A body's work of one evaluation.
template <class Algebra>
struct BodyData {
  using Vector = typename Algebra::Vector;
  typename Algebra::Frame frame;  // rotation relative to the parent and in the world (see place)
  typename Algebra::Point pin;    // world position of the pin (see place)
  double ud = 0.0;   // joint rate u̇
  double tau = 0.0;  // joint torque
  double u = 0.0;    // joint force left after the bias forces (inverse dynamics: the torque on the body's rotation)
  double d = 0.0;    // the joint's articulated inertia Sᵀ Iᴬ S
  double inv_d = 0.0;  // 1 / d
  Vector v, bias, pA, a, U;
  typename Algebra::Inertia IA;
};

// The joint angle of a hinge, with its rate and torque (τ_q = −σ).
template <class Algebra>
double hinge_angle(const BodyModel<Algebra>& m, const double* q, const double* qd, BodyData<Algebra>& d) {
  d.ud = m.sign * qd[m.dof];
  d.tau = -m.sign * (m.stiffness * q[m.dof] + m.damping * qd[m.dof]);
  return m.sign * q[m.dof] + m.offset;
}

// The loops closed on a tree (closed_loop.hpp), as the recognizer found them: the tree's
// coordinates are (q, the passive joints' coordinates), n_dof + dependent0.size() of them.
template <class Point>
struct TreeLoops {
  int n_dof = 0;                        // the system's DOFs
  std::vector<double> dependent0;       // the passive joints' coordinates at the recognition
  std::vector<std::string> dependent;   // and what they are (for messages)
  struct ClosurePoint {                 // a point of body a and of body b (or the ground, −1)
    int a, b;
    Point pa, pb;                       // in their body coordinates (the ground's: the world)
  };
  struct Cut {                          // a passive spatial HINGE between two placed bodies (or the ground)
    const ElementKernel* kernel = nullptr;   // the system's: the tree lives no longer than it
    std::array<int, 2> body{};               // of its LAMBDA nodes o1, o2 (index in the tree, or −1)
    std::array<Eigen::Vector4d, 2> lambda0;  // their Euler parameters at the recognition
    std::vector<int> rows;                   // its rigid deformations (1: e2, 2: e3)
    std::vector<double> value;               // and their values
    // e_r = (R_o1 axis) · (R_o2 across[r]) (formulation.md §4.10): o1's hinge axis e_x and, per
    // row, o2's e_z (e2) or −e_y (e3), in their bodies' coordinates (the ground's: world).
    Eigen::Vector3d axis;
    std::vector<Eigen::Vector3d> across;
  };
  std::vector<ClosurePoint> points;
  std::vector<Cut> cuts;
  bool closed() const { return !points.empty() || !cuts.empty(); }
  // A passive joint at `value`, described by `what`: its position in the tree's coordinates.
  int add_passive(int system_dofs, double value, std::string what) {
    dependent0.push_back(value);
    dependent.push_back(std::move(what));
    return system_dofs + static_cast<int>(dependent0.size()) - 1;
  }
};

template <class Algebra>
class ClosedLoopTree;

template <class Algebra>
class ArticulatedTree : public RecursiveTree {
 public:
  using Model = BodyModel<Algebra>;
  using BodyWork = BodyData<Algebra>;
  using Vector = typename Algebra::Vector;
  using Inertia = typename Algebra::Inertia;

  using Loops = TreeLoops<typename Algebra::Point>;

  int n_bodies() const { return static_cast<int>(bodies_.size()); }
  const Loops& loops() const { return loops_; }

  bool solve(const double* q, const double* qd, double* qdd) final {
    if (!outward(q, qd)) return false;
    applied_loads();
    return articulate() && accelerations(q, qd, qdd);
  }

  void inverse_dynamics(const double* q, const double* qd, const double* qdd, double* force) final {
    if (!outward(q, qd))
      throw InputError("inverse_dynamics: the floating base's three Euler parameters have a norm of 1 or more");
    applied_loads();
    forces(q, qd, qdd, force);
  }

 protected:
  // Adds a body (its parent placed before it).
  void add_body(const Model& m) {
    bodies_.push_back(m);
    work_.emplace_back();
  }
  // The applied loads on the bodies, subtracted from their bias forces.
  virtual void applied_loads() = 0;
  // A floating base (the root with BodyModel::free): its frame, pin and velocity v (d.frame,
  // d.pin, d.v) at (q, q̇), false if q is no orientation; q̈ of its DOFs from its acceleration relative to the ground's
  // (body coordinates, without the ground's fictitious −g); that acceleration from q̈; the
  // generalized forces of its DOFs from the wrench it carries (body coordinates, at its pin).
  virtual bool free_body_motion(const double*, const double*, BodyWork&) { return true; }
  virtual void free_body_qdd(const double*, const double*, const BodyWork&, const Vector&, double*) {}
  virtual Vector free_body_acceleration(const double*, const double*, const double*, const BodyWork&) {
    return Vector::Zero();
  }
  virtual void free_forces(const double*, const BodyWork&, const Vector&, double*) {}

  std::vector<Model> bodies_;
  std::vector<BodyWork> work_;
  Vector base_acceleration_ = Vector::Zero();  // −gravity, the fictitious acceleration of the ground
  Loops loops_;  // loops closed on the tree, if any (then ClosedLoopTree runs it)
  // Whether outward() places the bodies in the world too (rotations, Euler parameters, pins): a
  // tree sets it false when nothing in its passes reads them (no loads, floating base or loops);
  // its move_coordinates then places them from the frames relative to the parents.
  bool world_frames_ = true;
  friend class ClosedLoopTree<Algebra>;  // runs the passes below in the tree's coordinates

  // The passes, for the trees that combine them otherwise (closed_loop.hpp: loops closed on a tree).
  // Outwards: placements, velocities, velocity-product accelerations and the bias forces of the
  // bodies' inertia, with the joint torques; the articulated inertias start as the bodies'. False
  // if a floating base's q is no orientation. `placed`: the bodies are placed at q already (by
  // place(q, ...): the loops' last Newton iteration), their frames are kept.
  bool outward(const double* q, const double* qd, bool placed = false) {
    for (size_t i = 0; i < bodies_.size(); ++i) {
      const Model& m = bodies_[i];
      BodyWork& d = work_[i];
      const BodyWork* p = m.parent < 0 ? nullptr : &work_[m.parent];
      if (m.free) {
        if (!free_body_motion(q, qd, d)) return false;
        d.ud = d.tau = 0.0;
        d.bias = Vector::Zero();
      } else {
        const double theta = Algebra::joint_angle(m, p, q, qd, d);  // rotation relative to the parent
        if (!placed) Algebra::place(m, p, theta, d, world_frames_);
        Vector v = Algebra::joint_motion(m, d.ud);
        if (p) v += Algebra::to_child(m, d.frame, p->v);
        d.v = v;
        d.bias = Algebra::bias(m, v, d.ud);
      }
      const Vector& v = d.v;
      d.IA = m.inertia;
      d.pA = Algebra::cross_force(v, m.inertia * v) - m.load;
    }
    return true;
  }

  // Outwards: the placements alone (frames and pins; qd only for the joints' own records), no
  // velocities, bias terms or inertias: the loops' Newton iterations (closed_loop.hpp) need no
  // more. Trees without a floating base only (loops on one are refused).
  void place(const double* q, const double* qd) {
    for (size_t i = 0; i < bodies_.size(); ++i) {
      const Model& m = bodies_[i];
      const BodyWork* p = m.parent < 0 ? nullptr : &work_[m.parent];
      Algebra::place(m, p, Algebra::joint_angle(m, p, q, qd, work_[i]), work_[i]);
    }
  }

  // Inwards: articulated inertias and bias forces; false if a joint's articulated inertia is not
  // positive.
  bool articulate() {
    for (int i = static_cast<int>(bodies_.size()) - 1; i >= 0; --i) {
      const Model& m = bodies_[i];
      BodyWork& d = work_[i];
      if (m.free) continue;  // the root: its articulated inertia is solved whole (accelerations)
      d.U = Algebra::joint_column(m, d.IA);
      d.d = Algebra::joint_component(m, d.U);
      // Not positive: a body that moves no mass. Not finite (a trial state out of range): the
      // integrator rejects the non-finite q̈ like the general path's.
      if (d.d <= 0.0) return false;
      // One division, not one per entry of U Uᵀ / d, and none in the outward pass of the
      // accelerations, whose chain from the root to the leaves waits for each.
      d.inv_d = 1.0 / d.d;
      d.u = d.tau - Algebra::joint_component(m, d.pA);
      if (m.parent < 0) continue;
      const Inertia Ia = d.IA - (d.U * d.U.transpose()) * d.inv_d;
      const Vector pa = d.pA + Ia * d.bias + d.U * (d.u * d.inv_d);
      BodyWork& p = work_[m.parent];
      Algebra::add_inertia_to_parent(m, d.frame, Ia, p.IA);
      p.pA += Algebra::to_parent(m, d.frame, pa);
    }
    return true;
  }

  // Outwards: joint and body accelerations (relative to the fictitious acceleration −g of the
  // ground), q̈; false if a floating base's articulated inertia is not positive definite.
  bool accelerations(const double* q, const double* qd, double* qdd) {
    for (size_t i = 0; i < bodies_.size(); ++i) {
      const Model& m = bodies_[i];
      BodyWork& d = work_[i];
      Vector a = Algebra::to_child(m, d.frame, m.parent < 0 ? base_acceleration_ : work_[m.parent].a) + d.bias;
      if (m.free) {  // IA a + pA = 0: no joint holds it
        const Eigen::LLT<Inertia> llt(d.IA);
        if (llt.info() != Eigen::Success) return false;
        d.a = -llt.solve(d.pA);
        free_body_qdd(q, qd, d, d.a - a, qdd);
        continue;
      }
      const double udd = (d.u - d.U.dot(a)) * d.inv_d;
      Algebra::add_joint_acceleration(m, udd, a);
      d.a = a;
      qdd[m.dof] = Algebra::dof_acceleration(m, a, udd);
    }
    return true;
  }

  // Outwards at the placement and velocities of the last outward(): the bodies' accelerations d.a
  // for the joint accelerations q̈, from the ground's acceleration `base` (−g, or zero), with the
  // velocity-product terms d.bias if `velocity`.
  void accelerate(const double* q, const double* qd, const double* qdd, const Vector& base, bool velocity) {
    for (size_t i = 0; i < bodies_.size(); ++i) {
      const Model& m = bodies_[i];
      BodyWork& d = work_[i];
      Vector a = Algebra::to_child(m, d.frame, m.parent < 0 ? base : work_[m.parent].a);
      if (velocity) a += d.bias;
      if (m.free) a += free_body_acceleration(q, qd, qdd, d);
      else Algebra::add_joint_acceleration(m, Algebra::joint_acceleration(m, a, qdd), a);
      d.a = a;
    }
  }

  // Inwards: the generalized forces of the DOFs that hold the bodies' forces d.pA (body
  // coordinates, at their pins; summed into the parents on the way), less the joints' springs
  // and dampers if `joint_loads`. By virtual work: a hinge's q is its angle (u = sign q + offset);
  // a planar body's absolute rotation q (a DYNX BETA) turns its joint by q − θ_parent, so its
  // torque also acts on the parent's rotation, which the parent's own joint and its ancestors'
  // hinges carry (d.u holds what acts on a body's rotation from its subtree).
  void joint_forces(const double* q, double* force, bool joint_loads) {
    for (BodyWork& d : work_) d.u = 0.0;
    for (int i = static_cast<int>(bodies_.size()) - 1; i >= 0; --i) {
      const Model& m = bodies_[i];
      BodyWork& d = work_[i];
      if (m.free) {  // the wrench the base's six DOFs carry
        free_forces(q, d, d.pA, force);
        continue;
      }
      const double torque = Algebra::joint_component(m, d.pA) - (joint_loads ? d.tau : 0.0);
      BodyWork* p = m.parent < 0 ? nullptr : &work_[m.parent];
      if (p) p->pA += Algebra::to_parent(m, d.frame, d.pA);
      if (m.absolute) {
        force[m.dof] = torque + d.u;
        if (p) p->u -= torque;
      } else {
        force[m.dof] = m.sign * (torque + d.u);
        if (p) p->u += d.u;
      }
    }
  }

  // The inverse dynamics at the placement, velocities and loads of the last outward() and
  // applied_loads(): outwards the accelerations the given q̈ make, and each body's force
  // f = I a + pA (its bias forces of inertia less the applied loads); inwards the joints' share.
  void forces(const double* q, const double* qd, const double* qdd, double* force) {
    accelerate(q, qd, qdd, base_acceleration_, true);
    for (size_t i = 0; i < bodies_.size(); ++i) work_[i].pA += bodies_[i].inertia * work_[i].a;
    joint_forces(q, force, true);
  }

  // M(q) u at the placement of the last outward(): the joint forces of the accelerations u alone
  // (no gravity, no velocities, no loads). Overwrites d.a and d.pA. Fixed bases only (a floating
  // base's acceleration is not linear in its q̈ alone).
  void mass_times(const double* u, double* out) {
    accelerate(nullptr, nullptr, u, Vector::Zero(), false);
    for (size_t i = 0; i < bodies_.size(); ++i) work_[i].pA = bodies_[i].inertia * work_[i].a;
    joint_forces(nullptr, out, false);
  }
};

}  // namespace spacar

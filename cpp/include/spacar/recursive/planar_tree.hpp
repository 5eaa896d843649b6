// Recursive dynamics of planar open trees of rigid bodies (formulation.md §7).
//
// A planar model of rigid PLBEAMs (every deformation fixed) connected as an open tree is a
// kinematic tree of rigid bodies with revolute joints: beams sharing a BETA node are one body, a
// body hangs from its parent at a shared (or fixed) XY node, its pin, and turns about it by the
// rotation of a PLHINGE to the parent (DYNE) or by its own rotation (DYNX on one of its BETA
// nodes). Released PLHINGEs are springs and dampers between bodies; FORCE and gravity load it.
// The articulated-body algorithm (articulated.hpp) runs in planar algebra.
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "spacar/recursive/articulated.hpp"

namespace spacar {

// Planar spatial algebra: vectors (ω, vx, vy) in body coordinates, origin at the body's pin,
// axes those of the world rotated by the body's rotation φ since the reference state.
struct PlanarAlgebra {
  using Point = Eigen::Vector2d;
  using Vector = Eigen::Vector3d;
  using Inertia = Eigen::Matrix3d;
  struct Axis {  // the plane's normal
    static Axis Zero() { return {}; }
  };
  struct Frame {
    double c = 1.0, s = 0.0;    // cos, sin of the rotation relative to the parent
    double cw = 1.0, sw = 0.0;  // cos, sin of φ
    double phi = 0.0;           // rotation since the reference state
  };
  using Model = BodyModel<PlanarAlgebra>;
  using Work = BodyData<PlanarAlgebra>;

  static double joint_angle(const Model& m, const Work* p, const double* q, const double* qd, Work& d) {
    if (!m.absolute) return hinge_angle(m, q, qd, d);
    d.ud = qd[m.dof] - (p ? p->v[0] : 0.0);  // q is the rotation of a BETA node of the body
    d.tau = 0.0;
    return q[m.dof] - m.offset - (p ? p->frame.phi : 0.0);
  }

  // `world`: always (a child's angle is read from its parent's absolute rotation).
  static void place(const Model& m, const Work* p, double theta, Work& d, bool /*world*/ = true) {
    Frame& f = d.frame;
    f.c = std::cos(theta);
    f.s = std::sin(theta);
    if (!p) {
      f.phi = theta;
      f.cw = f.c;
      f.sw = f.s;
      d.pin = m.r;
      return;
    }
    const Frame& pf = p->frame;
    f.phi = pf.phi + theta;
    f.cw = pf.cw * f.c - pf.sw * f.s;
    f.sw = pf.sw * f.c + pf.cw * f.s;
    d.pin = p->pin + Point(pf.cw * m.r.x() - pf.sw * m.r.y(), pf.sw * m.r.x() + pf.cw * m.r.y());
  }

  static Vector joint_motion(const Model&, double ud) { return {ud, 0.0, 0.0}; }

  static Vector to_child(const Model& m, const Frame& f, const Vector& v) {
    const double c = f.c, s = f.s, rx = m.r.x(), ry = m.r.y();
    return {v[0], (s * rx - c * ry) * v[0] + c * v[1] + s * v[2], (c * rx + s * ry) * v[0] - s * v[1] + c * v[2]};
  }

  // The transpose of to_child.
  static Vector to_parent(const Model& m, const Frame& f, const Vector& g) {
    const double c = f.c, s = f.s, rx = m.r.x(), ry = m.r.y();
    return {g[0] + (s * rx - c * ry) * g[1] + (c * rx + s * ry) * g[2], c * g[1] - s * g[2], s * g[1] + c * g[2]};
  }

  static void add_inertia_to_parent(const Model& m, const Frame& f, const Inertia& I, Inertia& parent) {
    const double c = f.c, s = f.s, rx = m.r.x(), ry = m.r.y();
    Inertia X;
    X << 1.0, 0.0, 0.0, s * rx - c * ry, c, s, c * rx + s * ry, -s, c;
    parent += X.transpose() * I * X;
  }

  static Vector bias(const Model&, const Vector& v, double ud) { return {0.0, ud * v[2], -ud * v[1]}; }

  static Vector cross_force(const Vector& v, const Vector& h) {
    return {-v[2] * h[1] + v[1] * h[2], -v[0] * h[2], v[0] * h[1]};
  }

  static Vector joint_column(const Model&, const Inertia& I) { return I.col(0); }
  static double joint_component(const Model&, const Vector& g) { return g[0]; }
  static void add_joint_acceleration(const Model&, double udd, Vector& a) { a[0] += udd; }
  static double dof_acceleration(const Model& m, const Vector& a, double udd) {
    return m.absolute ? a[0] : m.sign * udd;
  }
  static double joint_acceleration(const Model& m, const Vector& a, const double* qdd) {
    return m.absolute ? qdd[m.dof] - a[0] : m.sign * qdd[m.dof];
  }
};

class PlanarTree : public ArticulatedTree<PlanarAlgebra> {
 public:
  // The tree of the system if it is one, else nullptr and (if why is given) the reason. The
  // body geometry and inertia are taken at the positions in data, which must satisfy the
  // constraints (a solved state).
  static std::unique_ptr<PlanarTree> detect(const System& sys, const Data& data, std::string* why = nullptr);

  // Exact: the recursive Newton–Euler algorithm on dual numbers (planar_rnea.hpp,
  // rnea_derivatives.hpp).
  bool dynamics_derivatives(int n, const double* q, const double* qd, const double* tau, double* qdd, double* dq,
                            double* dqd, double* dtau) override;
  // The inverse dynamics on a scalar type S (double or dual numbers; planar_rnea.hpp, which
  // defines it): the closed loops' derivatives run it in the tree's coordinates.
  template <class S>
  void inverse_dynamics_on(const S* q, const S* qd, const S* qdd, S* force) const;

 private:
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

  void applied_loads() override;
  void move_coordinates(Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd) override;

  std::vector<Follower> followers_;
  std::vector<Load> loads_;
  std::vector<Spring> springs_;
};

}  // namespace spacar

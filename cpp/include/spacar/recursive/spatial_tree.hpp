// Recursive dynamics of spatial open trees of rigid bodies (formulation.md §7, the spatial
// counterpart of planar_tree.hpp).
//
// A spatial model of rigid BEAMs (every deformation fixed) connected as an open tree is a
// kinematic tree of rigid bodies with revolute and prismatic joints: beams sharing a LAMBDA node
// are one body (a joint's LAMBDA node on no beam is a body of its own, with the joint's point on
// its side), a body hangs from its parent at a shared (or fixed) XYZ node, its pin, and turns
// about it by the rotation e1 of a HINGE to the parent (DYNE, e2 and e3 fixed); the pin may be
// its grandparent's too (joints at one origin). A BEARING with DYNE e1 and e2 … e6 rigid slides
// the body's own point (its pin) from a point of the parent along the axis, without turning.
// MASS (point masses, inertia tensors on LAMBDA nodes), EMASS, FORCE on points, TORQUEL, GRAVITY
// and the joints' ESTIFF and EDAMPP load it. The equations of motion are solved in O(N) by the
// articulated-body algorithm (articulated.hpp) in spatial algebra, with explicit positions instead
// of Newton's method: the same equations as the constraint formulation (each body's spatial
// inertia is the element and nodal mass matrices projected on its rigid motions). A floating base
// (an XYZ node and a free LAMBDA node, all DYNX but the dependent Euler parameter, on one body) is
// the free root: no joint, six DOFs (FreeBase; ArticulatedTree's free_* hooks).
//
// Closed loops (closed_loop.hpp): a HINGE (BEARING) with released e1 is a passive joint, whose
// coordinate the loops determine. The tree takes such joints like the DOF ones, after them in its
// coordinates; a loop closes where a body has a point another body (or the ground) placed first
// (a shared XYZ node: three constraints), or at a passive HINGE between two placed bodies, the
// cut (its rigid misalignments: up to two constraints). detect() records them in loops().
//
// Refused (the general path runs, and detect() says why): planar models (planar_tree.hpp), other
// DYNX coordinates, spherical joints (a shared XYZ node without a DOF hinge), HINGEs with rigid e1,
// or released e2, e3 outside a loop's cut (unless all three are released, without stiffness: a
// measuring hinge), flexible or partly fixed beams, elements other than BEAM, BEAMNL, HINGE,
// BEARING and L2MIN1, BEARINGs other than prismatic joints, loops without a passive joint or cut
// at a sliding one, loops on a floating base, prescribed motions, FORCE on LAMBDA nodes, partly
// fixed nodes, and mass models that do not move as a rigid body.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "spacar/elements/spatial.hpp"
#include "spacar/recursive/articulated.hpp"
#include "spacar/recursive/free_base.hpp"

namespace spacar {

namespace tree_detail {

// The Euler parameters of the composed rotation R(p ⊗ r) = R(p) R(r).
inline Eigen::Vector4d compose(const Eigen::Vector4d& p, const Eigen::Vector4d& r) {
  const Eigen::Vector3d pv = p.tail<3>(), rv = r.tail<3>();
  Eigen::Vector4d out;
  out[0] = p[0] * r[0] - pv.dot(rv);
  out.tail<3>() = p[0] * rv + r[0] * pv + pv.cross(rv);
  return out;
}

}  // namespace tree_detail

// Spatial algebra: vectors (angular; linear) in body coordinates, origin at the body's pin,
// axes those of the world rotated by the body's rotation since the reference state.
struct SpatialAlgebra {
  using Point = Eigen::Vector3d;
  using Vector = Eigen::Matrix<double, 6, 1>;
  using Inertia = Eigen::Matrix<double, 6, 6>;
  using Axis = Eigen::Vector3d;  // unit joint axis, the same in the parent's and the body's coordinates
  struct Frame {
    Eigen::Matrix3d E;       // parent coordinates → body coordinates
    Eigen::Matrix3d R;       // body coordinates → world (place_world)
    Eigen::Vector4d lambda;  // Euler parameters (λ0, λ1, λ2, λ3) of R (place_world)
    Eigen::Vector3d r;       // the pin from the parent's, in the parent's coordinates (a sliding joint's moves)
    double ch = 1.0, sh = 0.0;  // cosine and sine of half the hinge's angle (λ relative to the parent)
  };
  using Model = BodyModel<SpatialAlgebra>;
  using Work = BodyData<SpatialAlgebra>;

  static double joint_angle(const Model& m, const Work*, const double* q, const double* qd, Work& d) {
    return hinge_angle(m, q, qd, d);
  }

  // The rotation by the angle of cosine c and sine s about the unit axis k (Rodrigues), written
  // out: it runs for every body at every right-hand side and derivative.
  static Eigen::Matrix3d axis_rotation(const Eigen::Vector3d& k, double c, double s) {
    const double one_c = 1.0 - c;
    Eigen::Matrix3d R;
    R << c + one_c * k[0] * k[0], one_c * k[0] * k[1] - s * k[2], one_c * k[0] * k[2] + s * k[1],
         one_c * k[1] * k[0] + s * k[2], c + one_c * k[1] * k[1], one_c * k[1] * k[2] - s * k[0],
         one_c * k[2] * k[0] - s * k[1], one_c * k[2] * k[1] + s * k[0], c + one_c * k[2] * k[2];
    return R;
  }

  // The body's rotation relative to its parent and its pin: a hinge turns by θ about its axis, a
  // sliding joint moves the pin by θ along its axis without turning. `world`: its rotation, Euler
  // parameters and pin in the world too (place_world), which the passes of a right-hand side
  // need only with loads, a floating base or loops (ArticulatedTree::world_frames_).
  static void place(const Model& m, const Work* p, double theta, Work& d, bool world = true) {
    Frame& f = d.frame;
    f.r = m.r;
    if (m.prismatic) {
      f.r += theta * m.axis;
      f.E.setIdentity();
      f.ch = 1.0;
      f.sh = 0.0;
    } else {
      const double ch = std::cos(0.5 * theta), sh = std::sin(0.5 * theta);  // of the half angle, for λ too
      const double c = 1.0 - 2.0 * sh * sh, s = 2.0 * sh * ch;
      f.E = axis_rotation(m.axis, c, -s);  // the transpose: parent → body
      f.ch = ch;
      f.sh = sh;
    }
    if (world) place_world(m, p, d);
  }
  // The body's rotation, Euler parameters and pin in the world, from its placement relative to
  // its parent (place) and the parent's in the world.
  static void place_world(const Model& m, const Work* p, Work& d) {
    Frame& f = d.frame;
    const Eigen::Vector4d q_rel(f.ch, f.sh * m.axis[0], f.sh * m.axis[1], f.sh * m.axis[2]);
    if (!p) {
      f.R = f.E.transpose();
      f.lambda = q_rel;
      d.pin = f.r;
    } else {
      f.R.noalias() = p->frame.R * f.E.transpose();
      f.lambda = tree_detail::compose(p->frame.lambda, q_rel);
      d.pin = p->pin + p->frame.R * f.r;
    }
  }

  // S u̇: an angular rate about the axis, or (prismatic) a linear one along it.
  static Vector joint_motion(const Model& m, double ud) {
    Vector v = Vector::Zero();
    v.segment<3>(m.prismatic ? 3 : 0) = ud * m.axis;
    return v;
  }

  static Vector to_child(const Model&, const Frame& f, const Vector& v) {
    Vector out;
    out.head<3>() = f.E * v.head<3>();
    out.tail<3>() = f.E * (v.tail<3>() + v.head<3>().cross(f.r));
    return out;
  }

  // The transpose of to_child.
  static Vector to_parent(const Model&, const Frame& f, const Vector& g) {
    Vector out;
    out.tail<3>() = f.E.transpose() * g.tail<3>();
    out.head<3>() = f.E.transpose() * g.head<3>() + f.r.cross(out.tail<3>());
    return out;
  }

  // Xᵀ I X with X = [E 0; −E r̃ E] (parent → body, motion vectors), by blocks: rotated,
  // I' = [A B; Bᵀ C] in the parent's axes, then moved to its origin,
  // [A + r̃Bᵀ + (r̃Bᵀ)ᵀ − r̃Cr̃, B + r̃C; (B + r̃C)ᵀ, C] — a third of the full 6×6 products.
  static void add_inertia_to_parent(const Model&, const Frame& f, const Inertia& I, Inertia& parent) {
    using Mat3 = Eigen::Matrix3d;
    const Mat3& E = f.E;
    const Mat3 Ib = I.topLeftCorner<3, 3>(), Bb = I.topRightCorner<3, 3>(), Cb = I.bottomRightCorner<3, 3>();
    const Mat3 A = E.transpose() * Ib * E, B = E.transpose() * Bb * E, C = E.transpose() * Cb * E;
    // The products with r̃ by cross products (r̃ M: r × each column; M r̃: each row × r), two thirds
    // of the multiplications of the 3×3 products.
    const Eigen::Vector3d& r = f.r;
    Mat3 rC, rBt, rCr;
    for (int j = 0; j < 3; ++j) {
      rC.col(j) = r.cross(C.col(j));
      rBt.col(j) = r.cross(B.row(j).transpose());
    }
    for (int i = 0; i < 3; ++i) rCr.row(i) = rC.row(i).transpose().cross(r).transpose();
    parent.topLeftCorner<3, 3>() += A + rBt + rBt.transpose() - rCr;
    const Mat3 coupling = B + rC;
    parent.topRightCorner<3, 3>() += coupling;
    parent.bottomLeftCorner<3, 3>() += coupling.transpose();
    parent.bottomRightCorner<3, 3>() += C;
  }

  // v ×ₘ S u̇ = (ω × s_ω; ω × s_v + v × s_ω).
  static Vector bias(const Model& m, const Vector& v, double ud) {
    const Eigen::Vector3d s = ud * m.axis;
    Vector b;
    if (m.prismatic) b << Eigen::Vector3d::Zero(), v.head<3>().cross(s);
    else b << v.head<3>().cross(s), v.tail<3>().cross(s);
    return b;
  }

  static Vector cross_force(const Vector& v, const Vector& h) {
    const Eigen::Vector3d w = v.head<3>(), vl = v.tail<3>();
    Vector out;
    out << w.cross(h.head<3>()) + vl.cross(h.tail<3>()), w.cross(h.tail<3>());
    return out;
  }

  static Vector joint_column(const Model& m, const Inertia& I) {
    return m.prismatic ? Vector(I.rightCols<3>() * m.axis) : Vector(I.leftCols<3>() * m.axis);
  }
  static double joint_component(const Model& m, const Vector& g) {
    return m.axis.dot(m.prismatic ? g.tail<3>() : g.head<3>());
  }
  static void add_joint_acceleration(const Model& m, double udd, Vector& a) {
    a.segment<3>(m.prismatic ? 3 : 0) += udd * m.axis;
  }
  static double dof_acceleration(const Model& m, const Vector&, double udd) { return m.sign * udd; }
  static double joint_acceleration(const Model& m, const Vector&, const double* qdd) { return m.sign * qdd[m.dof]; }
};

class SpatialTree : public ArticulatedTree<SpatialAlgebra> {
 public:
  // The tree of the system if it is one, else nullptr and (if why is given) the reason. The
  // body geometry and inertia are taken at the positions in data, which must satisfy the
  // constraints (a solved state).
  static std::unique_ptr<SpatialTree> detect(const System& sys, const Data& data, std::string* why = nullptr);

  // Exact and analytic (spatial_derivatives.cpp): ∂τ/∂q, ∂τ/∂q̇ and M from passes over the tree in
  // world axes, ∂q̈/∂(q, q̇) = −M⁻¹ ∂τ/∂(q, q̇).
  bool dynamics_derivatives(int n, const double* q, const double* qd, const double* tau, double* qdd, double* dq,
                            double* dqd, double* dtau) override;
  // The inverse dynamics on a scalar type S (double or dual numbers; spatial_rnea.hpp, which
  // defines it), without a floating base: the closed loops' derivatives run it in the tree's
  // coordinates.
  template <class S>
  void inverse_dynamics_on(const S* q, const S* qd, const S* qdd, S* force) const;

 private:
  using Vec3 = Eigen::Vector3d;
  using Quat = Eigen::Vector4d;
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

  void applied_loads() override;
  // A floating base (spatial_tree.cpp): the root body's origin (XYZ node, DYNX) and orientation
  // (LAMBDA node, three Euler parameters DYNX, the dependent one calculable: FreeRotation).
  // FreeBaseMaps' dependent (0..3: the calculable parameter) and sign (of the dependent
  // parameter, which stays away from 0: see repartition).
  struct FreeBase : FreeBaseMaps {
    int x_dof = -1;                  // q index of the origin's x (y, z follow)
    std::array<int, 3> lambda_dof{};  // q indices of the three independent Euler parameters
    Eigen::Matrix3d R0 = Eigen::Matrix3d::Identity();  // R(λ) at the recognition (the body's reference)
    Eigen::Vector4d lambda0 = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);
  };
  Eigen::Vector4d base_lambda(const double* q) const;
  Eigen::Vector4d base_lambda_rate(const Eigen::Vector4d& l, const double* qd) const;
  bool free_body_motion(const double* q, const double* qd, BodyWork& d) override;
  void free_body_qdd(const double* q, const double* qd, const BodyWork& d, const Vector& acc, double* qdd) override;
  Vector free_body_acceleration(const double* q, const double* qd, const double* qdd, const BodyWork& d) override;
  void free_forces(const double* q, const BodyWork& d, const Vector& f, double* force) override;
  void move_coordinates(Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd) override;

  std::vector<Follower> followers_;
  std::vector<Load> loads_;
  bool floating_ = false;
  FreeBase base_;

  // A body's work in dynamics_derivatives: world axes at the world origin.
  struct WorldBody {
    Eigen::Matrix3d R;                     // body → world (SpatialAlgebra::place's, without λ)
    Eigen::Vector3d p;                     // the pin
    Eigen::Matrix<double, 6, 1> S, v, a, parent_v, parent_a;
    Eigen::Matrix<double, 6, 1> u, z;      // S × v_λ and u × v_λ − S × a_λ
    Eigen::Matrix<double, 6, 1> f, F;      // the body's force, then its subtree's; F: at q̈ = 0
    Eigen::Matrix<double, 6, 6> I;         // the inertia about the world origin
    Eigen::Matrix<double, 6, 6> Ic, QmB;   // over the subtree: Σ I and Σ (I (v ×) − B)
    Eigen::Matrix<double, 6, 3> L;         // over the subtree: the world-direction loads' matrices
    Eigen::Matrix<double, 6, 1> IS, QmBS;  // Ic S and (Σ (I (v ×) − B))ᵀ S
    Eigen::Vector3d LS;                    // Lᵀ S
  };
  struct DerivativeWork {  // kept between the states of a batch
    std::vector<WorldBody> bodies;
    Eigen::VectorXd bias, tau_t;
    Eigen::MatrixXd M, Linv, dtau_dq, dtau_dqd;
    std::vector<double> inverse, qdd_t, dq_t, dqd_t;  // a floating base's results in (ν, joints)
  };
  DerivativeWork derivative_work_;
};

}  // namespace spacar

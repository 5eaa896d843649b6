// Spatial rigid trees (spatial_tree.hpp): the recognizer, the applied loads, the coordinates
// moving with the bodies.
#include "spacar/recursive/spatial_tree.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "spacar/model/catalogue.hpp"
#include "spacar/model/topology.hpp"
#include "tree_common.hpp"

namespace spacar {

namespace {

using tree_detail::kGround;
using tree_detail::NodeInfo;

using tree_detail::compose;

// E(λ)ᵀ ω = (0, ω) ⊗ λ.
Eigen::Vector4d euler_E_transpose_times(const Eigen::Vector4d& l, const Eigen::Vector3d& w) {
  Eigen::Vector4d out;
  FreeBaseMaps::e_transpose_times(l.data(), w.data(), out.data());
  return out;
}

// Rigid-motion row of a coordinate: its rate for the body twist (ω, v) at the pin (world axes
// at the reference state); b is an XYZ node's position relative to the pin, lambda a LAMBDA
// node's parameters (λ̇ = ½ E(λ)ᵀ ω).
Eigen::Matrix<double, 1, 6> rigid_row(NodeKind kind, int component, const Eigen::Vector3d& b,
                                      const Eigen::Vector4d& lambda) {
  Eigen::Matrix<double, 1, 6> row = Eigen::Matrix<double, 1, 6>::Zero();
  if (kind == NodeKind::Lambda) {
    row.head<3>() = 0.5 * euler_E(lambda).col(component).transpose();
  } else {  // ẋ = v + ω × b = v − b̃ ω
    row.head<3>() = -skew(b).row(component);
    row[3 + component] = 1.0;
  }
  return row;
}

}  // namespace

// Recognizes the tree in a system and fills a SpatialTree, step by step (tree_common.hpp); a
// step that finds the system is not a spatial rigid tree says why and stops.
class SpatialTree::Builder : public tree_detail::TreeBuilder<SpatialTree::Builder, SpatialAlgebra> {
 public:
  Builder(const System& sys, const Data& data, SpatialTree& tree)
      : TreeBuilder(sys, data, NodeKind::XYZ, NodeKind::Lambda), e_(data.e), tree_(tree) {}

  bool build() {
    return supported_classes() && read_coordinates() && read_nodes() &&
           read_elements("BEAM, BEAMNL, HINGE, BEARING or L2MIN1") && group_bodies() && place_bodies() &&
           attach_loads() && record_loops();
  }

 private:
  friend TreeBuilder;
  using Vec3 = Eigen::Vector3d;

  bool supported_classes() {
    if (sys_.n_dof() == 0) return refuse("no degrees of freedom");
    if (!sys_.x_dyn.empty() && !floating_base())
      return refuse("DYNX coordinates other than a floating base's (an XYZ node and a free LAMBDA node) are not "
                    "hinge joints");
    if (!sys_.x_input.empty() || !sys_.e_input.empty()) return refuse("prescribed motions (INPUTX, INPUTE)");
    if (!sys_.e_line.empty() || !sys_.e_nonholonomic.empty() || !sys_.e_kinematic.empty() || !sys_.y_defs.empty())
      return refuse("LINE, nonholonomic or kinematic deformations");
    return true;
  }

  // The DYNX coordinates of a floating base: an XYZ node's three and a free rotation's three
  // Euler parameters (FreeRotation), nothing else.
  bool floating_base() {
    if (sys_.free_rotations.size() != 1 || sys_.x_dyn.size() != 6) return false;
    const FreeRotation& fr = sys_.free_rotations.front();
    int point = -1, n_point = 0;
    for (int g : sys_.x_dyn) {
      if (g >= fr.coord && g < fr.coord + 4) continue;
      if (sys_.coord_node_kind[g] != NodeKind::XYZ) return false;
      const int id = sys_.coord_label[g][0];
      if (point != -1 && id != point) return false;
      point = id;
      ++n_point;
    }
    if (n_point != 3) return false;
    base_point_ = point;
    base_orientation_ = fr.node;
    return true;
  }

  // The floating base: the body of its LAMBDA node, with its XYZ node as its pin, the root.
  bool place_free_root(std::vector<int>& queue) {
    if (base_point_ < 0) return true;
    const int body = g_.body_of.count(base_orientation_) ? g_.body_of.at(base_orientation_) : -1;
    if (body < 0 || !g_.points[body].count(base_point_))
      return refuse("the floating base's nodes " + std::to_string(base_point_) + " and " +
                    std::to_string(base_orientation_) + " are not on one rigid body");
    const FreeRotation& fr = sys_.free_rotations.front();
    SpatialTree::FreeBase& b = tree_.base_;
    const int xc = nodes_.at(base_point_).coord;
    b.x_dof = static_cast<int>(std::lower_bound(sys_.x_dyn.begin(), sys_.x_dyn.end(), xc) - sys_.x_dyn.begin());
    for (int k = 0; k < 3; ++k) b.lambda_dof[k] = fr.dofs[k];
    b.dependent = fr.dependent;
    b.lambda0 = lambda(base_orientation_);
    b.sign = b.lambda0[fr.dependent] < 0.0 ? -1.0 : 1.0;
    b.R0 = euler_R(b.lambda0);
    tree_.floating_ = true;
    Model bd;
    bd.free = true;
    bd.dof = b.x_dof;
    Slide slide;
    slide.pin = base_point_;
    slide.free = true;
    if (!place(body, kGround, bd, "the floating base", slide)) return false;
    queue.push_back(body);
    return true;
  }

  bool read_coordinates() {
    for (int g = 0; g < sys_.nx; ++g) {
      const NodeKind kind = sys_.coord_node_kind[g];
      if (kind != NodeKind::XYZ && kind != NodeKind::Lambda) return refuse(sys_.coord_name(g) + " is planar");
    }
    return true;
  }

  // A revolute joint (DYNE e1, rigid e2 and e3), or a measuring hinge (all released, no law), or
  // a passive joint of a closed loop (released e1: its rotation follows from the loop; if a
  // misalignment is released too, the joint can only be where the loop is cut).
  bool read_hinge(int i, const SystemElement& se, const std::vector<int>& ids) {
    const int k = se.def_offset;
    const DefClass c1 = sys_.def_class[k], c2 = sys_.def_class[k + 1], c3 = sys_.def_class[k + 2];
    auto rigid_or_released = [](DefClass c) { return c == DefClass::Fixed || c == DefClass::Released; };
    if (c1 == DefClass::Released && c2 == DefClass::Released && c3 == DefClass::Released && !se.has_constitutive)
      return true;  // a measuring hinge: no constraint, no load
    if (c1 == DefClass::Released && rigid_or_released(c2) && rigid_or_released(c3)) {
      Hinge h{i, ids.front(), ids.back(), -1};
      h.passive = true;
      h.cut_only = c2 != DefClass::Fixed || c3 != DefClass::Fixed;
      hinges_.push_back(h);
      passive_ = true;
      return true;
    }
    if (c1 != DefClass::Dynamic || c2 != DefClass::Fixed || c3 != DefClass::Fixed)
      return refuse(element_name(se) + " is not a revolute joint (DYNE e1, rigid e2 and e3)");
    hinges_.push_back({i, ids.front(), ids.back(), hinge_dof(se)});
    return true;
  }

  // A prismatic joint: a BEARING sliding along its axis (DYNE e1, e2 … e6 rigid), or a measuring
  // one (all released, no law).
  bool read_other(int i, const SystemElement& se, const std::vector<int>& ids, const char* accepted) {
    if (element_catalogue()[se.type].family != ElementFamily::Bearing)
      return refuse(element_name(se) + " is not a " + accepted);
    const int k = se.def_offset;
    bool released = !se.has_constitutive, rigid = true;
    for (int a = 0; a < 6; ++a) {
      released = released && sys_.def_class[k + a] == DefClass::Released;
      if (a > 0) rigid = rigid && sys_.def_class[k + a] == DefClass::Fixed;
    }
    if (released) return true;
    const DefClass c1 = sys_.def_class[k];
    if ((c1 != DefClass::Dynamic && c1 != DefClass::Released) || !rigid)
      return refuse(element_name(se) + " is not a prismatic joint (DYNE e1, rigid e2 … e6)");
    hinges_.push_back({i, ids[1], ids[3], hinge_dof(se), false, ids[0], ids[2]});
    if (c1 == DefClass::Released) {  // a passive sliding joint of a closed loop
      hinges_.back().passive = true;
      passive_ = true;
    }
    return true;
  }

  // Loops close on the tree where it has passive joints (closed_loop.hpp).
  bool loops_allowed() const { return passive_; }

  // Bodies without a beam: a joint's moving LAMBDA node on no beam is a body of its own (a rotor,
  // a link whose centre of mass is its joint's origin, as URDF's Panda fingers), with the joint's
  // point on its side if that is on no beam either (a sliding joint's). They join the grouping as
  // beams without an element (−1).
  bool group_bodies() {
    std::set<int> on_beams;
    for (const auto& [i, ids] : beams_) on_beams.insert(ids.begin(), ids.end());
    auto loose = [&](int id) { return id >= 0 && !nodes_.at(id).fixed && !on_beams.count(id); };
    for (const Hinge& h : hinges_)
      for (const auto& [o, p] : {std::pair{h.a, h.pa}, std::pair{h.b, h.pb}}) {
        if (!loose(o)) continue;
        std::vector<int> ids = {o};
        if (loose(p)) ids.push_back(p);
        beams_.push_back({-1, ids});
        on_beams.insert(ids.begin(), ids.end());
      }
    return TreeBuilder::group_bodies();
  }

  Eigen::Vector4d lambda(int id) const { return x_.segment<4>(nodes_.at(id).coord); }

  // The joint of a DOF hinge, from the parent's end (forward: node o1) to the child's. The axis
  // follows from ∂e1/∂λ_o2 = 2 aᵀ E(λ_o2) (plus a multiple of λ_o2ᵀ): a = ½ E(λ_o2) (∂e1/∂λ_o2)ᵀ.
  bool hinge_joint(const Hinge& h, bool forward, int, Model& bd) {
    const SystemElement& se = sys_.elements[h.element];
    const int n = static_cast<int>(se.coords.size());
    Eigen::VectorXd xl(n), e(se.nd);
    Eigen::MatrixXd B(se.nd, n);
    for (int a = 0; a < n; ++a) xl[a] = x_[se.coords[a]];
    se.kernel->first_derivatives(xl.data(), e.data(), B.data());
    bd.dof = h.dof;
    if (h.passive) {  // after the DOFs in the tree's coordinates: (q, the dependent joints')
      bd.dof = tree_.loops_.add_passive(sys_.n_dof(), e_[se.def_offset], element_name(se));
    }
    bd.sign = forward ? 1.0 : -1.0;  // e1 turns (slides) o2's body relative to o1's
    bd.offset = -bd.sign * e_[se.def_offset];  // u = sign · (e1 − e1 at the reference state)
    if (h.pa >= 0) {  // sliding: the axis is ∂e1/∂x_p2, in the world's axes, which are both bodies' here
      bd.prismatic = true;
      bd.axis = B.block<1, 3>(0, 7).transpose().normalized();
    } else {
      bd.axis = (0.5 * euler_E(lambda(h.b)) * B.block<1, 4>(0, 4).transpose()).normalized();
    }
    if (se.has_constitutive) {
      bd.stiffness = se.S(0, 0);
      bd.damping = se.D(0, 0);
    }
    return true;
  }

  // Placed body i's pin moved to r from its parent's (TreeBuilder).
  void set_pin_offset(int i, const Point& r) { tree_.bodies_[i].r = r; }

  // Spatial bodies turn only about hinges.
  bool place_rotated(int, std::vector<int>&) { return true; }

  // The rigid-motion row of coordinate g for a body pinned at p0 (see rigid_row).
  Eigen::Matrix<double, 1, 6> rigid_row_of(int g, const Vec3& p0) const {
    const int id = sys_.coord_label[g][0];
    const NodeInfo& node = nodes_.at(id);
    if (node.kind == NodeKind::Lambda) return rigid_row(node.kind, g - node.coord, Vec3::Zero(), lambda(id));
    return rigid_row(node.kind, g - node.coord, point(id) - p0, Eigen::Vector4d::Zero());
  }

  // Adds the body to the tree under the placed body `parent_body` (or kGround) with its joint
  // `bd`: the pin, the inertia about it, the coordinates moving with it.
  bool place(int body, int parent_body, Model bd, const std::string& joint, const Slide& slide) {
    const int index = tree_.n_bodies();
    Vec3 p0;
    if (!attach(body, parent_body, bd, joint, index, p0, slide)) return false;
    Inertia I = Inertia::Zero();
    auto row = [&](int g) { return rigid_row_of(g, p0); };
    for (int i : g_.beams[body])
      if (i >= 0) I += tree_detail::element_inertia<6>(sys_.elements[i], x_, row);
    for (int id : g_.points[body]) {
      // A hinge's pin, or a point where a loop closes: its mass and loads move with the body that
      // placed it first.
      if (owner_.at(id) != index) continue;
      for (int c = 0; c < 3; ++c) {
        const int g = nodes_[id].coord + c;
        I += sys_.point_mass[g] * row(g).transpose() * row(g);
      }
      tree_.followers_.push_back({nodes_[id].coord, index, true, point(id) - p0, Eigen::Vector4d::Zero()});
    }
    for (int id : g_.orientations[body]) {
      tree_.followers_.push_back({nodes_[id].coord, index, false, Vec3::Zero(), lambda(id)});
      lambda_body_[nodes_[id].coord] = index;
    }
    for (const BodyInertia& bi : sys_.bodies) {  // inertia tensors: ½ ω′ᵀJ′ω′, ω′ = R(λ)ᵀ ω
      auto it = lambda_body_.find(bi.coord);
      if (it == lambda_body_.end() || it->second != index) continue;
      const Eigen::Matrix3d R = euler_R(x_.segment<4>(bi.coord));
      I.topLeftCorner<3, 3>() += R * bi.J * R.transpose();
    }
    // The projection is a rigid body's spatial inertia only if the mass model moves rigidly
    // with the nodes: the translational block m 1, the coupling block skew.
    const double scale = std::max(I.cwiseAbs().maxCoeff(), 1e-300);
    const Eigen::Matrix3d T = I.bottomRightCorner<3, 3>(), C = I.topRightCorner<3, 3>();
    if ((T - T.trace() / 3.0 * Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-12 * scale ||
        (C + C.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale)
      return refuse("the mass model of the body turned by " + joint + " does not move as a rigid body");
    bd.inertia = 0.5 * (I + I.transpose());
    tree_.add_body(bd);
    return true;
  }

  // FORCE on points and TORQUEL, on the bodies they move with (loads on the ground do nothing).
  bool attach_loads() {
    for (const auto& [id, n] : nodes_) {
      if (n.fixed) continue;
      const int dims = n.kind == NodeKind::XYZ ? 3 : 4;
      const Eigen::VectorXd f = sys_.force.segment(n.coord, dims);
      if (f.isZero(0.0)) continue;
      if (n.kind == NodeKind::Lambda) return refuse("FORCE on LAMBDA node " + std::to_string(id));
      for (const Follower& fl : tree_.followers_)  // every moving point follows one body
        if (fl.coord == n.coord) tree_.loads_.push_back({fl.body, fl.b, f.head<3>()});
    }
    for (const Torque& t : sys_.torques) {
      auto it = lambda_body_.find(t.coord);
      if (it == lambda_body_.end()) continue;  // on the ground
      if (t.global) return refuse("TORQUEG (a torque fixed in space, not in the body)");
      const Eigen::Vector4d l = x_.segment<4>(t.coord);  // constant in body coordinates
      tree_.bodies_[it->second].load.head<3>() += euler_R(l) * t.T;  // R(λ0) T′
    }
    return true;
  }

  // The loops closed on the tree: the points two bodies share beyond their joints, and the cut
  // hinges' rigid misalignments (closed_loop.hpp).
  bool record_loops() {
    Loops& loops = tree_.loops_;
    record_closure_points(loops);
    for (int i : cuts_) {
      const Hinge& h = hinges_[i];
      const SystemElement& se = sys_.elements[h.element];
      if (h.pa >= 0) return refuse(element_name(se) + " closes a loop: a sliding joint is not cut");
      if (se.has_constitutive)  // its σ would act on the loop's constraint rows: not built
        return refuse(element_name(se) + " closes a loop and has a law (ESTIFF, EDAMPP): a cut has none");
      Loops::Cut cut;
      cut.kernel = se.kernel.get();
      for (int end = 0; end < 2; ++end) {
        const int id = end == 0 ? h.a : h.b, body = body_of(id);
        cut.body[end] = body == kGround ? kGround : placed_[body];
        cut.lambda0[end] = lambda(id);
      }
      const Eigen::Matrix3d* frame = se.kernel->axes_frame();  // a HINGE's (sliding joints are refused above)
      if (!frame) return refuse(element_name(se) + " closes a loop and has no hinge frame");
      const Eigen::Matrix3d& C0 = *frame;
      cut.axis = euler_R(cut.lambda0[0]) * C0.col(0);
      for (int k = 1; k < se.nd; ++k)
        if (sys_.def_class[se.def_offset + k] == DefClass::Fixed) {
          cut.rows.push_back(k);
          cut.value.push_back(e_[se.def_offset + k]);
          cut.across.push_back(euler_R(cut.lambda0[1]) * (k == 1 ? C0.col(2) : Eigen::Vector3d(-C0.col(1))));
        }
      loops.cuts.push_back(std::move(cut));
    }
    const bool closed = !loops.points.empty() || !loops.cuts.empty();
    if (closed && tree_.floating_) return refuse("a loop closes on a floating base");
    if (closed && loops.dependent0.empty()) return refuse("a loop closes with no joint that it determines");
    if (!closed && !loops.dependent0.empty())
      return refuse(loops.dependent.front() + " is released and in no loop");
    return true;
  }

  const Eigen::VectorXd& e_;
  SpatialTree& tree_;
  bool passive_ = false;  // a passive joint was read: loops may close
  std::map<int, int> lambda_body_;  // first λ coordinate → index in the tree
  int base_point_ = -1, base_orientation_ = -1;  // a floating base's XYZ and LAMBDA nodes
};

std::unique_ptr<SpatialTree> SpatialTree::detect(const System& sys, const Data& data, std::string* why) {
  auto tree = std::unique_ptr<SpatialTree>(new SpatialTree());
  if (!tree_detail::build(Builder(sys, data, *tree), why)) return nullptr;
  tree->base_acceleration_.tail<3>() = -sys.gravity;
  // The world frames only at the outputs (move_coordinates) where the passes do not read them.
  tree->world_frames_ = !tree->loads_.empty() || tree->loops_.closed() ||
                        std::any_of(tree->bodies_.begin(), tree->bodies_.end(), [](const Model& m) { return m.free; });
  return tree;
}

// FORCE at body points (world directions), subtracted from the bias forces.
void SpatialTree::applied_loads() {
  for (const Load& l : loads_) {
    BodyWork& bd = work_[l.body];
    const Vec3 f = bd.frame.R.transpose() * l.force;
    bd.pA.head<3>() -= l.b.cross(f);
    bd.pA.tail<3>() -= f;
  }
}

// The floating base's Euler parameters at q (the dependent one from the unit norm, with its
// sign at the recognition), and their rates at q̇ (the dependent one from λ · λ̇ = 0).
Eigen::Vector4d SpatialTree::base_lambda(const double* q) const {
  const double mu[3] = {q[base_.lambda_dof[0]], q[base_.lambda_dof[1]], q[base_.lambda_dof[2]]};
  Eigen::Vector4d l;
  base_.lambda(mu, l.data());
  return l;
}

Eigen::Vector4d SpatialTree::base_lambda_rate(const Eigen::Vector4d& l, const double* qd) const {
  const double mud[3] = {qd[base_.lambda_dof[0]], qd[base_.lambda_dof[1]], qd[base_.lambda_dof[2]]};
  Eigen::Vector4d ld;
  base_.lambda_rate(l.data(), mud, ld.data());
  return ld;
}

// The base's frame: rotated by R(λ) R0ᵀ since the recognition, its pin the XYZ node; its velocity
// in body coordinates, ω = R0 · 2 G(λ) λ̇ (the angular velocity in the LAMBDA node's axes,
// turned to the body's) and v = Rᵀ ẋ.
bool SpatialTree::free_body_motion(const double* q, const double* qd, BodyWork& d) {
  const Eigen::Vector4d l = base_lambda(q);
  if (!(std::abs(l[base_.dependent]) > 0.0) || !l.allFinite()) return false;  // |λ_independent| ≥ 1
  const Eigen::Vector4d ld = base_lambda_rate(l, qd);
  const Eigen::Matrix3d R = euler_R(l) * base_.R0.transpose();
  const Vec3 x(q[base_.x_dof], q[base_.x_dof + 1], q[base_.x_dof + 2]);
  const Vec3 xd(qd[base_.x_dof], qd[base_.x_dof + 1], qd[base_.x_dof + 2]);
  d.frame.R = R;
  d.frame.E = R.transpose();
  d.frame.r = x;
  d.frame.lambda = compose(l, Eigen::Vector4d(base_.lambda0[0], -base_.lambda0[1], -base_.lambda0[2], -base_.lambda0[3]));
  d.pin = x;
  d.v << base_.R0 * (2.0 * euler_G(l.data()) * ld), R.transpose() * xd;
  return true;
}

// q̈ of the base from its acceleration (ω̇; v̇) in body coordinates: ẍ = R (v̇ + ω × v) and
// λ̈ = ½ G(λ̇)ᵀ ω' + ½ G(λ)ᵀ ω̇' in the LAMBDA node's axes (ω' = R0ᵀ ω).
void SpatialTree::free_body_qdd(const double* q, const double* qd, const BodyWork& d, const Vector& acc,
                                double* qdd) {
  const Eigen::Vector4d l = base_lambda(q), ld = base_lambda_rate(l, qd);
  const Vec3 w = d.v.head<3>(), v = d.v.tail<3>();
  const Vec3 xdd = d.frame.R * (acc.tail<3>() + w.cross(v));
  for (int c = 0; c < 3; ++c) qdd[base_.x_dof + c] = xdd[c];
  const Eigen::Vector4d ldd = 0.5 * (euler_G(ld.data()).transpose() * (base_.R0.transpose() * w) +
                                     euler_G(l.data()).transpose() * (base_.R0.transpose() * acc.head<3>()));
  for (int i = 0, k = 0; i < 4; ++i)
    if (i != base_.dependent) qdd[base_.lambda_dof[k++]] = ldd[i];
}

// The inverse: ω̇ = R0 · 2 G(λ) λ̈ (G(λ̇) λ̇ = 0), λ̈ of the dependent parameter from
// λ · λ̈ + λ̇ · λ̇ = 0; v̇ = Rᵀ ẍ − ω × v.
SpatialTree::Vector SpatialTree::free_body_acceleration(const double* q, const double* qd, const double* qdd,
                                                        const BodyWork& d) {
  const Eigen::Vector4d l = base_lambda(q), ld = base_lambda_rate(l, qd);
  Eigen::Vector4d ldd;
  double dot = ld.squaredNorm();
  for (int i = 0, k = 0; i < 4; ++i) {
    if (i == base_.dependent) continue;
    ldd[i] = qdd[base_.lambda_dof[k++]];
    dot += l[i] * ldd[i];
  }
  ldd[base_.dependent] = -dot / l[base_.dependent];
  const Vec3 xdd(qdd[base_.x_dof], qdd[base_.x_dof + 1], qdd[base_.x_dof + 2]);
  Vector a;
  a << base_.R0 * (2.0 * euler_G(l.data()) * ldd), d.frame.R.transpose() * xdd - d.v.head<3>().cross(d.v.tail<3>());
  return a;
}

// The generalized forces of the base's DOFs for the wrench f = (moment; force) at its pin in body
// coordinates, by virtual power: fᵀ (ω; v) with v = Rᵀ ẋ and ω = R0 · 2 G(λ) λ̇, λ̇ of the
// independent parameters (the dependent one's rate −Σ λ_i λ̇_i / λ_dep).
void SpatialTree::free_forces(const double* q, const BodyWork& d, const Vector& f, double* force) {
  const Eigen::Vector4d l = base_lambda(q);
  const Vec3 fx = d.frame.R * f.tail<3>();
  for (int c = 0; c < 3; ++c) force[base_.x_dof + c] = fx[c];
  const Eigen::Vector4d g = 2.0 * euler_G(l.data()).transpose() * (base_.R0.transpose() * f.head<3>());
  for (int i = 0, k = 0; i < 4; ++i)
    if (i != base_.dependent) force[base_.lambda_dof[k++]] = g[i] - l[i] / l[base_.dependent] * g[base_.dependent];
}

// Positions, velocities and accelerations of the coordinates moving with the bodies.
void SpatialTree::move_coordinates(Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd) {
  if (!world_frames_)  // the passes placed the bodies relative to their parents only
    for (size_t i = 0; i < bodies_.size(); ++i)
      SpatialAlgebra::place_world(bodies_[i], bodies_[i].parent < 0 ? nullptr : &work_[bodies_[i].parent], work_[i]);
  const Vec3 g = -base_acceleration_.tail<3>();
  for (const Follower& f : followers_) {
    const BodyWork& bd = work_[f.body];
    const Eigen::Matrix3d& R = bd.frame.R;
    const Vec3 w = bd.v.head<3>(), wd = bd.a.head<3>();
    if (!f.point) {  // λ = λ_body ⊗ λ0, λ̇ = ½ E(λ)ᵀ ω, λ̈ = ½ E(λ̇)ᵀ ω + ½ E(λ)ᵀ ω̇ (world ω)
      const Quat l = compose(bd.frame.lambda, f.lambda0);
      const Vec3 ww = R * w, wdw = R * wd;
      const Quat ld = 0.5 * euler_E_transpose_times(l, ww);
      x.segment<4>(f.coord) = l;
      xd.segment<4>(f.coord) = ld;
      xdd.segment<4>(f.coord) = 0.5 * (euler_E_transpose_times(ld, ww) + euler_E_transpose_times(l, wdw));
      continue;
    }
    const Vec3 vp = bd.v.tail<3>() + w.cross(f.b);  // of the point, in body axes
    const Vec3 ap = bd.a.tail<3>() + wd.cross(f.b) + w.cross(vp);
    x.segment<3>(f.coord) = bd.pin + R * f.b;
    xd.segment<3>(f.coord) = R * vp;
    xdd.segment<3>(f.coord) = R * ap + g;
  }
}

}  // namespace spacar

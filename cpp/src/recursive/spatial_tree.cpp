#include "spacar/recursive/spatial_tree.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "spacar/model/catalogue.hpp"
#include "spacar/elements/spatial.hpp"
#include "spacar/model/topology.hpp"
#include "tree_common.hpp"

namespace spacar {

namespace {

using tree_detail::element_nodes;
using tree_detail::kGround;
using tree_detail::NodeInfo;

// The Euler parameters of the composed rotation R(p ⊗ r) = R(p) R(r).
Eigen::Vector4d compose(const Eigen::Vector4d& p, const Eigen::Vector4d& r) {
  const Eigen::Vector3d pv = p.tail<3>(), rv = r.tail<3>();
  Eigen::Vector4d out;
  out[0] = p[0] * r[0] - pv.dot(rv);
  out.tail<3>() = p[0] * rv + r[0] * pv + pv.cross(rv);
  return out;
}

// E(λ)ᵀ ω = (0, ω) ⊗ λ.
Eigen::Vector4d euler_E_transpose_times(const Eigen::Vector4d& l, const Eigen::Vector3d& w) {
  Eigen::Vector4d out;
  out[0] = -w.dot(l.tail<3>());
  out.tail<3>() = l[0] * w + w.cross(l.tail<3>());
  return out;
}

// R(λ) = E(λ) G(λ)ᵀ, body → global.
Eigen::Matrix3d euler_R(const Eigen::Vector4d& l) { return euler_E(l) * euler_G(l.data()).transpose(); }

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

// Recognizes the tree in a system and fills a SpatialTree, step by step; a step that finds the
// system is not a spatial rigid tree says why (refuse) and stops.
class SpatialTree::Builder {
 public:
  Builder(const System& sys, const Data& data, SpatialTree& tree)
      : sys_(sys), x_(data.x), e_(data.e), tree_(tree) {}

  bool build() {
    return supported_classes() && read_nodes() && read_elements() && group_bodies() && place_bodies() &&
           attach_loads();
  }

  const std::string& why() const { return why_; }

 private:
  struct Hinge {
    int element;
    int a, b;           // LAMBDA nodes o1, o2: e1 = rotation of o2 relative to o1
    int dof;            // position in q
    bool used = false;
  };

  bool refuse(const std::string& why) {
    why_ = why;
    return false;
  }

  bool supported_classes() {
    if (sys_.n_dof() == 0) return refuse("no degrees of freedom");
    if (!sys_.x_dyn.empty()) return refuse("DYNX coordinates (free Euler parameters) are not hinge joints");
    if (!sys_.x_input.empty() || !sys_.e_input.empty()) return refuse("prescribed motions (INPUTX, INPUTE)");
    if (!sys_.e_line.empty() || !sys_.e_nonholonomic.empty() || !sys_.e_kinematic.empty() || !sys_.y_defs.empty())
      return refuse("LINE, nonholonomic or kinematic deformations");
    return true;
  }

  bool read_nodes() {
    for (int g = 0; g < sys_.nx; ++g) {
      const NodeKind kind = sys_.coord_node_kind[g];
      if (kind != NodeKind::XYZ && kind != NodeKind::Lambda) return refuse(sys_.coord_name(g) + " is planar");
    }
    nodes_ = tree_detail::system_nodes(sys_);
    for (const auto& [id, n] : nodes_)
      if (!n.fixed && !n.free) return refuse("node " + std::to_string(id) + " is partly fixed");
    return true;
  }

  std::string element_name(const SystemElement& se) const {
    return "element " + std::to_string(se.id) + " (" + element_catalogue()[se.type].name + ")";
  }

  // Rigid beams (joined into bodies by shared LAMBDA nodes in group_bodies) and DOF hinges.
  bool read_elements() {
    for (size_t i = 0; i < sys_.elements.size(); ++i) {
      const SystemElement& se = sys_.elements[i];
      // Every node is spatial (read_nodes): the beams are BEAM(NL), the hinges HINGE.
      const ElementType& type = element_catalogue()[se.type];
      const std::vector<int> ids = element_nodes(sys_, se);
      if (type.family == ElementFamily::Beam) {
        if (!read_beam(static_cast<int>(i), se, ids)) return false;
      } else if (type.family == ElementFamily::Hinge) {
        if (!read_hinge(static_cast<int>(i), se, ids)) return false;
      } else if (!type.automatic) {  // L2MIN1: the normalisation the tree keeps exactly
        return refuse(element_name(se) + " is not a BEAM, BEAMNL, HINGE or L2MIN1");
      }
    }
    return true;
  }

  bool read_beam(int i, const SystemElement& se, const std::vector<int>& ids) {
    for (int a = 0; a < se.nd; ++a)
      if (sys_.def_class[se.def_offset + a] != DefClass::Fixed) return refuse(element_name(se) + " is not rigid");
    bool all_fixed = true, lambda_fixed = false;
    for (int id : ids) {
      all_fixed = all_fixed && nodes_[id].fixed;
      lambda_fixed = lambda_fixed || (nodes_[id].kind == NodeKind::Lambda && nodes_[id].fixed);
    }
    if (all_fixed) return true;  // part of the ground
    if (lambda_fixed) return refuse(element_name(se) + " has a fixed orientation and moving points");
    beams_.push_back({i, ids});
    return true;
  }

  bool read_hinge(int i, const SystemElement& se, const std::vector<int>& ids) {
    const int k = se.def_offset;
    const DefClass c1 = sys_.def_class[k], c2 = sys_.def_class[k + 1], c3 = sys_.def_class[k + 2];
    if (c1 == DefClass::Released && c2 == DefClass::Released && c3 == DefClass::Released && !se.has_constitutive)
      return true;  // a measuring hinge: no constraint, no load
    if (c1 != DefClass::Dynamic || c2 != DefClass::Fixed || c3 != DefClass::Fixed)
      return refuse(element_name(se) + " is not a revolute joint (DYNE e1, rigid e2 and e3)");
    const int dof = static_cast<int>(std::lower_bound(sys_.e_dyn.begin(), sys_.e_dyn.end(), k) - sys_.e_dyn.begin());
    hinges_.push_back({i, ids.front(), ids.back(), dof});
    return true;
  }

  // The bodies: moving rigid beams sharing a LAMBDA node are one.
  bool group_bodies() {
    g_ = tree_detail::group_beams(beams_, nodes_, NodeKind::Lambda);
    if (g_.stray >= 0) return refuse("node " + std::to_string(g_.stray) + " moves with no rigid BEAM");
    placed_.assign(g_.points.size(), -1);
    pin_.assign(g_.points.size(), -1);
    for (const auto& [id, n] : nodes_)
      if (n.kind == NodeKind::XYZ && n.fixed) owner_[id] = kGround;
    return true;
  }

  int body_of(int lambda_node) const {
    return nodes_.at(lambda_node).fixed ? kGround : g_.body_of.at(lambda_node);
  }
  bool is_placed(int body) const { return body == kGround || placed_[body] >= 0; }
  Eigen::Vector3d xyz(int id) const { return x_.segment<3>(nodes_.at(id).coord); }
  Eigen::Vector4d lambda(int id) const { return x_.segment<4>(nodes_.at(id).coord); }

  // The one XYZ node of the body on its parent (or fixed): its pin, −1 if none, −2 if more.
  int pin_of(int body) const {
    int pin = -1;
    for (int id : g_.points[body])
      if (owner_.count(id)) pin = pin == -1 ? id : -2;
    return pin;
  }

  // From the ground outwards, breadth first: a body joins the tree at its pin, turned by the one
  // DOF hinge to its parent.
  bool place_bodies() {
    std::map<int, std::vector<int>> hinges_at;  // body (or kGround) → its hinges
    for (size_t i = 0; i < hinges_.size(); ++i) {
      const Hinge& h = hinges_[i];  // its free nodes are on bodies (group_bodies)
      hinges_at[body_of(h.a)].push_back(static_cast<int>(i));
      hinges_at[body_of(h.b)].push_back(static_cast<int>(i));
    }
    std::vector<int> queue = {kGround};
    for (size_t k = 0; k < queue.size(); ++k) {
      const int parent = queue[k];
      for (int i : hinges_at[parent]) {
        Hinge& h = hinges_[i];
        if (h.used) continue;  // the parent's own joint
        const bool forward = body_of(h.a) == parent;
        const int child = forward ? body_of(h.b) : body_of(h.a);
        const std::string name = element_name(sys_.elements[h.element]);
        if (child == parent) return refuse(name + " joins a body (or the ground) to itself");
        if (is_placed(child)) return refuse(name + " closes a loop");
        h.used = true;
        if (!place(child, parent, hinge_joint(h, forward), name)) return false;
        queue.push_back(child);
      }
    }
    for (size_t b = 0; b < placed_.size(); ++b)
      if (placed_[b] < 0)
        return refuse("the body of node " + std::to_string(*g_.points[b].begin()) +
                      " does not hang from the ground by DOF hinges (a spherical joint, or a loop)");
    return true;
  }

  // The joint of a DOF hinge, from the parent's end (forward: node o1) to the child's. The axis
  // follows from ∂e1/∂λ_o2 = 2 aᵀ E(λ_o2) (plus a multiple of λ_o2ᵀ): a = ½ E(λ_o2) (∂e1/∂λ_o2)ᵀ.
  Body hinge_joint(const Hinge& h, bool forward) const {
    const SystemElement& se = sys_.elements[h.element];
    const int n = static_cast<int>(se.coords.size());
    Eigen::VectorXd xl(n), e(se.nd);
    Eigen::MatrixXd B(se.nd, n);
    for (int a = 0; a < n; ++a) xl[a] = x_[se.coords[a]];
    se.kernel->first_derivatives(xl.data(), e.data(), B.data());
    Body bd;
    bd.dof = h.dof;
    bd.sign = forward ? 1.0 : -1.0;  // e1 turns o2 relative to o1
    bd.offset = e_[se.def_offset];
    bd.axis = (0.5 * euler_E(lambda(h.b)) * B.block<1, 4>(0, 4).transpose()).normalized();
    if (se.has_constitutive) {
      bd.stiffness = se.S(0, 0);
      bd.damping = se.D(0, 0);
    }
    return bd;
  }

  // The rigid-motion row of coordinate g for a body pinned at p0 (see rigid_row).
  Eigen::Matrix<double, 1, 6> rigid_row_of(int g, const Eigen::Vector3d& p0) const {
    const int id = sys_.coord_label[g][0];
    const NodeInfo& node = nodes_.at(id);
    if (node.kind == NodeKind::Lambda) return rigid_row(node.kind, g - node.coord, Eigen::Vector3d::Zero(), lambda(id));
    return rigid_row(node.kind, g - node.coord, xyz(id) - p0, Eigen::Vector4d::Zero());
  }

  // Adds the body to the tree under the placed body `parent_body` (or kGround) with its joint
  // `bd`: the pin, the inertia about it, the coordinates moving with it.
  bool place(int body, int parent_body, Body bd, const std::string& joint) {
    const int parent = parent_body == kGround ? kGround : placed_[parent_body];
    const int pin = pin_of(body);
    if (pin < 0 || owner_.at(pin) != parent)
      return refuse(joint + " turns a body with no point, or more than one, on its parent");
    const int index = static_cast<int>(tree_.bodies_.size());
    placed_[body] = index;
    pin_[body] = pin;
    const Eigen::Vector3d p0 = xyz(pin);
    bd.parent = parent;
    bd.r = parent == kGround ? p0 : Eigen::Vector3d(p0 - pin0_[parent]);
    for (int id : g_.points[body])
      if (id != pin) owner_[id] = index;
    Mat6 I = Mat6::Zero();
    auto row = [&](int g) { return rigid_row_of(g, p0); };
    for (int i : g_.beams[body]) I += tree_detail::element_inertia<6>(sys_.elements[i], x_, row);
    for (int id : g_.points[body]) {
      if (id == pin) continue;  // its point mass and loads move with the parent
      for (int c = 0; c < 3; ++c) {
        const int g = nodes_[id].coord + c;
        I += sys_.point_mass[g] * row(g).transpose() * row(g);
      }
      tree_.followers_.push_back({nodes_[id].coord, index, true, xyz(id) - p0, Quat::Zero()});
    }
    for (int id : g_.orientations[body]) {
      tree_.followers_.push_back({nodes_[id].coord, index, false, Vec3::Zero(), lambda(id)});
      lambda_body_[nodes_[id].coord] = index;
    }
    for (const BodyInertia& bi : sys_.bodies) {  // inertia tensors: ½ ω′ᵀJ′ω′, ω′ = R(λ)ᵀ ω
      auto it = lambda_body_.find(bi.coord);
      if (it == lambda_body_.end() || it->second != index) continue;
      const Mat3 R = euler_R(x_.segment<4>(bi.coord));
      I.topLeftCorner<3, 3>() += R * bi.J * R.transpose();
    }
    // The projection is a rigid body's spatial inertia only if the mass model moves rigidly
    // with the nodes: the translational block m 1, the coupling block skew.
    const double scale = std::max(I.cwiseAbs().maxCoeff(), 1e-300);
    const Mat3 T = I.bottomRightCorner<3, 3>(), C = I.topRightCorner<3, 3>();
    if ((T - T.trace() / 3.0 * Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-12 * scale ||
        (C + C.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale)
      return refuse("the mass model of the body turned by " + joint + " does not move as a rigid body");
    bd.inertia = 0.5 * (I + I.transpose());
    tree_.bodies_.push_back(bd);
    pin0_.push_back(p0);
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
    for (const auto& [coord, T] : sys_.torquel) {
      auto it = lambda_body_.find(coord);
      if (it == lambda_body_.end()) continue;  // on the ground
      const Eigen::Vector4d l = x_.segment<4>(coord);  // constant in body coordinates
      tree_.bodies_[it->second].torque += euler_R(l) * T;  // R(λ0) T′
    }
    return true;
  }

  const System& sys_;
  const Eigen::VectorXd& x_;
  const Eigen::VectorXd& e_;
  SpatialTree& tree_;
  std::string why_;
  std::map<int, NodeInfo> nodes_;
  std::vector<std::pair<int, std::vector<int>>> beams_;  // moving rigid beams: element, nodes
  std::vector<Hinge> hinges_;
  tree_detail::BeamBodies g_;           // the bodies' nodes and beams
  std::map<int, int> lambda_body_;      // first λ coordinate → index in bodies_
  std::vector<int> placed_;             // body → index in bodies_, −1: not yet
  std::vector<int> pin_;                // body → its pin node, −1: not placed
  std::map<int, int> owner_;            // XYZ node → body (index in bodies_) it moves with, kGround
  std::vector<Eigen::Vector3d> pin0_;   // reference pin of each placed body
};

std::unique_ptr<SpatialTree> SpatialTree::detect(const System& sys, const Data& data, std::string* why) {
  auto tree = std::unique_ptr<SpatialTree>(new SpatialTree());
  Builder builder(sys, data, *tree);
  if (!builder.build()) {
    if (why) *why = builder.why();
    return nullptr;
  }
  tree->base_acceleration_.tail<3>() = -sys.gravity;
  return tree;
}

SpatialTree::Vec6 SpatialTree::to_child(const Body& bd, const Vec6& m) {
  Vec6 out;
  out.head<3>() = bd.E * m.head<3>();
  out.tail<3>() = bd.E * (m.tail<3>() + m.head<3>().cross(bd.r));
  return out;
}

SpatialTree::Vec6 SpatialTree::to_parent(const Body& bd, const Vec6& f) {
  Vec6 out;
  out.tail<3>() = bd.E.transpose() * f.tail<3>();
  out.head<3>() = bd.E.transpose() * f.head<3>() + bd.r.cross(out.tail<3>());
  return out;
}

// Xᵀ I X with X = [E 0; −E r̃ E] (parent → body, motion vectors), by blocks: rotated,
// I' = [A B; Bᵀ C] in the parent's axes, then moved to its origin,
// [A + r̃Bᵀ + (r̃Bᵀ)ᵀ − r̃Cr̃, B + r̃C; (B + r̃C)ᵀ, C] — a third of the full 6×6 products.
void SpatialTree::add_inertia_to_parent(const Body& bd, const Mat6& I, Mat6& parent) {
  const Mat3& E = bd.E;
  const Mat3 Ib = I.topLeftCorner<3, 3>(), Bb = I.topRightCorner<3, 3>(), Cb = I.bottomRightCorner<3, 3>();
  const Mat3 A = E.transpose() * Ib * E, B = E.transpose() * Bb * E, C = E.transpose() * Cb * E;
  const Mat3 rx = skew(bd.r);
  const Mat3 rC = rx * C, rBt = rx * B.transpose();
  parent.topLeftCorner<3, 3>() += A + rBt + rBt.transpose() - rC * rx;
  const Mat3 coupling = B + rC;
  parent.topRightCorner<3, 3>() += coupling;
  parent.bottomLeftCorner<3, 3>() += coupling.transpose();
  parent.bottomRightCorner<3, 3>() += C;
}

// Outwards: rotations, pins, velocities, velocity-product accelerations and the bias forces of
// the bodies' inertia, with the joint torques; the articulated inertias start as the bodies'.
void SpatialTree::outward(const double* q, const double* qd) {
  for (Body& bd : bodies_) {
    const Body* p = bd.parent == kGround ? nullptr : &bodies_[bd.parent];
    const double theta = bd.sign * (q[bd.dof] - bd.offset);  // rotation relative to the parent
    bd.ud = bd.sign * qd[bd.dof];
    bd.tau = -bd.sign * (bd.stiffness * q[bd.dof] + bd.damping * qd[bd.dof]);  // τ_q = −σ
    const double ch = std::cos(0.5 * theta), sh = std::sin(0.5 * theta);  // of the half angle, for λ too
    const double c = 1.0 - 2.0 * sh * sh, s = 2.0 * sh * ch;
    const Vec3& k = bd.axis;
    const Mat3 rel = c * Mat3::Identity() + s * skew(k) + (1.0 - c) * k * k.transpose();  // body → parent
    bd.E = rel.transpose();
    Quat q_rel;
    q_rel << ch, sh * k;
    Vec6 v = Vec6::Zero();
    v.head<3>() = bd.ud * k;
    if (!p) {
      bd.R = rel;
      bd.lambda = q_rel;
      bd.pin = bd.r;
    } else {
      bd.R = p->R * rel;
      bd.lambda = compose(p->lambda, q_rel);
      bd.pin = p->pin + p->R * bd.r;
      v += to_child(bd, p->v);
    }
    bd.v = v;
    const Vec3 w = v.head<3>(), vl = v.tail<3>(), s_w = bd.ud * k;
    bd.bias << w.cross(s_w), vl.cross(s_w);  // v ×ₘ S u̇
    bd.IA = bd.inertia;
    const Vec6 h = bd.inertia * v;
    bd.pA << w.cross(h.head<3>()) + vl.cross(h.tail<3>()), w.cross(h.tail<3>());  // v ×* I v
    bd.pA.head<3>() -= bd.torque;
  }
}

// FORCE at body points (world directions), subtracted from the bias forces.
void SpatialTree::applied_loads() {
  for (const Load& l : loads_) {
    Body& bd = bodies_[l.body];
    const Vec3 f = bd.R.transpose() * l.force;
    bd.pA.head<3>() -= l.b.cross(f);
    bd.pA.tail<3>() -= f;
  }
}

// Inwards: articulated inertias and bias forces; false if a joint's articulated inertia is not
// positive.
bool SpatialTree::articulate() {
  for (int i = static_cast<int>(bodies_.size()) - 1; i >= 0; --i) {
    Body& bd = bodies_[i];
    bd.U = bd.IA.leftCols<3>() * bd.axis;
    bd.d = bd.axis.dot(bd.U.head<3>());
    // Not positive: a body that moves no mass. Not finite (a trial state out of range): the
    // integrator rejects the non-finite q̈ like the general path's.
    if (bd.d <= 0.0) return false;
    bd.u = bd.tau - bd.axis.dot(bd.pA.head<3>());
    if (bd.parent == kGround) continue;
    const Mat6 Ia = bd.IA - bd.U * bd.U.transpose() / bd.d;
    const Vec6 pa = bd.pA + Ia * bd.bias + bd.U * (bd.u / bd.d);
    Body& p = bodies_[bd.parent];
    add_inertia_to_parent(bd, Ia, p.IA);
    p.pA += to_parent(bd, pa);
  }
  return true;
}

// Outwards: joint and body accelerations (relative to the fictitious acceleration −g of the
// ground), q̈.
void SpatialTree::accelerations(double* qdd) {
  for (Body& bd : bodies_) {
    Vec6 a = to_child(bd, bd.parent == kGround ? base_acceleration_ : bodies_[bd.parent].a) + bd.bias;
    const double udd = (bd.u - bd.U.dot(a)) / bd.d;
    a.head<3>() += udd * bd.axis;
    bd.a = a;
    qdd[bd.dof] = bd.sign * udd;
  }
}

// Positions, velocities and accelerations of the coordinates moving with the bodies.
void SpatialTree::move_coordinates(Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd) const {
  const Vec3 g = -base_acceleration_.tail<3>();
  for (const Follower& f : followers_) {
    const Body& bd = bodies_[f.body];
    const Vec3 w = bd.v.head<3>(), wd = bd.a.head<3>();
    if (!f.point) {  // λ = λ_body ⊗ λ0, λ̇ = ½ E(λ)ᵀ ω, λ̈ = ½ E(λ̇)ᵀ ω + ½ E(λ)ᵀ ω̇ (world ω)
      const Quat l = compose(bd.lambda, f.lambda0);
      const Vec3 ww = bd.R * w, wdw = bd.R * wd;
      const Quat ld = 0.5 * euler_E_transpose_times(l, ww);
      x.segment<4>(f.coord) = l;
      xd.segment<4>(f.coord) = ld;
      xdd.segment<4>(f.coord) = 0.5 * (euler_E_transpose_times(ld, ww) + euler_E_transpose_times(l, wdw));
      continue;
    }
    const Vec3 vp = bd.v.tail<3>() + w.cross(f.b);  // of the point, in body axes
    const Vec3 ap = bd.a.tail<3>() + wd.cross(f.b) + w.cross(vp);
    x.segment<3>(f.coord) = bd.pin + bd.R * f.b;
    xd.segment<3>(f.coord) = bd.R * vp;
    xdd.segment<3>(f.coord) = bd.R * ap + g;
  }
}

}  // namespace spacar

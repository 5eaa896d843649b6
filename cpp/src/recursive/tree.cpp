#include "spacar/recursive/tree.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>

#include "spacar/model/catalogue.hpp"
#include "spacar/recursive/spatial_tree.hpp"
#include "spacar/model/topology.hpp"
#include "tree_common.hpp"

namespace spacar {

namespace {

using tree_detail::element_nodes;
using tree_detail::kGround;
using tree_detail::NodeInfo;

// Rigid-motion row of a coordinate: its rate for the body twist (ω, vx, vy) at the pin, with
// b the coordinate's point relative to the pin (world axes at the reference state).
Eigen::RowVector3d rigid_row(NodeKind kind, int component, const Eigen::Vector2d& b) {
  if (kind == NodeKind::Beta) return {1.0, 0.0, 0.0};
  return component == 0 ? Eigen::RowVector3d(-b.y(), 1.0, 0.0) : Eigen::RowVector3d(b.x(), 0.0, 1.0);
}

}  // namespace

// Recognizes the tree in a system and fills a PlanarTree, step by step; any step may find that
// the system is not a planar rigid tree (false).
class PlanarTree::Builder {
 public:
  Builder(const System& sys, const Data& data, PlanarTree& tree) : sys_(sys), x_(data.x), tree_(tree) {}

  bool build() {
    return supported_classes() && read_nodes() && read_elements() && group_bodies() && place_bodies() &&
           attach_springs();
  }

 private:
  struct Hinge {
    int a, b;           // e = β_b − β_a
    int dof;            // position in q, −1: a released hinge (a spring between two bodies)
    double stiffness, damping;  // σ = S e + D ė (0 without ESTIFF / EDAMPP)
    bool used = false;
  };

  bool supported_classes() const {
    return sys_.n_dof() > 0 && sys_.x_input.empty() && sys_.e_input.empty() && sys_.e_line.empty() &&
           sys_.e_nonholonomic.empty() && sys_.e_kinematic.empty() && sys_.y_defs.empty() &&
           sys_.auto_released.empty() && sys_.bodies.empty() && sys_.torquel.empty();
  }

  bool read_nodes() {
    for (size_t j = 0; j < sys_.x_dyn.size(); ++j) dof_of_coord_[sys_.x_dyn[j]] = static_cast<int>(j);
    for (int g = 0; g < sys_.nx; ++g) {
      const NodeKind kind = sys_.coord_node_kind[g];
      if (kind != NodeKind::XY && kind != NodeKind::Beta) return false;
      if (sys_.coord_class[g] == CoordClass::Dynamic && kind != NodeKind::Beta) return false;  // DYNX only on rotations
    }
    nodes_ = tree_detail::system_nodes(sys_);
    for (const auto& [id, n] : nodes_)
      if (!n.fixed && !n.free) return false;  // partly fixed: neither a pin nor a body node
    return true;
  }

  // Rigid beams (joined into bodies by shared BETA nodes in group_bodies) and hinges.
  bool read_elements() {
    for (size_t i = 0; i < sys_.elements.size(); ++i) {
      const SystemElement& se = sys_.elements[i];
      // Every node is planar (read_nodes): the beams are PLBEAM(NL), the hinges PLHINGE.
      const ElementFamily family = element_catalogue()[se.type].family;
      const std::vector<int> ids = element_nodes(sys_, se);
      if (family == ElementFamily::Beam) {
        if (!read_beam(static_cast<int>(i), se, ids)) return false;
      } else if (family == ElementFamily::Hinge) {
        const int k = se.def_offset;
        int dof = -1;
        if (sys_.def_class[k] == DefClass::Dynamic)
          dof = static_cast<int>(sys_.x_dyn.size() +
                                 (std::lower_bound(sys_.e_dyn.begin(), sys_.e_dyn.end(), k) - sys_.e_dyn.begin()));
        else if (sys_.def_class[k] != DefClass::Released)
          return false;
        const bool law = se.has_constitutive;
        hinges_.push_back({ids.front(), ids.back(), dof, law ? se.S(0, 0) : 0.0, law ? se.D(0, 0) : 0.0});
      } else {
        return false;
      }
    }
    return true;
  }

  bool read_beam(int i, const SystemElement& se, const std::vector<int>& ids) {
    for (int a = 0; a < se.nd; ++a)
      if (sys_.def_class[se.def_offset + a] != DefClass::Fixed) return false;
    bool all_fixed = true, beta_fixed = false;
    for (int id : ids) {
      all_fixed = all_fixed && nodes_[id].fixed;
      beta_fixed = beta_fixed || (nodes_[id].kind == NodeKind::Beta && nodes_[id].fixed);
    }
    if (all_fixed) return true;   // part of the ground
    if (beta_fixed) return false;  // a fixed rotation with free points
    beams_.push_back({i, ids});
    return true;
  }

  // The bodies: moving rigid beams sharing a BETA node are one.
  bool group_bodies() {
    g_ = tree_detail::group_beams(beams_, nodes_, NodeKind::Beta);
    if (g_.stray >= 0) return false;  // every free node moves with a body
    placed_.assign(g_.points.size(), -1);
    pin_.assign(g_.points.size(), -1);
    for (const auto& [id, n] : nodes_)
      if (n.kind == NodeKind::XY && n.fixed) owner_[id] = kGround;
    return true;
  }

  int body_of_beta(int id) { return nodes_[id].fixed ? kGround : g_.body_of.at(id); }
  bool is_placed(int body) const { return body == kGround || placed_[body] >= 0; }
  Eigen::Vector2d xy(int id) const { return {x_[nodes_.at(id).coord], x_[nodes_.at(id).coord + 1]}; }

  // The DYNX rotation coordinate of a body, −1 if none (−2: more than one).
  int dynamic_rotation(int body) const {
    int found = -1;
    for (int id : g_.orientations[body])
      if (sys_.coord_class[nodes_.at(id).coord] == CoordClass::Dynamic) found = found == -1 ? nodes_.at(id).coord : -2;
    return found;
  }

  // The one XY node of the body on a placed body (or fixed): its pin, −1 if none, −2 if more.
  int pin_of(int body) const {
    int pin = -1;
    for (int id : g_.points[body])
      if (owner_.count(id)) pin = pin == -1 ? id : -2;
    return pin;
  }

  // From the ground outwards, breadth first: a body joins the tree at its pin, turned by the one
  // DOF hinge to its parent or by its own DYNX rotation.
  bool place_bodies() {
    std::map<int, std::vector<int>> hinges_at;    // body (or kGround) → its DOF hinges
    std::map<int, std::vector<int>> bodies_at;    // XY node → the bodies containing it
    for (size_t i = 0; i < hinges_.size(); ++i) {
      if (hinges_[i].dof < 0) continue;
      hinges_at[body_of_beta(hinges_[i].a)].push_back(static_cast<int>(i));
      hinges_at[body_of_beta(hinges_[i].b)].push_back(static_cast<int>(i));
    }
    for (size_t b = 0; b < g_.points.size(); ++b)
      for (int id : g_.points[b]) bodies_at[id].push_back(static_cast<int>(b));
    std::vector<int> queue = {kGround};
    for (size_t k = 0; k < queue.size(); ++k) {
      const int parent = queue[k];
      for (int i : hinges_at[parent]) {
        Hinge& h = hinges_[i];
        if (h.used) continue;  // the parent's own joint
        const bool forward = body_of_beta(h.a) == parent;
        const int child = forward ? body_of_beta(h.b) : body_of_beta(h.a);
        // A hinge inside a body, between ground nodes, or closing a loop.
        if (child == parent || is_placed(child)) return false;
        if (dynamic_rotation(child) != -1) return false;  // two DOFs for one rotation
        h.used = true;
        if (!place(child, parent, hinge_joint(h, forward))) return false;
        queue.push_back(child);
      }
      for (int id : owned_points(parent))
        for (int child : bodies_at[id]) {
          const int coord = dynamic_rotation(child);
          if (is_placed(child) || coord == -1) continue;
          if (coord < 0 || !place(child, parent, rotation_joint(coord))) return false;
          queue.push_back(child);
        }
    }
    for (int index : placed_)
      if (index < 0) return false;  // a body not hanging from the ground by joints (a loop's)
    for (const Hinge& h : hinges_)
      if (h.dof >= 0 && !h.used) return false;  // a hinge between bodies not on the ground
    return static_cast<int>(tree_.bodies_.size()) == sys_.n_dof();
  }

  // The joint of a DOF hinge, from the parent's end (forward: node a) to the child's.
  Body hinge_joint(const Hinge& h, bool forward) {
    Body bd;
    bd.dof = h.dof;
    bd.sign = forward ? 1.0 : -1.0;  // e = β_b − β_a
    const int parent_beta = forward ? h.a : h.b, own_beta = forward ? h.b : h.a;
    bd.offset = x_[nodes_[parent_beta].coord] - x_[nodes_[own_beta].coord];
    bd.stiffness = h.stiffness;
    bd.damping = h.damping;
    return bd;
  }

  // The joint of a body turned by its own DYNX rotation coordinate.
  Body rotation_joint(int coord) const {
    Body bd;
    bd.absolute = true;
    bd.dof = dof_of_coord_.at(coord);
    bd.offset = x_[coord];
    return bd;
  }

  // The XY nodes a placed body (or the ground) carries: pins of its children.
  std::vector<int> owned_points(int body) const {
    std::vector<int> out;
    for (const auto& [id, owner] : owner_)
      if (body == kGround && owner == kGround) out.push_back(id);
    if (body != kGround)
      for (int id : g_.points[body])
        if (id != pin_[body]) out.push_back(id);
    return out;
  }

  // Adds the body to the tree under the placed body `parent_body` (or kGround) with its joint
  // `bd`: the pin, the inertia about it, the coordinates and loads moving with it.
  bool place(int body, int parent_body, Body bd) {
    const int parent = parent_body == kGround ? kGround : placed_[parent_body];
    const int pin = pin_of(body);
    if (pin < 0 || owner_.at(pin) != parent) return false;  // no pin, two, or one on another body
    const int index = static_cast<int>(tree_.bodies_.size());
    placed_[body] = index;
    pin_[body] = pin;
    const Eigen::Vector2d p0 = xy(pin);
    bd.parent = parent;
    bd.r = parent == kGround ? p0 : Eigen::Vector2d(p0 - pin0_[parent]);
    for (int id : g_.points[body])
      if (id != pin) owner_[id] = index;
    Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
    for (int i : g_.beams[body]) I += element_inertia(sys_.elements[i], p0);
    for (int id : g_.points[body])
      if (id != pin) follow(id, index, p0, I);
    for (int id : g_.orientations[body]) follow(id, index, p0, I);
    // The projection is a rigid body's inertia only if the mass model moves rigidly with the
    // nodes (equal masses in x and y, no coupling between them).
    const double scale = I.cwiseAbs().maxCoeff();
    if (std::abs(I(1, 1) - I(2, 2)) > 1e-12 * scale || std::abs(I(1, 2)) > 1e-12 * scale) return false;
    bd.inertia = I;
    tree_.bodies_.push_back(bd);
    pin0_.push_back(p0);
    return true;
  }

  // The rigid-motion row of coordinate g for a body pinned at p0 (see rigid_row).
  Eigen::RowVector3d rigid_row_of(int g, const Eigen::Vector2d& p0) const {
    const int id = sys_.coord_label[g][0];
    const NodeInfo& node = nodes_.at(id);
    const Eigen::Vector2d b = node.kind == NodeKind::XY ? Eigen::Vector2d(xy(id) - p0) : Eigen::Vector2d::Zero();
    return rigid_row(node.kind, g - node.coord, b);
  }

  // The element's mass matrix on the rigid motions about the pin p0: Tᵀ M T.
  Eigen::Matrix3d element_inertia(const SystemElement& se, const Eigen::Vector2d& p0) const {
    return tree_detail::element_inertia<3>(se, x_, [&](int g) { return rigid_row_of(g, p0); });
  }

  // A node moving with body `index`: its point mass into I, its loads, its coordinates.
  void follow(int id, int index, const Eigen::Vector2d& p0, Eigen::Matrix3d& I) {
    const NodeInfo& n = nodes_[id];
    const bool point = n.kind == NodeKind::XY;
    const Eigen::Vector2d b = point ? Eigen::Vector2d(xy(id) - p0) : Eigen::Vector2d::Zero();
    for (int c = 0; c < (point ? 2 : 1); ++c) {
      const int g = n.coord + c;
      const Eigen::RowVector3d row = rigid_row_of(g, p0);
      I += sys_.point_mass[g] * row.transpose() * row;
      if (sys_.force[g] != 0.0) tree_.loads_.push_back({index, point ? c : 2, b, sys_.force[g]});
    }
    tree_.followers_.push_back({n.coord, index, point ? 0 : 2, b, x_[n.coord]});
  }

  // Released hinges: springs and dampers between two bodies (or a body and the ground).
  bool attach_springs() {
    for (const Hinge& h : hinges_) {
      if (h.dof >= 0 || (h.stiffness == 0.0 && h.damping == 0.0)) continue;  // a measuring hinge
      Spring s;
      auto end = [&](int id, int& body, double& beta0) {
        const int b = body_of_beta(id);
        body = b == kGround ? kGround : placed_[b];
        beta0 = x_[nodes_[id].coord];
      };
      end(h.a, s.body_a, s.beta0_a);
      end(h.b, s.body_b, s.beta0_b);
      s.stiffness = h.stiffness;
      s.damping = h.damping;
      tree_.springs_.push_back(s);
    }
    return true;
  }

  const System& sys_;
  const Eigen::VectorXd& x_;
  PlanarTree& tree_;
  std::map<int, NodeInfo> nodes_;
  std::map<int, int> dof_of_coord_;    // DYNX coordinate → its position in q
  std::vector<std::pair<int, std::vector<int>>> beams_;  // moving rigid beams: element, nodes
  std::vector<Hinge> hinges_;
  tree_detail::BeamBodies g_;          // the bodies' nodes and beams
  std::vector<int> placed_;            // body → index in bodies_, −1: not yet
  std::vector<int> pin_;               // body → its pin node, −1: not placed
  std::map<int, int> owner_;           // XY node → body (index in bodies_) it moves with, kGround
  std::vector<Eigen::Vector2d> pin0_;  // reference pin of each placed body
};

std::unique_ptr<RecursiveTree> RecursiveTree::detect(const System& sys, const Data& data, std::string* why) {
  if (sys.dim == 3) return SpatialTree::detect(sys, data, why);
  std::unique_ptr<RecursiveTree> tree = PlanarTree::detect(sys, data);
  if (!tree && why) *why = "not a planar open tree of rigid bodies (tree.hpp)";
  return tree;
}

std::unique_ptr<PlanarTree> PlanarTree::detect(const System& sys, const Data& data) {
  auto tree = std::unique_ptr<PlanarTree>(new PlanarTree());
  if (!Builder(sys, data, *tree).build()) return nullptr;
  tree->base_acceleration_ = Vec3(0.0, -sys.gravity[0], -sys.gravity[1]);
  return tree;
}

PlanarTree::Vec3 PlanarTree::to_child(const Body& bd, const Vec3& m) {
  const double c = bd.c, s = bd.s, rx = bd.r.x(), ry = bd.r.y();
  return {m[0], (s * rx - c * ry) * m[0] + c * m[1] + s * m[2], (c * rx + s * ry) * m[0] - s * m[1] + c * m[2]};
}

PlanarTree::Vec3 PlanarTree::to_parent(const Body& bd, const Vec3& f) {
  const double c = bd.c, s = bd.s, rx = bd.r.x(), ry = bd.r.y();
  return {f[0] + (s * rx - c * ry) * f[1] + (c * rx + s * ry) * f[2], c * f[1] - s * f[2], s * f[1] + c * f[2]};
}

PlanarTree::Mat3 PlanarTree::inertia_to_parent(const Body& bd, const Mat3& I) {
  const double c = bd.c, s = bd.s, rx = bd.r.x(), ry = bd.r.y();
  Mat3 X;
  X << 1.0, 0.0, 0.0, s * rx - c * ry, c, s, c * rx + s * ry, -s, c;
  return X.transpose() * I * X;
}

bool RecursiveTree::solve(const double* q, const double* qd, Eigen::VectorXd& x, Eigen::VectorXd& xd,
                          Eigen::VectorXd& xdd, double* qdd) {
  if (!solve(q, qd, qdd)) return false;
  move_coordinates(x, xd, xdd);
  return true;
}

bool RecursiveTree::solve(const double* q, const double* qd, double* qdd) {
  outward(q, qd);
  applied_loads();
  if (!articulate()) return false;
  accelerations(qdd);
  return true;
}

// Outwards: rotations, pins, velocities, velocity-product accelerations and the bias forces of
// the bodies' inertia, with the joint torques; the articulated inertias start as the bodies'.
void PlanarTree::outward(const double* q, const double* qd) {
  for (Body& bd : bodies_) {
    const Body* p = bd.parent == kGround ? nullptr : &bodies_[bd.parent];
    double theta;  // rotation relative to the parent
    if (bd.absolute) {  // q is the rotation of a BETA node of the body
      theta = q[bd.dof] - bd.offset - (p ? p->phi : 0.0);
      bd.ud = qd[bd.dof] - (p ? p->v[0] : 0.0);
      bd.tau = 0.0;
    } else {  // q is the hinge's rotation; its stress acts on the joint as τ_q = −σ
      theta = bd.sign * q[bd.dof] + bd.offset;
      bd.ud = bd.sign * qd[bd.dof];
      bd.tau = -bd.sign * (bd.stiffness * q[bd.dof] + bd.damping * qd[bd.dof]);
    }
    bd.c = std::cos(theta);
    bd.s = std::sin(theta);
    Vec3 v(bd.ud, 0.0, 0.0);
    if (!p) {
      bd.phi = theta;
      bd.cw = bd.c;
      bd.sw = bd.s;
      bd.pin = bd.r;
    } else {
      bd.phi = p->phi + theta;
      bd.cw = p->cw * bd.c - p->sw * bd.s;
      bd.sw = p->sw * bd.c + p->cw * bd.s;
      bd.pin = p->pin + Eigen::Vector2d(p->cw * bd.r.x() - p->sw * bd.r.y(), p->sw * bd.r.x() + p->cw * bd.r.y());
      v += to_child(bd, p->v);
    }
    bd.v = v;
    bd.bias = Vec3(0.0, bd.ud * v[2], -bd.ud * v[1]);  // v ×ₘ S u̇
    bd.IA = bd.inertia;
    const Vec3 Iv = bd.inertia * v;
    bd.pA = Vec3(-v[2] * Iv[1] + v[1] * Iv[2], -v[0] * Iv[2], v[0] * Iv[1]);  // v ×* I v
  }
}

// Springs of released hinges and FORCE, subtracted from the bias forces.
void PlanarTree::applied_loads() {
  for (const Spring& sp : springs_) {  // torque −σ on node b's body, +σ on node a's
    auto angle = [&](int b, double beta0) { return beta0 + (b == kGround ? 0.0 : bodies_[b].phi); };
    auto rate = [&](int b) { return b == kGround ? 0.0 : bodies_[b].v[0]; };
    const double sigma = sp.stiffness * (angle(sp.body_b, sp.beta0_b) - angle(sp.body_a, sp.beta0_a)) +
                         sp.damping * (rate(sp.body_b) - rate(sp.body_a));
    if (sp.body_b != kGround) bodies_[sp.body_b].pA[0] += sigma;
    if (sp.body_a != kGround) bodies_[sp.body_a].pA[0] -= sigma;
  }
  for (const Load& l : loads_) {
    Body& bd = bodies_[l.body];
    if (l.component == 2) {
      bd.pA[0] -= l.value;
      continue;
    }
    const double fx = l.component == 0 ? l.value : 0.0, fy = l.component == 1 ? l.value : 0.0;
    const double bx = bd.cw * fx + bd.sw * fy, by = -bd.sw * fx + bd.cw * fy;  // in body coordinates
    bd.pA -= Vec3(l.b.x() * by - l.b.y() * bx, bx, by);
  }
}

// Inwards: articulated inertias and bias forces; false if a joint's articulated inertia is not
// positive.
bool PlanarTree::articulate() {
  for (int i = static_cast<int>(bodies_.size()) - 1; i >= 0; --i) {
    Body& bd = bodies_[i];
    bd.U = bd.IA.col(0);
    bd.d = bd.U[0];
    // Not positive: a body that moves no mass. Not finite (a trial state out of range): the
    // integrator rejects the non-finite q̈ like the general path's.
    if (bd.d <= 0.0) return false;
    bd.u = bd.tau - bd.pA[0];  // the joint force left for the joint acceleration
    if (bd.parent == kGround) continue;
    const Mat3 Ia = bd.IA - bd.U * bd.U.transpose() / bd.d;
    const Vec3 pa = bd.pA + Ia * bd.bias + bd.U * (bd.u / bd.d);
    Body& p = bodies_[bd.parent];
    p.IA += inertia_to_parent(bd, Ia);
    p.pA += to_parent(bd, pa);
  }
  return true;
}

// Outwards: joint and body accelerations (relative to the fictitious upward acceleration of the
// ground), q̈.
void PlanarTree::accelerations(double* qdd) {
  for (Body& bd : bodies_) {
    Vec3 a = to_child(bd, bd.parent == kGround ? base_acceleration_ : bodies_[bd.parent].a) + bd.bias;
    const double udd = (bd.u - bd.U.dot(a)) / bd.d;
    a[0] += udd;
    bd.a = a;
    qdd[bd.dof] = bd.absolute ? a[0] : bd.sign * udd;
  }
}

// Positions, velocities and accelerations of the coordinates moving with the bodies.
void PlanarTree::move_coordinates(Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd) const {
  const double gx = -base_acceleration_[1], gy = -base_acceleration_[2];
  for (const Follower& f : followers_) {
    const Body& bd = bodies_[f.body];
    const double w = bd.v[0], wd = bd.a[0];
    if (f.component == 2) {
      x[f.coord] = f.value0 + bd.phi;
      xd[f.coord] = w;
      xdd[f.coord] = wd;
      continue;
    }
    const double bx = f.b.x(), by = f.b.y();
    const double vx = bd.v[1] - w * by, vy = bd.v[2] + w * bx;  // of the point, in body axes
    const double ax = bd.a[1] - wd * by - w * vy, ay = bd.a[2] + wd * bx + w * vx;
    x[f.coord] = bd.pin.x() + bd.cw * bx - bd.sw * by;
    x[f.coord + 1] = bd.pin.y() + bd.sw * bx + bd.cw * by;
    xd[f.coord] = bd.cw * vx - bd.sw * vy;
    xd[f.coord + 1] = bd.sw * vx + bd.cw * vy;
    xdd[f.coord] = bd.cw * ax - bd.sw * ay + gx;
    xdd[f.coord + 1] = bd.sw * ax + bd.cw * ay + gy;
  }
}

namespace tree_detail {

std::map<int, NodeInfo> system_nodes(const System& sys) {
  std::map<int, NodeInfo> nodes;
  for (int g = 0; g < sys.nx; ++g) {
    const CoordClass c = sys.coord_class[g];
    auto [it, fresh] = nodes.try_emplace(sys.coord_label[g][0]);
    if (fresh) {
      it->second.kind = sys.coord_node_kind[g];
      it->second.coord = g;
    }
    it->second.fixed = it->second.fixed && c == CoordClass::Fixed;
    it->second.free = it->second.free && (c == CoordClass::Calculable || c == CoordClass::Dynamic);
  }
  return nodes;
}

BeamBodies group_beams(const std::vector<std::pair<int, std::vector<int>>>& beams,
                       const std::map<int, NodeInfo>& nodes, NodeKind orientation) {
  std::vector<std::vector<int>> links;
  for (const auto& [i, ids] : beams) {
    links.emplace_back();
    for (int id : ids)
      if (nodes.at(id).kind == orientation) links.back().push_back(id);
  }
  const std::vector<std::vector<int>> rigid = rigid_bodies({}, links);
  std::map<int, int> rigid_of;      // orientation node → rigid_bodies() index
  for (size_t r = 0; r < rigid.size(); ++r)
    for (int id : rigid[r]) rigid_of[id] = static_cast<int>(r);
  BeamBodies out;
  std::map<int, int> body_of_rigid;  // rigid_bodies() index → body
  for (size_t k = 0; k < beams.size(); ++k) {
    const auto& [i, ids] = beams[k];
    auto [it, fresh] = body_of_rigid.try_emplace(rigid_of.at(links[k].front()), static_cast<int>(out.points.size()));
    if (fresh) {
      out.points.emplace_back();
      out.orientations.emplace_back();
      out.beams.emplace_back();
    }
    const int b = it->second;
    out.beams[b].push_back(i);
    for (int id : ids) (nodes.at(id).kind == orientation ? out.orientations[b] : out.points[b]).insert(id);
  }
  std::set<int> moving;
  for (size_t b = 0; b < out.points.size(); ++b) {
    moving.insert(out.points[b].begin(), out.points[b].end());
    moving.insert(out.orientations[b].begin(), out.orientations[b].end());
    for (int id : out.orientations[b]) out.body_of[id] = static_cast<int>(b);
  }
  for (const auto& [id, n] : nodes)
    if (!n.fixed && !moving.count(id)) {
      out.stray = id;
      break;
    }
  return out;
}

std::vector<int> element_nodes(const System& sys, const SystemElement& se) {
  std::vector<int> nodes;
  for (int g : se.coords) {
    const int id = sys.coord_label[g][0];
    if (nodes.empty() || nodes.back() != id) nodes.push_back(id);
  }
  return nodes;
}

}  // namespace tree_detail

}  // namespace spacar

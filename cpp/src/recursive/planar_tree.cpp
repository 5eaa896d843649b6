// Planar rigid trees (planar_tree.hpp): the recognizer, the applied loads, the coordinates moving
// with the bodies.
#include "spacar/recursive/planar_tree.hpp"
#include "spacar/recursive/planar_rnea.hpp"
#include "spacar/recursive/rnea_derivatives.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>

#include "spacar/model/catalogue.hpp"
#include "spacar/model/topology.hpp"
#include "tree_common.hpp"

namespace spacar {

namespace {

using tree_detail::kGround;
using tree_detail::NodeInfo;

// Rigid-motion row of a coordinate: its rate for the body twist (ω, vx, vy) at the pin, with
// b the coordinate's point relative to the pin (world axes at the reference state).
Eigen::RowVector3d rigid_row(NodeKind kind, int component, const Eigen::Vector2d& b) {
  if (kind == NodeKind::Beta) return {1.0, 0.0, 0.0};
  return component == 0 ? Eigen::RowVector3d(-b.y(), 1.0, 0.0) : Eigen::RowVector3d(b.x(), 0.0, 1.0);
}

}  // namespace

// Recognizes the tree in a system and fills a PlanarTree, step by step (tree_common.hpp); a
// step that finds the system is not a planar rigid tree says why and stops.
class PlanarTree::Builder : public tree_detail::TreeBuilder<PlanarTree::Builder, PlanarAlgebra> {
 public:
  Builder(const System& sys, const Data& data, PlanarTree& tree)
      : TreeBuilder(sys, data, NodeKind::XY, NodeKind::Beta), tree_(tree) {}

  bool build() {
    return supported_classes() && read_coordinates() && read_nodes() && read_elements("PLBEAM or PLHINGE") &&
           group_bodies() && index_points() && place_bodies() && all_dofs_are_joints() && attach_springs() &&
           record_loops();
  }

 private:
  friend TreeBuilder;

  bool supported_classes() {
    if (sys_.n_dof() == 0) return refuse("no degrees of freedom");
    if (!sys_.x_input.empty() || !sys_.e_input.empty()) return refuse("prescribed motions (INPUTX, INPUTE)");
    if (!sys_.e_line.empty() || !sys_.e_nonholonomic.empty() || !sys_.e_kinematic.empty() || !sys_.y_defs.empty())
      return refuse("LINE, nonholonomic or kinematic deformations");
    if (!sys_.auto_released.empty()) return refuse("automatically released deformations");
    if (!sys_.bodies.empty() || !sys_.torques.empty()) return refuse("inertia tensors or torques (TORQUEL, TORQUEG)");
    return true;
  }

  bool read_coordinates() {
    for (size_t j = 0; j < sys_.x_dyn.size(); ++j) dof_of_coord_[sys_.x_dyn[j]] = static_cast<int>(j);
    for (int g = 0; g < sys_.nx; ++g) {
      const NodeKind kind = sys_.coord_node_kind[g];
      if (kind != NodeKind::XY && kind != NodeKind::Beta) return refuse(sys_.coord_name(g) + " is spatial");
      if (sys_.coord_class[g] == CoordClass::Dynamic && kind != NodeKind::Beta)
        return refuse("DYNX " + sys_.coord_name(g) + " is not a rotation");
    }
    return true;
  }

  // A DOF hinge is a joint (place_bodies), a released one a spring between two bodies.
  bool read_hinge(int i, const SystemElement& se, const std::vector<int>& ids) {
    const int dof = hinge_dof(se);
    if (dof < 0 && sys_.def_class[se.def_offset] != DefClass::Released)
      return refuse(element_name(se) + " is neither a joint (DYNE) nor released");
    hinges_.push_back({i, ids.front(), ids.back(), dof});
    return true;
  }

  // The DYNX rotation coordinate of a body, −1 if none (−2: more than one).
  int dynamic_rotation(int body) const {
    int found = -1;
    for (int id : g_.orientations[body])
      if (sys_.coord_class[nodes_.at(id).coord] == CoordClass::Dynamic) found = found == -1 ? nodes_.at(id).coord : -2;
    return found;
  }

  // Placed body i's pin moved to r from its parent's (TreeBuilder).
  void set_pin_offset(int i, const Point& r) { tree_.bodies_[i].r = r; }

  // The joint of a DOF hinge, from the parent's end (forward: node a) to the child's.
  bool hinge_joint(const Hinge& h, bool forward, int child, Model& bd) {
    if (dynamic_rotation(child) != -1)
      return refuse(element_name(sys_.elements[h.element]) + " turns a body that has a DYNX rotation");
    const SystemElement& se = sys_.elements[h.element];
    bd.dof = h.dof;
    bd.sign = forward ? 1.0 : -1.0;  // e = β_b − β_a
    const int parent_beta = forward ? h.a : h.b, own_beta = forward ? h.b : h.a;
    bd.offset = x_[nodes_[parent_beta].coord] - x_[nodes_[own_beta].coord];
    if (se.has_constitutive) {
      bd.stiffness = se.S(0, 0);
      bd.damping = se.D(0, 0);
    }
    return true;
  }

  // The bodies pinned at the points of `parent` (or the ground) and turned by their own DYNX
  // rotation coordinate; then those of a closed loop, turned by their own calculable rotation
  // (a passive joint: the loops determine it; none of its BETA nodes is DYNX, no DOF hinge joins
  // it to a placed body).
  bool place_rotated(int parent, std::vector<int>& queue) {
    for (bool passive : {false, true})
      for (int id : owned_points(parent))
        for (int child : bodies_at_[id]) {
          if (is_placed(child)) continue;
          const int dynx = dynamic_rotation(child);
          if (dynx < -1) return refuse("a body has more than one DYNX rotation");
          if (passive ? dynx != -1 || hinged_to_placed(child) : dynx == -1) continue;
          const int coord = passive ? nodes_.at(*g_.orientations[child].begin()).coord : dynx;
          Model bd;
          bd.absolute = true;
          bd.offset = x_[coord];
          const std::string joint = (passive ? "the rotation of " : "DYNX ") + sys_.coord_name(coord);
          if (passive) {  // after the DOFs in the tree's coordinates: (q, the passive rotations)
            bd.dof = tree_.loops_.add_passive(sys_.n_dof(), x_[coord], joint);
          } else {
            bd.dof = dof_of_coord_.at(coord);
          }
          if (!place(child, parent, bd, joint, Slide{})) return false;
          queue.push_back(child);
        }
    return true;
  }

  // Whether a DOF PLHINGE joins the body to a placed body (or the ground): that hinge is its joint.
  // A DOF hinge to a body not yet placed turns that body (its child) instead.
  bool hinged_to_placed(int body) const {
    for (const Hinge& h : hinges_) {
      if (h.dof < 0) continue;
      const int a = body_of(h.a), b = body_of(h.b);
      if ((a == body && is_placed(b)) || (b == body && is_placed(a))) return true;
    }
    return false;
  }

  // A planar loop closes at points (a body's second pin on a placed body); its passive joints
  // are the bodies' own rotations (place_rotated).
  bool loops_allowed() const { return true; }

  // The loops closed on the tree: the points two bodies share beyond their pins (closed_loop.hpp).
  bool record_loops() {
    auto& loops = tree_.loops_;
    record_closure_points(loops);
    if (loops.closed() && loops.dependent0.empty()) return refuse("a loop closes with no body that it turns");
    if (!loops.closed() && !loops.dependent0.empty())
      return refuse(loops.dependent.front() + " is neither a DOF nor determined by a loop");
    return true;
  }

  // The bodies containing each XY node, for place_rotated.
  bool index_points() {
    for (size_t b = 0; b < g_.points.size(); ++b)
      for (int id : g_.points[b]) bodies_at_[id].push_back(static_cast<int>(b));
    return true;
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

  bool all_dofs_are_joints() {
    if (tree_.n_bodies() == sys_.n_dof() + static_cast<int>(tree_.loops_.dependent0.size())) return true;
    return refuse("a degree of freedom is not the rotation of a body");
  }

  // Adds the body to the tree under the placed body `parent_body` (or kGround) with its joint
  // `bd`: the pin, the inertia about it, the coordinates and loads moving with it.
  bool place(int body, int parent_body, Model bd, const std::string& joint, const Slide& slide) {
    const int index = tree_.n_bodies();
    Eigen::Vector2d p0;
    if (!attach(body, parent_body, bd, joint, index, p0, slide)) return false;
    Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
    for (int i : g_.beams[body]) I += element_inertia(sys_.elements[i], p0);
    for (int id : g_.points[body])  // not its pin, nor a point where a loop closes: the first body's
      if (owner_.at(id) == index) follow(id, index, p0, I);
    for (int id : g_.orientations[body]) follow(id, index, p0, I);
    // The projection is a rigid body's inertia only if the mass model moves rigidly with the
    // nodes (equal masses in x and y, no coupling between them).
    const double scale = I.cwiseAbs().maxCoeff();
    if (std::abs(I(1, 1) - I(2, 2)) > 1e-12 * scale || std::abs(I(1, 2)) > 1e-12 * scale)
      return refuse("the mass model of the body turned by " + joint + " does not move as a rigid body");
    bd.inertia = I;
    tree_.add_body(bd);
    return true;
  }

  // The rigid-motion row of coordinate g for a body pinned at p0 (see rigid_row).
  Eigen::RowVector3d rigid_row_of(int g, const Eigen::Vector2d& p0) const {
    const int id = sys_.coord_label[g][0];
    const NodeInfo& node = nodes_.at(id);
    const Eigen::Vector2d b = node.kind == NodeKind::XY ? Eigen::Vector2d(point(id) - p0) : Eigen::Vector2d::Zero();
    return rigid_row(node.kind, g - node.coord, b);
  }

  // The element's mass matrix on the rigid motions about the pin p0: Tᵀ M T.
  Eigen::Matrix3d element_inertia(const SystemElement& se, const Eigen::Vector2d& p0) const {
    return tree_detail::element_inertia<3>(se, x_, [&](int g) { return rigid_row_of(g, p0); });
  }

  // A node moving with body `index`: its point mass into I, its loads, its coordinates.
  void follow(int id, int index, const Eigen::Vector2d& p0, Eigen::Matrix3d& I) {
    const NodeInfo& n = nodes_[id];
    const bool is_point = n.kind == NodeKind::XY;
    const Eigen::Vector2d b = is_point ? Eigen::Vector2d(point(id) - p0) : Eigen::Vector2d::Zero();
    for (int c = 0; c < (is_point ? 2 : 1); ++c) {
      const int g = n.coord + c;
      const Eigen::RowVector3d row = rigid_row_of(g, p0);
      I += sys_.point_mass[g] * row.transpose() * row;
      if (sys_.force[g] != 0.0) tree_.loads_.push_back({index, is_point ? c : 2, b, sys_.force[g]});
    }
    tree_.followers_.push_back({n.coord, index, is_point ? 0 : 2, b, x_[n.coord]});
  }

  // Released hinges: springs and dampers between two bodies (or a body and the ground).
  bool attach_springs() {
    for (const Hinge& h : hinges_) {
      const SystemElement& se = sys_.elements[h.element];
      if (h.dof >= 0 || !se.has_constitutive) continue;  // a joint, or a measuring hinge
      Spring s;
      auto end = [&](int id, int& body, double& beta0) {
        const int b = body_of(id);
        body = b == kGround ? kGround : placed_[b];
        beta0 = x_[nodes_[id].coord];
      };
      end(h.a, s.body_a, s.beta0_a);
      end(h.b, s.body_b, s.beta0_b);
      s.stiffness = se.S(0, 0);
      s.damping = se.D(0, 0);
      if (s.stiffness != 0.0 || s.damping != 0.0) tree_.springs_.push_back(s);
    }
    return true;
  }

  PlanarTree& tree_;
  std::map<int, int> dof_of_coord_;               // DYNX coordinate → its position in q
  std::map<int, std::vector<int>> bodies_at_;      // XY node → the bodies containing it
};

std::unique_ptr<PlanarTree> PlanarTree::detect(const System& sys, const Data& data, std::string* why) {
  auto tree = std::unique_ptr<PlanarTree>(new PlanarTree());
  if (!tree_detail::build(Builder(sys, data, *tree), why)) return nullptr;
  tree->base_acceleration_ = Vector(0.0, -sys.gravity[0], -sys.gravity[1]);
  return tree;
}

bool PlanarTree::dynamics_derivatives(int n, const double* q, const double* qd, const double* tau, double* qdd,
                                      double* dq, double* dqd, double* dtau) {
  if (n != n_bodies()) return false;  // every body turned by one joint, its DOF
  auto id = [&](const auto* qq, const auto* qqd, const auto* qqdd, auto* out) { inverse_dynamics_on(qq, qqd, qqdd, out); };
  return rnea::forward_dynamics_derivatives(n, q, qd, tau, id, qdd, dq, dqd, dtau);
}

// Springs of released hinges and FORCE, subtracted from the bias forces.
void PlanarTree::applied_loads() {
  for (const Spring& sp : springs_) {  // torque −σ on node b's body, +σ on node a's
    auto angle = [&](int b, double beta0) { return beta0 + (b == kGround ? 0.0 : work_[b].frame.phi); };
    auto rate = [&](int b) { return b == kGround ? 0.0 : work_[b].v[0]; };
    const double sigma = sp.stiffness * (angle(sp.body_b, sp.beta0_b) - angle(sp.body_a, sp.beta0_a)) +
                         sp.damping * (rate(sp.body_b) - rate(sp.body_a));
    if (sp.body_b != kGround) work_[sp.body_b].pA[0] += sigma;
    if (sp.body_a != kGround) work_[sp.body_a].pA[0] -= sigma;
  }
  for (const Load& l : loads_) {
    BodyWork& bd = work_[l.body];
    const PlanarAlgebra::Frame& f = bd.frame;
    if (l.component == 2) {
      bd.pA[0] -= l.value;
      continue;
    }
    const double fx = l.component == 0 ? l.value : 0.0, fy = l.component == 1 ? l.value : 0.0;
    const double bx = f.cw * fx + f.sw * fy, by = -f.sw * fx + f.cw * fy;  // in body coordinates
    bd.pA -= Vector(l.b.x() * by - l.b.y() * bx, bx, by);
  }
}

// Positions, velocities and accelerations of the coordinates moving with the bodies.
void PlanarTree::move_coordinates(Eigen::VectorXd& x, Eigen::VectorXd& xd, Eigen::VectorXd& xdd) {
  const double gx = -base_acceleration_[1], gy = -base_acceleration_[2];
  for (const Follower& f : followers_) {
    const BodyWork& bd = work_[f.body];
    const PlanarAlgebra::Frame& fr = bd.frame;
    const double w = bd.v[0], wd = bd.a[0];
    if (f.component == 2) {
      x[f.coord] = f.value0 + fr.phi;
      xd[f.coord] = w;
      xdd[f.coord] = wd;
      continue;
    }
    const double bx = f.b.x(), by = f.b.y();
    const double vx = bd.v[1] - w * by, vy = bd.v[2] + w * bx;  // of the point, in body axes
    const double ax = bd.a[1] - wd * by - w * vy, ay = bd.a[2] + wd * bx + w * vx;
    x[f.coord] = bd.pin.x() + fr.cw * bx - fr.sw * by;
    x[f.coord + 1] = bd.pin.y() + fr.sw * bx + fr.cw * by;
    xd[f.coord] = fr.cw * vx - fr.sw * vy;
    xd[f.coord + 1] = fr.sw * vx + fr.cw * vy;
    xdd[f.coord] = fr.cw * ax - fr.sw * ay + gx;
    xdd[f.coord + 1] = fr.sw * ax + fr.cw * ay + gy;
  }
}

}  // namespace spacar

// Pieces shared by the recognizers of planar (planar_tree.cpp) and spatial (spatial_tree.cpp)
// rigid trees: the nodes of a system, the nodes of an element, an element's mass projected on the
// rigid motions of a body, and the steps of recognizing a tree (TreeBuilder).
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "spacar/model/catalogue.hpp"
#include "spacar/model/system.hpp"
#include "spacar/recursive/articulated.hpp"

namespace spacar {
namespace tree_detail {

constexpr int kGround = -1;

struct NodeInfo {
  NodeKind kind = NodeKind::Any;
  int coord = 0;       // first coordinate
  bool fixed = true;   // every coordinate fixed
  bool free = true;    // every coordinate calculable or dynamic (DYNX)
};

// Every node of the system by number.
std::map<int, NodeInfo> system_nodes(const System& sys);

// Node numbers of an element's coordinates, in slot order.
std::vector<int> element_nodes(const System& sys, const SystemElement& se);

// Moving rigid beams joined into bodies by their shared orientation nodes (BETA or LAMBDA;
// rigid_bodies), the bodies numbered in the order of their first beam.
struct BeamBodies {
  std::vector<std::set<int>> points, orientations;  // nodes of each body
  std::vector<std::vector<int>> beams;              // elements of each body
  std::map<int, int> body_of;                       // orientation node → body
  int stray = -1;                                   // a free node on no body (no tree), or −1
};
// beams: (element index, its nodes) of every moving rigid beam.
BeamBodies group_beams(const std::vector<std::pair<int, std::vector<int>>>& beams,
                       const std::map<int, NodeInfo>& nodes, NodeKind orientation);

// Tᵀ M T of element_inertia, with its matrices' storage bounded to Max rows (on the stack) or
// not (Max = Eigen::Dynamic, on the heap).
template <int N, int Max, class Row>
Eigen::Matrix<double, N, N> projected_mass(const SystemElement& se, const Eigen::VectorXd& x, Row row) {
  const int n = static_cast<int>(se.coords.size());
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, Max, 1> xl(n), vl(n), h(n);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, Max, Max> M(n, n);
  Eigen::Matrix<double, Eigen::Dynamic, N, 0, Max, N> T(n, N);
  vl.setZero();
  for (int a = 0; a < n; ++a) xl[a] = x[se.coords[a]];
  se.kernel->mass(xl.data(), vl.data(), M.data(), h.data());
  for (int a = 0; a < n; ++a) T.row(a) = row(se.coords[a]);
  return T.transpose() * M * T;
}

// The element's mass matrix at the positions x, projected on the rigid motions of a body:
// Tᵀ M T, with T's row a the rate of the element's coordinate a for the body's velocity (rows
// from `row`, a function of the global coordinate index). Zero without element mass.
template <int N, class Row>
Eigen::Matrix<double, N, N> element_inertia(const SystemElement& se, const Eigen::VectorXd& x, Row row) {
  if (!se.has_mass) return Eigen::Matrix<double, N, N>::Zero();
  // Up to 16 coordinates (a BEAM has 14) on the stack, the small products evaluated
  // coefficient-wise: on the heap, recognizing a 20-link tree called the general matrix product
  // and malloc 40 times each.
  constexpr int kOnStack = 16;
  if (se.coords.size() <= kOnStack) return projected_mass<N, kOnStack>(se, x, row);
  return projected_mass<N, Eigen::Dynamic>(se, x, row);
}

// The steps of recognizing a tree of rigid bodies in a system, shared by the planar and the
// spatial recognizer (Derived, which adds its own: the hinges it accepts, the joint a hinge
// makes, the body's inertia, coordinates and loads; set_pin_offset(i, r) moves a placed body's pin
// in the tree). Any step may find that the system is not
// such a tree: it says why (refuse) and returns false.
template <class Derived, class Algebra>
class TreeBuilder {
 public:
  const std::string& why() const { return why_; }

 protected:
  using Point = typename Algebra::Point;
  using Model = BodyModel<Algebra>;
  static constexpr int kDim = Point::RowsAtCompileTime;

  // A joint between orientation nodes a and b: a hinge (its rotation turns b relative to a, about
  // a point the two bodies share) or a sliding joint (its translation moves b's point pb relative
  // to a's point pa; the bodies share no point).
  struct Hinge {
    int element;
    int a, b;
    int dof;  // position in q, −1: released (a spring, or a measuring hinge)
    bool used = false;
    int pa = -1, pb = -1;  // a sliding joint's points on a's and b's bodies (−1: a hinge)
    // A joint of a closed loop whose coordinate the loops determine (released e1): a joint of the
    // tree, or (cut_only: its misalignments released too; or where it closes a loop) a cut.
    bool passive = false, cut_only = false;
  };

  // A point of a placed body (index in the tree) that another body (or the ground) placed first:
  // a loop closes there (Derived::loops_allowed()).
  struct ClosurePoint {
    int body, node;
  };

  // The points of the sliding joint that places a body: its own point (its pin, which slides)
  // and the parent's point it slides from; −1: a hinge. free: the body is a floating base, no
  // joint, its pin (its own) the point `pin`.
  struct Slide {
    int pin = -1, base = -1;
    bool free = false;
  };

  TreeBuilder(const System& sys, const Data& data, NodeKind point, NodeKind orientation)
      : sys_(sys), x_(data.x), point_kind_(point), orientation_kind_(orientation) {}

  bool refuse(const std::string& why) {
    why_ = why;
    return false;
  }

  std::string element_name(const SystemElement& se) const {
    return "element " + std::to_string(se.id) + " (" + element_catalogue()[se.type].name + ")";
  }

  // The nodes of the system; a partly fixed node is neither a pin nor a body's.
  bool read_nodes() {
    nodes_ = system_nodes(sys_);
    for (const auto& [id, n] : nodes_)
      if (!n.fixed && !n.free) return refuse("node " + std::to_string(id) + " is partly fixed");
    return true;
  }

  // Rigid beams (joined into bodies in group_bodies) and hinges (Derived::read_hinge); the
  // automatic element (L2MIN1) is the normalisation the tree keeps exactly.
  bool read_elements(const char* accepted) {
    for (size_t i = 0; i < sys_.elements.size(); ++i) {
      const SystemElement& se = sys_.elements[i];
      const ElementType& type = element_catalogue()[se.type];
      const std::vector<int> ids = element_nodes(sys_, se);
      if (type.family == ElementFamily::Beam) {
        if (!read_beam(static_cast<int>(i), se, ids)) return false;
      } else if (type.family == ElementFamily::Hinge) {
        if (!static_cast<Derived*>(this)->read_hinge(static_cast<int>(i), se, ids)) return false;
      } else if (!type.automatic) {
        if (!static_cast<Derived*>(this)->read_other(static_cast<int>(i), se, ids, accepted)) return false;
      }
    }
    return true;
  }

  // Another element (Derived may accept some: the spatial tree takes a BEARING as a sliding joint).
  bool read_other(int, const SystemElement& se, const std::vector<int>&, const char* accepted) {
    return refuse(element_name(se) + " is not a " + accepted);
  }

  bool read_beam(int i, const SystemElement& se, const std::vector<int>& ids) {
    for (int a = 0; a < se.nd; ++a)
      if (sys_.def_class[se.def_offset + a] != DefClass::Fixed) return refuse(element_name(se) + " is not rigid");
    bool all_fixed = true, orientation_fixed = false;
    for (int id : ids) {
      all_fixed = all_fixed && nodes_[id].fixed;
      orientation_fixed = orientation_fixed || (nodes_[id].kind == orientation_kind_ && nodes_[id].fixed);
    }
    if (all_fixed) return true;  // part of the ground
    if (orientation_fixed) return refuse(element_name(se) + " has a fixed orientation and moving points");
    beams_.push_back({i, ids});
    return true;
  }

  // The position of hinge element se's DOF in q (its rotation, deformation 1), −1 if released.
  int hinge_dof(const SystemElement& se) const {
    const int k = se.def_offset;
    if (sys_.def_class[k] != DefClass::Dynamic) return -1;
    return static_cast<int>(sys_.x_dyn.size() +
                            (std::lower_bound(sys_.e_dyn.begin(), sys_.e_dyn.end(), k) - sys_.e_dyn.begin()));
  }

  // The bodies: moving rigid beams sharing an orientation node are one.
  bool group_bodies() {
    g_ = group_beams(beams_, nodes_, orientation_kind_);
    if (g_.stray >= 0) return refuse("node " + std::to_string(g_.stray) + " moves with no rigid beam");
    placed_.assign(g_.points.size(), -1);
    pin_.assign(g_.points.size(), -1);
    for (const auto& [id, n] : nodes_)
      if (n.kind == point_kind_ && n.fixed) owner_[id] = kGround;
    return true;
  }

  int body_of(int orientation_node) const {
    return nodes_.at(orientation_node).fixed ? kGround : g_.body_of.at(orientation_node);
  }
  bool is_placed(int body) const { return body == kGround || placed_[body] >= 0; }
  Point point(int id) const { return x_.template segment<kDim>(nodes_.at(id).coord); }

  // The one point of the body on a placed body (or fixed): its pin, −1 if none, −2 if more.
  int pin_of(int body) const {
    int pin = -1;
    for (int id : g_.points[body])
      if (owner_.count(id)) pin = pin == -1 ? id : -2;
    return pin;
  }

  // From the ground outwards, breadth first: a body joins the tree at its pin, turned by the one
  // DOF hinge to its parent (Derived::hinge_joint, Derived::place), or, planar, by its own
  // rotation (Derived::place_rotated, called for every body placed and the ground).
  bool place_bodies() {
    // body (or kGround) → its joints: every DOF hinge, and the passive hinges of a spanning tree
    // grown from the DOF ones (each joining two bodies not yet connected), so that a loop is cut at
    // a passive joint wherever its DOF joints are, and not at one that cannot be cut if another
    // can; the other passive hinges are cuts (below).
    std::map<int, std::vector<int>> hinges_at;
    std::vector<int> set(g_.points.size() + 1);  // union–find over the bodies and the ground (last)
    for (size_t b = 0; b < set.size(); ++b) set[b] = static_cast<int>(b);
    auto root = [&](int body) {
      int r = body == kGround ? static_cast<int>(g_.points.size()) : body;
      while (set[r] != r) r = set[r] = set[set[r]];
      return r;
    };
    // Passes: the DOF hinges; the passive ones that cannot be cuts (a law, a sliding joint); the rest.
    auto pass_of = [&](const Hinge& h) {
      if (h.dof >= 0) return 0;
      if (!h.passive || h.cut_only) return -1;
      return h.pa >= 0 || sys_.elements[h.element].has_constitutive ? 1 : 2;
    };
    for (int pass = 0; pass < 3; ++pass)
      for (size_t i = 0; i < hinges_.size(); ++i) {
        const Hinge& h = hinges_[i];
        if (pass_of(h) != pass) continue;
        const int a = root(body_of(h.a)), b = root(body_of(h.b));
        if (pass > 0 && a == b) continue;  // closes a loop: a cut
        set[a] = b;
        hinges_at[body_of(h.a)].push_back(static_cast<int>(i));
        hinges_at[body_of(h.b)].push_back(static_cast<int>(i));
      }
    std::vector<int> queue = {kGround};
    if (!self().place_free_root(queue)) return false;
    for (size_t k = 0; k < queue.size(); ++k) {
      const int parent = queue[k];
      for (int i : hinges_at[parent]) {
        Hinge& h = hinges_[i];
        if (h.used) continue;  // the parent's own joint
        const bool forward = body_of(h.a) == parent;
        const int child = forward ? body_of(h.b) : body_of(h.a);
        const std::string name = element_name(sys_.elements[h.element]);
        if (child == parent) return refuse(name + " joins a body (or the ground) to itself");
        if (is_placed(child)) {
          if (!h.passive) return refuse(name + " closes a loop");
          h.used = true;  // a cut: its misalignments are constraints of the loop
          cuts_.push_back(i);
          continue;
        }
        h.used = true;
        Model bd;
        const Slide slide = h.pa < 0 ? Slide{} : forward ? Slide{h.pb, h.pa} : Slide{h.pa, h.pb};
        if (!self().hinge_joint(h, forward, child, bd) || !self().place(child, parent, bd, name, slide)) return false;
        queue.push_back(child);
      }
      if (!self().place_rotated(parent, queue)) return false;
    }
    for (size_t b = 0; b < placed_.size(); ++b)
      if (placed_[b] < 0)
        return refuse("the body of node " + std::to_string(*g_.points[b].begin()) +
                      " does not hang from the ground by joints (a spherical joint, or a loop)");
    for (size_t i = 0; i < hinges_.size(); ++i) {
      Hinge& h = hinges_[i];
      if (h.used || (h.dof < 0 && !h.passive)) continue;
      if (!h.passive || !is_placed(body_of(h.a)) || !is_placed(body_of(h.b)))
        return refuse(element_name(sys_.elements[h.element]) + " joins no placed body");
      h.used = true;
      cuts_.push_back(static_cast<int>(i));
    }
    return true;
  }

  // A floating base, the tree's root before the bodies that hang from the ground (Derived may
  // place one and add it to the queue).
  bool place_free_root(std::vector<int>&) { return true; }

  // Whether loops may close on the tree (Derived: the spatial tree, with passive joints).
  bool loops_allowed() const { return false; }

  // The first step of placing a body under the placed body `parent_body` (or kGround) with its
  // joint `bd`: its pin, its parent and its points; index and p0 are its place in the tree and
  // its pin's reference position.
  bool attach(int body, int parent_body, Model& bd, const std::string& joint, int index, Point& p0,
              const Slide& slide) {
    const int parent = parent_body == kGround ? kGround : placed_[parent_body];
    if (slide.free) {  // a floating base: it owns every point, its pin too
      mark_placed(body, index, kGround, true);
      pin_[body] = slide.pin;
      p0 = point(slide.pin);
      bd.parent = kGround;
      bd.r = p0;
      for (int id : g_.points[body]) owner_[id] = index;
      pin0_.push_back(p0);
      return true;
    }
    const bool sliding = slide.pin >= 0;
    // A hinge's pin is the point the body shares with its parent; a sliding joint's is the
    // body's own point of the joint, whose other point is on the parent, and the two share none.
    // In a closed loop the body's other points placed before close the loop (closure_points_).
    const bool loops = self().loops_allowed();
    int pin = sliding ? slide.pin : pin_of(body);
    if (!sliding && pin == -2 && loops) pin = pin_on(body, parent_body, parent);
    if (!sliding && g_.points[body].empty() && parent_body != kGround) {
      // A body of no point (a rotor's LAMBDA node, a link whose mass is at its joint's origin): it
      // turns about its parent's pin, as good as any point of the axis for a body whose mass is
      // all rotational inertia, until the joint of a child shows its pivot (pivot_of: the child's
      // pin, or the point a sliding child slides from).
      mark_placed(body, index, parent, false);
      p0 = pin0_[parent];
      bd.parent = parent;
      bd.r = Point::Zero();
      pin0_.push_back(p0);
      return true;
    }
    if (sliding) {
      if (!g_.points[body].count(pin) || (loops ? owner_.count(pin) > 0 : pin_of(body) != -1) ||
          !on_body(slide.base, parent_body, parent))
        return refuse(joint + " slides a body that is not joined to its parent by that joint alone");
      if (!pivot_of(slide.base, parent_body, parent, joint)) return false;  // the point it slides from
    } else if (pin < 0 || !on_body(pin, parent_body, parent)) {
      return refuse(joint + " turns a body with no point, or more than one, on its parent");
    } else if (!pivot_of(pin, parent_body, parent, joint)) {
      return false;
    }
    mark_placed(body, index, parent, true);
    pin_[body] = pin;
    p0 = point(pin);
    bd.parent = parent;
    bd.r = parent == kGround ? p0 : Point(p0 - pin0_[parent]);
    for (int id : g_.points[body]) {
      if (id == pin && !sliding) continue;  // the parent's
      if (owner_.count(id)) closure_points_.push_back({index, id});  // only with loops: refused above otherwise
      else owner_[id] = index;
    }
    pin0_.push_back(p0);
    return true;
  }

  // The one point of the body on the placed body parent_body (index parent), −2 if none or more.
  int pin_on(int body, int parent_body, int parent) const {
    int pin = -2;
    for (int id : g_.points[body])
      if (owner_.count(id) && on_body(id, parent_body, parent)) {
        if (pin != -2) return -2;
        pin = id;
      }
    return pin;
  }

  // Body `body` is index `index` of the tree, under index `parent` (or kGround); pivot_found: its
  // pin0_ is its pivot (a body of no point: not until a child's joint shows it, pivot_of).
  void mark_placed(int body, int index, int parent, bool pivot_found) {
    placed_[body] = index;
    body_at_.push_back(body);
    parent_at_.push_back(parent);
    pivot_found_.push_back(pivot_found);
  }

  // Whether a placed body's pin moves with it (a sliding joint's), not with its parent (a hinge's).
  bool owns_pin(int body) const { return pin_[body] >= 0 && owner_.at(pin_[body]) == placed_[body]; }

  // Whether point node id is on the placed body parent_body (index parent in the tree) or the
  // ground. Joints at one origin (two URDF joints at the same point, a spherical wrist) share it
  // with the parent's own parent, which placed it first. A body of no point carries its
  // children's joints at its pivot, a point of its own parent's (or, through further bodies of no
  // point, of the first ancestor with points).
  bool on_body(int id, int parent_body, int parent) const {
    if (!owner_.count(id)) return false;
    if (owner_.at(id) == parent ||
        (parent_body != kGround && (g_.points[parent_body].count(id) > 0 || pin_[parent_body] == id)))
      return true;
    if (parent_body == kGround || !g_.points[parent_body].empty()) return false;
    const int grand = parent_at_[parent];
    return on_body(id, grand == kGround ? kGround : body_at_[grand], grand);
  }

  // A joint at point `pin` (a hinge's pin, or the parent's point a sliding joint slides from) under
  // the body of no point parent_body (index parent) fixes that body's pivot, and those of its
  // ancestors of no point up to the one with points, at `pin`: they turn about axes through it
  // (their joints' axes meet there, as at a humanoid's elbow). A second joint at another point
  // cannot be placed. Nothing to do under a body with points.
  bool pivot_of(int pin, int parent_body, int parent, const std::string& joint) {
    std::vector<int> chain;  // tree indices of the bodies of no point, deepest first
    for (int i = parent; i != kGround && g_.points[body_at_[i]].empty(); i = parent_at_[i]) chain.push_back(i);
    if (parent_body == kGround || chain.empty()) return true;
    const Point p = point(pin);
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {  // from the top, each r from its parent's pivot
      const int i = *it;
      if (pivot_found_[i]) {
        if ((pin0_[i] - p).norm() > 0.0) return refuse(joint + " turns a body at another point than its parent's pivot");
        continue;
      }
      const int up = parent_at_[i];
      pin0_[i] = p;
      self().set_pin_offset(i, up == kGround ? p : Point(p - pin0_[up]));
      pivot_found_[i] = true;
    }
    return true;
  }

  // The points two bodies share beyond their joints (closure_points_) as the loops' constraints
  // (closed_loop.hpp): a point's body coordinates are its offset from the pin at the reference
  // state, when the body's axes are the world's (the ground's: the world position).
  template <class Loops>
  void record_closure_points(Loops& loops) const {
    loops.n_dof = sys_.n_dof();
    for (const ClosurePoint& c : closure_points_) {
      const int other = owner_.at(c.node);
      loops.points.push_back({c.body, other, point(c.node) - pin0_[c.body],
                              other == kGround ? point(c.node) : Point(point(c.node) - pin0_[other])});
    }
  }

  Derived& self() { return *static_cast<Derived*>(this); }

  const System& sys_;
  const Eigen::VectorXd& x_;
  const NodeKind point_kind_, orientation_kind_;
  std::string why_;
  std::map<int, NodeInfo> nodes_;
  std::vector<std::pair<int, std::vector<int>>> beams_;  // moving rigid beams: element, nodes
  std::vector<Hinge> hinges_;
  std::vector<int> cuts_;        // the passive hinges where loops are cut (indices into hinges_)
  std::vector<ClosurePoint> closure_points_;
  BeamBodies g_;                 // the bodies' nodes and beams
  std::vector<int> placed_;      // body → index in the tree, −1: not yet
  std::vector<int> pin_;         // body → its pin node, −1: not placed
  std::map<int, int> owner_;     // point node → body (index in the tree) it moves with, kGround
  std::vector<Point> pin0_;      // reference pin of each placed body
  std::vector<int> body_at_;     // index in the tree → body
  std::vector<int> parent_at_;   // index in the tree → its parent's index, kGround
  std::vector<bool> pivot_found_;  // index in the tree → its pin0_ is its pivot (mark_placed)
};

// Runs a recognizer (a TreeBuilder); false and, if why is given, its reason if the system is not
// its tree.
template <class Builder>
bool build(Builder&& builder, std::string* why) {
  if (builder.build()) return true;
  if (why) *why = builder.why();
  return false;
}

}  // namespace tree_detail
}  // namespace spacar

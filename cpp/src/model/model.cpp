#include "spacar/model/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include <Eigen/Dense>

#include "spacar/errors.hpp"

namespace spacar {

const char* coord_class_name(CoordClass c) {
  switch (c) {
    case CoordClass::Calculable: return "calculable";
    case CoordClass::Fixed: return "fixed";
    case CoordClass::Input: return "input";
    case CoordClass::Dynamic: return "dynamic";
  }
  return "?";
}

const char* def_class_name(DefClass c) {
  switch (c) {
    case DefClass::Fixed: return "fixed";
    case DefClass::Released: return "released";
    case DefClass::Input: return "input";
    case DefClass::Dynamic: return "dynamic";
    case DefClass::Linearization: return "linearization";
    case DefClass::Nonholonomic: return "nonholonomic";
    case DefClass::Kinematic: return "kinematic";
  }
  return "?";
}

namespace {

template <class... Args>
[[noreturn]] void fail(Args&&... args) {
  std::ostringstream os;
  (os << ... << args);
  throw InputError(os.str());
}

void require_finite(const std::vector<double>& values, const char* what) {
  for (double v : values)
    if (!std::isfinite(v)) fail(what, " value ", v, " is not a finite number");
}

void require_finite(double v, const char* what) {
  if (!std::isfinite(v)) fail(what, " value ", v, " is not a finite number");
}

void require_nonnegative(const std::vector<double>& values, const char* what) {
  for (size_t i = 0; i < values.size(); ++i)
    if (values[i] < 0.0) fail(what, " value ", i + 1, " is negative (", values[i], ")");
}

// Prefix of a message about an item defined at `origin` (file, line, keyword), if known.
std::string located(const std::string& origin) { return origin.empty() ? "" : origin + ": "; }

// Euler parameters must be of unit length (within 1e-3); the L2MIN1 constraint keeps them so.
void require_unit_euler(int id, const std::vector<double>& x) {
  double norm2 = 0.0;
  for (double v : x) norm2 += v * v;
  if (std::abs(std::sqrt(norm2) - 1.0) > 1e-3)
    fail("Euler parameters of node ", id, " have norm ", std::sqrt(norm2),
         "; they must be of unit length (within 1e-3)");
}

void require_count(const std::vector<double>& values, size_t lo, size_t hi, const char* what) {
  if (values.size() < lo || values.size() > hi) {
    if (lo == hi) fail(what, " takes ", lo, " value(s), got ", values.size());
    fail(what, " takes ", lo, " to ", hi, " values, got ", values.size());
  }
}

}  // namespace

// --- lookups ---

const Node& Model::node(int id) const {
  auto it = nodes.find(id);
  if (it == nodes.end()) fail("node ", id, " is not defined (nodes are created by elements)");
  return it->second;
}
// A node or element that may be changed through the reference: the lazy copies are made first.
Node& Model::node(int id) {
  before_change();
  return const_cast<Node&>(std::as_const(*this).node(id));
}

const Element& Model::element(int id) const {
  auto it = elements.find(id);
  if (it == elements.end()) fail("element ", id, " is not defined");
  return it->second;
}
Element& Model::element(int id) {
  before_change();
  return const_cast<Element&>(std::as_const(*this).element(id));
}

const ElementType& Model::type_of(const Element& el) const { return element_catalogue()[el.type]; }

int Model::deformation_index(const Element& el, int index) const {
  const int nd = type_of(el).n_deformations();
  if (index < 1 || index > nd)
    fail("element ", el.id, " (", type_of(el).name, ") has deformations 1..", nd, ", not ", index);
  return index - 1;
}

int Model::component_index(const Node& n, int component) const {
  const int nc = node_size(n.kind);
  if (component < 1 || component > nc)
    fail("node ", n.id, " (", node_keyword(n.kind), ") has components 1..", nc, ", not ", component);
  return component - 1;
}

void Model::require_open(const char* what) const {
  if (frozen_) fail(what, " after the first END: the topology is fixed once the analysis has started");
}

// --- topology ---

Node& Model::attach_node(int id, NodeKind kind, const std::string& element_name) {
  if (id <= 0) fail("node numbers must be positive, got ", id);
  auto [it, inserted] = nodes.try_emplace(id);
  Node& n = it->second;
  if (inserted) n.id = id;
  if (n.kind == NodeKind::Any) {
    if (n.x_given > node_size(kind))
      fail("node ", id, " was given ", n.x_given, " coordinates but ", element_name, " uses it as a ",
           node_keyword(kind), " node with ", node_size(kind));
    const int size = node_size(kind);
    std::vector<double> x(size, 0.0);
    for (int i = 0; i < size && i < static_cast<int>(n.x.size()); ++i) x[i] = n.x[i];
    if (kind == NodeKind::Lambda && n.x_given == 0) x[0] = 1.0;  // no rotation (manual §5.1 note 1)
    n.x = x;
    std::vector<CoordClass> cls(size, CoordClass::Calculable);
    for (int i = 0; i < size && i < static_cast<int>(n.cls.size()); ++i) cls[i] = n.cls[i];
    n.cls = cls;
    n.xd.assign(size, 0.0);
    n.xdd.assign(size, 0.0);
    n.kind = kind;
  } else if (n.kind != kind) {
    fail("node ", id, " is a ", node_keyword(n.kind), " node and cannot be used as a ",
         node_keyword(kind), " node by ", element_name);
  }
  n.used = true;
  return n;
}

void Model::add_element(const std::string& type_name, int id, const std::vector<int>& node_ids,
                        const std::vector<double>& params, const std::string& origin) {
  before_change();
  require_open("new elements");
  const int type = find_element_type(type_name);
  if (type < 0) fail("unknown element type ", type_name);
  const ElementType& et = element_catalogue()[type];
  if (id <= 0) fail("element numbers must be positive, got ", id);
  if (elements.count(id)) fail("element ", id, " is already defined (as ", type_of(elements.at(id)).name, ")");
  if (node_ids.size() != et.nodes.size())
    fail(et.name, " takes ", et.nodes.size(), " nodes, got ", node_ids.size());
  require_count(params, et.n_params_min, et.n_params_max, (et.name + " parameters").c_str());
  if (!et.n_params_allowed.empty() &&
      std::find(et.n_params_allowed.begin(), et.n_params_allowed.end(), static_cast<int>(params.size())) ==
          et.n_params_allowed.end()) {
    std::string counts;
    for (size_t i = 0; i < et.n_params_allowed.size(); ++i)
      counts += (i == 0 ? "" : i + 1 == et.n_params_allowed.size() ? " or " : ", ") +
                std::to_string(et.n_params_allowed[i]);
    fail(et.name, " ", id, " takes ", counts, " numbers after its nodes (", et.params, "), got ", params.size());
  }
  require_finite(params, et.name.c_str());
  if (et.has_direction && params[0] == 0.0 && params[1] == 0.0 && params[2] == 0.0)
    fail(et.name, " ", id, ": the direction vector has zero length");
  for (size_t i = 0; i < node_ids.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (node_ids[i] == node_ids[j]) fail(et.name, " ", id, " uses node ", node_ids[i], " twice");
  // Check every slot before changing anything, so that a failing line leaves the model intact.
  for (size_t i = 0; i < node_ids.size(); ++i) {
    if (node_ids[i] <= 0) fail("node numbers must be positive, got ", node_ids[i]);
    auto it = nodes.find(node_ids[i]);
    if (it != nodes.end() && it->second.kind != NodeKind::Any && it->second.kind != et.nodes[i])
      fail("node ", node_ids[i], " is a ", node_keyword(it->second.kind), " node and cannot be the ",
           et.node_roles[i], " (", node_keyword(et.nodes[i]), ") node of ", et.name, " ", id);
    if (it != nodes.end() && it->second.kind == NodeKind::Any &&
        it->second.x_given > node_size(et.nodes[i]))
      fail("node ", node_ids[i], " was given ", it->second.x_given, " coordinates but ", et.name, " ", id,
           " uses it as a ", node_keyword(et.nodes[i]), " node with ", node_size(et.nodes[i]));
    // Coordinates given by X before the node became a LAMBDA node: check them now.
    if (it != nodes.end() && it->second.kind == NodeKind::Any && et.nodes[i] == NodeKind::Lambda &&
        it->second.x_given > 0)
      require_unit_euler(node_ids[i], it->second.x);
  }
  for (size_t i = 0; i < node_ids.size(); ++i) attach_node(node_ids[i], et.nodes[i], et.name);
  Element el;
  el.id = id;
  el.type = type;
  el.nodes = node_ids;
  el.params = params;
  el.origin = origin;
  const size_t nd = et.deformations.size();
  el.cls.assign(nd, DefClass::Fixed);
  el.e.assign(nd, 0.0);
  el.ed.assign(nd, 0.0);
  el.edd.assign(nd, 0.0);
  el.e_given.assign(nd, false);
  el.kinematic_of.assign(nd, {0, 0});
  elements.emplace(id, std::move(el));
}

void Model::set_coordinates(int id, NodeKind kind, const std::vector<double>& values,
                            const std::string& origin) {
  before_change();
  require_finite(values, node_keyword(kind));
  if (id <= 0) fail("node numbers must be positive, got ", id);
  if (kind == NodeKind::Any) {
    if (values.empty() || values.size() > 4) fail("X takes 1 to 4 coordinates, got ", values.size());
  } else if (static_cast<int>(values.size()) != node_size(kind)) {
    fail(node_keyword(kind), " takes ", node_size(kind), " coordinates, got ", values.size());
  }
  // Validate everything before changing anything, so that a failing line leaves the model intact.
  auto it = nodes.find(id);
  const bool exists = it != nodes.end();
  if (!exists && frozen_) fail("node ", id, " is not defined");
  const NodeKind current = exists ? it->second.kind : NodeKind::Any;
  if (kind != NodeKind::Any && current != NodeKind::Any && current != kind)
    fail("node ", id, " is a ", node_keyword(current), " node, not a ", node_keyword(kind), " node");
  if (current != NodeKind::Any && static_cast<int>(values.size()) > node_size(current))
    fail("node ", id, " (", node_keyword(current), ") has ", node_size(current), " coordinates, got ",
         values.size());
  // A typed keyword declares the kind of a node no element has used yet.
  if (kind != NodeKind::Any && current == NodeKind::Any && frozen_)
    fail("node ", id, " is not used by any element");
  if (kind != NodeKind::Any && current == NodeKind::Any && exists && it->second.x_given > node_size(kind))
    fail("node ", id, " was given ", it->second.x_given, " coordinates but a ", node_keyword(kind), " node has ",
         node_size(kind));
  if (kind == NodeKind::Lambda || current == NodeKind::Lambda) {
    // The Euler parameters as they will be (X may set only the first few).
    std::vector<double> x = exists ? it->second.x : std::vector<double>(4, 0.0);
    for (size_t i = 0; i < values.size(); ++i) x[i] = values[i];
    require_unit_euler(id, x);
  }
  if (!exists) {
    Node n;
    n.id = id;
    n.kind = NodeKind::Any;
    n.x.assign(4, 0.0);
    n.cls.assign(4, CoordClass::Calculable);
    n.xd.assign(4, 0.0);
    n.xdd.assign(4, 0.0);
    n.origin = origin;
    it = nodes.emplace(id, std::move(n)).first;
  }
  Node& n = it->second;
  if (kind != NodeKind::Any && n.kind == NodeKind::Any) {
    n.kind = kind;
    n.x.resize(node_size(kind));
    n.cls.resize(node_size(kind));
    n.xd.resize(node_size(kind));
    n.xdd.resize(node_size(kind));
  }
  for (size_t i = 0; i < values.size(); ++i) n.x[i] = values[i];
  n.x_given = std::max(n.x_given, static_cast<int>(values.size()));
}

// --- boundary conditions ---

void Model::set_coordinate_class(int id, const std::vector<int>& components, CoordClass cls) {
  before_change();
  Node& n = node(id);
  if (components.empty()) {
    for (auto& c : n.cls) c = cls;
    return;
  }
  for (int c : components) component_index(n, c);  // validate all first
  for (int c : components) n.cls[component_index(n, c)] = cls;
}

void Model::set_deformation_class(int id, const std::vector<int>& indices, DefClass cls) {
  before_change();
  Element& el = element(id);
  std::vector<int> list = indices;
  if (list.empty())
    for (int i = 1; i <= type_of(el).n_deformations(); ++i) list.push_back(i);
  for (int i : list) deformation_index(el, i);
  for (int i : list) {
    const int k = deformation_index(el, i);
    // A deformation that stops being nonholonomic releases its kinematic coordinate.
    if (el.cls[k] == DefClass::Nonholonomic && cls != DefClass::Nonholonomic) {
      const auto [ke, ki] = el.kinematic_of[k];
      Element& kel = element(ke);
      if (kel.cls[ki - 1] == DefClass::Kinematic) kel.cls[ki - 1] = DefClass::Fixed;
      el.kinematic_of[k] = {0, 0};
    }
    if (el.cls[k] == DefClass::Kinematic && cls != DefClass::Kinematic)
      fail("element ", id, " deformation ", i,
           " is the kinematic coordinate of a nonholonomic deformation (ENHC); change that ENHC first");
    el.cls[k] = cls;
  }
}

void Model::set_nonholonomic(int e1, int i1, int e2, int i2) {
  before_change();
  Element& a = element(e1);
  Element& b = element(e2);
  const int k1 = deformation_index(a, i1);
  const int k2 = deformation_index(b, i2);
  if (e1 == e2 && i1 == i2) fail("a nonholonomic deformation cannot be its own kinematic coordinate");
  if (a.cls[k1] == DefClass::Kinematic)
    fail("element ", e1, " deformation ", i1,
         " is the kinematic coordinate of a nonholonomic deformation (ENHC); change that ENHC first");
  if (b.cls[k2] != DefClass::Fixed && b.cls[k2] != DefClass::Kinematic)
    fail("the kinematic coordinate element ", e2, " deformation ", i2, " must be a fixed deformation, it is ",
         def_class_name(b.cls[k2]), " (manual §5.3 note 2)");
  for (const auto& [id, el] : elements)
    for (size_t k = 0; k < el.kinematic_of.size(); ++k)
      if (el.kinematic_of[k][0] == e2 && el.kinematic_of[k][1] == i2 && !(id == e1 && int(k) == k1))
        fail("element ", e2, " deformation ", i2, " is already the kinematic coordinate of element ", id,
             " deformation ", k + 1);
  // A second ENHC of the same deformation replaces its pairing: the old kinematic coordinate
  // becomes a fixed deformation again (as when the nonholonomic deformation changes class).
  if (a.cls[k1] == DefClass::Nonholonomic) {
    const auto [old_e, old_i] = a.kinematic_of[k1];
    if (!(old_e == e2 && old_i == i2)) {
      Element& old = element(old_e);
      if (old.cls[old_i - 1] == DefClass::Kinematic) old.cls[old_i - 1] = DefClass::Fixed;
    }
  }
  a.cls[k1] = DefClass::Nonholonomic;
  a.kinematic_of[k1] = {e2, i2};
  b.cls[k2] = DefClass::Kinematic;
}

// --- initial values ---

void Model::set_xd(int id, int component, double value) {
  before_change();
  require_finite(value, "XD");
  Node& n = node(id);
  n.xd[component_index(n, component)] = value;
}

void Model::set_xdd(int id, int component, double value) {
  before_change();
  require_finite(value, "XDD");
  Node& n = node(id);
  n.xdd[component_index(n, component)] = value;
}

void Model::set_e(int id, int index, double value) {
  before_change();
  require_finite(value, "E");
  Element& el = element(id);
  const int k = deformation_index(el, index);
  el.e[k] = value;
  el.e_given[k] = true;
}

void Model::set_ed(int id, int index, double value) {
  before_change();
  require_finite(value, "ED");
  Element& el = element(id);
  el.ed[deformation_index(el, index)] = value;
}

void Model::set_edd(int id, int index, double value) {
  before_change();
  require_finite(value, "EDD");
  Element& el = element(id);
  el.edd[deformation_index(el, index)] = value;
}

void Model::set_time(double t) {
  before_change();
  require_finite(t, "TIME");
  time = t;
}

void Model::set_direction(int id, const std::vector<double>& xyz) {
  before_change();
  require_open("DIR");
  require_count(xyz, 3, 3, "DIR");
  require_finite(xyz, "DIR");
  Element& el = element(id);
  if (!type_of(el).has_direction) fail(type_of(el).name, " has no direction vector for DIR");
  if (xyz[0] == 0.0 && xyz[1] == 0.0 && xyz[2] == 0.0) fail("DIR: the direction vector has zero length");
  for (int i = 0; i < 3; ++i) el.params[i] = xyz[i];
}

void Model::set_lgeomy(int id, const std::vector<double>& values) {
  before_change();
  require_finite(values, "LGEOMY");
  Element& el = element(id);
  const int n = type_of(el).n_lgeomy;
  if (n == 0) fail(type_of(el).name, " has no reference geometry values (LGEOMY)");
  require_count(values, n, n, ("LGEOMY of " + type_of(el).name).c_str());
  el.lgeomy = values;
}

void Model::set_lengtho(int id, double l0) {
  before_change();
  require_finite(l0, "LENGTHO");
  Element& el = element(id);
  if (!type_of(el).has_length) fail(type_of(el).name, " has no reference length (LENGTHO)");
  if (!(l0 > 0.0)) fail("the reference length of element ", id, " must be positive, got ", l0);
  el.l0 = l0;
}

// --- properties ---

void Model::set_mass(int id, const std::vector<double>& values) {
  before_change();
  require_finite(values, "MASS");
  Node& n = node(id);
  switch (n.kind) {
    case NodeKind::XY:
    case NodeKind::XYZ:
      require_count(values, 1, 1, "MASS of a position node (m)");
      require_nonnegative(values, "MASS");
      break;
    case NodeKind::Beta:
      require_count(values, 1, 1, "MASS of a BETA node (Izz)");
      require_nonnegative(values, "MASS");
      break;
    case NodeKind::Lambda: {
      require_count(values, 6, 6, "MASS of a LAMBDA node (Ixx Ixy Ixz Iyy Iyz Izz)");
      // The tensor must be positive semidefinite. Leading principal minors do not decide that
      // (diag(0, 1, 0) with Iyz = 1 passes them), so look at the principal moments.
      Eigen::Matrix3d J;
      J << values[0], values[1], values[2], values[1], values[3], values[4], values[2], values[4], values[5];
      const Eigen::Vector3d moments = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(J, Eigen::EigenvaluesOnly).eigenvalues();
      if (moments[0] < -1e-12 * std::max(moments.cwiseAbs().maxCoeff(), 1e-300))
        fail("the inertia tensor of node ", id, " is not positive semidefinite (principal moments ", moments[0],
             ", ", moments[1], ", ", moments[2], ")");
      break;
    }
    case NodeKind::Any:
      fail("node ", id, " is not used by an element yet; define its element before MASS");
  }
  n.mass = values;
}

void Model::set_emass(int id, const std::vector<double>& values) {
  before_change();
  require_finite(values, "EMASS");
  Element& el = element(id);
  const ElementType& t = type_of(el);
  if (t.n_emass == 0) fail(t.name, " has no distributed mass (EMASS); use MASS on its nodes");
  require_count(values, 1, t.n_emass, ("EMASS of " + t.name).c_str());
  if (values[0] < 0.0) fail("EMASS value 1 is negative (", values[0], ")");
  if (!t.signed_emass_extras) require_nonnegative(values, "EMASS");
  el.emass = values;
}

void Model::set_estiff(int id, const std::vector<double>& values) {
  before_change();
  require_finite(values, "ESTIFF");
  Element& el = element(id);
  const ElementType& t = type_of(el);
  if (t.estiff.empty()) fail(t.name, " has no stiffness values (ESTIFF)");
  require_count(values, 1, t.n_estiff, ("ESTIFF of " + t.name).c_str());
  require_nonnegative(values, "ESTIFF");
  el.estiff = values;
}

void Model::set_edampp(int id, const std::vector<double>& values) {
  before_change();
  require_finite(values, "EDAMPP");
  Element& el = element(id);
  const ElementType& t = type_of(el);
  if (t.edampp.empty()) fail(t.name, " has no damping values (EDAMPP)");
  require_count(values, 1, std::max(t.n_estiff, 1), ("EDAMPP of " + t.name).c_str());
  require_nonnegative(values, "EDAMPP");
  el.edampp = values;
}

void Model::set_force(int id, const std::vector<double>& values) {
  before_change();
  require_finite(values, "FORCE");
  Node& n = node(id);
  if (n.kind == NodeKind::Any) fail("node ", id, " is not used by an element yet; define its element before FORCE");
  require_count(values, 1, node_size(n.kind), (std::string("FORCE on a ") + node_keyword(n.kind) + " node").c_str());
  n.force.assign(node_size(n.kind), 0.0);
  for (size_t i = 0; i < values.size(); ++i) n.force[i] = values[i];
}

namespace {
void set_torque(Node& n, int id, const std::vector<double>& values, const char* keyword, std::vector<double>& out) {
  require_finite(values, keyword);
  if (n.kind != NodeKind::Lambda) fail(keyword, " applies to LAMBDA nodes; node ", id, " is ", node_keyword(n.kind));
  require_count(values, 1, 3, keyword);
  out.assign(3, 0.0);
  for (size_t i = 0; i < values.size(); ++i) out[i] = values[i];
}
}  // namespace

void Model::set_torquel(int id, const std::vector<double>& values) {
  before_change();
  Node& n = node(id);
  set_torque(n, id, values, "TORQUEL", n.torquel);
}

void Model::set_torqueg(int id, const std::vector<double>& values) {
  before_change();
  Node& n = node(id);
  set_torque(n, id, values, "TORQUEG", n.torqueg);
}

void Model::set_gravity(const std::vector<double>& g) {
  before_change();
  require_count(g, 2, 3, "GRAVITY");
  require_finite(g, "GRAVITY");
  gravity = {g[0], g[1], g.size() > 2 ? g[2] : 0.0};
  gravity_given = true;
}

// --- settings ---

void Model::set_timestep(int n, double tp) {
  before_change();
  require_finite(tp, "TIMESTEP");
  if (n < 0) fail("the number of output intervals must not be negative, got ", n);
  if (tp < 0.0) fail("the time period must not be negative, got ", tp);
  if (n == 0 && tp > 0.0) fail("a positive time period needs at least one output interval");
  if (n > 10000000) fail("too many output intervals (", n, "); at most 10^7");
  settings.timestep_n = n;
  settings.timestep_tp = tp;
}

void Model::set_hmax(double h) {
  before_change();
  require_finite(h, "HMAX");
  if (!(h > 0.0)) fail("HMAX must be positive, got ", h);
  settings.hmax = h;
}

void Model::set_maxiterat(int n) {
  before_change();
  if (n < 1 || n > 1000) fail("MAXITERAT must be between 1 and 1000, got ", n);
  settings.maxiterat = n;
}

namespace {
void check_tolerance(double eps, const char* what) {
  require_finite(eps, what);
  if (!(eps > 0.0) || eps >= 1.0) fail(what, " must be a positive tolerance below 1, got ", eps);
}
void check_flag(int v, int max, const char* what) {
  if (v < 0 || v > max) fail(what, " must be between 0 and ", max, ", got ", v);
}
}  // namespace

void Model::set_epskin(double eps) {
  before_change();
  check_tolerance(eps, "EPSKIN");
  settings.epskin = eps;
}
void Model::set_epsint(double eps) {
  before_change();
  check_tolerance(eps, "EPSINT");
  settings.epsint = eps;
}
void Model::set_epsind(double eps) {
  before_change();
  check_tolerance(eps, "EPSIND");
  settings.epsind = eps;
}
void Model::set_forcemode(int mode) {
  before_change();
  check_flag(mode, 2, "FORCEMODE");
  settings.forcemode = mode;
}
void Model::set_animate(int flag) {
  before_change();
  check_flag(flag, 1, "ANIMATE");
  settings.animate = flag;
}
void Model::set_matasc(int flag) {
  before_change();
  check_flag(flag, 1, "MATASC");
  settings.matasc = flag;
}
void Model::set_jobid(int id) {
  before_change();
  settings.jobid = id;
}
void Model::set_restart(int flag) {
  before_change();
  check_flag(flag, 1, "RESTART");
  settings.restart = flag;
}
void Model::set_linear(int mode) {
  before_change();
  check_flag(mode, 2, "LINEAR");
  settings.linear = mode;
}

// --- preparation at END ---

void Model::prepare() {
  before_change();
  if (!frozen_) {
    for (const auto& [id, n] : nodes)
      if (n.kind == NodeKind::Any)
        fail(located(n.origin), "node ", id, " is not used by any element and has no kind (use XY, BETA, XYZ or LAMBDA)");
    add_automatic_constraints();
    if (elements.empty()) fail("the model has no elements");
    compute_reference_geometry();
    frozen_ = true;
  }
  // Euler parameters are accepted within 1e-3 of unit length (4-digit input, the dump). The
  // L2MIN1 constraint makes calculable ones exact, but nothing moves a fully fixed LAMBDA node,
  // whose automatically released L2MIN1 is then checked to EPSKIN: normalise them all here.
  for (auto& [id, n] : nodes) {
    if (n.kind != NodeKind::Lambda) continue;
    double norm2 = 0.0;
    for (double v : n.x) norm2 += v * v;
    if (norm2 > 0.0 && norm2 != 1.0)
      for (double& v : n.x) v /= std::sqrt(norm2);
  }
}

void Model::add_automatic_constraints() {
  // Every LAMBDA node needs its normalisation constraint; user L2MIN1 elements count.
  std::map<int, bool> has_constraint;
  for (const auto& [id, n] : nodes)
    if (n.kind == NodeKind::Lambda) has_constraint[id] = false;
  if (has_constraint.empty()) return;  // a planar or point model: no walk over the elements
  const int l2 = automatic_element_type();
  for (const auto& [id, el] : elements)
    if (el.type == l2) has_constraint[el.nodes[0]] = true;
  // Numbers after the largest element number; once that is the largest int (an input may use
  // it), the smallest free numbers.
  int next = elements.empty() ? 0 : elements.rbegin()->first;
  auto free_number = [&]() {
    if (next < std::numeric_limits<int>::max()) return ++next;
    int k = 1;
    while (elements.count(k)) ++k;
    return k;
  };
  for (const auto& [node_id, has] : has_constraint) {
    if (has) continue;
    const int id = free_number();
    add_element(element_catalogue()[l2].name, id, {node_id}, {});
    elements.at(id).automatic = true;
  }
}

void Model::compute_reference_geometry() {
  std::vector<double> xref;  // one buffer for all elements
  for (auto& [id, el] : elements) {
    const ElementType& t = type_of(el);
    if (!t.reference) continue;
    xref.clear();
    for (int nid : el.nodes) {
      const Node& n = nodes.at(nid);
      if (n.kind == NodeKind::Beta) xref.push_back(0.0);
      else if (n.kind == NodeKind::Lambda) xref.insert(xref.end(), {1.0, 0.0, 0.0, 0.0});
      else xref.insert(xref.end(), n.x.begin(), n.x.end());
    }
    double l0 = 0.0;
    std::vector<double> lgeomy;
    try {
      t.reference(xref.data(), el.params, l0, lgeomy);
    } catch (const InputError& err) {
      fail(located(el.origin), t.name, " ", id, ": ", err.what());
    }
    if (t.has_length && !el.l0) {
      if (!std::isfinite(l0))
        fail(located(el.origin), t.name, " ", id,
             " has a length that is not a finite number (the coordinates of its nodes are too large)");
      if (!(l0 > 0.0))
        fail(located(el.origin), t.name, " ", id,
             " has zero length: its nodes coincide in the initial positions");
      el.l0 = l0;
    }
    if (t.n_lgeomy > 0 && el.lgeomy.empty()) {
      for (double v : lgeomy)
        if (!std::isfinite(v))
          fail(located(el.origin), t.name, " ", id,
               ": its reference geometry (LGEOMY) is not finite (the coordinates of its nodes are too large)");
      el.lgeomy = lgeomy;
    }
  }
}

// --- lazy copies -------------------------------------------------------------------------------

Model LazyModelCopy::model() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (copy_) return Model(*copy_);
  if (live_) return Model(*live_);  // the live model, unchanged since (else copy_ is made)
  throw Error("the copy of the model these results keep could not be made when the model was deleted "
              "(out of memory)");
}

void LazyModelCopy::take(const Model& live) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (live_ != &live) return;
  copy_ = std::make_unique<Model>(live);
  live_ = nullptr;
}

void PendingCopies::add(const Model& owner, const std::shared_ptr<LazyModelCopy>& copy) {
  owner_ = &owner;
  list_.erase(std::remove_if(list_.begin(), list_.end(), [](const auto& w) { return w.expired(); }), list_.end());
  list_.push_back(copy);
}

void PendingCopies::make() {
  // One at a time, each dropped once made: if a copy fails (out of memory), it and the rest stay
  // pending, and the change that asked for them is not made (before_change() comes first).
  while (!list_.empty()) {
    if (const auto copy = list_.back().lock()) copy->take(*owner_);
    list_.pop_back();
  }
}

void PendingCopies::abandon() {
  for (const auto& w : list_)
    if (const auto copy = w.lock()) {
      std::lock_guard<std::mutex> lock(copy->mutex_);
      copy->live_ = nullptr;
    }
  list_.clear();
}

std::shared_ptr<LazyModelCopy> Model::lazy_copy() const {
  auto copy = std::make_shared<LazyModelCopy>();
  copy->live_ = this;
  pending_.add(*this, copy);
  return copy;
}

}  // namespace spacar

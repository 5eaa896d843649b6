#include "spacar/model/system.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "spacar/elements/spatial.hpp"
#include "spacar/errors.hpp"

namespace spacar {

Eigen::Vector4d Torque::force(const double* l) const {
  const Eigen::Matrix<double, 3, 4> P = global ? euler_E(Eigen::Map<const Eigen::Vector4d>(l)) : euler_G(l);
  return 2.0 * P.transpose() * T;
}

Eigen::Matrix4d Torque::stiffness() const {
  Eigen::Matrix4d K;
  for (int b = 0; b < 4; ++b) {  // P is linear in λ: column b is the force at the unit vector e_b
    double unit[4] = {0, 0, 0, 0};
    unit[b] = 1.0;
    K.col(b) = -force(unit);
  }
  return K;
}

std::string System::coord_name(int g) const {
  std::ostringstream os;
  os << "node " << coord_label[g][0] << " component " << coord_label[g][1];
  return os.str();
}

std::string System::def_name(int k) const {
  std::ostringstream os;
  const SystemElement& el = elements[e_element[k]];
  os << "element " << def_label[k][0] << " (" << element_catalogue()[el.type].name << ") deformation "
     << def_label[k][1];
  return os.str();
}

namespace {

// A LAMBDA node with three or four dynamic Euler parameters (the others calculable) rotates
// freely: returns the dependent parameter, or −1 if the node is not free.
int free_rotation_dependent(const Node& n, const std::map<int, int>& dependent) {
  if (n.kind != NodeKind::Lambda) return -1;
  int n_dyn = 0, calc = -1;
  for (int i = 0; i < 4; ++i) {
    if (n.cls[i] == CoordClass::Dynamic) ++n_dyn;
    else if (n.cls[i] == CoordClass::Calculable) calc = i;
  }
  if (!(n_dyn == 4 || (n_dyn == 3 && calc >= 0))) return -1;
  auto it = dependent.find(n.id);
  if (it != dependent.end()) return it->second;
  int best = 0;
  for (int i = 1; i < 4; ++i)
    if (std::abs(n.x[i]) > std::abs(n.x[best])) best = i;
  return n_dyn == 4 || std::abs(n.x[calc]) < 0.5 ? best : calc;
}

// The first coordinate of each node: node ids ascending (the order of model.nodes) beside
// their offsets, searched by bisection (a std::map's nodes cost a cache miss each, and the
// compilation of a large model looked up every element's nodes in one).
struct NodeOffsets {
  std::vector<int> ids, offsets;
  int at(int id) const {
    const auto it = std::lower_bound(ids.begin(), ids.end(), id);
    if (it == ids.end() || *it != id) throw Error("compile(): node " + std::to_string(id) + " is not defined");
    return offsets[it - ids.begin()];
  }
};

void number_coordinates(const Model& model, System& sys, NodeOffsets& node_offset,
                        const std::map<int, int>& dependent) {
  node_offset.ids.reserve(model.nodes.size());
  node_offset.offsets.reserve(model.nodes.size());
  for (const auto& [id, n] : model.nodes) {
    node_offset.ids.push_back(id);
    node_offset.offsets.push_back(sys.nx);
    const int dep = free_rotation_dependent(n, dependent);
    if (dep >= 0) sys.free_rotations.push_back({id, sys.nx, dep, {}});
    for (int i = 0; i < node_size(n.kind); ++i) {
      sys.coord_label.push_back({id, i + 1});
      sys.coord_node_kind.push_back(n.kind);
      CoordClass c = n.cls[i];
      if (dep >= 0) c = i == dep ? CoordClass::Calculable : CoordClass::Dynamic;
      sys.coord_class.push_back(c);
      ++sys.nx;
    }
    if (n.kind == NodeKind::XYZ || n.kind == NodeKind::Lambda) sys.dim = 3;
  }
}

void build_elements(const Model& model, System& sys, const NodeOffsets& node_offset, bool line_as_dof) {
  sys.elements.reserve(model.elements.size());
  for (const auto& [id, el] : model.elements) {
    const ElementType& t = element_catalogue()[el.type];
    ElementSetup setup;
    setup.params = el.params;
    setup.l0 = el.l0.value_or(0.0);
    setup.lgeomy = el.lgeomy;
    setup.emass = el.emass;
    SystemElement se;
    se.id = id;
    se.type = el.type;
    se.kernel = t.make(setup);
    se.coords.reserve(se.kernel->n_coords());
    for (size_t s = 0; s < el.nodes.size(); ++s)
      for (int i = 0; i < node_size(t.nodes[s]); ++i) se.coords.push_back(node_offset.at(el.nodes[s]) + i);
    se.def_offset = sys.ne;
    se.nd = t.n_deformations();
    se.S = Eigen::MatrixXd::Zero(se.nd, se.nd);
    se.D = Eigen::MatrixXd::Zero(se.nd, se.nd);
    if (!el.estiff.empty()) se.kernel->constitutive(el.estiff, se.S.data());
    if (!el.edampp.empty()) se.kernel->constitutive(el.edampp, se.D.data());
    se.has_constitutive = !el.estiff.empty() || !el.edampp.empty();
    se.has_mass = se.kernel->has_mass();
    for (int i = 0; i < se.nd; ++i) {
      if (se.kernel->period(i) > 0.0) sys.periodic_defs.push_back({sys.ne + i, se.kernel->period(i)});
      sys.def_velocity_level.push_back(se.kernel->velocity_level(i));
      sys.def_label.push_back({id, i + 1});
      const bool line = line_as_dof && el.cls[i] == DefClass::Linearization;
      sys.def_class.push_back(line ? DefClass::Dynamic : el.cls[i]);
      sys.e_element.push_back(static_cast<int>(sys.elements.size()));
    }
    sys.ne += se.nd;
    sys.elements.push_back(std::move(se));
  }
}

void check_velocity_level(const System& sys) {
  for (int k = 0; k < sys.ne; ++k) {
    const DefClass c = sys.def_class[k];
    if (sys.def_velocity_level[k] && c != DefClass::Nonholonomic && c != DefClass::Released)
      throw InputError(sys.def_name(k) + " is defined by its rate only (velocity level): declare it nonholonomic "
                       "(ENHC, rolling without slip) or released (RLSE, slipping), not " + def_class_name(c));
    if (c == DefClass::Kinematic && sys.def_velocity_level[k])
      throw InputError(sys.def_name(k) + " is defined by its rate only and cannot be a kinematic coordinate (ENHC)");
  }
}

void partition(System& sys) {
  check_velocity_level(sys);
  for (int g = 0; g < sys.nx; ++g) {
    switch (sys.coord_class[g]) {
      case CoordClass::Fixed: sys.x_fixed.push_back(g); break;
      case CoordClass::Calculable: sys.x_calc.push_back(g); break;
      case CoordClass::Input: sys.x_input.push_back(g); break;
      case CoordClass::Dynamic: sys.x_dyn.push_back(g); break;
    }
  }
  sys.calc_pos.assign(sys.nx, -1);
  for (size_t i = 0; i < sys.x_calc.size(); ++i) sys.calc_pos[sys.x_calc[i]] = static_cast<int>(i);

  for (int k = 0; k < sys.ne; ++k) {
    switch (sys.def_class[k]) {
      case DefClass::Fixed: sys.e_fixed.push_back(k); break;
      case DefClass::Released: sys.e_released.push_back(k); break;
      case DefClass::Input: sys.e_input.push_back(k); break;
      case DefClass::Dynamic: sys.e_dyn.push_back(k); break;
      case DefClass::Linearization: sys.e_line.push_back(k); break;
      case DefClass::Nonholonomic: sys.e_nonholonomic.push_back(k); break;
      case DefClass::Kinematic: sys.e_kinematic.push_back(k); break;
    }
  }

  // Position rows: deformations with known values; velocity rows: deformations with known rates.
  // A fixed deformation of an element without calculable coordinates constrains nothing: it is
  // checked against its target instead of entering the constraint block.
  sys.row_P.assign(sys.ne, -1);
  sys.row_V.assign(sys.ne, -1);
  for (int k = 0; k < sys.ne; ++k) {
    const DefClass c = sys.def_class[k];
    if (c == DefClass::Released) continue;
    if (c == DefClass::Fixed) {
      bool moves = false;
      for (int g : sys.elements[sys.e_element[k]].coords) moves = moves || sys.calc_pos[g] >= 0;
      if (!moves) {
        sys.auto_released.push_back(k);
        continue;
      }
    }
    if (c != DefClass::Nonholonomic) {
      sys.row_P[k] = static_cast<int>(sys.defs_P.size());
      sys.defs_P.push_back(k);
    }
    if (c != DefClass::Kinematic) {
      sys.row_V[k] = static_cast<int>(sys.defs_V.size());
      sys.defs_V.push_back(k);
    }
  }
  sys.velocity_block_is_position_block = sys.defs_P == sys.defs_V;

  // Columns of q̂ = (x^p, x^d, e^p, e^d).
  sys.qhat_col_x.assign(sys.nx, -1);
  sys.qhat_col_e.assign(sys.ne, -1);
  int col = 0;
  for (int g : sys.x_input) { sys.input_cols.push_back(col); sys.qhat_col_x[g] = col++; }
  for (int g : sys.x_dyn) { sys.dof_cols.push_back(col); sys.qhat_col_x[g] = col++; }
  for (int k : sys.e_input) { sys.input_cols.push_back(col); sys.qhat_col_e[k] = col++; }
  for (int k : sys.e_dyn) { sys.dof_cols.push_back(col); sys.qhat_col_e[k] = col++; }
  for (FreeRotation& fr : sys.free_rotations) {
    int j = 0;
    for (int i = 0; i < 4; ++i)
      if (i != fr.dependent) fr.dofs[j++] = sys.qhat_col_x[fr.coord + i] - static_cast<int>(sys.x_input.size());
  }
}

// Initial values: inputs start at their current value, deformation values not given by E are
// those of the current geometry (formulation.md §1.4).
void initial_values(const Model& model, System& sys) {
  Eigen::VectorXd x0(sys.nx);
  int g = 0;
  for (const auto& [id, n] : model.nodes)
    for (double v : n.x) x0[g++] = v;
  Eigen::VectorXd e_geom(sys.ne), e_given(sys.ne), ed(sys.ne), edd(sys.ne);
  std::vector<bool> given(sys.ne, false);
  std::vector<double> xl;
  auto model_element = model.elements.begin();  // sys.elements are in the order of model.elements
  for (const SystemElement& se : sys.elements) {
    xl.resize(se.coords.size());
    for (size_t i = 0; i < se.coords.size(); ++i) xl[i] = x0[se.coords[i]];
    se.kernel->deformations(xl.data(), e_geom.data() + se.def_offset);
    const Element& el = (model_element++)->second;
    for (int i = 0; i < se.nd; ++i) {
      e_given[se.def_offset + i] = el.e[i];
      given[se.def_offset + i] = el.e_given[i];
      ed[se.def_offset + i] = el.ed[i];
      edd[se.def_offset + i] = el.edd[i];
    }
  }
  auto value_of_def = [&](int k) { return given[k] ? e_given[k] : e_geom[k]; };

  sys.t0 = model.time;
  const int ni = sys.n_input();
  sys.p0.resize(ni);
  sys.pd0.resize(ni);
  sys.pdd0.resize(ni);
  int i = 0;
  for (int c : sys.x_input) {
    const Node& n = model.nodes.at(sys.coord_label[c][0]);
    const int comp = sys.coord_label[c][1] - 1;
    sys.p0[i] = n.x[comp];
    sys.pd0[i] = n.xd[comp];
    sys.pdd0[i] = n.xdd[comp];
    ++i;
  }
  for (int k : sys.e_input) {
    sys.p0[i] = value_of_def(k);
    sys.pd0[i] = ed[k];
    sys.pdd0[i] = edd[k];
    ++i;
  }
  sys.q0.resize(sys.n_dof());
  sys.qd0.resize(sys.n_dof());
  int j = 0;
  for (int c : sys.x_dyn) {
    const Node& n = model.nodes.at(sys.coord_label[c][0]);
    sys.q0[j] = n.x[sys.coord_label[c][1] - 1];
    sys.qd0[j++] = n.xd[sys.coord_label[c][1] - 1];
  }
  for (int k : sys.e_dyn) {
    sys.q0[j] = value_of_def(k);
    sys.qd0[j++] = ed[k];
  }
  for (int k = 0; k < sys.ne; ++k)
    if (sys.def_class[k] == DefClass::Released && given[k] && !sys.def_velocity_level[k])
      sys.warnings.push_back("E of released " + sys.def_name(k) + " is ignored: released deformations are computed");
  sys.e_target = Eigen::VectorXd::Zero(sys.ne);
  for (int k = 0; k < sys.ne; ++k) {
    const DefClass c = sys.def_class[k];
    if (c == DefClass::Fixed || c == DefClass::Linearization) sys.e_target[k] = given[k] ? e_given[k] : 0.0;
    else sys.e_target[k] = value_of_def(k);  // DOF, kinematic: initial values
  }
  // Integrated deformations: kinematic coordinates and the values of velocity-level ones.
  for (int k = 0; k < sys.ne; ++k) {
    if (sys.def_class[k] == DefClass::Kinematic || (sys.def_velocity_level[k] && sys.def_class[k] == DefClass::Released))
      sys.y_defs.push_back(k);
    if (sys.def_velocity_level[k]) sys.e_target[k] = given[k] ? e_given[k] : 0.0;
  }
  sys.y0.resize(sys.y_defs.size());
  for (size_t i = 0; i < sys.y_defs.size(); ++i) sys.y0[i] = sys.e_target[sys.y_defs[i]];
}

void masses_and_loads(const Model& model, System& sys, const NodeOffsets& node_offset) {
  sys.point_mass = Eigen::VectorXd::Zero(sys.nx);
  sys.force = Eigen::VectorXd::Zero(sys.nx);
  for (const auto& [id, n] : model.nodes) {
    const int off = node_offset.at(id);
    if (!n.mass.empty()) {
      if (n.kind == NodeKind::Lambda) {
        const auto& m = n.mass;
        BodyInertia b;
        b.coord = off;
        b.J << m[0], m[1], m[2], m[1], m[3], m[4], m[2], m[4], m[5];
        sys.bodies.push_back(b);
      } else {
        for (int i = 0; i < node_size(n.kind); ++i) sys.point_mass[off + i] = n.mass[0];
      }
    }
    for (size_t i = 0; i < n.force.size(); ++i) sys.force[off + i] = n.force[i];
    // A zero torque is no load (and would make the static tangent unsymmetric for nothing).
    for (const auto& [values, global] : {std::pair{&n.torquel, false}, std::pair{&n.torqueg, true}})
      if (!values->empty() && Eigen::Vector3d((*values)[0], (*values)[1], (*values)[2]).any())
        sys.torques.push_back({off, Eigen::Vector3d((*values)[0], (*values)[1], (*values)[2]), global});
  }
  sys.gravity = Eigen::Vector3d(model.gravity[0], model.gravity[1], model.gravity[2]);
}

void length_scales(const Model& model, System& sys) {
  double sum = 0.0;
  int n = 0;
  for (const auto& [id, el] : model.elements)
    if (el.l0) {
      sum += *el.l0;
      ++n;
    }
  if (n > 0 && sum > 0.0) sys.length_scale = sum / n;
  for (NodeKind k : sys.coord_node_kind) sys.coord_is_length.push_back(k == NodeKind::XY || k == NodeKind::XYZ);
  for (int k = 0; k < sys.ne; ++k)
    sys.def_is_length.push_back(element_catalogue()[sys.elements[sys.e_element[k]].type].has_length);
}

}  // namespace

std::unique_ptr<System> compile(const Model& model, const std::map<int, int>& dependent, bool line_as_dof) {
  if (!model.frozen()) throw Error("compile(): the model has not been prepared (call Model::prepare())");
  auto sys = std::make_unique<System>();
  sys->settings = model.settings;
  NodeOffsets node_offset;
  number_coordinates(model, *sys, node_offset, dependent);
  build_elements(model, *sys, node_offset, line_as_dof);
  partition(*sys);
  masses_and_loads(model, *sys, node_offset);
  length_scales(model, *sys);
  sys->n_structure_warnings = sys->warnings.size();
  reload_state(model, *sys);
  return sys;
}

void reload_state(const Model& model, System& sys) {
  sys.warnings.resize(sys.n_structure_warnings);
  sys.y_defs.clear();
  initial_values(model, sys);
  for (int k : sys.auto_released)
    if (!element_catalogue()[sys.elements[sys.e_element[k]].type].automatic)  // a fixed LAMBDA node is normal
      sys.warnings.push_back(sys.def_name(k) + " is fixed but none of its coordinates is calculable: it is checked, not solved for");
}

}  // namespace spacar

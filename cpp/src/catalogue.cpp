#include "spacar/catalogue.hpp"

#include "spacar/elements/element.hpp"
#include "spacar/elements/registry.hpp"

namespace spacar {

int node_size(NodeKind kind) {
  switch (kind) {
    case NodeKind::XY: return 2;
    case NodeKind::Beta: return 1;
    case NodeKind::XYZ: return 3;
    case NodeKind::Lambda: return 4;
    case NodeKind::Any: return 4;
  }
  return 0;
}

const char* node_keyword(NodeKind kind) {
  switch (kind) {
    case NodeKind::XY: return "XY";
    case NodeKind::Beta: return "BETA";
    case NodeKind::XYZ: return "XYZ";
    case NodeKind::Lambda: return "LAMBDA";
    case NodeKind::Any: return "X";
  }
  return "?";
}

bool is_orientation(NodeKind kind) { return kind == NodeKind::Beta || kind == NodeKind::Lambda; }

int ElementType::n_coordinates() const {
  int n = 0;
  for (NodeKind k : nodes) n += node_size(k);
  return n;
}

namespace {

using K = NodeKind;

ElementType& add(std::vector<ElementType>& table, const char* name, std::vector<NodeKind> nodes,
                 std::vector<std::string> roles, std::vector<std::string> deformations,
                 const char* description) {
  ElementType t;
  t.name = name;
  t.nodes = std::move(nodes);
  t.node_roles = std::move(roles);
  t.deformations = std::move(deformations);
  t.description = description;
  table.push_back(std::move(t));
  return table.back();
}

void set_params(ElementType& t, int n_min, int n_max, const char* meaning) {
  t.n_params_min = n_min;
  t.n_params_max = n_max;
  t.params = meaning;
}

void set_stiffness(ElementType& t, int n, const char* meaning) {
  t.n_estiff = n;
  t.estiff = meaning;
  t.edampp = "damping coefficients in the form of ESTIFF";
}

void set_emass(ElementType& t, int n, const char* meaning) {
  t.n_emass = n;
  t.emass = meaning;
}

std::vector<ElementType> build_catalogue() {
  const std::vector<std::string> beam_defs = {
      "elongation", "torsion", "bending about local y at p1", "bending about local y at p2",
      "bending about local z at p1", "bending about local z at p2"};
  const std::vector<std::string> beam_nodes = {"p1", "o1", "p2", "o2"};
  const char* beam_vector = "x y z: initial direction of the principal y-axis of the cross-section";
  std::vector<ElementType> t;
  t.reserve(16);

  for (const char* name : {"BEAM", "BEAMNL"}) {
    const bool nl = std::string(name) == "BEAMNL";
    ElementType& e = add(t, name, {K::XYZ, K::Lambda, K::XYZ, K::Lambda}, beam_nodes, beam_defs,
                         nl ? "spatial beam with bending-corrected elongation" : "spatial beam");
    if (nl) e.deformations[0] = "bending-corrected elongation";
    set_params(e, 3, 3, beam_vector);
    set_stiffness(e, 4, "EA GIp EIy EIz");
    set_emass(e, 4, "rhoA [rhoIp rhoIy rhoIz] (rotary inertia: extension)");
    e.has_length = true;
    e.n_lgeomy = 9;
    e.has_direction = true;
    e.reference = reference_beam;
    e.make = nl ? make_beamnl : make_beam;
  }
  {
    ElementType& e = add(t, "TRUSS", {K::XYZ, K::XYZ}, {"p1", "p2"}, {"elongation"}, "spatial truss");
    set_stiffness(e, 1, "EA");
    set_emass(e, 1, "rhoA");
    e.has_length = true;
    e.reference = reference_truss;
    e.make = make_truss;
  }
  {
    ElementType& e = add(t, "HINGE", {K::Lambda, K::Lambda}, {"o1", "o2"},
                         {"rotation about the axis", "misalignment about local y",
                          "misalignment about local z"},
                         "spatial hinge");
    set_params(e, 3, 3, "x y z: initial axis of rotation");
    set_stiffness(e, 1, "St (torsional stiffness of the rotation)");
    e.has_direction = true;
    e.make = make_hinge;
  }
  {
    ElementType& e = add(t, "BEARING", {K::XYZ, K::Lambda, K::XYZ, K::Lambda}, beam_nodes,
                         {"axial displacement", "radial displacement along local y",
                          "radial displacement along local z", "rotation about the axis",
                          "misalignment about local y", "misalignment about local z"},
                         "spatial bearing");
    set_params(e, 3, 3, "x y z: initial axis of rotation");
    e.n_lgeomy = 3;
    e.has_direction = true;
    e.reference = reference_bearing;
    e.make = make_bearing;
  }
  {
    ElementType& e = add(t, "SURFACE", {K::XYZ}, {"p1"}, {"surface function value"},
                         "point on a quadratic surface");
    set_params(e, 10, 10,
               "c1..c10: coefficients of c1x²+c2y²+c3z²+c4xy+c5yz+c6zx+c7x+c8y+c9z+c10");
    e.make = make_surface;
  }
  add(t, "L2MIN1", {K::Lambda}, {"o1"}, {"Euler parameter norm λᵀλ − 1"},
      "constraint on the Euler parameters (created automatically for every LAMBDA node)")
      .make = make_l2min1;
  for (const char* name : {"PLBEAM", "PLBEAMNL"}) {
    const bool nl = std::string(name) == "PLBEAMNL";
    ElementType& e = add(t, name, {K::XY, K::Beta, K::XY, K::Beta}, beam_nodes,
                         {nl ? "bending-corrected elongation" : "elongation", "bending at p1",
                          "bending at p2"},
                         nl ? "planar beam with bending-corrected elongation" : "planar beam");
    set_stiffness(e, 2, "EA EI");
    set_emass(e, 1, "rhoA");
    e.has_length = true;
    e.n_lgeomy = 1;
    e.reference = reference_plbeam;
    e.make = nl ? make_plbeamnl : make_plbeam;
  }
  {
    ElementType& e = add(t, "PLHINGE", {K::Beta, K::Beta}, {"o1", "o2"}, {"relative rotation"},
                         "planar hinge");
    set_stiffness(e, 1, "St (torsional stiffness)");
    e.make = make_plhinge;
  }
  {
    ElementType& e = add(t, "PLTRUSS", {K::XY, K::XY}, {"p1", "p2"}, {"elongation"}, "planar truss");
    set_stiffness(e, 1, "EA");
    set_emass(e, 1, "rhoA");
    e.has_length = true;
    e.reference = reference_pltruss;
    e.make = make_pltruss;
  }
  {
    ElementType& e = add(t, "PLBELT", {K::XY, K::Beta, K::XY, K::Beta}, beam_nodes,
                         {"belt elongation"}, "planar belt");
    set_params(e, 2, 2, "r1 r2: radii of pulley 1 and pulley 2");
    set_stiffness(e, 1, "EA");
    set_emass(e, 3, "rhoA a1 a2 (belt wound on the pulleys: a1*r1 and a2*r2)");
    e.has_length = true;
    e.n_lgeomy = 1;
    e.reference = reference_plbelt;
    e.make = make_plbelt;
  }
  {
    ElementType& e = add(t, "PLBEAR", {K::XY, K::Beta, K::XY, K::Beta}, beam_nodes,
                         {"relative displacement along local x", "relative displacement along local y",
                          "relative rotation"},
                         "planar bearing");
    set_stiffness(e, 3, "Sx Sy St (linear and torsional stiffness)");
    e.n_lgeomy = 2;
    e.reference = reference_plbear;
    e.make = make_plbear;
  }
  {
    ElementType& e = add(t, "PLWHEEL", {K::XY, K::Beta, K::Beta}, {"p1", "o1", "o2"},
                         {"longitudinal slip", "lateral slip"}, "planar wheel");
    set_params(e, 3, 3, "r x y: radius and initial axis of rotation");
    e.edampp = "d1 d2: linear creep damping of the released slips (extension)";
    e.n_estiff = 2;
    e.velocity_level = {true, true};
    e.make = make_plwheel;
  }
  {
    ElementType& e = add(t, "WHEEL", {K::XYZ, K::Lambda}, {"p1", "o1"},
                         {"height of the contact point", "longitudinal slip", "lateral slip"},
                         "knife-edge wheel rolling on a plane or a quadratic surface (extension)");
    set_params(e, 4, 14,
               "ax ay az r [nx ny nz or c1 .. c10]: initial axle direction, radius; ground-plane normal "
               "(default 0 0 1) or the coefficients of a quadratic surface as for SURFACE, positive on the "
               "wheel's side");
    e.n_params_allowed = {4, 7, 14};
    e.extension = true;
    e.velocity_level = {false, true, true};
    e.make = make_wheel;
  }
  return t;
}

}  // namespace

const std::vector<ElementType>& element_catalogue() {
  static const std::vector<ElementType> table = build_catalogue();
  return table;
}

int find_element_type(const std::string& name) {
  const auto& t = element_catalogue();
  for (size_t i = 0; i < t.size(); ++i)
    if (t[i].name == name) return static_cast<int>(i);
  return -1;
}

}  // namespace spacar

// The model: what an input file (or the Python builder) describes. Nodes, elements, the class of
// every nodal coordinate and deformation, initial values, properties and settings, plus the
// current state that the state dump writes. It is edited keyword by keyword until an analysis
// starts; the topology is frozen at the first END (prepare()). Analyses compile it into a
// System (system.hpp) and never modify it except to store the state reached.
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "spacar/catalogue.hpp"

namespace spacar {

// Class of a nodal coordinate (manual §5.3; default calculable).
enum class CoordClass : int { Calculable = 0, Fixed, Input, Dynamic };
// Class of a deformation (default fixed). Kinematic = the coordinate paired with a
// nonholonomic deformation by ENHC.
enum class DefClass : int { Fixed = 0, Released, Input, Dynamic, Linearization, Nonholonomic, Kinematic };

const char* coord_class_name(CoordClass c);
const char* def_class_name(DefClass c);

struct Node {
  int id = 0;
  NodeKind kind = NodeKind::Any;
  std::vector<double> x;          // current coordinates (size node_size(kind))
  std::vector<CoordClass> cls;    // per coordinate
  std::vector<double> xd, xdd;    // current rates (inputs and dynamic coordinates: given/integrated)
  std::vector<double> force;      // FORCE values (empty: none)
  std::vector<double> mass;       // MASS values as given (empty: none)
  std::vector<double> torquel;    // TORQUEL values (empty: none)
  bool used = false;              // referenced by an element
  int x_given = 0;                // number of coordinates given explicitly (X/XY/...)
  std::string origin;             // where the node was first defined by X/XY/... (for messages)
};

struct Element {
  int id = 0;
  int type = -1;                  // index into element_catalogue()
  std::vector<int> nodes;
  std::vector<double> params;     // numbers of the definition line, as given
  std::optional<double> l0;       // LENGTHO (set by the user or at the first END)
  std::vector<double> lgeomy;     // LGEOMY (set by the user or at the first END)
  std::vector<double> estiff, edampp, emass;
  std::vector<DefClass> cls;      // per deformation
  std::vector<double> e, ed, edd; // current values / rates of the deformations
  std::vector<bool> e_given;      // E was given (targets of fixed deformations, initial DOF values)
  std::vector<std::array<int, 2>> kinematic_of;  // nonholonomic: (element, index) of its kinematic coordinate; (0,0) if none
  bool automatic = false;         // L2MIN1 created automatically for a LAMBDA node
  std::string origin;             // where the element was defined, e.g. "f.dat, line 3, keyword PLBEAM"
};

struct Settings {
  int timestep_n = 0;             // TIMESTEP n Tp (n = 0: no integration)
  double timestep_tp = 0.0;
  double hmax = 9.999e3;
  int maxiterat = 10;
  double epskin = 1e-5;
  double epsint = 1e-3;
  double epsind = 1e-3;
  int forcemode = 1;
  int animate = 0;
  int matasc = 0;
  std::optional<int> jobid;
  int restart = 0;
  std::optional<int> linear;      // extension LINEAR 0/1/2
};

class Model {
 public:
  // --- topology (before the first END) ---
  // `origin` names the input line (file, line, keyword) for errors found later, at prepare().
  void add_element(const std::string& type, int id, const std::vector<int>& nodes,
                   const std::vector<double>& params, const std::string& origin = "");
  // X (kind Any) or a typed node keyword: set the first values.size() coordinates.
  void set_coordinates(int node, NodeKind kind, const std::vector<double>& values,
                       const std::string& origin = "");

  // --- boundary conditions; empty index list = all components / deformations ---
  void set_coordinate_class(int node, const std::vector<int>& components, CoordClass cls);
  void set_deformation_class(int element, const std::vector<int>& indices, DefClass cls);
  void set_nonholonomic(int element, int index, int kin_element, int kin_index);

  // --- initial values ---
  void set_xd(int node, int component, double value);
  void set_xdd(int node, int component, double value);
  void set_e(int element, int index, double value);
  void set_ed(int element, int index, double value);
  void set_edd(int element, int index, double value);
  void set_time(double t);
  void set_direction(int element, const std::vector<double>& xyz);
  void set_lgeomy(int element, const std::vector<double>& values);
  void set_lengtho(int element, double l0);

  // --- properties ---
  void set_mass(int node, const std::vector<double>& values);
  void set_emass(int element, const std::vector<double>& values);
  void set_estiff(int element, const std::vector<double>& values);
  void set_edampp(int element, const std::vector<double>& values);
  void set_force(int node, const std::vector<double>& values);
  void set_torquel(int node, const std::vector<double>& values);
  void set_gravity(const std::vector<double>& g);

  // --- settings ---
  void set_timestep(int n, double tp);
  void set_hmax(double h);
  void set_maxiterat(int n);
  void set_epskin(double eps);
  void set_epsint(double eps);
  void set_epsind(double eps);
  void set_forcemode(int mode);
  void set_animate(int flag);
  void set_matasc(int flag);
  void set_jobid(int id);
  void set_restart(int flag);
  void set_linear(int mode);

  // First END: create the automatic L2MIN1 elements, compute the reference geometry, check that
  // every node is used by an element, freeze the topology. Every call (every END) normalises the
  // Euler parameters of the LAMBDA nodes (accepted within 1e-3 of unit length).
  void prepare();
  bool frozen() const { return frozen_; }
  // Deserialisation only (pickle): the model was prepared when it was saved; its reference
  // geometry and automatic elements are part of the saved state, so nothing is recomputed.
  void restore_prepared() { frozen_ = true; }

  // Lookups that raise InputError naming the missing item.
  Node& node(int id);
  const Node& node(int id) const;
  Element& element(int id);
  const Element& element(int id) const;
  const ElementType& type_of(const Element& el) const;

  std::map<int, Node> nodes;
  std::map<int, Element> elements;
  Settings settings;
  double time = 0.0;
  std::array<double, 3> gravity{0.0, 0.0, 0.0};
  bool gravity_given = false;

 private:
  Node& attach_node(int id, NodeKind kind, const std::string& element_name);
  void require_open(const char* what) const;
  int deformation_index(const Element& el, int index) const;  // 1-based → 0-based, checked
  int component_index(const Node& n, int component) const;
  void add_automatic_constraints();
  void compute_reference_geometry();
  bool frozen_ = false;
};

}  // namespace spacar

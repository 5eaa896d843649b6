// The model: what an input file (or the Python builder) describes. Nodes, elements, the class of
// every nodal coordinate and deformation, initial values, properties and settings, plus the
// current state that the state dump writes. It is edited keyword by keyword until an analysis
// starts; the topology is frozen at the first END (prepare()). Analyses compile it into a
// System (system.hpp) and never modify it except to store the state reached.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "spacar/model/catalogue.hpp"

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
  std::vector<double> torqueg;    // TORQUEG values (empty: none)
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

// --- The fields of Node, Element and Settings, each listed once: the Python properties
// (bindings/bind_model.cpp) and the pickled records (serialize.hpp) are generated from these
// tables, in this order (the order is the pickle format: append new fields at the end and raise
// kModelStateVersion). A field is (name, member, doc); `Codec` says how it is stored when it is
// not stored as it is (the element type by name, so that a pickle does not depend on the order
// of the catalogue).

struct AsStored;           // the value itself; enums as their integer
struct ElementTypeByName;  // an index into element_catalogue() stored as the type's name

template <class S, class T, class Codec = AsStored>
struct Field {
  const char* name;
  T S::*member;
  const char* doc;
};

template <class Codec = AsStored, class S, class T>
constexpr Field<S, T, Codec> field(const char* name, T S::*member, const char* doc) {
  return {name, member, doc};
}

inline constexpr auto kNodeFields = std::make_tuple(
    field("id", &Node::id, "node number"),
    field("kind", &Node::kind, "node kind (X: given by X only, not yet used by an element)"),
    field("x", &Node::x, "current coordinates"),
    field("cls", &Node::cls, "class of every coordinate"),
    field("xd", &Node::xd, "current velocities"),
    field("xdd", &Node::xdd, "current accelerations"),
    field("force", &Node::force, "FORCE values (empty: none)"),
    field("mass", &Node::mass, "MASS values as given (empty: none)"),
    field("torquel", &Node::torquel, "TORQUEL values (empty: none)"),
    field("torqueg", &Node::torqueg, "TORQUEG values (empty: none)"),
    field("used", &Node::used, "referenced by an element"),
    field("x_given", &Node::x_given, "number of coordinates given explicitly (X/XY/...)"),
    field("origin", &Node::origin, "where the node was first defined (for messages)"));

inline constexpr auto kElementFields = std::make_tuple(
    field("id", &Element::id, "element number"),
    field<ElementTypeByName>("type", &Element::type, "index into the element catalogue"),
    field("nodes", &Element::nodes, "node numbers in the order of the definition line"),
    field("params", &Element::params, "numbers of the definition line, as given"),
    field("l0", &Element::l0, "LENGTHO (set by the user or at the first END)"),
    field("lgeomy", &Element::lgeomy, "LGEOMY (set by the user or at the first END)"),
    field("estiff", &Element::estiff, "ESTIFF values"),
    field("edampp", &Element::edampp, "EDAMPP values"),
    field("emass", &Element::emass, "EMASS values"),
    field("cls", &Element::cls, "class of every deformation"),
    field("e", &Element::e, "current deformations"),
    field("ed", &Element::ed, "current deformation rates"),
    field("edd", &Element::edd, "current deformation accelerations"),
    field("e_given", &Element::e_given, "E was given (targets of fixed deformations, initial DOF values)"),
    field("kinematic_of", &Element::kinematic_of,
          "nonholonomic deformations: (element, index) of the kinematic coordinate; (0, 0) if none"),
    field("automatic", &Element::automatic, "L2MIN1 created automatically for a LAMBDA node"),
    field("origin", &Element::origin, "where the element was defined (file, line, keyword)"));

inline constexpr auto kSettingsFields = std::make_tuple(
    field("timestep_n", &Settings::timestep_n, "TIMESTEP n: output intervals (0: no integration)"),
    field("timestep_tp", &Settings::timestep_tp, "TIMESTEP Tp: period of the block"),
    field("hmax", &Settings::hmax, "HMAX: largest integration step"),
    field("maxiterat", &Settings::maxiterat, "MAXITERAT: Newton iterations"),
    field("epskin", &Settings::epskin, "EPSKIN: tolerance of the kinematics"),
    field("epsint", &Settings::epsint, "EPSINT: tolerance of the integration (positions)"),
    field("epsind", &Settings::epsind, "EPSIND: tolerance of the integration (velocities)"),
    field("forcemode", &Settings::forcemode, "FORCEMODE"),
    field("animate", &Settings::animate, "ANIMATE"),
    field("matasc", &Settings::matasc, "MATASC"),
    field("jobid", &Settings::jobid, "JOBID (None: not given)"),
    field("restart", &Settings::restart, "RESTART"),
    field("linear", &Settings::linear, "LINEAR 0/1/2 (None: not given)"));

class Model;

// A copy of a model as it was when the copy was asked for (Model::lazy_copy), made only when it
// is first needed: when the model is about to change (its methods, an analysis storing its state),
// is destroyed or assigned, or when the copy is read. spacar.static and spacar.simulate keep one
// in their results (for the drawing, the DOF labels, compliance): a model of 512 beams copied at
// once is 11 000 allocations, 7 % of its cold static solve, for results that are rarely drawn.
class LazyModelCopy {
 public:
  // A Model equal to the model as it was (a new one at every call).
  Model model();

 private:
  friend class Model;
  friend class PendingCopies;
  void take(const Model& live);  // the copy made now, if not yet
  std::mutex mutex_;
  const Model* live_ = nullptr;  // the model, unchanged since, while the copy is not made
  std::unique_ptr<Model> copy_;
};

// The lazy copies of a model not yet made. Not copied or moved with the model: a copy or a moved-to
// model has none, and a moved-from or assigned-to model makes its own first (it is declared first
// in Model, so that this happens before any other member changes).
class PendingCopies {
 public:
  PendingCopies() = default;
  PendingCopies(const PendingCopies&) {}
  PendingCopies(PendingCopies&& other) { other.make(); }
  PendingCopies& operator=(const PendingCopies&) {
    make();
    return *this;
  }
  PendingCopies& operator=(PendingCopies&& other) {
    make();
    other.make();
    return *this;
  }
  ~PendingCopies() = default;
  bool empty() const { return list_.empty(); }
  void add(const Model& owner, const std::shared_ptr<LazyModelCopy>& copy);
  void make();  // every pending copy made from the owner as it is now
  void abandon();  // the pending copies told that they cannot be made (their model() raises)

 private:
  const Model* owner_ = nullptr;
  std::vector<std::weak_ptr<LazyModelCopy>> list_;
};

class Model {
  mutable PendingCopies pending_;  // first: see PendingCopies

 public:
  Model() = default;
  Model(const Model&) = default;
  Model(Model&&) = default;
  Model& operator=(const Model&) = default;
  Model& operator=(Model&&) = default;
  ~Model() {
    try {
      before_change();
    } catch (...) {  // out of memory: the results that kept this model raise when they need it
      pending_.abandon();
    }
  }

  // A copy of the model as it is now, made when first needed (LazyModelCopy).
  std::shared_ptr<LazyModelCopy> lazy_copy() const;
  // Called first by everything that changes the model (its methods here, the writable node() and
  // element(), Simulation::store_state; anything that writes the public members below must call
  // it first): the lazy copies not yet made are made now, of the model as it still is. Not safe
  // for two threads changing one model at once (no analysis is). Every call counts as a change
  // (revision()).
  void before_change() {
    if (!pending_.empty()) pending_.make();
    revision_.count.fetch_add(1, std::memory_order_relaxed);
  }
  // How many changes the model has seen (before_change() calls, assignments): a Simulation kept
  // for the next run of an unchanged model (Simulation::renew) checks it.
  std::uint64_t revision() const { return revision_.count.load(std::memory_order_relaxed); }

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
  void set_torqueg(int node, const std::vector<double>& values);
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
  void restore_prepared() {
    before_change();
    frozen_ = true;
  }

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
  // Not the value of a model: a copy starts at 0, a model assigned to counts the assignment as a
  // change (a Simulation bound to it must not take the other model's count for its own). Atomic:
  // a change from another thread during a run must be seen by the run's end (Simulation::run).
  struct Revision {
    Revision() = default;
    Revision(const Revision&) {}
    Revision& operator=(const Revision&) {
      count.fetch_add(1, std::memory_order_relaxed);
      return *this;
    }
    std::atomic<std::uint64_t> count{0};
  } revision_;
};

}  // namespace spacar

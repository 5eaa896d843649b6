// System: the frozen, analysis-ready form of a Model, compiled at every END. It holds the
// element kernels with their global coordinate indices, the partition of coordinates and
// deformations into classes (formulation.md §1.3) and the constant loads. It never changes
// during an analysis; everything that does lives in Data (data.hpp).
#pragma once

#include <Eigen/Dense>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "spacar/elements/element.hpp"
#include "spacar/model/model.hpp"

namespace spacar {

struct SystemElement {
  int id = 0;
  int type = -1;
  std::unique_ptr<ElementKernel> kernel;
  std::vector<int> coords;      // global coordinate index of each local coordinate
  int def_offset = 0;           // first global deformation index
  int nd = 0;
  bool has_constitutive = false;
  Eigen::MatrixXd S, D;         // stiffness and damping matrices (nd x nd)
  bool has_mass = false;
};

// A LAMBDA node whose rotation is free (at least three Euler parameters are dynamic): three
// parameters are degrees of freedom and the dependent one is solved from L2MIN1. The engine
// picks the dependent one with the largest magnitude and re-picks when it gets small, so that
// rotations through 180° never make the normalisation singular.
struct FreeRotation {
  int node = 0;                 // node number
  int coord = 0;                // first Euler parameter coordinate
  int dependent = 0;            // 0..3: the calculable parameter
  std::array<int, 3> dofs{};    // positions in q of the three dynamic parameters
};

// A rigid body on a LAMBDA node: body-frame inertia tensor J'.
struct BodyInertia {
  int coord = 0;                // first of the 4 Euler parameter coordinates
  Eigen::Matrix3d J;
};

// A constant torque on a LAMBDA node: body-fixed (TORQUEL, a follower load) or in global axes
// (TORQUEG, a dead load). Its generalized force 2 Pᵀ(λ) T, P = G (body) or E (global), is linear
// in λ: the load stiffness is a constant 4 x 4 matrix.
struct Torque {
  int coord;          // first λ coordinate
  Eigen::Vector3d T;  // components in the body frame (TORQUEL) or global axes (TORQUEG)
  bool global;
  Eigen::Vector4d force(const double* l) const;  // 2 Pᵀ(λ) T
  Eigen::Matrix4d stiffness() const;             // −∂force/∂λ
};

struct System {
  System() = default;
  System(const System&) = delete;  // owns the element kernels
  System& operator=(const System&) = delete;

  int nx = 0, ne = 0;
  std::vector<SystemElement> elements;

  // Labels: node/element number and 1-based component/deformation index.
  std::vector<std::array<int, 2>> coord_label, def_label;
  std::vector<NodeKind> coord_node_kind;
  std::vector<CoordClass> coord_class;
  std::vector<DefClass> def_class;

  // Index lists (global indices, ascending) per class.
  std::vector<int> x_fixed, x_calc, x_input, x_dyn;
  std::vector<int> e_fixed, e_released, e_input, e_dyn, e_line, e_nonholonomic, e_kinematic;
  // The deformation of each row of the constraint blocks (row → deformation; row_P and row_V
  // below are the inverse maps).
  std::vector<int> defs_P;      // deformations with known values: position constraint rows
  std::vector<int> defs_V;      // deformations with known rates: velocity constraint rows
  // defs_P == defs_V (no nonholonomic or kinematic rows): A_V is A_P, the same rows and pattern.
  bool velocity_block_is_position_block = false;
  std::vector<int> auto_released;  // fixed rows with no calculable coordinate, checked instead
  std::vector<int> e_element;   // element (index into elements) of each deformation
  // Deformations defined up to a period (angles), unwrapped to continuous values: (index, period).
  std::vector<std::pair<int, double>> periodic_defs;
  std::vector<char> def_velocity_level;  // only the rate is defined: the value is integrated

  // Maps from global index to position.
  std::vector<int> calc_pos;    // coordinate → column in the constraint block, −1 if not calculable
  std::vector<int> row_P, row_V;  // deformation → row in P / V, −1
  std::vector<int> qhat_col_x, qhat_col_e;  // coordinate/deformation → column of q̂, −1

  // q̂ = (x^p, x^d, e^p, e^d); q = (x^d, e^d) are the degrees of freedom, p = (x^p, e^p) the inputs.
  int n_qhat() const { return static_cast<int>(x_input.size() + x_dyn.size() + e_input.size() + e_dyn.size()); }
  int n_dof() const { return static_cast<int>(x_dyn.size() + e_dyn.size()); }
  int n_input() const { return static_cast<int>(x_input.size() + e_input.size()); }
  std::vector<int> dof_cols, input_cols;  // columns of q̂ that are DOFs / inputs

  // Prescribed motion of the inputs (p0 at t0, constant acceleration), ordered as input_cols.
  double t0 = 0.0;
  Eigen::VectorXd p0, pd0, pdd0;
  // Targets of fixed / LINE deformations (global deformation index → value); for DOF and
  // kinematic deformations their initial values.
  Eigen::VectorXd e_target;
  // Initial values of the degrees of freedom and their rates.
  Eigen::VectorXd q0, qd0;
  // Deformations integrated as first-order states y (ascending): the kinematic coordinates of
  // nonholonomic constraints and the values of released velocity-level deformations; y0 initial.
  std::vector<int> y_defs;
  Eigen::VectorXd y0;
  // Warnings found while compiling (printed as comments by the front ends); the first
  // n_structure_warnings of them come before those reload_state makes again (of the state, and
  // of the fixed deformations that are checked, not solved, which it lists last as compile did).
  std::vector<std::string> warnings;
  size_t n_structure_warnings = 0;

  // Mass and loads.
  Eigen::VectorXd point_mass;   // per coordinate: m on position coordinates, Izz on BETA (0 if none)
  std::vector<BodyInertia> bodies;
  std::vector<FreeRotation> free_rotations;
  Eigen::VectorXd force;        // constant applied loads per coordinate (FORCE)
  std::vector<Torque> torques;  // TORQUEL and TORQUEG
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  int dim = 2;                  // 2 for planar models, 3 if any spatial node exists
  double length_scale = 1.0;    // mean reference length of the elements (1 if none): step sizes
  std::vector<char> coord_is_length, def_is_length;  // length-type (vs angle-type) quantities

  Settings settings;

  std::string coord_name(int g) const;  // "node 3 component 2"
  std::string def_name(int k) const;    // "element 2 (PLBEAM) deformation 3"
};

// Compile a prepared model (Model::prepare() has run). Throws InputError for classifications
// that cannot be analysed.
// `dependent` overrides the dependent Euler parameter (0..3) of free rotations by node number.
// line_as_dof: LINE parameters become coordinates (dynamic), for the linearized equations.
std::unique_ptr<System> compile(const Model& model, const std::map<int, int>& dependent = {},
                                bool line_as_dof = false);

// The parts of a compiled system that follow the model's state (time, positions, rates, deformation
// values; its warnings of them) read again, for another run of a model whose structure has not
// changed (Simulation::renew): what compile() would give, without free rotations (whose partition
// follows the state too).
void reload_state(const Model& model, System& sys);

}  // namespace spacar

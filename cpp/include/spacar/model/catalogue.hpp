// The element catalogue: ONE table describing every element type of the SPACAR95 manual (§5.1)
// plus the extensions. The reader, the writer, the Python builder methods, the drawings and the
// generated keyword reference in docs/ are all driven by it. Each row is written in its element's
// source file next to the kernel (cpp/src/elements/); the list of element types is
// spacar/elements/list.hpp (docs/adding-an-element.md).
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace spacar {

// Node kinds. `Any` is a node only given by the generic keyword X and not yet used by an
// element; every element slot has a concrete kind.
enum class NodeKind : int { Any = 0, XY, Beta, XYZ, Lambda };

int node_size(NodeKind kind);             // number of coordinates (Any: 4, the maximum)
const char* node_keyword(NodeKind kind);  // "X", "XY", "BETA", "XYZ", "LAMBDA"
bool is_orientation(NodeKind kind);

class ElementKernel;
struct ElementSetup;

// The kind of an element, for the code that treats the planar and spatial versions of a kind
// alike: the recursive planar path (beams are bodies, hinges joints, cpp/src/tree.cpp) and the
// drawings (python/spacar/geometry.py). Other: no special treatment; drawn as a line through its
// position nodes (a point if it has one).
enum class ElementFamily : int { Other = 0, Beam, Truss, Hinge, Belt, Wheel, Bearing };

// Reference geometry from the initial positions (orientation nodes at their reference value):
// fills the reference length l0 (if the type has one) and the LGEOMY values.
using ReferenceFn = void (*)(const double* x_ref, const std::vector<double>& params, double& l0,
                             std::vector<double>& lgeomy);
using MakeFn = std::unique_ptr<ElementKernel> (*)(const ElementSetup& setup);

struct ElementType {
  std::string name;                       // input keyword, e.g. "PLBEAM"
  std::vector<NodeKind> nodes;            // node slots in input order
  std::vector<std::string> node_roles;    // e.g. {"p1", "o1", "p2", "o2"}
  std::vector<std::string> deformations;  // meaning of e1, e2, ...
  int n_params_min = 0, n_params_max = 0; // numbers after the node list on the definition line
  std::vector<int> n_params_allowed;       // the counts in [min, max] that are valid (empty: all)
  std::string params;                     // their meaning ("" if none)
  std::string estiff, edampp, emass;      // meaning of ESTIFF / EDAMPP / EMASS values ("" = not used)
  int n_estiff = 0, n_emass = 0;          // maximum number of ESTIFF/EDAMPP and EMASS values
  bool signed_emass_extras = false;       // EMASS values after the first may be negative (PLBELT's
                                          // winding factors); the first, a mass, never
  bool has_length = false;                // LENGTHO applies
  int n_lgeomy = 0;                       // number of LGEOMY values
  bool has_direction = false;             // DIR replaces the vector of the definition line
  bool extension = false;                 // not in the SPACAR95 manual
  bool automatic = false;                 // created for every LAMBDA node without one (L2MIN1, the
                                          // normalisation of its Euler parameters, manual §5.1)
  ElementFamily family = ElementFamily::Other;
  std::vector<bool> velocity_level;       // per deformation: only its rate is defined (wheel slips);
                                          // read from the kernel (kVelocityRows)
  std::string description;
  ReferenceFn reference = nullptr;        // nullptr: no reference geometry
  MakeFn make = nullptr;                  // the kernel of an element of this type

  int n_deformations() const { return static_cast<int>(deformations.size()); }
  int n_coordinates() const;
};

const std::vector<ElementType>& element_catalogue();
// Index of the type in element_catalogue(), or -1.
int find_element_type(const std::string& name);
// Index of the type created automatically for LAMBDA nodes (ElementType::automatic).
int automatic_element_type();

}  // namespace spacar

// What an element's source file needs to define its type: the kernel interface, the catalogue
// row and `element_type<Kernel>`, which starts a row from the kernel so that the sizes are
// written once. The declarations of all rows are generated from the list (list.hpp).
#pragma once

#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "spacar/model/catalogue.hpp"
#include "spacar/elements/element.hpp"
#include "spacar/errors.hpp"

namespace spacar {

#define SPACAR_ELEMENT(name) ElementType name##_element_type();
#include "spacar/elements/list.hpp"
#undef SPACAR_ELEMENT

// The start of the catalogue row of an element type computed by Kernel (an AutoDiffElement):
// name, node slots (kind and role, in input order), deformation names and a one-line
// description. The number of deformation names must be the kernel's ND (checked at compile
// time) and the node kinds must give its NC coordinates (checked when the catalogue is built,
// at import); the velocity-level rows are the kernel's kVelocityRows and the factory constructs
// the kernel from the ElementSetup (or by default if it takes none).
template <class Kernel, std::size_t NN, std::size_t NR, std::size_t ND>
ElementType element_type(const char* name, const NodeKind (&nodes)[NN], const char* const (&roles)[NR],
                         const char* const (&deformations)[ND], const char* description) {
  static_assert(NR == NN, "one role per node slot");
  static_assert(ND == Kernel::kDeformations, "one deformation name per deformation of the kernel");
  ElementType t;
  t.name = name;
  t.nodes.assign(nodes, nodes + NN);
  t.node_roles.assign(roles, roles + NR);
  t.deformations.assign(deformations, deformations + ND);
  t.description = description;
  for (std::size_t i = 0; i < ND; ++i) t.velocity_level.push_back((Kernel::kVelocityMask >> i) & 1u);
  if (t.n_coordinates() != Kernel::kCoords)
    throw std::logic_error(t.name + ": the node slots have " + std::to_string(t.n_coordinates()) +
                           " coordinates, the kernel " + std::to_string(Kernel::kCoords));
  t.make = []([[maybe_unused]] const ElementSetup& setup) -> std::unique_ptr<ElementKernel> {
    if constexpr (std::is_constructible_v<Kernel, const ElementSetup&>)
      return std::make_unique<Kernel>(setup);
    else
      return std::make_unique<Kernel>();
  };
  return t;
}

// The numbers after the node list on the definition line: how many and what they mean.
inline void set_params(ElementType& t, int n_min, int n_max, const char* meaning) {
  t.n_params_min = n_min;
  t.n_params_max = n_max;
  t.params = meaning;
}

// Up to n ESTIFF values (and EDAMPP values of the same form) with their meaning.
inline void set_stiffness(ElementType& t, int n, const char* meaning) {
  t.n_estiff = n;
  t.estiff = meaning;
  t.edampp = "damping coefficients in the form of ESTIFF";
}

// Up to n EMASS values with their meaning.
inline void set_emass(ElementType& t, int n, const char* meaning) {
  t.n_emass = n;
  t.emass = meaning;
}

}  // namespace spacar

// The element catalogue (catalogue.hpp) as seen from Python.
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "spacar/catalogue.hpp"

namespace spacar::bindings {

void bind_catalogue(py::module_& m) {
  py::enum_<NodeKind>(m, "NodeKind")
      .value("X", NodeKind::Any)
      .value("XY", NodeKind::XY)
      .value("BETA", NodeKind::Beta)
      .value("XYZ", NodeKind::XYZ)
      .value("LAMBDA", NodeKind::Lambda);
  m.def("node_size", &node_size);
  py::enum_<ElementFamily>(m, "ElementFamily")
      .value("Other", ElementFamily::Other)
      .value("Beam", ElementFamily::Beam)
      .value("Truss", ElementFamily::Truss)
      .value("Hinge", ElementFamily::Hinge)
      .value("Belt", ElementFamily::Belt)
      .value("Wheel", ElementFamily::Wheel);
  py::class_<ElementType>(m, "ElementType")
      .def_readonly("name", &ElementType::name)
      .def_readonly("nodes", &ElementType::nodes)
      .def_readonly("node_roles", &ElementType::node_roles)
      .def_readonly("deformations", &ElementType::deformations)
      .def_readonly("n_params_min", &ElementType::n_params_min)
      .def_readonly("n_params_max", &ElementType::n_params_max)
      .def_readonly("params", &ElementType::params)
      .def_readonly("estiff", &ElementType::estiff)
      .def_readonly("edampp", &ElementType::edampp)
      .def_readonly("emass", &ElementType::emass)
      .def_readonly("n_estiff", &ElementType::n_estiff)
      .def_readonly("n_emass", &ElementType::n_emass)
      .def_readonly("has_length", &ElementType::has_length)
      .def_readonly("n_lgeomy", &ElementType::n_lgeomy)
      .def_readonly("has_direction", &ElementType::has_direction)
      .def_readonly("extension", &ElementType::extension)
      .def_readonly("velocity_level", &ElementType::velocity_level)
      .def_readonly("signed_emass_extras", &ElementType::signed_emass_extras)
      .def_readonly("automatic", &ElementType::automatic)
      .def_readonly("family", &ElementType::family)
      .def_readonly("description", &ElementType::description)
      .def_property_readonly("n_deformations", &ElementType::n_deformations);
  m.def("element_catalogue", &element_catalogue, py::return_value_policy::reference);
}

}  // namespace spacar::bindings

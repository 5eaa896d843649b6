// The element catalogue (catalogue.hpp) as seen from Python.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>

#include "bindings.hpp"
#include "spacar/model/catalogue.hpp"
#include "spacar/errors.hpp"

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
      .value("Wheel", ElementFamily::Wheel)
      .value("Bearing", ElementFamily::Bearing);
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
  m.def(
      "element_deformations",
      [](const std::string& type, const RowMatrix& x, const std::vector<double>& params, double l0,
         const std::vector<double>& lgeomy) {
        const int t = find_element_type(type);
        if (t < 0) throw InputError("unknown element type " + type);
        ElementSetup s;
        s.params = params;
        s.l0 = l0;
        s.lgeomy = lgeomy;
        const std::unique_ptr<ElementKernel> k = element_catalogue()[t].make(s);
        if (x.cols() != k->n_coords())
          throw InputError(type + ": x must have " + std::to_string(k->n_coords()) + " columns");
        RowMatrix e(x.rows(), k->n_deformations());
        for (Eigen::Index r = 0; r < x.rows(); ++r) k->deformations(x.row(r).data(), e.row(r).data());
        return e;
      },
      py::arg("type"), py::arg("x"), py::arg("params") = std::vector<double>{}, py::arg("l0") = 1.0,
      py::arg("lgeomy") = std::vector<double>{},
      "The deformations of one element of the given type and properties at its nodal coordinates: one row of "
      "x per state, one row of the result per state (spacar.compare maps a peer's states to spacar's "
      "deformations with it, the element's kernel made once for all of them).");
}

}  // namespace spacar::bindings

// The model (model.hpp): its builder methods, its fields read-only, and its pickling.
#include <pybind11/stl.h>

#include <sstream>
#include <string>

#include "bindings.hpp"
#include "spacar/model/model.hpp"
#include "spacar/model/serialize.hpp"

namespace spacar::bindings {

namespace {

// A read-only property per field of the table (model.hpp).
template <class S, class... F>
py::class_<S> bind_fields(py::module_& m, const char* name, const std::tuple<F...>& fields) {
  py::class_<S> cls(m, name);
  std::apply([&cls](const auto&... f) { (cls.def_readonly(f.name, f.member, f.doc), ...); }, fields);
  return cls;
}

// Pickling: the state of serialize.hpp as Python tuples, lists, numbers and strings.
Model model_from_pickle(const py::tuple& state) {
  ModelState s;
  try {
    s = state.cast<ModelState>();
  } catch (const py::cast_error&) {
    bad_model_state("unknown format (saved by another version of spacar?)");
  }
  return model_from_state(s);
}

const char* class_name(CoordClass c) { return coord_class_name(c); }
const char* class_name(DefClass c) { return def_class_name(c); }

// "(0.5, 0)" and "[fixed, dynamic]": the values and classes of a repr.
template <class V>
std::string values(const V& v) {
  std::ostringstream os;
  os << "(";
  for (size_t i = 0; i < v.size(); ++i) os << (i ? ", " : "") << v[i];
  os << ")";
  return os.str();
}

template <class C>
std::string classes(const std::vector<C>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += std::string(i ? ", " : "") + class_name(v[i]);
  return s + "]";
}

// <Node 3 XY x = (0.5, 0) [calculable, calculable]>
std::string node_repr(const Node& n) {
  return "<Node " + std::to_string(n.id) + " " + node_keyword(n.kind) + " x = " + values(n.x) + " " + classes(n.cls) + ">";
}

// <Element 2 PLBEAM nodes (3, 4, 5, 6) e = (0, 0, 0) [fixed, dynamic, dynamic]>
std::string element_repr(const Element& e) {
  return "<Element " + std::to_string(e.id) + " " + element_catalogue()[e.type].name + " nodes " + values(e.nodes) +
         " e = " + values(e.e) + " " + classes(e.cls) + ">";
}

}  // namespace

void bind_model(py::module_& m) {
  py::enum_<CoordClass>(m, "CoordClass")
      .value("calculable", CoordClass::Calculable)
      .value("fixed", CoordClass::Fixed)
      .value("input", CoordClass::Input)
      .value("dynamic", CoordClass::Dynamic);
  py::enum_<DefClass>(m, "DefClass")
      .value("fixed", DefClass::Fixed)
      .value("released", DefClass::Released)
      .value("input", DefClass::Input)
      .value("dynamic", DefClass::Dynamic)
      .value("linearization", DefClass::Linearization)
      .value("nonholonomic", DefClass::Nonholonomic)
      .value("kinematic", DefClass::Kinematic);

  bind_fields<Node>(m, "Node", kNodeFields).def("__repr__", &node_repr);
  bind_fields<Element>(m, "Element", kElementFields)
      .def_property_readonly("type_name", [](const Element& e) { return element_catalogue()[e.type].name; })
      .def("__repr__", &element_repr);
  bind_fields<Settings>(m, "Settings", kSettingsFields);

  py::class_<LazyModelCopy, std::shared_ptr<LazyModelCopy>>(
      m, "LazyModelCopy", "A model's copy made when first needed (spacar/model/model.hpp)")
      .def("model", &LazyModelCopy::model, "A Model equal to the model as it was (a new one at every call)");
  py::class_<Model>(m, "Model")
      .def(py::init<>())
      .def("copy", [](const Model& self) { return Model(self); })
      .def("lazy_copy", &Model::lazy_copy,
           "A copy of the model as it is now, made when first needed (spacar._core.LazyModelCopy): when the "
           "model changes next, or when its model() is asked for")
      .def(py::pickle([](const Model& self) { return py::cast(model_state(self)).cast<py::tuple>(); },
                      &model_from_pickle))
      .def("add_element", &Model::add_element, py::arg("type"), py::arg("id"), py::arg("nodes"),
           py::arg("params"), py::arg("origin") = "")
      .def("set_coordinates", &Model::set_coordinates, py::arg("node"), py::arg("kind"), py::arg("values"),
           py::arg("origin") = "")
      .def("set_coordinate_class", &Model::set_coordinate_class)
      .def("set_deformation_class", &Model::set_deformation_class)
      .def("set_nonholonomic", &Model::set_nonholonomic)
      .def("set_xd", &Model::set_xd)
      .def("set_xdd", &Model::set_xdd)
      .def("set_e", &Model::set_e)
      .def("set_ed", &Model::set_ed)
      .def("set_edd", &Model::set_edd)
      .def("set_time", &Model::set_time)
      .def("set_direction", &Model::set_direction)
      .def("set_lgeomy", &Model::set_lgeomy)
      .def("set_lengtho", &Model::set_lengtho)
      .def("set_mass", &Model::set_mass)
      .def("set_emass", &Model::set_emass)
      .def("set_estiff", &Model::set_estiff)
      .def("set_edampp", &Model::set_edampp)
      .def("set_force", &Model::set_force)
      .def("set_torquel", &Model::set_torquel)
      .def("set_torqueg", &Model::set_torqueg)
      .def("set_gravity", &Model::set_gravity)
      .def("set_timestep", &Model::set_timestep)
      .def("set_hmax", &Model::set_hmax)
      .def("set_maxiterat", &Model::set_maxiterat)
      .def("set_epskin", &Model::set_epskin)
      .def("set_epsint", &Model::set_epsint)
      .def("set_epsind", &Model::set_epsind)
      .def("set_forcemode", &Model::set_forcemode)
      .def("set_animate", &Model::set_animate)
      .def("set_matasc", &Model::set_matasc)
      .def("set_jobid", &Model::set_jobid)
      .def("set_restart", &Model::set_restart)
      .def("set_linear", &Model::set_linear)
      .def("prepare", &Model::prepare)
      .def_property_readonly("frozen", &Model::frozen)
      .def_readonly("nodes", &Model::nodes)
      .def_readonly("elements", &Model::elements)
      .def(
          "element_type_name", [](const Model& m, int id) { return element_catalogue()[m.element(id).type].name; },
          py::arg("id"), "The type of element id, without the copy of every element that `elements` makes.")
      .def_readonly("settings", &Model::settings)
      .def_readonly("time", &Model::time)
      .def_readonly("gravity", &Model::gravity)
      .def_readonly("gravity_given", &Model::gravity_given);
}

}  // namespace spacar::bindings

// The model (model.hpp): its builder methods, its fields read-only, and its pickling.
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "spacar/errors.hpp"
#include "spacar/model.hpp"

namespace spacar::bindings {

namespace {

// --- pickling of the model: every field, exactly (floats are Python floats), so that a model
// sent to another process (spacar.sweep, dask) is the same model, state included.

constexpr int kModelStateVersion = 1;

template <class T>
std::vector<int> enum_ints(const std::vector<T>& v) {
  std::vector<int> out;
  for (T c : v) out.push_back(static_cast<int>(c));
  return out;
}

[[noreturn]] void bad_state(const std::string& why) {
  throw InputError("invalid pickled spacar model: " + why);
}

template <class T>
std::vector<T> to_enums(const std::vector<int>& v, int max_value, const char* what) {
  std::vector<T> out;
  for (int c : v) {
    if (c < 0 || c > max_value) bad_state(std::string(what) + " out of range");
    out.push_back(static_cast<T>(c));
  }
  return out;
}

py::tuple model_state(const Model& m) {
  py::list nodes, elements;
  for (const auto& [id, n] : m.nodes)
    nodes.append(py::make_tuple(n.id, static_cast<int>(n.kind), n.x, enum_ints(n.cls), n.xd, n.xdd, n.force,
                                n.mass, n.torquel, n.used, n.x_given, n.origin));
  for (const auto& [id, el] : m.elements) {
    std::vector<bool> given(el.e_given.begin(), el.e_given.end());
    elements.append(py::make_tuple(el.id, element_catalogue()[el.type].name, el.nodes, el.params, el.l0, el.lgeomy,
                                   el.estiff, el.edampp, el.emass, enum_ints(el.cls), el.e, el.ed, el.edd, given,
                                   el.kinematic_of, el.automatic, el.origin));
  }
  const Settings& st = m.settings;
  py::tuple settings = py::make_tuple(st.timestep_n, st.timestep_tp, st.hmax, st.maxiterat, st.epskin, st.epsint,
                                      st.epsind, st.forcemode, st.animate, st.matasc, st.jobid, st.restart, st.linear);
  return py::make_tuple(kModelStateVersion, nodes, elements, settings, m.time, m.gravity, m.gravity_given,
                        m.frozen());
}

Model model_from_state(const py::tuple& state) {
  if (state.size() != 8 || state[0].cast<int>() != kModelStateVersion)
    bad_state("unknown format (saved by another version of spacar?)");
  Model m;
  for (const py::handle& h : state[1].cast<py::list>()) {
    const py::tuple t = h.cast<py::tuple>();
    if (t.size() != 12) bad_state("node record");
    Node n;
    n.id = t[0].cast<int>();
    const int kind = t[1].cast<int>();
    if (kind < static_cast<int>(NodeKind::Any) || kind > static_cast<int>(NodeKind::Lambda)) bad_state("node kind");
    n.kind = static_cast<NodeKind>(kind);
    n.x = t[2].cast<std::vector<double>>();
    n.cls = to_enums<CoordClass>(t[3].cast<std::vector<int>>(), 3, "coordinate class");
    n.xd = t[4].cast<std::vector<double>>();
    n.xdd = t[5].cast<std::vector<double>>();
    n.force = t[6].cast<std::vector<double>>();
    n.mass = t[7].cast<std::vector<double>>();
    n.torquel = t[8].cast<std::vector<double>>();
    n.used = t[9].cast<bool>();
    n.x_given = t[10].cast<int>();
    n.origin = t[11].cast<std::string>();
    const size_t size = n.kind == NodeKind::Any ? 4 : static_cast<size_t>(node_size(n.kind));
    if (n.id <= 0 || n.x.size() != size || n.cls.size() != size || n.xd.size() != size || n.xdd.size() != size ||
        m.nodes.count(n.id))
      bad_state("node " + std::to_string(n.id));
    m.nodes.emplace(n.id, std::move(n));
  }
  for (const py::handle& h : state[2].cast<py::list>()) {
    const py::tuple t = h.cast<py::tuple>();
    if (t.size() != 17) bad_state("element record");
    Element el;
    el.id = t[0].cast<int>();
    el.type = find_element_type(t[1].cast<std::string>());
    if (el.type < 0) bad_state("element type " + t[1].cast<std::string>());
    const ElementType& et = element_catalogue()[el.type];
    el.nodes = t[2].cast<std::vector<int>>();
    el.params = t[3].cast<std::vector<double>>();
    el.l0 = t[4].cast<std::optional<double>>();
    el.lgeomy = t[5].cast<std::vector<double>>();
    el.estiff = t[6].cast<std::vector<double>>();
    el.edampp = t[7].cast<std::vector<double>>();
    el.emass = t[8].cast<std::vector<double>>();
    el.cls = to_enums<DefClass>(t[9].cast<std::vector<int>>(), 6, "deformation class");
    el.e = t[10].cast<std::vector<double>>();
    el.ed = t[11].cast<std::vector<double>>();
    el.edd = t[12].cast<std::vector<double>>();
    const auto given = t[13].cast<std::vector<bool>>();
    el.e_given.assign(given.begin(), given.end());
    el.kinematic_of = t[14].cast<std::vector<std::array<int, 2>>>();
    el.automatic = t[15].cast<bool>();
    el.origin = t[16].cast<std::string>();
    const size_t nd = static_cast<size_t>(et.n_deformations());
    bool ok = el.id > 0 && !m.elements.count(el.id) && el.nodes.size() == et.nodes.size() && el.cls.size() == nd &&
              el.e.size() == nd && el.ed.size() == nd && el.edd.size() == nd && el.e_given.size() == nd &&
              el.kinematic_of.size() == nd && el.params.size() >= static_cast<size_t>(et.n_params_min) &&
              el.params.size() <= static_cast<size_t>(et.n_params_max);
    for (size_t i = 0; ok && i < el.nodes.size(); ++i) {
      auto it = m.nodes.find(el.nodes[i]);
      ok = it != m.nodes.end() && it->second.kind == et.nodes[i];
    }
    if (!ok) bad_state("element " + std::to_string(el.id));
    m.elements.emplace(el.id, std::move(el));
  }
  for (const auto& [id, el] : m.elements)  // references of nonholonomic deformations
    for (size_t k = 0; k < el.cls.size(); ++k)
      if (el.cls[k] == DefClass::Nonholonomic) {
        auto it = m.elements.find(el.kinematic_of[k][0]);
        const int i = el.kinematic_of[k][1];
        if (it == m.elements.end() || i < 1 || i > static_cast<int>(it->second.cls.size()))
          bad_state("nonholonomic deformation of element " + std::to_string(id));
      }
  const py::tuple st = state[3].cast<py::tuple>();
  if (st.size() != 13) bad_state("settings record");
  Settings& s = m.settings;
  s.timestep_n = st[0].cast<int>();
  s.timestep_tp = st[1].cast<double>();
  s.hmax = st[2].cast<double>();
  s.maxiterat = st[3].cast<int>();
  s.epskin = st[4].cast<double>();
  s.epsint = st[5].cast<double>();
  s.epsind = st[6].cast<double>();
  s.forcemode = st[7].cast<int>();
  s.animate = st[8].cast<int>();
  s.matasc = st[9].cast<int>();
  s.jobid = st[10].cast<std::optional<int>>();
  s.restart = st[11].cast<int>();
  s.linear = st[12].cast<std::optional<int>>();
  m.time = state[4].cast<double>();
  m.gravity = state[5].cast<std::array<double, 3>>();
  m.gravity_given = state[6].cast<bool>();
  if (state[7].cast<bool>()) m.restore_prepared();
  return m;
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

  py::class_<Node>(m, "Node")
      .def_readonly("id", &Node::id)
      .def_readonly("kind", &Node::kind)
      .def_readonly("x", &Node::x)
      .def_readonly("cls", &Node::cls)
      .def_readonly("xd", &Node::xd)
      .def_readonly("xdd", &Node::xdd)
      .def_readonly("force", &Node::force)
      .def_readonly("mass", &Node::mass)
      .def_readonly("torquel", &Node::torquel)
      .def_readonly("used", &Node::used)
      .def_readonly("origin", &Node::origin);
  py::class_<Element>(m, "Element")
      .def_readonly("id", &Element::id)
      .def_readonly("type", &Element::type)
      .def_property_readonly("type_name", [](const Element& e) { return element_catalogue()[e.type].name; })
      .def_readonly("nodes", &Element::nodes)
      .def_readonly("params", &Element::params)
      .def_readonly("l0", &Element::l0)
      .def_readonly("lgeomy", &Element::lgeomy)
      .def_readonly("estiff", &Element::estiff)
      .def_readonly("edampp", &Element::edampp)
      .def_readonly("emass", &Element::emass)
      .def_readonly("cls", &Element::cls)
      .def_readonly("e", &Element::e)
      .def_readonly("ed", &Element::ed)
      .def_readonly("edd", &Element::edd)
      .def_readonly("e_given", &Element::e_given)
      .def_readonly("kinematic_of", &Element::kinematic_of)
      .def_readonly("automatic", &Element::automatic)
      .def_readonly("origin", &Element::origin);
  py::class_<Settings>(m, "Settings")
      .def_readonly("timestep_n", &Settings::timestep_n)
      .def_readonly("timestep_tp", &Settings::timestep_tp)
      .def_readonly("hmax", &Settings::hmax)
      .def_readonly("maxiterat", &Settings::maxiterat)
      .def_readonly("epskin", &Settings::epskin)
      .def_readonly("epsint", &Settings::epsint)
      .def_readonly("epsind", &Settings::epsind)
      .def_readonly("forcemode", &Settings::forcemode)
      .def_readonly("animate", &Settings::animate)
      .def_readonly("matasc", &Settings::matasc)
      .def_readonly("jobid", &Settings::jobid)
      .def_readonly("restart", &Settings::restart)
      .def_readonly("linear", &Settings::linear);

  py::class_<Model>(m, "Model")
      .def(py::init<>())
      .def("copy", [](const Model& self) { return Model(self); })
      .def(py::pickle([](const Model& self) { return model_state(self); },
                      [](const py::tuple& state) { return model_from_state(state); }))
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
      .def_readonly("settings", &Model::settings)
      .def_readonly("time", &Model::time)
      .def_readonly("gravity", &Model::gravity)
      .def_readonly("gravity_given", &Model::gravity_given);
}

}  // namespace spacar::bindings

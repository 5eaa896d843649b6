// spacar._core: thin pybind11 bindings of the C++ core. No logic here: the Python package
// (python/spacar) builds the user-facing API on top.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "spacar/catalogue.hpp"
#include "spacar/errors.hpp"
#include "spacar/integrator.hpp"
#include "spacar/dynamics.hpp"
#include "spacar/kinematics.hpp"
#include "spacar/limits.hpp"
#include "spacar/model.hpp"
#include "spacar/simulate.hpp"

namespace py = pybind11;
using namespace spacar;

void bind_kernels(py::module_& m);
void bind_integrator(py::module_& m);
void bind_sparse(py::module_& m);
void bind_radau(py::module_& m);  // test-only: the Radau IIA integrator

namespace {

// The Python exception types, created once; the C++ exception of the same name maps to each.
struct PyErrors {
  py::handle base, input, kinematics, mass, integration, time_limit, not_implemented;
};

PyErrors& py_errors() {
  static PyErrors e;
  return e;
}

// The Python exception type of a C++ exception of the core and its message; a null handle for
// any other exception (left to pybind11's own translation).
py::handle python_type(const std::exception_ptr& p, std::string& message) {
  const PyErrors& e = py_errors();
  try {
    std::rethrow_exception(p);
  } catch (const InputError& x) {
    message = x.what();
    return e.input;
  } catch (const KinematicsError& x) {
    message = x.what();
    return e.kinematics;
  } catch (const SingularMassError& x) {
    message = x.what();
    return e.mass;
  } catch (const NotImplementedError& x) {
    message = x.what();
    return e.not_implemented;
  } catch (const TimeLimitError& x) {
    message = x.what();
    return e.time_limit;
  } catch (const IntegrationError& x) {
    message = x.what();
    return e.integration;
  } catch (const StepRejected& x) {
    message = x.what();
    return e.integration;
  } catch (const Error& x) {
    message = x.what();
    return e.base;
  } catch (...) {
  }
  return py::handle();
}

void bind_errors(py::module_& m) {
  PyErrors& e = py_errors();
  e.base = py::exception<Error>(m, "SpacarError").release();
  e.input = py::exception<InputError>(m, "InputError", e.base).release();
  e.kinematics = py::exception<KinematicsError>(m, "KinematicsError", e.base).release();
  e.mass = py::exception<SingularMassError>(m, "SingularMassError", e.base).release();
  e.integration = py::exception<IntegrationError>(m, "IntegrationError", e.base).release();
  e.time_limit = py::exception<TimeLimitError>(m, "TimeLimitError", e.base).release();
  e.not_implemented = py::exception<NotImplementedError>(m, "NotImplementedError", e.base).release();
  py::register_exception_translator([](std::exception_ptr p) {
    if (!p) return;
    std::string message;
    const py::handle type = python_type(p, message);
    if (type) py::set_error(type, message.c_str());
    else std::rethrow_exception(p);
  });
}

// Raise the Python exception of a failed run with the results computed before the failure as
// its attribute `results`. Exceptions of Python code called by the run (the on_output callback)
// and foreign C++ exceptions propagate unchanged.
[[noreturn]] void raise_with_results(const std::exception_ptr& p, py::object results) {
  std::string message;
  const py::handle type = python_type(p, message);
  if (!type) std::rethrow_exception(p);
  py::object exc = py::reinterpret_borrow<py::object>(type)(message);
  exc.attr("results") = std::move(results);
  PyErr_SetObject(type.ptr(), exc.ptr());
  throw py::error_already_set();
}

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

py::dict linearization_to_dict(const Linearization& l) {
  py::dict d;
  d["t"] = l.t;
  d["z_label"] = l.z_label;
  d["n_line"] = l.n_line;
  d["M0"] = l.M0;
  d["C0"] = l.C0;
  d["D0"] = l.D0;
  d["K0"] = l.K0;
  d["N0"] = l.N0;
  d["G0"] = l.G0;
  d["r0"] = l.r0;
  d["DFz"] = l.DFz;
  d["DFez"] = l.DFez;
  d["y_label"] = l.y_label;
  d["Kk"] = l.Kk;
  d["AK0"] = l.AK0;
  d["BK0"] = l.BK0;
  return d;
}

py::dict block_results_to_dict(BlockResults&& r) {
  py::dict d;
  d["t"] = std::move(r.t);
  d["x"] = std::move(r.x);
  d["xd"] = std::move(r.xd);
  d["xdd"] = std::move(r.xdd);
  d["e"] = std::move(r.e);
  d["ed"] = std::move(r.ed);
  d["edd"] = std::move(r.edd);
  d["sigma"] = std::move(r.sigma);
  d["reaction"] = std::move(r.reaction);
  py::list lins;
  for (const Linearization& l : r.linearizations) lins.append(linearization_to_dict(l));
  d["linearizations"] = lins;
  d["rhs_evaluations"] = r.rhs_evaluations;
  d["steps"] = r.steps;
  d["accepted"] = r.accepted;
  d["rejected"] = r.rejected;
  d["newton_iterations"] = r.newton_iterations;
  d["jacobians"] = r.jacobians;
  d["decompositions"] = r.decompositions;
  d["last_step"] = r.last_step;
  d["wall_time"] = r.wall_time;
  d["recursive"] = r.recursive;
  d["warnings"] = r.warnings;
  return d;
}

void bind_simulation(py::module_& m) {
  py::class_<System>(m, "System")
      .def_readonly("nx", &System::nx)
      .def_readonly("ne", &System::ne)
      .def_readonly("coord_label", &System::coord_label)
      .def_readonly("def_label", &System::def_label)
      .def_readonly("coord_class", &System::coord_class)
      .def_readonly("def_class", &System::def_class)
      .def_readonly("x_calc", &System::x_calc)
      .def_readonly("x_input", &System::x_input)
      .def_readonly("x_dyn", &System::x_dyn)
      .def_readonly("x_fixed", &System::x_fixed)
      .def_readonly("e_input", &System::e_input)
      .def_readonly("e_dyn", &System::e_dyn)
      .def_readonly("rows_P", &System::rows_P)
      .def_readonly("rows_V", &System::rows_V)
      .def_readonly("dof_cols", &System::dof_cols)
      .def_readonly("input_cols", &System::input_cols)
      .def_readonly("q0", &System::q0)
      .def_readonly("qd0", &System::qd0)
      .def_readonly("warnings", &System::warnings)
      .def_property_readonly("n_dof", &System::n_dof)
      .def_property_readonly("n_qhat", &System::n_qhat);

  py::class_<Data>(m, "Data")
      .def_readonly("t", &Data::t)
      .def_readonly("x", &Data::x)
      .def_readonly("xd", &Data::xd)
      .def_readonly("xdd", &Data::xdd)
      .def_readonly("e", &Data::e)
      .def_readonly("ed", &Data::ed)
      .def_readonly("edd", &Data::edd)
      .def_readonly("sigma", &Data::sigma)
      .def_readonly("qhat", &Data::qhat)
      .def_readonly("qhat_d", &Data::qhat_d)
      .def_readonly("qhat_dd", &Data::qhat_dd)
      .def_readonly("DF", &Data::DF)
      .def_readonly("DFe", &Data::DFe)
      .def_readonly("acc0", &Data::acc0)
      .def_readonly("M", &Data::M)
      .def_readonly("Mbar", &Data::Mbar)
      .def_readonly("qdd", &Data::qdd)
      .def_readonly("reaction", &Data::reaction)
      .def_readonly("residual_load", &Data::residual_load)
      .def_readonly("sigma_equilibrium", &Data::sigma_equilibrium)
      .def_readonly("newton_iterations", &Data::newton_iterations);

  py::class_<Simulation>(m, "Simulation")
      .def(py::init<Model&>(), py::keep_alive<1, 2>())
      .def_property_readonly("system", &Simulation::system, py::return_value_policy::reference_internal)
      .def_property_readonly("data", &Simulation::data, py::return_value_policy::reference_internal)
      .def("assemble", &Simulation::assemble)
      .def("forces", &Simulation::forces)
      .def("reduced_accelerations",
           [](Simulation& s) {
             // q̈ of the reduced equations (3.1) with transfer functions at the last evaluated
             // state: an independent check of the integration path's sparse solve.
             Data& d = s.data();
             const System& sys = s.system();
             const Eigen::VectorXd qdd = d.qdd, xdd = d.xdd, edd = d.edd, qhat_dd = d.qhat_dd;
             solve_transfer(sys, d);
             solve_velocities(sys, d);
             solve_dynamics(sys, d);
             const Eigen::VectorXd reduced = d.qdd;
             d.qdd = qdd;
             d.xdd = xdd;
             d.edd = edd;
             d.qhat_dd = qhat_dd;
             return reduced;
           })
      .def("linearize", [](Simulation& s) { return linearization_to_dict(s.linearize()); })
      .def("diagnose",
           [](Simulation& s) {
             const ConstraintDiagnosis d = diagnose(s.system(), s.data());
             const System& sys = s.system();
             py::dict out;
             out["n_constraints"] = d.n_constraints;
             out["n_calculable"] = d.n_calculable;
             out["rank"] = d.rank;
             py::list red, und;
             for (int k : d.redundant) red.append(py::make_tuple(sys.def_label[k][0], sys.def_label[k][1]));
             for (int g : d.undetermined) und.append(py::make_tuple(sys.coord_label[g][0], sys.coord_label[g][1]));
             out["redundant"] = red;
             out["undetermined"] = und;
             out["text"] = d.text;
             return out;
           })
      .def("evaluate",
           [](Simulation& s, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
             if (q.size() != s.system().n_dof() || qd.size() != s.system().n_dof())
               throw InputError("evaluate(): q and qd must have one value per degree of freedom");
             s.evaluate(t, q.data(), qd.data());
           })
      .def("solve_state",
           [](Simulation& s, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
             // The integration path: positions, velocities, q̈ and stresses without DF.
             if (q.size() != s.system().n_dof() || qd.size() != s.system().n_dof())
               throw InputError("solve_state(): q and qd must have one value per degree of freedom");
             s.solve_state(t, q.data(), qd.data());
           })
      .def("recursive_state",
           [](Simulation& s, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) -> py::object {
             // The recursive path of planar rigid trees at (q, q̇), its tree taken at the solved
             // state of the first call: a dict of qdd, x, xd, xdd (None for other systems); a
             // check of it against solve_state() and move_to().
             if (q.size() != s.system().n_dof() || qd.size() != s.system().n_dof())
               throw InputError("recursive_state(): q and qd must have one value per degree of freedom");
             Eigen::VectorXd qdd, x, xd, xdd;
             if (!s.recursive_state(q.data(), qd.data(), qdd, x, xd, xdd)) return py::none();
             py::dict out;
             out["qdd"] = qdd;
             out["x"] = x;
             out["xd"] = xd;
             out["xdd"] = xdd;
             return out;
           })
      .def("move_to",
           [](Simulation& s, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
             if (q.size() != s.system().n_dof() || qd.size() != s.system().n_dof())
               throw InputError("move_to(): q and qd must have one value per degree of freedom");
             s.move_to(t, q.data(), qd.data());
           })
      .def(
          "run",
          [](Simulation& s, py::object on_output, double initial_step, const std::string& method,
             double time_limit, bool recursive) {
            RunOptions opt;
            opt.recursive = recursive;
            opt.initial_step = initial_step;
            if (method == "dop853") opt.method = Method::DOP853;
            else if (method == "dopri5") opt.method = Method::DOPRI5;
            else if (method == "radau5") opt.method = Method::RADAU5;
            else throw InputError("unknown integration method '" + method + "' (dop853, dopri5, radau5)");
            if (!on_output.is_none()) {
              opt.on_output = [on_output](int k, const Data& d, const Linearization* lin) {
                py::gil_scoped_acquire gil;
                py::dict state;
                state["t"] = d.t;
                state["x"] = d.x;
                state["xd"] = d.xd;
                state["xdd"] = d.xdd;
                state["e"] = d.e;
                state["ed"] = d.ed;
                state["edd"] = d.edd;
                state["sigma"] = d.sigma;
                state["reaction"] = d.reaction;
                if (lin) state["linearization"] = linearization_to_dict(*lin);
                on_output(k, state);
              };
            }
            opt.time_limit = time_limit;
            BlockResults r;
            std::exception_ptr failure;
            {
              py::gil_scoped_release release;
              try {
                s.run(r, opt);
              } catch (...) {
                failure = std::current_exception();
              }
            }
            if (failure) raise_with_results(failure, block_results_to_dict(std::move(r)));
            return block_results_to_dict(std::move(r));
          },
          py::arg("on_output") = py::none(), py::arg("initial_step") = 0.0, py::arg("method") = "dop853",
          py::arg("time_limit") = 0.0, py::arg("recursive") = true,
          "Run the block; on failure the exception has the results up to the failure as `results`.");
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "spacar C++ core";
  bind_errors(m);
  m.def("memory_limit", &memory_limit, "Bytes one analysis may allocate for its work and result arrays.");
  m.def("set_memory_limit", &set_memory_limit, py::arg("bytes"));
  bind_catalogue(m);
  bind_model(m);
  bind_simulation(m);
  bind_kernels(m);
  bind_integrator(m);
  bind_sparse(m);
  bind_radau(m);
}

// Direct access to one element kernel, for finite-difference tests and teaching: evaluate the
// deformations, their derivatives, the convective terms and the mass model at any x.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "spacar/model/catalogue.hpp"
#include "spacar/elements/element.hpp"
#include "spacar/errors.hpp"

namespace py = pybind11;
using namespace spacar;

namespace {

struct KernelHandle {
  std::unique_ptr<ElementKernel> k;
  int nc() const { return k->n_coords(); }
  int nd() const { return k->n_deformations(); }
  void check(const Eigen::VectorXd& x, int n, const char* what) const {
    if (x.size() != n) throw InputError(std::string(what) + " must have " + std::to_string(n) + " values");
  }
};

}  // namespace

void bind_kernels(py::module_& m) {
  py::class_<KernelHandle>(m, "ElementKernel")
      .def_property_readonly("n_coords", &KernelHandle::nc)
      .def_property_readonly("n_deformations", &KernelHandle::nd)
      .def("deformations",
           [](const KernelHandle& h, const Eigen::VectorXd& x) {
             h.check(x, h.nc(), "x");
             Eigen::VectorXd e(h.nd());
             h.k->deformations(x.data(), e.data());
             return e;
           })
      .def("first_derivatives",
           [](const KernelHandle& h, const Eigen::VectorXd& x) {
             h.check(x, h.nc(), "x");
             Eigen::VectorXd e(h.nd());
             Eigen::MatrixXd B(h.nd(), h.nc());
             h.k->first_derivatives(x.data(), e.data(), B.data());
             return B;
           })
      .def("rates",
           [](const KernelHandle& h, const Eigen::VectorXd& x, const Eigen::VectorXd& v) {
             h.check(x, h.nc(), "x");
             h.check(v, h.nc(), "v");
             Eigen::VectorXd r(h.nd());
             h.k->rates(x.data(), v.data(), r.data());
             return r;
           })
      .def("solve_end",  // x with one end solved from the other and e, or None (no closed form)
           [](const KernelHandle& h, int end, const Eigen::VectorXd& e, const Eigen::VectorXd& guess,
              Eigen::VectorXd x) -> py::object {
             h.check(x, h.nc(), "x");
             h.check(guess, h.nc(), "guess");
             h.check(e, h.nd(), "e");
             if (!h.k->solve_end(end, e.data(), guess.data(), x.data())) return py::none();
             return py::cast(x);
           })
      .def_property_readonly("has_closed_form", [](const KernelHandle& h) { return h.k->has_closed_form(); })
      .def("velocity_level", [](const KernelHandle& h, int i) { return h.k->velocity_level(i); })
      .def("period", [](const KernelHandle& h, int i) { return h.k->period(i); })
      .def("convective",
           [](const KernelHandle& h, const Eigen::VectorXd& x, const Eigen::VectorXd& v) {
             h.check(x, h.nc(), "x");
             h.check(v, h.nc(), "v");
             Eigen::VectorXd c(h.nd());
             h.k->convective(x.data(), v.data(), c.data());
             return c;
           })
      .def("stress_hessian",
           [](const KernelHandle& h, const Eigen::VectorXd& x, const Eigen::VectorXd& s) {
             h.check(x, h.nc(), "x");
             h.check(s, h.nd(), "sigma");
             Eigen::MatrixXd G(h.nc(), h.nc());
             h.k->stress_hessian(x.data(), s.data(), G.data());
             return G;
           })
      .def("constitutive",
           [](const KernelHandle& h, const std::vector<double>& values) {
             Eigen::MatrixXd S(h.nd(), h.nd());
             h.k->constitutive(values, S.data());
             return S;
           })
      .def_property_readonly("has_mass", [](const KernelHandle& h) { return h.k->has_mass(); })
      .def("mass",
           [](const KernelHandle& h, const Eigen::VectorXd& x, const Eigen::VectorXd& v) {
             h.check(x, h.nc(), "x");
             h.check(v, h.nc(), "v");
             Eigen::MatrixXd M(h.nc(), h.nc());
             Eigen::VectorXd hv(h.nc());
             h.k->mass(x.data(), v.data(), M.data(), hv.data());
             return py::make_tuple(M, hv);
           })
      .def("gravity",
           [](const KernelHandle& h, const Eigen::VectorXd& x, const Eigen::Vector3d& g) {
             h.check(x, h.nc(), "x");
             Eigen::VectorXd f(h.nc());
             h.k->gravity(x.data(), g.data(), f.data());
             return f;
           })
      .def("mass_and_gravity",
           [](const KernelHandle& h, const Eigen::VectorXd& x, const Eigen::VectorXd& v, const Eigen::Vector3d& g) {
             h.check(x, h.nc(), "x");
             h.check(v, h.nc(), "v");
             Eigen::MatrixXd M(h.nc(), h.nc());
             Eigen::VectorXd hv(h.nc()), f(h.nc());
             h.k->mass_and_gravity(x.data(), v.data(), g.data(), M.data(), hv.data(), f.data());
             return py::make_tuple(M, hv, f);
           })
      .def("gravity_potential",
           [](const KernelHandle& h, const Eigen::VectorXd& x, const Eigen::Vector3d& g) {
             h.check(x, h.nc(), "x");
             return h.k->gravity_potential(x.data(), g.data());
           })
      .def("kinetic_energy", [](const KernelHandle& h, const Eigen::VectorXd& x, const Eigen::VectorXd& v) {
        h.check(x, h.nc(), "x");
        h.check(v, h.nc(), "v");
        return h.k->kinetic_energy(x.data(), v.data());
      });

  m.def(
      "element_kernel",
      [](const std::string& type, const std::vector<double>& params, double l0, const std::vector<double>& lgeomy,
         const std::vector<double>& emass) {
        const int t = find_element_type(type);
        if (t < 0) throw InputError("unknown element type " + type);
        const ElementType& et = element_catalogue()[t];
        ElementSetup s;
        s.params = params;
        s.l0 = l0;
        s.lgeomy = lgeomy;
        s.emass = emass;
        return KernelHandle{et.make(s)};
      },
      py::arg("type"), py::arg("params") = std::vector<double>{}, py::arg("l0") = 1.0,
      py::arg("lgeomy") = std::vector<double>{}, py::arg("emass") = std::vector<double>{});
}

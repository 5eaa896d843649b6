// spacar._testing: the static forces and tangent stiffness at a solved state (statics.hpp), for
// the tests of the tangent against differences, and the saddle-point system of the nodal
// coordinates (nodal.hpp) against the dense reduced tangent.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include "spacar/analyses/nodal.hpp"
#include "spacar/analyses/simulate.hpp"
#include "spacar/analyses/statics.hpp"

namespace py = pybind11;

void bind_statics(py::module_& m) {
  m.def(
      "static_forces",
      [](spacar::Simulation& sim, double lambda) {
        Eigen::VectorXd R;
        Eigen::MatrixXd K;
        spacar::static_forces(sim.system(), sim.data(), lambda, R, &K);
        return py::make_tuple(R, K);
      },
      py::arg("simulation"), py::arg("load_factor"),
      "(R, K) at the simulation's solved positions, at rest, under λ times the loads: the reduced "
      "generalized forces and the dense tangent stiffness K0 + G0 (DF_qᵀ H DF_q).");
  m.def(
      "nodal_solve",
      [](spacar::Simulation& sim, double lambda, const Eigen::MatrixXd& loads) {
        const spacar::System& sys = sim.system();
        spacar::Data& data = sim.data();
        Eigen::VectorXd R;
        spacar::static_forces(sys, data, lambda, R);
        const spacar::NodalLayout layout(sys);
        spacar::SaddlePoint tangent(sys, layout);
        spacar::NodalCoefficients c;
        c.load_factor = lambda;
        const bool ok = tangent.factorize(sys, data, data.sigma, c);
        Eigen::MatrixXd dx(sys.nx, loads.cols());
        Eigen::VectorXd col;
        for (int j = 0; j < loads.cols(); ++j) {
          tangent.solve(loads.col(j), col);
          dx.col(j) = col;
        }
        py::dict d;
        d["ok"] = ok;
        d["dx"] = dx;
        d["singular"] = tangent.singular();
        d["sign"] = tangent.sign_determinant();
        d["negative"] = tangent.negative_eigenvalues();
        d["symmetric"] = tangent.symmetric();
        d["kkt"] = Eigen::MatrixXd(tangent.matrix());
        d["E"] = Eigen::MatrixXd(spacar::nodal_dof_map(sys, data));
        return d;
      },
      py::arg("simulation"), py::arg("load_factor"), py::arg("loads"),
      "At the simulation's solved positions, at rest, under λ times the loads: the saddle-point system of the "
      "nodal coordinates factorized and solved for each column of loads (nx x m): the displacements dx, the "
      "reduced tangent's sign of the determinant, negative eigenvalues and singularity, the scaled matrix and "
      "the map E (δq = E δx).");
}

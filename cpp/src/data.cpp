#include "spacar/data.hpp"

#include <algorithm>
#include <limits>

namespace spacar {

Data::Data(const System& sys) {
  const int nx = sys.nx, ne = sys.ne, nq = sys.n_qhat(), nd = sys.n_dof();
  const int nP = static_cast<int>(sys.rows_P.size()), nV = static_cast<int>(sys.rows_V.size());
  const int nc = static_cast<int>(sys.x_calc.size());
  x = xd = xdd = Eigen::VectorXd::Zero(nx);
  e = ed = edd = sigma = conv = Eigen::VectorXd::Zero(ne);
  qhat = qhat_d = qhat_dd = Eigen::VectorXd::Zero(nq);
  work.resize(sys.elements.size());
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const int n = static_cast<int>(sys.elements[i].coords.size()), m = sys.elements[i].nd;
    ElementWork& w = work[i];
    w.x = w.v = w.a = w.h = w.f = Eigen::VectorXd::Zero(n);
    w.B = Eigen::MatrixXd::Zero(m, n);
    w.c = Eigen::VectorXd::Zero(m);
    w.M = Eigen::MatrixXd::Zero(n, n);
  }
  target = residual = Eigen::VectorXd::Zero(nP);
  angle_ref = Eigen::VectorXd::Constant(ne, std::numeric_limits<double>::quiet_NaN());
  A = Eigen::MatrixXd::Zero(std::max(nP, nV), nc);
  rhs_DF = Eigen::MatrixXd::Zero(nV, nq);
  DF = Eigen::MatrixXd::Zero(nx, nq);
  DFe = Eigen::MatrixXd::Zero(ne, nq);
  acc0 = Eigen::VectorXd::Zero(nx);
  step = Eigen::VectorXd::Zero(std::max(nc, std::max(nP, nV)));
  M = Eigen::MatrixXd::Zero(nx, nx);
  h = f = g = reaction = Eigen::VectorXd::Zero(nx);
  DFq = Eigen::MatrixXd::Zero(nx, nd);
  Mbar = Eigen::MatrixXd::Zero(nd, nd);
  rhs = qdd = Eigen::VectorXd::Zero(nd);
}

double Data::estimate_bytes(const System& sys) {
  const double nx = sys.nx, ne = sys.ne, nq = sys.n_qhat(), nd = sys.n_dof();
  const double nP = static_cast<double>(sys.rows_P.size()), nV = static_cast<double>(sys.rows_V.size());
  const double nc = static_cast<double>(sys.x_calc.size()), nA = std::max(nP, nV);
  double doubles = nx * nx                 // M
                   + ne * ne               // global constitutive matrices of the linearization
                   + 2.0 * nA * nc         // A and its LU factors
                   + nV * nq + nc * nq     // rhs_DF and the solution of the transfer functions
                   + 2.0 * nx * nq + ne * nq  // DF (and the linearization's copy), DFe
                   + nx * nd + 2.0 * nd * nd  // DFq, Mbar and its factor
                   + 20.0 * (nx + ne + nq);   // vectors
  for (const SystemElement& se : sys.elements) {
    const double n = static_cast<double>(se.coords.size()), m = se.nd;
    doubles += 2.0 * m * n + n * n + 6.0 * n + 2.0 * m * m + 64.0;  // work arrays, S, D, kernel
  }
  return 8.0 * doubles;
}

}  // namespace spacar

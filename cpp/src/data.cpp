#include "spacar/data.hpp"

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
  h = f = g = reaction = residual_load = Eigen::VectorXd::Zero(nx);
  sigma_equilibrium = Eigen::VectorXd::Zero(ne);
  DFq = Eigen::MatrixXd::Zero(nx, nd);
  Mbar = Eigen::MatrixXd::Zero(nd, nd);
  rhs = qdd = Eigen::VectorXd::Zero(nd);
}

}  // namespace spacar

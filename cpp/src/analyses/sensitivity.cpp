// A static equilibrium held for design sensitivities (sensitivity.hpp).
#include "spacar/analyses/sensitivity.hpp"

#include <string>

#include "spacar/analyses/statics.hpp"
#include "spacar/kinematics/kinematics.hpp"

namespace spacar {

StaticPoint::StaticPoint(Model& model, const Eigen::VectorXd& x, const Eigen::VectorXd& e) : sim_(model) {
  sim_.assemble();
  put_at_static_row(sim_.system(), sim_.data(), x, e, "StaticPoint");
  forces();
}

Eigen::VectorXd StaticPoint::dofs() const {
  const System& sys = sim_.system();
  const Data& data = const_cast<Simulation&>(sim_).data();
  Eigen::VectorXd q(sys.n_dof());
  for (int j = 0; j < sys.n_dof(); ++j) q[j] = data.qhat[sys.dof_cols[j]];
  return q;
}

void StaticPoint::forces() {
  scale_ = static_forces(sim_.system(), sim_.data(), 1.0, R_);
  factorized_ = false;
}

void StaticPoint::move_to(const Eigen::VectorXd& q) {
  const System& sys = sim_.system();
  Data& data = sim_.data();
  if (q.size() != sys.n_dof())
    throw InputError("StaticPoint.move_to: q needs " + std::to_string(sys.n_dof()) + " values, got " +
                     std::to_string(q.size()));
  const Eigen::VectorXd at_rest = Eigen::VectorXd::Zero(sys.n_dof());
  set_dofs(sys, data, q.data(), at_rest.data());  // the DYNX coordinates themselves too
  data.jacobian_reusable = false;
  solve_positions(sys, data, std::max(sys.settings.maxiterat, 50), std::min(sys.settings.epskin, 1e-12), false);
  forces();
}

ReducedSystem& StaticPoint::reduced() {
  if (!reduced_) reduced_ = std::make_unique<ReducedSystem>(sim_.system(), sim_.data());
  return *reduced_;
}

void StaticPoint::factorize() {
  if (factorized_) return;
  const System& sys = sim_.system();
  ReducedSystem& red = reduced();
  if (!red.factorize(sim_.data().sigma, NodalCoefficients{}))
    throw StaticError("the tangent stiffness is not finite at this state");
  if (red.saddle().singular()) {
    const Eigen::VectorXd dx = red.saddle().null_direction();
    const std::string where = dx.size() ? dof_directions(sys, red.dofs(dx).cwiseQuotient(dof_scale(sys)))
                                        : "a direction not located";
    throw StaticError("the tangent stiffness is singular: no stiffness in " + where);
  }
  factorized_ = true;
}

bool StaticPoint::symmetric() {
  factorize();
  return reduced().saddle().symmetric();
}

Eigen::VectorXd StaticPoint::solve(const Eigen::VectorXd& r) {
  const System& sys = sim_.system();
  if (r.size() != sys.n_dof())
    throw InputError("StaticPoint.solve: r needs " + std::to_string(sys.n_dof()) + " values, got " +
                     std::to_string(r.size()));
  factorize();
  Eigen::VectorXd q, dx;
  reduced().solve(r, q, dx);
  return q;
}

Eigen::VectorXd StaticPoint::motion(const Eigen::VectorXd& dq) {
  if (dq.size() != sim_.system().n_dof())
    throw InputError("StaticPoint.motion: dq needs " + std::to_string(sim_.system().n_dof()) + " values");
  return reduced().motion(dq);
}

Eigen::Vector4d StaticPoint::energies(const Eigen::VectorXd& dq) {
  const Eigen::VectorXd v = motion(dq);
  return nodal_energies(sim_.system(), sim_.data(), sim_.data().sigma, v);
}

Eigen::MatrixXd StaticPoint::compliance(const std::vector<int>& nodes, Eigen::MatrixXd* U) {
  const System& sys = sim_.system();
  const Eigen::MatrixXd T = displacement_rows(sys, sim_.data(), nodes);
  Eigen::MatrixXd C(T.rows(), T.rows()), u(sys.n_dof(), T.rows());
  for (Eigen::Index j = 0; j < T.rows(); ++j) {
    u.col(j) = solve(reduced().reduce(T.row(j).transpose()));
    C.col(j) = T * motion(u.col(j));
  }
  if (U) *U = u;
  return C;
}

}  // namespace spacar

// The right-hand-side paths of a run (rhs_path.hpp).
#include "spacar/analyses/rhs_path.hpp"

#include "spacar/kinematics/dynamics.hpp"
#include "spacar/kinematics/kinematics.hpp"

namespace spacar {

std::unique_ptr<RhsPath> RhsPath::choose(const System& sys, const Data& data, bool recursive) {
  if (!recursive) return std::make_unique<GeneralPath>();
  if (std::unique_ptr<RecursiveTree> tree = RecursiveTree::detect(sys, data))
    return std::make_unique<TreePath>(std::move(tree));
  return chain_or_general(sys);
}

std::unique_ptr<RhsPath> RhsPath::chain_or_general(const System& sys) {
  if (std::unique_ptr<ExplicitChain> chain = ExplicitChain::detect(sys))
    return std::make_unique<ChainPath>(std::move(chain));
  return std::make_unique<GeneralPath>();
}

void GeneralPath::positions(const System& sys, Data& data, const Eigen::VectorXd*, bool exact) const {
  solve_positions(sys, data, sys.settings.maxiterat, simulation_kinematic_tolerance(sys), false, exact);
}

void GeneralPath::velocities(const System& sys, Data& data, bool) const { solve_velocities_direct(sys, data); }

void GeneralPath::residual(const System& sys, Data& data, Eigen::VectorXd& R) const {
  reduced_residual_direct(sys, data, R);
}

void GeneralPath::transfer(const System& sys, Data& data, const Eigen::VectorXd& v, Eigen::VectorXd& dx) const {
  transfer_times(sys, data, v, dx);
}

void ChainPath::transfer(const System& sys, Data& data, const Eigen::VectorXd& v, Eigen::VectorXd& dx) const {
  chain_->transfer_times(sys, data, v, dx);
}

void ChainPath::positions(const System& sys, Data& data, const Eigen::VectorXd* step_start, bool) const {
  chain_->solve_positions(sys, data, sys.settings.maxiterat, simulation_kinematic_tolerance(sys), step_start);
}

// Other evaluations factorize the velocity block, which the forces and transfer use.
void ChainPath::velocities(const System& sys, Data& data, bool in_rhs) const {
  if (in_rhs) chain_->solve_velocities(sys, data);
  else solve_velocities_direct(sys, data);
}

void ChainPath::residual(const System& sys, Data& data, Eigen::VectorXd& R) const {
  reduced_residual_direct(sys, data, R, chain_.get());
}

}  // namespace spacar

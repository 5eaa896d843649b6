// How a run evaluates the state at (t, q, q̇): the right-hand-side path, chosen once per run
// (Simulation::integrate_block) and asked at every evaluation instead of branching there.
//
// - GeneralPath: the constraint formulation for any model: Newton on the positions, one solve
//   with the velocity block for the velocities, the sparse equations of motion.
// - ChainPath: an open chain (chain.hpp): positions element by element from the step start's
//   branches, in right-hand sides its velocities and the residual form block by block.
// - TreePath: a planar or spatial tree of rigid bodies (tree.hpp): q̈ by the articulated-body
//   algorithm with explicit positions; output times are solved by the general path from the
//   tree's exact positions.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <utility>

#include "spacar/kinematics/data.hpp"
#include "spacar/model/system.hpp"
#include "spacar/recursive/chain.hpp"
#include "spacar/recursive/tree.hpp"

namespace spacar {

class RhsPath {
 public:
  virtual ~RhsPath() = default;
  // The path of a run: the tree or the open chain the system is if `recursive` (which the caller
  // turns off where those paths do not apply: time-dependent loads, a controller, energy
  // states), else the general path. Taken at the solved positions in data.
  static std::unique_ptr<RhsPath> choose(const System& sys, const Data& data, bool recursive);
  // The open chain's path if the system is one, else the general path.
  static std::unique_ptr<RhsPath> chain_or_general(const System& sys);
  // "general", "chain" or "tree" (the run's stats).
  virtual const char* name() const = 0;

  // The positions of the calculable coordinates from the prediction in data (its known
  // coordinates set). step_start: the positions of the step start, whose branches an open chain
  // keeps (nullptr: none); exact: the prediction already solves the constraints (the tree's).
  virtual void positions(const System& sys, Data& data, const Eigen::VectorXd* step_start, bool exact) const = 0;
  // The velocities (and ė, convective terms) at the positions just solved; in_rhs: inside a
  // right-hand side, where an open chain solves its own block by block.
  virtual void velocities(const System& sys, Data& data, bool in_rhs) const = 0;
  // The residual of the reduced equations at the q̂̈ set in data (reduced_residual_direct), after
  // positions() and velocities() in a right-hand side.
  virtual void residual(const System& sys, Data& data, Eigen::VectorXd& R) const = 0;
  // dx = DF v (nx) for rates v of q̂, at the state of the last right-hand side.
  virtual void transfer(const System& sys, Data& data, const Eigen::VectorXd& v, Eigen::VectorXd& dx) const = 0;
  // Whether a right-hand side's positions are held to the prediction from the step start (the
  // check that Newton stayed on the branch), given whether the step start is exact.
  virtual bool held_to_step_start(bool start_exact) const = 0;
  // Whether the step starts anchor the positions (not on the tree: explicit positions).
  virtual bool anchors_steps() const { return true; }
  // Whether generalized-α may use the residual form (no equations of motion per iteration).
  virtual bool residual_form() const { return false; }
  // The tree of rigid bodies, or nullptr.
  virtual RecursiveTree* tree() { return nullptr; }
};

class GeneralPath : public RhsPath {
 public:
  void positions(const System& sys, Data& data, const Eigen::VectorXd* step_start, bool exact) const override;
  void velocities(const System& sys, Data& data, bool in_rhs) const override;
  void residual(const System& sys, Data& data, Eigen::VectorXd& R) const override;
  void transfer(const System& sys, Data& data, const Eigen::VectorXd& v, Eigen::VectorXd& dx) const override;
  const char* name() const override { return "general"; }
  bool held_to_step_start(bool) const override { return true; }
};

class ChainPath : public GeneralPath {
 public:
  explicit ChainPath(std::unique_ptr<ExplicitChain> chain) : chain_(std::move(chain)) {}
  const char* name() const override { return "chain"; }
  void positions(const System& sys, Data& data, const Eigen::VectorXd* step_start, bool exact) const override;
  void velocities(const System& sys, Data& data, bool in_rhs) const override;
  void residual(const System& sys, Data& data, Eigen::VectorXd& R) const override;
  void transfer(const System& sys, Data& data, const Eigen::VectorXd& v, Eigen::VectorXd& dx) const override;
  // The chain's element iterations start from their predicted positions one by one: held to the
  // step start only from an exact one (an approximate one, generalized-α's last iterate, differs
  // by up to a Newton increment, which would reject good steps).
  bool held_to_step_start(bool start_exact) const override { return start_exact; }
  bool residual_form() const override { return true; }

 private:
  std::unique_ptr<ExplicitChain> chain_;
};

class TreePath : public GeneralPath {
 public:
  explicit TreePath(std::unique_ptr<RecursiveTree> tree) : tree_(std::move(tree)) {}
  const char* name() const override { return "tree"; }
  bool anchors_steps() const override { return false; }
  RecursiveTree* tree() override { return tree_.get(); }

 private:
  std::unique_ptr<RecursiveTree> tree_;
};

}  // namespace spacar

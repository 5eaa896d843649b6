// Explicit kinematics of open chains (formulation.md §2 solved in tree order): where the position
// constraints can be ordered so that each element (or an element with the normalisation of the
// Euler parameters it determines) has as many known deformation values (fixed, input, DOF, LINE)
// as unknown coordinates once the coordinates before it are known, the positions follow element
// by element outward from the known coordinates: a cantilever, a robot arm with flexible links,
// a rigid or flexible tree. Each step is a Newton iteration of the element's few coordinates (one
// or two iterations from the predicted positions), instead of a Newton iteration on all
// calculable coordinates with a sparse factorization per iteration; the velocities follow in the
// same order from the element's small linear system. Planar beams need no iteration: their
// deformations invert in closed form (ElementKernel::solve_end). Where some block iterates, the
// first Newton step is that of all coordinates together (the block-triangular Jacobian, solved
// block by block), so that the motion of the coordinates a block starts from reaches its own
// before its iterations.
//
// Refused (detect() returns nullptr), for the general path: closed loops (an element whose known
// values over-determine the coordinates it reaches), nonholonomic constraints (the velocity rows
// are not the position rows), velocity-level deformations among the position rows, and
// coordinates that only a group of several elements determines together (other than an element
// and the L2MIN1 normalisations of the rotations it reaches).
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <memory>
#include <vector>

#include "spacar/kinematics/data.hpp"
#include "spacar/errors.hpp"
#include "spacar/model/system.hpp"

namespace spacar {

class ExplicitChain {
 public:
  // The order of the system, or nullptr if it is not an open chain in the sense above.
  static std::unique_ptr<ExplicitChain> detect(const System& sys);

  // Positions of the calculable coordinates from the known ones (inputs and DOFs set in data,
  // the calculable coordinates holding the starting guess), as solve_positions() leaves them:
  // e and B evaluated at the solution, data.residual and the iteration counters set. Throws
  // KinematicsError when an element's iteration does not converge in max_iter iterations.
  // `reference`: the positions of a nearby solved state (the step start) whose branches the
  // closed-form blocks keep (a beam bent by less or more than 90°, the turn of a rotation);
  // nullptr: the starting positions in data.
  void solve_positions(const System& sys, Data& data, int max_iter, double tol,
                       const Eigen::VectorXd* reference = nullptr);
  // ẋ of the calculable coordinates, ė and the convective terms, as solve_velocities_direct().
  void solve_velocities(const System& sys, Data& data);
  // ẍ of the calculable coordinates and ë from q̂̈, as solve_accelerations_direct(). Both this
  // and transfer_transposed() require solve_velocities() at the current positions (the
  // convective terms, and the blocks factorized there).
  void solve_accelerations(const System& sys, Data& data);
  // out = DFᵀ w (n_qhat), as transfer_transposed() with the velocity block: the blocks'
  // transposed solves in reverse order; leaves the multipliers μ of the rows in data.sol_V (by
  // velocity row), as that does.
  void transfer_transposed(const System& sys, Data& data, const Eigen::VectorXd& w, Eigen::VectorXd& out);
  // dx = DF v for rates v of q̂, as transfer_times() with the velocity block.
  void transfer_times(const System& sys, Data& data, const Eigen::VectorXd& v, Eigen::VectorXd& dx) {
    rates(sys, data, v, false, dx);
  }

  int blocks() const { return static_cast<int>(blocks_.size()); }
  int closed_form_blocks() const {  // solved without iterations (Block::closed_end)
    return static_cast<int>(std::count_if(blocks_.begin(), blocks_.end(), [](const Block& b) { return b.closed_end >= 0; }));
  }

 private:
  struct Row {
    int def;      // global deformation index
    int row;      // row of the position block (sys.row_P)
  };
  // One step of the order: the unknown coordinates and the rows that determine them.
  struct Block {
    std::vector<int> elements;            // evaluated at every iteration
    std::vector<int> coords;              // global indices of the unknowns
    std::vector<Row> rows;
    // The entries of B that the block uses, listed once: row j of the block, the element's slot,
    // its local deformation and coordinate, and the unknown (in A) or the global coordinate
    // (known: a term of the right-hand side).
    struct Term {
      int j, slot, local, coord, target;
    };
    std::vector<Term> unknown_terms, known_terms;
    // A single element whose deformations are the block's rows and whose unknowns are one end's
    // coordinates: that end (0 or 1) if the element solves it in closed form
    // (ElementKernel::solve_end), -1 otherwise. guess: its coordinates in the reference state;
    // local_x, local_e: its coordinates and the rows' values (all three sized by make_block).
    int closed_end = -1;
    std::vector<double> guess, local_x, local_e;
    Eigen::MatrixXd A;                    // ∂(rows)/∂(unknowns), or its LU factors
    std::vector<int> piv;                 // the factors' row swaps
    Eigen::VectorXd r, dx;
  };
  void assemble(const Data& data, Block& b) const;
  // Σ over the known coordinates of B(row, l) v[coord], per row of the block, added to b.r.
  void add_known(const Data& data, Block& b, const Eigen::VectorXd& v, double sign) const;
  // One Newton step of all calculable coordinates, block by block (see solve_positions).
  void first_step(const System& sys, Data& data);
  // Newton on one block's coordinates; the iterations taken.
  int iterate(const System& sys, Data& data, Block& b, int max_iter, double tol) const;
  // The block's coordinates in closed form (Block::closed_end); false if the element declines.
  bool solve_closed(const System& sys, Data& data, Block& b) const;
  static int closed_end(const System& sys, const Block& b);
  // The block of `group`'s position rows on the unknowns U.
  static Block make_block(const System& sys, const std::vector<int>& group, const std::vector<int>& U);
  static KinematicsError singular(const System& sys, const Data& data, const Block& b, const char* what);
  // Rates y of all coordinates from the q̂ rates (velocities; with the convective terms,
  // accelerations), block by block as calculable_rates() does with the velocity block.
  void rates(const System& sys, Data& data, const Eigen::VectorXd& qhat_rate, bool convective, Eigen::VectorXd& y);
  // The blocks' A = B_u at the current positions, factorized for the rates and the adjoint sweep.
  void factorize_rates(const System& sys, const Data& data);

  std::vector<Block> blocks_;
  bool all_closed_ = false;  // every block in closed form: no first Newton step of all coordinates
  std::vector<int> rest_;  // elements without position rows: evaluated once at the end
  Eigen::VectorXd step_;   // the first Newton step of all coordinates (work space)
  bool rates_factorized_ = false;  // the blocks' A hold the factors of B_u at the current positions
  Eigen::VectorXd adjoint_;  // w less the loads the later blocks passed on (transfer_transposed)
};

}  // namespace spacar

// Linearized equations of motion (formulation.md §7) about a state of the model:
//   M0 δz̈ + (C0 + D0) δż + (K0 + N0 + G0) δz + K_k δy^k = r0
//   δẏ^k = AK0 δż + BK0 [δz; δy^k]                     (nonholonomic systems only)
// in the coordinates z = (q, e^ℓ): the degrees of freedom followed by the LINE parameters, and
// y^k the kinematic coordinates of nonholonomic constraints. M0, D0, K0 and G0 are assembled
// analytically (with the velocity transfer function); C0 and N0 are the remainders of central
// differences (Richardson-extrapolated) of the reduced residual with the kinematics re-solved
// at every perturbation; K_k and BK0 are such differences too.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <map>
#include <memory>
#include <vector>

#include "spacar/recursive/chain.hpp"
#include "spacar/kinematics/data.hpp"
#include "spacar/model/model.hpp"
#include "spacar/analyses/nodal.hpp"
#include "spacar/model/system.hpp"

namespace spacar {

struct Linearization {
  double t = 0.0;
  // Each z: {0, node, component} for a coordinate, {1, element, deformation} for a deformation.
  std::vector<std::array<int, 3>> z_label;
  int n_line = 0;               // the last n_line entries of z are LINE parameters
  Eigen::MatrixXd M0, C0, D0, K0, N0, G0;
  Eigen::VectorXd r0;           // residual at the nominal state (drives the LINE parameters)
  std::vector<std::array<int, 3>> y_label;  // kinematic coordinates {1, element, deformation}
  Eigen::MatrixXd Kk, AK0, BK0; // nz x nk, nk x nz, nk x (nz + nk)
  Eigen::MatrixXd DFz, DFez;    // ∂x/∂z (nx x nz) and ∂e/∂z (ne x nz): mode shapes

  // f(name, array) for each array above, named as the attributes of spacar.Linearization (whose
  // MATRICES lists them in the same order): the one list of them on this side.
  template <class F>
  void for_each_array(F&& f) const {
    f("M0", M0), f("C0", C0), f("D0", D0), f("K0", K0), f("N0", N0), f("G0", G0);
    f("Kk", Kk), f("AK0", AK0), f("BK0", BK0), f("DF", DFz), f("DFe", DFez), f("r0", r0);
  }
};

// The linearized equations at rest in the nodal coordinates (docs/formulation.md §10): for a state
// without rates, inputs at rest and in static equilibrium, where C0 = N0 = 0, the matrices of
// Linearization are M0 = Zᵀ M Z, D0 = Zᵀ D Z, K0 = Zᵀ K Z and G0 = Zᵀ G Z with Z = DF_z, the
// transfer function of z; here M, D, K, G are the sparse nodal matrices (over all coordinates,
// nx x nx), A the constraint rows and E the map δz = E δx. The eigen-analyses of large models
// solve with them and never form Z (spacar.Linearization.eigenfrequencies(k=...)).
struct NodalLinearization {
  double t = 0.0;
  std::vector<std::array<int, 3>> z_label;  // as Linearization's
  int n_line = 0;
  Eigen::SparseMatrix<double> M, D, K, G;   // nx x nx
  Eigen::SparseMatrix<double> A;            // constraint rows x nx
  Eigen::SparseMatrix<double> E;            // nz x nx
  Eigen::SparseMatrix<double> B;            // ∂e/∂x, ne x nx
  Eigen::SparseMatrix<double> S, Dc;        // constitutive stiffness and damping, ne x ne
  std::vector<int> free;                    // the free coordinates (the columns the solves use)
  Eigen::VectorXd r0;                       // the residual at the state (drives LINE parameters)
};

class Linearizer {
 public:
  // Compiles the model with its LINE parameters as coordinates. `dependent`: the dependent
  // Euler parameters of free rotations (as in the analysed system).
  explicit Linearizer(const Model& model, const std::map<int, int>& dependent = {});
  // How the finite-difference parts (C0, N0, Kk, BK0) are computed: to about 1e-11 relative;
  // to about 1e-8, at a third of the cost (an implicit integrator's Jacobian); or not at all, at
  // a state that compute_nodal accepted (at rest in static equilibrium: C0 = N0 = 0, no
  // kinematic coordinates).
  enum class Differences { Precise, Fast, None };
  // Linearize about the state of an analysis: sys/data hold a complete evaluation at time
  // data.t, with the complete stresses (the multipliers of the equations of motion).
  Linearization compute(const System& sys, const Data& data, Differences differences = Differences::Precise);
  // The nodal linearization at the analysed state (sys/data solved positions, rates and the
  // inputs' motion; no stresses needed): false, and nothing computed, unless the state is at
  // rest (no rates, inputs at rest, no kinematic coordinates) and in static equilibrium (the
  // reduced static residual below 1e-8 of the loads it balances).
  bool compute_nodal(const System& sys, const Data& data, NodalLinearization& out);
  // After compute_nodal: the dense reduced matrices at its state from sys/data solved there
  // (positions, rates, transfer functions), with q̈ = 0 and the static stresses of compute_nodal
  // in place of the equations of motion, which a model without mass does not have (its M0 is 0;
  // K0, G0, DF are complete).
  Linearization compute_at_rest(const System& sys, Data& data);
  // After compute_nodal: H = the coefficients' combination of K, G, M, D at that state in the
  // saddle-point system (nodal.hpp), factorized; then solves over the free coordinates,
  // x_f = Z (Zᵀ H Z)⁻¹ Zᵀ b_f (ReducedSystem: refined in z). False if the values are not finite.
  bool nodal_factorize(const NodalCoefficients& c);
  const SaddlePoint& nodal_system() const;
  void nodal_solve(const double* b, double* x);
  // vᵀ K v, vᵀ G v, vᵀ M v, vᵀ D v at compute_nodal's state for v over the free coordinates
  // (nodal_energies: the Rayleigh quotients of the eigen-analyses).
  Eigen::Vector4d nodal_energies(const Eigen::VectorXd& v_free);

 private:
  // The coordinates z of the analysed system (its DOFs, then the LINE parameters) with their
  // values, rates, accelerations and sizes, and their labels into `labels`; fills order_.
  struct ZState {
    Eigen::VectorXd z, zd, zdd, scale;
  };
  ZState z_state(const System& sys, const Data& data, std::vector<std::array<int, 3>>& labels, int& n_line);
  // The nominal state in ld_: the analysed one's inputs, time loads, positions; z, ż.
  void set_nominal(const System& sys, const Data& data, const ZState& zs, bool transfer);
  // The stages of compute(): the matrices at the nominal state, then those by differences.
  struct Nominal {
    Eigen::VectorXd x, angles;  // the nominal positions and the branches of their angles
  };
  Nominal nominal_matrices(const System& sys, const Data& data, const ZState& zs, Linearization& lin);
  void differenced_matrices(const System& sys, const ZState& zs, const Nominal& at, const Eigen::VectorXd& y,
                            const Eigen::VectorXd& yscale, bool precise, Linearization& lin);
  void residual(const Eigen::VectorXd& zdd, Eigen::VectorXd& R);
  // Kinematics at z, ż; the dense transfer functions only if asked (the nominal state: the
  // perturbed states of the finite differences need the residual only).
  void set_z(const Eigen::VectorXd& z, const Eigen::VectorXd& zd, bool transfer);
  std::unique_ptr<System> lin_;
  // The inputs' position, rate and acceleration at the analysed state (rows ordered as
  // input_cols): their block motion or a table's, as the analysis had them.
  Eigen::MatrixXd inputs_;
  std::unique_ptr<Data> ld_;
  std::vector<int> order_;      // z index → DOF index of the linearization system
  std::unique_ptr<ExplicitChain> chain_;  // the perturbed positions of an open chain; nullptr otherwise
  // The nodal linearization's reduced system and stresses (compute_nodal).
  std::unique_ptr<ReducedSystem> reduced_;
  Eigen::VectorXd nodal_sigma_;
};

}  // namespace spacar

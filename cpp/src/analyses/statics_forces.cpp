// The forces of a static equilibrium (statics.hpp): the reduced generalized forces R and the
// reactions at a state, the compliance of an equilibrium, and the names and scales of the DOFs
// in messages. The path of equilibria (Newton, load steps, arc length) is in statics.cpp.
#include "spacar/analyses/statics.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <utility>

#include "spacar/recursive/chain.hpp"
#include "spacar/kinematics/dynamics.hpp"
#include "spacar/kinematics/kinematics.hpp"
#include "spacar/limits.hpp"
#include "spacar/elements/spatial.hpp"
#include "spacar/analyses/nodal.hpp"


namespace spacar {

namespace {

// Σ_k B_kᵀ σ_k over all deformations, added to out.
void add_stress_loads(const System& sys, const Data& data, Eigen::VectorXd& out) {
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    const ElementWork& w = data.work[i];
    for (int a = 0; a < se.nd; ++a) {
      const double s = data.sigma[se.def_offset + a];
      if (s == 0.0) continue;
      for (size_t j = 0; j < se.coords.size(); ++j) out[se.coords[j]] += w.B(a, j) * s;
    }
  }
}

}  // namespace

std::string dof_name(const System& sys, int j) {
  const int nxd = static_cast<int>(sys.x_dyn.size());
  if (j < nxd) return "DYNX " + sys.coord_name(sys.x_dyn[j]);
  return "DYNE " + sys.def_name(sys.e_dyn[j - nxd]);
}

double static_forces(const System& sys, Data& data, double lambda, Eigen::VectorXd& R, Eigen::MatrixXd* K,
                     Eigen::VectorXd* full_load, ExplicitChain* chain) {
  const int nd = sys.n_dof();
  // At rest: no rates, no accelerations, hence no inertia or convective forces. The velocity
  // block (or the chain's blocks) is factorized here, for the transposed solve below.
  data.qhat_d.setZero();
  data.qhat_dd.setZero();
  rest_velocities(sys, data, !chain);  // a chain factorizes its blocks in its transposed solve
  data.xdd.setZero();
  data.edd.setZero();
  compute_inertia_and_loads(sys, data);
  if (full_load) *full_load = data.f;
  data.f *= lambda;
  constitutive_stresses(sys, data);
  // The unbalanced load w = −λf + Σ Bᵀσ on every coordinate; R = DF_qᵀ w.
  Eigen::VectorXd w = Eigen::VectorXd::Zero(sys.nx);
  add_stress_loads(sys, data, w);
  double scale = 0.0;  // the largest applied or elastic load on a coordinate, in units of energy
  for (int g = 0; g < sys.nx; ++g) {
    const double size = sys.coord_is_length[g] ? sys.length_scale : 1.0;
    scale = std::max(scale, std::max(std::abs(w[g]), std::abs(data.f[g])) * size);
  }
  w -= data.f;
  // R = DF_qᵀ w without DF: one transposed solve with the velocity block, A_Vᵀ μ = w_c, which
  // leaves μ in data.sol_V. The reaction stresses of the velocity rows are y = −μ, from the
  // equilibrium of the calculable coordinates (formulation.md §6); on DOF deformation rows
  // y → 0 at equilibrium. With them Σ σ_k H_k is exactly the derivative of DF_q (the
  // second-order transfer) contracted with w.
  Eigen::VectorXd out;
  if (chain) chain->transfer_transposed(sys, data, w, out);
  else transfer_transposed(sys, data, w, out);
  R.resize(nd);
  for (int j = 0; j < nd; ++j) R[j] = out[sys.dof_cols[j]];
  if (!sys.x_calc.empty())
    for (size_t r = 0; r < sys.defs_V.size(); ++r) data.sigma[sys.defs_V[r]] -= data.sol_V[r];
  data.reaction = -data.f;
  add_stress_loads(sys, data, data.reaction);
  for (int g = 0; g < sys.nx; ++g) {
    const CoordClass c = sys.coord_class[g];
    if (c != CoordClass::Fixed && c != CoordClass::Input) data.reaction[g] = 0.0;
  }
  if (K) {
    // The reduced tangent K0 + G0 = DF_qᵀ H DF_q, H the nodal tangent (structural plus
    // geometric with the complete stresses, the loads' stiffness scaled by λ): dense, for tests
    // and small models only.
    solve_transfer(sys, data);
    for (int j = 0; j < nd; ++j) data.DFq.col(j) = data.DF.col(sys.dof_cols[j]);
    NodalCoefficients c;
    c.load_factor = lambda;
    const Eigen::SparseMatrix<double> H = nodal_matrix(sys, data, data.sigma, c);
    const Eigen::MatrixXd HD = H * data.DFq;
    *K = data.DFq.transpose() * HD;
  }
  return scale;
}

// The characteristic size of each DOF: the mean element length for lengths, 1 for angles.
Eigen::VectorXd dof_scale(const System& sys) {
  Eigen::VectorXd scale(sys.n_dof());
  int j = 0;
  for (int g : sys.x_dyn) scale[j++] = sys.coord_is_length[g] ? sys.length_scale : 1.0;
  for (int k : sys.e_dyn) scale[j++] = sys.def_is_length[k] ? sys.length_scale : 1.0;
  return scale;
}

// The DOFs that make up the directions V (columns) of q: components ≥ 10% of the largest,
// the largest first, at most four named.
std::string dof_directions(const System& sys, const Eigen::MatrixXd& V) {
  std::vector<std::pair<double, int>> part;
  for (int j = 0; j < V.rows(); ++j) {
    double w = 0.0;
    for (int c = 0; c < V.cols(); ++c) w = std::max(w, std::abs(V(j, c)) / V.col(c).cwiseAbs().maxCoeff());
    if (w >= 0.1) part.push_back({-w, j});
  }
  std::sort(part.begin(), part.end());
  std::ostringstream os;
  os << "the direction of";
  for (size_t i = 0; i < part.size() && i < 4; ++i) os << (i ? ", " : " ") << dof_name(sys, part[i].second);
  if (part.size() > 4) os << " and " << part.size() - 4 << " more";
  return os.str();
}

Eigen::MatrixXd displacement_rows(const System& sys, const Data& data, const std::vector<int>& nodes) {
  std::vector<Eigen::RowVectorXd> rows;
  for (int n : nodes) {
    std::vector<int> coords;
    for (int g = 0; g < sys.nx; ++g)
      if (sys.coord_label[g][0] == n) coords.push_back(g);
    if (coords.empty()) throw InputError("node " + std::to_string(n) + " has no coordinates used by an element");
    if (sys.coord_node_kind[coords[0]] == NodeKind::Lambda) {
      const Eigen::Vector4d l = Eigen::Vector4d(data.x.segment<4>(coords[0])).normalized();
      const Eigen::Matrix<double, 3, 4> E = 2.0 * euler_E(l);
      for (int i = 0; i < 3; ++i) {
        Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(sys.nx);
        row.segment<4>(coords[0]) = E.row(i);
        rows.push_back(row);
      }
      continue;
    }
    for (int g : coords) {
      Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(sys.nx);
      row[g] = 1.0;
      rows.push_back(row);
    }
  }
  Eigen::MatrixXd T(rows.size(), sys.nx);
  for (size_t i = 0; i < rows.size(); ++i) T.row(i) = rows[i];
  return T;
}

void put_at_static_row(const System& sys, Data& data, const Eigen::VectorXd& x, const Eigen::VectorXd& e,
                       const char* where) {
  if (x.size() != sys.nx || e.size() != sys.ne)
    throw InputError(std::string(where) + ": x and e need " + std::to_string(sys.nx) + " and " +
                     std::to_string(sys.ne) + " values, got " + std::to_string(x.size()) + " and " +
                     std::to_string(e.size()));
  // The row is a solved state: its positions, and the independent coordinates from them; the
  // kinematics then only refreshes the deformations and their derivatives there.
  data.x = x;
  for (int g = 0; g < sys.nx; ++g)
    if (sys.qhat_col_x[g] >= 0) data.qhat[sys.qhat_col_x[g]] = x[g];
  for (int k = 0; k < sys.ne; ++k)
    if (sys.qhat_col_e[k] >= 0) data.qhat[sys.qhat_col_e[k]] = e[k];
  data.jacobian_reusable = false;
  solve_positions(sys, data, std::max(sys.settings.maxiterat, 50), std::min(sys.settings.epskin, 1e-10), false);
}

Eigen::MatrixXd static_compliance(Model& model, const std::vector<int>& nodes, double load_factor,
                                  const Eigen::VectorXd* x, const Eigen::VectorXd* e) {
  Simulation sim(model);
  sim.assemble();
  const System& sys = sim.system();
  Data& data = sim.data();
  if (x || e) {
    if (!x || !e) throw InputError("static_compliance: x and e must both be given");
    put_at_static_row(sys, data, *x, *e, "static_compliance");
  }
  if (sys.n_dof() == 0) {  // nothing can move: the supports and rigid deformations hold every point
    const Eigen::Index rows = displacement_rows(sys, data, nodes).rows();
    return Eigen::MatrixXd::Zero(rows, rows);
  }
  Eigen::VectorXd R;
  static_forces(sys, data, load_factor, R);
  ReducedSystem reduced(sys, data);
  NodalCoefficients c;
  c.load_factor = load_factor;
  if (!reduced.factorize(data.sigma, c)) throw StaticError("the tangent stiffness is not finite at this state");
  if (reduced.saddle().singular() && sys.n_dof() > 0) {
    const Eigen::VectorXd dx = reduced.saddle().null_direction();
    const std::string where = dx.size() ? dof_directions(sys, reduced.dofs(dx).cwiseQuotient(dof_scale(sys)))
                                        : "a direction not located";
    throw StaticError("the tangent stiffness is singular: no stiffness in " + where + "; the compliance is unbounded");
  }
  const Eigen::MatrixXd T = displacement_rows(sys, data, nodes);
  Eigen::MatrixXd TD(T.rows(), T.rows());
  Eigen::VectorXd q, dx;
  for (int j = 0; j < T.rows(); ++j) {
    reduced.solve(reduced.reduce(T.row(j).transpose()), q, dx);
    TD.col(j) = T * dx;
  }
  return TD;
}

}  // namespace spacar

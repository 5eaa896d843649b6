#include "spacar/kinematics/diagnosis.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "spacar/kinematics/dynamics.hpp"
#include "spacar/errors.hpp"
#include "spacar/kinematics/kinematics.hpp"
#include "spacar/limits.hpp"

namespace spacar {

namespace {

// Greedy selection in the given order: vectors (columns of V) that add rank are kept, the others
// are dependent on those before them. Returns the dependent ones. Gram-Schmidt with
// reorthogonalisation against the kept vectors, held as the columns of one matrix so that each
// projection is a matrix-vector product (large models: thousands of columns).
std::vector<int> dependent_columns(const Eigen::MatrixXd& V, const std::vector<int>& order) {
  const Eigen::Index m = V.rows();
  Eigen::MatrixXd basis(m, std::min<Eigen::Index>(m, static_cast<Eigen::Index>(order.size())));
  Eigen::Index k = 0;
  Eigen::VectorXd v(m), c;
  std::vector<int> dependent;
  for (int j : order) {
    v = V.col(j);
    const double norm0 = v.norm();
    for (int pass = 0; pass < 2 && k > 0; ++pass) {  // twice: Gram-Schmidt with reorthogonalisation
      c.noalias() = basis.leftCols(k).transpose() * v;
      v.noalias() -= basis.leftCols(k) * c;
    }
    if (norm0 == 0.0 || k == basis.cols() || v.norm() <= 1e-8 * norm0) {
      dependent.push_back(j);
    } else {
      basis.col(k++) = v / v.norm();
    }
  }
  return dependent;
}

// The prescribed coordinates (DYNX, INPUTX) whose column of the constraint Jacobian is not
// orthogonal to the left null space N (the combinations of redundant rows): freeing such a
// coordinate adds a column the redundant combination sees, and the rank grows by one. One pass
// over the elements: each row belongs to one element, so a column's entries come from the
// elements of its rows, and Nᵀ column and |column|² are summed entry by entry.
std::vector<int> determined_prescribed(const System& sys, const Data& data, const std::vector<int>& rows,
                                       const Eigen::MatrixXd& N) {
  std::vector<int> row_of(sys.ne, -1), slot(sys.nx, -1), prescribed;
  for (size_t r = 0; r < rows.size(); ++r) row_of[rows[r]] = static_cast<int>(r);
  for (const std::vector<int>* list : {&sys.x_dyn, &sys.x_input})
    for (int g : *list) {
      slot[g] = static_cast<int>(prescribed.size());
      prescribed.push_back(g);
    }
  Eigen::MatrixXd seen = Eigen::MatrixXd::Zero(N.cols(), static_cast<Eigen::Index>(prescribed.size()));
  Eigen::VectorXd norm2 = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(prescribed.size()));
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    for (size_t l = 0; l < se.coords.size(); ++l) {
      const int j = slot[se.coords[l]];
      if (j < 0) continue;
      for (int a = 0; a < se.nd; ++a)
        if (const int r = row_of[se.def_offset + a]; r >= 0) {
          const double v = data.work[i].B(a, static_cast<Eigen::Index>(l));
          seen.col(j) += v * N.row(r).transpose();
          norm2[j] += v * v;
        }
    }
  }
  std::vector<int> out;
  for (size_t j = 0; j < prescribed.size(); ++j)
    if (norm2[j] > 0.0 && seen.col(j).norm() > 1e-8 * std::sqrt(norm2[j])) out.push_back(prescribed[j]);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

ConstraintDiagnosis diagnose(const System& sys, Data& data, bool velocity, bool release_dynamic) {
  ConstraintDiagnosis d;
  const std::vector<int>& rows = velocity ? sys.defs_V : sys.defs_P;
  BlockMatrix& block = velocity ? data.AV : data.AP;
  const int nP = static_cast<int>(rows.size());
  const int nc = static_cast<int>(sys.x_calc.size());
  d.n_constraints = nP;
  d.n_calculable = nc;
  const bool too_large = nP > kMaxDiagnosisSize || nc > kMaxDiagnosisSize;
  if (too_large) {
    d.rank = -1;
  } else if (nP > 0 && nc > 0) {
    // Full SVD: U (nP x nP), V (nc x nc), the block and its work copy.
    require_memory(8.0 * (static_cast<double>(nP) * nP + static_cast<double>(nc) * nc + 3.0 * nP * nc),
                   "the constraint diagnosis of " + std::to_string(nP) + " constraints on " + std::to_string(nc) +
                       " calculable coordinates",
                   "");
    evaluate_elements(sys, data);
    assemble_block(sys, data, block, velocity ? data.AV_block : data.AP_block);
    // The decomposition cannot be interrupted: it starts only within the time limit (at most
    // kMaxDiagnosisSize rows, a few seconds).
    check_thread_deadline("(before the constraint diagnosis)");
    const Eigen::MatrixXd A = Eigen::MatrixXd(block.matrix());
    Eigen::BDCSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::VectorXd& s = svd.singularValues();
    const double tol = std::sqrt(std::numeric_limits<double>::epsilon()) * std::max(s[0], 1e-300);
    for (int i = 0; i < s.size(); ++i) d.rank += s[i] > tol;
    for (int i = d.rank; i < nP; ++i) {  // left null vectors: combinations of redundant rows
      const Eigen::VectorXd u = svd.matrixU().col(i);
      const double umax = u.cwiseAbs().maxCoeff();
      std::vector<std::pair<int, double>> group;
      for (int r = 0; r < nP; ++r)
        if (std::abs(u[r]) > 0.1 * umax) group.push_back({rows[r], u[r] / umax});
      d.redundant_groups.push_back(group);
    }
    if (d.rank < nP) d.determined = determined_prescribed(sys, data, rows, svd.matrixU().rightCols(nP - d.rank));
    for (int i = d.rank; i < nc; ++i) {  // right null vectors: undetermined motions
      const Eigen::VectorXd v = svd.matrixV().col(i);
      const double vmax = v.cwiseAbs().maxCoeff();
      std::vector<std::pair<int, double>> group;
      for (int j = 0; j < nc; ++j)
        if (std::abs(v[j]) > 0.1 * vmax) group.push_back({sys.x_calc[j], v[j] / vmax});
      d.undetermined_groups.push_back(group);
    }
    // A concrete set to release: keep prescribed rows (inputs, DOFs) first, then fixed ones in
    // ascending order (release_dynamic: fixed and inputs first, the DOFs last); each row
    // dependent on the kept ones is redundant.
    std::vector<int> order;
    for (int pass = 0; pass < 2; ++pass)
      for (int r = 0; r < nP; ++r) {
        const DefClass c = sys.def_class[rows[r]];
        const bool last = release_dynamic ? c == DefClass::Dynamic : c == DefClass::Fixed || c == DefClass::Nonholonomic;
        if ((pass == 1) == last) order.push_back(r);
      }
    // (The selections cost O(n^3): skipped when the SVD shows full rank.)
    if (d.rank < nP)
      for (int r : dependent_columns(A.transpose(), order)) d.redundant.push_back(rows[r]);
    std::sort(d.redundant.begin(), d.redundant.end());
    std::vector<int> cols(nc);
    for (int j = 0; j < nc; ++j) cols[j] = j;
    if (d.rank < nc)
      for (int j : dependent_columns(A, cols)) d.undetermined.push_back(sys.x_calc[j]);
  } else if (nc > 0) {
    d.undetermined = sys.x_calc;
  } else {
    d.redundant = rows;
  }

  std::ostringstream os;
  if (velocity)
    os << "  " << nP << " velocity constraint equations (fixed, input, dynamic, nonholonomic deformations) for " << nc
       << " calculable coordinate rates";
  else
    os << "  " << nP << " constraint equations (fixed, input, dynamic deformations) for " << nc
       << " calculable coordinates";
  if (nP > nc) os << ": over-constrained by " << nP - nc;
  if (nP < nc) os << ": under-constrained by " << nc - nP;
  if (too_large) {
    os << "; the block is too large for a detailed diagnosis (at most " << kMaxDiagnosisSize
       << " constraints and calculable coordinates).";
    d.text = os.str();
    return d;
  }
  os << "; rank " << d.rank << ".";
  if (velocity && (!d.redundant.empty() || !d.undetermined.empty()))
    os << "\n  the nonholonomic constraints (ENHC) do not determine these rates: pair each nonholonomic"
          "\n  deformation with a kinematic coordinate whose rate it determines (formulation.md §5).";
  // Long lists are cut (the structured fields keep everything): an error message stays readable.
  constexpr size_t kItems = 20, kGroups = 5, kTerms = 12;
  auto more = [&os](size_t shown, size_t total, const char* what) {
    if (total > shown) os << "\n   ... and " << total - shown << " more " << what;
  };
  if (!d.determined.empty()) {
    os << "\n  prescribed coordinates that the constraints determine; make one calculable again (remove its "
          "DYNX or INPUTX)\n  or release a constraint (below) for each redundancy:";
    for (size_t i = 0; i < d.determined.size() && i < kItems; ++i) {
      const int g = d.determined[i];
      const bool dof = sys.coord_class[g] == CoordClass::Dynamic;
      os << "\n   - " << (dof ? "DYNX " : "INPUTX ") << sys.coord_label[g][0] << " " << sys.coord_label[g][1] << "   ("
         << sys.coord_name(g) << (dof ? ", a degree of freedom" : ", an input") << ")";
    }
    more(kItems, d.determined.size(), "prescribed coordinates");
  }
  if (!d.redundant.empty()) {
    os << "\n  redundant constraints; release these (RLSE) to remove the redundancy:";
    for (size_t i = 0; i < d.redundant.size() && i < kItems; ++i) {
      const int k = d.redundant[i];
      os << "\n   - RLSE " << sys.def_label[k][0] << " " << sys.def_label[k][1] << "   (" << sys.def_name(k) << ")";
    }
    more(kItems, d.redundant.size(), "redundant constraints");
    for (size_t i = 0; i < d.redundant_groups.size() && i < kGroups; ++i) {
      const auto& group = d.redundant_groups[i];
      os << "\n  dependent combination:";
      for (size_t t = 0; t < group.size() && t < kTerms; ++t)
        os << " " << sys.def_name(group[t].first) << " (weight " << group[t].second << ")";
      if (group.size() > kTerms) os << " ... (" << group.size() - kTerms << " more terms)";
    }
    more(kGroups, d.redundant_groups.size(), "dependent combinations");
  }
  if (!d.undetermined.empty()) {
    os << "\n  undetermined coordinates; fix them (FIX), make them degrees of freedom (DYNX) or add elements:";
    for (size_t i = 0; i < d.undetermined.size() && i < kItems; ++i) os << "\n   - " << sys.coord_name(d.undetermined[i]);
    more(kItems, d.undetermined.size(), "undetermined coordinates");
    for (size_t i = 0; i < d.undetermined_groups.size() && i < kGroups; ++i) {
      const auto& group = d.undetermined_groups[i];
      os << "\n  free motion:";
      for (size_t t = 0; t < group.size() && t < kTerms; ++t)
        os << " " << sys.coord_name(group[t].first) << " (weight " << group[t].second << ")";
      if (group.size() > kTerms) os << " ... (" << group.size() - kTerms << " more terms)";
    }
    more(kGroups, d.undetermined_groups.size(), "free motions");
  }
  d.text = os.str();
  return d;
}

std::string diagnose_constraints(const System& sys, Data& data, bool velocity) {
  return diagnose(sys, data, velocity).text;
}

std::string weakest_constraint(const System& sys, Data& data) {
  const int nV = static_cast<int>(sys.defs_V.size()), nc = static_cast<int>(sys.x_calc.size());
  if (nV != nc || nc == 0 || nc > kMaxDiagnosisSize) return "";
  assemble_block(sys, data, data.AV, data.AV_block);
  check_thread_deadline("(before the constraint diagnosis)");
  Eigen::BDCSVD<Eigen::MatrixXd> svd(Eigen::MatrixXd(data.AV.matrix()), Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd& s = svd.singularValues();
  const double ratio = s[nc - 1] / s[0];
  if (!(ratio < 1e-6)) return "";
  std::ostringstream os;
  os << "  the velocity constraint block is nearly singular (smallest/largest singular value " << ratio
     << ");\n  constraints that lose their independence:";
  const Eigen::VectorXd u = svd.matrixU().col(nc - 1), v = svd.matrixV().col(nc - 1);
  for (int r = 0; r < nV; ++r)
    if (std::abs(u[r]) > 0.1 * u.cwiseAbs().maxCoeff()) os << " " << sys.def_name(sys.defs_V[r]);
  os << "\n  coordinates of the singular motion:";
  for (int j = 0; j < nc; ++j)
    if (std::abs(v[j]) > 0.1 * v.cwiseAbs().maxCoeff()) os << " " << sys.coord_name(sys.x_calc[j]);
  return os.str();
}

namespace {
// Naming the degrees of freedom without inertia takes dense matrices and an eigen-solver (cubic
// in their number): beyond this, the cause is said without the names.
bool too_large_to_name(const System& sys) {
  return sys.n_dof() > kMaxDiagnosisSize || Data::estimate_dense_bytes(sys) > static_cast<double>(memory_limit());
}

bool carries_mass(const System& sys) {
  return std::any_of(sys.elements.begin(), sys.elements.end(), [](const SystemElement& se) { return se.has_mass; }) ||
         (sys.point_mass.array() != 0.0).any() || !sys.bodies.empty();
}

void say_no_mass(std::ostream& os, const System& sys) {
  os << "no element or node carries mass (no EMASS, MASS or body inertia in the model): all its " << sys.n_dof()
     << " degrees of freedom (DYNX, DYNE) move no mass; add MASS or EMASS to the nodes or elements they move, "
        "or make them kinematic (INPUTX/INPUTE) for a kinematic analysis";
}
}  // namespace

[[noreturn]] void throw_singular_mass(const System& sys, const Data& data, const Eigen::MatrixXd& Mbar) {
  const int nd = sys.n_dof();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Mbar);
  const Eigen::VectorXd lam = eig.eigenvalues();
  const double tol = 1e-10 * std::max(lam.cwiseAbs().maxCoeff(), 1e-300);
  std::vector<bool> named(nd, false);
  for (int m = 0; m < nd && (m == 0 || lam[m] <= tol); ++m) {
    const Eigen::VectorXd v = eig.eigenvectors().col(m);
    const double vmax = v.cwiseAbs().maxCoeff();
    for (int j = 0; j < nd; ++j) named[j] = named[j] || std::abs(v[j]) >= 0.1 * vmax;
  }
  std::ostringstream os;
  os << "the reduced mass matrix is singular at t = " << data.t << " (smallest eigenvalue " << lam[0]
     << "): the degrees of freedom";
  // At most eight named (a massless mesh would list every DOF), then how many more.
  const int total = static_cast<int>(std::count(named.begin(), named.end(), true));
  for (int j = 0, shown = 0; j < nd && shown < 8; ++j) {
    if (!named[j]) continue;
    ++shown;
    const int col = sys.dof_cols[j];
    os << " [";
    for (int g = 0; g < sys.nx; ++g)
      if (sys.qhat_col_x[g] == col) os << "DYNX " << sys.coord_name(g);
    for (int k = 0; k < sys.ne; ++k)
      if (sys.qhat_col_e[k] == col) os << "DYNE " << sys.def_name(k);
    os << "]";
  }
  if (total > 8) os << " and " << total - 8 << " more";
  os << " move no mass; add MASS or EMASS to the nodes or elements they move";
  // A structure modelled for its stiffness alone (a flexure): its question is a static one.
  if (!carries_mass(sys))
    os << " (no node or element of the model carries mass: for its stiffness alone, its static equilibrium, "
          "compliance and buckling, use the static analysis, spacar static or spacar.static, which needs none)";
  throw SingularMassError(os.str());
}


void refuse_large_massless(const System& sys, double t) {
  if (sys.n_dof() == 0 || carries_mass(sys) || !too_large_to_name(sys)) return;
  std::ostringstream os;
  os << "the equations of motion are singular at t = " << t << ": ";
  say_no_mass(os, sys);
  throw SingularMassError(os.str());
}

void explain_singular_equations(const System& sys, Data& data) {
  // Too large to name the degrees of freedom: the cause without the names, and never a
  // complaint about the memory that naming them would need.
  const int nd = sys.n_dof();
  if (too_large_to_name(sys)) {
    refuse_large_massless(sys, data.t);
    std::ostringstream os;
    os << "the equations of motion are singular at t = " << data.t << ": degrees of freedom (of " << nd
       << ") that move no mass, or dependent constraints; too large to name them (the dense diagnosis is done up to "
       << kMaxDiagnosisSize << " degrees of freedom within the memory limit); check the masses (MASS, EMASS) and "
                               "spacar.check(model)";
    throw SingularMassError(os.str());
  }
  solve_transfer(sys, data);
  solve_velocities(sys, data);
  solve_dynamics(sys, data);
  throw SingularMassError("the equations of motion are singular at t = " + std::to_string(data.t));
}

}  // namespace spacar

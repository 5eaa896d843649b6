#include "spacar/forces.hpp"

namespace spacar {

namespace {
bool is_reaction_class(DefClass c) {
  return c == DefClass::Fixed || c == DefClass::Input || c == DefClass::Linearization || c == DefClass::Nonholonomic;
}
}  // namespace

void solve_reactions(const System& sys, Data& data) {
  data.g.noalias() = data.M * data.xdd;
  data.g += data.h - data.f;
  // Load of the constitutive stresses on the nodes, g + B_Wᵀ σ^W (σ of the other rows still 0).
  data.reaction = data.g;
  for (size_t i = 0; i < sys.elements.size(); ++i) {
    const SystemElement& se = sys.elements[i];
    const Eigen::MatrixXd& B = data.work[i].B;
    for (int a = 0; a < se.nd; ++a) {
      const int k = se.def_offset + a;
      if (is_reaction_class(sys.def_class[k])) data.sigma[k] = 0.0;
      if (data.sigma[k] == 0.0) continue;
      for (size_t j = 0; j < se.coords.size(); ++j) data.reaction[se.coords[j]] += B(a, j) * data.sigma[k];
    }
  }
  const int nc = static_cast<int>(sys.x_calc.size());
  data.sigma_equilibrium.setZero();
  if (nc > 0) {
    Eigen::VectorXd rhs(nc);
    for (int j = 0; j < nc; ++j) rhs[j] = -data.reaction[sys.x_calc[j]];
    const Eigen::VectorXd sV = data.lu.transpose().solve(rhs);
    for (size_t r = 0; r < sys.rows_V.size(); ++r) {
      const int k = sys.rows_V[r];
      // Constitutive DOF stresses are already in the right-hand side: (6.1) with σ^d unknown
      // gives σ^d = constitutive + sV (sV ≈ 0 iff q̈ satisfies (3.1)); reaction rows were 0.
      data.sigma_equilibrium[k] = data.sigma[k] + sV[r];
      if (!is_reaction_class(sys.def_class[k])) continue;  // DOF stresses stay constitutive
      data.sigma[k] = sV[r];
      const int e = sys.e_element[k];
      const SystemElement& se = sys.elements[e];
      const Eigen::MatrixXd& B = data.work[e].B;
      for (size_t j = 0; j < se.coords.size(); ++j) data.reaction[se.coords[j]] += B(k - se.def_offset, j) * sV[r];
    }
  }
  data.residual_load = data.reaction;
  // Only supports and drivers carry reactions; the other rows are in equilibrium (≈ 0).
  for (int g = 0; g < sys.nx; ++g) {
    const CoordClass c = sys.coord_class[g];
    if (c != CoordClass::Fixed && c != CoordClass::Input) data.reaction[g] = 0.0;
  }
}

}  // namespace spacar

// The base-class versions of ElementKernel's stiffness, mass and gravity functions: zero, for
// the element types without stiffness data or distributed mass (AutoDiffElement overrides the
// mass and gravity functions, an element file its constitutive matrix).
#include "spacar/elements/element.hpp"

namespace spacar {

void ElementKernel::constitutive(const std::vector<double>&, double* S) const {
  const int nd = n_deformations();
  for (int i = 0; i < nd * nd; ++i) S[i] = 0.0;
}

void ElementKernel::mass(const double*, const double*, double* M, double* h) const {
  const int n = n_coords();
  for (int i = 0; i < n * n; ++i) M[i] = 0.0;
  for (int i = 0; i < n; ++i) h[i] = 0.0;
}

void ElementKernel::gravity(const double*, const double*, double* f) const {
  for (int i = 0; i < n_coords(); ++i) f[i] = 0.0;
}

double ElementKernel::gravity_potential(const double*, const double*) const { return 0.0; }

double ElementKernel::kinetic_energy(const double*, const double*) const { return 0.0; }

}  // namespace spacar

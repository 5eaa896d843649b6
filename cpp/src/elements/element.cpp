// Defaults of the element interface for elements without stiffness or mass.
#include "spacar/elements/element.hpp"

#include <cmath>

#include "spacar/elements/registry.hpp"

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

double reference_chord(const double* p, const double* q, int dim) {
  double s = 0.0;
  for (int i = 0; i < dim; ++i) s += (q[i] - p[i]) * (q[i] - p[i]);
  return std::sqrt(s);
}

}  // namespace spacar

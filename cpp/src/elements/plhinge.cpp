// PLHINGE: relative rotation of two BETA nodes, e1 = β_o2 − β_o1; σ1 = St e1 (moment).
#include "spacar/elements/registry.hpp"

namespace spacar {
namespace {

class PlHinge : public AutoDiffElement<PlHinge, 2, 1> {
 public:
  template <class S>
  void deform(const S* x, S* e) const {
    e[0] = x[1] - x[0];
  }
  void constitutive(const std::vector<double>& v, double* S) const override { S[0] = v.empty() ? 0.0 : v[0]; }
};

}  // namespace

std::unique_ptr<ElementKernel> make_plhinge(const ElementSetup&) { return std::make_unique<PlHinge>(); }

}  // namespace spacar

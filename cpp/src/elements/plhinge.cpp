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

ElementType plhinge_element_type() {
  ElementType t = element_type<PlHinge>("PLHINGE", {NodeKind::Beta, NodeKind::Beta}, {"o1", "o2"},
                                        {"relative rotation"}, "planar hinge");
  set_stiffness(t, 1, "St (torsional stiffness)");
  t.family = ElementFamily::Hinge;
  return t;
}

}  // namespace spacar

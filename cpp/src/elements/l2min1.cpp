// L2MIN1: the normalisation of the Euler parameters of a LAMBDA node, e1 = λᵀλ − 1; created
// automatically for every LAMBDA node (manual §5.1). Fixed (0) by default.
#include "spacar/elements/registry.hpp"

namespace spacar {
namespace {

class L2Min1 : public AutoDiffElement<L2Min1, 4, 1> {
 public:
  template <class S>
  void deform(const S* x, S* e) const {
    e[0] = x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3] - 1.0;
  }
};

}  // namespace

ElementType l2min1_element_type() {
  ElementType t = element_type<L2Min1>("L2MIN1", {NodeKind::Lambda}, {"o1"}, {"Euler parameter norm λᵀλ − 1"},
                                       "constraint on the Euler parameters (created automatically for every "
                                       "LAMBDA node)");
  t.automatic = true;
  return t;
}

}  // namespace spacar

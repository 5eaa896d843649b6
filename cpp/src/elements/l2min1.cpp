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

std::unique_ptr<ElementKernel> make_l2min1(const ElementSetup&) { return std::make_unique<L2Min1>(); }

}  // namespace spacar

// PLBEAR: planar bearing (bushing) between p1 with its orientation o1 and p2 with o2
// (formulation.md §4.5): the position of p2 relative to p1 in the frame of o1, and the relative
// rotation.
//   [e1; e2] = R(β_o1)ᵀ (x_p2 − x_p1) − d0,   e3 = β_o2 − β_o1
// d0 (LGEOMY, 2 values) is the relative position at the reference. ESTIFF Sx Sy St: σ = diag S e.
#include "spacar/elements/registry.hpp"

namespace spacar {
namespace {

class PlBear : public AutoDiffElement<PlBear, 6, 3> {
 public:
  explicit PlBear(const ElementSetup& s) {
    if (s.lgeomy.size() != 2) throw InputError("PLBEAR needs 2 reference values (LGEOMY)");
    d0_[0] = s.lgeomy[0];
    d0_[1] = s.lgeomy[1];
  }

  template <class S>
  void deform(const S* x, S* e) const {
    const S dx = x[3] - x[0], dy = x[4] - x[1];
    const S c = cos(x[2]), s = sin(x[2]);
    e[0] = c * dx + s * dy - d0_[0];
    e[1] = -s * dx + c * dy - d0_[1];
    e[2] = x[5] - x[2];
  }

  void constitutive(const std::vector<double>& v, double* S) const override {
    for (int i = 0; i < 9; ++i) S[i] = 0.0;
    for (int i = 0; i < 3; ++i) S[4 * i] = i < static_cast<int>(v.size()) ? v[i] : 0.0;
  }

 private:
  double d0_[2];
};

void reference_plbear(const double* x, const std::vector<double>&, double&, std::vector<double>& lgeomy) {
  lgeomy = {x[3] - x[0], x[4] - x[1]};
}

}  // namespace

ElementType plbear_element_type() {
  const NodeKind p = NodeKind::XY, o = NodeKind::Beta;
  ElementType t = element_type<PlBear>(
      "PLBEAR", {p, o, p, o}, {"p1", "o1", "p2", "o2"},
      {"relative displacement along local x", "relative displacement along local y", "relative rotation"},
      "planar bearing");
  set_stiffness(t, 3, "Sx Sy St (linear and torsional stiffness)");
  t.n_lgeomy = 2;
  t.reference = reference_plbear;
  t.family = ElementFamily::Bearing;
  return t;
}

}  // namespace spacar

// The element interface. An element type is written once, as templates on the scalar type:
//   template <class S> void deform(const S* x, S* e) const;      the deformation functions D(x)
// Velocity-level deformations (wheel slips, only their rates are defined) are flagged by the
// bit mask `static constexpr unsigned kVelocityRows` and given by
//   template <class S> void slip_rates(const S* x, const S* v, S* edot) const;  (linear in v)
// For distributed mass, either the points whose velocities carry the kinetic energy,
//   template <class S> void mass_points(const S* x, S* g) const;
// or (general case) the kinetic energy and the gravity potential themselves,
//   template <class S> S kinetic(const S* x, const S* v) const;
//   template <class S> S potential(const S* x, const double* g) const;
// AutoDiffElement derives the exact first derivatives B = ∂e/∂x, the convective terms, the
// stress-weighted Hessians Σσ_i Γ_i, the mass matrix and convective inertia forces (Lagrange's
// equations) from these by forward-mode dual numbers (see autodiff.hpp). Where an element is
// evaluated often and its derivatives are simple (BEAM, HINGE), it may override
// first_derivatives and convective with written-out versions (the rates, one directional
// derivative, stay dual: cheaper than B v), and give its mass points' Jacobian and convective
// accelerations written out as
//   void point_jacobian(const double* x, const double* v, Eigen::Matrix<double, NG·DIM, NC>& Jg,
//                       Eigen::Matrix<double, NG·DIM, 1>& gamma) const;
#pragma once

#include <Eigen/Dense>
#include <type_traits>
#include <vector>

#include "spacar/autodiff.hpp"

namespace spacar {

// Everything an element kernel needs, taken from the model's element record.
struct ElementSetup {
  std::vector<double> params;   // numbers of the definition line (direction vector, radii, ...)
  double l0 = 0.0;              // reference length (LENGTHO)
  std::vector<double> lgeomy;   // reference geometry (LGEOMY)
  std::vector<double> emass;    // EMASS values
};

using MatrixRM = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic>;

class ElementKernel {
 public:
  virtual ~ElementKernel() = default;
  virtual int n_coords() const = 0;
  virtual int n_deformations() const = 0;

  // e = D(x).
  virtual void deformations(const double* x, double* e) const = 0;
  // e = D(x) and B = ∂e/∂x (n_deformations x n_coords, column-major) in one pass.
  virtual void first_derivatives(const double* x, double* e, double* B) const = 0;
  // c_i = vᵀ H_i v, the second-order (convective) term of ë = B ẍ + c.
  virtual void convective(const double* x, const double* v, double* c) const = 0;
  // G = Σ_i σ_i H_i, n_coords x n_coords, column-major (geometric stiffness, linearization).
  virtual void stress_hessian(const double* x, const double* sigma, double* G) const = 0;

  // Deformations defined only up to a period (an angle from atan2: 2π; a belt length: 2π|r2 −
  // r1|), 0 otherwise: the kinematic analysis unwraps them to continuous values.
  virtual double period(int i) const { return 0.0; }
  // Velocity-level deformation (only its rate is defined): its value is integrated, not computed.
  virtual bool velocity_level(int i) const { return false; }
  // The element's frame C0 from its axis (HINGE, formulation.md §4.10), nullptr for the others:
  // the recursive path writes a cut hinge's misalignments with it on dual numbers.
  virtual const Eigen::Matrix3d* axes_frame() const { return nullptr; }
  // The rates ė at (x, v) evaluated directly (for tests): holonomic rows as the directional
  // derivative of D along v, velocity-level rows from the element's slip-rate function.
  virtual void rates(const double* x, const double* v, double* edot) const = 0;

  // The closed-form inverse of the deformations, where the element has one (the planar beams):
  // the coordinates of one end (`end` 0: the first node pair's, 1: the second's) from those of the
  // other end and the deformation values e, written over that end's coordinates in x (all the
  // element's coordinates). `guess`: all its coordinates in a nearby state, whose branch of each
  // angle (a beam bent by less or more than 90°) and turn of the rotation are kept. False where
  // there is no closed form or e lies outside its range: the caller iterates.
  virtual bool solve_end(int end, const double* e, const double* guess, double* x) const { return false; }
  virtual bool has_closed_form() const { return false; }  // solve_end is implemented

  // Constitutive matrix from ESTIFF (or, in the same form, EDAMPP) values: σ = S e (+ D ė).
  // Zero for elements without stiffness data.
  virtual void constitutive(const std::vector<double>& values, double* S) const;

  // Consistent mass: M (n x n, column-major) and convective inertia force h (n) at (x, v),
  // such that the element's inertia load is M ẍ + h.
  virtual bool has_mass() const { return false; }
  virtual void mass(const double* x, const double* v, double* M, double* h) const;
  // Generalized load of uniform gravity g (2 or 3 components) on the element mass.
  virtual void gravity(const double* x, const double* g, double* f) const;
  // mass() and gravity() together (every right-hand side needs both; mass-point elements share
  // the Jacobian of their points).
  virtual void mass_and_gravity(const double* x, const double* v, const double* g, double* M, double* h,
                                double* f) const {
    mass(x, v, M, h);
    gravity(x, g, f);
  }
  // Potential of that gravity load, V = −∫ ρA g·r ds (for tests and energy checks).
  virtual double gravity_potential(const double* x, const double* g) const;
  // Kinetic energy (for tests and energy checks).
  virtual double kinetic_energy(const double* x, const double* v) const;
};

// Mass model of the "mass points" kind: T = ½ ġᵀ (W ⊗ I_dim) ġ with g = g(x), NG points of
// dimension DIM; gravity potential V = −Σ_k w_k gᵀg_k(x).
template <int NG, int DIM>
struct MassPoints {
  Eigen::Matrix<double, NG, NG> W = Eigen::Matrix<double, NG, NG>::Zero();
  Eigen::Matrix<double, NG, 1> w = Eigen::Matrix<double, NG, 1>::Zero();
};

// Consistent mass of linear interpolation between two points: W = (ρA l0/6)[[2, 1], [1, 2]],
// gravity weights ρA l0 (½, ½) (trusses).
template <int DIM>
MassPoints<2, DIM> linear_mass(double rhoA, double l0) {
  MassPoints<2, DIM> m;
  m.W << 2.0, 1.0, 1.0, 2.0;
  m.W *= rhoA * l0 / 6.0;
  m.w << 0.5, 0.5;
  m.w *= rhoA * l0;
  return m;
}

// Consistent mass of the cubic Hermite interpolation r = H1 x_p + H2 l0 t_p + H3 x_q + H4 l0 t_q
// (beams): W = ρA l0 ∫ H_i H_j dξ, gravity weights ρA l0 ∫ H_i dξ = ρA l0 (½, 1/12, ½, −1/12).
template <int DIM>
MassPoints<4, DIM> hermite_mass(double rhoA, double l0) {
  MassPoints<4, DIM> m;
  m.W << 13.0 / 35, 11.0 / 210, 9.0 / 70, -13.0 / 420,  //
      11.0 / 210, 1.0 / 105, 13.0 / 420, -1.0 / 140,      //
      9.0 / 70, 13.0 / 420, 13.0 / 35, -11.0 / 210,       //
      -13.0 / 420, -1.0 / 140, -11.0 / 210, 1.0 / 105;
  m.W *= rhoA * l0;
  m.w << 0.5, 1.0 / 12, 0.5, -1.0 / 12;
  m.w *= rhoA * l0;
  return m;
}

// A beam's bending pair [σa; σb] = [[diagonal, coupling], [coupling, diagonal]] [ea; eb] for the
// two bending deformations of one plane (the end rotations from the chord, times l0, formulation.md
// §4): Euler–Bernoulli's (EI/l0³)[[4, −2], [−2, 4]], or with a shear stiffness kGA > 0
// Timoshenko's, (EI/(l0³ (1 + Φ)))[[4 + Φ, Φ − 2], [Φ − 2, 4 + Φ]], Φ = 12 EI/(kGA l0²): the
// beam whose shear force is constant along it, so that a cantilever's tip deflection under a tip
// force, P L³/(3 EI) + P L/(kGA), is exact with one element.
// The bending measure of the beams (PLBEAM/BEAM, PLBEAMNL/BEAMNL, PLBEAMC/BEAMC): the manual's
// (the sines of the end rotations), the same with the bending-corrected elongation, or the arc's
// (the angles, and the elongation along the arc: exact for constant curvature).
enum class Bending { Sine, SineCorrected, Arc };

struct BendingPair {
  double diagonal, coupling;
};
inline BendingPair bending_pair(double EI, double kGA, double l0) {
  const double k = EI / (l0 * l0 * l0);
  const double phi = kGA > 0.0 ? 12.0 * EI / (kGA * l0 * l0) : 0.0;
  return {k * (4.0 + phi) / (1.0 + phi), k * (phi - 2.0) / (1.0 + phi)};
}

namespace detail {
template <class T, class = void>
struct velocity_rows : std::integral_constant<unsigned, 0> {};
template <class T>
struct velocity_rows<T, std::void_t<decltype(T::kVelocityRows)>> : std::integral_constant<unsigned, T::kVelocityRows> {};
template <class T, class = void>
struct has_point_jacobian : std::false_type {};
template <class T>
struct has_point_jacobian<T, std::void_t<decltype(&T::point_jacobian)>> : std::true_type {};
template <class T, class = void>
struct has_kinetic : std::false_type {};
template <class T>
struct has_kinetic<T, std::void_t<decltype(&T::template kinetic<double>)>> : std::true_type {};
}  // namespace detail

// Implements the kernel from the templated deformation (and mass) functions of Derived.
// NC: local coordinates, ND: deformations, NG/DIM: mass points (NG = 0: no distributed mass).
template <class Derived, int NC, int ND, int NG = 0, int DIM = 2>
class AutoDiffElement : public ElementKernel {
 public:
  // The sizes, for the catalogue row (element_type<Kernel> in registry.hpp).
  static constexpr int kCoords = NC;
  static constexpr int kDeformations = ND;
  static constexpr unsigned kVelocityMask = detail::velocity_rows<Derived>::value;

  int n_coords() const override { return NC; }
  int n_deformations() const override { return ND; }

  bool velocity_level(int i) const override { return (kVelocityMask >> i) & 1u; }

  void deformations(const double* x, double* e) const override {
    self().deform(x, e);
    for (int i = 0; i < ND; ++i)
      if (velocity_level(i)) e[i] = 0.0;
  }

  void first_derivatives(const double* x, double* e, double* B) const override {
    using J = Jet<double, NC>;
    J xj[NC], ej[ND];
    for (int k = 0; k < NC; ++k) xj[k] = J::variable(x[k], k);
    self().deform(xj, ej);
    for (int i = 0; i < ND; ++i) {
      e[i] = ej[i].a;
      for (int k = 0; k < NC; ++k) B[i + ND * k] = ej[i].d[k];
    }
    if constexpr (kVelocityMask != 0) {
      // Rows of velocity-level deformations: ė = B(x) v, B from the rates with v as variables.
      J xc[NC], vj[NC], rj[ND];
      for (int k = 0; k < NC; ++k) {
        xc[k] = J(x[k]);
        vj[k] = J::variable(0.0, k);
      }
      self().slip_rates(xc, vj, rj);
      for (int i = 0; i < ND; ++i) {
        if (!velocity_level(i)) continue;
        e[i] = 0.0;
        for (int k = 0; k < NC; ++k) B[i + ND * k] = rj[i].d[k];
      }
    }
  }

  void rates(const double* x, const double* v, double* edot) const override {
    using J1 = Jet<double, 1>;
    J1 xj[NC], ej[ND];
    for (int k = 0; k < NC; ++k) xj[k] = J1(x[k], {v[k]});
    self().deform(xj, ej);
    for (int i = 0; i < ND; ++i) edot[i] = ej[i].d[0];
    if constexpr (kVelocityMask != 0) {
      double r[ND];
      self().slip_rates(x, v, r);
      for (int i = 0; i < ND; ++i)
        if (velocity_level(i)) edot[i] = r[i];
    }
  }

  void convective(const double* x, const double* v, double* c) const override {
    using J1 = Jet<double, 1>;
    using J2 = Jet<J1, 1>;
    J2 xj[NC], ej[ND];
    for (int k = 0; k < NC; ++k) xj[k] = J2(J1(x[k], {v[k]}), {J1(v[k], {0.0})});
    self().deform(xj, ej);
    for (int i = 0; i < ND; ++i) c[i] = ej[i].d[0].d[0];
    if constexpr (kVelocityMask != 0) {
      // c = ∂(B(x) v)/∂x v for velocity-level rows.
      J1 xv[NC], vc[NC], rj[ND];
      for (int k = 0; k < NC; ++k) {
        xv[k] = J1(x[k], {v[k]});
        vc[k] = J1(v[k]);
      }
      self().slip_rates(xv, vc, rj);
      for (int i = 0; i < ND; ++i)
        if (velocity_level(i)) c[i] = rj[i].d[0];
    }
  }

  void stress_hessian(const double* x, const double* sigma, double* G) const override {
    using J1 = Jet<double, NC>;
    using J2 = Jet<J1, NC>;
    J2 xj[NC], ej[ND];
    for (int k = 0; k < NC; ++k) {
      J1 inner = J1::variable(x[k], k);
      xj[k] = J2(inner, {});
      xj[k].d[k] = J1(1.0);
    }
    self().deform(xj, ej);
    for (int j = 0; j < NC; ++j)
      for (int k = 0; k < NC; ++k) {
        double s = 0.0;
        for (int i = 0; i < ND; ++i)
          if (!velocity_level(i)) s += sigma[i] * ej[i].d[j].d[k];
        G[j + NC * k] = s;
      }
    if constexpr (kVelocityMask != 0) {
      // Γ_i = ∂(B_iᵀ)/∂x: outer jet over x, inner jet over the unit rates v_j.
      J2 xo[NC], vo[NC], rj[ND];
      for (int k = 0; k < NC; ++k) {
        xo[k] = J2(J1(x[k]), {});
        xo[k].d[k] = J1(1.0);
        vo[k] = J2(J1::variable(0.0, k), {});
      }
      self().slip_rates(xo, vo, rj);
      for (int j = 0; j < NC; ++j)
        for (int k = 0; k < NC; ++k)
          for (int i = 0; i < ND; ++i)
            if (velocity_level(i)) G[j + NC * k] += sigma[i] * rj[i].d[k].d[j];
    }
  }

  bool has_mass() const override {
    if constexpr (NG > 0) return self().mass_model().W.any();
    if constexpr (detail::has_kinetic<Derived>::value) return self().has_distributed_mass();
    return false;
  }

  void mass(const double* x, const double* v, double* M, double* h) const override {
    Eigen::Map<Eigen::Matrix<double, NC, NC>> Mm(M);
    Eigen::Map<Eigen::Matrix<double, NC, 1>> hm(h);
    Mm.setZero();
    hm.setZero();
    if constexpr (detail::has_kinetic<Derived>::value) lagrange(x, v, Mm, hm);
    if constexpr (NG > 0) {
      Eigen::Matrix<double, NG * DIM, NC> Jg;
      Eigen::Matrix<double, NG * DIM, 1> gamma;
      point_derivatives(x, v, Jg, gamma);
      Eigen::Matrix<double, NC, NC> Mp;
      Eigen::Matrix<double, NC, 1> hp;
      points_mass(Jg, gamma, Mp.data(), hp.data());
      Mm += Mp;
      hm += hp;
    }
  }

  void mass_and_gravity(const double* x, const double* v, const double* g, double* M, double* h,
                        double* f) const override {
    if constexpr (NG > 0 && !detail::has_kinetic<Derived>::value) {
      Eigen::Matrix<double, NG * DIM, NC> Jg;
      Eigen::Matrix<double, NG * DIM, 1> gamma;
      point_derivatives(x, v, Jg, gamma);
      points_mass(Jg, gamma, M, h);
      points_gravity(Jg, g, f);
    } else {
      ElementKernel::mass_and_gravity(x, v, g, M, h, f);
    }
  }

  void gravity(const double* x, const double* g, double* f) const override {
    Eigen::Map<Eigen::Matrix<double, NC, 1>> fm(f);
    fm.setZero();
    if constexpr (detail::has_kinetic<Derived>::value) {
      using J = Jet<double, NC>;
      J xj[NC];
      for (int k = 0; k < NC; ++k) xj[k] = J::variable(x[k], k);
      const J V = self().potential(xj, g);
      for (int k = 0; k < NC; ++k) fm[k] = -V.d[k];
    }
    if constexpr (NG > 0) {
      Eigen::Matrix<double, NG * DIM, NC> Jg;
      Eigen::Matrix<double, NG * DIM, 1> gamma;
      double zero[NC] = {};
      point_derivatives(x, zero, Jg, gamma);
      Eigen::Matrix<double, NC, 1> fp;
      points_gravity(Jg, g, fp.data());
      fm += fp;
    }
  }

  double gravity_potential(const double* x, const double* g) const override {
    double V = 0.0;
    if constexpr (detail::has_kinetic<Derived>::value) V += self().potential(x, g);
    if constexpr (NG > 0) {
      double points[NG * DIM];
      self().mass_points(x, points);
      for (int p = 0; p < NG; ++p)
        for (int d = 0; d < DIM; ++d) V -= self().mass_model().w[p] * g[d] * points[p * DIM + d];
    }
    return V;
  }

  double kinetic_energy(const double* x, const double* v) const override {
    if constexpr (detail::has_kinetic<Derived>::value) return self().kinetic(x, v);
    if constexpr (NG > 0) {
      // ġ from the mass points themselves (a directional jet), not from point_derivatives:
      // the checks of the mass matrix against T then also test an element's written-out mass.
      using J1 = Jet<double, 1>;
      J1 xj[NC], gj[NG * DIM];
      for (int k = 0; k < NC; ++k) xj[k] = J1(x[k], {v[k]});
      self().mass_points(xj, gj);
      Eigen::Matrix<double, NG * DIM, 1> gdot;
      for (int i = 0; i < NG * DIM; ++i) gdot[i] = gj[i].d[0];
      return 0.5 * gdot.dot(kron(self().mass_model().W) * gdot);
    }
    return 0.0;
  }

 private:
  const Derived& self() const { return static_cast<const Derived&>(*this); }

  // Lagrange's equations from T(x, v): M = ∂²T/∂v², h = (∂²T/∂v∂x) v − ∂T/∂x.
  template <class MM, class MH>
  void lagrange(const double* x, const double* v, MM& M, MH& h) const {
    using J1 = Jet<double, NC>;
    using J2 = Jet<J1, NC>;
    {  // Hessian in v.
      J2 xc[NC], vj[NC];
      for (int k = 0; k < NC; ++k) {
        xc[k] = J2(J1(x[k]), {});
        vj[k] = J2(J1::variable(v[k], k), {});
        vj[k].d[k] = J1(1.0);
      }
      const J2 T = self().kinetic(xc, vj);
      for (int a = 0; a < NC; ++a)
        for (int b = 0; b < NC; ++b) M(a, b) = T.d[a].d[b];
    }
    {  // (∂²T/∂v∂x) v: outer jet over v, inner directional derivative along x + εv.
      using D1 = Jet<double, 1>;
      using JD = Jet<D1, NC>;
      JD xv[NC], vj[NC];
      for (int k = 0; k < NC; ++k) {
        xv[k] = JD(D1(x[k], {v[k]}), {});
        vj[k] = JD(D1(v[k]), {});
        vj[k].d[k] = D1(1.0);
      }
      const JD T = self().kinetic(xv, vj);
      for (int a = 0; a < NC; ++a) h[a] = T.d[a].d[0];
    }
    {  // − ∂T/∂x
      J1 xj[NC], vc[NC];
      for (int k = 0; k < NC; ++k) {
        xj[k] = J1::variable(x[k], k);
        vc[k] = J1(v[k]);
      }
      const J1 T = self().kinetic(xj, vc);
      for (int a = 0; a < NC; ++a) h[a] -= T.d[a];
    }
  }

  // M = Jgᵀ (W ⊗ I) Jg and h = Jgᵀ (W ⊗ I) γ from the Jacobian and convective accelerations
  // of the mass points. Coefficient-based products: at these sizes Eigen's default would run
  // its blocked GEMM, several times slower for matrices of a few dozen entries.
  template <class MJ, class MG>
  void points_mass(const MJ& Jg, const MG& gamma, double* M, double* h) const {
    const Eigen::Matrix<double, NG * DIM, NC> WJ = kron(self().mass_model().W).lazyProduct(Jg);
    Eigen::Map<Eigen::Matrix<double, NC, NC>>(M).noalias() = Jg.transpose().lazyProduct(WJ);
    Eigen::Map<Eigen::Matrix<double, NC, 1>>(h).noalias() = WJ.transpose() * gamma;
  }

  // f = Jgᵀ (w ⊗ g): gravity on the point weights.
  template <class MJ>
  void points_gravity(const MJ& Jg, const double* g, double* f) const {
    Eigen::Matrix<double, NG * DIM, 1> load;
    for (int p = 0; p < NG; ++p)
      for (int d = 0; d < DIM; ++d) load[p * DIM + d] = self().mass_model().w[p] * g[d];
    Eigen::Map<Eigen::Matrix<double, NC, 1>>(f).noalias() = Jg.transpose() * load;
  }

  static Eigen::Matrix<double, NG * DIM, NG * DIM> kron(const Eigen::Matrix<double, NG, NG>& W) {
    Eigen::Matrix<double, NG * DIM, NG * DIM> K = Eigen::Matrix<double, NG * DIM, NG * DIM>::Zero();
    for (int a = 0; a < NG; ++a)
      for (int b = 0; b < NG; ++b)
        for (int d = 0; d < DIM; ++d) K(a * DIM + d, b * DIM + d) = W(a, b);
    return K;
  }

  // Jacobian of the mass points and their convective acceleration vᵀ∇²g v.
  template <class MJ, class MG>
  void point_derivatives(const double* x, const double* v, MJ& Jg, MG& gamma) const {
    if constexpr (detail::has_point_jacobian<Derived>::value) {  // written out by the element
      self().point_jacobian(x, v, Jg, gamma);
      return;
    }
    {
      using J = Jet<double, NC>;
      J xj[NC], gj[NG * DIM];
      for (int k = 0; k < NC; ++k) xj[k] = J::variable(x[k], k);
      self().mass_points(xj, gj);
      for (int i = 0; i < NG * DIM; ++i)
        for (int k = 0; k < NC; ++k) Jg(i, k) = gj[i].d[k];
    }
    using J1 = Jet<double, 1>;
    using J2 = Jet<J1, 1>;
    J2 xj[NC], gj[NG * DIM];
    for (int k = 0; k < NC; ++k) xj[k] = J2(J1(x[k], {v[k]}), {J1(v[k], {0.0})});
    self().mass_points(xj, gj);
    for (int i = 0; i < NG * DIM; ++i) gamma[i] = gj[i].d[0].d[0];
  }
};

}  // namespace spacar

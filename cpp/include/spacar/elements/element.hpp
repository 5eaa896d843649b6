// The element interface. An element type is written once, as templates on the scalar type:
//   template <class S> void deform(const S* x, S* e) const;      the deformation functions D(x)
// and, for elements with distributed mass, the points whose velocities carry the kinetic energy:
//   template <class S> void mass_points(const S* x, S* g) const;
// AutoDiffElement derives the exact first derivatives B = ∂e/∂x, the convective terms ẋᵀHẋ,
// the stress-weighted Hessians Σσ_i H_i, the consistent mass matrix and convective inertia
// forces from these by forward-mode dual numbers (see autodiff.hpp).
#pragma once

#include <Eigen/Dense>
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

  // Angle-type deformations (atan2 branch): the kinematic analysis unwraps them to continuous
  // multi-turn values.
  virtual bool is_angle(int i) const { return false; }

  // Constitutive matrix from ESTIFF (or, in the same form, EDAMPP) values: σ = S e (+ D ė).
  // Zero for elements without stiffness data.
  virtual void constitutive(const std::vector<double>& values, double* S) const;

  // Consistent mass: M (n x n, column-major) and convective inertia force h (n) at (x, v),
  // such that the element's inertia load is M ẍ + h.
  virtual bool has_mass() const { return false; }
  virtual void mass(const double* x, const double* v, double* M, double* h) const;
  // Generalized load of uniform gravity g (2 or 3 components) on the element mass.
  virtual void gravity(const double* x, const double* g, double* f) const;
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

// Implements the kernel from the templated deformation (and mass point) functions of Derived.
// NC: local coordinates, ND: deformations, NG/DIM: mass points (NG = 0: no distributed mass).
template <class Derived, int NC, int ND, int NG = 0, int DIM = 2>
class AutoDiffElement : public ElementKernel {
 public:
  int n_coords() const override { return NC; }
  int n_deformations() const override { return ND; }

  void deformations(const double* x, double* e) const override { self().deform(x, e); }

  void first_derivatives(const double* x, double* e, double* B) const override {
    using J = Jet<double, NC>;
    J xj[NC], ej[ND];
    for (int k = 0; k < NC; ++k) xj[k] = J::variable(x[k], k);
    self().deform(xj, ej);
    for (int i = 0; i < ND; ++i) {
      e[i] = ej[i].a;
      for (int k = 0; k < NC; ++k) B[i + ND * k] = ej[i].d[k];
    }
  }

  void convective(const double* x, const double* v, double* c) const override {
    using J1 = Jet<double, 1>;
    using J2 = Jet<J1, 1>;
    J2 xj[NC], ej[ND];
    for (int k = 0; k < NC; ++k) xj[k] = J2(J1(x[k], {v[k]}), {J1(v[k], {0.0})});
    self().deform(xj, ej);
    for (int i = 0; i < ND; ++i) c[i] = ej[i].d[0].d[0];
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
        for (int i = 0; i < ND; ++i) s += sigma[i] * ej[i].d[j].d[k];
        G[j + NC * k] = s;
      }
  }

  bool has_mass() const override {
    if constexpr (NG > 0) return self().mass_model().W.any();
    return false;
  }

  void mass(const double* x, const double* v, double* M, double* h) const override {
    Eigen::Map<Eigen::Matrix<double, NC, NC>> Mm(M);
    Eigen::Map<Eigen::Matrix<double, NC, 1>> hm(h);
    Mm.setZero();
    hm.setZero();
    if constexpr (NG > 0) {
      const auto& mp = self().mass_model();
      Eigen::Matrix<double, NG * DIM, NC> Jg;
      Eigen::Matrix<double, NG * DIM, 1> gamma;
      point_derivatives(x, v, Jg, gamma);
      const auto Wfull = kron(mp.W);
      Mm.noalias() = Jg.transpose() * Wfull * Jg;
      hm.noalias() = Jg.transpose() * (Wfull * gamma);
    }
  }

  void gravity(const double* x, const double* g, double* f) const override {
    Eigen::Map<Eigen::Matrix<double, NC, 1>> fm(f);
    fm.setZero();
    if constexpr (NG > 0) {
      const auto& mp = self().mass_model();
      Eigen::Matrix<double, NG * DIM, NC> Jg;
      Eigen::Matrix<double, NG * DIM, 1> gamma;
      double zero[NC] = {};
      point_derivatives(x, zero, Jg, gamma);
      Eigen::Matrix<double, NG * DIM, 1> load;
      for (int p = 0; p < NG; ++p)
        for (int d = 0; d < DIM; ++d) load[p * DIM + d] = mp.w[p] * g[d];
      fm.noalias() = Jg.transpose() * load;
    }
  }

  double gravity_potential(const double* x, const double* g) const override {
    double V = 0.0;
    if constexpr (NG > 0) {
      double points[NG * DIM];
      self().mass_points(x, points);
      for (int p = 0; p < NG; ++p)
        for (int d = 0; d < DIM; ++d) V -= self().mass_model().w[p] * g[d] * points[p * DIM + d];
    }
    return V;
  }

  double kinetic_energy(const double* x, const double* v) const override {
    if constexpr (NG > 0) {
      Eigen::Matrix<double, NG * DIM, NC> Jg;
      Eigen::Matrix<double, NG * DIM, 1> gamma;
      point_derivatives(x, v, Jg, gamma);
      Eigen::Map<const Eigen::Matrix<double, NC, 1>> vm(v);
      const Eigen::Matrix<double, NG * DIM, 1> gdot = Jg * vm;
      return 0.5 * gdot.dot(kron(self().mass_model().W) * gdot);
    }
    return 0.0;
  }

 private:
  const Derived& self() const { return static_cast<const Derived&>(*this); }

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

// The forward dynamics of a tree and its exact derivatives from an inverse dynamics written once
// on a scalar type (planar_rnea.hpp; the spatial tree's are analytic, spatial_derivatives.cpp): M from the inverse dynamics' columns,
// q̈ = M⁻¹ (τ − b(q, q̇)), and ∂τ/∂q, ∂τ/∂q̇ at (q, q̇, q̈) from the same passes on forward-mode
// dual numbers, so that ∂q̈/∂(q, q̇) = −M⁻¹ ∂τ/∂(q, q̇) and ∂q̈/∂τ = M⁻¹ (as
// pinocchio.computeABADerivatives). `id(q, q̇, q̈, τ)` is a generic callable: it is called with
// double and with Jet<double, N> arrays.
#pragma once

#include <algorithm>
#include <vector>

#include <Eigen/Dense>

#include "spacar/autodiff.hpp"

namespace spacar::rnea {

// ∂τ/∂q and ∂τ/∂q̇ (n × n) at (q, q̇, q̈): the 2n directions N at a time.
template <int N, class Id>
void directional_derivatives(int n, const double* q, const double* qd, const double* qdd, const Id& id,
                             Eigen::MatrixXd& dtau_dq, Eigen::MatrixXd& dtau_dqd) {
  using Dual = Jet<double, N>;
  std::vector<Dual> dual_q(q, q + n), dual_qd(qd, qd + n), dual_qdd(qdd, qdd + n), out(n);
  auto variable = [&](int k) -> Dual& { return k < n ? dual_q[k] : dual_qd[k - n]; };
  for (int first = 0; first < 2 * n; first += N) {  // directions first … first + N − 1 of (q, q̇)
    const int last = std::min(2 * n, first + N);
    for (int k = first; k < last; ++k) variable(k).d[k - first] = 1.0;
    id(dual_q.data(), dual_qd.data(), dual_qdd.data(), out.data());
    for (int k = first; k < last; ++k) {
      variable(k).d[k - first] = 0.0;
      for (int r = 0; r < n; ++r) (k < n ? dtau_dq(r, k) : dtau_dqd(r, k - n)) = out[r].d[k - first];
    }
  }
}

// q̈ and its derivatives (n × n, row major) at (q, q̇) under τ; false if the mass matrix is not
// positive definite.
template <class Id>
bool forward_dynamics_derivatives(int n, const double* q, const double* qd, const double* tau, const Id& id,
                                  double* qdd, double* dq, double* dqd, double* dtau) {
  // M e_j = τ(q, 0, e_j) − τ(q, 0, 0): the inverse dynamics is affine in q̈.
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd rest(n), column(n), unit = zero;
  Eigen::MatrixXd M(n, n);
  id(q, zero.data(), zero.data(), rest.data());
  for (int j = 0; j < n; ++j) {
    unit[j] = 1.0;
    id(q, zero.data(), unit.data(), column.data());
    unit[j] = 0.0;
    M.col(j) = column - rest;
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (M + M.transpose()));
  if (llt.info() != Eigen::Success) return false;
  Eigen::Map<Eigen::VectorXd> acc(qdd, n);
  id(q, qd, zero.data(), column.data());  // the bias forces b(q, q̇)
  acc = llt.solve(Eigen::Map<const Eigen::VectorXd>(tau, n) - column);
  // The 2n directions in as few passes as the dual numbers' widths allow (one for up to 16
  // directions: a robot of 8 joints).
  Eigen::MatrixXd dtau_dq(n, n), dtau_dqd(n, n);
  if (2 * n <= 8) directional_derivatives<8>(n, q, qd, qdd, id, dtau_dq, dtau_dqd);
  else if (2 * n <= 12) directional_derivatives<12>(n, q, qd, qdd, id, dtau_dq, dtau_dqd);
  else directional_derivatives<16>(n, q, qd, qdd, id, dtau_dq, dtau_dqd);
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  Eigen::Map<RowMajor>(dq, n, n) = -llt.solve(dtau_dq);
  Eigen::Map<RowMajor>(dqd, n, n) = -llt.solve(dtau_dqd);
  Eigen::Map<RowMajor>(dtau, n, n) = llt.solve(Eigen::MatrixXd::Identity(n, n));
  return true;
}

}  // namespace spacar::rnea

#include "spacar/elements/spatial.hpp"

#include <cmath>
#include <sstream>

#include "spacar/errors.hpp"

namespace spacar {

namespace {
// Only the direction of an axis or direction vector matters: scale it by its largest component,
// so that a tiny (1e-300) or huge vector does not underflow or overflow in the norm.
Eigen::Vector3d scaled(const Eigen::Vector3d& v) {
  const double m = v.cwiseAbs().maxCoeff();
  return m > 0.0 && std::isfinite(m) ? Eigen::Vector3d(v / m) : v;
}
}  // namespace

Eigen::Matrix3d frame_from_axis(const Eigen::Vector3d& axis_in, const Eigen::Vector3d& y_in, const std::string& what) {
  const std::string prefix = what.empty() ? "" : what + ": ";
  const Eigen::Vector3d axis = scaled(axis_in), y_hint = scaled(y_in);
  const double la = axis.norm();
  if (!(la > 0.0)) throw InputError(prefix + "the axis has zero length");
  const Eigen::Vector3d ex = axis / la;
  const Eigen::Vector3d y = y_hint - ex.dot(y_hint) * ex;
  if (!(y.norm() > 1e-5 * y_hint.norm()) || y_hint.norm() == 0.0) {
    std::ostringstream os;
    os << prefix << "the direction vector (" << y_in[0] << ", " << y_in[1] << ", " << y_in[2]
       << ") is parallel to the element axis (" << ex[0] << ", " << ex[1] << ", " << ex[2] << ")";
    throw InputError(os.str());
  }
  Eigen::Matrix3d C;
  C.col(0) = ex;
  C.col(1) = y.normalized();
  C.col(2) = C.col(0).cross(C.col(1));
  return C;
}

Eigen::Matrix3d hinge_frame(const Eigen::Vector3d& axis_in, const std::string& what) {
  const Eigen::Vector3d axis = scaled(axis_in);
  if (!(axis.norm() > 0.0)) throw InputError(what + ": the axis of rotation has zero length");
  int k = 0;
  const Eigen::Vector3d a = axis.cwiseAbs();
  for (int i = 1; i < 3; ++i)
    if (a[i] < a[k]) k = i;
  return frame_from_axis(axis, Eigen::Vector3d::Unit(k), what);
}

// R(λ)c = (λ0² − λ̄·λ̄) c + 2 λ̄ (λ̄·c) + 2 λ0 λ̄ × c: ∂/∂λ0 = 2 λ0 c + 2 λ̄ × c,
// ∂/∂λ̄ = 2 ((λ̄·c) 1 + λ̄ cᵀ − c λ̄ᵀ − λ0 c̃).
Eigen::Matrix<double, 3, 4> rotate_jacobian(const double* l, const Eigen::Vector3d& c) {
  const Eigen::Vector3d lb(l[1], l[2], l[3]);
  Eigen::Matrix<double, 3, 4> J;
  J.col(0) = 2.0 * (l[0] * c + lb.cross(c));
  J.rightCols<3>() = 2.0 * (lb.dot(c) * Eigen::Matrix3d::Identity() + lb * c.transpose() - c * lb.transpose() -
                            l[0] * skew(c));
  return J;
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

Eigen::Matrix<double, 3, 4> euler_G(const double* l) {
  Eigen::Matrix<double, 3, 4> G;
  G << -l[1], l[0], l[3], -l[2],  //
      -l[2], -l[3], l[0], l[1],   //
      -l[3], l[2], -l[1], l[0];
  return G;
}

Eigen::Matrix<double, 3, 4> euler_E(const Eigen::Vector4d& l) {
  Eigen::Matrix<double, 3, 4> E;
  E << -l[1], l[0], -l[3], l[2], -l[2], l[3], l[0], -l[1], -l[3], -l[2], l[1], l[0];
  return E;
}

Eigen::Matrix3d euler_R(const Eigen::Vector4d& l) { return euler_E(l) * euler_G(l.data()).transpose(); }

void add_rotational_inertia(int n, const double* x, const double* v, const int* lam, int nblocks,
                            const Eigen::Matrix3d* A, double* M, double* h) {
  Eigen::Map<Eigen::MatrixXd> Mm(M, n, n);
  Eigen::Map<Eigen::VectorXd> hm(h, n);
  Eigen::Matrix<double, 3, 4> G[4];
  Eigen::Vector3d w[4];
  for (int i = 0; i < nblocks; ++i) {
    G[i] = euler_G(x + lam[i]);
    w[i] = 2.0 * G[i] * Eigen::Map<const Eigen::Vector4d>(v + lam[i]);
  }
  for (int i = 0; i < nblocks; ++i) {
    Eigen::Vector3d Aw = Eigen::Vector3d::Zero();
    for (int j = 0; j < nblocks; ++j) {
      const Eigen::Matrix3d& Aij = A[i * nblocks + j];
      Mm.block<4, 4>(lam[i], lam[j]) += 4.0 * G[i].transpose() * Aij * G[j];
      Aw += Aij * w[j];
    }
    hm.segment<4>(lam[i]) += 4.0 * euler_G(v + lam[i]).transpose() * Aw;
  }
}

}  // namespace spacar

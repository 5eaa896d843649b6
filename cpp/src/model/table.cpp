#include "spacar/model/table.hpp"

#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "spacar/errors.hpp"

namespace spacar {

namespace {

// Second derivatives of the not-a-knot cubic spline through (t, y), all columns at once: the
// continuity rows of the interior samples, and at each end a continuous third derivative across
// the first (last) interior sample.
Eigen::MatrixXd not_a_knot_second_derivatives(const std::vector<double>& t, const Eigen::MatrixXd& y) {
  const int n = static_cast<int>(t.size());
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, y.cols());
  if (n == 2) return M;  // the straight line
  if (n == 3) {          // the parabola: one constant second derivative
    const Eigen::RowVectorXd d0 = (y.row(1) - y.row(0)) / (t[1] - t[0]);
    const Eigen::RowVectorXd d1 = (y.row(2) - y.row(1)) / (t[2] - t[1]);
    const Eigen::RowVectorXd m = 2.0 * (d1 - d0) / (t[2] - t[0]);
    for (int i = 0; i < 3; ++i) M.row(i) = m;
    return M;
  }
  std::vector<double> h(n - 1);
  for (int i = 0; i + 1 < n; ++i) h[i] = t[i + 1] - t[i];
  std::vector<Eigen::Triplet<double>> A;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, y.cols());
  A.emplace_back(0, 0, -h[1]);
  A.emplace_back(0, 1, h[0] + h[1]);
  A.emplace_back(0, 2, -h[0]);
  for (int i = 1; i + 1 < n; ++i) {
    A.emplace_back(i, i - 1, h[i - 1]);
    A.emplace_back(i, i, 2.0 * (h[i - 1] + h[i]));
    A.emplace_back(i, i + 1, h[i]);
    rhs.row(i) = 6.0 * ((y.row(i + 1) - y.row(i)) / h[i] - (y.row(i) - y.row(i - 1)) / h[i - 1]);
  }
  A.emplace_back(n - 1, n - 3, -h[n - 2]);
  A.emplace_back(n - 1, n - 2, h[n - 3] + h[n - 2]);
  A.emplace_back(n - 1, n - 1, -h[n - 3]);
  Eigen::SparseMatrix<double> S(n, n);
  S.setFromTriplets(A.begin(), A.end());
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
  lu.compute(S);
  if (lu.info() != Eigen::Success) throw InputError("Table: the cubic spline through the samples has no solution");
  return lu.solve(rhs);
}

}  // namespace

Table::Kind Table::parse_kind(const std::string& name) {
  if (name == "linear") return Kind::LINEAR;
  if (name == "cubic") return Kind::CUBIC;
  throw InputError("Table: kind must be 'linear' or 'cubic', got '" + name + "'");
}

Table::Table(std::vector<double> times, Eigen::MatrixXd values, Kind kind)
    : t_(std::move(times)), values_(std::move(values)), kind_(kind) {
  if (t_.size() < 2) throw InputError("Table: at least 2 times are needed");
  if (values_.rows() != static_cast<Eigen::Index>(t_.size()))
    throw InputError("Table: " + std::to_string(values_.rows()) + " rows of values for " +
                     std::to_string(t_.size()) + " times (one row per time)");
  if (values_.cols() < 1) throw InputError("Table: the values have no components");
  for (size_t i = 0; i < t_.size(); ++i) {
    if (!std::isfinite(t_[i])) throw InputError("Table: the times must be finite");
    if (i > 0 && !(t_[i] > t_[i - 1])) throw InputError("Table: the times must increase strictly");
  }
  if (!values_.allFinite()) throw InputError("Table: the values must be finite");
  second_ = kind_ == Kind::CUBIC ? not_a_knot_second_derivatives(t_, values_)
                                 : Eigen::MatrixXd::Zero(values_.rows(), values_.cols());
  // Samples so close that the slopes or the spline's second derivatives overflow (times 1e-300
  // apart) would give infinite or NaN values, rates and accelerations: refused here.
  double closest = t_[1] - t_[0];
  bool finite = second_.allFinite();
  for (size_t i = 0; i + 1 < t_.size(); ++i) {
    const double h = t_[i + 1] - t_[i];
    closest = std::min(closest, h);
    finite = finite && ((values_.row(i + 1) - values_.row(i)) / h).allFinite();
  }
  if (!finite) {
    std::ostringstream os;
    os << "Table: samples " << closest << " s apart are too close for the " << (kind_ == Kind::CUBIC ? "cubic" : "linear")
       << " interpolation of these values: its slopes or second derivatives overflow";
    throw InputError(os.str());
  }
}

size_t Table::interval(double t) const {
  if (last_ + 1 < t_.size() && t >= t_[last_] && t <= t_[last_ + 1]) return last_;
  const auto it = std::upper_bound(t_.begin(), t_.end(), t);
  const size_t i = static_cast<size_t>(std::clamp<std::ptrdiff_t>(it - t_.begin() - 1, 0,
                                                                  static_cast<std::ptrdiff_t>(t_.size()) - 2));
  last_ = i;
  return i;
}

double Table::operator()(double t, int c, int derivative) const {
  if (t < t_.front() || t > t_.back()) {  // held end values
    if (derivative > 0) return 0.0;
    return t < t_.front() ? values_(0, c) : values_(values_.rows() - 1, c);
  }
  const size_t i = interval(t);
  const double h = t_[i + 1] - t_[i];
  const double a = (t_[i + 1] - t) / h, b = 1.0 - a;
  const double y0 = values_(i, c), y1 = values_(i + 1, c), m0 = second_(i, c), m1 = second_(i + 1, c);
  switch (derivative) {
    case 0:
      return a * y0 + b * y1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
    case 1:
      return (y1 - y0) / h + (-(3.0 * a * a - 1.0) * m0 + (3.0 * b * b - 1.0) * m1) * h / 6.0;
    default:
      return a * m0 + b * m1;
  }
}

}  // namespace spacar

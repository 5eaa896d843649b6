// A table of values over time, interpolated at any time inside the integration loop: the
// time-dependent loads and the prescribed input motions of a run (simulate.hpp), evaluated at
// every stage without a call back to Python.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

namespace spacar {

class Table {
 public:
  // LINEAR: straight lines between the samples (continuous values, piecewise constant rates).
  // CUBIC: the not-a-knot cubic spline (as scipy.interpolate.CubicSpline by default): continuous
  // values, rates and second derivatives, so that an input motion has continuous accelerations;
  // it reproduces polynomials up to degree 3 exactly (with 2 or 3 samples: the line or parabola).
  enum class Kind { LINEAR, CUBIC };
  // The kind of its name, "linear" or "cubic"; InputError for any other.
  static Kind parse_kind(const std::string& name);

  // times: strictly increasing, at least 2; values: one row per time, one column per component.
  // InputError on anything else.
  Table(std::vector<double> times, Eigen::MatrixXd values, Kind kind);

  int components() const { return static_cast<int>(values_.cols()); }
  double start() const { return t_.front(); }
  double end() const { return t_.back(); }
  // The `derivative`-th time derivative (0, 1 or 2) of component c at t. Outside the sampled
  // interval the table holds its end values (rates 0).
  double operator()(double t, int c, int derivative = 0) const;

 private:
  std::vector<double> t_;
  Eigen::MatrixXd values_;
  Eigen::MatrixXd second_;  // second derivatives at the samples (cubic; zero for linear)
  Kind kind_;
  mutable size_t last_ = 0;  // interval of the last evaluation: the next stage is usually in it
  size_t interval(double t) const;
};

}  // namespace spacar

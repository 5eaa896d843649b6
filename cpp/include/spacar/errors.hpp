// Exceptions of the spacar core. The bindings map each one to the Python exception of the same
// name in the `spacar` package, so C++ failures reach users as catchable, explained errors.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>

namespace spacar {

// A number in a message: printf's %g with `digits` significant digits, as a stream of that
// precision writes it (the one formatter of the core's messages; snprintf, not a stream: some
// messages name every node, and a stream costs thousands of instructions per number).
inline std::string format_number(double v, int digits = 6) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Invalid model description: the reader adds file, line and keyword to the message; errors
// found at the first END name the line that defined the element or node (Element::origin).
struct InputError : Error {
  using Error::Error;
};

// The kinematic analysis cannot be solved (constraint block not square or singular, Newton failed).
struct KinematicsError : Error {
  using Error::Error;
};

// The reduced mass matrix is not positive definite (a degree of freedom without inertia).
struct SingularMassError : Error {
  using Error::Error;
};

// The analysis did not finish within the wall-clock time limit it was given
// (spacar.simulate(..., time_limit=...)); the results up to that moment are kept.
struct TimeLimitError : Error {
  using Error::Error;
};

// The user interrupted the analysis (Ctrl-C in Python: InterruptScope, limits.hpp); the results
// up to that moment are kept, as after a failure.
struct Interrupted : Error {
  using Error::Error;
};

// No static equilibrium was found (statics.hpp): the load factor reached, the worst residual and
// its degree of freedom are in the message; the bindings attach the converged load steps.
struct StaticError : Error {
  using Error::Error;
};

}  // namespace spacar

// Exceptions of the spacar core. The bindings map each one to the Python exception of the same
// name in the `spacar` package, so C++ failures reach users as catchable, explained errors.
#pragma once

#include <stdexcept>
#include <string>

namespace spacar {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Invalid model description: the reader adds file, line and keyword to the message. When the
// error concerns one element or node (found at the first END), its number is carried along so
// that the reader can name the line that defined it.
struct InputError : Error {
  explicit InputError(const std::string& message, int element_id = 0, int node_id = 0)
      : Error(message), element(element_id), node(node_id) {}
  int element = 0;
  int node = 0;
};

// The kinematic analysis cannot be solved (constraint block not square or singular, Newton failed).
struct KinematicsError : Error {
  using Error::Error;
};

// The reduced mass matrix is not positive definite (a degree of freedom without inertia).
struct SingularMassError : Error {
  using Error::Error;
};

// A feature that is specified but whose physics has not been implemented yet.
struct NotImplementedError : Error {
  using Error::Error;
};

}  // namespace spacar

// Test-only binding of the sparse LU (sparse_lu.hpp): factorize scipy.sparse matrices of one
// pattern, solve, and count the factorizations that chose pivots, so that the tests can check
// the replayed elimination against dense solves; and of the fixed-pattern assembly (BlockMatrix,
// sparse.hpp), checked against dense accumulation.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <stdexcept>

#include "spacar/linalg/sparse.hpp"
#include "spacar/linalg/sparse_lu.hpp"

namespace py = pybind11;

namespace {

using Sparse = Eigen::SparseMatrix<double>;

struct TestLU {
  Sparse pattern;
  spacar::SparseLU lu;

  explicit TestLU(const Sparse& A) : pattern(A) {
    if (A.rows() != A.cols()) throw std::invalid_argument("SparseLU: the matrix must be square");
    pattern.makeCompressed();
    lu.analyze(pattern);
  }

  bool factorize(const Sparse& A) {
    Sparse B = A;
    B.makeCompressed();
    const bool same = B.rows() == pattern.rows() && B.cols() == pattern.cols() && B.nonZeros() == pattern.nonZeros() &&
                      std::equal(B.outerIndexPtr(), B.outerIndexPtr() + B.cols() + 1, pattern.outerIndexPtr()) &&
                      std::equal(B.innerIndexPtr(), B.innerIndexPtr() + B.nonZeros(), pattern.innerIndexPtr());
    if (!same) throw std::invalid_argument("SparseLU.factorize: the pattern differs from the analyzed one");
    return lu.factorize(B);
  }

  Eigen::VectorXd solve(const Eigen::VectorXd& b, bool transposed) const {
    if (b.size() != pattern.rows()) throw std::invalid_argument("SparseLU.solve: wrong length of b");
    Eigen::VectorXd x(b.size());
    if (transposed) lu.solve_transposed(b.data(), x.data());
    else lu.solve(b.data(), x.data());
    return x;
  }
};

}  // namespace

void bind_sparse(py::module_& m) {
  py::class_<spacar::BlockMatrix>(m, "BlockMatrix")
      .def(py::init([](int rows, int cols) {
             auto b = std::make_unique<spacar::BlockMatrix>();
             b->reset(rows, cols);
             return b;
           }),
           py::arg("rows"), py::arg("cols"))
      .def("add_block", &spacar::BlockMatrix::add_block, py::arg("rows"), py::arg("cols"))
      .def("finalize", &spacar::BlockMatrix::finalize)
      .def("set_zero", &spacar::BlockMatrix::set_zero)
      .def("add", &spacar::BlockMatrix::add, py::arg("id"), py::arg("local"))
      .def("add_transposed", &spacar::BlockMatrix::add_transposed, py::arg("id"), py::arg("local"))
      .def("add_value", &spacar::BlockMatrix::add_value, py::arg("id"), py::arg("a"), py::arg("b"), py::arg("v"))
      .def_property_readonly("matrix", [](const spacar::BlockMatrix& b) { return Sparse(b.matrix()); });
  py::class_<TestLU>(m, "SparseLU")
      .def(py::init<const Sparse&>(), py::arg("A"))
      .def("factorize", &TestLU::factorize, py::arg("A"))
      .def("solve", [](const TestLU& t, const Eigen::VectorXd& b) { return t.solve(b, false); })
      .def("solve_transposed", [](const TestLU& t, const Eigen::VectorXd& b) { return t.solve(b, true); })
      .def("adopt_pivots", [](TestLU& t, const TestLU& other) {
        const Sparse &a = t.pattern, &b = other.pattern;
        const bool same = a.rows() == b.rows() && a.nonZeros() == b.nonZeros() &&
                          std::equal(a.outerIndexPtr(), a.outerIndexPtr() + a.cols() + 1, b.outerIndexPtr()) &&
                          std::equal(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), b.innerIndexPtr());
        if (!same) throw std::invalid_argument("SparseLU.adopt_pivots: the patterns differ");
        t.lu.adopt_pivots(other.lu, t.pattern);
      })
      .def_property_readonly("pivotings", [](const TestLU& t) { return t.lu.pivotings(); })
      .def_property_readonly("factor_nonzeros", [](const TestLU& t) { return t.lu.factor_nonzeros(); });
}

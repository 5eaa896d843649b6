"""The sparse LU of the constraint blocks and the equations of motion (cpp/src/linalg/sparse_lu.cpp):
solutions against dense solves, the replay of the pivot sequence on new values, re-pivoting
when a replayed pivot is poor, singular and non-finite matrices, and linear fill on a chain."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from spacar import _testing


def random_sparse(n, density, rng, diagonal=True):
    A = sp.random(n, n, density=density, random_state=rng, format="csc")
    if diagonal:
        A = A + sp.diags(rng.uniform(0.5, 2.0, n) * rng.choice([-1.0, 1.0], n))
    A = sp.csc_matrix(A)
    A.sort_indices()
    return A


def same_pattern(A, values):
    B = A.copy()
    B.data = np.asarray(values, dtype=float)
    return B


def perturbed(A, rng, size):
    """A with every value changed by a relative amount up to ``size`` (the same pattern)."""
    return same_pattern(A, A.data * (1.0 + size * rng.uniform(-1.0, 1.0, A.nnz)))


def factorize_perturbed(lu, A, rng, count, size=0.05, tol=1e-14):
    """``count`` factorizations of perturbed values of A, each solving exactly both ways."""
    for _ in range(count):
        B = perturbed(A, rng, size)
        assert lu.factorize(B)
        b = rng.normal(size=A.shape[0])
        assert relative_residual(B, lu.solve(b), b) < tol
        assert relative_residual(B.T.tocsc(), lu.solve_transposed(b), b) < tol


def relative_residual(A, x, b):
    return np.linalg.norm(A @ x - b) / (np.linalg.norm(A.toarray(), np.inf) * np.linalg.norm(x) + np.linalg.norm(b))


@pytest.mark.parametrize("n, density", [(1, 1.0), (5, 0.5), (40, 0.08), (300, 0.01)])
def test_solves_match_dense_solves(n, density):
    rng = np.random.default_rng(n)
    A = random_sparse(n, density, rng)
    lu = _testing.SparseLU(A)
    assert lu.factorize(A)
    dense = A.toarray()
    for _ in range(3):
        b = rng.normal(size=n)
        x, xt = lu.solve(b), lu.solve_transposed(b)
        assert relative_residual(A, x, b) < 1e-14
        assert relative_residual(A.T.tocsc(), xt, b) < 1e-14
        np.testing.assert_allclose(x, np.linalg.solve(dense, b), rtol=1e-8 * np.linalg.cond(dense), atol=0)


def test_new_values_replay_the_pivot_sequence():
    """Values that change by a few percent keep the pivots: no new pivot choice, exact solves."""
    rng = np.random.default_rng(7)
    A = random_sparse(200, 0.02, rng)
    lu = _testing.SparseLU(A)
    assert lu.factorize(A)
    chosen = lu.pivotings
    factorize_perturbed(lu, A, rng, 20)
    assert lu.pivotings == chosen


def test_a_poor_replayed_pivot_chooses_pivots_again():
    """Diagonally dominant values first (diagonal pivots), then a zero diagonal: the replay
    meets a zero pivot, the factorization pivots again and still solves exactly."""
    A = sp.csc_matrix(np.array([[10.0, 1.0, 1.0], [1.0, 10.0, 1.0], [1.0, 1.0, 10.0]]))
    lu = _testing.SparseLU(A)
    assert lu.factorize(A)
    chosen = lu.pivotings
    B = same_pattern(A, A.data)
    B.data[:] = [0.0, 1.0, 2.0, 1.0, 0.0, 3.0, 2.0, 3.0, 0.0]  # symmetric, zero diagonal, det 12
    assert lu.factorize(B)
    assert lu.pivotings > chosen
    b = np.array([1.0, -2.0, 0.5])
    np.testing.assert_allclose(B @ lu.solve(b), b, rtol=0, atol=1e-14)
    np.testing.assert_allclose(B.T @ lu.solve_transposed(b), b, rtol=0, atol=1e-14)


def test_adopted_pivots_are_replayed_on_the_first_factorization():
    """A second factorization of the same pattern (the velocity block after the position block)
    takes the first one's pivots: its first factorization is a replay, with exact solves; where
    the adopted pivots are poor for its values it chooses its own. A factorization that has
    pivots of its own keeps them."""
    rng = np.random.default_rng(11)
    A = random_sparse(120, 0.04, rng)
    first = _testing.SparseLU(A)
    assert first.factorize(A)
    second = _testing.SparseLU(A)
    second.adopt_pivots(first)
    assert first.pivotings == 1 and second.pivotings == 0
    factorize_perturbed(second, A, rng, 3)
    assert second.pivotings == 0  # replays only
    # Poor for the adopted pivots: the 3 × 3 case of the test above.
    D = sp.csc_matrix(np.array([[10.0, 1.0, 1.0], [1.0, 10.0, 1.0], [1.0, 1.0, 10.0]]))
    Z = same_pattern(D, [0.0, 1.0, 2.0, 1.0, 0.0, 3.0, 2.0, 3.0, 0.0])
    diagonal, zero = _testing.SparseLU(D), _testing.SparseLU(D)
    assert diagonal.factorize(D)
    zero.adopt_pivots(diagonal)
    assert zero.factorize(Z) and zero.pivotings == 1
    b = np.array([1.0, -2.0, 0.5])
    np.testing.assert_allclose(Z @ zero.solve(b), b, rtol=0, atol=1e-14)
    own = _testing.SparseLU(D)
    assert own.factorize(Z)
    own.adopt_pivots(diagonal)  # ignored: it has its own
    assert own.factorize(Z) and own.pivotings == 1
    with pytest.raises(ValueError, match="patterns differ"):
        own.adopt_pivots(first)


def test_saddle_point_matrix_with_zero_block():
    """The equations of motion with constraint rows: [[M, Bᵀ], [B, 0]], M positive definite
    and banded, B of full row rank; zero diagonal in the constraint block."""
    rng = np.random.default_rng(3)
    n, m = 60, 25
    L = sp.diags([rng.uniform(1, 2, n), rng.uniform(-0.3, 0.3, n - 1)], [0, -1])
    M = (L @ L.T).tocsc()
    B = sp.random(m, n, density=0.08, random_state=rng) + sp.eye(m, n)
    K = sp.bmat([[M, B.T], [B, None]], format="csc")
    K.sort_indices()
    lu = _testing.SparseLU(K)
    assert lu.factorize(K)
    b = rng.normal(size=n + m)
    assert relative_residual(K, lu.solve(b), b) < 1e-14
    np.testing.assert_allclose(lu.solve(b), np.linalg.solve(K.toarray(), b), rtol=1e-10, atol=1e-12)


def test_singular_and_non_finite_matrices_are_refused():
    rng = np.random.default_rng(11)
    A = random_sparse(30, 0.1, rng)
    lu = _testing.SparseLU(A)
    assert lu.factorize(A)
    dense = A.toarray()
    dense[:, 4] = 0.0  # a zero column, kept in the pattern
    assert not lu.factorize(same_pattern(A, _values_of(A, dense)))
    near = A.toarray()
    near[:, 7] = near[:, 3] * (1.0 + 1e-16)  # numerically dependent columns
    pattern = sp.csc_matrix((near != 0) | (A.toarray() != 0), dtype=float)
    lu2 = _testing.SparseLU(pattern)
    assert not lu2.factorize(_with_values(pattern, near))
    assert lu.factorize(A)  # and a good matrix again afterwards
    for bad in (np.nan, np.inf):
        values = A.data.copy()
        values[5] = bad
        assert not lu.factorize(same_pattern(A, values))
    assert lu.factorize(A)
    b = rng.normal(size=30)
    assert relative_residual(A, lu.solve(b), b) < 1e-14


def _values_of(A, dense):
    """The entries of dense at the pattern of A, in A's storage order."""
    rows, cols = A.indices, np.repeat(np.arange(A.shape[1]), np.diff(A.indptr))
    return dense[rows, cols]


def _with_values(pattern, dense):
    pattern = pattern.copy()
    pattern.sort_indices()
    return same_pattern(pattern, _values_of(pattern, dense))


def test_pattern_must_not_change():
    A = sp.csc_matrix(np.eye(3))
    lu = _testing.SparseLU(A)
    with pytest.raises(ValueError, match="pattern"):
        lu.factorize(sp.csc_matrix(np.ones((3, 3))))


def test_fill_of_a_chain_grows_linearly():
    """Block tridiagonal matrices (a chain of links, 3 unknowns each): nonzeros of the factors
    proportional to the number of links."""
    def chain(links, rng):
        blocks = 3 * links
        A = sp.lil_matrix((blocks, blocks))
        for i in range(links):
            s = slice(3 * i, 3 * i + 3)
            A[s, s] = rng.normal(size=(3, 3)) + 3 * np.eye(3)
            if i:
                A[s, 3 * i - 3:3 * i] = rng.normal(size=(3, 3))
                A[3 * i - 3:3 * i, s] = rng.normal(size=(3, 3))
        A = A.tocsc()
        A.sort_indices()
        return A

    rng = np.random.default_rng(5)
    fill = {}
    for links in (100, 1000):
        A = chain(links, rng)
        lu = _testing.SparseLU(A)
        assert lu.factorize(A)
        b = rng.normal(size=A.shape[0])
        assert relative_residual(A, lu.solve(b), b) < 1e-13
        fill[links] = lu.factor_nonzeros
    assert fill[1000] < 11 * fill[100]


def test_solves_without_valid_factors_are_nan():
    """Before any factorization and after a failed one the factors are incomplete: the solution
    is NaN (never a read outside the work space)."""
    A = sp.csc_matrix(np.array([[2.0, 1.0], [1.0, 3.0]]))
    lu = _testing.SparseLU(A)
    assert np.isnan(lu.solve(np.ones(2))).all()
    assert lu.factorize(A)
    assert not lu.factorize(same_pattern(A, [1.0, 1.0, 1.0, 1.0]))  # singular
    assert np.isnan(lu.solve(np.ones(2))).all() and np.isnan(lu.solve_transposed(np.ones(2))).all()
    assert lu.factorize(A)
    np.testing.assert_allclose(A @ lu.solve(np.ones(2)), np.ones(2), rtol=0, atol=1e-15)


def test_overflow_in_a_replay_chooses_pivots_again():
    """Values near the largest double: the replayed elimination overflows (an infinite pivot),
    a new pivot choice does not, and the solution is exact."""
    A = sp.csc_matrix(np.array([[1.0, 1.0], [0.5, 1.0]]))
    lu = _testing.SparseLU(A)
    assert lu.factorize(A)
    B = sp.csc_matrix(np.array([[1e305, 1e308], [-9e307, 1e308]]))
    assert lu.factorize(B)
    x = lu.solve(np.array([1.0, 0.0]))
    assert np.isfinite(x).all()
    np.testing.assert_allclose(B @ x, [1.0, 0.0], rtol=0, atol=1e-12)


def test_a_preferred_diagonal_pivot_respects_the_singularity_threshold():
    """The diagonal is kept as pivot only above 1e-13 of the largest entry: otherwise the
    larger candidate, whose replay then holds (no new pivot choice at every factorization)."""
    A = sp.csc_matrix(np.array([[0.6e-13, 1.0], [5e-13, 1.0]]))
    lu = _testing.SparseLU(A)
    assert lu.factorize(A)
    chosen = lu.pivotings
    for _ in range(3):
        assert lu.factorize(A)
    assert lu.pivotings == chosen
    b = np.array([1.0, 2.0])
    np.testing.assert_allclose(A @ lu.solve(b), b, rtol=1e-12)


def test_binding_refuses_another_shape():
    """A 3×2 matrix whose stored entries match the first columns of a 3×3 pattern with an
    empty last column."""
    lu = _testing.SparseLU(sp.csc_matrix(np.diag([1.0, 1.0, 0.0])))
    with pytest.raises(ValueError, match="pattern"):
        lu.factorize(sp.csc_matrix(np.eye(3)[:, :2]))


def test_amd_ordering_is_tried_after_enough_replays():
    """A 2-D grid Laplacian: COLAMD's factors first; after 32 replays AMD's ordering of A + Aᵀ
    is tried once and kept because its factors are sparser; the solves stay exact."""
    k = 20
    T = sp.diags([-1.0, 4.0, -1.0], [-1, 0, 1], shape=(k, k))
    A = (sp.kron(sp.eye(k), T) + sp.kron(sp.diags([-1.0, -1.0], [-1, 1], shape=(k, k)), sp.eye(k))).tocsc()
    lu = _testing.SparseLU(A)
    assert lu.factorize(A)
    colamd_fill, chosen = lu.factor_nonzeros, lu.pivotings
    rng = np.random.default_rng(0)
    for i in range(40):
        B = perturbed(A, rng, 0.01)
        assert lu.factorize(B)
        assert lu.pivotings == (chosen if i < 31 else chosen + 1)
        b = rng.normal(size=A.shape[0])
        assert relative_residual(B, lu.solve(b), b) < 1e-14
    assert lu.factor_nonzeros < 0.8 * colamd_fill


@pytest.mark.parametrize("seed", range(6))
def test_amd_trial_keeps_exact_factors_either_way(seed):
    """Random patterns, whichever ordering fills less: after the trial (kept or not) the factors
    are never fuller than COLAMD's and every solve stays exact."""
    rng = np.random.default_rng(seed)
    A = random_sparse(150, 0.03, rng)
    lu = _testing.SparseLU(A)
    assert lu.factorize(A)
    colamd_fill = lu.factor_nonzeros
    factorize_perturbed(lu, A, rng, 40, tol=1e-13)
    assert lu.factor_nonzeros <= colamd_fill


def test_block_matrix_assembles_what_dense_accumulation_gives():
    """The fixed-pattern assembly (BlockMatrix, sparse.hpp) of blocks that overlap, leave rows and
    columns out (−1) and repeat a global row or column within a block: its pattern holds exactly
    the entries the blocks reach, sorted and compressed, and add, add_transposed and add_value
    sum into the same matrix as a dense accumulation."""
    rng = np.random.default_rng(7)
    rows, cols = 23, 17
    B = _testing.BlockMatrix(rows, cols)
    blocks = []
    for _ in range(30):
        r = [int(v) for v in rng.integers(-1, rows, rng.integers(1, 7))]
        c = [int(v) for v in rng.integers(-1, cols, rng.integers(1, 7))]
        blocks.append((B.add_block(r, c), r, c))
    B.finalize()
    for _ in range(2):  # a second assembly into the same pattern starts from zero
        B.set_zero()
        dense, reached = np.zeros((rows, cols)), np.zeros((rows, cols), bool)
        for k, (bid, r, c) in enumerate(blocks):
            local = rng.normal(size=(len(r), len(c)))
            transposed = k % 3 == 1
            if transposed:
                B.add_transposed(bid, local.T.copy())
            else:
                B.add(bid, local)
            for a, i in enumerate(r):
                for b, j in enumerate(c):
                    if i >= 0 and j >= 0:
                        dense[i, j] += local[a, b]
                        reached[i, j] = True
            if k % 3 == 2:  # one more entry, by its local place
                a, b = int(rng.integers(len(r))), int(rng.integers(len(c)))
                B.add_value(bid, a, b, 0.5)
                if r[a] >= 0 and c[b] >= 0:
                    dense[r[a], c[b]] += 0.5
        A = B.matrix
        assert A.has_sorted_indices
        coo = A.tocoo()
        stored = np.zeros((rows, cols), bool)
        stored[coo.row, coo.col] = True
        assert A.nnz == reached.sum() and np.array_equal(stored, reached)
        np.testing.assert_allclose(A.toarray(), dense, rtol=0, atol=1e-14)

"""A time limit bounds a run whatever its size (issue 24: work is bounded before it is done), also
inside the long computations between the integrator's steps. Kept out of the sanitizer job's
files (.ci/sanitizers): its timings assume an uninstrumented build."""

import time

import pytest

import spacar
from spacar import TimeLimitError


def test_a_time_limit_bounds_a_long_factorization():
    # A chain of 20 000 flexible beams whose rotations carry no inertia: the equations of motion
    # are singular, and the sparse factorization of the first right-hand side fills in for 18 s
    # before a zero pivot shows (measured). The limit reaches inside the factorization: the run
    # stops within a moment of it (the model's preparation and assembly take about 0.4 s here).
    n = 20000
    m = spacar.Model()
    for i in range(1, n + 1):
        m.plbeam(i, 2 * i - 1, 2 * i, 2 * i + 1, 2 * i + 2)
        m.x(2 * i + 1, i / n, 0.0)
        m.mass(2 * i + 1, 1.0 / n)
        m.dyne(i, 2)
        m.dyne(i, 3)
        m.estiff(i, 0.0, 175.0)
    m.fix(1)
    m.fix(2)
    m.gravity(0.0, -9.81)
    m.timestep(1, 1e-4)
    start = time.perf_counter()
    with pytest.raises(TimeLimitError, match=r"the time limit of 1 s was exceeded \(in a sparse factorization\)"):
        spacar.simulate(m, time_limit=1.0, progress=False)
    assert time.perf_counter() - start < 5.0

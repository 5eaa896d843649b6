"""A time limit bounds a run whatever its size (issue 24: work is bounded before it is done), also
inside the long computations between the integrator's steps. Kept out of the sanitizer job's
files (.ci/sanitizers): its timings assume an uninstrumented build."""

import time

import numpy as np
import pytest

import spacar
from spacar import cli
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
    with pytest.raises(TimeLimitError, match=r"the time limit of 2 s was exceeded \(in a sparse factorization\)"):
        spacar.simulate(m, time_limit=2.0, progress=False)   # the set-up (0.3 s) counts too
    assert time.perf_counter() - start < 6.0


def _massless_chain(n):
    """A chain of n flexible PLBEAMs (set-up about 0.3 s at n = 20 000)."""
    m = spacar.Model()
    for i in range(1, n + 1):
        m.plbeam(i, 2 * i - 1, 2 * i, 2 * i + 1, 2 * i + 2)
        m.x(2 * i + 1, i / n, 0.0)
        m.dyne(i, 2)
        m.dyne(i, 3)
        m.estiff(i, 0.0, 175.0)
    m.fix(1)
    m.fix(2)
    m.timestep(1, 1e-4)
    return m


@pytest.fixture(scope="module")
def long_chain():
    return _massless_chain(20000)


def test_the_time_limit_covers_the_set_up(long_chain):
    # The model's preparation and compilation are inside the limit: a limit shorter than them
    # stops the analysis there, before the first step.
    for analysis in (lambda m: spacar.simulate(m, time_limit=1e-3, progress=False),
                     lambda m: spacar.static(m, time_limit=1e-3),
                     lambda m: spacar.check(m, time_limit=1e-3)):
        start = time.perf_counter()
        with pytest.raises(TimeLimitError, match=r"the time limit of 0\.001 s was exceeded \(in the model's "
                                                 r"(preparation|compilation)\)"):
            analysis(long_chain.copy())
        assert time.perf_counter() - start < 2.0


def test_the_set_up_counts_against_the_run():
    # The run's clock starts at the set-up: `time_spent` seconds of it leave the run the rest.
    m = _massless_chain(2)
    for i in (1, 2):
        m.emass(i, 1.0)
    sim = spacar._core.Simulation(m.core, time_limit=10.0)
    with pytest.raises(TimeLimitError, match=r"the time limit of 10 s was exceeded at t = 0"):
        sim.run(time_limit=10.0, time_spent=10.0)
    sim.run(time_limit=10.0, time_spent=9.0)   # the rest, a second, is enough


def test_a_static_analysis_stopped_by_its_limit_keeps_its_load_steps():
    m = _massless_chain(2)
    m.force(5, 0.0, -1e-3)
    with pytest.raises(TimeLimitError, match=r"\(in the static analysis\)") as err:
        spacar.static(m, steps=10**6, time_limit=0.3)   # about 20 s of load steps
    lam = err.value.results.t
    assert 0 < len(lam) < 10**6 and np.allclose(np.diff(lam), 1e-6)


def test_spacar_check_and_static_take_a_time_limit(tmp_path, capsys):
    path = tmp_path / "chain.dat"
    path.write_text(_chain_text(3))
    assert cli.main(["check", str(path), "--time-limit", "30"]) == 0
    assert cli.main(["static", str(path), "--time-limit", "30"]) == 0
    path.write_text(_chain_text(20000))
    for command in ("check", "static"):
        assert cli.main([command, str(path), "--time-limit", "0.001"]) == 1
        assert "TimeLimitError: the time limit of 0.001 s was exceeded" in capsys.readouterr().err


def test_an_analysis_in_a_callback_keeps_the_outer_limit():
    # A check inside on_output has its own (no) limit and must not lift the run's.
    m = _massless_chain(2)
    for i in (1, 2):
        m.emass(i, 1.0)
    m.gravity(0.0, -9.81)
    m.timestep(2000, 600.0)   # about 4 s of integration
    small = _massless_chain(2)
    start = time.perf_counter()
    with pytest.raises(TimeLimitError, match="the time limit of 0.5 s"):
        spacar.simulate(m, time_limit=0.5, progress=False, on_output=lambda k, s: k == 1 and spacar.check(small))
    assert time.perf_counter() - start < 3.0


def _chain_text(n):
    lines = [f"PLBEAM {i} {2 * i - 1} {2 * i} {2 * i + 1} {2 * i + 2}" for i in range(1, n + 1)]
    lines += [f"X {2 * i + 1} {i / n} 0" for i in range(0, n + 1)]
    lines += [f"DYNE {i} 2 3" for i in range(1, n + 1)] + [f"ESTIFF {i} 0 175" for i in range(1, n + 1)]
    lines += ["FIX 1", "FIX 2", f"FORCE {2 * n + 1} 0 -1e-3", "END", "END"]
    return "\n".join(lines) + "\n"

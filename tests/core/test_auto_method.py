"""method="auto": DOP853 until it detects stiffness (Hairer's test), then Radau IIA until the
stiffness goes (ρ(J)·h below DOP853's stability bound over LSODA's factor 5), or, for an undamped
structure at EPSINT ≥ 1e-6, generalized-α as soon as DOP853's steps are set by its fastest
vibration; the switches in res.stats. The rules on scalar ODEs through the test bindings, then the analysis: a stiffly damped
steel cantilever goes to radau5 early and costs about what radau5 costs, the manual's slider-crank
stays on DOP853 with the very same numbers."""

from pathlib import Path

import numpy as np
import pytest

import spacar
from spacar import _testing
from test_radau5_simulate import steel_cantilever

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "slidercrank.dat"


def relaxation(lam):
    """y' = λ(t) (y − cos t) − sin t: the smooth solution y = cos t, attracting at the rate −λ(t)."""
    def f(t, y):
        return np.array([lam(t) * (y[0] - np.cos(t)) - np.sin(t)])

    def jac(t, y):
        return np.array([[lam(t)]])

    return f, jac


@pytest.mark.parametrize("method, bound", [("dop853", 6.1), ("dopri5", 3.25)])
def test_explicit_method_detects_stiffness(method, bound):
    f, _ = relaxation(lambda t: -1e4)
    out = _testing.explicit_rk_solve(f, 0.0, np.array([1.0]), 10.0, [10.0], 1e-6, 1e-6, method=method,
                                     detect_stiffness=True)
    # The steps sit at the stability limit |hλ| ≈ bound: stopped after some tens of them.
    assert out["stiff"] and out["t_reached"] < 0.05, out
    assert 0.5 * bound < out["hlamb"] < 2.0 * bound
    assert out["naccept"] < 100
    # Without detection the same run goes through (at the stability limit: many steps).
    full = _testing.explicit_rk_solve(f, 0.0, np.array([1.0]), 10.0, [10.0], 1e-6, 1e-6, method=method)
    assert full["naccept"] > 5000 and abs(full["y"][0, 0] - np.cos(10.0)) < 1e-5


def test_explicit_method_does_not_call_a_mild_problem_stiff():
    f, _ = relaxation(lambda t: -1.0)
    out = _testing.explicit_rk_solve(f, 0.0, np.array([1.0]), 10.0, [5.0, 10.0], 1e-6, 1e-6,
                                     detect_stiffness=True)
    assert not out["stiff"] and out["t_reached"] == 10.0
    assert abs(out["y"][1, 0] - np.cos(10.0)) < 1e-5


def test_radau_detects_that_the_stiffness_goes():
    # λ = −10⁴ until t = 1, then −1: Radau's steps follow cos t, ρ(J)·h falls below 6.1/5 after t = 1
    # and the run stops 15 steps later.
    f, jac = relaxation(lambda t: -1e4 if t < 1.0 else -1.0)
    out = _testing.radau5_solve(f, jac, 0.0, np.array([1.0]), 10.0, [10.0], 1e-6, 1e-6, nonstiff_bound=6.1 / 5)
    assert out["nonstiff"] and 1.0 < out["t_reached"] < 8.0, out
    assert out["rho"] == pytest.approx(1.0)
    # Stiff throughout: no stop.
    f, jac = relaxation(lambda t: -1e4)
    out = _testing.radau5_solve(f, jac, 0.0, np.array([1.0]), 10.0, [10.0], 1e-6, 1e-6, nonstiff_bound=6.1 / 5)
    assert not out["nonstiff"] and out["t_reached"] == 10.0
    assert out["rho"] == pytest.approx(1e4)


def test_damped_cantilever_switches_to_radau_early():
    # 8 PLBEAMs of steel with EDAMPP 0.001·EI: DOP853 alone takes 1.2 million right-hand sides
    # (docs/stiff-integration.md); under auto it hands over after a few tens of steps.
    rad = spacar.simulate(steel_cantilever(damping=1e-3), method="radau5", progress=False)
    res = spacar.simulate(steel_cantilever(damping=1e-3), method="auto", progress=False)
    assert [s[1:] for s in res.stats["switches"]] == [("dop853", "radau5")]
    t_switch = res.stats["switches"][0][0]
    assert 0.0 < t_switch < 1e-3, res.stats
    assert res.stats["method"].startswith("auto: dop853→radau5 at t=")
    assert res.stats["jacobians"] >= 1
    assert res.stats["rhs_evaluations"] < 3 * rad.stats["rhs_evaluations"], (res.stats, rad.stats)
    scale = np.abs(rad.x - rad.x[0]).max()
    assert np.abs(res.x - rad.x).max() < 1e-2 * scale


def tip_reference(n=8, t_end=0.2):
    """The undamped steel cantilever's tip (x, y) at t_end, Richardson-extrapolated from
    generalized-α at ρ∞ = 1 and fixed steps 4e-5 and 2e-5 s (second order; as
    benchmarks/error_control.py)."""
    def tip(h):
        res = spacar.simulate(steel_cantilever(n, t_end=t_end, n_out=1, eps=1e-10), method="generalized_alpha",
                              rho_inf=1.0, fixed_step=h, progress=False)
        return res.node(n + 1).x[-1]
    coarse, fine = tip(4e-5), tip(2e-5)
    return fine + (fine - coarse) / 3.0


def test_undamped_structure_goes_to_generalized_alpha():
    # 8 PLBEAMs of steel, undamped, EPSINT 1e-4: DOP853's steps are set by the fastest vibration
    # the release excites (h|λ| > 1), which generalized-α need not resolve. Before, auto went to
    # radau5 at EPSINT 1e-3 (3 349 steps, 0.23 s) and stayed on DOP853 at 1e-4 (2 740 steps); now
    # it hands over within the first millisecond and costs what generalized-α costs.
    eps = 1e-4
    ga = spacar.simulate(steel_cantilever(n_out=1, eps=eps), method="generalized_alpha", progress=False)
    res = spacar.simulate(steel_cantilever(n_out=1, eps=eps), method="auto", progress=False)
    assert [s[1:] for s in res.stats["switches"]] == [("dop853", "generalized_alpha")]
    assert res.stats["switches"][0][0] < 5e-3, res.stats
    assert res.stats["steps"] < 1.2 * ga.stats["steps"], (res.stats, ga.stats)
    error = np.abs(res.node(9).x[-1] - tip_reference()).max()
    assert error < 0.5 * eps, error  # measured: 0.12 EPSINT


def test_short_run_of_a_coarse_structure_goes_to_generalized_alpha():
    # 4 PLBEAMs, 0.2 s: DOP853 is stability-limited from the start (at EPSINT 0.1 to 1e-3: 650-1000
    # steps, 10-29 % refused) but its run is shorter than Hairer's 1000 steps ahead; the switch to
    # generalized-α needs only 500 (its Newton matrix is one factorization). Before, at EPSINT 1e-3,
    # DOP853 to the end (26 ms; now 2.1 ms). At this EPSINT DOP853 alone takes 13 053 right-hand
    # sides, auto 1 463 (measured 2026-12-05).
    eps = 1e-4
    res = spacar.simulate(steel_cantilever(4, n_out=1, eps=eps), method="auto", progress=False)
    dop = spacar.simulate(steel_cantilever(4, n_out=1, eps=eps), method="dop853", progress=False)
    assert [s[1:] for s in res.stats["switches"]] == [("dop853", "generalized_alpha")]
    assert res.stats["switches"][0][0] < 5e-3, res.stats
    assert res.stats["rhs_evaluations"] < 0.3 * dop.stats["rhs_evaluations"], (res.stats, dop.stats)
    error = np.abs(res.node(5).x[-1] - tip_reference(4)).max()
    assert error < 0.5 * eps, error  # measured: 0.026 EPSINT


def test_tight_tolerances_and_damped_structures_keep_off_generalized_alpha():
    # Below EPSINT 1e-6 a second-order method does not pay: the old rules (radau5 where stiff).
    tight = spacar.simulate(steel_cantilever(t_end=0.005, eps=1e-7), method="auto", progress=False)
    assert all(s[2] != "generalized_alpha" for s in tight.stats["switches"]), tight.stats
    damped = spacar.simulate(steel_cantilever(t_end=0.005, eps=1e-4, damping=1e-3), method="auto", progress=False)
    assert [s[1:] for s in damped.stats["switches"]] == [("dop853", "radau5")]


def test_slider_crank_stays_on_dop853_with_the_same_numbers():
    dop = spacar.simulate(spacar.read(EXAMPLE), method="dop853", progress=False)
    res = spacar.simulate(spacar.read(EXAMPLE), method="auto", progress=False)
    assert res.stats["switches"] == [] and res.stats["method"] == "dop853"
    assert dop.stats["method"] == "dop853" and dop.stats["switches"] == []
    for name in ("x", "xd", "xdd", "e", "ed", "edd", "sigma"):
        assert np.array_equal(getattr(res, name), getattr(dop, name)), name
    assert res.stats["rhs_evaluations"] == dop.stats["rhs_evaluations"]
    assert res.stats["steps"] == dop.stats["steps"]


def test_each_block_starts_explicit():
    # A stiff block does not decide for the next one: every block starts with DOP853.
    model = steel_cantilever(damping=1e-3, t_end=0.02)
    first = spacar.simulate(model, method="auto", progress=False)
    assert first.stats["switches"]
    second = spacar.simulate(model, method="auto", progress=False)
    assert second.stats["switches"][0][1] == "dop853"


def test_cli_and_sweep_accept_auto(capsys):
    from spacar.cli import main

    assert main(["run", str(EXAMPLE), "--method", "auto", "--no-progress"]) == 0
    assert "block 1" in capsys.readouterr().out
    out = spacar.sweep(spacar.read(EXAMPLE), {"EPSINT": [1e-3, 1e-4]}, method="auto",
                       outputs={"method": lambda res: res.stats["method"]}, workers=1, progress=False)
    assert not out.errors
    assert list(out["method"]) == ["dop853", "dop853"]


def test_auto_is_the_default():
    res = spacar.simulate(steel_cantilever(damping=1e-3, t_end=0.02), progress=False)
    assert res.stats["switches"] and res.stats["method"].startswith("auto: dop853→radau5")
    import inspect

    assert inspect.signature(spacar.simulate).parameters["method"].default == "auto"
    assert inspect.signature(spacar.sweep).parameters["method"].default == "auto"

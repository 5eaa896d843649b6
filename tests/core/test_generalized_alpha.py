"""The generalized-α integrator (method="generalized_alpha"): its order and numerical damping on
the linear oscillator in closed form (through spacar._testing), and in the analysis the same
motion as a tight DOP853 solution on a flexible cantilever, the manual's slider-crank (inputs,
closed loop), a rolling wheel (ENHC) and with the energy balance."""

from pathlib import Path

import numpy as np
import pytest

import spacar
from spacar import _testing
from spacar.compare import models

from test_damped_oscillator import check_against_closed_form, oscillator
from test_radau5_simulate import incline_wheel

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "slidercrank.dat"


def linear_oscillator(omega, zeta=0.0):
    f = lambda t, y: np.array([y[1], -omega**2 * y[0] - 2 * zeta * omega * y[1]])
    jac = lambda t, y: np.array([[0.0, 1.0], [-omega**2, -2 * zeta * omega]])
    return f, jac


def fixed_step_error(rho, h, omega=10.0, zeta=0.1, t_end=2.0):
    f, jac = linear_oscillator(omega, zeta)
    out = _testing.generalized_alpha_solve(f, jac, 0.0, np.array([1.0, 0.0]), t_end, [t_end], 1e-12, 1e-12, 1,
                                           rho_inf=rho, fixed_step=h)
    wd = omega * np.sqrt(1 - zeta**2)
    exact = np.exp(-zeta * omega * t_end) * (np.cos(wd * t_end) + zeta * omega / wd * np.sin(wd * t_end))
    return abs(out["y"][0, 0] - exact), out


@pytest.mark.parametrize("rho", [1.0, 0.8, 0.5, 0.0])
def test_second_order_at_fixed_steps(rho):
    # Halving the step divides the error by 4 (2nd order) for every spectral radius: 1e-3 ... 2.5e-4.
    errors = [fixed_step_error(rho, h)[0] for h in (4e-3, 2e-3, 1e-3)]
    for coarse, fine in zip(errors, errors[1:]):
        assert 3.6 < coarse / fine < 4.4, errors


@pytest.mark.parametrize("rho", [1.0, 0.8, 0.5, 0.0])
def test_spectral_radius_at_infinite_frequency(rho):
    # ω h = 10⁴: the amplification matrix has the spectral radius ρ∞ (Chung & Hulbert; a double
    # eigenvalue −ρ∞, so the amplitude falls as (a + b n) ρ∞ⁿ): ρ∞ = 1 keeps it, 0 removes it at once.
    f, jac = linear_oscillator(1e5)
    h, steps = 0.1, 30
    out = _testing.generalized_alpha_solve(f, jac, 0.0, np.array([1.0, 0.0]), steps * h,
                                           [k * h for k in range(1, steps + 1)], 1e-10, 1e-10, 1, rho_inf=rho,
                                           fixed_step=h)
    q = np.abs(out["y"][:, 0])
    if rho == 1.0:
        assert np.allclose(q, 1.0, atol=1e-3), q
    elif rho == 0.0:
        assert (q[2:] < 1e-3).all(), q
    else:
        n0, n1 = 20, 29
        rate = (q[n1] / q[n0]) ** (1.0 / (n1 - n0)) / ((1 + n1) / (1 + n0)) ** (1.0 / (n1 - n0))
        assert rho * 0.99 < rate < rho * 1.1, (rate, q)


def test_error_control_follows_the_tolerance():
    # Undamped 10 rad/s over three periods: the error falls with the tolerance, one right-hand side
    # per step or little more (simplified Newton on an exact Jacobian). Below 1e-5 the tolerance is
    # tightened to tol √(tol / 1e-5) (tolerance proportionality): the global error then falls in
    # proportion to tol (it fell as tol^(2/3) under control of the local error alone).
    f, jac = linear_oscillator(10.0)
    errors = []
    for tol in (1e-4, 1e-6, 1e-7, 1e-8):
        out = _testing.generalized_alpha_solve(f, jac, 0.0, np.array([1.0, 0.0]), 2.0, [2.0], tol, tol, 1,
                                               rho_inf=1.0)
        errors.append(abs(out["y"][0, 0] - np.cos(20.0)))
        assert out["nfev"] < 1.3 * out["nsteps"] + 5, out
    assert errors[0] > 10 * errors[1] > 100 * errors[3], errors
    assert errors[3] < 1e-4
    per_tol = [e / tol for e, tol in zip(errors, (1e-4, 1e-6, 1e-7, 1e-8))]
    assert max(per_tol[1:]) < 1.3 * min(per_tol[1:]), per_tol
    assert per_tol[0] < per_tol[1], per_tol


def varying_mass(a, k=400.0, c=0.5):
    """M(q) q̈ = −k q − c q̇ with M(q) = 1 + a q²: f, its Jacobian, the residual
    R = M(q) (D − f) = M(q) D + k q + c q̇ and the weight M at the Jacobian's state."""
    mass = lambda q: 1.0 + a * q * q
    f = lambda t, y: np.array([y[1], -(k * y[0] + c * y[1]) / mass(y[0])])
    at_jacobian = {}

    def jac(t, y):
        q, v = y
        m = at_jacobian["M"] = mass(q)
        return np.array([[0.0, 1.0], [-k / m + (k * q + c * v) * 2 * a * q / m**2, -c / m]])

    residual = lambda t, y, D: np.array([mass(y[0]) * D[0] + k * y[0] + c * y[1]])
    return f, jac, residual, lambda: np.array([[at_jacobian["M"]]])


@pytest.mark.parametrize("a", [1e-4, 0.3, 10.0])
def test_residual_form_gives_the_same_motion(a):
    # The residual form's iterations converge to the same step solutions within the Newton
    # tolerance: against a tight reference (scipy's DOP853 at 1e-13), the two forms' results
    # differ by a small fraction of the method's error. Where the mass matrix moves far from the
    # Jacobian's (a = 10: M from 1 to 11), the form is left after a step or two for the form with
    # the exact M, and costs no more right-hand sides than it.
    from scipy.integrate import solve_ivp
    f, jac, residual, weight = varying_mass(a)
    y0, t_end = np.array([1.0, 0.0]), 1.0
    exact = solve_ivp(f, (0.0, t_end), y0, method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
    for tol in (1e-4, 1e-6):
        plain = _testing.generalized_alpha_solve(f, jac, 0.0, y0, t_end, [t_end], tol, tol, 1, rho_inf=0.9)
        res = _testing.generalized_alpha_solve(f, jac, 0.0, y0, t_end, [t_end], tol, tol, 1, rho_inf=0.9,
                                               residual=residual, weight=weight)
        error = np.abs(plain["y"][0] - exact).max()
        assert np.abs(res["y"][0] - plain["y"][0]).max() < 0.05 * error, (a, tol)
        assert res["nsteps"] == plain["nsteps"] and res["nreject"] == plain["nreject"] and res["nresidual"] > 0
        if a == 10.0:
            assert res["nresidual"] < 20 and res["nfev"] <= plain["nfev"] + 5, res


@pytest.mark.parametrize("zeta", [0.1, 2.0], ids=["underdamped", "overdamped"])
def test_truss_oscillator_follows_the_closed_form(zeta):
    # The analysis's closed-form oscillator (test_damped_oscillator): the motion, rates and stresses.
    omega = 2.0 * np.pi
    res = spacar.simulate(oscillator(omega, zeta, t_end=3.0, n_out=30, eps=1e-9), method="generalized_alpha",
                          progress=False)
    check_against_closed_form(res, omega, zeta, tol=1e-4)
    assert res.stats["method"] == "generalized_alpha" and res.stats["jacobians"] >= 1


def test_cantilever_agrees_with_dop853():
    ref = spacar.simulate(models.cantilever(4, t_end=0.2, n_out=10, eps=1e-10), progress=False)
    scale = np.abs(ref.x - ref.x[0]).max()
    for kwargs in ({}, {"rho_inf": 1.0}, {"rho_inf": 0.5}):
        res = spacar.simulate(models.cantilever(4, t_end=0.2, n_out=10, eps=1e-7), method="generalized_alpha",
                              progress=False, **kwargs)
        assert np.abs(res.x - ref.x).max() < 2e-3 * scale, kwargs
    # Fixed steps: second order in the step.
    errors = []
    for h in (1e-3, 5e-4, 2.5e-4):
        res = spacar.simulate(models.cantilever(4, t_end=0.2, n_out=10, eps=1e-8), method="generalized_alpha",
                              rho_inf=1.0, fixed_step=h, progress=False)
        assert res.stats["steps"] == pytest.approx(0.2 / h, abs=2)
        errors.append(np.abs(res.x - ref.x).max())
    # (Not exactly 4 per halving: the phases of the unresolved high modes add up differently.)
    assert errors[0] > 5 * errors[2] and errors[2] < 1e-2 * scale, errors


@pytest.mark.parametrize("rho", [0.8, 1.0])
def test_loose_tolerances_on_a_steel_cantilever_complete(rho):
    # EPS 0.1 and 0.03 on 8 steel PLBEAMs: trial steps of 10 ms over modes of 0.1 ms. The
    # explicit chain solved them in closed form on the branches of the extrapolated positions
    # (folded beams), which the Newton iterations of the step starts could not follow: the runs
    # stopped with a KinematicsError. The branches are now those of the step start, and the step
    # starts take the chain's positions too. (The results are as inaccurate as the tolerance
    # allows: on the general path too, a loose EPS may end with a beam turned over.)
    for eps in (0.1, 0.03):
        res = spacar.simulate(models.cantilever(8, ei=175.0, rho_a=0.785, t_end=0.2, eps=eps),
                              method="generalized_alpha", rho_inf=rho, progress=False)
        assert res.t[-1] == pytest.approx(0.2) and np.isfinite(res.x).all(), eps


@pytest.mark.parametrize("eps", [0.1, 0.03])
def test_a_loose_tolerance_on_a_fine_mesh_takes_few_steps(eps):
    # 128 steel PLBEAMs at EPS 0.1: Newton left its iterates as loose as the tolerance, their
    # unresolved modes made states the kinematics refused, and the step grew back at once to the
    # one refused: 18 533 steps, 10 882 refused, 14 s (EPS 0.01: 106 steps). Newton now stops at
    # no looser a relative tolerance than 2e-4, and after a refused step the steps grow back
    # slowly: about 60 steps.
    res = spacar.simulate(models.cantilever(128, ei=175.0, rho_a=0.785, t_end=0.2, eps=eps),
                          method="generalized_alpha", progress=False, time_limit=20)
    assert res.t[-1] == pytest.approx(0.2) and np.isfinite(res.x).all()
    assert res.stats["steps"] < 300 and res.stats["rejected"] < 60, res.stats


def test_slider_crank_agrees_with_dop853():
    # Prescribed crank (INPUTX), a closed loop solved by Newton at every evaluation.
    ref_model = spacar.read(EXAMPLE)
    ref_model.epsint(1e-10)
    ref_model.epsind(1e-10)
    ref = spacar.simulate(ref_model, progress=False)
    tight = spacar.read(EXAMPLE)
    tight.epsint(1e-9)
    tight.epsind(1e-9)
    res = spacar.simulate(tight, method="generalized_alpha", progress=False)
    amplitude = np.abs(ref.e).max()
    assert np.abs(res.e - ref.e).max() < 1e-4 * amplitude


def test_nonholonomic_wheel_agrees_with_dop853():
    # ENHC: the slips' kinematic coordinates are first-order states beside the positions and rates.
    ref = spacar.simulate(incline_wheel(1e-10), progress=False)
    res = spacar.simulate(incline_wheel(1e-9), method="generalized_alpha", progress=False)
    assert np.abs(res.x - ref.x).max() < 1e-6
    assert np.abs(res.sigma - ref.sigma).max() < 1e-5 * np.abs(ref.sigma).max()


def test_energy_balance_under_generalized_alpha():
    # The energy's quadrature states are first-order states too: the balance closes.
    res = spacar.simulate(oscillator(2 * np.pi, 0.1, t_end=1.0, n_out=10, eps=1e-9), method="generalized_alpha",
                          energy=True, progress=False)
    en = res.energy
    total = en.balance  # total − initial
    assert np.abs(total).max() < 1e-5 * np.abs(en["kinetic"] + en["strain"]).max()


def test_options_are_checked():
    with pytest.raises(spacar.InputError, match="rho_inf"):
        spacar.simulate(spacar.read(EXAMPLE), method="generalized_alpha", rho_inf=1.5, progress=False)
    with pytest.raises(spacar.InputError, match="fixed_step"):
        spacar.simulate(spacar.read(EXAMPLE), method="dop853", fixed_step=1e-3, progress=False)
    with pytest.raises(spacar.InputError, match="fixed_step"):
        spacar.simulate(spacar.read(EXAMPLE), method="generalized_alpha", fixed_step=-1.0, progress=False)
    with pytest.raises(spacar.InputError, match="rho_inf is an option of method 'generalized_alpha' only"):
        spacar.simulate(spacar.read(EXAMPLE), method="radau5", rho_inf=0.5, progress=False)


def test_a_fixed_step_longer_than_the_output_interval_is_cut_to_it():
    """A fixed step of 1e300 would step over the whole block and interpolate every output (found
    by review: outputs 4.3× the amplitude off): it is cut to the output interval, with a warning,
    and the run is the one at that step."""
    def run(h):
        model = models.cantilever(4, t_end=0.2, n_out=10, eps=1e-8)
        res = spacar.simulate(model, method="generalized_alpha", fixed_step=h, progress=False)
        return res, model.warnings
    (cut, warned), (interval, quiet) = run(1e300), run(0.02)
    assert any("longer than the output interval Tp/n = 0.02" in w for w in warned)
    assert not any("output interval" in w for w in quiet)
    assert cut.stats["steps"] == interval.stats["steps"]
    np.testing.assert_array_equal(cut.x, interval.x)


def test_a_fixed_step_the_step_limit_cannot_reach_is_refused_before_any_work():
    model = spacar.read(EXAMPLE)
    with pytest.raises(spacar.InputError, match=r"fixed_step 1e-09 needs Tp/fixed_step = .* steps, more than the limit"):
        spacar.simulate(model, method="generalized_alpha", fixed_step=1e-9, progress=False)


def test_cli_and_sweep_accept_generalized_alpha(capsys):
    from spacar.cli import main

    assert main(["run", str(EXAMPLE), "--method", "generalized_alpha", "--no-progress"]) == 0
    assert "block 1" in capsys.readouterr().out
    # Its options with another method: refused, not ignored.
    assert main(["run", str(EXAMPLE), "--method", "dop853", "--fixed-step", "1e-3", "--no-progress"]) != 0
    assert "fixed_step is an option of method 'generalized_alpha' only" in capsys.readouterr().err
    out = spacar.sweep(spacar.read(EXAMPLE), {"EPSINT": [1e-3, 1e-4]}, method="generalized_alpha",
                       outputs={"steps": lambda res: res.stats["steps"]}, workers=1, progress=False)
    assert not out.errors
    assert (out["steps"] > 0).all()


def steel_cantilever_tip(n, damped=False, **options):
    """The tip's y at 0.2 s and the steps of n steel PLBEAMs released under gravity (with EDAMPP
    1e-3 EI if damped), integrated by generalized-α with the options given."""
    model = models.cantilever(n, ei=175.0, rho_a=0.785, t_end=0.2, n_out=1, eps=options.pop("eps", 1e-10),
                              epskin=1e-12)
    if damped:
        for e in range(1, n + 1):
            model.edampp(e, 0.0, 1e-3 * 175.0)
    res = spacar.simulate(model, method="generalized_alpha", progress=False, **options)
    return res.node(n + 1).x[-1, 1], res.stats["steps"]


def richardson_tip(n, damped=False):
    """The reference tip: generalized-α (ρ∞ = 1) at fixed steps 4e-5 and 2e-5 s, extrapolated for
    its second order."""
    (coarse, _), (fine, _) = (steel_cantilever_tip(n, damped, rho_inf=1.0, fixed_step=h) for h in (4e-5, 2e-5))
    return fine + (fine - coarse) / 3.0


@pytest.mark.parametrize("n", [8, 32, 64])
def test_epsint_bounds_a_flexible_beams_tip_error_on_every_mesh(n):
    """The error estimate of the positions is measured in the nodal coordinates (issue 36): on the
    DOFs, the elements' deformations, which the tip adds up, the tip error grew past EPSINT as the
    mesh was refined (24.6 EPSINT at 64 elements and 1e-4, in 17 steps). The undamped steel
    cantilever against a Richardson-extrapolated reference (fixed steps 4e-5 and 2e-5 s, second
    order): within EPSINT, at about the same number of steps on every mesh."""
    eps = 1e-4
    tip, steps = steel_cantilever_tip(n, eps=eps)
    assert abs(tip - richardson_tip(n)) < eps
    assert 300 < steps < 550


@pytest.mark.parametrize("eps", [1e-5, 1e-6, 1e-7])
def test_epsint_bounds_a_damped_beams_tip_error(eps):
    """With stiffness-proportional damping the fast modes die out and the smooth motion sets the
    steps; under control of the local error alone the global error grew as EPSINT^(2/3) (3.2
    EPSINT at 1e-6, 7.1 at 1e-7). With the tolerance tightened below 1e-5 (tolerance
    proportionality) it stays within 3 EPSINT (measured 1.4-1.7)."""
    tip, _ = steel_cantilever_tip(8, damped=True, eps=eps)
    assert abs(tip - richardson_tip(8, damped=True)) < 3 * eps

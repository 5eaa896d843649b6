"""The implicit Radau IIA integrator in the analysis (simulate(method="radau5")): the same motion
as DOP853 on flexible and rigid mechanisms, with step counts that do not grow with the stiffness
and a small fraction of the work on stiffly damped structures."""

from pathlib import Path

import numpy as np
import pytest

import spacar
from spacar.compare import models
from support.spatial_models import G_, tighten

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "slidercrank.dat"


def steel_cantilever(n=8, t_end=0.2, n_out=20, eps=1e-3, stiffness=1.0, damping=0.0):
    """A 1 m steel bar of 10 x 10 mm (EI 175 N m², ρA 0.785 kg/m) of n PLBEAMs released under
    gravity; `stiffness` scales EI, `damping` sets EDAMPP as that fraction of EI (seconds)."""
    ei = 175.0 * stiffness
    m = models.cantilever(n, ei=ei, rho_a=0.785, t_end=t_end, n_out=n_out, eps=eps)
    if damping:
        for i in range(1, n + 1):
            m.edampp(i, 0.0, damping * ei)
    return m


def test_cantilever_agrees_with_dop853_at_tight_tolerance():
    ref = spacar.simulate(models.cantilever(4, t_end=0.2, n_out=10, eps=1e-10), progress=False)
    res = spacar.simulate(models.cantilever(4, t_end=0.2, n_out=10, eps=1e-10), method="radau5", progress=False)
    scale = np.abs(ref.x).max()
    assert np.abs(res.x - ref.x).max() < 1e-6 * scale
    assert np.abs(res.xd - ref.xd).max() < 1e-6 * np.abs(ref.xd).max()
    assert res.stats["jacobians"] >= 1 and res.stats["decompositions"] >= res.stats["jacobians"]
    assert "jacobians" not in ref.stats  # the explicit methods' statistics are unchanged


def test_step_count_does_not_grow_with_stiffness():
    # Damped steel cantilever with EI x 1, x 100, x 10^4: DOP853's steps grow with the highest
    # eigenfrequency (1583 steps already at x 1), Radau's follow the accuracy of the motion.
    # (Undamped, the vibrations excited by the release are part of the solution and the error
    # control resolves them: there the steps depend on their amplitudes, see docs/stiff-integration.md.)
    for k in (1.0, 100.0, 1e4):
        res = spacar.simulate(steel_cantilever(n=4, t_end=0.05, stiffness=k, damping=1e-3), method="radau5",
                              progress=False)
        assert res.stats["steps"] < 100, (k, res.stats)


def test_damped_cantilever_takes_few_steps():
    # Stiffness-proportional damping makes the high modes stiff (real eigenvalues to -1e6): DOP853
    # needs about 10^5 steps for 0.2 s, Radau some tens.
    res = spacar.simulate(steel_cantilever(damping=1e-3), method="radau5", progress=False)
    assert res.stats["steps"] < 150, res.stats
    # Same motion as DOP853 over the first 10 ms (affordable for the explicit method).
    short = dict(t_end=0.01, n_out=5, damping=1e-3, eps=1e-6)
    ref = spacar.simulate(steel_cantilever(**short), method="dop853", progress=False)
    res = spacar.simulate(steel_cantilever(**short), method="radau5", progress=False)
    assert res.stats["steps"] * 50 < ref.stats["steps"]
    assert np.abs(res.x - ref.x).max() < 1e-5 * np.abs(ref.x - ref.x[0]).max() + 1e-9


def test_slider_crank_agrees_with_dop853():
    # The manual's slider-crank (prescribed crank rotation, INPUTX with XD): the bending
    # deformations of the rod within the tolerance of a tight DOP853 solution.
    ref_model = spacar.read(EXAMPLE)
    ref_model.epsint(1e-10)
    ref_model.epsind(1e-10)
    ref = spacar.simulate(ref_model, progress=False)
    res = spacar.simulate(spacar.read(EXAMPLE), method="radau5", progress=False)
    dop = spacar.simulate(spacar.read(EXAMPLE), progress=False)
    amplitude = np.abs(ref.e).max()
    err_radau = np.abs(res.e - ref.e).max() / amplitude
    err_dop = np.abs(dop.e - ref.e).max() / amplitude
    assert err_radau < 2e-3, (err_radau, err_dop)
    tight = spacar.read(EXAMPLE)
    tight.epsint(1e-8)
    tight.epsind(1e-8)
    res = spacar.simulate(tight, method="radau5", progress=False)
    assert np.abs(res.e - ref.e).max() < 1e-5 * amplitude


def test_unknown_method_is_refused():
    with pytest.raises(spacar.InputError, match="radau5"):
        spacar.simulate(spacar.read(EXAMPLE), method="radau", progress=False)


def test_cli_and_sweep_accept_radau5(capsys):
    from spacar.cli import main

    assert main(["run", str(EXAMPLE), "--method", "radau5", "--no-progress"]) == 0
    assert "block 1" in capsys.readouterr().out
    out = spacar.sweep(spacar.read(EXAMPLE), {"EPSINT": [1e-3, 1e-4]}, method="radau5",
                       outputs={"jacobians": lambda res: res.stats["jacobians"]}, workers=1, progress=False)
    assert not out.errors
    assert (out["jacobians"] > 0).all()


def incline_wheel(eps):
    """A wheel (PLWHEEL 2, spin DYNX 5) rolling down an incline, its centre held by PLBEAR 1 from
    the ground whose e1, e2 are the kinematic coordinates of the slips (ENHC), heading fixed."""
    m = spacar.Model()
    m.plbear(1, 1, 2, 3, 4)
    m.plwheel(2, 3, 4, 5, 0.4, 0.0, 1.0)
    m.xy(3, 0.0, 0.0)
    m.fix(1)
    m.fix(2)
    m.e(1, 3, 0.3)
    m.enhc(2, 1, 1, 1)
    m.enhc(2, 2, 1, 2)
    m.dynx(5)
    m.mass(3, 2.0)
    m.mass(5, 0.11)
    m.gravity(3.0, -1.0)
    m.timestep(10, 2.0)
    m.forcemode(1)  # complete stresses (the contact forces of the wheel) at the output times
    for set_eps in (m.epsint, m.epsind):
        set_eps(eps)
    m.epskin(1e-12)
    return m


def test_nonholonomic_wheel_agrees_with_dop853():
    # ENHC: the kinematic coordinates of the slips are states; their rows and columns of the
    # Jacobian come from Kk, AK0 and BK0.
    ref = spacar.simulate(incline_wheel(1e-10), progress=False)
    res = spacar.simulate(incline_wheel(1e-8), method="radau5", progress=False)
    assert np.abs(res.x - ref.x).max() < 1e-9
    assert np.abs(res.e - ref.e).max() < 1e-9
    assert np.abs(ref.sigma).max() > 0
    assert np.abs(res.sigma - ref.sigma).max() < 1e-8 * np.abs(ref.sigma).max()


def free_body(period, n_out):
    """A rigid body on LAMBDA node 1 (full inertia tensor, body-fixed torque), tumbling: every
    Euler parameter changes sign, so the dependent one is re-partitioned during the run."""
    lam0 = np.array([0.6, -0.2, 0.5, 0.4]) / np.linalg.norm([0.6, -0.2, 0.5, 0.4])
    w0 = np.array([0.5, -1.0, 2.0])
    m = spacar.Model()
    m.lambda_(1, *lam0)
    m.mass(1, 2.0, 0.1, -0.2, 3.0, 0.3, 4.0)
    m.dynx(1)
    m.torquel(1, 0.3, -0.2, 0.5)
    for i, v in enumerate(0.5 * G_(lam0).T @ w0):
        m.xd(1, i + 1, v)
    m.timestep(n_out, period)
    return tighten(m)


def test_free_rotation_with_repartitions_agrees_with_dop853():
    # Every re-partition ends a segment and starts a new Radau integration.
    ref = spacar.simulate(free_body(10.0, 50), progress=False)
    res = spacar.simulate(free_body(10.0, 50), method="radau5", progress=False)
    signs = np.sign(res.node(1).x)
    assert all(np.count_nonzero(np.diff(signs[:, i])) >= 2 for i in range(4))
    assert np.abs(res.x - ref.x).max() < 1e-7

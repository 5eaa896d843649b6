"""The implicit Radau IIA integrator in the analysis (simulate(method="radau5")): the same motion
as DOP853 on flexible and rigid mechanisms, with step counts that do not grow with the stiffness
and a small fraction of the work on stiffly damped structures."""

from pathlib import Path

import numpy as np
import pytest

import spacar
from spacar.compare import models

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
    ref = spacar.simulate(steel_cantilever(**short), progress=False)
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

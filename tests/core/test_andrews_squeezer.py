"""Andrews' squeezing mechanism (Hairer–Wanner's seven-body mechanism, the Test Set for IVP
Solvers' problem "andrews"), built in spacar from rigid PLBEAMs, PLHINGEs and a PLTRUSS spring
(tests/support/andrews_squeezer.py), against

* an independent reference: the test set's own equations of motion in its seven angles (index-3
  DAE with six constraints) in index-1 form, integrated by SciPy's DOP853 at rtol 1e-12;
* the test set's published angles at t = 0.03.
"""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from support import andrews_squeezer as sq
from support.paths import ROOT

N_OUT = 6


@pytest.fixture(scope="module")
def reference():
    t = np.linspace(0.0, sq.T_END, N_OUT + 1)
    y, drift = sq.reference_solution(t)
    assert drift < 1e-12           # the index-1 form kept the positions on the constraints
    return y


def test_reference_matches_published_values(reference):
    # The published values (PSIDE at 1e-14) and this reference agree to 1.4e-9 rad on β ≈ 15.8
    # rad, i.e. 1e-10 relative; the reference does not move at rtol 1e-13.
    np.testing.assert_allclose(reference[-1, :7], sq.Q_END_PUBLISHED, rtol=0, atol=1e-8)


def test_spring_is_the_test_sets_spring():
    m = sq.squeezer_model()
    spring = m.elements[sq.SPRING]
    assert spring.l0 == pytest.approx(sq.L0)       # natural length l0 = 0.07785 m
    # Initial elongation, and stiffness c0 = EA / l0 = 4530 N/m.
    pts = sq.points(sq.Q0)
    stretch = np.linalg.norm(pts["D"] - pts["C"]) - sq.L0
    res = spacar.simulate(sq.squeezer_model(n_out=1), method="dop853")
    assert res.deformation(sq.SPRING, 1)[0] == pytest.approx(stretch, abs=1e-12)
    assert res.stress(sq.SPRING, 1)[0] == pytest.approx(sq.C0 * stretch, rel=1e-10)


@pytest.mark.parametrize("method", ["dop853", "radau5", "auto"])
def test_angles_against_reference_and_published(method, reference):
    res = spacar.simulate(sq.squeezer_model(eps=1e-10, n_out=N_OUT), method=method)
    q, qd = sq.angles(res), sq.rates(res)
    # Largest errors measured: dop853 7.8e-10 rad, radau5 1.4e-9 rad at t = 0.03 (β ≈ 15.8 rad,
    # |β̇| ≈ 1140 rad/s).
    np.testing.assert_allclose(q, reference[:, :7], rtol=0, atol=1e-8)
    np.testing.assert_allclose(qd, reference[:, 7:], rtol=0, atol=2e-5)
    np.testing.assert_allclose(q[-1], sq.Q_END_PUBLISHED, rtol=0, atol=1e-8)
    # The released hinges measure the relative angles Θ, Φ, Ω directly.
    for elem, k in ((sq.HINGE_THETA, 1), (sq.HINGE_PHI, 3), (sq.HINGE_OMEGA, 5)):
        np.testing.assert_allclose(res.deformation(elem, 1), q[:, k] - sq.Q0[k], atol=1e-12)
    if method == "auto":
        # Not stiff (the test set classes it as non-stiff): auto stays on DOP853.
        assert res.stats["method"] == "dop853"


def test_tight_dop853_to_the_reference(reference):
    res = spacar.simulate(sq.squeezer_model(eps=1e-12, n_out=N_OUT), method="dop853")
    # Measured 4.6e-12 rad: the two formulations agree to the reference's own accuracy.
    np.testing.assert_allclose(sq.angles(res), reference[:, :7], rtol=0, atol=1e-10)


def test_example_file_is_the_model(reference):
    # examples/andrews_squeezer.dat: the dump of squeezer_model(eps=1e-10, n_out=30).
    res = spacar.simulate(spacar.read(ROOT / "examples" / "andrews_squeezer.dat"), method="dop853")
    assert res.t[-1] == pytest.approx(sq.T_END) and len(res.t) == 31
    np.testing.assert_allclose(sq.angles(res)[::5], reference[:, :7], rtol=0, atol=1e-8)


def test_every_start_of_newton_reaches_the_reference_and_the_predictor_saves_iterations(reference):
    """The start and the matrix of Newton's iterations on the positions (RunOptions of
    benchmarks/newton.py) change the work, not the motion: the second-order Taylor predictor
    with the chord (the default; 46 calculable coordinates, so the chord is used), the last
    positions as they are, and a fresh factorization in every iteration all reach the reference."""
    from spacar import _core

    runs = {}
    for order, chord in ((2, True), (0, True), (2, False)):
        model = sq.squeezer_model(eps=1e-10, n_out=N_OUT)
        sim = _core.Simulation(model.core)
        arrays = sim.run(recursive=False, predictor_order=order, chord=chord)
        runs[order, chord] = arrays["newton_iterations"] / arrays["rhs_evaluations"]
        labels = [tuple(lbl) for lbl in sim.system.coord_label]
        res = spacar.Results(arrays, labels, sim.system.def_label, {})
        np.testing.assert_allclose(sq.angles(res), reference[:, :7], rtol=0, atol=1e-8)
    # Measured: 4.08 iterations per right-hand side by default, 5.08 from the last positions,
    # 2.50 with a fresh factorization (full Newton: quadratic, but a factorization each).
    assert runs[2, True] < 0.9 * runs[0, True]
    assert runs[2, False] < runs[2, True]
    with pytest.raises(spacar.InputError, match="predictor's order"):
        _core.Simulation(sq.squeezer_model().core).run(predictor_order=3)

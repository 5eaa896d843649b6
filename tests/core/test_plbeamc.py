"""PLBEAMC (issue 39, extension): the planar beam exact for constant curvature. Its bending
deformations are the end rotations' angles from the chord and its elongation is measured along
the arc, so a tip moment M L / EI = 2π rolls a cantilever of any mesh into the closed circle
(PLBEAM needs 100 elements for 1e-3 L, tests/core/test_statics.py), and Euler's elastica
converges as h⁴ instead of h²: against the shooting solution of tests/core/test_statics.py it is
over a thousand times more accurate than PLBEAM at 16 elements. At the straight reference it is
PLBEAM to first order: the same K0 and M0, the same eigenfrequencies (Euler–Bernoulli's
cantilever, 1.875² √(EI/ρAL⁴)/2π, as the mesh is refined)."""
from __future__ import annotations

import numpy as np
import pytest

import spacar

from test_statics import elastica_tip


def cantilever(n, kind="plbeamc", moment=0.0, force=(0.0, 0.0), mass=0.0):
    """n beams along x from the clamped nodes 1, 2 (L = EI = 1, axially rigid, bending DYNE)."""
    m = spacar.Model()
    for k in range(1, n + 1):
        getattr(m, kind)(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2)
        m.x(2 * k + 1, k / n, 0.0)
        m.estiff(k, 0.0, 1.0)
        m.dyne(k, 2, 3)
        if mass:
            m.emass(k, mass)
    m.fix(1)
    m.fix(2)
    if moment:
        m.force(2 * n + 2, moment)
    if any(force):
        m.force(2 * n + 1, *force)
    return m


@pytest.mark.parametrize("n", [2, 4, 7])
def test_tip_moment_closes_the_circle_with_any_mesh(n):
    res = spacar.static(cantilever(n, moment=2 * np.pi), steps=8)
    x, y, beta = res.x[-1, -3:]
    assert np.hypot(x, y) < 1e-12 and beta == pytest.approx(2 * np.pi, abs=1e-12)
    xy = res.x[-1].reshape(-1, 3)[:, :2]                      # every node on the circle
    assert np.hypot(xy[:, 0], xy[:, 1] - 1 / (2 * np.pi)) == pytest.approx(1 / (2 * np.pi), abs=1e-12)


def test_elastica_converges_as_h4():
    ref = elastica_tip(3.0)
    error = {}
    for kind in ("plbeam", "plbeamc"):
        for n in (8, 16):
            res = spacar.static(cantilever(n, kind, force=(0.0, 3.0)), steps=4)
            error[kind, n] = np.abs(res.x[-1, -3:-1] - ref).max()
    assert error["plbeamc", 8] < 5e-6 and error["plbeamc", 16] < 3e-7
    assert 12 < error["plbeamc", 8] / error["plbeamc", 16] < 20          # h⁴ (PLBEAM: h²)
    assert error["plbeam", 16] > 1000 * error["plbeamc", 16]


def test_at_rest_it_is_plbeam():
    lin_c = spacar.linearize(cantilever(16, "plbeamc", mass=1.0))
    lin = spacar.linearize(cantilever(16, "plbeam", mass=1.0))
    assert lin_c.K0 == pytest.approx(lin.K0, rel=1e-12, abs=1e-9)
    assert lin_c.M0 == pytest.approx(lin.M0, rel=1e-12, abs=1e-15)
    f = lin_c.eigenfrequencies(2)
    assert f == pytest.approx(lin.eigenfrequencies(2), rel=1e-10)
    assert f[0] == pytest.approx(1.8751040687**2 / (2 * np.pi), rel=1e-5)   # Euler–Bernoulli


def test_a_swinging_flexible_pendulum_conserves_energy():
    """The dynamics path (the jets' derivatives, the Hermite mass): a cantilever released under
    gravity swings with its energy kept to the integrator's tolerance."""
    m = cantilever(6, mass=1.0)
    m.gravity(0.0, -9.81)
    m.timestep(20, 0.2)
    m.epsint(1e-8)
    res = spacar.simulate(m, energy=True)
    e = res.energy
    assert np.abs(e.balance).max() < 1e-6 * np.abs(e["potential"]).max()
    assert np.ptp(e["strain"]) > 1e-3 * np.abs(e["potential"]).max()   # it bends as it swings

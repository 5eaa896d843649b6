"""BEAMC (issue 39, extension): the spatial beam exact for constant curvature and twist. Its
bending and torsion are the angles of the relative rotation of its end sections (their log map)
and its chord's departure from the helix they define, its elongation is measured along that
helix, so that

* a tip moment M L / EI = 2π rolls a cantilever of 3 elements into the closed circle (each
  element turns by less than π: the relative rotation of its sections has an axis);
* a dead tip moment M in any direction on a section with GJ = EIy = EIz bends it into the helix
  R(s) = exp(s M̂/EI), r(L) = L F(L M/EI) e_x, F(φ) = ∫₀¹ exp(u φ̂) du — exact with 2, 3 or 5
  elements, where BEAM needs 128 for 1e-4 L;
* Bathe and Bolourchi's 45° bend converges several times faster than with BEAM;
* in the plane it is PLBEAMC (tests/elements/test_elements_spatial.py, the planar reduction).

The models use SPACAR's deformation degrees of freedom (DYNE, as SPACAR Light writes them)."""
from __future__ import annotations

import numpy as np
import pytest

import spacar

from support.spatial_models import bathe_bend


def cantilever(n, kind="beamc", EI=1.0, GJ=1.0, EA=1e6):
    """n beams along x (L = 1) from the clamped nodes 1, 2; all deformations DYNE."""
    m = spacar.Model()
    for k in range(n):
        getattr(m, kind)(k + 1, 2 * k + 1, 2 * k + 2, 2 * k + 3, 2 * k + 4, 0, 1, 0)
        m.dyne(k + 1)
        m.estiff(k + 1, EA, GJ, EI, EI)
    for k in range(n + 1):
        m.x(2 * k + 1, k / n, 0, 0)
    m.fix(1)
    m.fix(2)
    return m


def hat(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def exp_map(v):
    a = np.linalg.norm(v)
    return np.eye(3) + np.sin(a) / a * hat(v) + (1 - np.cos(a)) / a**2 * hat(v) @ hat(v)


def rotation(lam):
    return spacar.geometry.rotation(lam)


@pytest.mark.parametrize("n", [3, 4])
def test_tip_moment_closes_the_circle(n):
    m = cantilever(n)
    m.torqueg(2 * n + 2, 0.0, 0.0, 2 * np.pi)
    res = spacar.static(m, steps=8)
    assert np.abs(res.node(2 * n + 1).x[-1]).max() < 1e-11
    assert rotation(res.node(2 * n + 2).x[-1]) == pytest.approx(np.eye(3), abs=1e-10)


@pytest.mark.parametrize("n", [2, 3, 5])
def test_a_skew_moment_makes_the_exact_helix(n):
    M = np.array([1.0, 2.0, 2.0])                        # |M| L / EI = 3: the tip turns by 172°
    a = np.linalg.norm(M)
    F = np.eye(3) + (1 - np.cos(a)) / a**2 * hat(M) + (a - np.sin(a)) / a**3 * hat(M) @ hat(M)
    m = cantilever(n)
    m.torqueg(2 * n + 2, *M)
    res = spacar.static(m, steps=6)
    assert res.node(2 * n + 1).x[-1] == pytest.approx(F @ [1.0, 0.0, 0.0], abs=1e-11)
    assert rotation(res.node(2 * n + 2).x[-1]) == pytest.approx(exp_map(M), abs=1e-11)
    for k in range(1, n):                                # every node on the helix, turned as it
        s = k / n
        assert res.node(2 * k + 1).x[-1] == pytest.approx(
            s * (np.eye(3) + (1 - np.cos(s * a)) / (s * a) ** 2 * hat(s * M)
                 + (s * a - np.sin(s * a)) / (s * a) ** 3 * hat(s * M) @ hat(s * M)) @ [1.0, 0.0, 0.0], abs=1e-11)
    if n == 2:
        with pytest.raises(spacar.StaticError):          # BEAM cannot bend an element past 90°
            b = cantilever(2, "beam")
            b.torqueg(6, *M)
            spacar.static(b, steps=6)
        b = cantilever(32, "beam")
        b.torqueg(66, *M)
        assert np.abs(spacar.static(b, steps=6).node(65).x[-1] - F @ [1.0, 0.0, 0.0]).max() > 1e-3


def bend(n, kind):
    """The tip of Bathe and Bolourchi's 45° bend (tests/support/spatial_models.py)."""
    return spacar.static(bathe_bend(n, kind), steps=1).node(n + 1).x[-1]


def test_a_left_handed_frame_is_refused():
    m = cantilever(1)
    m.lgeomy(1, 1, 0, 0, 0, 0, 1, 0, 1, 0)
    m.torqueg(4, 0, 0, 1.0)
    with pytest.raises(spacar.InputError, match="right-handed orthonormal frame"):
        spacar.static(m)


def test_the_45_degree_bend_converges_faster():
    limit = bend(256, "beamc")
    assert limit == pytest.approx(bend(256, "beam"), abs=2e-3)          # one limit
    assert limit == pytest.approx([47.2, 15.8, 53.4], abs=0.35)          # published (Simo and Vu-Quoc)
    error = {kind: np.abs(bend(16, kind) - limit).max() for kind in ("beam", "beamc")}
    assert error["beamc"] < 0.02 and error["beam"] > 3 * error["beamc"]

"""Automatic release of over-constraints (issue 19: `model.release_overconstraints()`,
`spacar check --release`): the redundant rigid deformations that the constraint diagnosis
names are released, the function says which, and the model then runs — with the motion of the
closed-form mechanism (welded four-bar, parallelogram with a redundant crank) or the static
equilibrium of the released structure.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import spacar
from spacar.cli import main

# A four-bar whose rocker (element 3) shares the coupler's end rotation node 7: welded instead
# of pinned, 9 rigid deformations for 8 calculable coordinates (as in test_check.py).
WELDED_FOURBAR = """\
PLBEAM 1 1 2 3 4
PLBEAM 2 3 5 6 7
PLBEAM 3 8 9 6 7
X 3 0.0 1.0
X 6 2.0 1.2
X 8 2.0 0.0
FIX 1
FIX 8
INPUTX 2 1
XD 2 1 1.0
EPSKIN 1e-12
TIMESTEP 4 1.0
END
"""


def fourbar_rocker_pin(theta):
    """The coupler–rocker pin of the pinned four-bar (ground pivots (0, 0), (2, 0), crank 1,
    coupler |(2, 0.2)|, rocker 1.2) at crank angle θ, by circle intersection."""
    A = np.array([-math.sin(theta), math.cos(theta)])
    B0 = np.array([2.0, 0.0])
    coupler, rocker = math.hypot(2.0, 0.2), 1.2
    d = B0 - A
    dist = np.linalg.norm(d)
    a = (coupler**2 - rocker**2 + dist**2) / (2 * dist)
    h = math.sqrt(coupler**2 - a**2)
    return A + a * d / dist + h * np.array([-d[1], d[0]]) / dist


def test_welded_fourbar_released_runs_as_the_pinned_one():
    model = spacar.read_string(WELDED_FOURBAR)
    with pytest.raises(spacar.KinematicsError):
        model.copy().run()
    released = model.release_overconstraints()
    assert released == [(3, 3)]
    assert model.elements[3].cls[2].name == "released"
    assert model.check().diagnosis.ok
    res = model.run()
    for k, t in enumerate(res.t):
        np.testing.assert_allclose(res.node(6).x[k], fourbar_rocker_pin(t), atol=1e-10)
    assert model.release_overconstraints() == []  # nothing left to release


def hanging_parallel_guide(P, W):
    """Three rigid legs of length 1 hanging from the pivots (0, 0), (0.5, 0), (1, 0), pinned to a
    rigid platform of two PLBEAMs welded at its middle node 7: a parallelogram with a redundant
    middle leg (15 rigid deformations for 14 coordinates). The first leg's angle is the degree of
    freedom; the platform carries a horizontal load P and a weight W."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)       # leg (0, 0)-(0, -1)
    m.plbeam(2, 5, 6, 7, 8)       # leg (0.5, 0)-(0.5, -1)
    m.plbeam(3, 9, 10, 11, 12)    # leg (1, 0)-(1, -1)
    m.plbeam(4, 3, 13, 7, 14)     # platform (0, -1)-(0.5, -1)
    m.plbeam(5, 7, 14, 11, 15)    # platform (0.5, -1)-(1, -1), welded to element 4 at node 14
    for node, xy in ((3, (0, -1)), (5, (0.5, 0)), (7, (0.5, -1)), (9, (1, 0)), (11, (1, -1))):
        m.x(node, *xy)
    m.fix(1)
    m.fix(5)
    m.fix(9)
    m.dynx(2, 1)
    m.force(7, P, -W)
    return m


def test_parallel_guide_released_finds_its_static_equilibrium():
    """After the release the guide swings like a pendulum: the platform translates on the circle
    of the legs to the angle φ with tan φ = P/W."""
    P, W = 0.6, 1.0
    m = hanging_parallel_guide(P, W)
    d = m.check().diagnosis
    assert len(d.redundant) == 1
    with pytest.raises(spacar.KinematicsError):
        spacar.static(m.copy(), steps=2)
    released = m.release_overconstraints()
    assert released == d.redundant
    assert m.check().diagnosis.ok
    res = spacar.static(m, steps=4)
    phi = math.atan2(P, W)
    np.testing.assert_allclose(res.node(7).x[-1], [0.5 + math.sin(phi), -math.cos(phi)], atol=1e-9)
    np.testing.assert_allclose(res.node(3).x[-1], [math.sin(phi), -math.cos(phi)], atol=1e-9)


def test_cli_check_release(tmp_path, capsys):
    path = tmp_path / "welded.dat"
    path.write_text(WELDED_FOURBAR)
    assert main(["check", str(path), "--release"]) == 0
    out = capsys.readouterr().out
    assert all(line.startswith("*") for line in out.splitlines())
    assert "* released 1 redundant constraint:" in out
    assert "* RLSE 3 3   (element 3 (PLBEAM) deformation 3)" in out
    assert "the constraints determine the calculable coordinates" in out


def test_nothing_to_release_says_so(tmp_path, capsys):
    path = tmp_path / "pinned.dat"
    path.write_text(WELDED_FOURBAR.replace("PLBEAM 3 8 9 6 7", "PLBEAM 3 8 9 6 10"))
    assert main(["check", str(path), "--release"]) == 0
    assert "* released 0 redundant constraints (none is over-constrained)" in capsys.readouterr().out


def test_a_redundant_input_is_not_released():
    """Two actuators (INPUTE) between the same nodes: the redundancy is among the prescribed
    deformations, which RLSE cannot fix; InputError names it and the model is not changed."""
    m = spacar.Model()
    m.pltruss(1, 1, 3)
    m.pltruss(2, 1, 3)
    m.pltruss(3, 2, 3)
    m.x(1, 0.0, 0.0)
    m.x(2, 1.0, 0.0)
    m.x(3, 0.5, 0.5)
    m.fix(1)
    m.fix(2)
    m.inpute(1, 1)
    m.inpute(2, 1)
    assert m.check().diagnosis.redundant == [(2, 1)]
    with pytest.raises(spacar.InputError, match=r"element 2 deformation 1 \(input, not fixed\)"):
        m.release_overconstraints()
    assert [c.name for c in m.elements[3].cls] == ["fixed"]

"""TORQUEG (extension): a constant torque in global axes on a LAMBDA node, a dead load, beside the
manual's body-fixed TORQUEL (a follower). Checked on a cantilever twisted and bent far out of its
reference by a torque about a skew axis: the clamp's reaction moment is −T exactly for TORQUEG and
−R(λ_tip) T′ for TORQUEL (equilibrium of the whole beam, no forces); the tangent under the large
torque (the load stiffness −∂(2 Eᵀ T)/∂λ) gives the compliance that finite differences of
equilibria give; the reader and writer carry the keyword."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar.io.reader import apply_block

N = 8
TIP = 2 * N + 2  # the tip's LAMBDA node
T = np.array([0.3, -0.5, 0.8])


def cantilever(kind: str, torque=T) -> spacar.Model:
    m = spacar.Model()
    for k in range(N):
        m.beam(k + 1, 2 * k + 1, 2 * k + 2, 2 * k + 3, 2 * k + 4, 0, 1, 0)
    for k in range(N + 1):
        m.x(2 * k + 1, k / N, 0, 0)
    m.fix(1)
    m.fix(2)
    for k in range(N):
        m.rlse(k + 1)
        m.estiff(k + 1, 1e4, 1.0, 1.2, 1.5)
        m.dynx(2 * k + 3)
        m.dynx(2 * k + 4)
    getattr(m, kind)(TIP, *torque)
    return m


def rotation(q) -> np.ndarray:
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def test_clamp_balances_a_global_torque_and_a_body_fixed_one():
    res = spacar.static(cantilever("torqueg"), steps=4)
    tip = res.node(TIP).x[-1]
    assert 2 * np.arccos(tip[0]) > 0.7                                  # far from the reference
    assert res.reaction_moment(2)[-1] == pytest.approx(-T, abs=1e-9)
    assert max(res.stats["iterations"]) <= 6                            # the exact tangent
    res = spacar.static(cantilever("torquel"), steps=4)
    R = rotation(res.node(TIP).x[-1])
    assert res.reaction_moment(2)[-1] == pytest.approx(-R @ T, abs=1e-9)
    assert not np.allclose(R @ T, T, atol=1e-2)                          # the two loads differ here


def test_tangent_under_a_global_torque_is_the_difference_of_equilibria():
    m = cantilever("torqueg")
    spacar.static(m, steps=4)
    C = spacar.compliance(m, 2 * N + 1, rotation=TIP)                   # rotations per global moment
    h = 1e-6
    columns = []
    for i in range(3):
        ends = []
        for s in (1, -1):
            mi = cantilever("torqueg", T + s * h * np.eye(3)[i])
            ends.append(spacar.static(mi, steps=4).node(TIP).x[-1])
        # the small rotation vector between the two equilibria, in global axes: 2 E(λ) δλ
        l = 0.5 * (ends[0] + ends[1])
        E = np.array([[-l[1], l[0], -l[3], l[2]], [-l[2], l[3], l[0], -l[1]], [-l[3], -l[2], l[1], l[0]]])
        columns.append(2 * E @ (ends[0] - ends[1]) / (2 * h))
    assert np.column_stack(columns) == pytest.approx(C[3:, 3:], rel=1e-5, abs=1e-7)


def test_reader_and_writer_carry_torqueg():
    text = "\n".join(["BEAM 1 1 2 3 4 0 1 0", "X 1 0 0 0", "X 3 1 0 0", "FIX 1", "FIX 2", "RLSE 1", "DYNX 3", "DYNX 4",
                      "END", "ESTIFF 1 1e4 1 1.2 1.5", "TORQUEG 4 0.1 0.2", "END", "END"])
    m = spacar.read_string(text)
    apply_block(m, m.blocks[1])                                          # the properties' block
    assert list(m.nodes[4].torqueg) == [0.1, 0.2, 0.0]
    assert "TORQUEG    4" in m.dump()
    bad = spacar.read_string(text.replace("TORQUEG 4", "TORQUEG 3"))
    with pytest.raises(spacar.InputError, match="line 11, keyword TORQUEG: TORQUEG applies to LAMBDA nodes; node 3 is XYZ"):
        apply_block(bad, bad.blocks[1])

"""spacar.state_space against exudyn's ComputeLinearizedSystem (issue 22) on the same models,
built by spacar.compare.exudyn: exudyn's M, K, D projected into the null space N of its
constraints (q = Nᵀ y) give the transfer function c Nᵀ (K − ω²M + iωD)⁻¹ N b, with b and c
unit vectors on exudyn's coordinates of the input and output. The converter does not carry
INPUTF/OUTX itself: the tests pick the exudyn coordinates that are the same physical
quantities (the rotation of a rigid body, the y of an ANCF node).

* a four-bar with a torsional spring-damper at the crank (rigid links): crank torque → crank
  angle, rocker angle and rocker rate, equal to rounding;
* a flexible cantilever (PLBEAMs ↔ ANCF cables, the same cubic Hermite bending): tip force →
  tip deflection to 1e-10;
* a four-bar with a flexible coupler (four PLBEAMs with axial stiffness EA ↔ ANCF cables):
  agreement to 1e-5 at EA = 1e7; the difference falls as 1/EA, because the two element
  formulations differ only in their axial interpolation (ANCF has a slope-stretch coordinate).
"""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar.compare import models

exu = pytest.importorskip("exudyn")

from spacar.compare import exudyn as sp_exudyn  # noqa: E402

FREQS = np.array([0.01, 0.1, 0.135, 0.3, 2.0, 10.0])  # Hz


def exudyn_response(model, inputs, outputs, rates=(), freqs=FREQS):
    """exudyn's frequency response (len(freqs), outputs + rates, inputs); ``inputs``/``outputs``/
    ``rates``: (exudyn node, coordinate) pairs."""
    ex = sp_exudyn.build(model)
    M, K, D, _, N = ex.mbs.ComputeLinearizedSystem(exu.SimulationSettings(), projectIntoConstraintNullspace=True,
                                                   returnConstraintJacobian=True, returnConstraintNullspace=True)
    Nt = np.asarray(N).T

    def row(pair):
        v = np.zeros(Nt.shape[0])
        v[ex.mbs.GetNodeODE2Index(pair[0](ex)) + pair[1]] = 1.0
        return v @ Nt

    B = np.column_stack([row(p) for p in inputs])
    C = np.vstack([row(p) for p in outputs + rates])
    out = []
    for w in 2 * np.pi * freqs:
        scale = np.r_[np.ones(len(outputs)), np.full(len(rates), 1j * w)]
        out.append(scale[:, None] * (C @ np.linalg.solve(K - w**2 * M + 1j * w * D, B)))
    return np.array(out)


def body_of(beta_node):
    """The exudyn node of the rigid body carrying spacar's BETA node."""
    def node(ex):
        (b,) = [b.index for b in ex.topology.bodies[1:] if beta_node in b.orientation_nodes]
        return ex._bodies[b][0]
    return node


def ancf_of(position_node):
    return lambda ex: ex._ancf[position_node][0]


def crank_spring(m):
    """A torsional spring-damper between the ground (fixed BETA node 10) and the crank (11),
    (the crank rotation is the DOF, the hinge released); crank torque in, crank and rocker angles and the rocker rate out."""
    m.plhinge(4, 10, 11)
    m.fix(10)
    m.rlse(4)
    m.estiff(4, 3.0)
    m.edampp(4, 0.2)
    m.inputf(1, 11, 1)
    m.outx(1, 11, 1)
    m.outx(2, 32, 1)
    m.outxp(3, 32, 1)
    return m


def rigid_four_bar():
    m = models.four_bar(crank_speed=0.0)
    m.gravity(0.0, 0.0)
    return crank_spring(m)


def flexible_four_bar(EA, n=4, EI=2.0):
    """models.four_bar with its coupler (node 2 → node 3) made of n PLBEAMs, all deformations
    elastic (EA, EI)."""
    m = spacar.Model()
    m.plbeam(1, 1, 11, 2, 12)
    nodes = [2] + [100 + k for k in range(1, n)] + [3]
    for k in range(n):
        m.plbeam(10 + k, nodes[k], 200 + k, nodes[k + 1], 201 + k)
        m.emass(10 + k, 1.5)
        m.estiff(10 + k, EA, EI)
        m.dyne(10 + k)
    for k in range(1, n):
        m.x(nodes[k], 2.0 * k / n, 1.0 + 0.5 * k / n)
    m.plbeam(3, 4, 31, 3, 32)
    m.x(2, 0.0, 1.0)
    m.x(3, 2.0, 1.5)
    m.x(4, 2.5, 0.0)
    m.fix(1)
    m.fix(4)
    m.emass(1, 1.0)
    m.emass(3, 1.2)
    m.mass(3, 0.3)
    m.dynx(11, 1)
    return crank_spring(m)


def four_bar_responses(m):
    spacar_h = spacar.state_space(m).frequency_response(FREQS)
    exudyn_h = exudyn_response(m, [(body_of(11), 2)], [(body_of(11), 2), (body_of(32), 2)], [(body_of(32), 2)])
    return spacar_h, exudyn_h


def test_rigid_four_bar_with_a_crank_spring():
    spacar_h, exudyn_h = four_bar_responses(rigid_four_bar())
    np.testing.assert_allclose(spacar_h, exudyn_h, rtol=1e-12, atol=0)


def test_flexible_cantilever():
    n = 6
    m = models.cantilever(n)
    m.gravity(0.0, 0.0)
    tip = n + 1
    m.inputf(1, tip, 2)
    m.outx(1, tip, 2)
    m.outxp(2, tip, 2)
    freqs = np.array([0.01, 0.3, 1.0, 5.0, 20.0, 100.0])
    spacar_h = spacar.state_space(m).frequency_response(freqs)
    exudyn_h = exudyn_response(m, [(ancf_of(tip), 1)], [(ancf_of(tip), 1)], [(ancf_of(tip), 1)], freqs)
    np.testing.assert_allclose(spacar_h, exudyn_h, rtol=1e-10, atol=0)


def test_flexible_four_bar():
    errors = []
    for EA in (1e5, 1e7):
        spacar_h, exudyn_h = four_bar_responses(flexible_four_bar(EA))
        errors.append(np.abs(spacar_h / exudyn_h - 1).max())
    # measured: 9.6e-4 and 9.2e-6, dominated by the 10 Hz point (near the coupler's modes)
    assert errors[1] < 2e-5
    assert 50 < errors[0] / errors[1] < 200

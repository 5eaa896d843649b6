"""The integration path solves the equations of motion of the free coordinates with the
constraint rows as one sparse system (no transfer functions); the reduced equations (3.1)
M̄ q̈ = −DF_qᵀ[M(DF_p p̈ + a) + h − f] − DFe_qᵀσ are solved independently with the transfer
functions. Both must give the same accelerations in planar, spatial, flexible, driven and
nonholonomic mechanisms, at random states."""
import numpy as np
import pytest

import spacar
from support.simulation import assembled

EXAMPLES = ["examples/slidercrank.dat", "examples/slidercrank3d.dat", "examples/bicycle.dat"]


def states(model, count, seed):
    """The model's assembled state and random perturbations of its DOF values and rates."""
    sim = assembled(model)
    q0, qd0 = np.array(sim.system.q0), np.array(sim.system.qd0)
    rng = np.random.default_rng(seed)
    out = [(0.0, q0, qd0)]
    for _ in range(count):
        out.append((rng.uniform(0, 1), q0 + 1e-3 * rng.standard_normal(q0.size),
                    qd0 + rng.standard_normal(q0.size)))
    return sim, out


@pytest.mark.parametrize("path", EXAMPLES)
def test_sparse_and_reduced_accelerations_agree(path):
    sim, cases = states(spacar.read(path), 5, 1)
    for t, q, qd in cases:
        sim.evaluate(t, q, qd)
        fast = np.array(sim.data.qdd)
        reduced = np.array(sim.reduced_accelerations())
        assert np.abs(fast - reduced).max() <= 1e-9 * max(1.0, np.abs(reduced).max())


def test_chain_with_gravity_agrees():
    """A 12-link pendulum chain of rigid PLBEAMs sharing their end rotations; the joint angles
    are the bending deformations at p of links 2..12 and the base rotation: large enough for
    the sparse factorization."""
    m = spacar.Model()
    n = 12
    for i in range(n):
        m.plbeam(i + 1, 2 * i + 1, 2 * i + 2, 2 * i + 3, 2 * i + 4)
        m.x(2 * i + 3, (i + 1) / n, 0.1 * np.sin(i))
        m.emass(i + 1, 1.0)
        if i > 0:
            m.dyne(i + 1, 2)
    m.fix(1)
    m.dynx(2, 1)
    m.gravity(0.0, -9.81)
    sim, cases = states(m, 3, 2)
    for t, q, qd in cases:
        sim.evaluate(t, q, qd)
        fast, reduced = np.array(sim.data.qdd), np.array(sim.reduced_accelerations())
        assert np.abs(fast - reduced).max() <= 1e-9 * max(1.0, np.abs(reduced).max())

"""Static equilibrium of a model, for the tests of reactions and of linearization at rest."""
from __future__ import annotations

import numpy as np

from support.simulation import assembled


def static_equilibrium(model, tol=1e-13):
    """The DOF values at rest in equilibrium: Newton on the reduced force R(q) = −M̄ q̈ (at
    q̇ = 0) with a central-difference Jacobian (R, unlike q̈, is well conditioned). Returns the
    simulation moved to that state and q."""
    sim = assembled(model.copy())
    nd = sim.system.n_dof
    q, zero = np.zeros(nd), np.zeros(nd)

    def force(q):
        sim.move_to(0.0, q, zero)
        return -np.array(sim.data.Mbar) @ np.array(sim.data.qdd)

    for _ in range(30):
        R = force(q)
        if np.abs(R).max() < tol:
            sim.move_to(0.0, q, zero)
            return sim, q
        J = np.column_stack([(force(q + dq) - force(q - dq)) / 2e-6 for dq in 1e-6 * np.eye(nd)])
        q = q - np.linalg.solve(J, R)
    raise AssertionError(f"no static equilibrium: |R| = {np.abs(R).max()}")

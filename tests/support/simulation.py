"""The core simulation of a model at its assembled state, as the tests that call the engine's
stages directly (evaluate, move_to, linearize) start from it."""
from __future__ import annotations

import re

import numpy as np

import spacar
from spacar import _core


def assembled(model):
    """A ``spacar._core.Simulation`` of ``model`` (prepared here, as the first END does) at the
    assembled initial state. The simulation works on the model itself: pass ``model.copy()`` to
    keep the model as it was."""
    model.prepare()
    sim = _core.Simulation(model.core)
    sim.assemble()
    return sim


def assert_start_rows_agree(model, seed=0):
    """The output row at the start of a run on the recursive path and on the general path of
    ``model`` (a tree), its DOFs set moving at random rates: the same state, whose recursive
    output row is solved from the tree's q̈ and the general one from the equations of motion;
    everything reported there agrees to 1e-10."""
    probe = spacar.simulate(model.copy(), method="dop853", progress=False)
    rng = np.random.default_rng(seed)
    for label in probe.dof_labels:
        kind, a, b = re.match(r"([xe])\((\d+),(\d+)\)", label).groups()
        setter = model.xd if kind == "x" else model.ed
        setter(int(a), int(b), float(rng.uniform(-1.5, 1.5)))
    model.forcemode(1)
    model.timestep(1, 1e-3)
    fast = spacar.simulate(model.copy(), method="dop853", progress=False)
    general = spacar.simulate(model.copy(), method="dop853", recursive=False, progress=False)
    assert fast.stats["recursive"] and not general.stats["recursive"]
    assert np.abs(general.xd[0]).max() > 0.1  # moving
    for field in ("x", "xd", "xdd", "e", "ed", "edd", "sigma", "reaction"):
        a, b = getattr(fast, field)[0], getattr(general, field)[0]
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-10 * max(1.0, np.abs(b).max()), err_msg=field)

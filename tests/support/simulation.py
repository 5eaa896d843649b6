"""The core simulation of a model at its assembled state, as the tests that call the engine's
stages directly (evaluate, move_to, linearize) start from it."""
from __future__ import annotations

from spacar import _core


def assembled(model):
    """A ``spacar._core.Simulation`` of ``model`` (prepared here, as the first END does) at the
    assembled initial state. The simulation works on the model itself: pass ``model.copy()`` to
    keep the model as it was."""
    model.prepare()
    sim = _core.Simulation(model.core)
    sim.assemble()
    return sim

"""Running an analysis block from Python."""
from __future__ import annotations

from . import _core
from .linearize import Linearization
from .results import Results


def simulate(model, *, method: str = "dop853", on_output=None) -> Results:
    """Run the analysis of the model's current block, as SPACAR does at an END.

    The mechanism is assembled at the current time; with degrees of freedom the reduced
    equations of motion are integrated over the TIMESTEP period (in C++, with the EPSINT /
    EPSIND error control), otherwise the kinematic analysis runs at every output time. The state
    reached is stored in the model (see :meth:`spacar.Model.dump`).

    ``on_output(k, state)`` is called after output time k is recorded, with ``state`` a dict of
    NumPy arrays ``t, x, xd, xdd, e, ed, edd, sigma, reaction`` (progress, files written as the
    run proceeds). It runs at output times only, never inside the integration.
    Returns :class:`spacar.Results`.
    """
    model.prepare()
    sim = _core.Simulation(model._core)
    restart = model._core.settings.restart == 1
    step = 0.0 if restart else model._continue_step
    arrays = sim.run(on_output=on_output, initial_step=step, method=method)
    model._continue_step = arrays["last_step"]
    system = sim.system
    stats = {k: arrays[k] for k in ("rhs_evaluations", "steps", "accepted", "rejected",
                                    "newton_iterations", "wall_time")}
    model.warnings.extend(w for w in arrays["warnings"] if w not in model.warnings)
    res = Results(arrays, system.coord_label, system.def_label, stats)
    res.linearizations = [Linearization(d, system.coord_label, system.def_label) for d in arrays["linearizations"]]
    res.settings_linear = model.settings.linear
    return res

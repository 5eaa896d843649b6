"""Running an analysis block from Python."""
from __future__ import annotations

from . import _core
from ._util import seconds_or_none, show
from .errors import InputError, SpacarError
from .linearize import Linearization
from .results import Results


def _results(arrays: dict, system, settings_linear) -> Results:
    stats = {k: arrays[k] for k in ("rhs_evaluations", "steps", "accepted", "rejected",
                                    "newton_iterations", "wall_time")}
    res = Results(arrays, system.coord_label, system.def_label, stats)
    res.linearizations = [Linearization(d, system.coord_label, system.def_label) for d in arrays["linearizations"]]
    res.settings_linear = settings_linear
    return res


def simulate(model, *, method: str = "dop853", on_output=None, time_limit=None) -> Results:
    """Run the analysis of the model's current block, as SPACAR does at an END.

    The mechanism is assembled at the current time; with degrees of freedom the reduced
    equations of motion are integrated over the TIMESTEP period (in C++, with the EPSINT /
    EPSIND error control), otherwise the kinematic analysis runs at every output time. The state
    reached is stored in the model (see :meth:`spacar.Model.dump`).

    ``on_output(k, state)`` is called after output time k is recorded, with ``state`` a dict of
    NumPy arrays ``t, x, xd, xdd, e, ed, edd, sigma, reaction`` (progress, files written as the
    run proceeds). It runs at output times only, never inside the integration.

    ``time_limit``: wall-clock seconds the block may take (None: no limit); beyond it
    :class:`spacar.TimeLimitError`.

    Returns :class:`spacar.Results`. If the analysis fails midway, the :class:`spacar.SpacarError`
    raised carries the results up to the failure as ``err.results`` (a :class:`spacar.Results`
    with the output times recorded before the failure, possibly none); the model's state is
    then left as it was before the block.
    """
    limit = seconds_or_none(time_limit, "time_limit") or 0.0
    if on_output is not None and not callable(on_output):
        raise InputError(f"on_output must be a function on_output(k, state) or None, got {show(on_output)}")
    if not isinstance(method, str):
        raise InputError(f"method must be 'dop853' or 'dopri5', got {show(method)}")
    model.prepare()
    sim = _core.Simulation(model._core)
    restart = model._core.settings.restart == 1
    step = 0.0 if restart else model._continue_step
    try:
        arrays = sim.run(on_output=on_output, initial_step=step, method=method, time_limit=limit)
    except SpacarError as err:
        partial = getattr(err, "results", None)
        if isinstance(partial, dict):
            model.warnings.extend(w for w in partial["warnings"] if w not in model.warnings)
            err.results = _results(partial, sim.system, model.settings.linear)
        raise
    model._continue_step = arrays["last_step"]
    model.warnings.extend(w for w in arrays["warnings"] if w not in model.warnings)
    return _results(arrays, sim.system, model.settings.linear)

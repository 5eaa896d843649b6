"""Static equilibrium of a model's block (docs/statics.md)::

    res = spacar.static(model, steps=10)   # λ = 0.1, 0.2, ..., 1
    res.t                                   # the load factors of the rows
    res.node(21).x[-1]                      # tip position at the full load
    res.stats["indefinite_at"]              # None, or where the equilibrium became unstable

The solve runs in C++ (cpp/src/analyses/statics.cpp): full Newton on the reduced equations at rest with
the exact tangent stiffness K0 + G0, the load factor λ raised from 0 to 1 in equal steps, a step
halved when Newton fails in it; or, with ``arc_length=True``, the path followed in (q, λ) past
limit points::

    res = spacar.static(model, steps=20, arc_length=True)
    res.stats["limit_points"]               # load factors of the limit points passed
"""
from __future__ import annotations

import numbers
import threading
from functools import partial
from types import SimpleNamespace

import numpy as np

from . import _core
from ._util import seconds_or_none, show
from .errors import InputError, SpacarError, StaticError  # noqa: F401  (StaticError: spacar.statics.StaticError)
from .model import Model
from .results import KeptModel, Results, dof_labels


def _results(arrays: dict, model, *, end_model=None) -> Results:
    load = np.asarray(arrays["load"], dtype=float)
    x, e = arrays["x"], arrays["e"]
    rest_x, rest_e = np.zeros_like(x), np.zeros_like(e)
    table = {"t": load, "x": x, "xd": rest_x, "xdd": rest_x.copy(), "e": e, "ed": rest_e,
             "edd": rest_e.copy(), "sigma": arrays["sigma"], "reaction": arrays["reaction"]}
    indefinite = float(arrays["indefinite_at"])
    stats = {
        "analysis": "static",
        "load_reached": float(arrays["load_reached"]),
        "newton_iterations": int(arrays["newton_iterations"]),
        "iterations": list(arrays["iterations"]),
        "step_cuts": int(arrays["step_cuts"]),
        "kinematic_iterations": int(arrays["kinematic_iterations"]),
        "indefinite_at": None if np.isnan(indefinite) else indefinite,
        "limit_points": [float(v) for v in arrays["limit_points"]],
        "wall_time": float(arrays["wall_time"]),
    }
    res = Results(table, arrays["coord_label"], arrays["def_label"], stats)
    # A copy of the model at the end of the solve, made when first needed (a lazy copy: when the
    # model changes next, or when it is asked for): res.geometry is built from it when first
    # used, and spacar.compliance(res, node) takes the loads and elements from it (not pickled);
    # a StaticSolver's results share its model for the geometry instead, and `end_model` makes
    # compliance's copy with the solve's loads when first needed.
    if end_model is None:
        res._geometry_source = core = KeptModel(model)
        res._static_model = lambda: Model._of_core(core.core())
    else:
        res._geometry_source = core = model.core
        res._static_model = end_model
    res.shapes = getattr(model, "urdf_shapes", None)  # a URDF robot's link shapes, for spacar.view3d
    # The degrees of freedom of the system the solve compiled, labelled when first asked for.
    system = SimpleNamespace(coord_label=arrays["coord_label"], def_label=arrays["def_label"],
                             x_dyn=arrays["x_dyn"], e_dyn=arrays["e_dyn"])
    res._set_dofs(partial(dof_labels, system, core))
    return res


def _count(value, name: str, low: int, high: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not low <= value <= high:
        raise InputError(f"{name} must be an integer from {low} to {high}, got {show(value)}")
    return int(value)


def static(model, steps: int = 10, *, arc_length: bool = False, max_steps: int = 200,
           max_iterations: int = 30, max_cuts: int = 12, tolerance: float = 1e-10, time_limit=None) -> Results:
    """Static equilibrium of the model's current block: the configuration in which the degrees of
    freedom (DYNX, DYNE) are in equilibrium at rest under the block's loads (FORCE, TORQUEL,
    GRAVITY, and the prestress of deformations given with E), with the inputs (INPUTX, INPUTE)
    moved to their values at the end of the block (their XD, XDD over the TIMESTEP period).

    The path starts at the model's current state (the generalized forces R0 that hold it, zero
    from an unloaded stress-free assembly, are released as (1 − λ) R0), so that a block that
    continues from the equilibrium of the one before moves gradually from the old loads to the
    new ones. Loads and inputs are applied together in ``steps`` equal steps of λ; at each
    step Newton's method with the exact tangent stiffness (structural plus geometric, K0 + G0 of
    :func:`spacar.linearize`) solves the reduced equations. A step in which Newton fails (or in
    which the stiffness changes the sign of its determinant: a limit or bifurcation point) is
    halved, up to ``max_cuts`` times. ``tolerance``: the residual relative to the largest load
    balanced. No mass is needed.

    With ``arc_length=True`` the equilibrium path is followed in (q, λ) instead (Riks'
    normal-plane arc-length method): past limit points (snap-through), λ falling and rising
    again, until λ reaches 1. The first step raises λ by about 1/``steps``; later steps adapt
    to the Newton iterations (a failed step is halved, ``max_cuts`` times in a row at most);
    one row per step (``res.t`` = λ may decrease), the last row at λ = 1 exactly. Limit points
    passed are located (λ stationary along the path) and listed in
    ``res.stats["limit_points"]`` with a warning each. At most ``max_steps`` steps, then
    StaticError. Inputs that the block moves travel with λ, as the loads do (a drive that
    folds back, displacement control through a compliant spring, is followed past its folds).

    Returns :class:`spacar.Results` with one row per load step (``res.t`` holds λ; the last row
    is the full load): x, e, the complete stresses σ (reaction stresses included) and the
    reactions, rates and accelerations zero; ``res.stats`` has ``newton_iterations``,
    ``iterations`` (per row), ``step_cuts``, ``load_reached`` (the last converged load factor),
    ``kinematic_iterations``, ``wall_time``, ``limit_points`` (the load factors of the limit
    points passed; arc length only) and ``indefinite_at`` (the first load factor at which the
    tangent stiffness is indefinite, i.e. the equilibrium is unstable because a buckling load
    was passed; None if never, with a warning in ``model.warnings`` otherwise).
    The model's state is left at the equilibrium, at rest, at the block's start time.

    Raises :class:`spacar.StaticError` if no equilibrium is found (loads beyond a limit point,
    a degree of freedom without stiffness), with the converged steps as ``err.results``; the
    model is then not changed. ``time_limit``: wall-clock seconds the analysis may take, its
    set-up included (None: no limit); beyond it :class:`spacar.TimeLimitError`, also with the
    converged steps.
    """
    if not isinstance(model, Model):
        raise InputError(f"static: model must be a spacar.Model, got {show(model)}")
    options = _options(steps, arc_length, max_steps, max_iterations, max_cuts, tolerance, time_limit)
    # The core prepares the model (the first END) as a simulation does.
    return _solved(lambda: _core.solve_static(model.core, *options), model.warnings, partial(_results, model=model))


def _options(steps, arc_length, max_steps, max_iterations, max_cuts, tolerance, time_limit) -> tuple:
    """static's options checked, in the order of the core's arguments."""
    steps = _count(steps, "steps", 1, 10**7)
    max_iterations = _count(max_iterations, "max_iterations", 1, 1000)
    max_cuts = _count(max_cuts, "max_cuts", 0, 50)
    max_steps = _count(max_steps, "max_steps", 1, 10**6)
    if not isinstance(arc_length, bool):
        raise InputError(f"arc_length must be True or False, got {show(arc_length)}")
    if isinstance(tolerance, bool) or not isinstance(tolerance, numbers.Real) or not 0 < tolerance < 1:
        raise InputError(f"tolerance must be a number between 0 and 1, got {show(tolerance)}")
    limit = seconds_or_none(time_limit, "time_limit") or 0.0
    return steps, max_iterations, max_cuts, float(tolerance), arc_length, max_steps, limit


def _solved(solve, warnings: list, results) -> Results:
    """The results of ``solve()`` (the core's arrays), its warnings added to ``warnings``; a
    failure's converged steps as its ``results``."""
    try:
        arrays = solve()
    except SpacarError as err:
        partial_arrays = getattr(err, "results", None)
        if isinstance(partial_arrays, dict):
            warnings.extend(w for w in partial_arrays["warnings"] if w not in warnings)
            err.results = results(partial_arrays)
        raise
    warnings.extend(w for w in arrays["warnings"] if w not in warnings)
    return results(arrays)


class StaticSolver:
    """The static analysis of one model, its set-up paid once, solved for many load cases::

        solver = spacar.StaticSolver(model)        # prepared, compiled and set up now
        res = solver(steps=1)                       # spacar.static(model, steps=1), the model unchanged
        f = solver.force                            # the model's FORCE on every nodal coordinate (a copy)
        f[solver.coordinate(21, 2)] = 2.5           # another load case: FORCE on node 21, y
        res = solver(f, steps=1)

    :func:`spacar.static` compiles the model, recognizes an open chain and orders the sparse
    tangent stiffness at every call: a third of the time of a one-step solve of a few hundred
    beams. A solver does that once, on a copy of the model as it is when the solver is made (later
    changes to the model are not seen: make a new solver). Each call is :func:`spacar.static`'s
    analysis with its options (``steps``, ``arc_length``, ``max_steps``, ``max_iterations``,
    ``max_cuts``, ``tolerance``, ``time_limit``; the time limit covers the call), from the
    model's state when the solver was made, and gives the same results to the last digit; the
    model is not changed. ``force`` (nx values, in the order of :attr:`coordinate_labels`): the
    FORCE loads on the nodal coordinates in place of the model's, applied with the load factor as
    the model's are (torques, gravity and prescribed inputs stay the model's). The results share
    the solver's copy of the model for ``res.geometry``, and ``spacar.compliance(res, node)``
    takes the loads of their call. The warnings of the calls are collected in ``solver.warnings``
    (each once), not in the model's. The set-up runs when the solver is made, without a time
    limit. One call at a time per solver (calls from several threads wait for each other)."""

    def __init__(self, model: Model):
        if not isinstance(model, Model):
            raise InputError(f"StaticSolver: model must be a spacar.Model, got {show(model)}")
        self._solver = _core.StaticSolver(model.core)
        self._model = Model._of_core(self._solver.model)
        self._model.urdf_shapes = getattr(model, "urdf_shapes", None)
        self.warnings: list[str] = []
        self._labels = np.asarray(self._solver.coordinate_labels)
        self._lock = threading.Lock()

    @property
    def force(self) -> np.ndarray:
        """The model's FORCE loads on every nodal coordinate (a copy, in the order of
        :attr:`coordinate_labels`)."""
        return np.asarray(self._solver.force)

    @property
    def coordinate_labels(self) -> np.ndarray:
        """(node, component) of every nodal coordinate, components from 1 (nx × 2)."""
        return self._labels.copy()

    def coordinate(self, node: int, component: int) -> int:
        """The index of coordinate ``component`` (from 1) of ``node`` in :attr:`force`."""
        hits = np.flatnonzero((self._labels[:, 0] == node) & (self._labels[:, 1] == component))
        if len(hits) == 0:
            raise InputError(f"StaticSolver: the model has no coordinate {show(component)} of node {show(node)}")
        return int(hits[0])

    def __call__(self, force=None, *, steps: int = 10, arc_length: bool = False, max_steps: int = 200,
                 max_iterations: int = 30, max_cuts: int = 12, tolerance: float = 1e-10, time_limit=None) -> Results:
        options = _options(steps, arc_length, max_steps, max_iterations, max_cuts, tolerance, time_limit)
        if force is not None:
            try:
                force = np.array(force, dtype=float)
            except (TypeError, ValueError, OverflowError):
                raise InputError(f"StaticSolver: force must be numbers, got {show(force)}") from None
            if force.shape != (len(self._labels),):
                raise InputError(f"StaticSolver: force must have one value per nodal coordinate "
                                 f"({len(self._labels)}), got shape {force.shape}")
        # spacar.compliance(res, ...) prepares the model it is given: a copy, made when first needed.
        end_model = partial(_loaded_model, self._model, self._labels, force)
        with self._lock:
            return _solved(lambda: self._solver.solve(force, *options), self.warnings,
                           partial(_results, model=self._model, end_model=end_model))

    def __repr__(self) -> str:
        return f"<spacar.StaticSolver: {len(self._labels)} nodal coordinates>"


def _loaded_model(model: Model, labels: np.ndarray, force) -> Model:
    """A copy of ``model``, with the FORCE loads ``force`` (one per coordinate of ``labels``) if
    given."""
    copy = Model._of_core(model.core.copy())
    if force is None:
        return copy
    for node in np.unique(labels[:, 0]):
        values = force[labels[:, 0] == node]
        copy.force(int(node), *(float(v) for v in values))
    return copy


def static_blocks(model, **kwargs):
    """The static equilibrium of every block of the input in order, as ``spacar static`` does:
    the current block first, then each later block applied to the equilibrium reached (a load
    history). Yields one :class:`spacar.Results` per block (``kwargs`` go to :func:`static`)."""
    from .io.reader import apply_block

    for k, block in enumerate(model.blocks or [None]):
        if k > 0:
            apply_block(model, block)
        yield static(model, **kwargs)

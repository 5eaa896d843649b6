"""Inverse dynamics and the derivatives of the forward dynamics at given states: functions that
set the model up at every call, and :class:`Dynamics`, which does that once."""
from __future__ import annotations

import contextlib
import math
import threading

import numpy as np

from . import _core
from ._util import show, time_limited
from .errors import InputError
from .model import Model
from .results import dof_labels


def _states(what, finite=True, **arrays):
    """The arrays (q, qd, ...) as float matrices of states (one per row; views where they can be), and the
    shape they were given in (a vector: one state). Written for a call per state: a few µs.
    ``finite=False``: their finiteness left to the core (Simulation.inverse_dynamics and
    dynamics_derivatives check it in nanoseconds, where a sum per array here costs microseconds)."""
    out = []
    for name, value in arrays.items():
        a = value
        if type(a) is not np.ndarray or a.dtype != np.float64:
            try:
                a = np.array(value, dtype=float)
            except (TypeError, ValueError, OverflowError):
                raise InputError(f"{what}: {name} must be an array of numbers, got {show(value)}") from None
        # The sum is finite when every value is (short of an overflow, which the full test decides).
        if a.ndim not in (1, 2) or (finite and not (math.isfinite(a.sum()) or np.isfinite(a).all())):
            raise InputError(f"{what}: {name} must be a finite vector or a matrix of states (one per row)")
        out.append(a)
    shape = out[0].shape
    if any(a.shape != shape for a in out):
        raise InputError(f"{what}: {', '.join(list(arrays)[:-1])} and {list(arrays)[-1]} must have the same shape, got "
                         f"{', '.join(str(a.shape) for a in out)}")
    # Any strides: the core reads float rows of unit stride in place, the binding copies others.
    rows = [a.reshape(1, -1) if a.ndim == 1 else a for a in out]
    return rows, shape


def _one_state(a, b, c):
    """_states' answer (finiteness left to the core) for the call of a controller: three float
    vectors of one length, passed on as views; None for anything else."""
    F = np.float64
    if (type(a) is np.ndarray and type(b) is np.ndarray and type(c) is np.ndarray and a.ndim == 1
            and a.dtype == F and b.dtype == F and c.dtype == F and a.shape == b.shape == c.shape):
        return [a[None], b[None], c[None]], a.shape
    return None


def _limited(time_limit, where):
    """time_limited, or nothing to enter when there is no limit (a call per state stays cheap)."""
    return contextlib.nullcontext() if time_limit is None else time_limited(time_limit, where)


class Dynamics:
    """The dynamics of a model at given states, with its set-up paid once: the model compiled and
    assembled, a tree of rigid bodies recognized, when it is made; each call then evaluates its
    batch of states in C++ (as :func:`inverse_dynamics` and :func:`dynamics_derivatives`, which
    pay that set-up at every call: about 0.1 ms for a 6-DOF robot, where the evaluation of one
    state takes microseconds)::

        dyn = spacar.Dynamics(model)
        tau = dyn.inverse_dynamics(q, qd, qdd)                      # as pinocchio.rnea
        qdd, dq, dqd, dtau = dyn.dynamics_derivatives(q, qd, tau)   # as pinocchio.computeABADerivatives

    The model as it is when the Dynamics is made is used (a copy; later changes are not seen: make
    a new one). ``path``: ``"tree"`` (the recursive algorithms) or ``"general"`` (the reduced
    equations; each call then sets the model up again, so that a call does not depend on the calls
    before it, and costs what the functions' calls cost). ``dof_labels`` name q's columns. One call at a
    time (calls from several threads wait for each other)."""

    def __init__(self, model: Model, *, _copy: bool = True):
        if not isinstance(model, Model):
            raise InputError(f"Dynamics: model must be a spacar.Model, got {show(model)}")
        self._model_core = model.core.copy() if _copy else model.core
        self._sim = _core.Simulation(self._model_core)  # prepares the model (the first END) and compiles it
        self._sim.assemble()
        self._assembled = True
        self.n_dof = self._sim.system.n_dof
        self._lock = threading.Lock()
        self._path = None

    @property
    def path(self) -> str:
        """"tree" if the model is a tree of rigid bodies of the recursive path, else "general"."""
        if self._path is None:
            with self._lock:
                self._path = "tree" if self._sim.recursive_refusal() == "" else "general"
        return self._path

    @property
    def dof_labels(self) -> list:
        return dof_labels(self._sim.system, self._model_core)

    def inverse_dynamics(self, q, qd, qdd, *, time_limit=None) -> np.ndarray:
        """:func:`inverse_dynamics` at these states."""
        rows, shape = _one_state(q, qd, qdd) or _states("inverse_dynamics", False, q=q, qd=qd, qdd=qdd)
        with self._lock, _limited(time_limit, "in inverse_dynamics"):
            self._reassemble()
            force, path = self._sim.inverse_dynamics(*rows)
            self._assembled = path == "tree"  # the general path moved the positions
        return np.asarray(force).reshape(shape)

    def dynamics_derivatives(self, q, qd, tau, *, time_limit=None):
        """:func:`dynamics_derivatives` at these states."""
        rows, shape = _one_state(q, qd, tau) or _states("dynamics_derivatives", False, q=q, qd=qd, tau=tau)
        with self._lock, _limited(time_limit, "in dynamics_derivatives"):
            self._reassemble()
            qdd, dq, dqd, dtau = self._sim.dynamics_derivatives(*rows)
        n, states = shape[-1], shape[:-1]
        return (np.asarray(qdd).reshape(shape), *(np.asarray(m).reshape(states + (n, n)) for m in (dq, dqd, dtau)))

    def _reassemble(self):
        """After a general-path call (its Newton iterations moved the positions): the simulation
        made and assembled again, as at the start."""
        if not self._assembled:
            self._sim = _core.Simulation(self._model_core)
            self._sim.assemble()
            self._assembled = True

    def __repr__(self) -> str:
        return f"<spacar.Dynamics: {self.n_dof} DOFs>"


def dynamics_derivatives(model: Model, q, qd, tau, *, time_limit=None):
    """The forward dynamics and its derivatives, as ``pinocchio.computeABADerivatives``:
    ``(qdd, dqdd_dq, dqdd_dqd, dqdd_dtau)`` at the state (``q``, ``qd``) under the generalized
    forces ``tau`` on the DOFs beyond the model's own loads (those of :func:`inverse_dynamics`):
    q̈ (n), ∂q̈/∂q, ∂q̈/∂q̇ and ∂q̈/∂τ = M⁻¹ (n × n). ``q``, ``qd``, ``tau`` may be batches of states,
    one per row: the results then have a leading axis of states.

    Exact: ∂τ/∂q and ∂τ/∂q̇ analytic on spatial trees (passes over the tree in world axes) and
    from the recursive Newton–Euler algorithm on dual numbers on planar ones, and
    ∂q̈/∂(q, q̇) = −M⁻¹ ∂τ/∂(q, q̇), in C++ over the whole batch. For planar and spatial trees of
    rigid bodies on the recursive path (URDF robots, pendulums, branched linkages, floating bases
    in their DOFs of the origin and three Euler parameters; formulation.md §7) and closed loops
    closed at points and at cut hinges (their forward dynamics on dual numbers); other models raise
    InputError saying why they are not one. ``time_limit``: wall-clock
    seconds (:class:`spacar.TimeLimitError`), the set-up included. Each call compiles and
    assembles the model: :class:`Dynamics` does that once for many calls."""
    if not isinstance(model, Model):
        raise InputError(f"dynamics_derivatives: model must be a spacar.Model, got {show(model)}")
    _states("dynamics_derivatives", q=q, qd=qd, tau=tau)  # refused before the set-up
    with time_limited(time_limit, "in dynamics_derivatives"):
        return Dynamics(model, _copy=False).dynamics_derivatives(q, qd, tau)


def inverse_dynamics(model: Model, q, qd, qdd, *, time_limit=None) -> np.ndarray:
    """The generalized forces on the degrees of freedom, beyond the model's own loads, gravity,
    springs and dampers, under which it has the accelerations ``qdd`` at the state (``q``,
    ``qd``): M̄(q) q̈ + h(q, q̇) − (its loads), as ``pinocchio.rnea`` for a robot read by
    :func:`spacar.from_urdf`. ``q``, ``qd`` and ``qdd`` hold one value per DOF (in the order of
    ``Results.dof_labels``), or a batch of states, one per row: the result has their shape.

    A tree of rigid bodies (the systems of the recursive path, formulation.md §7) is solved by the
    recursive Newton–Euler algorithm, O(N) per state, in C++ over the whole batch. Any other
    system is solved by its reduced equations, M̄ (q̈ − q̈₀) with q̈₀ its accelerations under its
    own loads; there each state's positions are found by Newton from the previous state's (the
    first from the assembled one), so a batch should move in small steps along a path.
    ``time_limit``: wall-clock seconds it may take, the set-up included
    (:class:`spacar.TimeLimitError` beyond). Each call compiles and assembles the model:
    :class:`Dynamics` does that once for many calls."""
    if not isinstance(model, Model):
        raise InputError(f"inverse_dynamics: model must be a spacar.Model, got {show(model)}")
    _states("inverse_dynamics", q=q, qd=qd, qdd=qdd)  # refused before the set-up
    with time_limited(time_limit, "in inverse_dynamics"):
        return Dynamics(model, _copy=False).inverse_dynamics(q, qd, qdd)

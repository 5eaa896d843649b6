"""Many short runs of one model from different initial states (:class:`Rollout`), for
optimizations, Monte Carlo studies, shooting methods and learning: compiled, assembled and its
right-hand-side path chosen once, then every batch of states integrated in one call into C++."""
from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from . import _core
from ._util import seconds_or_none, show
from .errors import InputError, SpacarError
from .model import Model
from .results import dof_labels
from .simulate import check_method_options


class RolloutResults:
    """The states of a rollout at its output times.

    ``t`` (nt): the output times, the first the start of every state's run. ``q``, ``qd``: the
    DOFs and their rates, (states, nt, n) for a batch of initial states, (nt, n) for one.
    ``x``: the positions of every coordinate, (states, nt, nx) or (nt, nx), when asked for
    (``coordinates=True``), else None. ``stats``: ``path`` ("tree", "chain" or "general"),
    ``wall_time`` (seconds of the call in C++), ``rhs_evaluations``, ``steps`` and ``rejected``
    (one per state), ``method``. ``dof_labels``, ``coordinate_labels`` name the columns."""

    def __init__(self, arrays: dict, t, batch: bool, rollout: "Rollout"):
        nt, n = len(t), rollout.n_dof
        self.t = t
        shape = (-1, nt) if batch else (nt,)
        self.q = np.asarray(arrays["q"]).reshape(shape + (n,))
        self.qd = np.asarray(arrays["qd"]).reshape(shape + (n,))
        x = arrays["x"]
        self.x = None if x is None else np.asarray(x).reshape(shape + (len(rollout.coordinate_labels),))
        self.stats = {"path": arrays["path"], "wall_time": arrays["wall_time"], "method": rollout.method}
        for key in ("rhs_evaluations", "steps", "rejected"):
            self.stats[key] = np.asarray(arrays[key], dtype=np.int64)
        self.warnings = list(arrays["warnings"])
        self.dof_labels = rollout.dof_labels
        self.coordinate_labels = rollout.coordinate_labels

    def __repr__(self) -> str:
        return (f"<spacar.RolloutResults: q {self.q.shape}, path {self.stats['path']!r}, "
                f"{int(self.stats['rhs_evaluations'].sum())} right-hand sides in {self.stats['wall_time']:.3g} s>")


class Rollout:
    """Runs of ``model`` from many initial states over the same output times, its set-up paid once.

    ::

        roll = spacar.Rollout(model)              # compiled now; assembled at the first call
        res = roll(q0, qd0)                       # q0, qd0: (n,) or (states, n); TIMESTEP's times
        res = roll(q0, qd0, t=np.linspace(0, 0.3, 31))
        res.q, res.qd                             # (states, nt, n)

    ``spacar.simulate`` pays for every block its set-up: the model compiled, assembled by Newton's
    method, the tree of a robot recognized, the complete state (coordinates, velocities,
    accelerations, stresses) solved at every output time and handed to Python. A rollout does that
    once: each call integrates its states (one per row of ``q0``, ``qd0``) in C++ from ``t[0]``
    through the output times ``t`` (default: the model's TIMESTEP times from its current time) and
    records the DOFs and their rates there, the positions of every coordinate too with
    ``coordinates=True``. The integration is :func:`spacar.simulate`'s: the same ``method``
    (default ``"auto"``), error control (EPSINT, EPSIND), ``recursive`` path (the articulated-body
    algorithm on a tree of rigid bodies), ``rho_inf`` and ``fixed_step``; each state gives what a
    block run from it gives. ``q0`` or ``qd0`` None: the model's initial DOFs or rates (for every
    state). On the general path each state's positions are found by Newton's method from the
    assembled ones (as the first step of a block from there), so states far from the model's
    initial one may reach another assembly of a closed loop.

    The model as it is when the Rollout is made is used: later changes to it are not seen (make
    a new Rollout). The model itself is not changed. A failure names the state; the exception
    carries the states before it as ``err.results``. A floating base whose run exchanges its
    dependent Euler parameter is recorded in the DOFs it started with all the same. Time-dependent
    loads, controllers and the energy balance are :func:`spacar.simulate`'s.

    ``threads``: a batch is split into this many contiguous parts, integrated in parallel, each by
    its own compiled copy of the model (made when first needed; its first call assembles); None
    (default): the machine's cores for batches of at least 8 states per core, else one. A state's
    result does not depend on the thread or the states before it. One call at a time per Rollout
    (calls from several threads wait for each other)."""

    def __init__(self, model: Model, *, method: str = "auto", recursive: bool = True, rho_inf=None,
                 fixed_step=None, threads=None):
        if not isinstance(model, Model):
            raise InputError(f"Rollout: model must be a spacar.Model, got {show(model)}")
        self._fixed_step = check_method_options(method, rho_inf, fixed_step, recursive)
        if method not in _core.integration_methods:
            raise InputError(f"Rollout: method must be one of {', '.join(map(repr, _core.integration_methods))}, "
                             f"got {show(method)}")
        self.method = method
        self._recursive = bool(recursive)
        self._rho_inf = _core.run_defaults["rho_inf"] if rho_inf is None else float(rho_inf)
        if threads is not None and (isinstance(threads, (bool, np.bool_)) or not isinstance(threads, (int, np.integer))
                                    or threads < 1):
            raise InputError(f"Rollout: threads must be a positive whole number or None, got {show(threads)}")
        self._threads = None if threads is None else int(threads)
        # The model as it is now, in a copy of the Rollout's own, whatever the user's model
        # becomes. Every thread's simulation prepares (the first END: its Euler parameters
        # normalized) and compiles a copy of its own of that one, so that all see the same model.
        self._pristine = model.core.copy()
        self._cores = [self._pristine.copy()]
        self._sims = [_core.Simulation(self._cores[0])]
        system = self._sims[0].system
        self.n_dof = system.n_dof
        if self.n_dof == 0:
            raise InputError("Rollout: the model has no degrees of freedom to integrate")
        # The model's initial DOFs and rates, one state each (2-D).
        self._initial = (np.array(system.q0, dtype=float).reshape(1, -1), np.array(system.qd0, dtype=float).reshape(1, -1))
        settings = model.core.settings
        n_out = settings.timestep_n
        self._times = model.current_time + settings.timestep_tp * np.arange(n_out + 1) / max(n_out, 1)
        self._times[-1] = model.current_time + settings.timestep_tp  # the block's end exactly
        coords = system.coord_label
        self.coordinate_labels = [tuple(c) for c in coords]
        self.dof_labels = dof_labels(system, model.core, coords)
        self._lock = threading.Lock()

    def __call__(self, q0=None, qd0=None, t=None, *, coordinates: bool = False, time_limit=None) -> RolloutResults:
        q0, qd0, batch = self._initial_states(q0, qd0)
        times = self._output_times(t)
        if not isinstance(coordinates, (bool, np.bool_)):
            raise InputError(f"Rollout: coordinates must be True or False, got {show(coordinates)}")
        limit = seconds_or_none(time_limit, "time_limit") or 0.0
        with self._lock:
            parts = self._parts(q0.shape[0])
            while len(self._sims) < len(parts):
                self._cores.append(self._pristine.copy())
                self._sims.append(_core.Simulation(self._cores[-1]))
            cancel = _core.Cancellation()

            def run(k):
                a, b = parts[k]
                try:
                    with cancel.watch():  # Ctrl-C (the main thread's) stops the other threads too
                        return self._sims[k].rollout(q0[a:b], qd0[a:b], times, method=self.method,
                                                     recursive=self._recursive, rho_inf=self._rho_inf,
                                                     fixed_step=self._fixed_step, coordinates=bool(coordinates),
                                                     time_limit=limit)
                except SpacarError as err:
                    return err

            if len(parts) == 1:
                outcomes = [run(0)]
            else:
                pool = ThreadPoolExecutor(len(parts))  # the core releases the GIL
                try:
                    futures = [pool.submit(run, k) for k in range(len(parts))]
                    outcomes = [f.result() for f in futures]
                except KeyboardInterrupt:
                    cancel.cancel()
                    raise
                finally:
                    pool.shutdown(wait=True, cancel_futures=True)
        arrays = _joined(outcomes, parts)
        if isinstance(arrays, SpacarError):
            err = arrays
            partial = getattr(err, "results", None)
            if not isinstance(partial, dict) or partial["failed"] < 0:
                raise err
            failed = type(err)(f"rollout, state {partial['failed']} (q0 = {_short(q0[partial['failed']])}): {err}")
            failed.results = RolloutResults(partial, times, True, self)
            raise failed from err
        return RolloutResults(arrays, times, batch, self)

    def _parts(self, states: int) -> list:
        """The batch's contiguous parts [(first, end)], one per thread."""
        threads = self._threads
        if threads is None:
            cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
            threads = cores if states >= 8 * cores else 1
        threads = max(1, min(threads, states))
        return [(k * states // threads, (k + 1) * states // threads) for k in range(threads)]

    def _initial_states(self, q0, qd0):
        """q0, qd0 as (states, n) float arrays (a missing one the model's, broadcast), and whether
        a batch was given."""
        if q0 is None and qd0 is None:
            return self._initial[0], self._initial[1], False
        given = []
        for name, value in (("q0", q0), ("qd0", qd0)):
            if value is None:
                given.append(None)
                continue
            try:
                a = np.array(value, dtype=float)
            except (TypeError, ValueError, OverflowError):
                raise InputError(f"Rollout: {name} must be an array of numbers, got {show(value)}") from None
            if a.ndim not in (1, 2) or a.shape[-1] != self.n_dof or not np.isfinite(a).all():
                raise InputError(f"Rollout: {name} must be finite, {self.n_dof} values (one per DOF, in the order of "
                                 f"dof_labels) or a matrix of states with {self.n_dof} columns, got shape {a.shape}")
            given.append(a)
        batch = any(a is not None and a.ndim == 2 for a in given)
        rows = max((a.shape[0] for a in given if a is not None and a.ndim == 2), default=1)
        out = []
        for a, default in zip(given, self._initial):
            a = np.atleast_2d(default if a is None else a)
            if a.shape[0] != rows and a.shape[0] != 1:
                raise InputError(f"Rollout: q0 and qd0 must have the same number of states (rows), got "
                                 f"{given[0].shape[0]} and {given[1].shape[0]}")
            if a.shape[0] != rows:  # one state for all (a vector, or the model's)
                a = np.repeat(a, rows, axis=0)
            out.append(np.ascontiguousarray(a))
        return out[0], out[1], batch

    def _output_times(self, t) -> np.ndarray:
        """The output times as a float array (the core refuses times that are not finite or do not
        increase, naming the time)."""
        if t is None:
            return self._times
        try:
            return np.asarray(t, dtype=float).reshape(-1)
        except (TypeError, ValueError, OverflowError):
            raise InputError(f"Rollout: t must be an array of output times, got {show(t)}") from None

    def __repr__(self) -> str:
        return f"<spacar.Rollout: {self.n_dof} DOFs, method {self.method!r}, {len(self._times)} TIMESTEP output times>"


def _joined(outcomes: list, parts: list):
    """The parts' results as one (their rows and per-state counters in order), or the error of
    the first part that failed, its partial results joined to the parts before it and its failed
    state numbered in the whole batch."""
    done = []
    for (a, _), out in zip(parts, outcomes):
        if isinstance(out, SpacarError):
            partial = getattr(out, "results", None)
            if isinstance(partial, dict) and partial["failed"] >= 0:
                partial["failed"] += a
                out.results = _concatenated(done + [partial])
            return out
        done.append(out)
    return _concatenated(done)


def _concatenated(parts: list) -> dict:
    """The parts' results (dicts of the core's rollout) as one: rows and counters in order."""
    if len(parts) == 1:
        return parts[0]
    out = dict(parts[-1])
    for key in ("q", "qd", "x"):
        out[key] = None if parts[0][key] is None else np.concatenate([np.asarray(p[key]) for p in parts])
    for key in ("rhs_evaluations", "steps", "rejected"):
        out[key] = [n for p in parts for n in p[key]]
    out["wall_time"] = max(p["wall_time"] for p in parts)
    out["warnings"] = list(dict.fromkeys(w for p in parts for w in p["warnings"]))
    return out


def _short(values) -> str:
    shown = ", ".join(f"{v:.6g}" for v in values[:6])
    return f"[{shown}{', …' if len(values) > 6 else ''}]"

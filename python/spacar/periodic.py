"""Periodic steady states of driven mechanisms and their Floquet multipliers (docs/periodic.md).

A mechanism driven with period T (a crank at constant speed, a support moved by a periodic
table, periodic loads) has the flow Φ: s(t0) ↦ s(t0 + T) over one period of its state
s = (q, q̇), the degrees of freedom and their rates. A periodic orbit is a fixed point
Φ(s) = s, found here by shooting: Newton's method on Φ(s) − s with the monodromy matrix
∂Φ/∂s, each column a central difference of two runs of the core's integrator over one
period. The eigenvalues of the monodromy at the orbit are its Floquet multipliers: the orbit is
asymptotically stable when they all lie inside the unit circle, unstable when one lies outside
(Meijaard's stability of the periodic motion of flexible mechanisms; Mathieu's equation for a
pendulum on a vibrating support).
"""
from __future__ import annotations

import math
import numbers
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from . import _core
from ._util import seconds_or_none, show
from .errors import InputError, SpacarError, TimeLimitError
from .model import Model
from .results import Results

__all__ = ["PeriodicOrbit", "floquet", "periodic_orbit"]


@dataclass
class PeriodicOrbit:
    """A periodic state of a driven model (:func:`periodic_orbit`, :func:`floquet`).

    ``q``, ``qd``: the degrees of freedom and their rates at ``t0`` (in ``dof_labels`` order, as
    :attr:`spacar.Results.q`); ``period``; ``monodromy``: ∂s(t0+T)/∂s(t0) for s = (q, q̇), 2n x 2n;
    ``multipliers``: its eigenvalues (the Floquet multipliers), largest modulus first;
    ``residual``: max |Φ(s) − s| of the orbit (0 is exactly periodic); ``iterations``: Newton
    steps taken; ``runs``: integrations over one period done in all; ``results``: the motion
    over one period from the orbit (:class:`spacar.Results`, ``steps`` output intervals)."""

    t0: float
    period: float
    q: np.ndarray
    qd: np.ndarray
    dof_labels: list
    monodromy: np.ndarray
    multipliers: np.ndarray
    residual: float
    iterations: int
    runs: int
    results: Results | None = field(default=None, repr=False)

    @property
    def spectral_radius(self) -> float:
        """The largest modulus of the Floquet multipliers."""
        return float(np.max(np.abs(self.multipliers))) if self.multipliers.size else 0.0

    @property
    def exponents(self) -> np.ndarray:
        """The Floquet exponents log(μ)/T (complex; real part < 0: a decaying perturbation)."""
        return np.log(self.multipliers.astype(complex)) / self.period

    def is_stable(self, margin: float = 1e-6) -> bool:
        """True when every multiplier lies inside the circle of radius 1 + ``margin``. An
        undamped (conservative) motion has multipliers on the unit circle, computed to the
        accuracy of the monodromy (about 1e-8): within the margin it counts as stable (marginally)."""
        return self.spectral_radius <= 1.0 + margin


class _Flow:
    """The flow over one period of a copy of the model: Φ(s) for s = (q, q̇) at t0."""

    def __init__(self, model, period, integration_tolerance, method, inputs, forces, deadline):
        self.model, self.period, self.method = model, period, method
        self.inputs, self.forces, self.deadline = inputs, forces, deadline
        self.integration_tolerance = integration_tolerance
        system = _core.Simulation(model.core).system
        coords = [tuple(int(v) for v in c) for c in system.coord_label]
        defs = [tuple(int(v) for v in c) for c in system.def_label]
        self.x_dofs = [coords[g] for g in system.x_dyn]
        self.e_dofs = [defs[k] for k in system.e_dyn]
        self.n = system.n_dof
        self.s0 = np.concatenate([np.asarray(system.q0, float), np.asarray(system.qd0, float)])
        self.runs = 0

    def start(self, s, steps: int = 1) -> Model:
        """A copy of the model at t0 in the state s, set to run one period in `steps` outputs."""
        m = self.model.copy()
        q, qd = s[:self.n], s[self.n:]
        core = m.core
        for j, (node, comp) in enumerate(self.x_dofs):
            x = list(core.nodes[node].x)
            x[comp - 1] = float(q[j])
            m.x(node, *x)
            m.xd(node, comp, float(qd[j]))
        for j, (elem, i) in enumerate(self.e_dofs, start=len(self.x_dofs)):
            m.e(elem, i, float(q[j]))
            m.ed(elem, i, float(qd[j]))
        m.timestep(steps, self.period)
        m.epsint(self.integration_tolerance)
        m.epsind(self.integration_tolerance)
        m.matasc(0)
        m.animate(0)
        return m

    def run(self, s, steps: int = 1) -> Results:
        from .simulate import simulate

        remaining = None
        if self.deadline is not None:
            remaining = self.deadline - time.monotonic()
            if remaining <= 0:
                raise TimeLimitError("the periodic orbit's time limit passed (periodic_orbit)")
        self.runs += 1
        return simulate(self.start(s, steps), method=self.method, inputs=self.inputs, forces=self.forces,
                        progress=False, time_limit=remaining)

    def __call__(self, s) -> np.ndarray:
        res = self.run(s)
        return np.concatenate([res.q[-1], res.qd[-1]])

    def monodromy(self, s, delta) -> np.ndarray:
        """∂Φ/∂s by central differences, the step delta·max(1, |s_i|) in component i."""
        m = np.empty((2 * self.n, 2 * self.n))
        for i in range(2 * self.n):
            h = delta * max(1.0, abs(s[i]))
            plus, minus = s.copy(), s.copy()
            plus[i] += h
            minus[i] -= h
            m[:, i] = (self(plus) - self(minus)) / (2.0 * h)
        return m


def _number(value, what, positive=True):
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool) and math.isfinite(value)
    if not ok or (positive and value <= 0):
        raise InputError(f"{what} must be a positive finite number, got {show(value)}")
    return float(value)


def _check_common(model, period, tolerance, delta, method, steps, what):
    if not isinstance(model, Model):
        raise InputError(f"{what}: model must be a spacar.Model, got {show(model)}")
    period = _number(period, f"{what}: period")
    tolerance = _number(tolerance, f"{what}: integration_tolerance")
    delta = _number(delta, f"{what}: delta")
    if not isinstance(method, str):
        raise InputError(f"{what}: method must be an integration method's name, got {show(method)}")
    if isinstance(steps, bool) or not isinstance(steps, numbers.Integral) or steps < 1:
        raise InputError(f"{what}: steps must be a positive integer, got {show(steps)}")
    return period, tolerance, delta


def _check_tables(inputs, forces, t0, period, what):
    """The input and load tables must cover the period: beyond its samples a table holds its end
    values, which would make the drive something else than the one meant."""
    from .table import Table

    for name, given in (("inputs", inputs), ("forces", forces)):
        for key, table in (given or {}).items() if isinstance(given, dict) else ():
            if isinstance(table, Table) and (table.t[0] > t0 + 1e-12 * max(1.0, abs(t0)) or
                                             table.t[-1] < t0 + period * (1 - 1e-12)):
                raise InputError(f"{what}: the {name} table of {key} covers [{table.t[0]:g}, {table.t[-1]:g}], not "
                                 f"the period [{t0:g}, {t0 + period:g}] from the model's current time")


def _state(flow, q, qd, what):
    n = flow.n
    if n == 0:
        raise InputError(f"{what}: the model has no degrees of freedom (DYNX, DYNE): its motion is "
                         "prescribed, periodic whenever its inputs are")
    s = flow.s0.copy()
    for part, given, name in ((slice(0, n), q, "q"), (slice(n, 2 * n), qd, "qd")):
        if given is None:
            continue
        try:
            v = np.array(given, dtype=float).reshape(-1)
        except (TypeError, ValueError, OverflowError):
            raise InputError(f"{what}: {name} must be {n} numbers (the degrees of freedom), got {show(given)}") \
                from None
        if v.shape != (n,) or not np.isfinite(v).all():
            raise InputError(f"{what}: {name} must be {n} finite numbers (the degrees of freedom), "
                             f"got {show(given)}")
        s[part] = v
    return s


def _orbit(flow, s, residual, iterations, steps, delta) -> PeriodicOrbit:
    mono = flow.monodromy(s, delta)
    mu = np.linalg.eigvals(mono)
    mu = mu[np.argsort(-np.abs(mu), kind="stable")]
    if np.all(np.abs(mu.imag) <= 1e-14 * np.maximum(1.0, np.abs(mu))):
        mu = mu.real
    res = flow.run(s, steps)
    return PeriodicOrbit(t0=float(flow.model.current_time), period=flow.period, q=s[:flow.n].copy(),
                         qd=s[flow.n:].copy(), dof_labels=list(res.dof_labels), monodromy=mono,
                         multipliers=mu, residual=float(residual), iterations=iterations, runs=flow.runs,
                         results=res)


def floquet(model, period, *, q=None, qd=None, inputs=None, forces=None, method: str = "dop853",
            integration_tolerance: float = 1e-12, delta: float = 1e-6, steps: int = 100,
            time_limit=None) -> PeriodicOrbit:
    """The Floquet multipliers of ``model`` over one ``period`` from its current state (or from
    the degrees of freedom ``q`` and rates ``qd`` given, at the model's current time), taken to
    be periodic: the monodromy matrix and its eigenvalues, without shooting (for an orbit known
    beforehand, e.g. the rest state of a pendulum on a vibrating support; use
    :func:`periodic_orbit` to find it). The residual max |Φ(s) − s| says how periodic the state is.

    ``inputs``, ``forces``: the time-dependent inputs and loads of :func:`spacar.simulate`
    (tables over at least one period from the model's current time). ``integration_tolerance``
    sets EPSINT and EPSIND of the runs (the monodromy's accuracy is about this tolerance over
    ``delta``); ``delta``: the step of the central differences, relative to max(1, |s_i|);
    ``steps``: output intervals of ``results``. The runs take ``method`` (``"dop853"`` by
    default; ``"radau5"`` for stiff flexible models). ``time_limit``: seconds for the whole
    analysis (None: none)."""
    period, tol, delta = _check_common(model, period, integration_tolerance, delta, method, steps, "floquet")
    limit = seconds_or_none(time_limit, "floquet: time_limit")
    deadline = None if limit is None else time.monotonic() + limit
    _check_tables(inputs, forces, float(model.current_time), period, "floquet")
    flow = _Flow(model, period, tol, method, inputs, forces, deadline)
    s = _state(flow, q, qd, "floquet")
    residual = float(np.max(np.abs(flow(s) - s)))
    return _orbit(flow, s, residual, 0, steps, delta)


def periodic_orbit(model, period, *, q=None, qd=None, inputs=None, forces=None, method: str = "dop853",
                   tolerance: float = 1e-10, max_iterations: int = 20, integration_tolerance: float = 1e-12,
                   delta: float = 1e-6, steps: int = 100, time_limit=None) -> PeriodicOrbit:
    """The periodic steady state of ``model`` driven with ``period`` (a crank at constant speed
    over one turn, periodic input tables or loads), by shooting from the model's current state
    (or from ``q``, ``qd``): Newton's method on Φ(s) − s = 0 for s = (q, q̇) at the model's
    current time, Φ the run over one period, the monodromy ∂Φ/∂s by central differences
    (2·2n runs per step for n degrees of freedom). It stops when max |Φ(s) − s| ≤ ``tolerance``
    · max(1, |s|) and returns a :class:`PeriodicOrbit` with the Floquet multipliers of the orbit
    found: without a long transient run, the state the motion settles to (if the multipliers lie
    inside the unit circle) and whether it does.

    The other arguments are those of :func:`floquet`. A :class:`spacar.SpacarError` if Newton
    does not converge in ``max_iterations`` steps, or if a multiplier equals 1 (Φ(s) − s has a
    singular Jacobian: a free, undriven motion, or resonance with the drive), naming the residual."""
    period, tol, delta = _check_common(model, period, integration_tolerance, delta, method, steps,
                                       "periodic_orbit")
    tolerance = _number(tolerance, "periodic_orbit: tolerance")
    if isinstance(max_iterations, bool) or not isinstance(max_iterations, numbers.Integral) or max_iterations < 1:
        raise InputError(f"periodic_orbit: max_iterations must be a positive integer, got {show(max_iterations)}")
    limit = seconds_or_none(time_limit, "periodic_orbit: time_limit")
    deadline = None if limit is None else time.monotonic() + limit
    _check_tables(inputs, forces, float(model.current_time), period, "periodic_orbit")
    flow = _Flow(model, period, tol, method, inputs, forces, deadline)
    s = _state(flow, q, qd, "periodic_orbit")
    history = []
    for iteration in range(max_iterations + 1):
        r = flow(s) - s
        residual = float(np.max(np.abs(r)))
        history.append(residual)
        if residual <= tolerance * max(1.0, float(np.max(np.abs(s)))):
            orbit = _orbit(flow, s, residual, iteration, steps, delta)
            ones = np.abs(orbit.multipliers - 1.0) < 1e-6
            if np.any(ones):
                warnings.warn(f"periodic_orbit: a Floquet multiplier is 1 within {np.abs(orbit.multipliers - 1).min():.1g}: "
                              "the orbit found may belong to a family (a free motion, not one set by the drive), or "
                              "the drive is in resonance", RuntimeWarning, stacklevel=2)
            return orbit
        if iteration == max_iterations:
            break
        jac = flow.monodromy(s, delta) - np.eye(2 * flow.n)
        if np.linalg.cond(jac) > 1e12:
            raise SpacarError("periodic_orbit: a Floquet multiplier is 1 (the monodromy minus the identity is "
                              "singular): the motion is not driven with this period, or the drive is in "
                              f"resonance; residual {residual:.3g}")
        s = s - np.linalg.solve(jac, r)
    raise SpacarError(f"periodic_orbit: no periodic orbit within {max_iterations} Newton steps; the residuals "
                      f"max |Φ(s) − s| were {', '.join(f'{v:.3g}' for v in history)} (a better start q, qd, "
                      "or a tighter integration_tolerance)")

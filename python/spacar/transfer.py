"""Transfer functions of a mechanism: how its coordinates and deformations move with its inputs and
degrees of freedom, to first and second order (SPACAR's DF and D2F, docs/formulation.md §6).

    tf = spacar.transfer(model)              # at the model's current configuration
    tf.DF                                    # ∂x/∂q̂ (coordinates × q̂), q̂ = the inputs and DOFs
    tf.D2F                                   # ∂²x/∂q̂∂q̂ (coordinates × q̂ × q̂)
    tf.ratio((8, 1), ("x", 2, 1))            # velocity ratio ∂x(8, 1)/∂q̂ of the crank's input
    path = spacar.transfer_path(model, steps=72)   # the same along the block's input motion

q̂ holds the independent coordinates in SPACAR's order: the input coordinates, the coordinate DOFs
(DYNX), the input deformations, the deformation DOFs (DYNE); ``q_labels`` and ``is_input`` name
them. ẋ = DF q̂̇ and ẍ = DF q̂̈ + q̂̇ᵀ D2F q̂̇ (likewise ė, ë with DFe, D2Fe): the velocity and acceleration
ratios of a driven mechanism are the columns of DF and D2F of its input. The kinematic analysis
alone: no masses are needed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import _core
from ._util import show, time_limited
from .errors import InputError
from .model import Model

__all__ = ["Transfer", "TransferPath", "transfer", "transfer_path"]


def _q_labels(system) -> tuple:
    """(labels, is_input) of the independent coordinates q̂ in DF's column order: ("x", node,
    component) or ("e", element, deformation)."""
    inputs = [("x", *system.coord_label[g]) for g in system.x_input] + [("e", *system.def_label[k])
                                                                        for k in system.e_input]
    dofs = [("x", *system.coord_label[g]) for g in system.x_dyn] + [("e", *system.def_label[k]) for k in system.e_dyn]
    labels, is_input = [None] * system.n_qhat, [False] * system.n_qhat
    for col, label in zip(system.input_cols, inputs):
        labels[col], is_input[col] = tuple(int(v) if i else v for i, v in enumerate(label)), True
    for col, label in zip(system.dof_cols, dofs):
        labels[col] = tuple(int(v) if i else v for i, v in enumerate(label))
    return labels, is_input


@dataclass
class _Arrays:
    """The fields of Transfer and TransferPath (of one configuration, or stacked over a path)."""

    t: float | np.ndarray
    q: np.ndarray
    q_labels: list
    is_input: list
    x: np.ndarray
    e: np.ndarray
    DF: np.ndarray
    DFe: np.ndarray
    D2F: np.ndarray
    D2Fe: np.ndarray
    coordinate_labels: list
    deformation_labels: list


@dataclass
class Transfer(_Arrays):
    """The transfer functions at one configuration (:func:`transfer`).

    ``DF`` (nx × n), ``DFe`` (ne × n): ∂x/∂q̂ and ∂e/∂q̂; ``D2F`` (nx × n × n), ``D2Fe``
    (ne × n × n): the second derivatives, symmetric in their last two indices. q̂: the inputs
    (INPUTX, INPUTE) and the degrees of freedom in SPACAR's order (input coordinates, DYNX, input
    deformations, DYNE), labelled by ``q_labels`` ("x", node, component) or ("e", element,
    deformation), ``is_input`` telling which; ``q`` their values.
    ``x``, ``e``: the coordinates and deformations there, rows labelled by
    ``coordinate_labels`` (node, component) and ``deformation_labels`` (element, deformation),
    as in :class:`spacar.Results`."""

    def column(self, label) -> int:
        """The index in q̂ of ("x", node, component) or ("e", element, deformation)."""
        key = tuple(label)
        if key not in self.q_labels:
            raise InputError(f"{show(label)} is not an input or degree of freedom; q̂ is {self.q_labels}")
        return self.q_labels.index(key)

    def _row(self, output):
        """(DF or DFe, D2F or D2Fe, row) of an output: (node, component) or ("e", element, deformation)."""
        key = tuple(output)
        if len(key) == 3 and key[0] == "e":
            if key[1:] not in self.deformation_labels:
                raise InputError(f"element {key[1]} has no deformation {key[2]}")
            return self.DFe, self.D2Fe, self.deformation_labels.index(key[1:])
        if len(key) == 3 and key[0] == "x":
            key = key[1:]
        if key not in self.coordinate_labels:
            raise InputError(f"node {key[0]} has no coordinate {key[1]}" if len(key) == 2 else
                             f"an output is (node, component) or ('e', element, deformation), got {show(output)}")
        return self.DF, self.D2F, self.coordinate_labels.index(key)

    def ratio(self, output, wrt) -> float:
        """The velocity ratio ∂output/∂q̂_wrt (first order)."""
        first, _, row = self._row(output)
        return float(first[row, self.column(wrt)])

    def second(self, output, wrt, wrt2=None) -> float:
        """∂²output/∂q̂_wrt∂q̂_wrt2 (wrt2 defaults to wrt): the acceleration ratio of a single input
        driven at constant rate."""
        _, second, row = self._row(output)
        return float(second[row, self.column(wrt), self.column(wrt if wrt2 is None else wrt2)])


def _simulation(model, what):
    if not isinstance(model, Model):
        raise InputError(f"{what}: model must be a spacar.Model, got {show(model)}")
    sim = _core.Simulation(model.core)
    sim.assemble()
    return sim


def _transfer_here(sim, t, q, labels, is_input, coordinate_labels, deformation_labels) -> Transfer:
    sim.kinematic_state(t, q)
    d = sim.data
    n = len(labels)
    d2f, d2fe = sim.second_order_transfer()
    x, e = np.array(d.x), np.array(d.e)
    return Transfer(t=float(t), q=np.array(d.qhat), q_labels=labels, is_input=is_input, x=x, e=e,
                    DF=np.array(d.DF).reshape(len(x), n), DFe=np.array(d.DFe).reshape(len(e), n),
                    D2F=np.asarray(d2f).reshape(len(x), n, n), D2Fe=np.asarray(d2fe).reshape(len(e), n, n),
                    coordinate_labels=coordinate_labels, deformation_labels=deformation_labels)


def _labels(system):
    return ([tuple(int(v) for v in c) for c in system.coord_label],
            [tuple(int(v) for v in c) for c in system.def_label])


def _state(at, model, system):
    if at is None:
        return model.current_time, np.array(system.q0, dtype=float)
    try:
        t, q = at
        t = float(t)
        q = np.array(q, dtype=float).reshape(-1)
    except (TypeError, ValueError, OverflowError):
        raise InputError("transfer: at must be (t, q): a time and the degrees of freedom") from None
    if q.shape != (system.n_dof,) or not (np.isfinite(t) and np.isfinite(q).all()):
        raise InputError(f"transfer: at=(t, q) needs a finite time and {system.n_dof} finite DOF values")
    return t, q


def transfer(model, at=None, *, time_limit=None) -> Transfer:
    """The first- and second-order transfer functions of ``model`` (:class:`Transfer`).

    ``at``: None for the model's current configuration, or ``(t, q)``: the inputs at time t (their
    block motion) and the degrees of freedom q (in ``Results.dof_labels`` order); the mechanism
    is moved there from its assembled configuration in small steps, so that it stays on the
    assembled branch. Any model the kinematic analysis solves, closed loops included; no masses
    are needed. ``time_limit``: wall-clock seconds (:class:`spacar.TimeLimitError` beyond)."""
    with time_limited(time_limit, "in the transfer functions"):
        sim = _simulation(model, "transfer")
        system = sim.system
        t, q = _state(at, model, system)
        labels, is_input = _q_labels(system)
        coordinate_labels, deformation_labels = _labels(system)
        t0, q0 = model.current_time, np.array(system.q0, dtype=float)
        need = max(1.0, np.abs(q - q0).max(initial=0.0) / 0.1, abs(t - t0) / _time_step(model))
        if not need <= _MAX_STEPS:
            raise InputError(f"transfer: at=(t, q) is {need:.3g} continuation steps from the model's configuration, "
                             f"more than {_MAX_STEPS}; move the model nearer first (or give a TIMESTEP that spans t)")
        steps = int(math.ceil(need))
        for s in np.linspace(0.0, 1.0, steps + 1)[1:-1]:  # continuation: the first-order predictor's steps
            sim.kinematic_state(t0 + s * (t - t0), q0 + s * (q - q0))
        return _transfer_here(sim, t, q, labels, is_input, coordinate_labels, deformation_labels)


_MAX_STEPS = 100_000  # continuation steps from the assembled configuration to at=(t, q)


def _time_step(model) -> float:
    """A continuation step in time: a hundredth of the block (its inputs turn a crank by a few degrees)."""
    s = model.settings
    return max(s.timestep_tp / 100.0, 1e-12) if s.timestep_tp > 0 else 1.0


@dataclass
class TransferPath(_Arrays):
    """The transfer functions along a path (:func:`transfer_path`): ``t`` (m,), and per time the
    arrays of :class:`Transfer` stacked: ``q`` (m, n), ``x`` (m, nx), ``e`` (m, ne), ``DF`` (m, nx,
    n), ``DFe``, ``D2F`` (m, nx, n, n), ``D2Fe``; labels as in Transfer. ``at(k)`` is the
    Transfer of time k."""

    def at(self, k: int) -> Transfer:
        return Transfer(float(self.t[k]), self.q[k], self.q_labels, self.is_input, self.x[k], self.e[k], self.DF[k],
                        self.DFe[k], self.D2F[k], self.D2Fe[k], self.coordinate_labels, self.deformation_labels)

    def ratio(self, output, wrt) -> np.ndarray:
        """The velocity ratio ∂output/∂q̂_wrt at every time of the path."""
        return np.array([self.at(k).ratio(output, wrt) for k in range(len(self.t))])

    def second(self, output, wrt, wrt2=None) -> np.ndarray:
        """∂²output/∂q̂_wrt∂q̂_wrt2 at every time of the path."""
        return np.array([self.at(k).second(output, wrt, wrt2) for k in range(len(self.t))])

    def plot(self, output, wrt, ax=None):
        """The velocity ratio and the second-order ratio of ``output`` against the input ``wrt``
        along the path (matplotlib); returns the axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        column = self.at(0).column(wrt)
        ax.plot(self.q[:, column], self.ratio(output, wrt), label=f"∂{tuple(output)}/∂q̂ (velocity ratio)")
        ax.plot(self.q[:, column], self.second(output, wrt), label=f"∂²{tuple(output)}/∂q̂² (acceleration ratio)")
        ax.set_xlabel(f"{tuple(wrt)}")
        ax.legend()
        return ax


def transfer_path(model, steps: int = 72, *, t_end=None, time_limit=None) -> TransferPath:
    """The transfer functions of ``model`` along its inputs' motion: at ``steps`` + 1 equally
    spaced times from the model's current time to ``t_end`` (default the end of the current block,
    TIMESTEP), the degrees of freedom held at their current values: the kinematic analysis of a
    driven mechanism over a cycle (a crank turned by its INPUTX's XD), its velocity and
    acceleration ratios included. No masses are needed, the model is not changed."""
    if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or not 1 <= steps <= 10**6:
        raise InputError(f"transfer_path: steps must be a whole number from 1 to 10⁶, got {show(steps)}")
    with time_limited(time_limit, "in the transfer path"):
        sim = _simulation(model, "transfer_path")
        system = sim.system
        t0 = model.current_time
        if t_end is None:
            t_end = t0 + model.settings.timestep_tp
        try:
            t_end = float(t_end)
        except (TypeError, ValueError, OverflowError):
            raise InputError(f"transfer_path: t_end must be a number, got {show(t_end)}") from None
        if not np.isfinite(t_end):
            raise InputError("transfer_path: t_end must be finite")
        labels, is_input = _q_labels(system)
        coordinate_labels, deformation_labels = _labels(system)
        q = np.array(system.q0, dtype=float)
        times = np.linspace(t0, t_end, int(steps) + 1)
        per = [_transfer_here(sim, t, q, labels, is_input, coordinate_labels, deformation_labels) for t in times]
    stack = {name: np.array([getattr(p, name) for p in per]) for name in ("q", "x", "e", "DF", "DFe", "D2F", "D2Fe")}
    return TransferPath(t=times, q_labels=labels, is_input=is_input, coordinate_labels=coordinate_labels,
                        deformation_labels=deformation_labels, **stack)

"""Inverse dynamics: the generalized forces under which a model has given accelerations."""
from __future__ import annotations

import numpy as np

from . import _core
from ._util import show, time_limited
from .errors import InputError
from .model import Model


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
    ``time_limit``: wall-clock seconds it may take (:class:`spacar.TimeLimitError` beyond)."""
    if not isinstance(model, Model):
        raise InputError(f"inverse_dynamics: model must be a spacar.Model, got {show(model)}")
    arrays = []
    for name, value in (("q", q), ("qd", qd), ("qdd", qdd)):
        try:
            a = np.array(value, dtype=float)
        except (TypeError, ValueError, OverflowError):
            raise InputError(f"inverse_dynamics: {name} must be an array of numbers, got {show(value)}") from None
        if a.ndim not in (1, 2) or not np.isfinite(a).all():
            raise InputError(f"inverse_dynamics: {name} must be a finite vector or a matrix of states (one per row)")
        arrays.append(a)
    shape = arrays[0].shape
    if any(a.shape != shape for a in arrays):
        raise InputError(f"inverse_dynamics: q, qd and qdd must have the same shape, got "
                         f"{', '.join(str(a.shape) for a in arrays)}")
    with time_limited(time_limit, "in inverse_dynamics"):
        sim = _core.Simulation(model.core)  # prepares the model (the first END) and compiles it
        sim.assemble()
        rows = [np.ascontiguousarray(np.atleast_2d(a)) for a in arrays]
        force, _ = sim.inverse_dynamics(*rows)
    return np.asarray(force).reshape(shape)

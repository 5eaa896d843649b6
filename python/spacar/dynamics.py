"""Inverse dynamics: the generalized forces under which a model has given accelerations."""
from __future__ import annotations

import numpy as np

from . import _core
from ._util import show, time_limited
from .errors import InputError
from .model import Model


def _states(what, **arrays):
    """The arrays (q, qd, ...) as float arrays of one shape: a vector or a matrix of states."""
    out = []
    for name, value in arrays.items():
        try:
            a = np.array(value, dtype=float)
        except (TypeError, ValueError, OverflowError):
            raise InputError(f"{what}: {name} must be an array of numbers, got {show(value)}") from None
        if a.ndim not in (1, 2) or not np.isfinite(a).all():
            raise InputError(f"{what}: {name} must be a finite vector or a matrix of states (one per row)")
        out.append(a)
    if any(a.shape != out[0].shape for a in out):
        raise InputError(f"{what}: {', '.join(list(arrays)[:-1])} and {list(arrays)[-1]} must have the same shape, got "
                         f"{', '.join(str(a.shape) for a in out)}")
    return out


def dynamics_derivatives(model: Model, q, qd, tau, *, time_limit=None):
    """The forward dynamics and its derivatives, as ``pinocchio.computeABADerivatives``:
    ``(qdd, dqdd_dq, dqdd_dqd, dqdd_dtau)`` at the state (``q``, ``qd``) under the generalized
    forces ``tau`` on the DOFs beyond the model's own loads (those of :func:`inverse_dynamics`):
    q̈ (n), ∂q̈/∂q, ∂q̈/∂q̇ and ∂q̈/∂τ = M⁻¹ (n × n). ``q``, ``qd``, ``tau`` may be batches of states,
    one per row: the results then have a leading axis of states.

    Exact: ∂τ/∂q and ∂τ/∂q̇ analytic on spatial trees (passes over the tree in world axes) and
    from the recursive Newton–Euler algorithm on dual numbers on planar ones, and
    ∂q̈/∂(q, q̇) = −M⁻¹ ∂τ/∂(q, q̇), in C++ over the whole batch. For planar and spatial trees of
    rigid bodies on the recursive path (URDF robots, pendulums, branched linkages; formulation.md
    §7); other models raise InputError saying why they are not one. ``time_limit``: wall-clock
    seconds (:class:`spacar.TimeLimitError`)."""
    if not isinstance(model, Model):
        raise InputError(f"dynamics_derivatives: model must be a spacar.Model, got {show(model)}")
    q, qd, tau = _states("dynamics_derivatives", q=q, qd=qd, tau=tau)
    with time_limited(time_limit, "in dynamics_derivatives"):
        sim = _core.Simulation(model.core)
        sim.assemble()
        rows = [np.ascontiguousarray(np.atleast_2d(a)) for a in (q, qd, tau)]
        qdd, dq, dqd, dtau = sim.dynamics_derivatives(*rows)
    n = rows[0].shape[1]
    shape = q.shape[:-1]
    return (np.asarray(qdd).reshape(q.shape), *(np.asarray(m).reshape(shape + (n, n)) for m in (dq, dqd, dtau)))


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
    arrays = _states("inverse_dynamics", q=q, qd=qd, qdd=qdd)
    shape = arrays[0].shape
    with time_limited(time_limit, "in inverse_dynamics"):
        sim = _core.Simulation(model.core)  # prepares the model (the first END) and compiles it
        sim.assemble()
        rows = [np.ascontiguousarray(np.atleast_2d(a)) for a in arrays]
        force, _ = sim.inverse_dynamics(*rows)
    return np.asarray(force).reshape(shape)

"""Values over time for time-dependent loads and input motions (docs/mechatronics.md).

A :class:`Table` is interpolated in C++ at the time of every stage of the integrator, so a load
or an input motion given as a table costs no Python call during the run."""
from __future__ import annotations

import numpy as np

from . import _core
from ._util import finite_time, show
from .errors import InputError


class Table:
    """Samples ``values`` at the strictly increasing ``t``, interpolated by ``kind``:

    - ``"linear"``: straight lines between the samples (rates piecewise constant);
    - ``"cubic"``: the not-a-knot cubic spline (``scipy.interpolate.CubicSpline``'s default):
      continuous values, rates and second derivatives, exact for polynomials up to degree 3.

    ``values`` has one row per time: a 1-D array for one component (an input's position, the
    load of a node with one coordinate), else one column per component (e.g. a planar node's
    ``Fx, Fy``). Outside ``[t[0], t[-1]]`` the table holds its end values (rates zero).
    ``table(t, derivative=0)`` evaluates it (an array of the components; a float for one).
    """

    def __init__(self, t, values, kind: str = "cubic"):
        if not isinstance(kind, str) or kind not in ("linear", "cubic"):
            raise InputError(f"Table: kind must be 'linear' or 'cubic', got {show(kind)}")
        try:
            times = np.asarray(t, dtype=float)
            vals = np.asarray(values, dtype=float)
        except (TypeError, ValueError, OverflowError):  # OverflowError: an integer beyond double
            raise InputError("Table: t and values must be arrays of numbers") from None
        if times.ndim != 1:
            raise InputError(f"Table: t must be one-dimensional, got shape {times.shape}")
        self.scalar = vals.ndim == 1
        if self.scalar:
            vals = vals[:, None]
        if vals.ndim != 2:
            raise InputError(f"Table: values must have one row per time, got shape {np.shape(values)}")
        self.t, self.values, self.kind = times, vals, kind
        self.core = _core.Table(times, vals, kind)  # the C++ table (checks sizes, finiteness, increasing times)

    @property
    def components(self) -> int:
        return self.values.shape[1]

    def __call__(self, t, derivative: int = 0):
        if derivative not in (0, 1, 2):
            raise InputError(f"Table: derivative must be 0, 1 or 2, got {show(derivative)}")
        t = finite_time(t, "Table: the time")
        out = np.array([self.core(t, c, derivative) for c in range(self.components)])
        return float(out[0]) if self.scalar else out

    def __repr__(self):
        return f"Table({len(self.t)} samples on [{self.t[0]:g}, {self.t[-1]:g}], {self.components} component(s), {self.kind})"

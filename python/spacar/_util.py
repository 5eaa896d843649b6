"""Small helpers shared by the modules: safe texts of user values for messages, argument checks."""
from __future__ import annotations

import contextlib
import math
import numbers

from .errors import InputError


def show(value) -> str:
    """A short text of any value for an error message: huge integers cannot even be converted to
    text (Python refuses beyond 4300 digits), long values are cut, a failing repr is replaced."""
    if isinstance(value, numbers.Integral) and not isinstance(value, bool):
        try:
            if not -10**30 < value < 10**30:
                return f"an integer of {int(value).bit_length()} bits"
        except Exception:  # noqa: BLE001 - an Integral whose comparison fails
            pass
    try:
        text = repr(value)
    except Exception:  # noqa: BLE001 - any object may be passed; the message must not fail
        text = f"<{type(value).__name__}>"
    return text if len(text) <= 60 else text[:57] + "..."


def seconds_or_none(value, what: str):
    """A positive finite number of seconds (as float), or None."""
    if value is None:
        return None
    try:
        ok = isinstance(value, numbers.Real) and not isinstance(value, bool) and math.isfinite(value) and value > 0
    except (OverflowError, TypeError, ValueError):
        ok = False
    if not ok:
        raise InputError(f"{what} must be a positive number of seconds or None, got {show(value)}")
    return float(value)


def finite_time(value, what: str) -> float:
    """A time as a finite float; InputError naming ``what`` for anything else (a string, a tuple,
    an integer beyond double, NaN, infinity)."""
    try:
        t = float(value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{what} must be a number, got {show(value)}") from None
    if not math.isfinite(t):
        raise InputError(f"{what} must be a finite number, got {show(value)}")
    return t


@contextlib.contextmanager
def time_limited(time_limit, where: str):
    """The calls into the core made by this thread inside the block share a deadline of
    ``time_limit`` seconds (None: none), checked where the core checks a run's; a block that
    ends past it raises TimeLimitError naming ``where``."""
    from . import _core

    limit = seconds_or_none(time_limit, "time_limit") or 0.0
    with _core.Deadline(limit):
        yield
        _core.check_deadline(f"({where})")


def returned_loads(value, n: int, what: str, t: float):
    """The ``n`` finite numbers a user's function returned at time ``t`` as a float array, or an
    InputError naming ``what`` ("forces: the function of node 3") and the value (a string, a
    dict, a complex number, the wrong count, NaN)."""
    import numpy as np

    try:
        loads = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError, OverflowError):
        loads = None
    if loads is None or loads.shape != (n,) or not np.isfinite(loads).all():
        raise InputError(f"{what} must return {n} finite number{'s' if n != 1 else ''}, got {show(value)} "
                         f"at t = {t:g}")
    return loads

"""Exceptions of spacar. They are created by the C++ core (``spacar._core``), so an error raised
in C++ arrives in Python as exactly these classes.

An analysis that fails midway (:func:`spacar.simulate`) raises its error with the results computed
until the failure as the attribute ``results`` (a :class:`spacar.Results` with the output times
recorded so far; possibly none).

Every element type of the catalogue has its physics, so there is no spacar error for a missing
one (an earlier ``spacar.NotImplementedError`` shadowed Python's builtin of that name).

- :class:`SpacarError` — base class of every spacar error.
- :class:`InputError` — invalid input; from the reader it names file, line and keyword.
- :class:`KinematicsError` — the kinematic analysis cannot be solved.
- :class:`SingularMassError` — a degree of freedom without inertia.
- :class:`IntegrationError` — the integrator cannot continue.
- :class:`TimeLimitError` — the analysis did not finish within its ``time_limit``.
- :class:`StaticError` — no static equilibrium was found (:func:`spacar.static`); ``err.results``
  holds the load steps converged before the failure.
"""
from ._core import (  # noqa: F401
    InputError,
    IntegrationError,
    KinematicsError,
    SingularMassError,
    SpacarError,
    StaticError,
    TimeLimitError,
)

__all__ = [
    "SpacarError",
    "InputError",
    "KinematicsError",
    "SingularMassError",
    "IntegrationError",
    "TimeLimitError",
    "StaticError",
]

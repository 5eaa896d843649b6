"""Exceptions of spacar. They are created by the C++ core (``spacar._core``), so an error raised
in C++ arrives in Python as exactly these classes.

An analysis that fails midway (:func:`spacar.simulate`) raises its error with the results computed
until the failure as the attribute ``results`` (a :class:`spacar.Results` with the output times
recorded so far; possibly none).

- :class:`SpacarError` — base class of every spacar error.
- :class:`InputError` — invalid input; from the reader it names file, line and keyword.
- :class:`KinematicsError` — the kinematic analysis cannot be solved.
- :class:`SingularMassError` — a degree of freedom without inertia.
- :class:`IntegrationError` — the integrator cannot continue.
- :class:`TimeLimitError` — the analysis did not finish within its ``time_limit``.
- :class:`NotImplementedError` — a specified element type whose physics is not available yet.
"""
from ._core import (  # noqa: F401
    InputError,
    IntegrationError,
    KinematicsError,
    NotImplementedError,
    SingularMassError,
    SpacarError,
    TimeLimitError,
)

__all__ = [
    "SpacarError",
    "InputError",
    "KinematicsError",
    "SingularMassError",
    "IntegrationError",
    "TimeLimitError",
    "NotImplementedError",
]

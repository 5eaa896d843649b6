"""spacar: finite-element kinematic and dynamic analysis of multibody systems with rigid and
flexible links — a modern reimplementation of SPACAR95 (Schwab & Meijaard, TU Delft).

Quick start::

    import spacar
    model = spacar.read("examples/slidercrank.dat")   # the manual's slider-crank
    res = spacar.simulate(model)                      # integrates the first block
    print(res.node(8).x[-1])                          # slider position at t = 5 s
    print(model.dump())                               # the restartable state dump
"""
from . import _core
from .check import Check, Diagnosis, Summary, check, summary
from .errors import (
    InputError,
    IntegrationError,
    KinematicsError,
    NotImplementedError,
    SingularMassError,
    SpacarError,
)
from .io.reader import parse, read, read_string
from .io.writer import dump
from .keywords import KEYWORDS
from .linearize import Linearization, linearize
from .model import Model
from .results import Results
from .simulate import simulate

__version__ = "0.1.0"


def element_catalogue():
    """The element catalogue (one entry per element type), from the C++ core."""
    return list(_core.element_catalogue())


__all__ = [
    "Model",
    "Results",
    "Summary",
    "KEYWORDS",
    "read",
    "read_string",
    "parse",
    "dump",
    "simulate",
    "linearize",
    "Linearization",
    "summary",
    "element_catalogue",
    "SpacarError",
    "InputError",
    "KinematicsError",
    "SingularMassError",
    "IntegrationError",
    "NotImplementedError",
]

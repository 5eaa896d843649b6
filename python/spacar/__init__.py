"""spacar: finite-element kinematic and dynamic analysis of multibody systems with rigid and
flexible links — a modern reimplementation of SPACAR95 (Schwab & Meijaard, TU Delft).

Quick start::

    import spacar
    model = spacar.read("examples/slidercrank.dat")   # the manual's slider-crank
    res = spacar.simulate(model)                      # integrates the first block
    print(res.node(8).x[-1])                          # slider position at t = 5 s
    print(model.dump())                               # the restartable state dump
    spacar.plot(res, "e(2,2)")                        # matplotlib (imported when first used)
    spacar.animate(res)                               # an animation, inline in Jupyter

``import spacar`` stays light: matplotlib, pandas and tqdm are imported only by the functions
that use them (``plot``, ``draw``, ``animate``, ``save_animation``; ``Results.to_pandas``; the
progress bar).
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
from .geometry import Geometry
from .results import Results
from .simulate import simulate

__version__ = "0.1.0"


def element_catalogue():
    """The element catalogue (one entry per element type), from the C++ core."""
    return list(_core.element_catalogue())


_LAZY = {
    "plot": ("plotting", "plot"),
    "draw": ("plotting", "draw"),
    "animate": ("animation", "animate"),
    "save_animation": ("animation", "save_animation"),
}


def __getattr__(name):
    # The plotting functions import matplotlib: only when first used (PEP 562).
    if name in _LAZY:
        import importlib

        module, attr = _LAZY[name]
        value = getattr(importlib.import_module(f".{module}", __name__), attr)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + list(_LAZY))


__all__ = [
    "Model",
    "Results",
    "Geometry",
    "plot",
    "draw",
    "animate",
    "save_animation",
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
    "check",
    "Check",
    "Diagnosis",
    "element_catalogue",
    "SpacarError",
    "InputError",
    "KinematicsError",
    "SingularMassError",
    "IntegrationError",
    "NotImplementedError",
]

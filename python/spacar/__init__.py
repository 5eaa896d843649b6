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
that use them (``plot``, ``draw``, ``animate``, ``animate_mode``, ``save_animation``, ``explore``;
``Results.to_pandas``; the progress bar).
"""
from . import _core
from ._util import show as _show
from . import flexure, mechanism, notebook, section, sensitivity
from .check import Check, Diagnosis, Summary, check, summary
from .compliance import compliance, support_stiffness
from .control import Controller
from .dynamics import Dynamics, dynamics_derivatives, inverse_dynamics
from .energy import Energy
from .table import Table
from .errors import (
    InputError,
    IntegrationError,
    KinematicsError,
    SingularMassError,
    SpacarError,
    TimeLimitError,
)
from .io.reader import parse, read, read_string
from .io.writer import dump
from .keywords import KEYWORDS
from .linearize import Linearization, linearize
from .model import Model
from .geometry import Geometry
from .results import Results
from .rollout import Rollout, RolloutResults
from .simulate import simulate
from .spacar_light import LightResults, light, light_model
from .statics import StaticError, StaticSolver, static
from .statespace import StateSpace, state_space
from .sweep import SweepError, SweepResult, sweep
from .periodic import PeriodicOrbit, floquet, periodic_orbit
from .transfer import Transfer, TransferPath, transfer, transfer_path
from .urdf import from_urdf

__version__ = "0.1.0"


def memory_limit() -> int:
    """Bytes one analysis may allocate for its work and result arrays (default 4 GiB). Inputs
    that would need more (e.g. ``TIMESTEP 10000000 1`` on a large model) are refused with an
    :class:`InputError` before anything is allocated."""
    return _core.memory_limit()


def set_memory_limit(nbytes: int) -> None:
    """Set the limit of :func:`memory_limit` for this process."""
    if isinstance(nbytes, bool) or not isinstance(nbytes, int) or not 0 < nbytes < 2**63:
        raise InputError(f"the memory limit must be a positive number of bytes, got {_show(nbytes)}")
    _core.set_memory_limit(nbytes)


def element_catalogue():
    """The element catalogue (one entry per element type), from the C++ core."""
    return list(_core.element_catalogue())


_LAZY = {
    "plot": ("plotting", "plot"),
    "draw": ("plotting", "draw"),
    "animate": ("animation", "animate"),
    "save_animation": ("animation", "save_animation"),
    "animate_mode": ("animation", "animate_mode"),
    "explore": ("interactive", "explore"),
    "view3d": ("interactive", "view3d"),
}


def __getattr__(name):
    # The plotting functions import matplotlib (explore also ipywidgets): only when first used (PEP 562).
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
    "Table",
    "Controller",
    "Energy",
    "Results",
    "Geometry",
    "plot",
    "draw",
    "animate",
    "save_animation",
    "animate_mode",
    "explore",
    "view3d",
    "Summary",
    "KEYWORDS",
    "read",
    "read_string",
    "from_urdf",
    "parse",
    "dump",
    "simulate",
    "Rollout",
    "RolloutResults",
    "inverse_dynamics",
    "dynamics_derivatives",
    "Dynamics",
    "static",
    "StaticSolver",
    "StaticError",
    "compliance",
    "support_stiffness",
    "section",
    "sensitivity",
    "flexure",
    "light",
    "light_model",
    "LightResults",
    "mechanism",
    "sweep",
    "SweepResult",
    "SweepError",
    "linearize",
    "Linearization",
    "state_space",
    "StateSpace",
    "transfer",
    "transfer_path",
    "Transfer",
    "TransferPath",
    "periodic_orbit",
    "floquet",
    "PeriodicOrbit",
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
    "TimeLimitError",
    "memory_limit",
    "set_memory_limit",
]

"""Running an analysis block from Python."""
from __future__ import annotations

import re
import threading
import time
import weakref
import functools
from types import SimpleNamespace

import numpy as np

from . import _core
from ._util import returned_loads, seconds_or_none, show
from .errors import InputError, KinematicsError, SpacarError
from .io.matasc import MatascWriter, default_stem
from .linearize import Linearization
from .model import Model
from .results import KeptModel, Results, dof_labels
from .table import Table
from .control import Controller
from .energy import Energy


def _method_used(arrays: dict) -> str:
    """The integrator(s) of the block: "dop853", or with switches (method "auto") e.g.
    "auto: dop853→radau5 at t=0.0123"."""
    if not arrays["switches"]:
        return arrays["method"]
    return "auto: " + arrays["method"] + "".join(f"→{to} at t={t:.6g}" for t, _, to in arrays["switches"])


def _results(arrays: dict, system, model, method: str = "dop853") -> Results:
    # The counters of the core's table (kRunCounters); those of the implicit methods' work
    # (Jacobians, i.e. linearizations, and LU factorizations) where one ran.
    implicit = method in _core.implicit_methods or bool(arrays["switches"])
    stats = {k: arrays[k] for k, implicit_only in _core.run_counters if implicit or not implicit_only}
    stats.update(wall_time=arrays["wall_time"], recursive=arrays["recursive"], path=arrays["path"])
    stats["method"] = _method_used(arrays)
    stats["switches"] = [tuple(s) for s in arrays["switches"]]
    # The labels as (n, 2) arrays, one conversion each (a list is a Python pair per label), taken
    # once; the results make their lookups from them when first used.
    coords, defs = system.coord_label_array, system.def_label_array
    lins = arrays["linearizations"]
    if lins:  # each takes the labels as Python pairs: converted once
        coord_list, def_list = coords.tolist(), defs.tolist()
        lins = [Linearization(d, coord_list, def_list) for d in lins]
    res = Results(arrays, coords, defs, stats, None, lins, model.settings.linear)
    res._geometry_source = core = KeptModel(model)  # res.geometry is built from it when first used
    res.shapes = getattr(model, "urdf_shapes", None)  # a URDF robot's link shapes, for spacar.view3d
    # The DOF labels, when first asked for, from the compiled system's lists and the copy.
    dofs = SimpleNamespace(x_dyn=system.x_dyn, e_dyn=system.e_dyn)
    res._set_dofs(functools.partial(dof_labels, dofs, core, coords, defs))
    if "energy" in arrays:
        res._energy = Energy(res.t, arrays["energy"])
    return res


def _node_coordinates(labels) -> dict:
    """node → its global coordinate indices, in component order."""
    out: dict = {}
    for g, (n, _) in enumerate(labels):
        out.setdefault(int(n), []).append(g)
    return out


def _time_loads(sim, system, forces, inputs):
    """Hand the time-dependent loads and input motions to the core: tables as C++ tables, the
    callables as one Python function of t called at every right-hand side."""
    labels = [(int(n), int(i)) for n, i in system.coord_label]
    nodes = _node_coordinates(labels)
    if not isinstance(forces, dict) or not isinstance(inputs, dict):
        raise InputError("forces and inputs must be dicts: forces={node: Table or f(t)}, inputs={(node, i): Table}")
    tables, functions = [], []
    for node, f in forces.items():
        if node not in nodes:
            raise InputError(f"forces: node {show(node)} is not a node of the model")
        coords = nodes[node]
        if isinstance(f, Table):
            if f.components != len(coords):
                raise InputError(f"forces: node {node} has {len(coords)} coordinates, its table {f.components} "
                                 f"components (one per FORCE value)")
            tables.append((coords, f.core))
        elif callable(f):
            functions.append((np.array(coords), f, node))
        else:
            raise InputError(f"forces: node {node} needs a spacar.Table or a function f(t), got {show(f)}")
    index = {lbl: g for g, lbl in enumerate(labels)}
    deformations = {(int(e), int(k)): j for j, (e, k) in enumerate(system.def_label)}
    x_input, e_input = list(system.x_input), list(system.e_input)
    motions = []
    for key, table in inputs.items():
        # An input's index in the core: the INPUTX coordinates first, then the INPUTE deformations.
        if isinstance(key, tuple) and len(key) == 3 and key[0] == "e":
            name = f"e{key[1:]}"
            k = deformations.get(tuple(key[1:]))
            if k is None or k not in e_input:
                raise InputError(f"inputs: {name} is not an input deformation (INPUTE)")
            number = len(x_input) + e_input.index(k)
        elif isinstance(key, tuple) and len(key) == 2 and tuple(key) in index:
            name = f"x{key}"
            g = index[tuple(key)]
            if g not in x_input:
                raise InputError(f"inputs: {name} is not an input coordinate (INPUTX)")
            number = x_input.index(g)
        else:
            raise InputError(f"inputs: {show(key)} is neither a (node, coordinate) nor an ('e', element, "
                             f"deformation) of the model")
        if not isinstance(table, Table) or table.components != 1:
            raise InputError(f"inputs: {name} needs a spacar.Table of one component (the position)")
        motions.append((number, table.core))
    load_function = None
    if functions:
        nx = len(labels)

        def load_function(t):
            load = np.zeros(nx)
            for coords, f, node in functions:
                load[coords] += returned_loads(f(t), len(coords),
                                               f"forces: the function of node {node} (one value per FORCE value)", t)
            return load
    sim.set_time_loads(tables, motions, load_function)


def _dead_position_hint(err, res, system, model) -> str:
    """For a kinematic Newton failure after some output times: the inputs at the last position
    solved and where they were heading, with the usual cause — the mechanism passed a dead
    (limit, toggle) position — and the Grashof condition of a four-bar's crank."""
    failed = re.search(r"did not converge .*?at t = ([-+0-9.eE]+)", str(err))
    if failed is None or res is None or len(res.t) == 0:
        return ""
    t, t0 = float(failed.group(1)), model.current_time
    reached, heading = [], []
    for (n, i), cls, value in zip(system.coord_label, system.coord_class, res.x[-1]):
        if cls.name == "input":
            node = model.nodes[n]
            reached.append(f"node {n} x{i} = {value:.6g}")
            dt = t - t0
            heading.append(f"{node.x[i - 1] + node.xd[i - 1] * dt + 0.5 * node.xdd[i - 1] * dt * dt:.6g}")
    for (e, i), cls, value in zip(system.def_label, system.def_class, res.e[-1]):
        if cls.name == "input":
            reached.append(f"element {e} e{i} = {value:.6g}")
    if not reached:
        return ""
    towards = f" (heading for {', '.join(heading)} at t = {t:.6g})" if len(heading) == len(reached) else ""
    return (f"\nThe last position solved: t = {res.t[-1]:.6g}, inputs {', '.join(reached)}{towards}. "
            "If the mechanism has no position beyond it, the inputs drove it into a dead (limit) "
            "position, where the driven link lines up with the link it drives (a toggle): a four-bar's "
            "crank turns fully only if it is the shortest link and shortest + longest <= the sum of the "
            "other two (Grashof). Check the link lengths, or keep the input within its range.")


class _Runs:
    """A model's runs. One at a time (issue 38): a run starts from the model's state and leaves its
    end state in it, so threads simulating the same model started at the same time and blocks were
    lost (six threads of one 5 s run each left the manual's slider-crank at t = 10, not 30); a run
    now waits for the one before and continues from its end, as runs one after the other do. And
    the simulation of the last run, when it took the recursive path: the next run of the unchanged
    model renews it instead of compiling the model and recognizing its tree again (issue 37)."""

    __slots__ = ("lock", "simulation")

    def __init__(self):
        self.lock = threading.RLock()
        self.simulation = None

    def take_simulation(self, model: Model, time_limit: float):
        """The kept simulation renewed for the model's next block, or a new one (which prepares
        the model, at its first END, and compiles it)."""
        sim, self.simulation = self.simulation, None
        if sim is not None and sim.renew():
            return sim
        return _core.Simulation(model.core, time_limit=time_limit)


_RUNS_GUARD = threading.Lock()
_RUNS: "weakref.WeakKeyDictionary[Model, _Runs]" = weakref.WeakKeyDictionary()


def _runs(model: Model) -> _Runs:
    with _RUNS_GUARD:
        runs = _RUNS.get(model)
        if runs is None:
            runs = _RUNS[model] = _Runs()
        return runs


def check_method_options(method, rho_inf, fixed_step, recursive) -> float:
    """Refuse what the integration options cannot be (before any work); the fixed step (0: none)."""
    if not isinstance(method, str):
        implicit = _core.implicit_methods
        explicit = [m for m in _core.integration_methods if m not in implicit and m != "auto"]
        raise InputError(f"method must be {' or '.join(map(repr, explicit))} (explicit), "
                         f"{' or '.join(map(repr, implicit))} (implicit) or 'auto', got {show(method)}")
    if rho_inf is not None and (isinstance(rho_inf, (bool, np.bool_))
                                or not isinstance(rho_inf, (int, float, np.number)) or not 0.0 <= rho_inf <= 1.0):
        raise InputError(f"rho_inf (the spectral radius of generalized_alpha) must be a number in [0, 1], "
                         f"got {show(rho_inf)}")
    step_size = seconds_or_none(fixed_step, "fixed_step") or 0.0
    for name, given in (("fixed_step", step_size), ("rho_inf", rho_inf is not None)):
        if given and method != "generalized_alpha":
            raise InputError(f"{name} is an option of method 'generalized_alpha' only, not of {show(method)}")
    if not isinstance(recursive, (bool, np.bool_)):
        raise InputError(f"recursive must be True or False, got {show(recursive)}")
    return step_size


def simulate(model, *, method: str = "auto", on_output=None, progress=None, output_stem=None,
             time_limit=None, recursive: bool = True, forces=None, inputs=None, controller=None,
             energy: bool = False, rho_inf=None, fixed_step=None) -> Results:
    """Run the analysis of the model's current block, as SPACAR does at an END.

    The mechanism is assembled at the current time; with degrees of freedom the reduced
    equations of motion are integrated over the TIMESTEP period (in C++, with the EPSINT /
    EPSIND error control), otherwise the kinematic analysis runs at every output time. The state
    reached is stored in the model (see :meth:`spacar.Model.dump`).

    ``on_output(k, state)`` is called after output time k is recorded, with ``state`` a dict of
    NumPy arrays ``t, x, xd, xdd, e, ed, edd, sigma, reaction`` (progress, files written as the
    run proceeds). It runs at output times only, never inside the integration.

    ``progress``: a tqdm bar over simulated time; ``None`` shows it in interactive sessions for
    runs longer than a second, ``True`` always, ``False`` never (see :mod:`spacar.progress`).

    With ``MATASC 1`` the output times also go to the MATASC files ``<stem>_x.asc``, ...
    (docs/matasc.md), line by line as the run proceeds; the stem is ``output_stem``, else
    ``model.output_stem``, else the input file name without extension, else ``spacar``.

    ``method``: ``"auto"`` (default: DOP853 until it detects stiffness, then radau5 until the
    stiffness goes; docs/stiff-integration.md), ``"dop853"``, ``"dopri5"``, ``"radau5"``
    (implicit Radau IIA of order 5 for stiff systems, its Newton matrix from the linearized
    equations) or ``"generalized_alpha"`` (implicit, second order, one right-hand side per Newton
    iteration, the positions under error control; for flexible links at loose tolerances, with
    ``rho_inf`` its spectral radius at infinite frequency (default 0.9): 1 keeps every mode's amplitude, smaller
    values damp the highest modes; ``fixed_step``: steps of this size without error control,
    EPSINT/EPSIND then only stop its Newton iterations). The implicit methods add ``jacobians``
    and ``decompositions`` to ``res.stats``, as does a switch.
    ``res.stats["method"]`` names the integrator(s) used (``"dop853"``, ``"radau5"``,
    ``"auto: dop853→radau5 at t=0.0123"``), ``res.stats["switches"]`` lists the changes as
    ``(t, from, to)``.

    ``time_limit``: wall-clock seconds the block may take, the model's set-up included (None: no
    limit); beyond it :class:`spacar.TimeLimitError`.

    ``recursive``: planar and spatial open trees of rigid bodies (rigid PLBEAMs joined by
    PLHINGEs, or rigid BEAMs joined by HINGEs, whose rotations are the degrees of freedom)
    integrate with the articulated-body algorithm in the hinge angles instead of the constraint
    formulation (the same equations, several times
    cheaper per right-hand side; at the output times the positions and velocities are solved
    by the general path, the accelerations and stresses from the tree's q̈). ``False``
    always takes the general path. ``res.stats["recursive"]`` says which path ran.

    Time-dependent loads and inputs (docs/mechatronics.md): ``forces={node: f}`` adds to the
    node's FORCE values either a :class:`spacar.Table` (interpolated in C++ at every stage, no
    Python during the run) or a function ``f(t)`` returning them (called once per right-hand
    side: 12 calls per DOP853 step). ``inputs={(node, i): table}`` prescribes the motion of an
    INPUTX coordinate by a table of its position, the rate and acceleration from the table's
    derivatives (a cubic table has continuous accelerations), instead of the block's constant
    acceleration; ``inputs={("e", e, i): table}`` likewise an INPUTE deformation.
    ``controller``: a :class:`spacar.Controller`, sampled at its rate with its actuator loads
    held between samples. These runs take the general path (not ``recursive``).

    ``energy=True``: ``res.energy`` (a :class:`spacar.energy.Energy`) holds the kinetic,
    potential, strain energy, the dissipated work and the external work at the output times;
    the two works are integrated as extra states of the integrator.

    Returns :class:`spacar.Results` (with ``res.geometry`` for drawing). If the analysis fails
    midway, the :class:`spacar.SpacarError` raised carries the results up to the failure as
    ``err.results`` (a :class:`spacar.Results` with the output times recorded before the failure,
    possibly none; the MATASC files hold the same times); the model's state is then left as it
    was before the block. Ctrl-C (from the main thread) interrupts the run within about 20 ms:
    ``KeyboardInterrupt`` carries the results so far as ``err.results`` in the same way.
    """
    from . import __version__, progress as _progress

    if not isinstance(model, Model):
        raise InputError(f"simulate: model must be a spacar.Model, got {show(model)}")
    limit = seconds_or_none(time_limit, "time_limit") or 0.0
    if on_output is not None and not callable(on_output):
        raise InputError(f"on_output must be a function on_output(k, state) or None, got {show(on_output)}")
    step_size = check_method_options(method, rho_inf, fixed_step, recursive)
    if not isinstance(energy, (bool, np.bool_)):
        raise InputError(f"energy must be True or False, got {show(energy)}")
    if controller is not None and not isinstance(controller, Controller):
        raise InputError(f"controller must be a spacar.Controller or None, got {show(controller)}")
    runs = _runs(model)
    with runs.lock:  # one run at a time on a model: each starts where the last ended
        started = time.monotonic()   # the time limit covers the set-up too
        sim = runs.take_simulation(model, limit)
        system = sim.system
        for name, value in (("forces", forces), ("inputs", inputs)):
            if value is not None and not isinstance(value, dict):  # before its truth value (an array has none)
                raise InputError(f"{name} must be a dict: forces={{node: Table or f(t)}}, inputs={{(node, i): Table}}, "
                                 f"got {show(value)}")
        if forces or inputs:
            _time_loads(sim, system, forces or {}, inputs or {})
        on_sample, finish_sampling = (None, None) if controller is None else controller._bind(system.coord_label)
        settings = model.core.settings
        callbacks = []
        writer = None
        if settings.matasc == 1:
            stem = output_stem if output_stem is not None else default_stem(model)
            writer = MatascWriter(stem, source=model.source, jobid=settings.jobid, version=__version__,
                                  coordinate_labels=system.coord_label, deformation_labels=system.def_label,
                                  coordinate_classes=[c.name for c in system.coord_class],
                                  forcemode=settings.forcemode, created=model._matasc_files)
            def write(k, state, writer=writer, mode=settings.linear):
                writer.write(k, state)
                if "linearization" in state:
                    writer.write_linearization(Linearization(state["linearization"], system.coord_label,
                                                             system.def_label), mode)
            callbacks.append(write)
        bar = _progress.make(progress, model.current_time, settings.timestep_tp)
        if bar is not None:
            callbacks.append(bar)
        if on_output is not None:
            callbacks.append(on_output)
        if not callbacks:
            callback = None
        elif len(callbacks) == 1:
            callback = callbacks[0]
        else:
            def callback(k, state):
                for c in callbacks:
                    c(k, state)

        restart = settings.restart == 1
        step = 0.0 if restart else model._continue_step
        try:
            arrays = sim.run(on_output=callback, initial_step=step, method=method, time_limit=limit,
                             recursive=bool(recursive),  # numpy booleans too
                             sample_period=0.0 if controller is None else 1.0 / controller.rate,
                             on_sample=on_sample, energy=bool(energy), rho_inf=_core.run_defaults["rho_inf"] if rho_inf is None else float(rho_inf),
                             fixed_step=step_size, time_spent=time.monotonic() - started)
        except KeyboardInterrupt as err:  # Ctrl-C inside the run: the rows done, as after a failure
            if isinstance(getattr(err, "results", None), dict):
                err.results = _results(err.results, sim.system, model, method)
            raise
        except SpacarError as err:
            partial = getattr(err, "results", None)
            if isinstance(partial, dict):
                model.warnings.extend(w for w in partial["warnings"] if w not in model.warnings)
                err.results = _results(partial, sim.system, model, method)
            hint = _dead_position_hint(err, getattr(err, "results", None), sim.system, model) \
                if isinstance(err, KinematicsError) and not inputs else ""
            if hint:
                explained = KinematicsError(f"{err}{hint}")
                explained.results = err.results
                raise explained from err
            raise
        finally:
            if finish_sampling is not None:
                finish_sampling()
            if writer is not None:
                writer.close()
            if bar is not None:
                bar.close()
        model._continue_step = arrays["last_step"]
        model.warnings.extend(w for w in arrays["warnings"] if w not in model.warnings)
        if sim.renewable:  # a run on an open tree that nothing else changed the model during
            runs.simulation = sim
        return _results(arrays, sim.system, model, method)

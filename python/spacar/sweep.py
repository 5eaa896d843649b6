"""Parameter studies: many analyses of one model over a grid or a sample of parameter values, in
parallel processes (default), on a Dask cluster, or serially, gathered into NumPy arrays.

A parameter is named like the input line it replaces, keyword and identifying numbers::

    spacar.sweep("examples/slidercrank.dat", {
        "XD 2 1": [1.0, 1.5, 2.0],                       # crank speed: XD n i x
        ("ESTIFF 2", "ESTIFF 3"): [(0.0, k) for k in (1e-3, 2e-3)],   # both rod elements
    })

Each case is a copy of the model with those lines applied after its own input lines (before
its END), as if the input file had said so; then the analysis runs (``"simulate"``: the current
block, ``"linearize"``: the linearized equations at the current state) and the requested
outputs are kept. Anything a keyword cannot express is a factory: ``sweep(make_model, {...})``
calls ``make_model(params)`` with the case's parameters and analyses the model it returns.

See docs/sweep.md.
"""
from __future__ import annotations

import concurrent.futures
import contextlib
import itertools
import math
import multiprocessing
import numbers
import os
import pickle
import sys
import threading
import time
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from . import _core, progress as bars  # named so: sweep()'s argument is `progress`
from .results import _ARRAYS
from ._util import seconds_or_none, show, time_limited
from .errors import InputError, SpacarError
from .keywords import INT, LOOKUP, SETTINGS, Keyword, did_you_mean
from .model import Model, check_args

__all__ = ["sweep", "SweepResult", "SweepError"]

# Keyword groups whose lines are values that a later line replaces. Element, boundary-condition
# and control lines change the model's structure or accumulate: use a factory for those.
_SWEEPABLE_GROUPS = ("Nodes (§5.2)", "Initial values (§5.4)", "Dynamic properties (§5.5)", SETTINGS)

RESULT_ARRAYS = _ARRAYS  # t and the core's output arrays
LINEARIZATION_OUTPUTS = ("eigenfrequencies", "eigenvalues", "buckling_factors", "M0", "C0", "D0", "K0", "N0",
                         "G0", "r0", "stiffness", "damping")


class SweepError(NamedTuple):
    """A failed case: its index, its parameters, the exception's type name and message."""

    index: int
    parameters: dict
    type: str
    message: str


# --- parameters ---------------------------------------------------------------------------------

@dataclass(frozen=True)
class _Line:
    """A parameter that replaces the values of a keyword line: ``keyword ids... values...``."""

    key: str
    keyword: Keyword
    ids: tuple

    def arguments(self, value) -> tuple:
        several = isinstance(value, (tuple, list)) or (isinstance(value, np.ndarray) and value.ndim > 0)
        values = tuple(value) if several else (value,)
        return (*self.ids, *values)


def _identifiers(kw: Keyword) -> int:
    """How many leading numbers identify a line of this keyword (node, element, component)."""
    if kw.group == SETTINGS:
        return 0
    n = 0
    for p in kw.params:
        if p.kind != INT or p.count_min != 1 or p.count_max != 1:
            break
        n += 1
    return n


def _parse_line_key(key: str) -> _Line:
    words = key.split()
    if not words:
        raise InputError(f"sweep parameter {show(key)}: empty")
    kw = LOOKUP.get(words[0].upper()[:8])
    if kw is None:
        raise InputError(f"sweep parameter {show(key)}: unknown keyword {show(words[0])}{did_you_mean(words[0])}")
    if kw.group not in _SWEEPABLE_GROUPS:
        raise InputError(f"sweep parameter {show(key)}: {kw.name} lines define the model's structure and cannot "
                         "be replaced by value; use a factory function (sweep(make_model, ...))")
    n_ids = _identifiers(kw)
    names = " ".join(p.name for p in kw.params[:n_ids])
    if len(words) - 1 != n_ids:
        what = f"{kw.name} {names}" if n_ids else kw.name
        raise InputError(f"sweep parameter {show(key)}: a {kw.name} line is named by {show(what)} "
                         f"({n_ids} number{'s' if n_ids != 1 else ''} after the keyword)")
    try:
        ids = tuple(int(w) for w in words[1:])
    except ValueError:
        raise InputError(f"sweep parameter {show(key)}: {names} must be integers") from None
    return _Line(key, kw, ids)


def _lines_of(key) -> tuple:
    if isinstance(key, str):
        return (_parse_line_key(key),)
    if isinstance(key, tuple) and key and all(isinstance(k, str) for k in key):
        return tuple(_parse_line_key(k) for k in key)
    raise InputError(f"sweep parameter {show(key)}: a keyword line such as 'ESTIFF 2' or a tuple of them")


def _name(key) -> str:
    if isinstance(key, str):
        return key
    if isinstance(key, tuple) and key and all(isinstance(k, str) for k in key):
        return " & ".join(key)
    raise InputError(f"sweep parameter {show(key)}: name it by a string (an input line such as 'ESTIFF 2', or any "
                     "name for a factory) or a tuple of input lines")


def _check_value(key, lines, value):
    """Refuse a value that no model could take (wrong type or count, NaN, infinity) at once."""
    for line in lines:
        try:
            check_args(line.keyword, line.arguments(value))
        except InputError as err:
            raise InputError(f"sweep parameter {show(_name(key))} = {show(value)}: {err}") from None


# Bytes a case holds at least while a sweep runs, before its outputs: its parameters' dict, its
# index and chunk entries, its outcome (its outputs come on top: 6.6 kB per case in all for the
# slider-crank's final state, measured with tracemalloc).
_CASE_BYTES = 500
_PARAMETER_BYTES = 100


def _check_size(n_cases: int, n_parameters: int):
    """Refuse a grid whose cases alone would exceed the memory limit, before building it."""
    from . import memory_limit

    need = n_cases * (_CASE_BYTES + _PARAMETER_BYTES * n_parameters)
    if need > memory_limit():
        raise InputError(f"sweep: a grid of {n_cases:,} cases would need at least {need / 1e9:.3g} GB to hold its "
                         f"cases and outcomes, more than the memory limit of {memory_limit() / 1e9:.3g} GB "
                         "(spacar.set_memory_limit); sweep fewer values, a sample (a list of dicts), or in parts")


def _cases(parameters, by_lines: bool):
    """(names, cases as dicts name → value, grid axes or None)."""
    if isinstance(parameters, dict):
        if not parameters:
            raise InputError("sweep: no parameters")
        names, axes = [], []
        for key, values in parameters.items():
            if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
                raise InputError(f"sweep parameter {show(_name(key))}: give a sequence of values, got {show(values)}")
            values = list(values)
            if not values:
                raise InputError(f"sweep parameter {show(_name(key))}: no values")
            names.append(_name(key))
            axes.append(values)
        keys = list(parameters)
        _check_size(math.prod(len(a) for a in axes), len(names))
        cases = [dict(zip(names, combo)) for combo in itertools.product(*axes)]
        grid = dict(zip(names, axes))
    elif isinstance(parameters, (list, tuple)):
        if not parameters or not all(isinstance(c, dict) for c in parameters):
            raise InputError("sweep: parameters must be a dict of value lists (a grid) or a list of dicts (a sample)")
        keys = list(parameters[0])
        for i, c in enumerate(parameters):
            if list(c) != keys:
                raise InputError(f"sweep: case {i} has the parameters {list(c)}, case 0 has {keys}")
        names = [_name(k) for k in keys]
        cases = [{_name(k): v for k, v in c.items()} for c in parameters]
        grid = None
    else:
        raise InputError("sweep: parameters must be a dict of value lists (a grid) or a list of dicts (a sample)")
    if len(set(names)) != len(names):
        raise InputError(f"sweep: parameter names repeat: {names}")
    lines = {}
    if by_lines:
        for key, name in zip(keys, names):
            lines[name] = _lines_of(key)
        for case in cases:
            for name, value in case.items():
                _check_value(name, lines[name], value)
    return names, cases, grid, lines


# --- outputs ----------------------------------------------------------------------------------------

def _linearization_output(name):
    def get(lin):
        value = getattr(lin, name)
        return value() if callable(value) else value
    return get


class _Outputs:
    """What to keep of a case's result: name → extractor. Picklable (names, or the user's
    functions)."""

    def __init__(self, spec, analysis):
        self.spec = spec
        self.analysis = analysis
        self.single = None  # a function whose return value names the outputs itself
        self.items = {}
        if spec is None:
            spec = "final" if analysis == "simulate" else "eigenfrequencies" if analysis == "linearize" else None
        if spec is None:
            self.single = _identity
        elif callable(spec):
            self.single = spec
        elif isinstance(spec, str):
            self._add_name(spec)
        elif isinstance(spec, dict):
            for name, item in spec.items():
                if callable(item):
                    self.items[str(name)] = item
                elif isinstance(item, str):
                    self._check_name(item)
                    self.items[str(name)] = item
                else:
                    raise InputError(f"sweep outputs[{show(name)}]: a function or an output name, got {show(item)}")
        elif isinstance(spec, (list, tuple)):
            for name in spec:
                if not isinstance(name, str):
                    raise InputError(f"sweep outputs: names, got {show(name)}")
                self._add_name(name)
        else:
            raise InputError(f"sweep outputs: a name, a list of names, a dict or a function, got {show(spec)}")

    def _check_name(self, name):
        allowed = RESULT_ARRAYS if self.analysis == "simulate" else LINEARIZATION_OUTPUTS
        base = name[:-len("_final")] if self.analysis == "simulate" and name.endswith("_final") else name
        if callable(self.analysis) or base not in allowed:
            if callable(self.analysis):
                raise InputError(f"sweep outputs: with an analysis function, give functions of its result, not {show(name)}")
            raise InputError(f"sweep outputs: unknown output {show(name)} for analysis={show(self.analysis)}; "
                             f"one of {', '.join(allowed)}" + (", 'final', 'history'" if self.analysis == "simulate" else ""))

    def _add_name(self, name):
        if self.analysis == "simulate" and name in ("final", "history"):
            for a in RESULT_ARRAYS:
                self.items[a] = a + ("_final" if name == "final" else "")
            return
        self._check_name(name)
        self.items[name] = name

    def extract(self, result) -> dict:
        if self.single is not None:
            value = self.single(result)
            return dict(value) if isinstance(value, dict) else {"value": value}
        out = {}
        for name, item in self.items.items():
            if callable(item):
                out[name] = item(result)
            elif self.analysis == "simulate":
                final = item.endswith("_final")
                array = getattr(result, item[:-len("_final")] if final else item)
                out[name] = array[-1] if final else array
            else:
                out[name] = _linearization_output(item)(result)
        return out


def _identity(result):
    return result


# --- running cases ------------------------------------------------------------------------------

@dataclass
class _Task:
    """Everything a worker needs besides the cases (sent once per chunk, pickled)."""

    model: Any                # a spacar.Model or a factory(params) -> Model
    lines: dict               # parameter name -> tuple of _Line (keyword-line parameters)
    analysis: Any             # "simulate", "linearize" or a function(model) -> result
    outputs: _Outputs
    method: str = "auto"
    time_limit: float | None = None
    n_cases: int = 1


def _case_stem(model, index: int, n_cases: int) -> str:
    """The MATASC stem of case ``index``: the model's own stem with ``_case<index>`` appended
    (zero-padded to the number of cases), so that parallel cases never share a file."""
    from .io.matasc import default_stem

    return f"{default_stem(model)}_case{index:0{len(str(max(n_cases - 1, 0)))}d}"


def _run_case(task: _Task, params: dict, index: int = 0):
    if isinstance(task.model, Model):
        model = task.model.copy()
        for name, value in params.items():
            for line in task.lines[name]:
                try:
                    model.apply(line.keyword.name, *line.arguments(value))
                except SpacarError as err:
                    raise type(err)(f"sweep parameter {show(name)} = {show(value)}: {err}") from None
    else:
        model = task.model(dict(params))
        if not isinstance(model, Model):
            raise InputError(f"the factory returned {type(model).__name__}, not a spacar.Model")
    if model.core.settings.matasc == 1:
        model.output_stem = _case_stem(model, index, task.n_cases)
    n_warnings = len(model.warnings)
    # The time limit bounds the whole case: the analysis and the outputs computed from its result
    # (a linearization's eigen-analysis).
    with time_limited(task.time_limit, "in this case of the sweep"):
        if task.analysis == "simulate":
            from .simulate import simulate

            result = simulate(model, method=task.method, time_limit=task.time_limit)
        elif task.analysis == "linearize":
            from .linearize import linearize

            result = linearize(model)
        else:
            result = task.analysis(model)
        values = {name: np.asarray(v) for name, v in task.outputs.extract(result).items()}
    labels = None
    if task.analysis == "simulate":
        labels = (result.coordinate_labels, result.deformation_labels)
    return values, labels, model.warnings[n_warnings:]


# The outcome's payload of a case that a Ctrl-C kept from running.
_NOT_RUN = ("KeyboardInterrupt", "not run: the sweep was interrupted")


def _run_cases(task: _Task, cases: list, cancel=None) -> list:
    """Run the cases [(index, params)]; returns [(index, ok, payload, seconds)] with payload
    (values, labels, warnings) or, for a failed case, (exception type name, message). Once
    ``cancel`` (a _core.Cancellation) is cancelled, the running analysis stops and no case starts."""
    out = []
    for index, params in cases:
        start = time.perf_counter()
        if cancel is not None and cancel.cancelled:
            out.append((index, False, _NOT_RUN, math.nan))
            continue
        try:
            with cancel.watch() if cancel is not None else contextlib.nullcontext():
                payload = _run_case(task, params, index)
            ok = True
        except KeyboardInterrupt:
            if cancel is None or not cancel.cancelled:
                raise
            ok, payload = False, ("KeyboardInterrupt", "interrupted: the sweep was interrupted while this case ran")
        except Exception as err:  # noqa: BLE001 - every failure is reported with its case
            ok = False
            payload = (_type_name(err), str(err))
        out.append((index, ok, payload, time.perf_counter() - start))
    return out


def _run_chunk(task_bytes: bytes, cases: list) -> list:
    """Worker entry point (module level, so that spawned processes and dask workers import it)."""
    return _run_cases(pickle.loads(task_bytes), cases)


def _type_name(err: BaseException) -> str:
    t = type(err)
    module = t.__module__
    if module.startswith("spacar"):
        module = "spacar"
    return t.__name__ if module == "builtins" else f"{module}.{t.__name__}"


def _dumps(obj) -> bytes:
    """Pickle with cloudpickle when it is installed (lambdas and notebook functions travel),
    otherwise the standard pickle."""
    try:
        import cloudpickle
    except ImportError:  # pragma: no cover - cloudpickle comes with the dask extra
        cloudpickle = None
    try:
        return cloudpickle.dumps(obj) if cloudpickle else pickle.dumps(obj)
    except Exception as err:  # noqa: BLE001
        raise InputError(f"sweep: the model, factory or output functions cannot be sent to worker processes "
                         f"({type(err).__name__}: {err}); define functions at module level, install "
                         "cloudpickle, or use workers=1") from None


# --- progress ----------------------------------------------------------------------------------

class _Progress:
    def __init__(self, progress, total):
        self.total = total
        self.done = 0
        self.bar = None
        self.callback = None
        if callable(progress):
            self.callback = progress
            return
        tqdm = bars.tqdm_class()
        if progress is None:
            progress = tqdm is not None and bars.automatic()
        if progress:
            if tqdm is not None:
                self.bar = tqdm(total=total, desc="spacar.sweep", unit="case")
            else:
                self.callback = self._print

    def _print(self, done, total):
        print(f"spacar.sweep: {done}/{total} cases", file=sys.stderr, flush=True)

    def update(self, n, failed=0):
        self.done += n
        if self.bar is not None:
            self.bar.update(n)
            if failed:
                self.bar.set_postfix(failed=failed)
        elif self.callback is not None:
            self.callback(self.done, self.total)

    def close(self):
        if self.bar is not None:
            self.bar.close()


# --- the result -------------------------------------------------------------------------------------

@dataclass
class SweepResult:
    """The outcome of :func:`spacar.sweep`.

    ``parameters``: name → array over the cases (shape (n,) for numbers, (n, k) for tuples of k
    values). ``values``: output name → array of shape (n, *output shape), NaN for failed cases
    (an object array if the cases' outputs differ in shape or are not numbers). ``errors``: one
    :class:`SweepError` per failed case. ``ok``: which cases succeeded. For a grid, ``grid``
    holds the axes and :meth:`reshaped` gives the values in the grid's shape.
    """

    parameters: dict
    values: dict
    errors: list
    ok: np.ndarray
    cases: list
    grid: dict | None = None
    seconds: np.ndarray | None = None      # wall time of each case in its worker
    wall_time: float = 0.0                 # of the whole sweep
    workers: int = 1                       # threads, processes or cluster workers that ran the cases
    warnings: list = field(default_factory=list)   # (index, message) of new warnings per case
    coordinate_labels: list | None = None  # columns of x, xd, xdd, reaction: (node, component)
    deformation_labels: list | None = None  # columns of e, ed, edd, sigma: (element, deformation)
    analysis: Any = "simulate"

    def __len__(self):
        return len(self.cases)

    def __getitem__(self, name):
        return self.values[name]

    @property
    def shape(self) -> tuple:
        return tuple(len(v) for v in self.grid.values()) if self.grid else (len(self.cases),)

    def reshaped(self, name) -> np.ndarray:
        """``values[name]`` with the case axis split into the grid's axes (in parameter order)."""
        v = self.values[name]
        return v.reshape(self.shape + v.shape[1:])

    def raise_errors(self):
        """Raise a SpacarError listing the failed cases, if any."""
        if self.errors:
            lines = [f"case {e.index} {e.parameters}: {e.type}: {e.message.splitlines()[0]}" for e in self.errors[:10]]
            more = f"\n... and {len(self.errors) - 10} more" if len(self.errors) > 10 else ""
            raise SpacarError(f"{len(self.errors)} of {len(self)} cases failed:\n" + "\n".join(lines) + more)

    def to_xarray(self):
        """An ``xarray.Dataset``: for a grid of numbers the dimensions are the parameters with
        their values as coordinates; otherwise one dimension ``case`` with the parameters as
        coordinates. Outputs of the result arrays get the dimensions ``coordinate`` (with ``node``
        and ``component``), ``deformation`` (``element``, ``index``) and ``time``."""
        try:
            import xarray as xr
        except ImportError:  # pragma: no cover
            raise ImportError("to_xarray() needs xarray: pip install 'spacar[dask]' or pip install xarray") from None
        if self.grid is not None:
            # One dimension per parameter; numbers are its coordinate, tuples of numbers are
            # numbered along it and given as a coordinate "<name> values".
            case_dims = list(self.grid)
            coords = {}
            for name, axis in self.grid.items():
                values = self.parameters[name].reshape(self.shape + self.parameters[name].shape[1:])
                axis_values = np.asarray(values[tuple(slice(None) if d == name else 0 for d in case_dims)])
                if axis_values.ndim == 1 and axis_values.dtype.kind in "biuf":
                    coords[name] = axis_values
                else:
                    coords[name] = np.arange(len(axis))
                    if axis_values.dtype != object:
                        coords[f"{name} values"] = ((name,) + tuple(f"{name}_dim{i}" for i in range(1, axis_values.ndim)),
                                                    axis_values)
        else:
            case_dims = ["case"]
            coords = {"case": np.arange(len(self.cases))}
            for name, v in self.parameters.items():
                if v.dtype != object:
                    coords[name] = (("case",) + tuple(f"{name}_dim{i}" for i in range(1, v.ndim)), v)
        scalar_grid = self.grid is not None
        shape = self.shape if scalar_grid else (len(self.cases),)
        data = {}
        for name, v in self.values.items():
            if v.dtype == object:
                continue  # ragged outputs do not fit a Dataset
            v = v.reshape(shape + v.shape[1:])
            data[name] = (case_dims + self._output_dims(name, v.ndim - len(shape)), v)
        data["ok"] = (case_dims, self.ok.reshape(shape))
        if self.seconds is not None:
            data["seconds"] = (case_dims, self.seconds.reshape(shape))
        if self.coordinate_labels is not None and any("coordinate" in d[0] for d in data.values()):
            coords["node"] = ("coordinate", np.array([c[0] for c in self.coordinate_labels]))
            coords["component"] = ("coordinate", np.array([c[1] for c in self.coordinate_labels]))
        if self.deformation_labels is not None and any("deformation" in d[0] for d in data.values()):
            coords["element"] = ("deformation", np.array([c[0] for c in self.deformation_labels]))
            coords["index"] = ("deformation", np.array([c[1] for c in self.deformation_labels]))
        return xr.Dataset(data, coords=coords, attrs={"analysis": str(self.analysis), "failed": len(self.errors)})

    def _output_dims(self, name, ndim):
        base = name[:-len("_final")] if name.endswith("_final") else name
        if self.analysis == "simulate" and base in RESULT_ARRAYS:
            column = "coordinate" if base in ("x", "xd", "xdd", "reaction") else "deformation"
            dims = [] if base == "t" else [column]
            if ndim > len(dims):
                dims = ["time"] + dims
            if len(dims) == ndim:
                return dims
        if self.analysis == "linearize" and base in ("eigenfrequencies", "eigenvalues", "buckling_factors") and ndim == 1:
            return ["mode"]
        return [f"{name}_dim{i}" for i in range(ndim)]

    def __repr__(self):
        shape = "x".join(str(n) for n in self.shape)
        outs = ", ".join(f"{k} {v.shape[1:] if v.dtype != object else '(ragged)'}" for k, v in self.values.items())
        return (f"<spacar.SweepResult: {len(self.cases)} cases ({shape}{' grid' if self.grid else ''}), "
                f"{len(self.errors)} failed, outputs: {outs or 'none'}; {self.wall_time:.3g} s>")


def _stack(per_case: list, n: int):
    """Stack the cases' arrays of one output; NaN (or None) where a case failed."""
    present = [v for v in per_case if v is not None]
    shapes = {v.shape for v in present}
    numeric = all(v.dtype.kind in "biufc" for v in present)
    if len(shapes) == 1 and numeric:
        (shape,) = shapes
        dtype = np.result_type(*[v.dtype for v in present])
        if len(present) < n:
            dtype = np.result_type(dtype, np.float64)
        out = np.full((n, *shape), np.nan, dtype=dtype) if dtype.kind in "fc" else np.empty((n, *shape), dtype)
        for i, v in enumerate(per_case):
            if v is not None:
                out[i] = v
        return out
    out = np.empty(n, dtype=object)
    for i, v in enumerate(per_case):
        out[i] = v
    return out


def _parameter_arrays(names, cases):
    out = {}
    for name in names:
        column = [c[name] for c in cases]
        try:
            arr = np.asarray(column)
            if arr.dtype == object or arr.dtype.kind not in "biuf":
                raise ValueError
        except (ValueError, TypeError):
            arr = np.empty(len(column), dtype=object)
            arr[:] = column
        out[name] = arr
    return out


# --- the entry point -------------------------------------------------------------------------------

def sweep(model, parameters, *, analysis="simulate", outputs=None, method: str = "auto",
          time_limit: float | None = None, workers: int | None = None, client=None, executor=None,
          chunksize: int | None = None, progress=None) -> SweepResult:
    """Run an analysis of ``model`` for every case of ``parameters`` and gather the outputs.

    ``model``: a :class:`spacar.Model` (or an input file name), copied for every case; or a
    factory ``make_model(params) -> Model`` called with the case's parameters (a dict).

    ``parameters``: a dict ``{name: [values]}`` for the grid of all combinations
    (``itertools.product``, in the dict's order), or a list of dicts (an explicit sample). With a
    model, a name is an input line: the keyword and the numbers that identify the line, e.g.
    ``"ESTIFF 2"``, ``"XD 2 1"``, ``"X 3"``, ``"MASS 8"``, ``"TIMESTEP"``, ``"EPSINT"``; a value
    is the rest of that line (a number, or a tuple for several numbers: ``(0.0, 1.2e-3)``). A
    tuple of names sets the same values on several lines (``("ESTIFF 2", "ESTIFF 3")``).

    ``analysis``: ``"simulate"`` (:func:`spacar.simulate` of the current block), ``"linearize"``
    (:func:`spacar.linearize` at the current state) or a function ``f(model) -> result``.

    ``outputs``: for ``"simulate"``, ``"final"`` (default: the arrays t, x, xd, xdd, e, ed, edd,
    sigma, reaction of :class:`spacar.Results` at the last output time, under those names),
    ``"history"`` (the whole arrays) or a list of array names (``"x"``: the whole array,
    ``"x_final"``: its last row); for ``"linearize"``, ``"eigenfrequencies"``
    (default) or names of :class:`spacar.Linearization` attributes (M0, K0, ...). A function of
    the result returns a number, an array or a dict of them; a dict ``{name: function or name}``
    names each output.

    ``time_limit``: seconds per case, the analysis and its outputs (:class:`spacar.TimeLimitError`
    beyond; checked inside the core's work, so a case stops at its limit).

    Where the cases run: ``client`` (a ``dask.distributed.Client``) runs them on that cluster;
    ``executor`` (any ``concurrent.futures.Executor``) on it; otherwise ``workers`` local
    processes (started with "spawn", so scripts need the ``if __name__ == "__main__":`` guard),
    or in this process with ``workers=1``. By default (``workers=None``) threads of this process,
    one per CPU: the analysis runs in C++ without the GIL, so threads run cases in parallel
    without the start-up, import and pickling costs of processes (which made a sweep of short runs
    slower than a plain loop). Cases go in chunks of ``chunksize`` (default: about four chunks
    per worker). ``result.workers`` says how many ran them.

    ``progress``: True for a progress bar (tqdm when installed), False for none, None (default)
    for a bar in an interactive session (a terminal or a Jupyter kernel, unless
    ``SPACAR_PROGRESS=0``; as :func:`spacar.simulate`), or a function ``progress(done, total)``.

    A model that writes MATASC files (``MATASC 1``) writes each case's files under its own
    stem, the model's stem with ``_case<k>`` appended (``slidercrank_case07_x.asc``; k is the
    case's index, zero-padded: its parameters are ``result.cases[k]``), so that cases running
    in parallel never write the same file.

    Failed cases do not stop the sweep: they are listed in ``result.errors`` with their
    parameters, exception type and message, and their values are NaN. Returns a
    :class:`SweepResult`.
    """
    start = time.perf_counter()
    if isinstance(model, (str, os.PathLike)):
        from .io.reader import read

        model = read(model)
    if not isinstance(model, Model) and not callable(model):
        raise InputError(f"sweep: model must be a spacar.Model, an input file or a factory function, got {show(model)}")
    if not (analysis in ("simulate", "linearize") or callable(analysis)):
        raise InputError(f"sweep: analysis must be 'simulate', 'linearize' or a function, got {show(analysis)}")
    time_limit = seconds_or_none(time_limit, "sweep: time_limit")
    if not isinstance(method, str) or method not in _core.integration_methods:
        raise InputError(f"sweep: unknown integration method {show(method)} ({', '.join(_core.integration_methods)})")
    names, cases, grid, lines = _cases(parameters, by_lines=isinstance(model, Model))
    n = len(cases)
    task = _Task(model, lines, analysis, _Outputs(outputs, analysis), method, time_limit, n)
    indexed = list(enumerate(cases))

    for name, value in (("workers", workers), ("chunksize", chunksize)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 1):
            raise InputError(f"sweep: {name} must be a positive integer, got {show(value)}")
    for name, value in (("client", client), ("executor", executor)):
        if value is not None and not callable(getattr(value, "submit", None)):
            raise InputError(f"sweep: {name} must be a dask.distributed.Client or a concurrent.futures.Executor, "
                             f"got {show(value)}")
    if client is not None or executor is not None:
        n_workers = _client_workers(client) if client is not None else (workers or os.cpu_count() or 1)
    else:
        n_workers = max(1, min(workers or os.cpu_count() or 1, n))
    size = chunksize or max(1, math.ceil(n / (4 * n_workers)))
    chunks = [indexed[i:i + size] for i in range(0, n, size)]

    outcomes = {}
    bar = _Progress(progress, n)
    failed = 0

    collecting = threading.Lock()  # _isolate collects from several threads

    def collect(chunk, results):
        nonlocal failed
        with collecting:
            for index, ok, payload, seconds in results:
                outcomes[index] = (ok, payload, seconds)
                failed += not ok
            bar.update(len(chunk), failed)

    cancel = _core.Cancellation()
    try:
        if client is None and executor is None and n_workers == 1:
            for chunk in chunks:
                done = []
                try:  # case by case, so that a Ctrl-C keeps every case done
                    for case in chunk:
                        done.extend(_run_cases(task, [case]))
                finally:
                    if done:
                        collect(chunk[:len(done)], done)
        elif client is None and executor is None and workers is None:
            _run_threads(task, chunks, n_workers, collect, cancel)
        elif client is not None:
            _run_dask(client, _dumps(task), chunks, collect)
        elif executor is not None:
            _run_executor(executor, _dumps(task), chunks, collect)
        else:
            _run_processes(_dumps(task), chunks, n_workers, collect)
    except KeyboardInterrupt as err:
        # Ctrl-C: what is pending is cancelled (the threads' running cases stop within
        # milliseconds), what is done is kept, as err.results.
        cancel.cancel()
        for i in range(n):
            outcomes.setdefault(i, (False, _NOT_RUN, math.nan))
        err.results = _gather(task, names, cases, grid, outcomes, time.perf_counter() - start)
        err.results.workers = n_workers
        raise
    finally:
        bar.close()

    result = _gather(task, names, cases, grid, outcomes, time.perf_counter() - start)
    result.workers = n_workers
    return result


def _client_workers(client) -> int:
    try:
        return max(1, sum(client.nthreads().values()))
    except Exception:  # noqa: BLE001 - any client-like object
        return os.cpu_count() or 1


def _lost(chunk, message: str, err: BaseException | None = None) -> list:
    """The outcome of the cases of ``chunk`` that no worker could run."""
    kind = _type_name(err) if err is not None else "spacar.SpacarError"
    return [(i, False, (kind, message), math.nan) for i, _ in chunk]


def _run_threads(task, chunks, n_workers, collect, cancel):
    """Threads share the task: nothing to pickle, nothing to start. On Ctrl-C (which reaches only
    this, the main thread) the pending chunks are dropped and the running analyses cancelled."""
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=n_workers)
    futures, collected = {}, set()
    try:
        futures = {pool.submit(_run_cases, task, chunk, cancel): chunk for chunk in chunks}
        for future in concurrent.futures.as_completed(futures):
            collect(futures[future], future.result())
            collected.add(future)
    except KeyboardInterrupt:
        cancel.cancel()
        pool.shutdown(wait=True, cancel_futures=True)
        for future, chunk in futures.items():  # the chunks that ended meanwhile, stopped or not
            if future not in collected and future.done() and not future.cancelled() and future.exception() is None:
                collect(chunk, future.result())
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _run_executor(executor, payload, chunks, collect):
    """On a user's executor, which spacar cannot restart: a chunk whose worker died is reported
    as such."""
    futures = {executor.submit(_run_chunk, payload, chunk): chunk for chunk in chunks}
    for future in concurrent.futures.as_completed(futures):
        chunk = futures[future]
        try:
            collect(chunk, future.result())
        except Exception as err:  # noqa: BLE001 - a worker that died
            collect(chunk, _lost(chunk, f"the worker running this case failed or died: {err}", err))


def _run_processes(payload, chunks, n_workers, collect):
    """Spawned worker processes. A case that kills its process (a crash, a signal, the memory
    of the machine) breaks the whole pool: the cases it took with it are then run by processes
    that report case by case (_isolate), so that a process that dies names the case it was
    running, which alone fails, its error saying how its process ended; the others complete."""
    from concurrent.futures.process import BrokenProcessPool

    context = multiprocessing.get_context("spawn")
    pool = concurrent.futures.ProcessPoolExecutor(max_workers=min(n_workers, len(chunks)), mp_context=context)
    suspects = []
    try:
        futures = {pool.submit(_run_chunk, payload, chunk): chunk for chunk in chunks}
        for future in concurrent.futures.as_completed(futures):
            chunk = futures[future]
            try:
                collect(chunk, future.result())
            except BrokenProcessPool:
                suspects.extend(chunk)
            except Exception as err:  # noqa: BLE001 - e.g. a result that cannot be pickled back
                collect(chunk, _lost(chunk, f"the worker could not return this case: {err}", err))
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
    if suspects:
        _isolate(payload, suspects, context, n_workers, collect)


def _isolate(payload, cases, context, n_workers, collect):
    """Run ``cases`` in ``n_workers`` processes side by side, each reporting every case as it ends:
    a process that dies is blamed for the case it had not reported, which fails naming how the
    process ended, and a new process takes the rest of its share. Each crash costs one process
    start; the innocent cases run on."""
    shares = [cases[i::n_workers] for i in range(n_workers) if cases[i::n_workers]]

    def run_share(share):
        while share:
            receive, send = context.Pipe(duplex=False)
            process = context.Process(target=_run_reporting, args=(payload, share, send), daemon=True)
            process.start()
            send.close()
            done = 0
            try:
                while done < len(share):
                    collect([share[done]], receive.recv())
                    done += 1
            except EOFError:  # the process died while running share[done]
                process.join()
                collect([share[done]], _lost([share[done]], f"the worker process running this case "
                                                            f"{_ending(process.exitcode)}: a crash in the analysis "
                                                            "or a callable, a kill, or the machine's memory"))
                done += 1
            finally:
                receive.close()
                process.join()
            share = share[done:]

    with concurrent.futures.ThreadPoolExecutor(max_workers=len(shares)) as threads:
        for future in [threads.submit(run_share, share) for share in shares]:
            future.result()


def _run_reporting(payload, cases, send):
    """Worker process of _isolate: the cases one by one, each outcome sent when it ends."""
    for case in cases:
        send.send(_run_chunk(payload, [case]))
    send.close()


def _ending(code) -> str:
    """How a process with this exit code ended, in words."""
    if code is not None and code < 0:
        import signal

        try:
            return f"was killed by signal {signal.Signals(-code).name}"
        except ValueError:
            return f"was killed by signal {-code}"
    return f"exited with status {code}"


def _run_dask(client, payload, chunks, collect):
    """On a Dask cluster. The task is sent with each chunk (not scattered once: a scattered copy
    dies with the workers that hold it, and the chunks could not be rerun on their successors), so
    that Dask reruns the chunks of a dead worker on the others. Dask gives up on a task when the
    workers running it died several times (KilledWorker), which also befalls tasks that merely
    shared a worker with the culprit: such chunks are split into single cases, and each single case
    given up on is run once more alone on the cluster, after the rest, where only a case that kills
    its workers by itself fails, with Dask's account of it."""
    from distributed import as_completed

    def submit(chunk):
        return client.submit(_run_chunk, payload, chunk, pure=False)

    def killed(err):
        return type(err).__name__ == "KilledWorker"

    futures = [submit(chunk) for chunk in chunks]
    owner = {future.key: chunk for future, chunk in zip(futures, chunks)}
    running = as_completed(futures)
    suspects = []
    for future in running:
        chunk = owner.pop(future.key)
        try:
            collect(chunk, future.result())
        except Exception as err:  # noqa: BLE001 - a worker that died, a lost connection
            if killed(err) and len(chunk) > 1:
                for case in chunk:
                    again = submit([case])
                    owner[again.key] = [case]
                    running.add(again)
            elif killed(err):
                suspects.append(chunk)
            else:
                collect(chunk, _lost(chunk, f"this case could not be run by the cluster: {err}", err))
    for chunk in suspects:  # one at a time: nothing else runs beside it
        try:
            collect(chunk, submit(chunk).result())
        except Exception as err:  # noqa: BLE001
            why = "killed every Dask worker that ran it, alone" if killed(err) else "could not be run by the cluster"
            collect(chunk, _lost(chunk, f"this case {why}: {err}", err))


def _gather(task, names, cases, grid, outcomes, wall_time) -> SweepResult:
    n = len(cases)
    ok = np.zeros(n, dtype=bool)
    seconds = np.full(n, np.nan)
    errors, warnings = [], []
    per_output: dict[str, list] = {}
    order: list[str] = []
    labels = None
    for i in range(n):
        success, payload, secs = outcomes[i]
        seconds[i] = secs
        if not success:
            errors.append(SweepError(i, dict(cases[i]), payload[0], payload[1]))
            continue
        ok[i] = True
        values, case_labels, case_warnings = payload
        labels = labels or case_labels
        warnings.extend((i, w) for w in case_warnings)
        for name, v in values.items():
            if name not in per_output:
                per_output[name] = [None] * n
                order.append(name)
            per_output[name][i] = v
    values = {name: _stack(per_output[name], n) for name in order}
    return SweepResult(
        parameters=_parameter_arrays(names, cases), values=values, errors=errors, ok=ok, cases=cases,
        grid=grid, seconds=seconds, wall_time=wall_time, warnings=warnings,
        coordinate_labels=[tuple(c) for c in labels[0]] if labels else None,
        deformation_labels=[tuple(c) for c in labels[1]] if labels else None,
        analysis=task.analysis if isinstance(task.analysis, str) else getattr(task.analysis, "__name__", "function"))

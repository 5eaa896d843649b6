"""Results of an analysis block as NumPy arrays over the output times, with lookup by node and
element numbers and by the input keyword names::

    res.t                      # (nt,) output times
    res.x, res.xd, res.xdd     # (nt, nx) nodal coordinates, ascending (node, component)
    res.e, res.ed, res.edd     # (nt, ne) deformations, ascending (element, deformation)
    res.sigma                  # (nt, ne) generalized stresses (FORCEMODE 2: complete)
    res.reaction               # (nt, nx) reactions on fixed and input coordinates (FORCEMODE ≥ 1)
    res.node(8).x              # (nt, 2) coordinates of node 8
    res.element(2).e           # (nt, 3) deformations of element 2
    res.deformation(2, 2)      # (nt,) element 2 deformation 2
    res["XD", 2, 1]            # by keyword name: velocity of node 2 component 1
    res["e(2,2)"]              # by MATASC column label
    res.q, res.qd, res.qdd     # (nt, ndof) the degrees of freedom, in the model's DOF order
    res.dof_labels             # ["x(5,1)", "e(3,1) HINGE", ...]: DYNX coordinates, then DYNE

``to_pandas()`` (pandas optional), ``save``/``load`` (NumPy ``.npz``) and the plot helpers
``plot``, ``draw``, ``animate`` (matplotlib, imported only when used).
"""
from __future__ import annotations

import json
import math
import os
import re
import stat
import zipfile
import zlib
from dataclasses import dataclass

import numpy as np

from . import _core
from ._util import finite_time, show
from .energy import KEYS as ENERGY_KEYS, Energy
from .errors import InputError, SpacarError
from .geometry import Geometry, euler_e
from .linearize import MATRICES, Linearization

# name: (attribute, over coordinates or deformations, MATASC label prefix, description)
QUANTITIES = {
    "x": ("x", "coordinate", "x", "position"),
    "xd": ("xd", "coordinate", "xd", "velocity"),
    "xdd": ("xdd", "coordinate", "xdd", "acceleration"),
    "e": ("e", "deformation", "e", "deformation"),
    "ed": ("ed", "deformation", "ed", "deformation rate"),
    "edd": ("edd", "deformation", "edd", "deformation acceleration"),
    "sigma": ("sigma", "deformation", "s", "stress"),
    "reaction": ("reaction", "coordinate", "r", "reaction"),
}
# Accepted spellings (case-insensitive): the input keywords X, XD, XDD, E, ED, EDD and the
# MATASC label prefixes.
ALIASES = {
    "x": "x", "xd": "xd", "xdd": "xdd", "e": "e", "ed": "ed", "edd": "edd",
    "sigma": "sigma", "s": "sigma", "sig": "sigma", "stress": "sigma",
    "reaction": "reaction", "reactions": "reaction", "r": "reaction", "rx": "reaction",
}
# A label may end in the element type, as the DOF labels do ("e(3,1) HINGE").
_LABEL_RE = re.compile(r"^\s*([A-Za-z]+)\s*\(\s*(\d+)\s*,\s*(\d+)\s*\)\s*(?:([A-Za-z][A-Za-z0-9]*)\s*)?$")
_LINE_RE = re.compile(r"^\s*([A-Za-z]+)\s+(\d+)\s+(\d+)\s*$")
# The arrays recorded at every output time, from the core's table (kOutputArrays, simulate.hpp):
# name, over "coordinate" or "deformation", what they hold.
STATE_ARRAYS = tuple(name for name, _, _ in _core.output_arrays)
_ARRAYS = ("t",) + STATE_ARRAYS
_ELEMENT_TYPES = frozenset(t.name for t in _core.element_catalogue())


def _int_pairs(labels) -> list:
    """Labels (node or element, index) as pairs of Python ints. The core's and a results file's
    are lists of int pairs already, taken as a whole (a short run's results stay cheap); others
    (NumPy integers) are converted."""
    if isinstance(labels, np.ndarray):  # an (n, 2) integer array: converted in C
        return list(map(tuple, labels.tolist()))
    pairs = list(map(tuple, labels))
    if pairs and not (set(map(len, pairs)) == {2} and type(pairs[0][0]) is int and type(pairs[0][1]) is int):
        pairs = [(int(a), int(b)) for a, b in pairs]
    return pairs


def require_results(res, what: str) -> None:
    """Refuse anything but Results in the drawing and plotting functions, with what to do."""
    from .model import Model

    if isinstance(res, Model):
        raise SpacarError(f"spacar.{what} draws results, not a model: simulate first, e.g. "
                          f"res = spacar.simulate(model); spacar.{what}(res, ...)")
    if not isinstance(res, Results):
        raise InputError(f"spacar.{what} needs spacar.Results (of spacar.simulate or spacar.static), got {show(res)}")


class KeptModel:
    """The model that results keep (spacar.static, spacar.simulate): a lazy copy of the model's
    core at the solve (``_core.LazyModelCopy``, made when the model changes next, or is deleted,
    or here), made a core model once, when the geometry, the DOF labels or compliance first need
    it."""

    __slots__ = ("_lazy", "_made")

    def __init__(self, model):
        self._lazy, self._made = model.core.lazy_copy(), None

    def core(self):
        if self._made is None:
            self._made, self._lazy = self._lazy.model(), None
        return self._made


def model_core(source):
    """The core model of ``source``: a core model itself, or a KeptModel's."""
    return source.core() if isinstance(source, KeptModel) else source


def dof_labels(system, core, coords=None, defs=None) -> list:
    """Labels of the degrees of freedom of a compiled system (``_core.Simulation(...).system``) in
    its DOF order, the order of q in the core: the DYNX coordinates ascending (``"x(5,1)"``),
    then the DYNE deformations ascending, with their element type (``"e(3,1) HINGE"``).
    ``coords``, ``defs``: the system's coordinate and deformation labels, if already taken."""
    # Each attribute of the compiled system is a fresh copy of the whole list (20 µs for a
    # 20-link spatial chain): taken once (inside the loops, a chain of 4000 beams took minutes).
    core = model_core(core)
    coords = system.coord_label if coords is None else coords
    defs = system.def_label if defs is None else defs
    coords, defs = (a.tolist() if isinstance(a, np.ndarray) else a for a in (coords, defs))
    out = [f"x({n},{c})" for n, c in (coords[g] for g in system.x_dyn)]
    types = {}  # element → its type name: one call per element, not per deformation
    for k in system.e_dyn:
        e, i = defs[k]
        if e not in types:
            types[e] = core.element_type_name(e)
        out.append(f"e({e},{i}) {types[e]}")
    return out


def quantity(name: str) -> str:
    """The canonical quantity name (``x``, ``xd``, ..., ``sigma``, ``reaction``) of a keyword
    name or label prefix."""
    try:
        return ALIASES[str(name).lower()]
    except KeyError:
        raise InputError(f"unknown quantity {name!r}: use one of X, XD, XDD, E, ED, EDD, SIGMA, "
                         "REACTION (or the MATASC prefixes s, r)") from None


def parse_spec(spec) -> tuple:
    """(quantity, number, index) of a column specification: a tuple ``("XD", 2, 1)``, a MATASC
    label ``"xd(2,1)"`` or a keyword line ``"XD 2 1"``."""
    if isinstance(spec, str):
        m = _LABEL_RE.match(spec) or _LINE_RE.match(spec)
        if not m:
            raise InputError(f"cannot read {spec!r} as a quantity: write e.g. 'x(8,1)', 'e(2,2)' or 'XD 2 1'")
        if m.re is _LABEL_RE and m.group(4) and m.group(4).upper() not in _ELEMENT_TYPES:
            raise InputError(f"cannot read {spec!r} as a quantity: {m.group(4)!r} is not an element type")
        return quantity(m.group(1)), int(m.group(2)), int(m.group(3))
    try:
        name, number, index = spec
    except (TypeError, ValueError):
        raise InputError(f"a quantity is (name, number, index) or a label like 'x(8,1)', not {spec!r}") from None
    return quantity(name), int(number), int(index)


@dataclass(frozen=True)
class NodeResults:
    """Coordinates of one node over time: arrays of shape (nt, components)."""

    node: int
    x: np.ndarray
    xd: np.ndarray
    xdd: np.ndarray
    reaction: np.ndarray | None = None


@dataclass(frozen=True)
class ElementResults:
    """Deformations of one element over time: arrays of shape (nt, deformations)."""

    element: int
    e: np.ndarray
    ed: np.ndarray
    edd: np.ndarray
    sigma: np.ndarray


def _stat_value(key, value):
    """A statistic as JSON stores it: None, a number, a string or a list as they are, a NumPy
    number as a float; anything else is refused by name (a raw TypeError before, issue 38)."""
    if value is None or isinstance(value, (bool, int, float, str, list)):
        return value
    if isinstance(value, np.generic) and np.issubdtype(type(value), np.number):
        return float(value)
    raise InputError(f"Results.save: the statistic {key!r} is not a number, string or list: {show(value)}")


class Results:
    """Arrays over the output times of one block (or of several, see :meth:`concatenate`).

    ``t`` (nt,), ``x``, ``xd``, ``xdd``, ``reaction`` (nt, nx) for all nodal coordinates in
    ascending (node, component) order, ``e``, ``ed``, ``edd``, ``sigma`` (nt, ne) for all
    deformations in ascending (element, deformation) order; ``coordinate_labels`` and
    ``deformation_labels`` give the (node, component) and (element, deformation) of each column.
    ``q``, ``qd``, ``qdd`` (nt, ndof) are the degrees of freedom, their rates and accelerations
    in the model's DOF order (the order of ``spacar.linearize``'s z and of the core's q: DYNX
    coordinates ascending, then DYNE deformations ascending), named by ``dof_labels``
    (``"x(5,1)"``, ``"e(3,1) HINGE"``; each also a key: ``res["e(3,1) HINGE"]``).
    ``geometry`` (a :class:`spacar.geometry.Geometry`) describes the model for drawing,
    ``linearizations`` holds one :class:`spacar.Linearization` per output time when the model
    asks for them (LINE, LINEAR), ``stats`` the integrator's work.
    """

    def __init__(self, arrays: dict, coordinate_labels, deformation_labels, stats: dict,
                 geometry: Geometry | None = None, linearizations=(), settings_linear=None, dof_labels=()):
        self.t = np.asarray(arrays["t"], dtype=float)
        self.x, self.xd, self.xdd = arrays["x"], arrays["xd"], arrays["xdd"]
        self.e, self.ed, self.edd, self.sigma = arrays["e"], arrays["ed"], arrays["edd"], arrays["sigma"]
        # (nt, nx): loads exerted by the supports and drivers on the fixed and input coordinates
        # (FORCEMODE ≥ 1; zero on the other coordinates); sigma then includes the reaction
        # stresses of fixed, input and LINE deformations (formulation.md §6).
        self.reaction = arrays["reaction"]
        self.linearizations = list(linearizations)  # one spacar.Linearization per output time
        self.settings_linear = settings_linear
        # An (n, 2) array of the core's is converted to Python pairs when first used.
        self._coordinate_labels = coordinate_labels if isinstance(coordinate_labels, np.ndarray) \
            else _int_pairs(coordinate_labels)
        self._deformation_labels = deformation_labels if isinstance(deformation_labels, np.ndarray) \
            else _int_pairs(deformation_labels)
        self.stats = dict(stats)
        self.geometry = geometry
        self.shapes = None  # a URDF robot's link shapes (spacar.visuals.RobotShapes), set by simulate
        self._lookup = None  # {label: column} of x and of e, made at the first lookup
        self._set_dofs(dof_labels)

    # What a large model's results cost beyond the core's arrays is their labels as Python
    # objects: the lookup tables and the DOF labels are made when first used (0.5 ms of a 4 ms
    # static solve of 256 beams, issue 34).
    def _set_dofs(self, labels):
        """``labels``: the DOF labels, or a function of none that makes them when first used."""
        self._dof_labels = labels if callable(labels) else [str(lbl) for lbl in labels]
        self._dof_columns = None  # found at the first use (a short run's results stay cheap)

    @property
    def dof_labels(self) -> list:
        """``["x(5,1)", "e(3,1) HINGE", ...]``: the degrees of freedom in the order of :attr:`q`."""
        if callable(self._dof_labels):
            self._dof_labels = [str(lbl) for lbl in self._dof_labels()]
        return self._dof_labels

    @property
    def coordinate_labels(self) -> list:
        """(node, component) of each column of x, xd, xdd and reaction."""
        if not isinstance(self._coordinate_labels, list):
            self._coordinate_labels = _int_pairs(self._coordinate_labels)
        return self._coordinate_labels

    @property
    def deformation_labels(self) -> list:
        """(element, deformation) of each column of e, ed, edd and sigma."""
        if not isinstance(self._deformation_labels, list):
            self._deformation_labels = _int_pairs(self._deformation_labels)
        return self._deformation_labels

    @property
    def _coord(self) -> dict:
        return self._tables()[0]

    @property
    def _def(self) -> dict:
        return self._tables()[1]

    def _tables(self):
        if self._lookup is None:
            self._lookup = tuple(dict(zip(labels, range(len(labels))))
                                 for labels in (self.coordinate_labels, self.deformation_labels))
        return self._lookup

    def _dof_places(self) -> dict:
        """{"x" or "e": (positions in q, columns of x or e)}: each DOF is a column of x (DYNX)
        or of e (DYNE)."""
        if self._dof_columns is None:
            columns = {"x": ([], []), "e": ([], [])}
            for j, lbl in enumerate(self.dof_labels):
                attr, col = self.column(lbl)
                columns[attr][0].append(j)
                columns[attr][1].append(col)
            self._dof_columns = columns
        return self._dof_columns

    def _dof_values(self, x, e) -> np.ndarray:
        places = self._dof_places()
        (jx, cx), (je, ce) = places["x"], places["e"]
        out = np.empty((len(self.t), len(self.dof_labels)))
        out[:, jx] = x[:, cx]
        out[:, je] = e[:, ce]
        return out

    @property
    def q(self) -> np.ndarray:
        """(nt, ndof): the degrees of freedom over time, in the order of :attr:`dof_labels`."""
        return self._dof_values(self.x, self.e)

    @property
    def qd(self) -> np.ndarray:
        """(nt, ndof): the rates of the degrees of freedom."""
        return self._dof_values(self.xd, self.ed)

    @property
    def qdd(self) -> np.ndarray:
        """(nt, ndof): the accelerations of the degrees of freedom."""
        return self._dof_values(self.xdd, self.edd)

    # The geometry is only needed for drawing, plotting and saving, and building it costs more than
    # a small run: spacar.simulate and spacar.static keep the model as it was at the run
    # (``_geometry_source``, a KeptModel) and the Geometry is made from it on first access.
    @property
    def geometry(self) -> Geometry | None:
        if self._geometry_source is not None:
            self._geometry = Geometry.from_model(model_core(self._geometry_source))
            self._geometry_source = None
        return self._geometry

    @geometry.setter
    def geometry(self, value: Geometry | None):
        self._geometry, self._geometry_source = value, None

    def __getstate__(self):
        # Pickles hold the Geometry (plain data, as before it was lazy), not the model's core
        # (nor the model that static results keep for spacar.compliance).
        state = {k: v for k, v in self.__dict__.items()
                 if k not in ("_geometry", "_geometry_source", "_static_model", "_dof_columns", "_dof_labels", "_lookup",
                              "_coordinate_labels", "_deformation_labels")}
        state["geometry"] = self.geometry
        state["dof_labels"] = self.dof_labels
        state["coordinate_labels"] = self.coordinate_labels
        state["deformation_labels"] = self.deformation_labels
        return state

    def __setstate__(self, state):
        state = dict(state)
        geometry = state.pop("geometry", None)
        labels = state.pop("dof_labels", ())  # (pickled before the results had their DOFs: none)
        self._coordinate_labels = state.pop("coordinate_labels")
        self._deformation_labels = state.pop("deformation_labels")
        for old in ("_coord", "_def", "_dof_x", "_dof_e"):  # (older pickles' tables are made again)
            state.pop(old, None)
        state.setdefault("shapes", None)  # (pickled before the results kept a robot's link shapes)
        self.__dict__.update(state)
        self._lookup = None
        self._set_dofs(labels)
        self.geometry = geometry

    @property
    def energy(self):
        """The energy balance (a mapping of arrays over the output times, see
        :class:`spacar.energy.Energy`) of a run with ``spacar.simulate(..., energy=True)``."""
        energy = self.__dict__.get("_energy")
        if energy is None:
            raise InputError("no energy balance: run spacar.simulate(model, energy=True)")
        return energy

    @property
    def reactions(self) -> np.ndarray:
        """Alias of :attr:`reaction`."""
        return self.reaction

    # --- lookup by numbers -------------------------------------------------------------------

    def _columns(self, table, number, what):
        cols = [i for (n, _), i in table.items() if n == number]
        if not cols:
            raise InputError(f"there is no {what} {number} in the results")
        return cols

    @property
    def node_columns(self) -> dict:
        """{node: [columns of x]} in ascending node order."""
        out: dict = {}
        for i, (n, _) in enumerate(self.coordinate_labels):
            out.setdefault(n, []).append(i)
        return out

    def node(self, n: int) -> NodeResults:
        """Coordinates, rates, accelerations and reactions of node n over time."""
        cols = self._columns(self._coord, n, "node")
        return NodeResults(n, self.x[:, cols], self.xd[:, cols], self.xdd[:, cols], self.reaction[:, cols])

    def element(self, e: int) -> ElementResults:
        """Deformations, rates, accelerations and stresses of element e over time."""
        cols = self._columns(self._def, e, "element")
        return ElementResults(e, self.e[:, cols], self.ed[:, cols], self.edd[:, cols], self.sigma[:, cols])

    def coordinate_index(self, n: int, i: int) -> int:
        try:
            return self._coord[(n, i)]
        except KeyError:
            raise InputError(f"node {n} has no component {i}") from None

    def deformation_index(self, e: int, i: int) -> int:
        try:
            return self._def[(e, i)]
        except KeyError:
            raise InputError(f"element {e} has no deformation {i}") from None

    def coordinate(self, n: int, i: int, what: str = "x") -> np.ndarray:
        """Node n component i over time; ``what`` = ``x`` (default), ``xd``, ``xdd`` or
        ``reaction``."""
        q = quantity(what)
        if QUANTITIES[q][1] != "coordinate":
            raise InputError(f"{what!r} is a deformation quantity: use deformation()")
        return getattr(self, QUANTITIES[q][0])[:, self.coordinate_index(n, i)]

    def deformation(self, e: int, i: int, what: str = "e") -> np.ndarray:
        """Element e deformation i over time; ``what`` = ``e`` (default), ``ed``, ``edd`` or
        ``sigma``."""
        q = quantity(what)
        if QUANTITIES[q][1] != "deformation":
            raise InputError(f"{what!r} is a coordinate quantity: use coordinate()")
        return getattr(self, QUANTITIES[q][0])[:, self.deformation_index(e, i)]

    def stress(self, e: int, i: int) -> np.ndarray:
        """Generalized stress σ of element e deformation i over time."""
        return self.deformation(e, i, "sigma")

    # --- lookup by keyword names and labels ---------------------------------------------------

    def column(self, spec) -> tuple:
        """(array name, column index) of a specification (see :func:`parse_spec`)."""
        q, number, index = parse_spec(spec)
        attr, over, _, _ = QUANTITIES[q]
        col = self.coordinate_index(number, index) if over == "coordinate" else self.deformation_index(number, index)
        return attr, col

    def get(self, name, number: int | None = None, index: int | None = None) -> np.ndarray:
        """Values over time by keyword name: ``res.get("XD", 2, 1)``, ``res.get("E", 2, 2)``,
        ``res.get("SIGMA", 1, 1)``, or a label ``res.get("xd(2,1)")``; ``"t"`` gives the times."""
        if isinstance(name, str) and name.lower() == "t" and number is None:
            return self.t
        spec = name if number is None else (name, number, index)
        attr, col = self.column(spec)
        return getattr(self, attr)[:, col]

    def __getitem__(self, key):
        if isinstance(key, tuple):
            return self.get(*key)
        return self.get(key)

    @staticmethod
    def label(spec) -> str:
        """The MATASC column label of a specification: ``label(("XD", 2, 1)) == "xd(2,1)"``."""
        q, number, index = parse_spec(spec)
        return f"{QUANTITIES[q][2]}({number},{index})"

    @staticmethod
    def describe(spec) -> str:
        """A readable name: ``"xd(2,1): velocity of node 2, component 1"``."""
        q, number, index = parse_spec(spec)
        _, over, prefix, text = QUANTITIES[q]
        where = f"node {number}, component {index}" if over == "coordinate" else f"element {number}, deformation {index}"
        return f"{prefix}({number},{index}): {text}, {where}"

    def labels(self, name: str) -> list:
        """Column labels of one quantity (``labels("x") == ["x(1,1)", "x(1,2)", ...]``)."""
        q = quantity(name)
        _, over, prefix, _ = QUANTITIES[q]
        table = self.coordinate_labels if over == "coordinate" else self.deformation_labels
        return [f"{prefix}({a},{b})" for a, b in table]

    def time_index(self, t: float) -> int:
        """Index of the output time nearest to t (a finite number)."""
        return int(np.argmin(np.abs(self.t - finite_time(t, "time_index: t"))))

    # --- conversions --------------------------------------------------------------------------

    def supported_columns(self) -> list:
        """Columns of the fixed and input coordinates (where reactions act); all columns when the
        geometry is unknown."""
        if self.geometry is None:
            return list(range(len(self.coordinate_labels)))
        cls = self.geometry.coordinate_classes
        return [i for i, (n, c) in enumerate(self.coordinate_labels)
                if c - 1 < len(cls.get(n, ())) and cls[n][c - 1] in ("fixed", "input")]

    def to_pandas(self, quantities=STATE_ARRAYS):
        """A ``pandas.DataFrame`` indexed by ``t`` with one column per quantity and coordinate
        or deformation, named by the MATASC labels (``x(8,1)``, ``e(2,2)``, ``s(2,1)``,
        ``r(1,1)``; reactions only on the fixed and input coordinates). Needs pandas."""
        try:
            import pandas as pd
        except ImportError:  # pragma: no cover - depends on the environment
            raise ImportError("Results.to_pandas() needs pandas: pip install pandas") from None
        parts = {}
        for name in quantities:
            q = quantity(name)
            values = getattr(self, QUANTITIES[q][0])
            labels = self.labels(q)
            cols = self.supported_columns() if q == "reaction" else range(values.shape[1])
            for c in cols:
                parts[labels[c]] = values[:, c]
        return pd.DataFrame(parts, index=pd.Index(self.t, name="t"))

    def save(self, path) -> None:
        """Save to a NumPy ``.npz`` file (arrays, labels, statistics, geometry and
        linearizations); read back with :meth:`Results.load`. ``.npz`` is appended to a name
        without it (as NumPy does). An existing file is replaced (written to a temporary file
        next to it, then renamed: a failed save leaves the old file); a symbolic link or a
        non-regular file in its place is refused; the file keeps its mode, and a file with hard
        links is rewritten in place, so that the links keep sharing it."""
        path = _path_argument(path, "Results.save")
        if not path.endswith(".npz"):
            path += ".npz"
        data = {name: np.asarray(getattr(self, name)) for name in _ARRAYS}
        data["coordinate_labels"] = np.asarray(self.coordinate_labels, dtype=np.int64).reshape(-1, 2)
        data["deformation_labels"] = np.asarray(self.deformation_labels, dtype=np.int64).reshape(-1, 2)
        energy = self.__dict__.get("_energy")
        if energy is not None:
            for key in ENERGY_KEYS:
                data[f"energy_{key}"] = np.asarray(energy[key], dtype=float)
        lin_meta = []
        for k, lin in enumerate(self.linearizations):
            lin_meta.append({"t": float(lin.t), "z_labels": [list(z) for z in lin.z_labels], "n_line": int(lin.n_line),
                             "y_labels": [list(y) for y in lin.y_labels]})
            for name in MATRICES:
                data[f"lin{k}_{name}"] = np.asarray(getattr(lin, name))
        meta = {
            "format": "spacar.Results",
            "version": 2,  # 2: with the kinematic coordinates of the linearizations
            "stats": {k: _stat_value(k, v) for k, v in self.stats.items()},
            "settings_linear": self.settings_linear,
            "dof_labels": self.dof_labels,
            "geometry": None if self.geometry is None else self.geometry.to_dict(),
            "linearizations": lin_meta,
            "energy": energy is not None,
        }
        data["meta"] = np.array(json.dumps(meta))
        from .io.files import write_replacing

        def write(temporary):
            with open(temporary, "wb") as fh:  # through a file object: NumPy appends no .npz
                np.savez_compressed(fh, **data)

        write_replacing(path, write, "save the results")

    @classmethod
    def load(cls, path) -> "Results":
        """Read a file written by :meth:`save`. The file is checked before it is used: its
        arrays' sizes (from their headers, before anything is decompressed) against
        :func:`spacar.memory_limit`, then the names, types and shapes of its arrays and its
        description; every failure is an :class:`spacar.InputError` naming the file."""
        path = _path_argument(path, "Results.load")
        try:
            return _load(cls, path)
        except InputError as err:
            if str(err).startswith(f"{path}: "):
                raise
            raise InputError(f"{path}: {err}") from None  # e.g. a DOF label of no coordinate
        except (OSError, EOFError) as err:
            raise InputError(f"{path}: cannot read the results file ({getattr(err, 'strerror', None) or err})") from None
        except (ValueError, TypeError, KeyError, IndexError, AttributeError, RecursionError, zipfile.BadZipFile,
                zlib.error, NotImplementedError, OverflowError) as err:
            raise InputError(f"{path}: not a valid spacar results file ({type(err).__name__}: "
                             f"{show(str(err))})") from None

    @classmethod
    def concatenate(cls, results) -> "Results":
        """One Results of several consecutive blocks of the same model (a block boundary time
        appears twice, as in the MATASC files). If the blocks' degrees of freedom differ (a block
        changed the classes), the whole has none (``dof_labels`` empty)."""
        if isinstance(results, (str, bytes, Results)) or not hasattr(results, "__iter__"):
            raise InputError(f"concatenate(): results must be a list of spacar.Results, got {show(results)}")
        results = list(results)
        if not results:
            raise InputError("concatenate() needs at least one Results")
        for i, r in enumerate(results):
            if not isinstance(r, Results):
                raise InputError(f"concatenate(): results[{i}] is not a spacar.Results, got {show(r)}")
        first = results[0]
        for r in results[1:]:
            if r.coordinate_labels != first.coordinate_labels or r.deformation_labels != first.deformation_labels:
                raise InputError("concatenate(): the results are of different models")
        arrays = {name: np.concatenate([getattr(r, name) for r in results]) for name in _ARRAYS}
        stats: dict = {}
        for r in results:
            for k, v in r.stats.items():
                if isinstance(v, bool):  # e.g. "recursive": true of the whole only if of every block
                    stats[k] = stats.get(k, True) and v
                elif isinstance(v, (int, float)):
                    stats[k] = stats.get(k, 0) + v
        lins = [lin for r in results for lin in r.linearizations]
        # Blocks that change the classes have different DOFs: then no q over the whole.
        same_dofs = all(r.dof_labels == first.dof_labels for r in results)
        whole = cls(arrays, first.coordinate_labels, first.deformation_labels, stats,
                    results[-1].geometry or first.geometry, lins, results[-1].settings_linear,
                    first.dof_labels if same_dofs else ())
        whole.shapes = getattr(results[-1], "shapes", None) or getattr(first, "shapes", None)
        energies = [r.__dict__.get("_energy") for r in results]
        if all(e is not None for e in energies):  # the energy balance of every block: of the whole
            whole._energy = Energy.concatenate(energies)
        return whole

    # --- plots (matplotlib, imported when used) ------------------------------------------------

    def plot(self, y, x="t", **kwargs):
        """Plot quantities against time or against another quantity; see :func:`spacar.plot`."""
        from .plotting import plot

        return plot(self, y, x, **kwargs)

    def draw(self, k: int = -1, **kwargs):
        """Draw the mechanism at output index k; see :func:`spacar.draw`."""
        from .plotting import draw

        return draw(self, k, **kwargs)

    def animate(self, **kwargs):
        """Animation of the run; see :func:`spacar.animate`."""
        from .animation import animate

        return animate(self, **kwargs)

    def reaction_moment(self, n: int) -> np.ndarray:
        """Reaction on the orientation node ``n`` (LAMBDA) as a global moment, shape (nt, 3):
        m = ½ E(λ) r_λ (formulation.md §6), the moment exerted by the support or driver. The
        component of r_λ along λ (the normalisation) does no work and has no moment."""
        cols = self._columns(self._coord, n, "node")
        if len(cols) != 4:
            raise InputError(f"node {n} is not a LAMBDA node")
        lam, r = self.x[:, cols], self.reaction[:, cols]
        return 0.5 * np.einsum("tij,tj->ti", euler_e(lam), r)

    def __len__(self):
        return len(self.t)

    def __repr__(self):
        if len(self.t) == 0:
            return (f"<spacar.Results: no output times, {self.x.shape[1]} coordinates, "
                    f"{self.e.shape[1]} deformations>")
        return (f"<spacar.Results: {len(self.t)} output times from t = {self.t[0]:g} to {self.t[-1]:g}, "
                f"{self.x.shape[1]} coordinates, {self.e.shape[1]} deformations>")


# --- reading a saved file -------------------------------------------------------------------------

_FLOAT_ARRAYS = {"t": ("nt",), **{name: ("nt", "ne" if over == "deformation" else "nx")
                                  for name, over, _ in _core.output_arrays}}
_LIN_RE = re.compile(r"^lin(\d+)_([A-Za-z0-9]+)$")


def _path_argument(path, what: str) -> str:
    try:
        path = os.fspath(path)
    except TypeError:
        raise InputError(f"{what}: path must be a file name or path, got {show(path)}") from None
    return os.fsdecode(path) if isinstance(path, bytes) else path


def _headers(zf: zipfile.ZipFile, path: str) -> dict:
    """{array name: (shape, dtype)} from the .npy headers, nothing decompressed beyond them."""
    from numpy.lib import format as npy

    out = {}
    for info in zf.infolist():
        if not info.filename.endswith(".npy"):
            raise InputError(f"{path}: unexpected member {show(info.filename)} (a spacar results file holds .npy arrays only)")
        if info.flag_bits & 0x1:  # zipfile raises RuntimeError asking for a password (found by fuzzing)
            raise InputError(f"{path}: {info.filename} is encrypted (Results.save writes no encrypted members)")
        with zf.open(info) as fh:
            version = npy.read_magic(fh)
            if version not in ((1, 0), (2, 0)):
                raise InputError(f"{path}: {info.filename}: unsupported .npy format version {version}")
            read_header = npy.read_array_header_1_0 if version == (1, 0) else npy.read_array_header_2_0
            try:
                shape, _, dtype = read_header(fh)
            except (OSError, EOFError, zipfile.BadZipFile, zlib.error):
                raise
            except Exception as err:  # noqa: BLE001  numpy's parser of an untrusted header: any failure
                # (ValueError, SyntaxError, and tokenize.TokenError from its filter, found by fuzzing)
                raise InputError(f"{path}: {info.filename}: not a valid .npy header ({type(err).__name__}: "
                                 f"{show(str(err))})") from None
        out[info.filename[:-4]] = (shape, dtype)
    return out


def _check_sizes(headers: dict, path: str) -> None:
    from . import memory_limit

    total = 0
    for name, (shape, dtype) in headers.items():
        if dtype.hasobject:
            raise InputError(f"{path}: array {show(name)} holds Python objects (not written by Results.save)")
        total += math.prod(shape) * dtype.itemsize
    if total > memory_limit():
        raise InputError(f"{path}: its arrays would need {total / 1e9:.3g} GB, more than the memory limit of "
                         f"{memory_limit() / 1e9:.3g} GB (spacar.set_memory_limit)")


def _is_label(value, kinds) -> bool:
    return isinstance(value, list) and len(value) == len(kinds) and all(
        isinstance(v, k) and not isinstance(v, bool) for v, k in zip(value, kinds))


def _meta(f, headers, path) -> dict:
    if "meta" not in headers or headers["meta"][0] != () or headers["meta"][1].kind != "U":
        raise InputError(f"{path}: not a spacar results file (no description 'meta')")
    text = f["meta"]
    # UCS-4 code units beyond U+10FFFF make str() an invalid Python string (json then raises
    # SystemError; found by fuzzing): the description is checked as numbers first.
    if np.atleast_1d(text).astype(text.dtype.newbyteorder("<")).view("<u4").max(initial=0) > 0x10FFFF:
        raise InputError(f"{path}: the description 'meta' holds invalid characters (not written by Results.save)")
    meta = json.loads(str(text))
    if not isinstance(meta, dict) or meta.get("format") != "spacar.Results":
        raise InputError(f"{path}: not a spacar results file")
    checks = {
        "version": lambda v: isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= 2,
        "stats": lambda v: isinstance(v, dict),
        "settings_linear": lambda v: v is None or isinstance(v, int) and not isinstance(v, bool),
        "dof_labels": lambda v: isinstance(v, list) and all(isinstance(x, str) for x in v),
        "geometry": lambda v: v is None or isinstance(v, dict),
        "energy": lambda v: v is None or isinstance(v, bool),
        "linearizations": lambda v: isinstance(v, list) and all(
            isinstance(lm, dict) and isinstance(lm.get("t"), (int, float)) and not isinstance(lm.get("t"), bool)
            and isinstance(lm.get("n_line"), int) and isinstance(lm.get("z_labels"), list)
            and all(_is_label(z, (str, int, int)) for z in lm["z_labels"])
            and (lm.get("y_labels") is None or isinstance(lm["y_labels"], list)
                 and all(_is_label(y, (str, int, int)) for y in lm["y_labels"])) for lm in v),
    }
    for key, ok in checks.items():
        if key not in meta and key in ("version", "dof_labels"):
            continue  # files of version 1 lack the DOFs
        if not ok(meta.get(key)):
            raise InputError(f"{path}: the description's {key!r} is malformed: {show(meta.get(key))}")
    return meta


def _header_shape(headers, name, kinds, path, expected=None) -> tuple:
    """The shape of array ``name`` from its header, after checking its presence, type and (with
    ``expected``) shape: nothing is decompressed for a wrong file."""
    if name not in headers:
        raise InputError(f"{path}: the array {name!r} is missing (not a spacar results file?)")
    shape, dtype = headers[name]
    if dtype.kind not in kinds:
        raise InputError(f"{path}: the array {name!r} has the type {dtype}, expected "
                         f"{'floats' if 'f' in kinds else 'integers'}")
    if expected is not None and tuple(shape) != tuple(expected):
        raise InputError(f"{path}: the array {name!r} has the shape {tuple(shape)}, expected {tuple(expected)}")
    return tuple(shape)


_META_MAX_BYTES = 256 * 2**20  # the JSON description (geometry of a large model: a few MB)


def _check_header_shapes(headers, meta, path) -> None:
    sizes = {}
    for name, key in (("coordinate_labels", "nx"), ("deformation_labels", "ne")):
        shape = _header_shape(headers, name, "iu", path)
        if len(shape) != 2 or shape[1] != 2:
            raise InputError(f"{path}: the array {name!r} has the shape {shape}, expected (n, 2)")
        sizes[key] = shape[0]
    shape = _header_shape(headers, "t", "f", path)
    if len(shape) != 1:
        raise InputError(f"{path}: the array 't' has the shape {shape}, expected (n,)")
    sizes["nt"] = shape[0]
    for name, dims in _FLOAT_ARRAYS.items():
        _header_shape(headers, name, "f", path, tuple(sizes[d] for d in dims))
    if meta.get("energy"):
        for key in ENERGY_KEYS:
            _header_shape(headers, f"energy_{key}", "f", path, (sizes["nt"],))
    n_lins = len(meta["linearizations"])
    for name in headers:
        m = _LIN_RE.match(name)
        if m and (int(m.group(1)) >= n_lins or m.group(2) not in MATRICES):
            raise InputError(f"{path}: unexpected array {name!r}")
    for k, lm in enumerate(meta["linearizations"]):
        nz, nk = len(lm["z_labels"]), len(lm.get("y_labels") or ())
        expected = {"M0": (nz, nz), "C0": (nz, nz), "D0": (nz, nz), "K0": (nz, nz), "N0": (nz, nz),
                    "G0": (nz, nz), "r0": (nz,), "DF": (sizes["nx"], nz), "DFe": (sizes["ne"], nz)}
        for name, shape in expected.items():
            _header_shape(headers, f"lin{k}_{name}", "f", path, shape)
        # (files of version 1 lack Kk, AK0 and BK0; an empty one may come without its shape)
        for name, size in (("Kk", nz * nk), ("AK0", nk * nz), ("BK0", nk * (nz + nk))):
            if f"lin{k}_{name}" in headers:
                shape = _header_shape(headers, f"lin{k}_{name}", "f", path)
                if math.prod(shape) != size:
                    raise InputError(f"{path}: the array 'lin{k}_{name}' has the shape {shape}, expected "
                                     f"{size} values")


def _load(cls, path: str) -> "Results":
    try:
        mode = os.stat(path).st_mode
    except OSError as err:
        raise InputError(f"{path}: cannot read the results file ({err.strerror})") from None
    if not stat.S_ISREG(mode):
        raise InputError(f"{path}: not a regular file")
    with zipfile.ZipFile(path) as zf:
        headers = _headers(zf, path)
    _check_sizes(headers, path)
    if "meta" in headers and headers["meta"][1].itemsize > _META_MAX_BYTES:
        raise InputError(f"{path}: the description 'meta' is larger than {_META_MAX_BYTES} bytes")
    with np.load(path, allow_pickle=False) as f:
        meta = _meta(f, headers, path)
        _check_header_shapes(headers, meta, path)  # before any array is decompressed
        coord, defs = f["coordinate_labels"], f["deformation_labels"]
        for name, labels in (("coordinate_labels", coord), ("deformation_labels", defs)):
            if labels.size and not (np.abs(labels) < 2**31).all():
                raise InputError(f"{path}: the array {name!r} holds numbers out of range")
        arrays = {name: f[name].astype(float, copy=False) for name in _ARRAYS}
        lins = []
        for k, lm in enumerate(meta["linearizations"]):
            mats = {name: f[f"lin{k}_{name}"] for name in MATRICES if f"lin{k}_{name}" in headers}
            for name, matrix in mats.items():  # Results.save writes the finite matrices of a run
                if not np.isfinite(matrix).all():
                    raise InputError(f"{path}: the array 'lin{k}_{name}' holds values that are not finite "
                                     f"(not written by Results.save)")
            lins.append(Linearization.from_arrays(lm["t"], lm["z_labels"], lm["n_line"], mats, coord, defs,
                                                  lm.get("y_labels")))
        energy = Energy(arrays["t"], {key: f[f"energy_{key}"] for key in ENERGY_KEYS}) if meta.get("energy") else None
    geometry = None if meta["geometry"] is None else Geometry.from_dict(meta["geometry"])
    res = cls(arrays, coord, defs, meta["stats"], geometry, lins, meta["settings_linear"],
              meta.get("dof_labels", ()))  # (files written before the DOFs were saved lack them)
    res._dof_places()  # the DOF labels name coordinates and deformations of the file
    if energy is not None:
        res._energy = energy
    return res

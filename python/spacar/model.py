"""The builder API: :class:`Model` has one method per input keyword, so a SPACAR user recognises
every line (``model.plbeam(1, 1, 2, 3, 4)``, ``model.x(3, 0.15, 0.0)``, ``model.fix(8, 2)``,
``model.dyne(2, 2)``). The reader (:mod:`spacar.io.reader`) is a thin dispatcher onto these
methods. The model itself lives in the C++ core (``spacar._core.Model``), public as :attr:`Model.core`.
"""
from __future__ import annotations

import math
import numbers
from typing import NamedTuple

import numpy as np

from . import _core
from ._util import show
from .errors import InputError
from .keywords import INT, KEYWORDS, Keyword, did_you_mean

_INT_LIMIT = 2**31 - 1


class Signal(NamedTuple):
    """A state-space input or output: its keyword (INPUTF, OUTX, ...), node or element number,
    component or deformation index, and the input line that defined it (for later messages)."""

    keyword: str
    number: int
    index: int
    origin: str = ""


# The state-space signals on a node's coordinate (the others are on an element's deformation).
NODE_SIGNALS = ("INPUTF", "BASEX", "BASEXP", "BASEXPP", "OUTX", "OUTXP", "OUTXPP", "OUTR")


def _check_value(kw: Keyword, pname: str, kind: str, value):
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]  # a 0-d array is its number
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise InputError(f"{kw.name}: {pname} must be a number, got {show(value)}")
    try:
        real, overflow = float(value), False
    except (OverflowError, ValueError, TypeError):  # huge Python ints and fractions
        real, overflow = math.inf, True
    if kind == INT:
        if isinstance(value, numbers.Integral):
            value = int(value)
        elif math.isfinite(real) and real.is_integer():
            value = int(real)
        else:
            raise InputError(f"{kw.name}: {pname} must be an integer, got {show(value)}")
        if abs(value) > _INT_LIMIT:
            raise InputError(f"{kw.name}: {pname} = {show(value)} is out of range")
        return value
    if overflow:
        raise InputError(f"{kw.name}: {pname} must be a finite number, got a value too large for a double")
    value = real
    if not math.isfinite(value):
        raise InputError(f"{kw.name}: {pname} must be a finite number, got {show(value)}")
    return value


def check_args(kw: Keyword, args) -> list:
    """Validate the arguments of a keyword against its signature; returns them grouped: one entry
    per parameter group (a scalar for single values, a list for variable counts)."""
    args = list(args)
    if len(args) < sum(p.count_min for p in kw.params):
        raise InputError(f"{kw.name} expects {kw.usage()}: too few values ({len(args)} given)")
    out = []
    pos = 0
    for p, n in zip(kw.params, kw.counts(len(args))):
        vals = [_check_value(kw, p.name, p.kind, v) for v in args[pos:pos + n]]
        pos += n
        out.append(vals[0] if p.count_min == p.count_max == 1 else vals)
    if pos != len(args):
        raise InputError(f"{kw.name} expects {kw.usage()}: too many values ({len(args)} given)")
    return out


_COORD = {"FIX": _core.CoordClass.fixed, "INPUTX": _core.CoordClass.input, "DYNX": _core.CoordClass.dynamic}
_DEF = {
    "RLSE": _core.DefClass.released,
    "INPUTE": _core.DefClass.input,
    "DYNE": _core.DefClass.dynamic,
    "LINE": _core.DefClass.linearization,
}
_NODE_KIND = {
    "X": _core.NodeKind.X,
    "XY": _core.NodeKind.XY,
    "BETA": _core.NodeKind.BETA,
    "XYZ": _core.NodeKind.XYZ,
    "LAMBDA": _core.NodeKind.LAMBDA,
}


class Model:
    """A multibody model described keyword by keyword.

    Every SPACAR95 keyword is a method of the same name in lower case (``LAMBDA`` is
    ``lambda_``); element keywords take the element number, the node numbers and the numbers of
    the definition line. Omitted component or deformation indices mean "all".
    """

    def __init__(self):
        self._core = _core.Model()
        self.blocks = []       # parsed input blocks, when read from a file
        self.source = None     # input file name, when read from a file
        self.warnings = []     # reader and analysis warnings
        self._continue_step = 0.0  # integrator step to continue with (RESTART 0)
        self._origin = ""      # input line being applied (file, line, keyword), for later messages
        self.output_stem = None  # stem of the MATASC files (None: input file name or "spacar")
        self._matasc_files = {}  # MATASC files created by this model's runs (later blocks append)
        # State-space inputs and outputs (INPUTF, INPUTS; OUTX, OUTXP, OUTE, OUTEP, OUTS): {k: Signal}
        self.state_space_inputs = {}
        self.state_space_outputs = {}
        # The lines that prescribed coordinates (DYNX, INPUTX), for the constraint diagnosis's
        # "the latest of them": (node, component or 0 for all) → (order, "DYNX 3 1", origin).
        self._prescribed = {}
        self._prescribed_lines = 0  # DYNX/INPUTX lines applied so far: the order of the records

    # --- dispatch used by the reader ---------------------------------------------------------

    def apply(self, keyword: str, *args, origin: str = ""):
        """Apply one keyword line: ``model.apply("FIX", 8, 2)``. ``origin`` (file, line, keyword)
        is remembered with the elements and nodes the line defines, for errors found at the
        first END (e.g. an element of zero length)."""
        kw = KEYWORDS.get(keyword.upper()) if isinstance(keyword, str) else None
        if kw is None or kw.name in ("END", "EOF"):
            raise InputError(f"unknown keyword {show(keyword)}{did_you_mean(keyword)}")
        self._origin = origin
        try:
            return getattr(self, kw.builder)(*args)
        finally:
            self._origin = ""

    def prepare(self):
        """What the first END does before an analysis: create the automatic L2MIN1 elements,
        compute the reference geometry and freeze the topology. Errors found here name the input
        line that defined the element or node concerned."""
        self._core.prepare()

    def _call(self, name, *args):
        kw = KEYWORDS[name]
        return check_args(kw, args)

    # --- elements (generated from the catalogue, see _element_method) -----------------------

    def _element(self, type_name, args):
        kw = KEYWORDS[type_name]
        vals = check_args(kw, args)
        has_params = kw.params[-1].name == "params"
        nodes = vals[1:-1] if has_params else vals[1:]
        params = vals[-1] if has_params else []
        self._core.add_element(type_name, vals[0], nodes, params, self._origin)

    # --- nodes ------------------------------------------------------------------------------

    def _node(self, kind, args):
        n, values = self._call(kind, *args)
        if not isinstance(values, list):  # BETA: a single value
            values = [values]
        self._core.set_coordinates(n, _NODE_KIND[kind], values, self._origin)

    def x(self, n, *values):
        """X n x1..x4: coordinates of any node (usually one created by an element)."""
        self._node("X", (n, *values))

    def xy(self, n, x, y):
        """XY n x y: 2D position node."""
        self._node("XY", (n, x, y))

    def beta(self, n, beta):
        """BETA n beta: 2D orientation node."""
        self._node("BETA", (n, beta))

    def xyz(self, n, x, y, z):
        """XYZ n x y z: 3D position node."""
        self._node("XYZ", (n, x, y, z))

    def lambda_(self, n, l0, l1, l2, l3):
        """LAMBDA n l0 l1 l2 l3: 3D orientation node (Euler parameters)."""
        self._node("LAMBDA", (n, l0, l1, l2, l3))

    # --- boundary conditions ----------------------------------------------------------------

    def _coord_class(self, name, args):
        n, comps = self._call(name, *args)
        node = self._core.nodes.get(n) if name in ("DYNX", "INPUTX") else None
        before = [c.name for c in node.cls] if node is not None else []
        self._core.set_coordinate_class(n, comps, _COORD[name])
        if name in ("DYNX", "INPUTX"):
            line = f"{name} {n}" + "".join(f" {c}" for c in comps)
            self._prescribed_lines += 1
            for c in comps or (0,):
                self._prescribed[(n, c)] = (self._prescribed_lines, line, self._origin)
        if before:  # a FIX that a later line frees is more often a slip than meant
            freed = [i + 1 for i, c in enumerate(before) if c == "fixed" and (not comps or i + 1 in comps)]
            if freed:
                where = f"{self._origin}: " if self._origin else ""
                self.warnings.append(f"{where}{name} {n} {' '.join(map(str, freed))} frees component"
                                     f"{'s' if len(freed) > 1 else ''} {', '.join(map(str, freed))} of node {n}, "
                                     "fixed by an earlier FIX")

    def _def_class(self, name, args):
        e, idx = self._call(name, *args)
        self._core.set_deformation_class(e, idx, _DEF[name])

    def fix(self, n, *components):
        """FIX n [i...]: fix node n component(s) i (all if omitted)."""
        self._coord_class("FIX", (n, *components))

    def inputx(self, n, *components):
        """INPUTX n [i...]: node n component(s) i are input motions."""
        self._coord_class("INPUTX", (n, *components))

    def dynx(self, n, *components):
        """DYNX n [i...]: node n component(s) i are dynamic degrees of freedom."""
        self._coord_class("DYNX", (n, *components))

    def calculable(self, n, *components):
        """Node n's component(s) i (all if omitted) calculable again: neither fixed, input nor
        degree of freedom, what a coordinate is that no FIX, INPUTX or DYNX names (not an input
        keyword; :func:`spacar.mechanism.dead_positions` drives a copy of a mechanism by another
        coordinate with it)."""
        n, comps = self._call("FIX", n, *components)
        self._core.set_coordinate_class(n, comps, _core.CoordClass.calculable)
        for key in [k for k in self._prescribed if k[0] == n and (not comps or k[1] in comps or k[1] == 0)]:
            del self._prescribed[key]

    def rlse(self, e, *deformations):
        """RLSE e [i...]: release deformation(s) i of element e (all if omitted)."""
        self._def_class("RLSE", (e, *deformations))

    def inpute(self, e, *deformations):
        """INPUTE e [i...]: deformation(s) i of element e are input motions."""
        self._def_class("INPUTE", (e, *deformations))

    def dyne(self, e, *deformations):
        """DYNE e [i...]: deformation(s) i of element e are dynamic degrees of freedom."""
        self._def_class("DYNE", (e, *deformations))

    def line(self, e, *deformations):
        """LINE e [i...]: deformation(s) i of element e are linearization parameters."""
        self._def_class("LINE", (e, *deformations))

    def enhc(self, e1, i1, e2, i2):
        """ENHC e1 i1 e2 i2: deformation (e1, i1) is nonholonomic with kinematic coordinate (e2, i2)."""
        self._core.set_nonholonomic(*self._call("ENHC", e1, i1, e2, i2))

    # --- initial values ---------------------------------------------------------------------

    def xd(self, n, i, value):
        """XD n i x: node n component i has velocity x."""
        self._core.set_xd(*self._call("XD", n, i, value))

    def xdd(self, n, i, value):
        """XDD n i x: node n component i has acceleration x."""
        self._core.set_xdd(*self._call("XDD", n, i, value))

    def e(self, e, i, value):
        """E e i x: element e deformation i has value x."""
        self._core.set_e(*self._call("E", e, i, value))

    def ed(self, e, i, value):
        """ED e i x: element e deformation i has rate x."""
        self._core.set_ed(*self._call("ED", e, i, value))

    def edd(self, e, i, value):
        """EDD e i x: element e deformation i has double rate x."""
        self._core.set_edd(*self._call("EDD", e, i, value))

    def time(self, t):
        """TIME t: set the current time."""
        self._core.set_time(*self._call("TIME", t))

    def dir(self, e, x, y, z):
        """DIR e x y z: the first director (direction vector) of element e."""
        e, v = self._call("DIR", e, x, y, z)
        self._core.set_direction(e, v)

    def lgeomy(self, e, *values):
        """LGEOMY e x1..x13: reference geometry values of element e."""
        e, v = self._call("LGEOMY", e, *values)
        self._core.set_lgeomy(e, v)

    def lengtho(self, e, l0):
        """LENGTHO e l0: reference length of element e."""
        self._core.set_lengtho(*self._call("LENGTHO", e, l0))

    # --- dynamic properties -----------------------------------------------------------------

    def mass(self, n, *values):
        """MASS n m | Izz | Ixx Ixy Ixz Iyy Iyz Izz: concentrated mass or inertia at node n."""
        n, v = self._call("MASS", n, *values)
        self._core.set_mass(n, v)

    def emass(self, e, *values):
        """EMASS e rhoA [...]: distributed mass per length of element e."""
        e, v = self._call("EMASS", e, *values)
        self._core.set_emass(e, v)

    def estiff(self, e, *values):
        """ESTIFF e x1..x4: stiffness parameters of element e."""
        e, v = self._call("ESTIFF", e, *values)
        self._core.set_estiff(e, v)

    def edampp(self, e, *values):
        """EDAMPP e x1..x4: damping parameters of element e (in the form of ESTIFF)."""
        e, v = self._call("EDAMPP", e, *values)
        self._core.set_edampp(e, v)

    def force(self, n, *values):
        """FORCE n x1..x4: constant load on the coordinates of node n."""
        n, v = self._call("FORCE", n, *values)
        self._core.set_force(n, v)

    def torquel(self, n, *values):
        """TORQUEL n T1 [T2 T3]: constant body-fixed torque at LAMBDA node n."""
        n, v = self._call("TORQUEL", n, *values)
        self._core.set_torquel(n, v)

    def torqueg(self, n, *values):
        """TORQUEG n T1 [T2 T3] (extension): constant torque in global axes (a dead load) at
        LAMBDA node n."""
        n, v = self._call("TORQUEG", n, *values)
        self._core.set_torqueg(n, v)

    def gravity(self, *g):
        """GRAVITY gx gy [gz] (extension): uniform gravity acting on all masses."""
        (v,) = self._call("GRAVITY", *g)
        self._core.set_gravity(v)

    # --- state-space inputs and outputs (spacar.state_space) ----------------------------------

    def _signal(self, name, args, table):
        k, number, index = self._call(name, *args)
        if k < 1:
            raise InputError(f"the number k of an input or output must be 1 or more, got {k}")
        on_node = name in NODE_SIGNALS
        items = self._core.nodes if on_node else self._core.elements
        what = "node" if on_node else "element"
        if number not in items:
            raise InputError(f"{what} {number} does not exist (define it before this line)")
        count = len(items[number].x if on_node else items[number].cls)
        if not 1 <= index <= count:
            part = "coordinate" if on_node else "deformation"
            raise InputError(f"{what} {number} has {part}s 1..{count}, not {index}")
        table[k] = Signal(name, number, index, self._origin)

    def inputf(self, k, n, i):
        """INPUTF k n i: state-space input k is a force on coordinate i of node n."""
        self._signal("INPUTF", (k, n, i), self.state_space_inputs)

    def inputs(self, k, e, i):
        """INPUTS k e i: state-space input k is an actuator stress on deformation i of element e."""
        self._signal("INPUTS", (k, e, i), self.state_space_inputs)

    def basex(self, k, n, i):
        """BASEX k n i: state-space input k is the position of the INPUTX coordinate i of node n."""
        self._signal("BASEX", (k, n, i), self.state_space_inputs)

    def basexp(self, k, n, i):
        """BASEXP k n i: state-space input k is the velocity of the INPUTX coordinate i of node n."""
        self._signal("BASEXP", (k, n, i), self.state_space_inputs)

    def basexpp(self, k, n, i):
        """BASEXPP k n i: state-space input k is the acceleration of the INPUTX coordinate i of node n."""
        self._signal("BASEXPP", (k, n, i), self.state_space_inputs)

    def outx(self, k, n, i):
        """OUTX k n i: state-space output k is coordinate i of node n."""
        self._signal("OUTX", (k, n, i), self.state_space_outputs)

    def outxp(self, k, n, i):
        """OUTXP k n i: state-space output k is the rate of coordinate i of node n."""
        self._signal("OUTXP", (k, n, i), self.state_space_outputs)

    def outxpp(self, k, n, i):
        """OUTXPP k n i: state-space output k is the acceleration of coordinate i of node n."""
        self._signal("OUTXPP", (k, n, i), self.state_space_outputs)

    def outr(self, k, n, i):
        """OUTR k n i: state-space output k is the reaction on the fixed or input coordinate i of node n."""
        self._signal("OUTR", (k, n, i), self.state_space_outputs)

    def oute(self, k, e, i):
        """OUTE k e i: state-space output k is deformation i of element e."""
        self._signal("OUTE", (k, e, i), self.state_space_outputs)

    def outep(self, k, e, i):
        """OUTEP k e i: state-space output k is the rate of deformation i of element e."""
        self._signal("OUTEP", (k, e, i), self.state_space_outputs)

    def outs(self, k, e, i):
        """OUTS k e i: state-space output k is the stress of deformation i of element e."""
        self._signal("OUTS", (k, e, i), self.state_space_outputs)

    # --- settings ---------------------------------------------------------------------------

    def timestep(self, n, tp):
        """TIMESTEP n Tp: integrate over Tp with n output intervals."""
        self._core.set_timestep(*self._call("TIMESTEP", n, tp))

    def hmax(self, h):
        """HMAX h: maximum integration step."""
        self._core.set_hmax(*self._call("HMAX", h))

    def maxiterat(self, n):
        """MAXITERAT n: maximum kinematic (Newton) iterations per evaluation."""
        self._core.set_maxiterat(*self._call("MAXITERAT", n))

    def epskin(self, eps):
        """EPSKIN eps: kinematic convergence tolerance on the deformations (a simulation uses at most
        1e-4 of EPSINT and EPSIND, so that Newton's residual stays below the step control's scale)."""
        self._core.set_epskin(*self._call("EPSKIN", eps))

    def epsint(self, eps):
        """EPSINT eps: integration tolerance for the degrees of freedom."""
        self._core.set_epsint(*self._call("EPSINT", eps))

    def epsind(self, eps):
        """EPSIND eps: integration tolerance for the rates of the degrees of freedom."""
        self._core.set_epsind(*self._call("EPSIND", eps))

    def forcemode(self, mode):
        """FORCEMODE 0|1|2: reaction forces (1) and element stresses (2)."""
        self._core.set_forcemode(*self._call("FORCEMODE", mode))

    def animate(self, flag):
        """ANIMATE 0|1: produce an animation of the run."""
        self._core.set_animate(*self._call("ANIMATE", flag))

    def matasc(self, flag):
        """MATASC 0|1: write the state at every output time to ASCII files."""
        self._core.set_matasc(*self._call("MATASC", flag))

    def jobid(self, ident):
        """JOBID id: integer identifier of the job."""
        self._core.set_jobid(*self._call("JOBID", ident))

    def restart(self, flag):
        """RESTART 0|1: continue (0) or restart (1) the integrator at the next block."""
        self._core.set_restart(*self._call("RESTART", flag))

    def linear(self, mode):
        """LINEAR 0|1|2 (extension): linearized equations at every output time."""
        self._core.set_linear(*self._call("LINEAR", mode))

    # --- inspection -------------------------------------------------------------------------

    @property
    def core(self) -> _core.Model:
        """The C++ model this Model builds (``spacar._core.Model``), itself and not a copy: what
        the core's functions take, e.g. ``spacar._core.Simulation(model.core)``. Change the model
        through the keyword methods, which check their arguments and name the input line."""
        return self._core

    @property
    def nodes(self):
        """The nodes, ``{number: spacar._core.Node}`` (a snapshot)."""
        return self._core.nodes

    @property
    def elements(self):
        """The elements, ``{number: spacar._core.Element}`` (a snapshot)."""
        return self._core.elements

    @property
    def settings(self):
        return self._core.settings

    @property
    def current_time(self) -> float:
        return self._core.time

    @classmethod
    def _of_core(cls, core: _core.Model) -> "Model":
        """A Model around an existing core model (not copied), e.g. the snapshot that static
        results keep."""
        model = cls()
        model._core = core
        return model

    def copy(self) -> "Model":
        """An independent copy of the model and its state (blocks included)."""
        other = Model()
        other._core = self._core.copy()
        other.blocks = list(self.blocks)
        other.source = self.source
        other.warnings = list(self.warnings)
        other._continue_step = self._continue_step
        other.output_stem = self.output_stem
        other.state_space_inputs = dict(self.state_space_inputs)
        other.state_space_outputs = dict(self.state_space_outputs)
        other._prescribed = dict(self._prescribed)
        other._prescribed_lines = self._prescribed_lines
        copies = {"urdf_joints": list, "urdf_links": dict, "urdf_base": lambda base: base,   # set by spacar.from_urdf
                  "urdf_shapes": lambda shapes: shapes}
        for name, copy in copies.items():
            if hasattr(self, name):
                setattr(other, name, copy(getattr(self, name)))
        return other

    def summary(self):
        """Counts of nodes, elements, coordinate and deformation classes (see :mod:`spacar.check`)."""
        from .check import summary

        return summary(self)

    def check(self, time_limit=None):
        """Summary and constraint diagnosis (redundant deformations, undetermined coordinates)
        within ``time_limit`` seconds (None: no limit); see :func:`spacar.check.check`."""
        from .check import check

        return check(self, time_limit=time_limit)

    def release_overconstraints(self, time_limit=None) -> list:
        """Release (RLSE) the redundant rigid deformations that :meth:`check` names; returns the
        released ``(element, deformation)`` pairs. See :func:`spacar.check.release_overconstraints`."""
        from .check import release_overconstraints

        return release_overconstraints(self, time_limit=time_limit)

    def run_blocks(self, **kwargs):
        """Analyse the blocks of the input in order, as ``spacar run`` does: the current block
        first, then each later block applied to the state reached. Yields one
        :class:`spacar.Results` per block (``kwargs`` go to :func:`spacar.simulate`)."""
        from .io.reader import apply_block
        from .simulate import simulate

        for k, block in enumerate(self.blocks or [None]):
            if k > 0:
                apply_block(self, block)
            yield simulate(self, **kwargs)

    def run(self, **kwargs):
        """Run the analysis of the current block; see :func:`spacar.simulate`."""
        from .simulate import simulate

        return simulate(self, **kwargs)

    def dump(self, digits: int = 4) -> str:
        """The state dump (manual §5.7), a restartable input block."""
        from .io.writer import dump

        return dump(self, digits=digits)

    def __repr__(self):
        return f"<spacar.Model: {len(self.nodes)} nodes, {len(self.elements)} elements, t = {self.current_time:g}>"


def _element_method(type_name: str):
    kw = KEYWORDS[type_name]

    def method(self, *args):
        self._element(type_name, args)

    method.__name__ = type_name.lower()
    method.__doc__ = f"{kw.usage()}: {kw.doc}."
    return method


for _t in _core.element_catalogue():
    setattr(Model, _t.name.lower(), _element_method(_t.name))

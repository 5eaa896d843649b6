"""The input keywords of SPACAR95 (manual §5) and the extensions, as one table.

The element keywords come from the C++ element catalogue (``spacar._core.element_catalogue()``);
the others are listed here. The reader, the builder methods of :class:`spacar.Model`, the
writer and the generated keyword reference in ``docs/`` are all driven by this table.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from . import _core

INT, REAL = "int", "real"


@dataclass(frozen=True)
class Param:
    """A parameter group of a keyword line: ``count_min``..``count_max`` numbers of one type."""

    name: str
    kind: str  # INT or REAL
    count_min: int = 1
    count_max: int = 1


@dataclass(frozen=True)
class Keyword:
    name: str
    group: str
    params: tuple[Param, ...]
    doc: str
    method: str = ""  # name of the spacar.Model builder method
    extension: bool = False
    aliases: tuple[str, ...] = field(default_factory=tuple)

    @property
    def builder(self) -> str:
        return self.method or self.name.lower()

    def counts(self, n_values: int) -> list[int]:
        """How many of ``n_values`` values each parameter group takes, in order: as many as it
        can, up to its maximum, while leaving the later groups their minimum counts. The reader
        and the builder methods group a line's values by this one rule. With too few values
        every group still gets its minimum (the sum then exceeds ``n_values``)."""
        counts, pos = [], 0
        for i, p in enumerate(self.params):
            rest = sum(q.count_min for q in self.params[i + 1:])
            n = min(max(n_values - pos - rest, p.count_min), p.count_max)
            counts.append(n)
            pos += n
        return counts

    def usage(self) -> str:
        parts = [self.name]
        for p in self.params:
            if p.count_min == p.count_max == 1:
                parts.append(p.name)
            elif p.count_min == 0:
                parts.append(f"[{p.name}...]" if p.count_max > 1 else f"[{p.name}]")
            else:
                parts.append(f"{p.name}({p.count_min}..{p.count_max})")
        return " ".join(parts)


def _p(name, kind=INT, lo=1, hi=1):
    return Param(name, kind, lo, hi)


MANY = 10**6

# Groups as in the manual's sections.
ELEMENTS, NODES, BOUNDARY, INITIAL, PROPERTIES, SETTINGS, CONTROL = (
    "Elements (§5.1)",
    "Nodes (§5.2)",
    "Boundary conditions (§5.3)",
    "Initial values (§5.4)",
    "Dynamic properties (§5.5)",
    "Settings and controls (§5.6)",
    "Input control",
)
STATE_SPACE = "State-space inputs and outputs"


def _element_keywords():
    out = []
    for t in _core.element_catalogue():
        params = [_p("e")] + [_p(role) for role in t.node_roles]
        if t.n_params_max:
            params.append(_p("params", REAL, t.n_params_min, t.n_params_max))
        doc = t.description + (f"; {t.params}" if t.params else "")
        out.append(Keyword(t.name, ELEMENTS, tuple(params), doc, extension=t.extension))
    return out


# The most ESTIFF (and EDAMPP) values any element type takes (the spatial beam's six with shear).
_MOST_ESTIFF = max(t.n_estiff for t in _core.element_catalogue())
_MOST_EMASS = max(t.n_emass for t in _core.element_catalogue())

_OTHER = [
    Keyword("X", NODES, (_p("n"), _p("x", REAL, 1, 4)), "any node n with coordinates x1..x4"),
    Keyword("XY", NODES, (_p("n"), _p("x", REAL, 2, 2)), "2D position node n with coordinates x y"),
    Keyword("BETA", NODES, (_p("n"), _p("beta", REAL)), "2D orientation node n with angle beta"),
    Keyword("XYZ", NODES, (_p("n"), _p("x", REAL, 3, 3)), "3D position node n with coordinates x y z"),
    Keyword("LAMBDA", NODES, (_p("n"), _p("lambda", REAL, 4, 4)),
            "3D orientation node n with Euler parameters l0 l1 l2 l3", method="lambda_"),
    Keyword("FIX", BOUNDARY, (_p("n"), _p("i", INT, 0, MANY)),
            "node n component i is fixed (no i: all components)"),
    Keyword("INPUTX", BOUNDARY, (_p("n"), _p("i", INT, 0, MANY)), "node n component i is input motion"),
    Keyword("DYNX", BOUNDARY, (_p("n"), _p("i", INT, 0, MANY)),
            "node n component i is a dynamic degree of freedom"),
    Keyword("RLSE", BOUNDARY, (_p("e"), _p("i", INT, 0, MANY)),
            "element e deformation i is released (no i: all deformations)"),
    Keyword("INPUTE", BOUNDARY, (_p("e"), _p("i", INT, 0, MANY)), "element e deformation i is input motion"),
    Keyword("DYNE", BOUNDARY, (_p("e"), _p("i", INT, 0, MANY)),
            "element e deformation i is a dynamic degree of freedom"),
    Keyword("LINE", BOUNDARY, (_p("e"), _p("i", INT, 0, MANY)),
            "element e deformation i is a linearization parameter"),
    Keyword("ENHC", BOUNDARY, (_p("e1"), _p("i1"), _p("e2"), _p("i2")),
            "element e1 deformation i1 is nonholonomic; its kinematic coordinate is element e2 deformation i2"),
    Keyword("XD", INITIAL, (_p("n"), _p("i"), _p("x", REAL)), "node n component i has velocity x"),
    Keyword("XDD", INITIAL, (_p("n"), _p("i"), _p("x", REAL)), "node n component i has acceleration x"),
    Keyword("E", INITIAL, (_p("e"), _p("i"), _p("x", REAL)), "element e deformation i has value x"),
    Keyword("ED", INITIAL, (_p("e"), _p("i"), _p("x", REAL)), "element e deformation i has rate x"),
    Keyword("EDD", INITIAL, (_p("e"), _p("i"), _p("x", REAL)), "element e deformation i has double rate x"),
    Keyword("TIME", INITIAL, (_p("t", REAL),), "set the current time to t"),
    Keyword("DIR", INITIAL, (_p("e"), _p("x", REAL, 3, 3)), "the first director of element e is x y z",
            method="dir"),
    Keyword("LGEOMY", INITIAL, (_p("e"), _p("x", REAL, 1, 13)), "element e general geometry values x1..x13"),
    Keyword("LENGTHO", INITIAL, (_p("e"), _p("l0", REAL)), "element e has initial length l0",
            aliases=("LENGTH0",)),
    Keyword("MASS", PROPERTIES, (_p("n"), _p("m", REAL, 1, 6)),
            "concentrated mass m (XY, XYZ), Izz (BETA) or inertia tensor Ixx Ixy Ixz Iyy Iyz Izz (LAMBDA) at node n"),
    Keyword("EMASS", PROPERTIES, (_p("e"), _p("rhoA", REAL, 1, _MOST_EMASS)),
            "distributed mass rhoA per length of element e (PLBELT: rhoA a1 a2)"),
    Keyword("ESTIFF", PROPERTIES, (_p("e"), _p("x", REAL, 1, _MOST_ESTIFF)),
            "stiffness parameters of element e (meaning per element type)"),
    Keyword("EDAMPP", PROPERTIES, (_p("e"), _p("x", REAL, 1, _MOST_ESTIFF)),
            "damping values of element e, in the form of ESTIFF"),
    Keyword("FORCE", PROPERTIES, (_p("n"), _p("f", REAL, 1, 4)), "prescribed constant force x1..x4 at node n"),
    Keyword("TORQUEL", PROPERTIES, (_p("n"), _p("T", REAL, 1, 3)),
            "body-fixed constant torque at LAMBDA node n"),
    Keyword("TORQUEG", PROPERTIES, (_p("n"), _p("T", REAL, 1, 3)),
            "constant torque in global axes at LAMBDA node n", extension=True),
    Keyword("GRAVITY", PROPERTIES, (_p("g", REAL, 2, 3),),
            "uniform gravity acceleration gx gy [gz] acting on all masses", extension=True),
    Keyword("TIMESTEP", SETTINGS, (_p("n"), _p("Tp", REAL)),
            "integrate over a time period Tp with n constant output intervals"),
    Keyword("HMAX", SETTINGS, (_p("h", REAL),), "maximum integration step size h"),
    Keyword("MAXITERAT", SETTINGS, (_p("n"),), "maximum number n of kinematic iterations per step"),
    Keyword("EPSKIN", SETTINGS, (_p("eps", REAL),), "kinematic convergence tolerance on the deformations (in a simulation at most 1e-4 of EPSINT and EPSIND)"),
    Keyword("EPSINT", SETTINGS, (_p("eps", REAL),), "local integration error tolerance for the deformations"),
    Keyword("EPSIND", SETTINGS, (_p("eps", REAL),),
            "local integration error tolerance for the deformation rates"),
    Keyword("FORCEMODE", SETTINGS, (_p("mode"),),
            "0: no forces; 1: reaction forces; 2: reaction forces and element stresses"),
    Keyword("ANIMATE", SETTINGS, (_p("flag"),), "1: produce an animation of the run"),
    Keyword("MATASC", SETTINGS, (_p("flag"),), "1: write the state at every output time to ASCII files"),
    Keyword("JOBID", SETTINGS, (_p("id"),), "integer identifier of the input file"),
    Keyword("RESTART", SETTINGS, (_p("flag"),), "0: continue the integrator; 1: restart it"),
    Keyword("LINEAR", SETTINGS, (_p("mode"),),
            "1: linearized equations at every output time; 2: also buckling factors", extension=True),
    # The inputs u and outputs y of spacar.state_space (modern SPACAR's names; see
    # docs/linearization.md): k numbers them 1, 2, ... in the order of u and y.
    Keyword("INPUTF", STATE_SPACE, (_p("k"), _p("n"), _p("i")),
            "input k is a force on coordinate i of node n (in the directions of FORCE)", extension=True),
    Keyword("INPUTS", STATE_SPACE, (_p("k"), _p("e"), _p("i")),
            "input k is an actuator stress on deformation i of element e (a DYNE, released or LINE deformation)",
            extension=True),
    Keyword("BASEX", STATE_SPACE, (_p("k"), _p("n"), _p("i")),
            "input k is the position of the INPUTX coordinate i of node n (a support's motion)", extension=True),
    Keyword("BASEXP", STATE_SPACE, (_p("k"), _p("n"), _p("i")),
            "input k is the velocity of the INPUTX coordinate i of node n", extension=True),
    Keyword("BASEXPP", STATE_SPACE, (_p("k"), _p("n"), _p("i")),
            "input k is the acceleration of the INPUTX coordinate i of node n (e.g. a floor's vibration)",
            extension=True),
    Keyword("OUTX", STATE_SPACE, (_p("k"), _p("n"), _p("i")), "output k is coordinate i of node n",
            extension=True),
    Keyword("OUTXP", STATE_SPACE, (_p("k"), _p("n"), _p("i")), "output k is the rate of coordinate i of node n",
            extension=True),
    Keyword("OUTXPP", STATE_SPACE, (_p("k"), _p("n"), _p("i")),
            "output k is the acceleration of coordinate i of node n", extension=True),
    Keyword("OUTR", STATE_SPACE, (_p("k"), _p("n"), _p("i")),
            "output k is the reaction on the fixed or INPUTX coordinate i of node n (a force sensor)",
            extension=True),
    Keyword("OUTE", STATE_SPACE, (_p("k"), _p("e"), _p("i")), "output k is deformation i of element e",
            extension=True),
    Keyword("OUTEP", STATE_SPACE, (_p("k"), _p("e"), _p("i")), "output k is the rate of deformation i of element e",
            extension=True),
    Keyword("OUTS", STATE_SPACE, (_p("k"), _p("e"), _p("i")),
            "output k is the stress of deformation i of element e (a DYNE or released deformation)", extension=True),
    Keyword("EOF", CONTROL, (), "logical end of the input"),
    Keyword("END", CONTROL, (), "end of a block: the analysis runs, the state dump is printed"),
]

KEYWORDS: dict[str, Keyword] = {k.name: k for k in _element_keywords() + _OTHER}

# Lookup by the significant part of a keyword token: its first 8 characters, upper case.
LOOKUP: dict[str, Keyword] = {}
for _k in KEYWORDS.values():
    for _name in (_k.name, *_k.aliases):
        LOOKUP[_name[:8]] = _k


def did_you_mean(word) -> str:
    """" (did you mean TIMESTEP?)" for a misspelt keyword (the closest names of the catalogue),
    or ""."""
    import difflib

    if not isinstance(word, str):
        return ""
    close = difflib.get_close_matches(word.upper(), list(KEYWORDS), n=3, cutoff=0.6)
    return f" (did you mean {' or '.join(close)}?)" if close else ""

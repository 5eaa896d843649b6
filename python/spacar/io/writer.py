"""Writer of the state dump (manual §5.7; formulation.md §9.3): a complete, restartable input
block in the layout of the manual's example output. Keywords are left-justified in 8 columns,
integers are written as `` %3d`` and reals as `` %10.3E`` (4 significant digits, as the manual);
``digits`` selects more significant digits for a lossless restart.
"""
from __future__ import annotations

import numbers

from .. import _core
from .._util import show
from ..errors import InputError
from ..model import Model

_CLASS_KEYWORD_X = {
    _core.CoordClass.fixed: "FIX",
    _core.CoordClass.input: "INPUTX",
    _core.CoordClass.dynamic: "DYNX",
}
_CLASS_KEYWORD_E = {
    _core.DefClass.released: "RLSE",
    _core.DefClass.input: "INPUTE",
    _core.DefClass.dynamic: "DYNE",
    _core.DefClass.linearization: "LINE",
}
_NODE_KEYWORD = {
    _core.NodeKind.XY: "XY",
    _core.NodeKind.BETA: "BETA",
    _core.NodeKind.XYZ: "XYZ",
    _core.NodeKind.LAMBDA: "LAMBDA",
    _core.NodeKind.X: "X",
}


class _Lines:
    def __init__(self, digits: int):
        if isinstance(digits, bool) or not isinstance(digits, numbers.Integral) or not 1 <= digits <= 17:
            raise InputError(f"dump: digits must be an integer between 1 and 17, got {show(digits)}")
        digits = int(digits)
        self.real = f" {{:{digits + 6}.{digits - 1}E}}"
        self.out = []

    def add(self, keyword: str, ints=(), reals=()):
        text = f"{keyword:<8s}" + "".join(f" {i:3d}" for i in ints) + "".join(self.real.format(r) for r in reals)
        self.out.append(text.rstrip())


def dump(model, digits: int = 4) -> str:
    """The state dump of ``model`` (a :class:`spacar.Model`) as text, ending with ``END``.

    Before the first analysis the model is dumped as it will be analysed (a prepared copy: with
    the reference geometry ``LENGTHO``/``LGEOMY`` and the automatic ``L2MIN1`` elements), so the
    layout is the same before and after a run."""
    if not isinstance(model, Model):
        raise InputError(f"dump: model must be a spacar.Model, got {show(model)}")
    core = model.core
    if not core.frozen:
        core = core.copy()
        core.prepare()
    nodes = core.nodes
    elements = core.elements
    out = _Lines(digits)
    # 1. elements, as given at input
    for eid, el in sorted(elements.items()):
        out.add(el.type_name, [eid, *el.nodes], el.params)
    # 2. nodes with their current coordinates
    for nid, n in sorted(nodes.items()):
        out.add(_NODE_KEYWORD[n.kind], [nid], n.x)
    # 3. boundary conditions on coordinates, one line per coordinate
    for nid, n in sorted(nodes.items()):
        for i, c in enumerate(n.cls, start=1):
            if c in _CLASS_KEYWORD_X:
                out.add(_CLASS_KEYWORD_X[c], [nid, i])
    # 4. deformation classes, then the nonholonomic pairs
    for eid, el in sorted(elements.items()):
        for i, c in enumerate(el.cls, start=1):
            if c in _CLASS_KEYWORD_E:
                out.add(_CLASS_KEYWORD_E[c], [eid, i])
    for eid, el in sorted(elements.items()):
        for i, c in enumerate(el.cls, start=1):
            if c == _core.DefClass.nonholonomic:
                out.add("ENHC", [eid, i, *el.kinematic_of[i - 1]])
    # 5. time and rates of input and dynamic coordinates
    out.add("TIME", reals=[core.time])
    for nid, n in sorted(nodes.items()):
        for i, c in enumerate(n.cls, start=1):
            if c in (_core.CoordClass.input, _core.CoordClass.dynamic):
                out.add("XD", [nid, i], [n.xd[i - 1]])
                out.add("XDD", [nid, i], [n.xdd[i - 1]])
    # 6. values and rates of input, dynamic and kinematic deformations; non-zero targets
    moving = (_core.DefClass.input, _core.DefClass.dynamic, _core.DefClass.kinematic)
    for eid, el in sorted(elements.items()):
        for i, c in enumerate(el.cls, start=1):
            if c in moving:
                out.add("E", [eid, i], [el.e[i - 1]])
                out.add("ED", [eid, i], [el.ed[i - 1]])
                out.add("EDD", [eid, i], [el.edd[i - 1]])
    velocity_level = {t.name: t.velocity_level for t in _core.element_catalogue()}
    for eid, el in sorted(elements.items()):
        for i, c in enumerate(el.cls, start=1):
            if c in (_core.DefClass.fixed, _core.DefClass.linearization) and el.e_given[i - 1] and el.e[i - 1] != 0:
                out.add("E", [eid, i], [el.e[i - 1]])
            elif velocity_level[el.type_name][i - 1] and el.e_given[i - 1] and (
                    c == _core.DefClass.released or (c == _core.DefClass.nonholonomic and el.e[i - 1] != 0)):
                # integrated value of a slip (released) or the constant value of a nonholonomic one
                out.add("E", [eid, i], [el.e[i - 1]])
    # 7. reference geometry
    for eid, el in sorted(elements.items()):
        if el.l0 is not None:
            out.add("LENGTHO", [eid], [el.l0])
    for eid, el in sorted(elements.items()):
        if el.lgeomy:
            out.add("LGEOMY", [eid], el.lgeomy)
    # 8. properties
    for nid, n in sorted(nodes.items()):
        if n.mass:
            out.add("MASS", [nid], n.mass)
    for attr, keyword in (("emass", "EMASS"), ("estiff", "ESTIFF"), ("edampp", "EDAMPP")):
        for eid, el in sorted(elements.items()):
            if getattr(el, attr):
                out.add(keyword, [eid], getattr(el, attr))
    for attr, keyword in (("force", "FORCE"), ("torquel", "TORQUEL"), ("torqueg", "TORQUEG")):
        for nid, n in sorted(nodes.items()):
            if getattr(n, attr):
                out.add(keyword, [nid], getattr(n, attr))
    if core.gravity_given:
        out.add("GRAVITY", reals=core.gravity)
    # 9. state-space inputs and outputs
    for table in (model.state_space_inputs, model.state_space_outputs):
        for k, sig in sorted(table.items()):
            out.add(sig.keyword, [k, sig.number, sig.index])
    # 10. settings
    s = core.settings
    out.add("HMAX", reals=[s.hmax])
    out.add("MAXITERAT", [s.maxiterat])
    out.add("EPSKIN", reals=[s.epskin])
    out.add("EPSINT", reals=[s.epsint])
    out.add("EPSIND", reals=[s.epsind])
    for name in ("FORCEMODE", "ANIMATE", "MATASC", "RESTART"):
        out.add(name, [getattr(s, name.lower())])
    if s.jobid is not None:
        out.add("JOBID", [s.jobid])
    if s.linear is not None:
        out.add("LINEAR", [s.linear])
    out.add("TIMESTEP", [s.timestep_n], [s.timestep_tp])
    out.add("END")
    return "\n".join(out.out) + "\n"

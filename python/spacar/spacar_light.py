"""SPACAR Light's model, accepted as it is (docs/light.md): ``spacar.light`` ::

    out = spacar.light(nodes, elements, nprops, eprops, opt)      # SPACAR Light 1.38's call
    out = spacar.light(nodes, elements, nprops, eprops, rls, opt) # its earlier 1.x call
    out.step(10).node(3).p           # position of node 3 at load step 10 (1-based, as MATLAB)
    out.step(10).node(3).CMglob      # its 6 x 6 compliance in global axes
    out.step(1).freq                 # eigenfrequencies (Hz)
    out.model                        # the spacar.Model it built, at the last step

The inputs are those of spacarlight.m (precision-utwente/spalight): ``nodes`` (n x 3),
``elements`` (m x 2, node numbers from 1), ``nprops`` (a list with one dict, or None, per node:
``fix``, ``fix_pos``, ``force``, ``moment``, ``mass`` ...), ``eprops`` (a list of dicts: ``elems``,
``emod``, ``smod``, ``dens``, ``cshape``, ``dim``, ``orien``, ``nbeams``, ``flex`` ...), the releases
``rls`` (one ``{"def": [...]}`` per element) and ``opt`` (``gravity``, ``loadsteps``, ``calcbuck``,
``calccompl``, ``transfer`` ...). The model built is the one spacarlight.m writes: node i is the
XYZ node 3i − 2 and the LAMBDA node 3i − 1, each element is meshed into ``nbeams`` BEAMs through
new nodes numbered from 3n + 1 in steps of 3, the flexible deformations (``flex``) of the beams
are degrees of freedom (DYNE) with the section's stiffness (shear included) and mass, the others
rigid, and redundant ones are released (RLSE) as given in ``rls`` or, without it, found by the
constraint diagnosis (SPACAR Light's "autosolve").
"""
from __future__ import annotations

import math
import numbers
from types import SimpleNamespace

import numpy as np

from ._util import show
from .errors import InputError, SingularMassError
from .geometry import rotation
from .model import Model
from .section import Material, circle, rectangle, stresses

__all__ = ["light", "LightResults", "light_model"]

VERSION = "1.38"  # the SPACAR Light whose input and output this follows

NPROPS = ("fix", "fix_x", "fix_y", "fix_z", "fix_pos", "fix_orien", "fix_warp", "displ_x", "displ_y", "displ_z", "rot",
          "rot_x", "rot_y", "rot_z", "force", "moment", "mass", "mominertia", "force_initial", "moment_initial",
          "displ_initial_x", "displ_initial_y", "displ_initial_z", "rot_initial", "rot_initial_x", "rot_initial_y",
          "rot_initial_z", "transfer_in", "transfer_out")
EPROPS = ("elems", "emod", "smod", "dens", "cshape", "dim", "orien", "nbeams", "flex", "color", "hide", "opacity",
          "cw", "warping")
OPT = ("filename", "gravity", "silent", "calccompl", "calcbuck", "transfer", "mode", "rls", "loadsteps",
       "showinputonly", "customkin", "customdyn", "customvis", "spavisual", "rigidstress", "stressperelement")
# Options that ask for what spacar.light does not do, and why.
_REFUSED_OPT = {
    "customkin": "raw SPACAR input lines are not applied: add them to out.model with its keyword methods",
    "customdyn": "raw SPACAR input lines are not applied: add them to out.model with its keyword methods",
    "mode": "only the static analysis with load steps (SPACAR Light's mode 10) is run",
}
_AXES = {"x": 0, "y": 1, "z": 2}
_TRANSFER_IN = {"force_x": 1, "force_y": 2, "force_z": 3}
_TRANSFER_OUT = {"displ_x": ("OUTX", 1), "displ_y": ("OUTX", 2), "displ_z": ("OUTX", 3),
                 "veloc_x": ("OUTXP", 1), "veloc_y": ("OUTXP", 2), "veloc_z": ("OUTXP", 3)}


# ------------------------------------------------------------------------------------------------
# Reading SPACAR Light's structures
# ------------------------------------------------------------------------------------------------

def _fields(value, what: str) -> dict:
    """A struct of SPACAR Light as a dict: a mapping, an object with attributes, or None (an
    empty entry of a MATLAB struct array). Empty values ([] in MATLAB) count as absent."""
    if value is None:
        return {}
    if isinstance(value, dict):
        items = value
    elif hasattr(value, "__dict__"):
        items = vars(value)
    else:
        raise InputError(f"{what} must be a dict of fields (or None), got {show(value)}")
    return {k: v for k, v in items.items() if not _empty(v)}


def _empty(v) -> bool:
    if v is None or isinstance(v, str):
        return v is None or v == ""
    return isinstance(v, (list, tuple, np.ndarray)) and np.size(np.asarray(v, dtype=object)) == 0


def _per_item(value, count: int, what: str, item: str) -> list:
    """SPACAR Light's struct array (one entry per node or element, 1-based) as a list of dicts:
    a list (entry i for number i + 1) or a dict keyed by the number."""
    if value is None:
        return [{} for _ in range(count)]
    if isinstance(value, dict) and all(isinstance(k, numbers.Integral) for k in value):
        if any(not 1 <= k <= count for k in value):
            raise InputError(f"{what} names {item}s {sorted(k for k in value if not 1 <= k <= count)} that do not "
                             f"exist (1 to {count})")
        return [_fields(value.get(k + 1), f"{what}({k + 1})") for k in range(count)]
    if isinstance(value, dict) or hasattr(value, "__dict__") and not isinstance(value, (list, tuple)):
        value = [value]  # a single struct: the first
    if not isinstance(value, (list, tuple)):
        raise InputError(f"{what} must be a list with one entry per {item} (or a dict {{{item}: fields}}), "
                         f"got {show(value)}")
    if len(value) > count:
        raise InputError(f"{what} has {len(value)} entries but there are {count} {item}s: "
                         f"{what}({count + 1}) belongs to no {item}")
    out = [_fields(v, f"{what}({k + 1})") for k, v in enumerate(value)]
    return out + [{} for _ in range(count - len(out))]


def _unknown(fields: dict, allowed, what: str):
    bad = sorted(set(fields) - set(allowed), key=str)
    if bad:
        raise InputError(f"unknown {what} field {bad[0]!r} (SPACAR Light's fields: {', '.join(allowed)})")


def _vector(value, size: int, what: str) -> np.ndarray:
    try:
        v = np.asarray(value)
        v = v.astype(float).ravel() if v.dtype.kind in "iuf" else None  # numbers only: no text, no flags
    except (TypeError, ValueError):
        v = None
    if v is None or v.size != size or not np.isfinite(v).all():
        raise InputError(f"{what} must be {size} number{'s' if size > 1 else ''}, got {show(value)}")
    return v


def _number(value, what: str) -> float:
    return float(_vector(value, 1, what)[0])


def _whole(value, what: str, low: int, high: int) -> int:
    v = _number(value, what) if not isinstance(value, (bool, np.bool_)) else math.nan
    if not (v.is_integer() and low <= v <= high):
        raise InputError(f"{what} must be a whole number from {low} to {high}, got {show(value)}")
    return int(v)


def _flag(value, what: str) -> bool:
    if isinstance(value, np.ndarray) and value.size == 1:
        value = value.item()
    if isinstance(value, (bool, np.bool_)) or (isinstance(value, numbers.Integral) and value in (0, 1)):
        return bool(value)
    raise InputError(f"{what} must be true or false, got {show(value)}")


def _numbers_list(value, what: str, low: int, high: int) -> list:
    try:
        v = np.atleast_1d(np.asarray(value)).ravel()
    except ValueError:  # ragged
        v = np.array(["?"])
    if v.dtype.kind not in "iuf" or not all(float(x).is_integer() and low <= x <= high for x in v):
        raise InputError(f"{what} must be numbers from {low} to {high}, got {show(value)}")
    return [int(x) for x in v]


def _quaternion_axis_angle(axang, what: str) -> np.ndarray:
    """SPACAR Light's rotation [angle, axis x, y, z] as Euler parameters."""
    v = _vector(axang, 4, what)
    axis = v[1:]
    if not np.linalg.norm(axis) > 0:
        raise InputError(f"{what} must be [angle, x, y, z] with a nonzero axis, got {show(axang)}")
    return np.r_[math.cos(v[0] / 2), math.sin(v[0] / 2) * axis / np.linalg.norm(axis)]


def _quaternion_about(axis: int, angle: float) -> np.ndarray:
    q = np.zeros(4)
    q[0], q[axis + 1] = math.cos(angle / 2), math.sin(angle / 2)
    return q


class _Element:
    """One element of SPACAR Light: its nodes, its property set and its beams."""

    def __init__(self, number, p, q):
        self.number, self.p, self.q = number, p, q
        self.nbeams, self.orien, self.flex, self.section, self.set = 1, np.array([0.0, 1.0, 0.0]), [], None, None
        self.warping = False  # eprops.warping: BEAMW, flexible in its warping deformations 7 and 8 too
        self.mass_section = None
        self.beams: list = []


def _section(props: dict, k: int, need_stiffness: bool, need_mass: bool):
    """The spacar Section of property set k (1-based): 'rect' [width, thickness] with the width
    along orien (the section's y axis) or 'circ' [diameter]."""
    where = f"eprops({k})"
    for name in ("cshape", "dim") + (("emod", "smod") if need_stiffness else ()) + (("dens",) if need_mass else ()):
        if name not in props:
            raise InputError(f"{where} needs {name!r} for its {'flexible' if name in ('emod', 'smod') else ''} "
                             f"elements {show(props.get('elems'))}".replace("  ", " "))
    E = _number(props["emod"], f"{where}.emod") if "emod" in props else 1.0
    G = _number(props["smod"], f"{where}.smod") if "smod" in props else E / 2.6
    rho = _number(props.get("dens", 0.0), f"{where}.dens")
    try:
        material = Material(E, G=G, rho=rho, name=where)
    except InputError as err:
        raise InputError(f"{where}: {err}") from None
    shape = str(props["cshape"]).lower()
    if shape == "rect":
        w, t = _vector(props["dim"], 2, f"{where}.dim (rect: [width thickness])")
        return rectangle(b=t, h=w, material=material)  # h along y: the width along orien
    if shape == "circ":
        (d,) = _vector(props["dim"], 1, f"{where}.dim (circ: [diameter])")
        return circle(d, material=material)
    raise InputError(f"{where}.cshape must be 'rect' or 'circ', got {show(props['cshape'])}")


# ------------------------------------------------------------------------------------------------
# The model
# ------------------------------------------------------------------------------------------------

class _Light:
    """SPACAR Light's input checked and turned into a spacar.Model (:func:`light_model`)."""

    def __init__(self, nodes, elements, nprops, eprops, rls, opt):
        self.opt = _fields(opt, "opt")
        _unknown(self.opt, OPT, "opt")
        for name, why in _REFUSED_OPT.items():
            if name in self.opt and not (name == "mode" and _number(self.opt[name], "opt.mode") == 10):
                raise InputError(f"opt.{name} is not supported by spacar.light: {why}")
        if rls is not None and "rls" in self.opt:
            raise InputError("the releases are given twice: as the argument rls and as opt.rls")
        rls = self.opt.get("rls", rls)
        self.nodes = self._nodes(nodes)
        n = len(self.nodes)
        self.elements = self._elements(elements, n)
        self.nprops = _per_item(nprops, n, "nprops", "node")
        for k, p in enumerate(self.nprops):
            _unknown(p, NPROPS, f"nprops({k + 1})")
        sets = eprops if isinstance(eprops, (list, tuple)) else [eprops]
        self.eprops = [_fields(e, f"eprops({k + 1})") for k, e in enumerate(sets)]
        for k, e in enumerate(self.eprops):
            _unknown(e, EPROPS, f"eprops({k + 1})")
        self.notes: list = []  # remarks for the results' warnings
        self.rls = None if rls is None else [self._releases(k + 1, r) for k, r in
                                             enumerate(_per_item(rls, len(self.elements), "rls", "element"))]
        self._element_sets()
        self.loadsteps = _whole(self.opt.get("loadsteps", 10), "opt.loadsteps", 1, 10**5)
        self.transfer = self._transfer()
        for node in range(1, n + 1):  # every load and motion read now, before any work
            self._combinations(node)
            self.loads(node, 1.0)
            self.inputs(node, 1.0)

    @staticmethod
    def _releases(k: int, r: dict) -> list:
        _unknown(r, ("def",), f"rls({k})")
        return _numbers_list(r["def"], f"rls({k}).def", 1, 6) if r else []

    @staticmethod
    def _nodes(nodes) -> np.ndarray:
        try:
            a = np.asarray(nodes, dtype=float)
        except (TypeError, ValueError):
            a = None
        if a is None or a.ndim != 2 or a.shape[1] != 3 or len(a) == 0 or not np.isfinite(a).all():
            raise InputError(f"nodes must be an n x 3 array of x y z, got {show(nodes)}")
        return a

    def _elements(self, elements, n) -> list:
        try:
            a = np.asarray(elements)
        except ValueError:  # ragged
            a = np.zeros(0)
        if a.ndim == 1 and a.size == 2:
            a = a.reshape(1, 2)
        if a.ndim != 2 or a.shape[1] != 2 or len(a) == 0 or a.dtype.kind not in "iuf":
            raise InputError(f"elements must be an m x 2 array of node numbers (p q), got {show(elements)}")
        out = []
        for k, (p, q) in enumerate(a):
            if not (float(p).is_integer() and float(q).is_integer() and 1 <= p <= n and 1 <= q <= n):
                raise InputError(f"element {k + 1} joins nodes {show([p.item(), q.item()])}: node numbers run from 1 "
                                 f"to {n}")
            if p == q:
                raise InputError(f"element {k + 1} joins node {int(p)} to itself")
            if not np.linalg.norm(self.nodes[int(q) - 1] - self.nodes[int(p) - 1]) > 0:
                raise InputError(f"element {k + 1} has no length: nodes {int(p)} and {int(q)} are at the same point")
            out.append(_Element(k + 1, int(p), int(q)))
        unused = sorted(set(range(1, n + 1)) - {e.p for e in out} - {e.q for e in out})
        if unused:
            raise InputError(f"node {unused[0]} is not connected to any element")
        return out

    def _element_sets(self):
        for k, props in enumerate(self.eprops, start=1):
            if "elems" not in props:
                continue  # SPACAR Light ignores a set without elements (with a warning)
            elems = _numbers_list(props["elems"], f"eprops({k}).elems", 1, len(self.elements))
            if len(set(elems)) < len(elems):
                raise InputError(f"eprops({k}).elems lists an element twice: {elems}")
            for e in elems:
                el = self.elements[e - 1]
                if el.set is not None:
                    raise InputError(f"element {e} is in eprops({el.set}) and eprops({k}): one set per element")
                el.set = k
                el.warping = _flag(props.get("warping", False), f"eprops({k}).warping")
                _flag(props.get("cw", False), f"eprops({k}).cw")  # 1.38: deprecated, no effect
                el.nbeams = _whole(props.get("nbeams", 1), f"eprops({k}).nbeams", 1, 10000)
                if "orien" in props:
                    el.orien = _vector(props["orien"], 3, f"eprops({k}).orien")
                el.flex = sorted(set(_numbers_list(props["flex"], f"eprops({k}).flex", 1, 6))) if "flex" in props else []
                dens = _number(props.get("dens", 0.0), f"eprops({k}).dens")
                if el.flex or dens > 0:
                    section = _section(props, k, bool(el.flex), dens > 0)
                    el.section = section if el.flex else None
                    el.mass_section = section if dens > 0 else None
                    if el.warping and section.Iw == 0.0:  # spacarlight.m: a round section does not warp
                        el.warping = False
                        self.notes.append(f"eprops({k}).warping: a circular cross-section does not warp; modelled "
                                          "without warping")
        for el in self.elements:  # the width's direction across every element, given or the default
            axis = self.nodes[el.q - 1] - self.nodes[el.p - 1]
            across = el.orien - np.dot(el.orien, axis) * axis / np.dot(axis, axis)
            if not np.linalg.norm(across) > 1e-9 * np.linalg.norm(el.orien):
                where = f"eprops({el.set}).orien" if el.set and "orien" in self.eprops[el.set - 1] else \
                    "the default orien (no orien given)"
                raise InputError(f"{where} {show(el.orien.tolist())} lies along element {el.number}: give the "
                                 "direction of the cross-section's width, across the element")

    def _transfer(self):
        """opt.transfer = [true, ζ] with the nodes' transfer_in/out: (ζ or None, inputs, outputs,
        their names); None without it."""
        names = {}
        for j, props in enumerate(self.nprops, start=1):
            for field, allowed in (("transfer_in", _TRANSFER_IN), ("transfer_out", _TRANSFER_OUT)):
                given = props.get(field, [])
                given = [given] if isinstance(given, str) else given
                if not isinstance(given, (list, tuple)) or not all(isinstance(g, str) and g in allowed for g in given) \
                        or len(set(given)) < len(given):
                    raise InputError(f"nprops({j}).{field} must be distinct names of {', '.join(allowed)}, got "
                                     f"{show(props.get(field))}")
                names[j, field] = list(given)
        spec = self.opt.get("transfer")
        spec = list(spec) if isinstance(spec, (list, tuple)) else [spec]
        if spec == [None] or not _flag(spec[0], "opt.transfer{1}"):
            return None
        zeta = None if len(spec) < 2 else _number(spec[1], "opt.transfer{2} (the relative damping)")
        inputs = [("INPUTF", 3 * j - 2, _TRANSFER_IN[n]) for (j, f), ns in names.items() if f == "transfer_in"
                  for n in ns]
        outputs = [(_TRANSFER_OUT[n][0], 3 * j - 2, _TRANSFER_OUT[n][1]) for (j, f), ns in names.items()
                   if f == "transfer_out" for n in ns]
        label = lambda f: [f"{n.replace('_', '-')} n{j}" for (j, g), ns in names.items() if g == f for n in ns]  # noqa: E731
        if not inputs or not outputs:
            raise InputError("opt.transfer needs transfer_in and transfer_out in nprops")
        return zeta, inputs, outputs, label("transfer_in"), label("transfer_out")

    def _combinations(self, node: int):
        """What spacarlight.m refuses on one node: a direction both fixed and loaded or moved."""
        p = self.nprops[node - 1]
        flag = lambda name: _flag(p.get(name, False), f"nprops({node}).{name}")  # noqa: E731
        if flag("fix") and any(flag(f) for f in ("fix_pos", "fix_orien", "fix_x", "fix_y", "fix_z", "fix_warp")):
            raise InputError(f"nprops({node}) combines fix with fix_pos, fix_orien, fix_warp or fix_x/y/z")
        held = flag("fix") or flag("fix_pos")
        for axis, i in _AXES.items():
            loaded = any(name in p and _vector(p[name], 3, f"nprops({node}).{name}")[i] != 0
                         for name in ("force", "force_initial"))
            moved = f"displ_{axis}" in p or f"displ_initial_{axis}" in p
            if (held or flag(f"fix_{axis}")) + loaded + moved > 1:
                raise InputError(f"nprops({node}) fixes, loads or moves the {axis} position at once: one of them")
        turned = [name for name in ("rot", "rot_x", "rot_y", "rot_z") if name in p or
                  name.replace("rot", "rot_initial") in p]
        if len(turned) > 1:
            raise InputError(f"nprops({node}) prescribes {' and '.join(turned)}: one input rotation per node")
        twisted = any(name in p and _vector(p[name], 3, f"nprops({node}).{name}").any()
                      for name in ("moment", "moment_initial"))
        if (flag("fix") or flag("fix_orien")) + twisted + bool(turned) > 1:
            raise InputError(f"nprops({node}) fixes, loads (moment) or turns (rot) the orientation at once: one of them")

    # --- the spacar model ---

    def model(self) -> Model:
        m = Model()
        n = len(self.nodes)
        for i, x in enumerate(self.nodes):
            self._declare(m, 3 * i + 1, x)
        next_node, beam = 3 * n + 1, 1
        warped, restrained = set(), set()  # warping nodes used; those held (by rigid warping elements)
        for el in self.elements:
            # (position, orientation, warping) nodes of the points along the element
            points = [(3 * el.p - 2, 3 * el.p - 1, 3 * el.p)]
            a, b = self.nodes[el.p - 1], self.nodes[el.q - 1]
            for k in range(1, el.nbeams):
                self._declare(m, next_node, a + (b - a) * k / el.nbeams)
                points.append((next_node, next_node + 1, next_node + 2))
                next_node += 3
            points.append((3 * el.q - 2, 3 * el.q - 1, 3 * el.q))
            el.beams = list(range(beam, beam + el.nbeams))
            for k, e in enumerate(el.beams):
                (p, o, w), (q, r, v) = points[k], points[k + 1]
                if el.warping and el.flex:
                    m.beamw(e, p, o, q, r, w, v, *el.orien)
                    warped.update((w, v))
                else:
                    m.beam(e, p, o, q, r, *el.orien)
                    if el.warping:  # a rigid element with warping holds the warping of its ends
                        restrained.update(pt[2] for pt in points)
            beam += el.nbeams
        self._warping_supports(m, warped, restrained)
        for el in self.elements:
            self._properties(m, el)
        for i, props in enumerate(self.nprops):
            self._supports(m, i + 1, props)
        for i, props in enumerate(self.nprops):
            if "mass" in props:
                m.mass(3 * i + 1, float(_vector(props["mass"], 1, f"nprops({i + 1}).mass")[0]))
            if "mominertia" in props:
                m.mass(3 * i + 2, *_vector(props["mominertia"], 6, f"nprops({i + 1}).mominertia"))
        if "gravity" in self.opt:
            m.gravity(*_vector(self.opt["gravity"], 3, "opt.gravity"))
        m.timestep(1, 1.0)  # a static block moves its inputs by XD over this period
        return m

    def _warping_supports(self, m: Model, warped: set, restrained: set):
        """The warping nodes fixed at a node fixed (fix) or with fix_warp and where a rigid element
        with warping ends (spacarlight.m's rules); the others free, degrees of freedom (DYNX),
        since BEAMW's warping deformations are released (spacarlight.m: "always calculable")."""
        for i, props in enumerate(self.nprops, start=1):
            if _flag(props.get("fix", False), f"nprops({i}).fix") or _flag(props.get("fix_warp", False),
                                                                          f"nprops({i}).fix_warp"):
                restrained.add(3 * i)
        for w in sorted(warped):
            (m.fix if w in restrained else m.dynx)(w)

    @staticmethod
    def _declare(m: Model, node: int, x):
        m.xyz(node, *x)
        m.lambda_(node + 1, 1.0, 0.0, 0.0, 0.0)

    def _properties(self, m: Model, el: _Element):
        released = self.rls[el.number - 1] if self.rls is not None else []
        for k, e in enumerate(el.beams):
            dynamic = [d for d in el.flex if not (k == len(el.beams) - 1 and d in released)]
            if dynamic:
                m.dyne(e, *dynamic)
            if k == len(el.beams) - 1 and released:
                m.rlse(e, *released)
            warping = el.warping and bool(el.flex)
            if warping:
                m.rlse(e, 7, 8)
            if el.section is not None:
                m.estiff(e, *el.section.beam_estiff(shear=True, warping=warping))
            if el.mass_section is not None:
                m.emass(e, *el.mass_section.emass(rotary=True, warping=warping))

    def _supports(self, m: Model, node: int, props: dict):
        """FIX and INPUTX of a node of SPACAR Light (their combinations checked in _combinations;
        its warping node in _warping_supports)."""
        pos, rot = 3 * node - 2, 3 * node - 1
        flag = lambda name: _flag(props.get(name, False), f"nprops({node}).{name}")  # noqa: E731
        if flag("fix") or flag("fix_pos"):
            m.fix(pos)
        if flag("fix") or flag("fix_orien"):
            m.fix(rot)
        for axis, i in _AXES.items():
            if flag(f"fix_{axis}"):
                m.fix(pos, i + 1)
            if f"displ_{axis}" in props or f"displ_initial_{axis}" in props:
                m.inputx(pos, i + 1)
        for (target, c) in self.inputs(node, 0.0):
            if target == rot:
                m.inputx(rot, c)

    def loads(self, node: int, factor: float) -> dict:
        """{(keyword, node): values} of node's loads at the load factor (initial + factor · additional)."""
        props, out = self.nprops[node - 1], {}
        for name, keyword, target in (("force", "FORCE", 3 * node - 2), ("moment", "TORQUEG", 3 * node - 1)):
            if name in props or f"{name}_initial" in props:
                v = np.zeros(3)
                if f"{name}_initial" in props:
                    v += _vector(props[f"{name}_initial"], 3, f"nprops({node}).{name}_initial")
                if name in props:
                    v += factor * _vector(props[name], 3, f"nprops({node}).{name}")
                out[(keyword, target)] = v
        return out

    def inputs(self, node: int, factor: float) -> dict:
        """{(node, component): value} of node's prescribed coordinates at the load factor."""
        props, out = self.nprops[node - 1], {}
        x0 = self.nodes[node - 1]
        for axis, i in _AXES.items():
            a, b = props.get(f"displ_initial_{axis}"), props.get(f"displ_{axis}")
            if a is not None or b is not None:
                value = x0[i]
                value += _vector(a, 1, f"nprops({node}).displ_initial_{axis}")[0] if a is not None else 0.0
                value += factor * _vector(b, 1, f"nprops({node}).displ_{axis}")[0] if b is not None else 0.0
                out[(3 * node - 2, i + 1)] = value
        # Rotations as spacarlight.m writes them: INPUTX of the Euler parameters λ1..λ3 of the
        # initial rotation, DELINPX of those of the additional one; they move linearly with the load.
        for name in ("rot", "rot_x", "rot_y", "rot_z"):
            a, b = props.get(name.replace("rot", "rot_initial")), props.get(name)
            if a is None and b is None:
                continue
            components = (2, 3, 4) if name == "rot" else (_AXES[name[-1]] + 2,)
            value = np.zeros(4)
            for part, f, field in ((a, 1.0, name.replace("rot", "rot_initial")), (b, factor, name)):
                if part is None:
                    continue
                what = f"nprops({node}).{field}"
                value += f * (_quaternion_axis_angle(part, what) if name == "rot" else
                              _quaternion_about(_AXES[name[-1]], _number(part, what)))
            for c in components:
                out[(3 * node - 1, c)] = value[c - 1]
        return out

    def has_additional(self) -> bool:
        names = ("force", "moment", "displ_x", "displ_y", "displ_z", "rot", "rot_x", "rot_y", "rot_z")
        return any(name in p for p in self.nprops for name in names)


def _release(m: Model, light: _Light, diagnosis) -> list:
    """SPACAR Light's autosolve: the degrees of freedom (DYNE) that ``diagnosis`` (the model's,
    named with release_dynamic) finds redundant become released (RLSE); returns [(beam,
    deformation)] released."""
    from .check import check

    if not diagnosis.detailed:
        raise InputError(f"the model has {diagnosis.n_constraints} constraints, too many for the automatic release: "
                         "give the releases (opt.rls) by hand")
    redundant = [tuple(r) for r in diagnosis.redundant]
    beams = {e: el for el in light.elements for e in el.beams}
    rigid = [(e, i) for e, i in redundant if e not in beams or i not in beams[e].flex]
    if rigid:
        text = check(m).diagnosis.text
        raise InputError("the model is over-constrained where it is rigid (a closed loop of rigid elements, or "
                         "supports that fix a rigid body twice): releasing flexible deformations cannot solve it; "
                         f"the constraint diagnosis:\n{text}")
    for e, i in redundant:
        m.rlse(e, i)
    return redundant


def light_model(nodes, elements, nprops, eprops, rls=None, opt=None) -> Model:
    """The spacar.Model that :func:`light` builds, the releases made, with all its loads (initial
    and additional) and its prescribed motions set to reach their final values in one block:
    ``spacar.static(light_model(...))`` solves the last load step; a model to go on with in
    spacar."""
    m, light_, _ = _build(nodes, elements, nprops, eprops, rls, opt)
    _apply(m, light_, 1.0)
    return m


def _build(nodes, elements, nprops, eprops, rls, opt):
    releases = isinstance(rls, (list, tuple)) or isinstance(rls, dict) and (
        "def" in rls or any(isinstance(k, numbers.Integral) for k in rls))
    if opt is None and rls is not None and not releases:
        rls, opt = None, rls  # the 1.38 call: opt fifth
    from .check import check

    light = _Light(nodes, elements, nprops, eprops, rls, opt)
    m = light.model()
    diagnosis, released = check(m, release_dynamic=light.rls is None).diagnosis, []
    if light.rls is None and (diagnosis.redundant or not diagnosis.detailed):  # released, then diagnosed again
        released = _release(m, light, diagnosis)
        diagnosis = check(m).diagnosis
    if not diagnosis.ok:
        raise InputError("the model is not exactly constrained (check the supports fix, fix_pos ..., the elements' "
                         f"flex and the releases rls):\n{diagnosis.text}")
    return m, light, released


# ------------------------------------------------------------------------------------------------
# Results, shaped as spacarlight.m's
# ------------------------------------------------------------------------------------------------

class _OneBased:
    """A list read as SPACAR Light's struct array: ``s(k)`` 1-based as in MATLAB, ``s[k]`` 0-based
    as in Python, ``len(s)``, iteration."""

    def __init__(self, items, what: str):
        self._items, self._what = list(items), what

    def __call__(self, k):
        if isinstance(k, bool) or not isinstance(k, numbers.Integral) or not 1 <= k <= len(self._items):
            raise InputError(f"{self._what}({show(k)}): {self._what}s are numbered 1 to {len(self._items)}")
        return self._items[k - 1]

    def __getitem__(self, k):
        return self._items[k]

    def __len__(self):
        return len(self._items)

    def __iter__(self):
        return iter(self._items)

    def __repr__(self):
        if not self._items:
            return f"<no {self._what}s>"
        return f"<{len(self._items)} {self._what}s: {self._what}(1) … {self._what}({len(self._items)})>"


class LightNode(SimpleNamespace):
    """A node's results at a load step (``out.step(i).node(j)``) or over all of them
    (``out.node(j)``, load steps along the last axis): ``p`` (position), ``r_quat`` (Euler
    parameters λ0..λ3), ``r_axang`` (angle, axis x y z), ``r_eulzyx`` (Euler angles ZYX: about z,
    y, x), ``Freac`` and ``Mreac`` (the reaction force and moment of its supports and inputs, global
    axes), ``CMglob``/``CMloc`` (its 6 x 6 compliance in global and in the node's own axes, per
    force and moment, when ``opt.calccompl``). SPACAR Light 1.x's names ``x``, ``rx_quat``,
    ``rx_axang``, ``rx_eulzyx`` give the same."""

    x = property(lambda self: self.p)
    rx_quat = property(lambda self: self.r_quat)
    rx_axang = property(lambda self: self.r_axang)
    rx_eulzyx = property(lambda self: self.r_eulzyx)


class LightStep(SimpleNamespace):
    """The results of one load step: ``node(j)``, ``element(j)`` (``e``: the deformations of its
    beams, nbeams x 6; ``stressmax`` with ``opt.stressperelement``), ``freq`` (Hz, ascending),
    ``freqmodes`` (their mode shapes in the degrees of freedom), ``buck`` (load multipliers, with
    ``opt.calcbuck``), ``stressmax`` (the largest von Mises stress of the flexible elements), ``load``
    (the load factor of the additional loads), ``results`` (the spacar.Results of the step)."""


class LightResults(SimpleNamespace):
    """What :func:`light` returns, as spacarlight.m's ``results``: ``step(i)`` (:class:`LightStep`),
    ``node(j)`` (:class:`LightNode` over all steps), ``freq`` (modes x steps), ``buck``,
    ``stressmax`` (per step), ``element(j)`` (``spa_nrs``: its beams, ``L0``: their lengths), ``ndof``,
    ``version``, ``rls`` (the releases used, per element), ``statespace`` (with ``opt.transfer``),
    and beyond SPACAR Light: ``model`` (the spacar.Model at the last step), ``sections``."""


def _axis_angle(q) -> np.ndarray:
    angle = 2 * math.acos(max(-1.0, min(1.0, q[0])))
    s = math.sqrt(max(0.0, 1 - q[0] ** 2))
    axis = np.array([1.0, 0.0, 0.0]) if s < 1e-3 else np.asarray(q[1:]) / s
    return np.r_[angle, axis]


def _euler_zyx(q) -> np.ndarray:
    q = np.asarray(q) / np.linalg.norm(q)
    w, x, y, z = q
    return np.array([math.atan2(2 * (x * y + w * z), w * w + x * x - y * y - z * z),
                     math.asin(max(-1.0, min(1.0, -2 * (x * z - w * y)))),
                     math.atan2(2 * (y * z + w * x), w * w - x * x - y * y + z * z)])


def light(nodes, elements, nprops=None, eprops=None, rls=None, opt=None, *, time_limit=None) -> LightResults:
    """SPACAR Light's static analysis of the model given as spacarlight.m takes it (see the
    module's docstring and docs/light.md): ``light(nodes, elements, nprops, eprops, opt)`` (1.38,
    releases in ``opt["rls"]``) or ``light(nodes, elements, nprops, eprops, rls, opt)`` (1.x).

    The loads and prescribed motions are applied in ``opt["loadsteps"]`` (default 10) steps: step
    1 holds the initial ones (``force_initial``, ``moment_initial``, ``displ_initial_*``,
    ``rot_initial*``, gravity), step k adds (k − 1)/(loadsteps − 1) of the others (``force``,
    ``moment``, ``displ_*``, ``rot*``); with no others there is one step. Moments are fixed in
    global axes (TORQUEG). At every step: the equilibrium (:func:`spacar.static`), the compliance
    of every node (:func:`spacar.compliance`), the eigenfrequencies (when the model has mass) and,
    with ``opt["calcbuck"]``, the buckling load multipliers of the step's loads
    (:func:`spacar.linearize`), and the largest stress (:func:`spacar.section.stresses`).
    ``time_limit``: wall-clock seconds for each static solve."""
    from .statespace import state_space
    from .statics import static

    m, light_, released = _build(nodes, elements, nprops, eprops, rls, opt)
    opt = light_.opt
    out = LightResults(version=VERSION, model=m, warnings=list(light_.notes), rls=_releases(light_, released))
    out.sections = {e: el.section for el in light_.elements if el.section is not None for e in el.beams}
    if _flag(opt.get("showinputonly", False), "opt.showinputonly"):
        out.step = _OneBased([], "step")
        return out
    n_nodes = len(light_.nodes)
    factors = [0.0] if not light_.has_additional() else \
        list(np.linspace(0.0, 1.0, light_.loadsteps)) if light_.loadsteps > 1 else [1.0]
    calccompl = _flag(opt.get("calccompl", True), "opt.calccompl")
    calcbuck = _flag(opt.get("calcbuck", False), "opt.calcbuck")
    rigidstress = _flag(opt.get("rigidstress", False), "opt.rigidstress")
    per_element = _flag(opt.get("stressperelement", False), "opt.stressperelement")
    stressed = {e: (el.section or el.mass_section) for el in light_.elements for e in el.beams
                if (el.section is not None or (rigidstress and el.mass_section is not None))}
    steps = []
    for k, factor in enumerate(factors):
        _apply(m, light_, factor)
        res = static(m, steps=10 if k == 0 else 1, time_limit=time_limit)
        if res.stats["indefinite_at"] is not None:
            out.warnings.append(f"load step {k + 1}: the equilibrium is unstable (the tangent stiffness became "
                                "indefinite in it: a buckling load was passed)")
        steps.append(_step(m, light_, res, factor, n_nodes, calccompl, calcbuck, stressed, per_element, out))
    out.warnings += [w for w in m.warnings if w not in out.warnings]
    out.step = _OneBased(steps, "step")
    out.ndof = len(steps[-1].results.dof_labels)
    if out.ndof == 0:
        out.warnings.append("the model has no degrees of freedom (no flex): everything is rigid")
    out.freq = _columns([s.freq for s in steps])
    if calcbuck:
        out.buck = _columns([s.buck for s in steps])
    out.stressmax = np.array([s.stressmax for s in steps])
    out.node = _OneBased([_history(steps, j) for j in range(n_nodes)], "node")
    out.element = _OneBased([_element(light_, el) for el in light_.elements], "element")
    if light_.transfer is not None:
        zeta, inputs, outputs, in_names, out_names = light_.transfer
        out.statespace = state_space(m, inputs=inputs, outputs=outputs, damping=zeta)
        out.statespace.input_names, out.statespace.output_names = in_names, out_names
    return out


def _element(light_: _Light, el: _Element) -> SimpleNamespace:
    """``spa_nrs``: its beams; ``L0``: their lengths; ``Ri``: the axes of its beams at the start
    (columns: along the element, the width's direction orien, their cross product)."""
    axis = light_.nodes[el.q - 1] - light_.nodes[el.p - 1]
    x = axis / np.linalg.norm(axis)
    y = el.orien - np.dot(el.orien, x) * x
    y /= np.linalg.norm(y)
    return SimpleNamespace(spa_nrs=list(el.beams), L0=np.full(el.nbeams, np.linalg.norm(axis) / el.nbeams),
                           Ri=np.column_stack([x, y, np.cross(x, y)]))


def _releases(light_: _Light, released) -> list:
    """The releases per element as SPACAR Light's rls: [{"def": [...]}, ...]."""
    if light_.rls is not None:
        return [{"def": list(r)} for r in light_.rls]
    owner = {e: el.number for el in light_.elements for e in el.beams}
    out = [set() for _ in light_.elements]
    for e, i in released:
        out[owner[e] - 1].add(i)
    return [{"def": sorted(r)} for r in out]


def _apply(m: Model, light_: _Light, factor: float):
    """The loads and input targets of the load factor on the model (inputs by their XD over the
    block's period of 1)."""
    for node in range(1, len(light_.nodes) + 1):
        for (keyword, target), v in light_.loads(node, factor).items():
            (m.force if keyword == "FORCE" else m.torqueg)(target, *v)
        for (target, c), value in light_.inputs(node, factor).items():
            m.xd(target, c, value - m.nodes[target].x[c - 1])


def _step(m, light_, res, factor, n_nodes, calccompl, calcbuck, stressed, per_element, out) -> LightStep:
    from .compliance import compliance
    from .linearize import linearize

    step = LightStep(load=float(factor), results=res)
    nodes = []
    for j in range(1, n_nodes + 1):
        pos, rot = 3 * j - 2, 3 * j - 1
        q = np.array(m.nodes[rot].x[:4])
        node = LightNode(p=np.array(m.nodes[pos].x[:3]), r_quat=q, r_axang=_axis_angle(q), r_eulzyx=_euler_zyx(q),
                         Freac=res.node(pos).reaction[-1].copy(), Mreac=res.reaction_moment(rot)[-1])
        if calccompl:
            C = compliance(m, pos, rotation=rot)
            T = np.kron(np.eye(2), rotation(q).T)
            node.CMglob, node.CMloc = C, T @ C @ T.T
        nodes.append(node)
    step.node = _OneBased(nodes, "node")
    lin = linearize(m)
    try:
        f, shapes, _ = lin.mode_shapes()
        step.freq, step.freqmodes = np.asarray(f), shapes
    except SingularMassError:
        step.freq, step.freqmodes = np.zeros(0), None
        massless = "no eigenfrequencies: the model has no mass (give dens or mass)"
        if massless not in out.warnings:  # once, beside the other warnings
            out.warnings.append(massless)
    if calcbuck:
        step.buck = np.sort(np.abs(lin.buckling_factors()))
    elements = []
    s = stresses(res, stressed) if stressed else None
    values = s.at(-1, "von_mises") if s is not None else {}
    step.stressmax = max(values.values(), default=0.0)
    for el in light_.elements:
        entry = SimpleNamespace(e=np.array([[res.e[-1, res.deformation_index(b, i)] for i in range(1, 7)]
                                            for b in el.beams]))
        if per_element:
            entry.stressmax = max((values[b] for b in el.beams if b in values), default=0.0)
        elements.append(entry)
    step.element = _OneBased(elements, "element")
    return step


def _columns(rows) -> np.ndarray:
    """Per-step vectors as the columns of one array (NaN where a step has fewer)."""
    n = max((len(r) for r in rows), default=0)
    a = np.full((n, len(rows)), np.nan)
    for k, r in enumerate(rows):
        a[:len(r), k] = r
    return a


def _history(steps, j) -> LightNode:
    nodes = [s.node[j] for s in steps]
    out = LightNode(**{name: np.stack([getattr(n, name) for n in nodes], axis=-1)
                       for name in ("p", "r_quat", "r_axang", "r_eulzyx", "Freac", "Mreac")})
    out.spa_nrs = [3 * j + 1, 3 * j + 2]  # its XYZ and LAMBDA nodes
    if hasattr(nodes[0], "CMglob"):
        out.CMglob = np.stack([n.CMglob for n in nodes], axis=-1)
        out.CMloc = np.stack([n.CMloc for n in nodes], axis=-1)
    return out

"""What a drawing of a mechanism needs to know about the model, and the shapes to draw.

:class:`Geometry` is a lightweight, picklable description of the model attached to
:class:`spacar.Results` by :func:`spacar.simulate` (``res.geometry``): node kinds, the elements
with their node numbers, reference geometry (``l0``, ``LGEOMY``: PLBEAM α0, BEAM reference
frame) and definition-line numbers, the class of every nodal coordinate and the nodal masses.

:func:`shapes` turns the nodal coordinates of one output time into simple shapes (polylines and
symbols, in 2-D for planar models and 3-D otherwise). It uses only NumPy; the matplotlib code
is in :mod:`spacar.plotting`. Beams are drawn with their cubic deflection shape: the Hermite
interpolation of the nodal positions and the nodal material tangents that also defines their
consistent mass (formulation.md §4.2, §4.8)::

    r(ξ) = H1 x_p + H2 l0 t_p + H3 x_q + H4 l0 t_q,   ξ ∈ [0, 1]
    H1 = 1 − 3ξ² + 2ξ³,  H2 = ξ − 2ξ² + ξ³,  H3 = 3ξ² − 2ξ³,  H4 = −ξ² + ξ³

with t = (cos(α0 + β), sin(α0 + β)) for PLBEAM(NL) and t = R(λ) e_x0 for BEAM(NL).

Each element is drawn by the drawing of its family (``ElementType.family`` of the catalogue:
beams, trusses, hinges, belts, wheels); a type of another family is drawn as a line through its
position nodes (a point if it has one, nothing if it has none).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache
from typing import NamedTuple

import numpy as np

POSITION_KINDS = ("XY", "XYZ")
ORIENTATION_KINDS = ("BETA", "LAMBDA")


@lru_cache(maxsize=None)
def _families() -> dict:
    from . import _core

    return {t.name: t.family.name for t in _core.element_catalogue()}


def family(type_name: str) -> str:
    """The catalogue family of an element type ("Beam", "Truss", "Hinge", "Belt", "Wheel"), or
    "Other" (also for a type the catalogue does not know)."""
    return _families().get(type_name, "Other")


@dataclass
class ElementGeometry:
    """One element: number, type name, node numbers, reference length, LGEOMY values and the
    numbers of its definition line (hinge axis, wheel radius, ...)."""

    id: int
    type: str
    nodes: tuple
    l0: float | None = None
    lgeomy: tuple = ()
    params: tuple = ()


@dataclass
class Geometry:
    """Model description for drawing; plain Python data (picklable, JSON-able)."""

    node_kinds: dict                                   # {node: "XY" | "BETA" | "XYZ" | "LAMBDA"}
    elements: list                                     # [ElementGeometry], ascending number
    coordinate_classes: dict = field(default_factory=dict)  # {node: ("fixed", "calculable", ...)}
    masses: dict = field(default_factory=dict)          # {node: (values of MASS)}

    # --- construction and serialisation ------------------------------------------------------

    @classmethod
    def from_model(cls, model) -> "Geometry":
        """The geometry of a :class:`spacar.Model` or of its core (:attr:`spacar.Model.core`),
        prepared: with reference geometry."""
        core = getattr(model, "core", model)
        nodes = core.nodes
        elements = core.elements
        return cls(
            node_kinds={int(n): node.kind.name for n, node in sorted(nodes.items())},
            elements=[ElementGeometry(int(eid), el.type_name, tuple(int(n) for n in el.nodes),
                                      None if el.l0 is None else float(el.l0),
                                      tuple(float(v) for v in el.lgeomy), tuple(float(v) for v in el.params))
                      for eid, el in sorted(elements.items())],
            coordinate_classes={int(n): tuple(c.name for c in node.cls) for n, node in sorted(nodes.items())},
            masses={int(n): tuple(float(v) for v in node.mass) for n, node in sorted(nodes.items()) if node.mass},
        )

    def to_dict(self) -> dict:
        return {
            "node_kinds": {str(n): k for n, k in self.node_kinds.items()},
            "elements": [dict(id=e.id, type=e.type, nodes=list(e.nodes), l0=e.l0, lgeomy=list(e.lgeomy),
                              params=list(e.params)) for e in self.elements],
            "coordinate_classes": {str(n): list(c) for n, c in self.coordinate_classes.items()},
            "masses": {str(n): list(m) for n, m in self.masses.items()},
        }

    @classmethod
    def from_dict(cls, d: dict) -> "Geometry":
        return cls(
            node_kinds={int(n): k for n, k in d["node_kinds"].items()},
            elements=[ElementGeometry(e["id"], e["type"], tuple(e["nodes"]), e["l0"], tuple(e["lgeomy"]),
                                      tuple(e["params"])) for e in d["elements"]],
            coordinate_classes={int(n): tuple(c) for n, c in d.get("coordinate_classes", {}).items()},
            masses={int(n): tuple(m) for n, m in d.get("masses", {}).items()},
        )

    # --- queries -------------------------------------------------------------------------------

    @property
    def spatial(self) -> bool:
        """True if the model has 3-D nodes (XYZ or LAMBDA): it is drawn in 3-D."""
        return any(k in ("XYZ", "LAMBDA") for k in self.node_kinds.values())

    @property
    def position_nodes(self) -> list:
        return [n for n, k in self.node_kinds.items() if k in POSITION_KINDS]

    def anchors(self) -> dict:
        """{orientation node: position node where it is drawn}: each orientation node of an
        element goes with the position node before it on the element line (p1 o1 p2 o2; the
        spin node of PLWHEEL with the wheel centre). Orientation nodes met only in hinges get the
        anchor of the node at the other side of the hinge."""
        out: dict = {}
        for el in self.elements:
            last = None
            for n in el.nodes:
                kind = self.node_kinds.get(n)
                if kind in POSITION_KINDS:
                    last = n
                elif kind in ORIENTATION_KINDS and last is not None:
                    out.setdefault(n, last)
        changed = True
        while changed:  # hinge chains: o1 -- HINGE -- o2
            changed = False
            for el in self.elements:
                if family(el.type) == "Hinge":
                    a, b = el.nodes
                    if a in out and b not in out:
                        out[b] = out[a]
                        changed = True
                    elif b in out and a not in out:
                        out[a] = out[b]
                        changed = True
        return out

    def joints(self) -> list:
        """Position nodes drawn as pin joints: where element ends meet with different (or no)
        orientation nodes, or where a support holds a node whose rotation is free."""
        ends: dict = {}
        for el in self.elements:
            kinds = [self.node_kinds.get(n) for n in el.nodes]
            for j, n in enumerate(el.nodes):
                if kinds[j] not in POSITION_KINDS:
                    continue
                nxt = el.nodes[j + 1] if j + 1 < len(el.nodes) else None
                orient = nxt if nxt is not None and self.node_kinds.get(nxt) in ORIENTATION_KINDS else None
                if family(el.type) == "Truss":
                    orient = None
                ends.setdefault(n, []).append(orient)
        pins = []
        for n, orients in ends.items():
            distinct = set(orients)
            if len(orients) >= 2 and (len(distinct) >= 2 or None in distinct):
                pins.append(n)
            elif self.supported(n) and None in distinct:
                pins.append(n)
            elif self.supported(n) and any(o is not None and not self.fully_fixed(o) for o in distinct):
                pins.append(n)
        return sorted(pins)

    def classes(self, n) -> tuple:
        return self.coordinate_classes.get(n, ())

    def fully_fixed(self, n) -> bool:
        c = self.classes(n)
        return bool(c) and all(x == "fixed" for x in c)

    def supported(self, n) -> bool:
        """Some component of node n is fixed or an input motion."""
        return any(x in ("fixed", "input") for x in self.classes(n))


def rotation(lam) -> np.ndarray:
    """R(λ) of Euler parameters λ = (λ0, λ1, λ2, λ3) (docs/formulation.md §2), body → global."""
    l0, l1, l2, l3 = (float(v) for v in lam)
    lb = np.array([l1, l2, l3])
    skew = np.array([[0.0, -l3, l2], [l3, 0.0, -l1], [-l2, l1, 0.0]])
    return (l0 * l0 - lb @ lb) * np.eye(3) + 2.0 * np.outer(lb, lb) + 2.0 * l0 * skew


def euler_e(lam) -> np.ndarray:
    """E(λ) of docs/formulation.md §2, the 3 × 4 matrix of ω = 2 E(λ) λ̇ in global axes; λ of shape
    (..., 4) gives (..., 3, 4)."""
    l0, l1, l2, l3 = np.moveaxis(np.asarray(lam, dtype=float), -1, 0)
    return np.stack([np.stack([-l1, l0, -l3, l2], -1),
                     np.stack([-l2, l3, l0, -l1], -1),
                     np.stack([-l3, -l2, l1, l0], -1)], -2)


def hermite(xp, tp, xq, tq, l0: float, n: int = 21) -> np.ndarray:
    """Points r(ξ), ξ = 0..1 (n values), of the cubic Hermite curve with end points xp, xq and
    end tangents dr/dξ = l0 tp, l0 tq."""
    xi = np.linspace(0.0, 1.0, n)[:, None]
    h1 = 1 - 3 * xi**2 + 2 * xi**3
    h2 = xi - 2 * xi**2 + xi**3
    h3 = 3 * xi**2 - 2 * xi**3
    h4 = -(xi**2) + xi**3
    xp, tp, xq, tq = (np.asarray(v, dtype=float) for v in (xp, tp, xq, tq))
    return h1 * xp + h2 * l0 * tp + h3 * xq + h4 * l0 * tq


def beam_tangents(el: ElementGeometry, coords: dict):
    """Material tangents (t_p, t_q) of a beam element at the nodal coordinates ``coords``."""
    p, rp, q, rq = el.nodes
    if len(coords[rp]) == 1:  # a BETA node: a planar beam
        a0 = el.lgeomy[0] if el.lgeomy else 0.0
        bp, bq = a0 + coords[rp][0], a0 + coords[rq][0]
        return np.array([math.cos(bp), math.sin(bp)]), np.array([math.cos(bq), math.sin(bq)])
    ex0 = np.array(el.lgeomy[:3]) if len(el.lgeomy) >= 3 else _unit(np.subtract(coords[q], coords[p]))
    return rotation(coords[rp]) @ ex0, rotation(coords[rq]) @ ex0


def beam_curve(el: ElementGeometry, coords: dict, n: int = 21) -> np.ndarray:
    """The cubic deflection shape of a beam element (n points from p to q)."""
    p, _, q, _ = el.nodes
    tp, tq = beam_tangents(el, coords)
    l0 = el.l0 if el.l0 is not None else float(np.linalg.norm(np.subtract(coords[q], coords[p])))
    return hermite(coords[p], tp, coords[q], tq, l0, n)


def _unit(v):
    v = np.asarray(v, dtype=float)
    n = np.linalg.norm(v)
    return v / n if n > 0 else v


def _perpendicular_pair(a):
    """Two unit vectors u, v with (u, v, a) right-handed and orthonormal."""
    a = _unit(a)
    k = int(np.argmin(np.abs(a)))
    e = np.zeros(3)
    e[k] = 1.0
    u = _unit(e - (e @ a) * a)
    return u, np.cross(a, u)


def _circle(centre, u, v, r, n=41):
    phi = np.linspace(0.0, 2 * math.pi, n)[:, None]
    return np.asarray(centre) + r * (np.cos(phi) * u + np.sin(phi) * v)


class Shape(NamedTuple):
    """Something to draw: ``kind`` (beam, truss, link, belt, wheel, spoke, axis, triad-x/y/z,
    pin, ground, slider, mass, point), the element or node it belongs to, and its points
    (m × 2 or m × 3)."""

    kind: str
    element: int | None
    node: int | None
    points: np.ndarray


def shapes(geometry: Geometry, coords: dict, scale: float = 1.0, beam_points: int = 21) -> list:
    """The shapes of the mechanism with nodal coordinates ``coords`` ({node: array}); ``scale``
    is a characteristic length for symbols (axis lines, body triads). Always the same list of
    shapes in the same order for one geometry, so a drawing can be updated frame by frame."""
    dim = 3 if geometry.spatial else 2
    out: list = []

    def pos(n):
        x = np.zeros(dim)
        c = np.asarray(coords[n], dtype=float)[:dim]
        x[: len(c)] = c
        return x

    anchors = geometry.anchors()
    context = _DrawContext(geometry, coords, pos, anchors, scale, beam_points)
    for el in geometry.elements:
        out.extend(_DRAWINGS.get(family(el.type), _draw_default)(el, context))
    # Bodies: LAMBDA nodes with inertia get their body frame drawn (at their anchor or the origin).
    for n, m in sorted(geometry.masses.items()):
        if geometry.node_kinds.get(n) == "LAMBDA":
            anchor = anchors.get(n)
            centre = pos(anchor) if anchor is not None else np.zeros(3)
            R = rotation(coords[n])
            for j, name in enumerate("xyz"):
                out.append(Shape(f"triad-{name}", None, n, np.array([centre, centre + 0.25 * scale * R[:, j]])))
    # Supports, joints and masses at position nodes.
    for n in geometry.joints():
        out.append(Shape("pin", None, n, pos(n)[None, :]))
    for n in geometry.position_nodes:
        cls = geometry.classes(n)
        if geometry.fully_fixed(n):
            out.append(Shape("ground", None, n, pos(n)[None, :]))
        elif "fixed" in cls:
            out.append(Shape("slider", None, n, pos(n)[None, :]))
        elif n in geometry.masses:
            out.append(Shape("mass", None, n, pos(n)[None, :]))
    return out


class _DrawContext(NamedTuple):
    """What the drawing of an element needs besides the element: the geometry, the nodal
    coordinates, pos(node) (its position padded to the drawing's dimension), the anchors of the
    orientation nodes and the symbol and beam-curve sizes."""

    geometry: Geometry
    coords: dict
    pos: object
    anchors: dict
    scale: float
    beam_points: int


def _draw_default(el, f):
    """An element without a drawing of its family: the line through its position nodes."""
    points = [f.pos(n) for n in el.nodes if f.geometry.node_kinds.get(n) in POSITION_KINDS]
    if not points:
        return []
    if len(points) == 1:
        return [Shape("point", el.id, None, points[0][None, :])]
    return [Shape("link", el.id, None, np.array(points))]


def _draw_beam(el, f):
    nodes = el.nodes
    c = {n: np.asarray(f.coords[n], dtype=float) for n in nodes}
    c[nodes[0]], c[nodes[2]] = f.pos(nodes[0]), f.pos(nodes[2])
    return [Shape("beam", el.id, None, beam_curve(el, c, f.beam_points))]


def _draw_truss(el, f):
    return [Shape("truss", el.id, None, np.array([f.pos(el.nodes[0]), f.pos(el.nodes[1])]))]


def _draw_wheel(el, f):
    nodes, centre = el.nodes, f.pos(el.nodes[0])
    if f.geometry.node_kinds.get(nodes[0]) == "XY":  # seen from above: the wheel's track, its axle
        axis = _unit(el.params[1:3])
        b = float(f.coords[nodes[1]][0])
        a = np.array([math.cos(b) * axis[0] - math.sin(b) * axis[1], math.sin(b) * axis[0] + math.cos(b) * axis[1]])
        roll = np.array([a[1], -a[0]])
        r = el.params[0]
        return [Shape("wheel", el.id, None, np.array([centre - r * roll, centre + r * roll])),
                Shape("axis", el.id, None, np.array([centre - 0.5 * r * a, centre + 0.5 * r * a]))]
    R = rotation(f.coords[nodes[1]])
    a0 = _unit(el.params[0:3])
    r = el.params[3]
    u0, v0 = _perpendicular_pair(a0)
    return [Shape("wheel", el.id, None, _circle(centre, R @ u0, R @ v0, r)),
            Shape("spoke", el.id, None, np.array([centre, centre + r * (R @ u0)])),
            Shape("axis", el.id, None, np.array([centre - 0.3 * r * (R @ a0), centre + 0.3 * r * (R @ a0)]))]


def _draw_hinge(el, f):
    """A pin at the anchor of the hinge's first node; a spatial hinge also shows its axis."""
    anchor = f.anchors.get(el.nodes[0])
    if f.geometry.node_kinds.get(el.nodes[0]) == "BETA":
        return [] if anchor is None else [Shape("pin", el.id, None, f.pos(anchor)[None, :])]
    centre = f.pos(anchor) if anchor is not None else np.zeros(3)
    a = rotation(f.coords[el.nodes[0]]) @ _unit(el.params[0:3])
    return [Shape("axis", el.id, None, np.array([centre - 0.08 * f.scale * a, centre + 0.08 * f.scale * a])),
            Shape("pin", el.id, None, centre[None, :])]


def _draw_belt(el, f):
    """PLBELT: the two pulleys (with a mark showing their rotation) and the free span on the
    external tangent with both centres on its right (formulation.md §4.6)."""
    coords, pos = f.coords, f.pos
    p1, o1, p2, o2 = el.nodes
    r1, r2 = el.params[:2]
    c1, c2 = pos(p1), pos(p2)
    d = c2 - c1
    L = float(np.hypot(*d))
    out = []
    a0 = el.lgeomy[0] if el.lgeomy else 0.0
    for c, r, o in ((c1, r1, o1), (c2, r2, o2)):
        u, v = np.array([1.0, 0.0]), np.array([0.0, 1.0])
        out.append(Shape("wheel", el.id, None, _circle(c, u, v, r)))
        b = a0 + float(coords[o][0])
        out.append(Shape("spoke", el.id, None, np.array([c, c + r * np.array([math.cos(b), math.sin(b)])])))
    if L > abs(r2 - r1) and L > 0:
        alpha = math.atan2(d[1], d[0])
        s_angle = alpha + math.asin((r2 - r1) / L)
        s = np.array([math.cos(s_angle), math.sin(s_angle)])
        m = np.array([s[1], -s[0]])
        out.append(Shape("belt", el.id, None, np.array([c1 - r1 * m, c2 - r2 * m])))
    else:
        out.append(Shape("belt", el.id, None, np.array([c1, c2])))
    return out



_DRAWINGS = {"Beam": _draw_beam, "Truss": _draw_truss, "Hinge": _draw_hinge, "Belt": _draw_belt,
             "Wheel": _draw_wheel}


def frame_coordinates(node_columns: dict, xrow) -> dict:
    """{node: coordinates} of one row of the x array."""
    return {n: np.asarray(xrow)[cols] for n, cols in node_columns.items()}

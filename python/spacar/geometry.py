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

Besides the elements: a fully fixed node whose elements end in fixed orientation nodes is a
clamp (a hatched wall, :meth:`Geometry.clamps`), rigid links of three or more nodes are filled
bodies (:meth:`Geometry.rigid_bodies`), and :func:`magnified` scales the deflections of the
flexible beams relative to their rigid-body motion.

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
    """The catalogue family of an element type ("Beam", "Truss", "Hinge", "Belt", "Wheel",
    "Bearing"), or "Other" (also for a type the catalogue does not know)."""
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
    deformation_classes: tuple = ()   # ("fixed", "calculable", ...) per deformation; () if unknown

    @property
    def rigid(self) -> bool:
        """All deformations fixed (known only for geometries made from a model)."""
        return bool(self.deformation_classes) and all(c == "fixed" for c in self.deformation_classes)

    @property
    def flexible(self) -> bool:
        """Some deformation not fixed (a geometry without deformation classes has no flexible element)."""
        return bool(self.deformation_classes) and not self.rigid


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
                                      tuple(float(v) for v in el.lgeomy), tuple(float(v) for v in el.params),
                                      tuple(c.name for c in el.cls))
                      for eid, el in sorted(elements.items())],
            coordinate_classes={int(n): tuple(c.name for c in node.cls) for n, node in sorted(nodes.items())},
            masses={int(n): tuple(float(v) for v in node.mass) for n, node in sorted(nodes.items()) if node.mass},
        )

    def to_dict(self) -> dict:
        return {
            "node_kinds": {str(n): k for n, k in self.node_kinds.items()},
            "elements": [dict(id=e.id, type=e.type, nodes=list(e.nodes), l0=e.l0, lgeomy=list(e.lgeomy),
                              params=list(e.params), deformation_classes=list(e.deformation_classes))
                         for e in self.elements],
            "coordinate_classes": {str(n): list(c) for n, c in self.coordinate_classes.items()},
            "masses": {str(n): list(m) for n, m in self.masses.items()},
        }

    @classmethod
    def from_dict(cls, d: dict) -> "Geometry":
        return cls(
            node_kinds={int(n): k for n, k in d["node_kinds"].items()},
            elements=[ElementGeometry(e["id"], e["type"], tuple(e["nodes"]), e["l0"], tuple(e["lgeomy"]),
                                      tuple(e["params"]), tuple(e.get("deformation_classes", ())))
                      for e in d["elements"]],
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

    def _end_orientations(self, n) -> set:
        """The orientation nodes that follow position node n on the lines of its elements."""
        out = set()
        for el in self.elements:
            for j, m in enumerate(el.nodes[:-1]):
                if m == n and self.node_kinds.get(el.nodes[j + 1]) in ORIENTATION_KINDS:
                    out.add(el.nodes[j + 1])
        return out

    def clamps(self) -> list:
        """Fully fixed position nodes whose elements all end there in fully fixed orientation
        nodes: a clamp (a fixed position and a fixed rotation), drawn as a hatched wall, where
        a pinned support gets a pin on a ground triangle."""
        pins = set(self.joints())
        out = []
        for n in self.position_nodes:
            orients = self._end_orientations(n)
            if self.fully_fixed(n) and n not in pins and orients and all(self.fully_fixed(o) for o in orients):
                out.append(n)
        return out

    def rigid_bodies(self) -> list:
        """The moving rigid links of three or more position nodes (a coupler triangle): rigid
        beams (all deformations fixed) whose orientation nodes are joined, by shared nodes or
        rigid hinges, into one body (the core's grouping, ``_core.rigid_bodies``). Each entry is
        (orientation nodes, position nodes); links of two nodes are bars and left out, and so is
        the ground (all position nodes fully fixed)."""
        from . import _core

        beams = [el for el in self.elements if family(el.type) == "Beam" and el.rigid]
        links = [[el.nodes[1], el.nodes[3]] for el in beams]
        links += [list(el.nodes[:2]) for el in self.elements
                  if family(el.type) == "Hinge" and el.rigid and len(el.nodes) >= 2]
        orient = sorted({n for link in links for n in link})
        out = []
        for group in _core.rigid_bodies(orient, links):
            members = set(group)
            points = []
            for el in beams:
                if el.nodes[1] in members:
                    points += [p for p in (el.nodes[0], el.nodes[2]) if p not in points]
            if len(points) >= 3 and not all(self.fully_fixed(p) for p in points):
                out.append((tuple(group), tuple(points)))
        return out

    def flexible_components(self) -> list:
        """The flexible structures: beams with a deformation that is not fixed, joined by shared
        nodes. Each entry is (root, beams) with root = (position node, orientation node) the
        end whose motion is the structure's rigid-body motion: clamped to the ground if it can
        be, else welded to a rigid link, else on a fixed point, else pinned to a rigid link, else
        supported, else the first beam's first end."""
        beams = [el for el in self.elements if family(el.type) == "Beam" and el.flexible]
        rigid_orient = {n for el in self.elements if el.rigid for n in el.nodes
                        if self.node_kinds.get(n) in ORIENTATION_KINDS}
        rigid_points = {n for el in self.elements if el.rigid for n in el.nodes
                        if self.node_kinds.get(n) in POSITION_KINDS}
        parent = {}

        def find(a):
            while parent.setdefault(a, a) != a:
                a = parent[a]
            return a

        for el in beams:
            for n in el.nodes[1:]:
                parent[find(n)] = find(el.nodes[0])
        groups: dict = {}
        for el in beams:
            groups.setdefault(find(el.nodes[0]), []).append(el)
        out = []
        for members in groups.values():
            ends = [(el.nodes[0], el.nodes[1]) for el in members] + [(el.nodes[2], el.nodes[3]) for el in members]
            rank = lambda e: (not self.fully_fixed(e[1]), e[1] not in rigid_orient,  # noqa: E731
                              not self.fully_fixed(e[0]), e[0] not in rigid_points, not self.supported(e[0]))
            out.append((min(ends, key=rank), members))
        return out


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
    p, rp, q, rq = el.nodes[:4]  # (BEAMW's warping nodes follow)
    if len(coords[rp]) == 1:  # a BETA node: a planar beam
        a0 = el.lgeomy[0] if el.lgeomy else 0.0
        bp, bq = a0 + coords[rp][0], a0 + coords[rq][0]
        return np.array([math.cos(bp), math.sin(bp)]), np.array([math.cos(bq), math.sin(bq)])
    ex0 = np.array(el.lgeomy[:3]) if len(el.lgeomy) >= 3 else _unit(np.subtract(coords[q], coords[p]))
    return rotation(coords[rp]) @ ex0, rotation(coords[rq]) @ ex0


def beam_curve(el: ElementGeometry, coords: dict, n: int = 21) -> np.ndarray:
    """The cubic deflection shape of a beam element (n points from p to q)."""
    p, _, q, _ = el.nodes[:4]
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
    pin, ground, clamp, slider, mass, point, body), the element or node it belongs to (a body:
    its first orientation node), and its points (m × 2 or m × 3; a clamp's strokes are
    separated by rows of NaN, a body's outline is closed)."""

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
    # Rigid links of three or more nodes: a filled body (closed outline) under their bars.
    for orient, points in geometry.rigid_bodies():
        out.append(Shape("body", None, orient[0], _outline(np.array([pos(n) for n in points]))))
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
    clamps = set(geometry.clamps())
    for n in geometry.position_nodes:
        cls = geometry.classes(n)
        if n in clamps:
            out.append(Shape("clamp", None, n, _clamp(n, context)))
        elif geometry.fully_fixed(n):
            out.append(Shape("ground", None, n, pos(n)[None, :]))
        elif "fixed" in cls:
            out.append(Shape("slider", None, n, pos(n)[None, :]))
        elif n in geometry.masses:
            out.append(Shape("mass", None, n, pos(n)[None, :]))
    return out


def _outline(points) -> np.ndarray:
    """The closed convex outline of points (m × 2, or m × 3 near a plane: the outline in their
    best-fitting plane), its first point repeated at the end."""
    centre = points.mean(axis=0)
    rel = points - centre
    if points.shape[1] == 3:
        rel = rel @ np.linalg.svd(rel)[2][:2].T
    order = sorted(range(len(points)), key=lambda i: (rel[i, 0], rel[i, 1]))

    def half(seq):  # Andrew's monotone chain
        h = []
        for i in seq:
            while len(h) >= 2:
                a, b = rel[h[-1]] - rel[h[-2]], rel[i] - rel[h[-2]]
                if a[0] * b[1] - a[1] * b[0] > 0:
                    break
                h.pop()
            h.append(i)
        return h

    hull = half(order)[:-1] + half(order[::-1])[:-1]
    return points[hull + hull[:1]]


def _clamp(n, f) -> np.ndarray:
    """A clamp at position node n: a wall across the mean direction of the elements leaving n,
    hatched on the side away from them (one polyline, strokes separated by NaN rows)."""
    x = f.pos(n)
    d = np.zeros(len(x))
    for el in f.geometry.elements:
        if n not in el.nodes:
            continue
        if family(el.type) == "Beam" and n in (el.nodes[0], el.nodes[2]):
            c = {m: np.asarray(f.coords[m], dtype=float) for m in el.nodes}
            c[el.nodes[0]], c[el.nodes[2]] = f.pos(el.nodes[0]), f.pos(el.nodes[2])
            tp, tq = beam_tangents(el, c)
            d += _unit(tp if n == el.nodes[0] else -np.asarray(tq))
        else:
            d += sum((_unit(f.pos(m) - x) for m in el.nodes
                      if m != n and f.geometry.node_kinds.get(m) in POSITION_KINDS), np.zeros(len(x)))
    d = _unit(d) if np.linalg.norm(d) > 0 else np.eye(len(x))[1]
    w, h = 0.06 * f.scale, 0.035 * f.scale
    nan = np.full((1, len(x)), np.nan)
    if len(x) == 2:
        u = np.array([-d[1], d[0]])
        rows = [np.array([x - w * u, x + w * u])]
        for s in np.linspace(-1.0, 1.0, 5):
            a = x + s * w * u
            rows += [nan, np.array([a, a - h * d - 0.6 * h * u])]
        return np.vstack(rows)
    u, v = _perpendicular_pair(d)
    corners = [x + w * (a * u + b * v) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1))]
    rows = [np.array(corners)]
    for a in corners[:4] + [x]:
        rows += [nan, np.array([a, a - h * d])]
    return np.vstack(rows)


def _qmul(a, b) -> np.ndarray:
    return np.concatenate([[a[0] * b[0] - a[1:] @ b[1:]], a[0] * b[1:] + b[0] * a[1:] + np.cross(a[1:], b[1:])])


def _qpow(q, m: float) -> np.ndarray:
    """The rotation of unit Euler parameters q with its angle multiplied by m."""
    s = float(np.linalg.norm(q[1:]))
    if s == 0.0:
        return np.array([1.0, 0.0, 0.0, 0.0])
    half = math.atan2(s, q[0]) * m
    return np.concatenate([[math.cos(half)], math.sin(half) * q[1:] / s])


def magnified(geometry: Geometry, coords: dict, factor: float) -> dict:
    """Nodal coordinates with the deflections of the flexible beams scaled by ``factor``.

    Each flexible structure (:meth:`Geometry.flexible_components`) moves with its root end
    (position x_r, rotation R_r): its rigid-body motion puts node n at
    x_r + R_r (X_n − X_r), with X_n − X_r summed from the beams' reference chords
    (l0 (cos α0, sin α0), l0 e_x0), and turns every orientation node with the root. The
    displacement from there (and the rotation relative to the root) is multiplied by
    ``factor``; rigid parts are drawn between the nodes so moved."""
    out = {n: np.asarray(c, dtype=float) for n, c in coords.items()}
    for (root, root_o), beams in geometry.flexible_components():
        if any(el.l0 is None for el in beams):
            continue
        planar = len(coords[root_o]) == 1
        ref = {root: 0.0}
        pending = list(beams)
        while pending:
            el = next((el for el in pending if el.nodes[0] in ref or el.nodes[2] in ref), None)
            if el is None:
                break
            pending.remove(el)
            if planar:
                a0 = el.lgeomy[0] if el.lgeomy else 0.0
                chord = el.l0 * np.array([math.cos(a0), math.sin(a0)])
            else:
                chord = el.l0 * _unit(el.lgeomy[:3])
            p, q = el.nodes[0], el.nodes[2]
            if p in ref:
                ref.setdefault(q, ref[p] + chord)
            else:
                ref[p] = ref[q] - chord
        x_r = np.asarray(coords[root], dtype=float)
        if planar:
            b = float(coords[root_o][0])
            R = np.array([[math.cos(b), -math.sin(b)], [math.sin(b), math.cos(b)]])
        else:
            lam_r = np.asarray(coords[root_o], dtype=float)
            R = rotation(lam_r)
        for n, X in ref.items():
            if n != root:
                rigid = x_r + R @ X
                out[n] = rigid + factor * (np.asarray(coords[n], dtype=float) - rigid)
        for o in {m for el in beams for m in (el.nodes[1], el.nodes[3])} - {root_o}:
            if planar:
                out[o] = coords[root_o] + factor * (np.asarray(coords[o], dtype=float) - coords[root_o])
            else:
                conj = lam_r * np.array([1.0, -1.0, -1.0, -1.0])
                out[o] = _qmul(lam_r, _qpow(_qmul(conj, np.asarray(coords[o], dtype=float)), factor))
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

"""Flexure mechanisms built from their parts (docs/flexures.md): rigid bodies joined by leaf
springs and wire flexures, each meshed into beams with its cross-section, in the plane (PLBEAM) or
in space (BEAM)::

    from spacar import flexure, section

    leaf = section.rectangle(b=0.02, h=0.0005, material=section.STEEL)
    fx = flexure.Flexure()                                   # planar; Flexure(spatial=True): 3-D
    stage = fx.body(at=(0.015, 0.05))
    fx.leaf_spring(fx.ground, stage, (0.0, 0.0), (0.0, 0.05), leaf, n=8)
    fx.leaf_spring(fx.ground, stage, (0.03, 0.0), (0.03, 0.05), leaf, n=8)
    model = fx.model()                                       # a spacar.Model
    C = spacar.compliance(model, stage.node, rotation=stage.rotation_node)

The model is the one a SPACAR user writes by hand for a flexure (and SPACAR Light writes for its
users): each flexure a chain of beams whose deformations are released (RLSE) with the section's
stiffness (ESTIFF, and EMASS when the material has a density); every node of a flexure and the
reference node of every body dynamic (DYNX), so that the whole structure finds its equilibrium;
a flexure's end that is not a body's reference point joined to the body by a rigid beam (all its
deformations fixed), whose far nodes are then calculable; the ground's points fixed.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from ._util import show
from .errors import InputError
from .model import Model
from .section import Section, _positive

__all__ = ["Body", "Flexure", "Beam"]

_CLOSE = 1e-12  # relative: points closer than this (to the model's size) are the same point


class Body:
    """A rigid body of a :class:`Flexure`: its reference point ``at``, the node of that point
    (``node``: its coordinates) and of the body's rotation (``rotation_node``: BETA in the plane,
    the Euler parameters of LAMBDA in space), the nodes to load, drive or ask the compliance of.
    The ground is a body too (``Flexure.ground``), with its nodes fixed."""

    def __init__(self, flexure, name: str, at, node: int, rotation_node: int, mass: float, inertia, fixed: bool):
        self.flexure, self.name, self.at = flexure, name, at
        self.node, self.rotation_node = node, rotation_node
        self.mass, self.inertia, self.fixed = mass, inertia, fixed

    def __repr__(self):
        where = ", ".join(f"{v:g}" for v in self.at)
        return f"<spacar.flexure.Body {self.name!r} at ({where}): node {self.node}, rotation node {self.rotation_node}>"


class Beam:
    """A flexure of a :class:`Flexure` (a leaf spring, a wire, a beam): its ``elements`` from
    ``a`` to ``b``, the nodes along it (``nodes``: position nodes, ``rotation_nodes``), its
    ``section``."""

    def __init__(self, kind: str, a, b, section: Section, elements: list, nodes: list, rotation_nodes: list):
        self.kind, self.a, self.b, self.section = kind, a, b, section
        self.elements, self.nodes, self.rotation_nodes = elements, nodes, rotation_nodes

    def __repr__(self):
        return (f"<spacar.flexure.Beam {self.kind} of {len(self.elements)} elements "
                f"{self.elements[0]}–{self.elements[-1]}>")


class Flexure:
    """A flexure mechanism in the plane (PLBEAM, the default) or in space (``spatial=True``:
    BEAM). ``nonlinear=True`` meshes the flexures with PLBEAMNL/BEAMNL, whose elongation includes
    the shortening by bending: the stiffness of a loaded flexure along its stroke (support
    stiffness, buckling) needs it. ``arc=True`` meshes them with PLBEAMC/BEAMC, exact for
    constant curvature (and twist, in space; their elongation along the arc includes the
    shortening too): large deflections to 1e-6 of the length with a dozen elements where PLBEAM
    needs hundreds.
    ``warping=True`` (space) meshes them with BEAMW, Vlasov's warping torsion: each point along a
    flexure gets a warping node (its rate of twist), fixed at both ends, where the ground or a
    body holds the section from warping; the section's EIw and ρIw from ``section.apply``.
    ``ground``: the fixed body. Bodies, flexures, then :meth:`model` builds the spacar.Model (each
    call a new one)."""

    def __init__(self, spatial: bool = False, nonlinear: bool = False, arc: bool = False, warping: bool = False):
        if not all(isinstance(v, bool) for v in (spatial, nonlinear, arc, warping)):
            raise InputError("Flexure: spatial, nonlinear, arc and warping must be True or False")
        if arc and nonlinear:
            raise InputError("Flexure: arc=True meshes the flexures with PLBEAMC/BEAMC, whose elongation already "
                             "includes the bending's shortening: not with nonlinear=True")
        if warping and (not spatial or arc or nonlinear):
            raise InputError("Flexure: warping=True meshes the flexures with BEAMW, in space (spatial=True), and not "
                             "with arc or nonlinear")
        self.spatial, self.nonlinear, self.arc, self.warping = spatial, nonlinear, arc, warping
        self.dim = 3 if spatial else 2
        self._element_type = "BEAMW" if warping else \
            ("BEAM" if spatial else "PLBEAM") + ("C" if arc else "NL" if nonlinear else "")
        self._next_node = 1
        self._next_element = 1
        self._positions: dict = {}      # node → coordinates
        self._extent = 1.0              # the largest coordinate of the positions (at least 1)
        self._dynamic: set = set()      # nodes whose coordinates are DYNX
        self._fixed: set = set()        # nodes fixed
        self._elements: list = []       # (number, nodes, vector or None, section or None, flexible)
        self._ground_points: dict = {}  # ground point → its (node, rotation node)
        self.bodies: list = []
        self.flexures: list = []
        self.ground = self._new_body("ground", (0.0,) * self.dim, 0.0, None, fixed=True)

    # --- parts ---------------------------------------------------------------------------------

    def body(self, at, *, mass: float = 0.0, inertia=None, name: str | None = None) -> Body:
        """A rigid body with its reference point ``at`` (its node's position), free to move;
        ``mass`` at that point and the rotational ``inertia`` about it (the plane: Izz; space:
        (Ixx, Ixy, Ixz, Iyy, Iyz, Izz) in the body's axes, which are the global axes at the
        start), both optional (a static analysis needs none)."""
        at = self._point(at, "at")
        mass = _positive(mass, "mass", zero=True)
        if inertia is not None:
            size = 6 if self.spatial else 1
            values = np.atleast_1d(np.asarray(inertia, dtype=float)) if _numbers(inertia) else None
            if values is None or values.size != size or not np.isfinite(values).all():
                raise InputError(f"inertia must be {'(Ixx, Ixy, Ixz, Iyy, Iyz, Izz)' if self.spatial else 'Izz'}, "
                                 f"got {show(inertia)}")
            inertia = tuple(float(v) for v in values.ravel())
        return self._new_body(name or f"body {len(self.bodies)}", at, mass, inertia, fixed=False)

    def beam(self, body_a: Body, body_b: Body, a, b, section: Section, *, n: int = 8, y=None,
             kind: str = "beam", _stations=None) -> Beam:
        """A flexible beam from point ``a`` of ``body_a`` to point ``b`` of ``body_b``, meshed
        into ``n`` elements of the cross-section ``section`` (its ESTIFF, and its EMASS when the
        material has a density), or of the ``n`` sections of a list, from ``a`` to ``b`` (a
        tapered or notched flexure). In space, ``y`` is the direction of the section's y axis (the
        axis of its ``h``: a leaf's thickness), not along the beam; None: a direction
        perpendicular to the beam (for round sections)."""
        self._check_body(body_a, "body_a")
        self._check_body(body_b, "body_b")
        if body_a is body_b:
            raise InputError(f"a {kind} joins two different bodies, got {body_a.name!r} twice")
        n = _element_count(n)
        sections = [section] * n if isinstance(section, Section) else \
            list(section) if isinstance(section, (list, tuple)) else None
        if sections is None or len(sections) != n or not all(isinstance(c, Section) for c in sections):
            raise InputError(f"section must be a spacar.section Section (rectangle, circle, tube) or a list of n = {n} "
                             f"of them, got {show(section)}")
        for c in sections:
            c._mat()  # a material, for E, G and rho
        a, b = self._point(a, "a"), self._point(b, "b")
        axis = np.subtract(b, a)
        length = float(np.linalg.norm(axis))
        if not length > _CLOSE * self._size(a, b):
            raise InputError(f"the {kind} from {a} to {b} has no length")
        vector = self._y_axis(axis, y) if self.spatial else None
        arms: list = []  # rigid beams to the bodies, numbered after the flexure's elements
        ends = [self._attach(body_a, a, arms), self._attach(body_b, b, arms)]
        nodes, rotations = [ends[0][0]], [ends[0][1]]
        for k in range(1, n):
            fraction = k / n if _stations is None else float(_stations[k])   # of the way from a to b
            node, rotation = self._new_point(tuple(float(v) for v in np.add(a, axis * fraction)))
            self._dynamic.update((node, rotation))
            nodes.append(node)
            rotations.append(rotation)
        nodes.append(ends[1][0])
        rotations.append(ends[1][1])
        warps = []  # BEAMW: the warping node of each point, held at the ends
        if self.warping:
            for k in range(n + 1):
                warps.append(self._next_node)
                (self._fixed if k in (0, n) else self._dynamic).add(self._next_node)
                self._next_node += 1
        elements = []
        for k in range(n):
            ends = (nodes[k], rotations[k], nodes[k + 1], rotations[k + 1]) + (tuple(warps[k:k + 2]) if warps else ())
            elements.append(self._add_element(ends, vector, sections[k]))
        for arm_nodes, arm_vector in arms:
            self._add_element(arm_nodes, arm_vector, None)
        flexure = Beam(kind, a, b, section, elements, nodes, rotations)
        self.flexures.append(flexure)
        return flexure

    def leaf_spring(self, body_a: Body, body_b: Body, a, b, section: Section, *, n: int = 8, thickness=None) -> Beam:
        """A leaf spring from ``a`` on ``body_a`` to ``b`` on ``body_b``: a beam of the
        rectangular ``section`` (``section.rectangle(b=width, h=thickness)``), bending in the plane
        (planar) or, in space, thin along ``thickness`` (the direction of the leaf's normal)."""
        if self.spatial and thickness is None:
            raise InputError("a leaf spring in space needs the direction of its thickness: thickness=(x, y, z)")
        return self.beam(body_a, body_b, a, b, section, n=n, y=thickness, kind="leaf spring")

    def notch_hinge(self, body_a: Body, body_b: Body, at, direction, *, radius: float, thickness: float,
                    width: float, material, n: int = 40, thickness_axis=None, depth: float | None = None,
                    length: float = 0.0) -> Beam:
        """A notch hinge: material of width ``width`` between two cuts that leave ``thickness`` at
        ``at``, joining ``body_a`` (at ``at − (length/2 + radius) · d``) to ``body_b`` (at
        ``at + (length/2 + radius) · d``), ``d`` the unit ``direction`` through the hinge from a to
        b; in space ``thickness_axis`` is the direction across the thin section. The cuts are
        circles of radius ``radius`` (right-circular), or with ``depth`` ellipses of semi-axes
        ``radius`` along the hinge and ``depth`` across it; with ``length`` > 0 the thin section
        runs straight over that length, the cuts its rounded ends (a corner-filleted hinge of
        fillet radius ``radius``). Meshed into ``n`` short beams of rectangular section, each as
        thick as the profile t(x) = thickness + 2 depth (1 − √(1 − (u/radius)²)), u = max(0,
        |x| − length/2), at its middle: its compliance is the midpoint sum of Euler–Bernoulli's
        ∫ dx / E I(x) (for circles Paros and Weisbord's closed form, for corner fillets
        Lobontiu's): to 1e-5 with the default 40 for circular cuts, 1e-4 for corner fillets
        (3e-5 with 80; docs/flexures.md)."""
        from .section import Material, rectangle

        R = _positive(radius, "radius")
        b = R if depth is None else _positive(depth, "depth")
        t = _positive(thickness, "thickness")
        w = _positive(width, "width")
        flat = _positive(length, "length", zero=True)
        if not isinstance(material, Material):
            raise InputError(f"material must be a spacar.section.Material, got {show(material)}")
        n = _element_count(n)
        at = np.asarray(self._point(at, "at"))
        d = np.asarray(self._point(direction, "direction"))
        if not np.linalg.norm(d) > 0:
            raise InputError("direction must not be zero")
        d = d / np.linalg.norm(d)
        half = flat / 2 + R
        if flat > 0:
            # A quarter of the pieces in each fillet (where the compliance varies), the straight
            # part in pieces no shorter than theirs (one at least), the pieces left to the fillets.
            if n < 5:
                raise InputError(f"a notch hinge with a straight part (length > 0) needs n ≥ 5 pieces, got {n}")
            straight = max(1, min(n - 2 * (n // 4), math.ceil(flat / (R / (n // 4)))))
            fillet = (n - straight) // 2
            straight = n - 2 * fillet
            edges = np.concatenate([np.linspace(-half, -flat / 2, fillet + 1),
                                    np.linspace(-flat / 2, flat / 2, straight + 1)[1:-1],
                                    np.linspace(flat / 2, half, fillet + 1)])
        else:
            edges = np.linspace(-half, half, n + 1)
        x = (edges[:-1] + edges[1:]) / 2                          # the middles of the pieces
        u = np.maximum(np.abs(x) - flat / 2, 0.0)
        profile = t + 2 * b * (1 - np.sqrt(1 - (u / R) ** 2))
        sections = [rectangle(b=w, h=float(h), material=material) for h in profile]
        if self.spatial and thickness_axis is None:
            raise InputError("a notch hinge in space needs the direction across its thin section: thickness_axis=(x, y, z)")
        return self.beam(body_a, body_b, tuple(at - half * d), tuple(at + half * d), sections, n=n, y=thickness_axis,
                         kind="notch hinge", _stations=(edges + half) / (2 * half))

    def wire(self, body_a: Body, body_b: Body, a, b, section: Section, *, n: int = 8) -> Beam:
        """A wire flexure (a slender rod of a round section) from ``a`` on ``body_a`` to ``b`` on
        ``body_b``."""
        return self.beam(body_a, body_b, a, b, section, n=n, kind="wire")

    # --- the model -----------------------------------------------------------------------------

    def model(self) -> Model:
        """The spacar.Model of the mechanism (a new one at every call): loads, drives (INPUTX on a
        body's node) and analyses are added to it as to any model."""
        if not self.flexures:
            raise InputError("the flexure mechanism has no flexures: add leaf springs, wires or beams first")
        used = {node for _, nodes, _, _, _ in self._elements for node in nodes}
        for body in self.bodies:
            if not body.fixed and body.node not in used:
                raise InputError(f"the body {body.name!r} is joined to nothing: attach a flexure to it")
        m = Model()
        element = getattr(m, self._element_type.lower())
        rigid = getattr(m, "beam" if self.spatial else "plbeam")
        for number, nodes, vector, section, _ in self._elements:
            (element if section is not None else rigid)(number, *nodes, *(vector if self.spatial else ()))
        for node, x in self._positions.items():
            if node in used:
                m.x(node, *x)
        for number, _, _, section, _ in self._elements:
            if section is not None:
                m.rlse(number)
                section.apply(m, number)
        for node in sorted(self._fixed & used):
            m.fix(node)
        for node in sorted((self._dynamic - self._fixed) & used):
            m.dynx(node)
        for body in self.bodies:
            if body.mass > 0.0:
                m.mass(body.node, body.mass)
            if body.inertia is not None:
                m.mass(body.rotation_node, *body.inertia)
        return m

    # --- inside ------------------------------------------------------------------------------

    def _new_body(self, name, at, mass, inertia, fixed) -> Body:
        if any(b.name == name for b in self.bodies):
            raise InputError(f"there is a body named {name!r} already")
        node, rotation = self._new_point(at)
        (self._fixed if fixed else self._dynamic).update((node, rotation))
        body = Body(self, name, at, node, rotation, mass, inertia, fixed)
        self.bodies.append(body)
        if fixed:
            self._ground_points[tuple(at)] = (node, rotation)
        return body

    def _new_point(self, at):
        node, rotation = self._next_node, self._next_node + 1
        self._next_node += 2
        self._positions[node] = tuple(at)
        self._extent = max([self._extent] + [abs(v) for v in at])
        return node, rotation

    def _add_element(self, nodes, vector, section) -> int:
        number = self._next_element
        self._next_element += 1
        self._elements.append((number, nodes, vector, section, section is not None))
        return number

    def _attach(self, body: Body, point, arms: list):
        """The nodes of a flexure's end at ``point`` of ``body``: the body's own at its reference
        point; on the ground fixed nodes there; elsewhere new nodes held to the body by a rigid
        beam from its reference point (its nodes and y axis appended to ``arms``)."""
        if self._same(point, body.at):
            return body.node, body.rotation_node
        if body.fixed:
            for where, nodes in self._ground_points.items():  # a clamp there already
                if self._same(point, where):
                    return nodes
            nodes = self._new_point(point)
            self._fixed.update(nodes)
            self._ground_points[tuple(point)] = nodes
            return nodes
        node, rotation = self._new_point(point)
        arm = np.subtract(point, body.at)
        arms.append(((body.node, body.rotation_node, node, rotation), self._y_axis(arm, None) if self.spatial else None))
        return node, rotation

    def _y_axis(self, axis, y):
        """A unit vector for the section's y axis: ``y`` less its component along the beam, or
        (None) the global axis least aligned with the beam, made perpendicular."""
        axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
        if y is None:
            y = np.eye(3)[int(np.argmin(np.abs(axis)))]
        else:
            y = self._point(y, "the y axis")
        given = float(np.linalg.norm(y))
        y = np.asarray(y, dtype=float) - np.dot(y, axis) * axis
        norm = np.linalg.norm(y)
        if not norm > 1e-9 * given:
            raise InputError(f"the direction {tuple(float(v) for v in y)} lies along the beam: give one across it")
        return tuple(float(v) for v in y / norm)

    def _point(self, value, name):
        if not _numbers(value):
            raise InputError(f"{name} must be a point of {self.dim} coordinates, got {show(value)}")
        p = np.asarray(value, dtype=float).ravel()
        if p.size != self.dim or not np.isfinite(p).all():
            raise InputError(f"{name} must be a point of {self.dim} finite coordinates, got {show(value)}")
        return tuple(float(v) for v in p)

    def _size(self, *points) -> float:
        """The model's size (its largest coordinate, at least 1) with ``points``: the scale of
        "the same point" and "no length"."""
        return max([self._extent] + [abs(v) for p in points for v in p])

    def _same(self, p, q) -> bool:
        return math.dist(p, q) <= _CLOSE * self._size(p, q)

    def _check_body(self, body, name):
        if not isinstance(body, Body) or body.flexure is not self:
            raise InputError(f"{name} must be a body of this flexure mechanism (Flexure.body or .ground), got {show(body)}")


def _numbers(value) -> bool:
    try:
        np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return False
    return not isinstance(value, (str, bytes, bool))


def _element_count(n) -> int:
    if isinstance(n, bool) or not isinstance(n, numbers.Integral) or not 1 <= n <= 100_000:
        raise InputError(f"n must be a number of elements from 1 to 100000, got {show(n)}")
    return int(n)

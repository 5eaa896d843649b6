"""The rigid-body structure of a spacar model: which nodes move together as one rigid body,
where the bodies are jointed, their mass properties, and which elements are flexible.

The converters to exudyn and Pinocchio (:mod:`spacar.compare.exudyn`,
:mod:`spacar.compare.pinocchio`) start from this analysis. It uses only the model's input data
(element types, node lists, classes of coordinates and deformations, reference geometry, masses)
and the assembled configuration of a :class:`spacar._core.Simulation`; no peer library is
imported here.

Conventions
-----------
* Every body has a *body frame* that coincides with the global frame in spacar's reference
  configuration (all BETA nodes 0, all LAMBDA nodes (1, 0, 0, 0)); its orientation at any time is
  the rotation of the body's orientation nodes (they rotate together because the elements that
  join them are rigid). Point coordinates in the body frame are relative to the body's *anchor*
  (its first position node), built from the reference chords of its rigid elements
  (PLBEAM: l0 (cos α0, sin α0); BEAM: l0 e_x0), so they are exact whatever the current state.
* The ground (body 0) is everything fixed: fully fixed position nodes and fixed orientation
  nodes (which must all have the same rotation, R_g). Its body frame is the global frame and its
  point coordinates are global coordinates.
* A joint is a position node shared by two bodies. It is a revolute joint if a PLHINGE/HINGE
  element with released or dynamic e1 (and, for HINGE, rigid e2, e3) joins the orientation nodes
  of the two bodies — its axis is the HINGE axis, its angle ±e1 — and otherwise, in a planar
  model, a revolute joint about z whose angle is the difference of the BETA nodes; in a spatial
  model, a spherical joint.
"""
from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from ..errors import InputError, SpacarError
from ..geometry import euler_e, rotation  # E(λ) of ω = 2 E(λ) λ̇; R(λ), body → global

PLANAR_BEAMS = ("PLBEAM", "PLBEAMNL")
SPATIAL_BEAMS = ("BEAM", "BEAMNL")
PLANAR_TYPES = PLANAR_BEAMS + ("PLHINGE",)
SPATIAL_TYPES = SPATIAL_BEAMS + ("HINGE", "L2MIN1")

NK = _core.NodeKind
CC = _core.CoordClass
DC = _core.DefClass
ORIENTATION_KINDS = (NK.BETA, NK.LAMBDA)
POSITION_KINDS = (NK.XY, NK.XYZ)


class PeerResultError(SpacarError):
    """A peer engine reported success but returned a state that is not a solution (not finite,
    or run away from the start): its numbers are not to be trusted (issue 38, finding 2: exudyn's
    DOPRI5 returned q ≈ 1e19 as a success)."""


class UnsupportedModelError(InputError):
    """The model uses something the converter cannot express in the peer library; the message
    says what and how to change the model (see :mod:`spacar.compare`)."""


# --- rotations ------------------------------------------------------------------------------

def rot_z(beta: float) -> np.ndarray:
    c, s = math.cos(beta), math.sin(beta)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def lambda_of_rotation(R: np.ndarray, near=None) -> np.ndarray:
    """Euler parameters of a rotation matrix (Shepperd's method); the sign is chosen closest to
    ``near`` (default: λ0 ≥ 0)."""
    t = np.trace(R)
    cand = [t, R[0, 0], R[1, 1], R[2, 2]]
    k = int(np.argmax(cand))
    if k == 0:
        l0 = 0.5 * math.sqrt(1.0 + t)
        lam = [l0, (R[2, 1] - R[1, 2]) / (4 * l0), (R[0, 2] - R[2, 0]) / (4 * l0), (R[1, 0] - R[0, 1]) / (4 * l0)]
    elif k == 1:
        l1 = 0.5 * math.sqrt(1.0 + 2 * R[0, 0] - t)
        lam = [(R[2, 1] - R[1, 2]) / (4 * l1), l1, (R[0, 1] + R[1, 0]) / (4 * l1), (R[0, 2] + R[2, 0]) / (4 * l1)]
    elif k == 2:
        l2 = 0.5 * math.sqrt(1.0 + 2 * R[1, 1] - t)
        lam = [(R[0, 2] - R[2, 0]) / (4 * l2), (R[0, 1] + R[1, 0]) / (4 * l2), l2, (R[1, 2] + R[2, 1]) / (4 * l2)]
    else:
        l3 = 0.5 * math.sqrt(1.0 + 2 * R[2, 2] - t)
        lam = [(R[1, 0] - R[0, 1]) / (4 * l3), (R[0, 2] + R[2, 0]) / (4 * l3), (R[1, 2] + R[2, 1]) / (4 * l3), l3]
    lam = np.array(lam)
    ref = np.array([1.0, 0, 0, 0]) if near is None else np.asarray(near, dtype=float)
    return -lam if lam @ ref < 0 else lam


# --- structure ------------------------------------------------------------------------------

@dataclass
class Body:
    """A rigid body: its orientation nodes, its points (position nodes) in the body frame, and
    its mass properties about the body-frame origin."""

    index: int
    orientation_nodes: list = field(default_factory=list)
    points: dict = field(default_factory=dict)        # node -> (3,) body-frame coordinates
    mass: float = 0.0
    first_moment: np.ndarray = field(default_factory=lambda: np.zeros(3))
    inertia_origin: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))  # about the origin
    driven: object = None   # DrivenRotation of an INPUTX BETA node

    @property
    def is_ground(self) -> bool:
        return self.index == 0

    @property
    def com(self) -> np.ndarray:
        return self.first_moment / self.mass if self.mass > 0 else np.zeros(3)

    @property
    def inertia_com(self) -> np.ndarray:
        """Inertia tensor about the centre of mass, in the body frame."""
        c = self.com
        return self.inertia_origin - self.mass * (c @ c * np.eye(3) - np.outer(c, c))

    def inertia_about(self, point) -> np.ndarray:
        d = self.com - np.asarray(point, dtype=float)
        return self.inertia_com + self.mass * (d @ d * np.eye(3) - np.outer(d, d))

    def add_point_mass(self, m: float, r) -> None:
        r = np.asarray(r, dtype=float)
        self.mass += m
        self.first_moment = self.first_moment + m * r
        self.inertia_origin = self.inertia_origin + m * (r @ r * np.eye(3) - np.outer(r, r))

    def add_rigid_mass(self, m: float, c, J_c) -> None:
        """Mass m with centre c and inertia J_c about c."""
        self.add_point_mass(m, c)
        self.inertia_origin = self.inertia_origin + np.asarray(J_c, dtype=float)

    def add_rotary_inertia(self, J) -> None:
        self.inertia_origin = self.inertia_origin + np.asarray(J, dtype=float)


@dataclass
class Joint:
    """A joint at position node ``node`` between ``bodies = (a, b)``. ``axis`` (revolute) is
    given in the frame of the orientation nodes of ``a`` — the same components in the frame of
    ``b``, as the relative rotation is about it; for the ground that frame is R_g, not the global
    frame. ``hinge = (element, sign)`` when a hinge element defines the joint angle: the rotation
    of b relative to a is sign · e1."""

    kind: str                 # "revolute" | "spherical"
    bodies: tuple
    node: int
    axis: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    hinge: tuple = None
    stiffness: float = 0.0
    damping: float = 0.0

    def reversed(self) -> "Joint":
        """The same joint seen from b: the axis is unchanged (a rotation leaves its own axis
        fixed), the angle changes sign."""
        hinge = None if self.hinge is None else (self.hinge[0], -self.hinge[1])
        return Joint(self.kind, (self.bodies[1], self.bodies[0]), self.node, self.axis, hinge,
                     self.stiffness, self.damping)


@dataclass
class DrivenRotation:
    """An INPUTX BETA node: β(t) = β0 + ω0 (t − t0) + ½ α0 (t − t0)²."""

    node: int
    t0: float
    beta0: float
    omega0: float
    alpha0: float


@dataclass
class FlexibleBeam:
    """A PLBEAM/PLBEAMNL with released (or dynamic) bending deformations."""

    element: int
    type: str
    nodes: tuple              # (p, rp, q, rq)
    l0: float
    alpha0: float
    rho_a: float
    ei: float
    ea: float                 # None if e1 is rigid
    nonlinear: bool


@dataclass
class Topology:
    planar: bool
    bodies: list              # Body; bodies[0] is the ground
    joints: list              # Joint
    flexible: list            # FlexibleBeam
    body_of_orientation: dict  # orientation node -> body index
    bodies_of_point: dict     # position node -> [body indices]
    partial_fix: dict         # position node -> fixed component indices (0-based)
    point_masses: dict        # position node -> mass (nodes of flexible beams only)
    ground_rotation: np.ndarray
    gravity: np.ndarray
    node_kind: dict
    x0: np.ndarray            # assembled configuration (spacar coordinate order)
    xd0: np.ndarray
    coord_index: dict         # (node, component 1-based) -> column
    def_index: dict           # (element, deformation 1-based) -> column
    epsint: float
    epsind: float

    # --- tree -------------------------------------------------------------------------------

    def tree(self):
        """Joints in breadth-first order from the ground, each oriented parent → child, as a
        list of (joint, parent, child). Raises UnsupportedModelError for closed loops or bodies
        not connected to the ground."""
        adj = {b.index: [] for b in self.bodies}
        for j in self.joints:
            a, b = j.bodies
            adj[a].append(j)
            adj[b].append(j.reversed())
        n_bodies = len(self.bodies)
        if len(self.joints) != n_bodies - 1:
            raise UnsupportedModelError(
                f"the bodies form a closed loop ({len(self.joints)} joints for {n_bodies - 1} moving bodies); "
                "Pinocchio's kinematic trees cannot represent it — use spacar.compare.exudyn")
        seen, order, queue = {0}, [], deque([0])
        while queue:
            p = queue.popleft()
            for j in adj[p]:
                c = j.bodies[1]
                if c in seen:
                    continue
                seen.add(c)
                order.append((j, p, c))
                queue.append(c)
        if len(seen) != n_bodies:
            missing = sorted(set(range(n_bodies)) - seen)
            raise UnsupportedModelError(f"bodies {missing} are not connected to the ground by joints (closed loop elsewhere)")
        return order

    # --- state helpers ----------------------------------------------------------------------

    def body_rotation(self, b: int, x) -> np.ndarray:
        """Rotation matrix of body b in configuration x."""
        if b == 0:
            return self.ground_rotation
        n = self.bodies[b].orientation_nodes[0]
        if self.planar:
            return rot_z(x[self.coord_index[(n, 1)]])
        return rotation([x[self.coord_index[(n, i)]] for i in range(1, 5)])

    def body_angle(self, b: int, x) -> float:
        """Planar: absolute rotation angle of body b (not wrapped)."""
        if b == 0:
            return math.atan2(self.ground_rotation[1, 0], self.ground_rotation[0, 0])
        return float(x[self.coord_index[(self.bodies[b].orientation_nodes[0], 1)]])

    def body_omega(self, b: int, x, xd) -> np.ndarray:
        """Global angular velocity of body b."""
        if b == 0:
            return np.zeros(3)
        n = self.bodies[b].orientation_nodes[0]
        if self.planar:
            return np.array([0.0, 0.0, xd[self.coord_index[(n, 1)]]])
        lam = [x[self.coord_index[(n, i)]] for i in range(1, 5)]
        lamd = [xd[self.coord_index[(n, i)]] for i in range(1, 5)]
        return 2.0 * euler_e(lam) @ np.asarray(lamd)

    def body_omega_rows(self, b: int, x, DF) -> np.ndarray:
        """∂ω_b/∂(columns of DF): 3 × ncols."""
        if b == 0:
            return np.zeros((3, DF.shape[1]))
        n = self.bodies[b].orientation_nodes[0]
        if self.planar:
            out = np.zeros((3, DF.shape[1]))
            out[2] = DF[self.coord_index[(n, 1)]]
            return out
        idx = [self.coord_index[(n, i)] for i in range(1, 5)]
        lam = x[idx]
        return 2.0 * euler_e(lam) @ DF[idx]

    def point_position(self, node: int, x) -> np.ndarray:
        k = 2 if self.node_kind[node] == NK.XY else 3
        p = np.zeros(3)
        p[:k] = [x[self.coord_index[(node, i)]] for i in range(1, k + 1)]
        return p

    def body_anchor(self, b: int) -> int:
        """The position node whose body-frame coordinates are the origin (non-ground bodies)."""
        return next(iter(self.bodies[b].points))


def _chord(el) -> np.ndarray:
    """Reference chord x_q − x_p of a beam element in the reference frame."""
    if el.type_name in PLANAR_BEAMS:
        a0 = el.lgeomy[0] if el.lgeomy else 0.0
        return el.l0 * np.array([math.cos(a0), math.sin(a0), 0.0])
    ex0 = np.asarray(el.lgeomy[:3], dtype=float)
    return el.l0 * ex0


def _is_rigid(el) -> bool:
    return all(c == DC.fixed for c in el.cls)


def _check_zero_targets(el):
    for i, (c, v) in enumerate(zip(el.cls, el.e)):
        if c == DC.fixed and abs(v) > 0.0:
            raise UnsupportedModelError(
                f"element {el.id} ({el.type_name}) has a rigid deformation {i + 1} with the non-zero target E = {v:g}; "
                "the converters need rigid deformations at their reference value 0")


def _convertible(model) -> bool:
    """Whether the model is planar; UnsupportedModelError for what the converters cannot carry
    over (element types, planar and spatial mixed, loads other than GRAVITY, prescribed
    positions)."""
    nodes = model.nodes
    types = {el.type_name for el in model.elements.values()}
    unsupported = sorted(types - set(PLANAR_TYPES) - set(SPATIAL_TYPES))
    if unsupported:
        raise UnsupportedModelError(
            f"element type(s) {', '.join(unsupported)} cannot be converted; supported: "
            f"{', '.join(PLANAR_TYPES)} (planar), {', '.join(SPATIAL_TYPES)} (spatial)")
    planar = bool(types & set(PLANAR_TYPES))
    if planar and types & set(SPATIAL_TYPES):
        raise UnsupportedModelError("the model mixes planar and spatial elements")
    if not types:
        raise UnsupportedModelError("the model has no elements")
    # Loads the converters do not carry over.
    for n, nd in nodes.items():
        if any(abs(v) > 0 for v in nd.force):
            raise UnsupportedModelError(f"node {n} has a FORCE; loads other than GRAVITY are not converted")
        for torque in ("torquel", "torqueg"):
            if any(abs(v) > 0 for v in getattr(nd, torque)):
                raise UnsupportedModelError(f"node {n} has a {torque.upper()}; loads other than GRAVITY are not converted")
        if nd.kind in POSITION_KINDS and any(c == CC.input for c in nd.cls):
            raise UnsupportedModelError(f"node {n}: prescribed positions (INPUTX) are not converted")
        if nd.kind == NK.LAMBDA and any(c == CC.input for c in nd.cls):
            raise UnsupportedModelError(f"node {n}: prescribed LAMBDA coordinates (INPUTX) are not converted")
    return planar


def _mass_properties(nodes, flexible, rigid_beams, bodies, bodies_of_point, body_of_orientation) -> dict:
    """The masses onto the bodies (point masses, rotary inertias, rigid beams' EMASS); returns
    the point masses on flexible beams' nodes, which belong to no body."""
    point_masses = {}
    flexible_pos = {el.nodes[0] for el in flexible} | {el.nodes[2] for el in flexible}
    for n, nd in nodes.items():
        if not nd.mass or not nd.used:
            continue
        if nd.kind in POSITION_KINDS:
            owners = bodies_of_point.get(n, [])
            if 0 in owners:
                continue  # a mass on the ground does not move
            if owners:
                b = bodies[min(owners)]
                b.add_point_mass(nd.mass[0], b.points[n])
            elif n in flexible_pos:
                point_masses[n] = nd.mass[0]
            else:
                raise UnsupportedModelError(f"node {n} has a MASS but belongs to no body or beam")
        else:
            b = body_of_orientation.get(n)
            if b is None:
                if nd.kind == NK.BETA and nd.mass[0] != 0:
                    raise UnsupportedModelError(
                        f"BETA node {n} of a flexible beam has a MASS (rotary inertia); not converted")
                continue
            if b == 0:
                continue
            if nd.kind == NK.BETA:
                bodies[b].add_rotary_inertia(np.diag([0.0, 0.0, nd.mass[0]]))
            else:
                m = list(nd.mass) + [0.0] * (6 - len(nd.mass))
                ixx, ixy, ixz, iyy, iyz, izz = m[:6]
                bodies[b].add_rotary_inertia(np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]))
    for el in rigid_beams:
        if not el.emass or el.emass[0] == 0:
            if len(el.emass) > 1 and any(v != 0 for v in el.emass[1:]):
                raise UnsupportedModelError(f"element {el.id}: rotary inertia without EMASS ρA is not converted")
            continue
        b = body_of_orientation[el.nodes[1]]
        if b == 0:
            continue
        bd = bodies[b]
        c = _chord(el)
        m = el.emass[0] * el.l0
        e = c / np.linalg.norm(c)
        J = m * el.l0**2 / 12.0 * (np.eye(3) - np.outer(e, e))
        bd.add_rigid_mass(m, bd.points[el.nodes[0]] + 0.5 * c, J)
        if el.type_name in SPATIAL_BEAMS and len(el.emass) > 1:
            rot = list(el.emass[1:4]) + [0.0] * (4 - len(el.emass))
            rho_ip, rho_iy, rho_iz = rot[:3]
            C0 = np.column_stack([np.asarray(el.lgeomy[3 * i:3 * i + 3], dtype=float) for i in range(3)])
            bd.add_rotary_inertia(el.l0 * C0 @ np.diag([rho_ip, rho_iy, rho_iz]) @ C0.T)
    return point_masses


def _classify_elements(elements):
    """The rigid beams, the flexible (planar) beams and the hinges of a model; the elements the
    converters cannot carry over raise UnsupportedModelError."""
    flexible, rigid_beams, hinges = [], [], []
    for k, el in sorted(elements.items()):
        t = el.type_name
        if any(c in (DC.input, DC.linearization, DC.nonholonomic, DC.kinematic) for c in el.cls):
            raise UnsupportedModelError(
                f"element {k} ({t}): INPUTE, LINE and ENHC deformations are not converted")
        if t == "L2MIN1":
            continue
        if t in PLANAR_BEAMS + SPATIAL_BEAMS:
            if _is_rigid(el):
                _check_zero_targets(el)
                rigid_beams.append(el)
            elif t in PLANAR_BEAMS and el.cls[1] != DC.fixed and el.cls[2] != DC.fixed:
                flexible.append(el)
            else:
                raise UnsupportedModelError(
                    f"element {k} ({t}): only rigid beams (all deformations fixed) and planar beams with both "
                    "bending deformations released/DYNE are converted")
        elif t in ("PLHINGE", "HINGE"):
            if t == "HINGE" and (el.cls[1] != DC.fixed or el.cls[2] != DC.fixed):
                raise UnsupportedModelError(f"element {k} (HINGE): released misalignments e2, e3 are not converted")
            _check_zero_targets(el)
            hinges.append(el)
    return flexible, rigid_beams, hinges


def _rigid_bodies(nodes, orient, flexible, rigid_beams, hinges):
    """The bodies (body 0 the ground, then the moving bodies by their first node) and the body of
    every orientation node: rigid beams and rigid hinges join orientation nodes into rigid
    bodies (the core's union-find), the bodies holding a fixed one are together the ground; a
    BETA node of flexible beams only is no rigid body, and must not join one that moves."""
    flexible_orient = {el.nodes[1] for el in flexible} | {el.nodes[3] for el in flexible}
    links = [[el.nodes[1], el.nodes[3]] for el in rigid_beams]
    links += [[el.nodes[0], el.nodes[1]] for el in hinges if el.cls[0] == DC.fixed]
    fixed_orient = {n for n in orient if all(c == CC.fixed for c in nodes[n].cls)}
    ground, moving = set(), []
    for group in _core.rigid_bodies(orient, links):
        if fixed_orient.intersection(group):
            ground.update(group)
        else:
            moving.append(group)
    for n in orient:
        cls = nodes[n].cls
        if any(c == CC.fixed for c in cls) and not all(c == CC.fixed for c in cls):
            raise UnsupportedModelError(f"orientation node {n} is partly fixed; fix all or none of its components")
    rigid_orient = {el.nodes[1] for el in rigid_beams} | {el.nodes[3] for el in rigid_beams}
    for el in hinges:
        rigid_orient |= set(el.nodes[:2])
    for n in flexible_orient:
        if n in rigid_orient and n not in ground:
            raise UnsupportedModelError(
                f"BETA node {n} joins a flexible beam to a rigid body (clamped connection to a moving body); "
                "only clamping to the ground, pins (shared position nodes) and free ends are converted")
    groups = [sorted(ground)]
    for group in moving:
        body = [n for n in group if n not in flexible_orient]
        if body:
            groups.append(body)
    bodies = [Body(i) for i in range(len(groups))]
    body_of_orientation = {}
    for i, group in enumerate(groups):
        for n in group:
            bodies[i].orientation_nodes.append(n)
            body_of_orientation[n] = i
    return bodies, body_of_orientation


def _ground_rotation(ground, planar, x0, coord_index):
    """The rotation of the ground: every fixed orientation node must have the same."""
    gnodes = ground.orientation_nodes
    if not gnodes:
        return np.eye(3)

    def node_rot(n):
        if planar:
            return rot_z(x0[coord_index[(n, 1)]])
        return rotation([x0[coord_index[(n, i)]] for i in range(1, 5)])
    ground_rotation = node_rot(gnodes[0])
    for n in gnodes[1:]:
        if np.abs(node_rot(n) - ground_rotation).max() > 1e-9:
            raise UnsupportedModelError(f"fixed orientation nodes {gnodes[0]} and {n} differ in rotation")
    return ground_rotation


def _driven_rotations(model, orient, bodies, body_of_orientation, x0, coord_index):
    """The bodies turned by an INPUTX BETA node get its motion."""
    nodes = model.nodes
    for n in orient:
        if nodes[n].kind == NK.BETA and nodes[n].cls[0] == CC.input:
            b = body_of_orientation.get(n)
            if b is None or b == 0:
                raise UnsupportedModelError(f"INPUTX on BETA node {n} of a flexible beam is not converted")
            if bodies[b].driven is not None:
                raise UnsupportedModelError(f"body with BETA nodes {bodies[b].orientation_nodes} has two INPUTX nodes")
            nd = nodes[n]
            bodies[b].driven = DrivenRotation(n, model.current_time, float(x0[coord_index[(n, 1)]]),
                                              float(nd.xd[0]), float(nd.xdd[0]))


def _ground_point(node) -> np.ndarray:
    return np.pad(np.asarray(node.x[:3], dtype=float), (0, 3 - len(node.x[:3])))


def _place_points(body, edges, nodes, fully_fixed, planar, x0, coord_index):
    """The points of a body in its frame (the ground's: global), propagated along its rigid
    beams' chords from a fixed node (the ground) or its first point, the cycles checked."""
    pts = body.points
    if body.index == 0:
        for n in sorted(fully_fixed):
            pts[n] = _ground_point(nodes[n])
    elif edges:
        pts[edges[0][0]] = np.zeros(3)
    changed = True
    while changed:
        changed = False
        for p, q, c, eid in edges:
            if p in pts and q not in pts:
                pts[q] = pts[p] + c
                changed = True
            elif q in pts and p not in pts:
                pts[p] = pts[q] - c
                changed = True
            elif p in pts and q in pts:
                if np.abs(pts[q] - pts[p] - c).max() > 1e-9 * max(1.0, np.abs(c).max()):
                    raise UnsupportedModelError(
                        f"element {eid}: its reference chord does not fit the rigid body it belongs to "
                        "(inconsistent LENGTHO/LGEOMY or an over-constrained ground)")
        if not changed:
            # a ground sub-structure not connected to a fixed node: start it from its assembled position
            missing = [(p, q) for p, q, _, _ in edges if p not in pts and q not in pts]
            if missing and body.index == 0:
                p0 = missing[0][0]
                pts[p0] = np.pad(x0[[coord_index[(p0, i)] for i in range(1, 3 if planar else 4)]], (0, 1 if planar else 0))
                changed = True
            elif missing:
                raise UnsupportedModelError(f"body {body.orientation_nodes}: its rigid elements are not connected")
    if body.index > 0 and not pts:
        raise UnsupportedModelError(
            f"orientation node(s) {body.orientation_nodes} belong to no element with a position node")


def _body_points(nodes, pos_nodes, rigid_beams, bodies, body_of_orientation, ground_rotation, planar, x0, coord_index):
    """Every body's points (_place_points) and the bodies of every point, fixed points on the ground."""
    fully_fixed = {n for n in pos_nodes if all(c == CC.fixed for c in nodes[n].cls)}
    edges = {b.index: [] for b in bodies}
    for el in rigid_beams:
        b = body_of_orientation[el.nodes[1]]
        R = ground_rotation if b == 0 else np.eye(3)
        edges[b].append((el.nodes[0], el.nodes[2], R @ _chord(el), el.id))
    for b in bodies:
        _place_points(b, edges[b.index], nodes, fully_fixed, planar, x0, coord_index)
    bodies_of_point = {}
    for b in bodies:
        for n in b.points:
            bodies_of_point.setdefault(n, []).append(b.index)
    for n in fully_fixed:
        bodies_of_point.setdefault(n, [])
        if 0 not in bodies_of_point[n]:
            bodies_of_point[n].insert(0, 0)
            bodies[0].points[n] = _ground_point(nodes[n])
    return bodies_of_point


def _hinge_joints(hinges, body_of_orientation) -> dict:
    """The revolute joints of the hinge elements by their pair of bodies (their pivots found later)."""
    hinge_pairs = {}
    for el in hinges:
        if el.cls[0] == DC.fixed:
            continue
        a, b = body_of_orientation.get(el.nodes[0]), body_of_orientation.get(el.nodes[1])
        if a is None or b is None:
            raise UnsupportedModelError(f"element {el.id} ({el.type_name}) joins a flexible beam; not converted")
        if a == b:
            raise UnsupportedModelError(f"element {el.id} ({el.type_name}) joins two nodes of the same rigid body")
        if el.type_name == "PLHINGE":
            axis = np.array([0.0, 0.0, 1.0])
        else:
            axis = np.asarray(el.params[:3], dtype=float)
            axis = axis / np.linalg.norm(axis)
        st = el.estiff[0] if el.estiff else 0.0
        dp = el.edampp[0] if el.edampp else 0.0
        key = (min(a, b), max(a, b))
        if key in hinge_pairs:
            raise UnsupportedModelError(f"bodies {key} are joined by two hinge elements")
        hinge_pairs[key] = Joint("revolute", (a, b), -1, axis, (el.id, 1), st, dp)
    return hinge_pairs


def _joints(hinges, body_of_orientation, bodies_of_point, planar):
    """The joints: at every point shared by bodies, the hinge element's revolute joint there or, without
    one, a pin (planar) or a spherical joint; no two joints between the same bodies (a weld)."""
    hinge_pairs = _hinge_joints(hinges, body_of_orientation)
    joints = []
    for n, owners in sorted(bodies_of_point.items()):
        if len(owners) < 2:
            continue
        first = owners[0]
        for other in owners[1:]:
            key = (min(first, other), max(first, other))
            if key in hinge_pairs:
                j = hinge_pairs.pop(key)
                if j.node != -1:
                    raise UnsupportedModelError(f"bodies {key} share more than one position node")
                j.node = n
                joints.append(j)
            elif planar:
                joints.append(Joint("revolute", (first, other), n))
            else:
                joints.append(Joint("spherical", (first, other), n))
    for key, j in hinge_pairs.items():
        raise UnsupportedModelError(
            f"hinge element {j.hinge[0]} joins bodies that share no position node (its pivot is undefined)")
    seen = {}
    for j in joints:
        key = tuple(sorted(j.bodies))
        if key in seen:
            raise UnsupportedModelError(
                f"bodies {key} share the position nodes {seen[key]} and {j.node}: a rigid connection; "
                "model it as one body")
        seen[key] = j.node
    return joints


def _flexible_beams(flexible):
    """The flexible beams' properties; beams through a shared BETA node must be straight there."""
    flex = []
    for el in flexible:
        ea = None
        if el.cls[0] != DC.fixed:
            ea = el.estiff[0] if el.estiff else 0.0
        ei = el.estiff[1] if len(el.estiff) > 1 else 0.0
        if el.edampp and any(v != 0 for v in el.edampp):
            raise UnsupportedModelError(f"element {el.id}: EDAMPP of flexible beams is not converted")
        if any(v != 0 for v in el.estiff[2:]):
            raise UnsupportedModelError(f"element {el.id}: the shear stiffness kGA of a Timoshenko beam is not "
                                        "converted (the peer's beams here are shear-rigid)")
        if ei <= 0:
            raise UnsupportedModelError(f"element {el.id}: a flexible beam needs ESTIFF EI > 0")
        flex.append(FlexibleBeam(el.id, el.type_name, tuple(el.nodes), el.l0,
                                 el.lgeomy[0] if el.lgeomy else 0.0,
                                 el.emass[0] if el.emass else 0.0, ei, ea, el.type_name == "PLBEAMNL"))
    alpha_at = {}
    for fb in flex:
        for n in (fb.nodes[1], fb.nodes[3]):
            if n in alpha_at and abs(alpha_at[n] - fb.alpha0) > 1e-12:
                raise UnsupportedModelError(
                    f"BETA node {n} joins flexible beams with different reference angles (a kink); not converted")
            alpha_at[n] = fb.alpha0
    return flex


def analyse(model, sim=None) -> Topology:
    """Analyse a :class:`spacar.Model` (prepared and assembled here if no ``sim`` is given)."""
    model.prepare()
    if sim is None:
        sim = _core.Simulation(model.core)
        sim.assemble()
    system = sim.system
    # assemble() solves the positions only; the rates come with an evaluation at the initial state
    sim.evaluate(float(model.current_time), np.asarray(system.q0, dtype=float), np.asarray(system.qd0, dtype=float))
    data = sim.data
    x0 = np.array(data.x, dtype=float)
    xd0 = np.array(data.xd, dtype=float)
    coord_index = {tuple(lbl): i for i, lbl in enumerate(system.coord_label)}
    def_index = {tuple(lbl): i for i, lbl in enumerate(system.def_label)}

    nodes = model.nodes
    planar = _convertible(model)
    node_kind = {n: nd.kind for n, nd in nodes.items()}
    flexible, rigid_beams, hinges = _classify_elements(model.elements)
    orient = [n for n, kd in node_kind.items() if kd in ORIENTATION_KINDS and nodes[n].used]
    bodies, body_of_orientation = _rigid_bodies(nodes, orient, flexible, rigid_beams, hinges)
    ground_rotation = _ground_rotation(bodies[0], planar, x0, coord_index)
    _driven_rotations(model, orient, bodies, body_of_orientation, x0, coord_index)
    pos_nodes = [n for n, kd in node_kind.items() if kd in POSITION_KINDS and nodes[n].used]
    bodies_of_point = _body_points(nodes, pos_nodes, rigid_beams, bodies, body_of_orientation, ground_rotation,
                                   planar, x0, coord_index)
    point_masses = _mass_properties(nodes, flexible, rigid_beams, bodies, bodies_of_point, body_of_orientation)
    joints = _joints(hinges, body_of_orientation, bodies_of_point, planar)
    flex = _flexible_beams(flexible)

    flexible_pos = {el.nodes[0] for el in flexible} | {el.nodes[2] for el in flexible}
    partial_fix = {n: [i for i, c in enumerate(nodes[n].cls) if c == CC.fixed]
                   for n in pos_nodes if any(c == CC.fixed for c in nodes[n].cls)
                   and not all(c == CC.fixed for c in nodes[n].cls)}
    for n in partial_fix:
        if n not in flexible_pos and len(bodies_of_point.get(n, [])) != 1:
            raise UnsupportedModelError(f"node {n}: a partly fixed node must belong to one body or to beams")
    for n in pos_nodes:
        if n not in bodies_of_point and n not in flexible_pos:
            raise UnsupportedModelError(f"position node {n} belongs to no rigid body or flexible beam")

    gravity = np.asarray(model.core.gravity, dtype=float)
    return Topology(planar, bodies, joints, flex, body_of_orientation, bodies_of_point, partial_fix,
                    point_masses, ground_rotation, gravity, node_kind, x0, xd0, coord_index, def_index,
                    float(model.settings.epsint), float(model.settings.epsind))

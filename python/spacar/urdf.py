"""Robots from URDF files (docs/robots.md)::

    model = spacar.from_urdf("ur5_robot.urdf")          # fixed base, GRAVITY 0 0 -9.81
    model.timestep(100, 0.5)
    res = spacar.simulate(model)
    res.q                                                 # (nt, n joints): Pinocchio's q
    model.urdf_joints                                     # the joint of each DOF

A URDF robot becomes a spacar model of rigid spatial bodies, built as the element set builds
them (docs/elements.md):

* a **body** per moving joint (and the ground): the links joined to it by fixed joints merged
  into it, as Pinocchio merges them; one LAMBDA node carries its orientation, its points (the
  link frames' origins, the joints to its children, its centre of mass) are XYZ nodes held by
  rigid BEAMs from the body's origin (each BEAM with its own end LAMBDA node; points of the ground
  are fixed nodes);
* a **revolute or continuous joint** is a HINGE from the parent's LAMBDA node to the child's about
  the joint axis, its rotation e1 the DOF (DYNE), the misalignments fixed; the child's origin is
  the parent's XYZ node at the joint;
* a **prismatic joint** is a BEARING from the parent's point at the joint to the child's origin
  along the joint axis, its axial displacement e1 the DOF, the other five deformations fixed;
* **inertia**: the body's mass (MASS) at its centre of mass and its rotational inertia about it
  (MASS with the inertia tensor) on its LAMBDA node.

The model is built in the URDF's zero configuration: every LAMBDA node at its reference, so a
body's orientation is its rotation from that configuration and the inertia tensors are given in
the global axes of it. The DOFs are the joints in Pinocchio's order (depth first from the root
link, the children of a link in the order of their joint names, as urdfdom stores them; for a
chain, root to tip), element k being joint k, so that ``res.q`` (in rad and m) is the ``q`` of
``pinocchio.buildModelFromUrdf`` with the same signs.

Parsed with the standard library's ``xml.etree``; Pinocchio is not needed.
"""
from __future__ import annotations

import math
import os
import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

import numpy as np

from ._util import show
from .errors import InputError
from .io.files import read_input
from .model import Model

MOVING = ("revolute", "continuous", "prismatic")
# Points of a body closer than this (relative to the robot's size) are one node: a BEAM needs a
# length.
_SAME_POINT = 1e-12


@dataclass
class _Link:
    name: str
    shapes: list = field(default_factory=list)   # spacar.visuals.Shape: <visual> and <collision>
    mass: float = 0.0
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))       # in the link frame
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))  # about the COM, in the link frame


@dataclass
class _Joint:
    name: str
    type: str
    parent: str
    child: str
    xyz: np.ndarray
    rpy: np.ndarray
    axis: np.ndarray


@dataclass
class _Body:
    """A rigid body: the links merged by fixed joints; positions and tensors in the global axes
    of the zero configuration."""
    origin: np.ndarray               # its first point; the moments below are about it
    lam: int = 0                     # its LAMBDA node
    points: list = field(default_factory=list)   # [(position, node)]; points[0] is the origin
    mass: float = 0.0
    first_moment: np.ndarray = field(default_factory=lambda: np.zeros(3))  # Σ m c
    # Σ (R I Rᵀ + m (|c|² 1 − c cᵀ)), c the centres of mass from the origin
    inertia_o: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))

    def add(self, link: _Link, R, origin):
        """Add the inertia of a link whose frame is (R, origin) in the zero configuration."""
        c = origin + R @ link.com - self.origin
        self.mass += link.mass
        self.first_moment += link.mass * c
        self.inertia_o += R @ link.inertia @ R.T + link.mass * (c @ c * np.eye(3) - np.outer(c, c))

    def centre_and_inertia(self):
        """(centre of mass, rotational inertia about it); the centre None without mass."""
        if self.mass == 0:
            return None, self.inertia_o
        c = self.first_moment / self.mass
        return self.origin + c, self.inertia_o - self.mass * (c @ c * np.eye(3) - np.outer(c, c))


def rpy_matrix(rpy) -> np.ndarray:
    """URDF's rotation of roll, pitch, yaw: Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


# --- reading ------------------------------------------------------------------------------------

class _Reader:
    def __init__(self, path):
        self.path = str(path)
        self.warnings = []

    def fail(self, text):
        raise InputError(f"{self.path}: {text}")

    def numbers(self, elem, attr, n, default, where):
        text = elem.get(attr) if elem is not None else None
        if text is None:
            return np.array(default, dtype=float)
        try:
            values = [float(v) for v in text.split()]
        except ValueError:
            values = []
        if len(values) != n or not all(math.isfinite(v) for v in values):
            self.fail(f"{where}: {attr}={text!r} must be {n} finite number{'s' if n > 1 else ''}")
        return np.array(values)

    def origin(self, elem, where):
        o = elem.find("origin")
        return self.numbers(o, "xyz", 3, (0, 0, 0), where), self.numbers(o, "rpy", 3, (0, 0, 0), where)

    def name(self, elem, what):
        name = elem.get("name")
        if not name:
            self.fail(f"a <{what}> without a name")
        return name

    def link(self, elem) -> _Link:
        link = _Link(self.name(elem, "link"))
        link.shapes = self.shapes(elem, link.name)
        inertial = elem.find("inertial")
        if inertial is None:
            return link
        where = f"link {link.name!r}"
        xyz, rpy = self.origin(inertial, where)
        mass = inertial.find("mass")
        link.mass = float(self.numbers(mass, "value", 1, (0.0,), where)[0]) if mass is not None else 0.0
        if link.mass < 0:
            self.fail(f"{where}: negative mass {link.mass:g}")
        i = inertial.find("inertia")
        get = {k: float(self.numbers(i, k, 1, (0.0,), where)[0]) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
        J = np.array([[get["ixx"], get["ixy"], get["ixz"]],
                      [get["ixy"], get["iyy"], get["iyz"]],
                      [get["ixz"], get["iyz"], get["izz"]]])
        R = rpy_matrix(rpy)
        link.com, link.inertia = xyz, R @ J @ R.T
        return link

    def shapes(self, elem, link) -> list:
        """The link's <visual> and <collision> geometries (spacar.visuals.Shape), for drawing."""
        from .visuals import Shape, resolve

        out = []
        for role in ("visual", "collision"):
            for k, v in enumerate(elem.findall(role)):
                where = f"link {link!r} <{role}> {k + 1}"
                xyz, rpy = self.origin(v, where)
                geometry = v.find("geometry")
                shape = None if geometry is None else next(iter(geometry), None)
                if shape is None:
                    continue
                if shape.tag == "box":
                    size = tuple(self.numbers(shape, "size", 3, (0, 0, 0), where))
                elif shape.tag == "cylinder":
                    size = (float(self.numbers(shape, "radius", 1, (0,), where)[0]),
                            float(self.numbers(shape, "length", 1, (0,), where)[0]))
                elif shape.tag == "sphere":
                    size = (float(self.numbers(shape, "radius", 1, (0,), where)[0]),)
                elif shape.tag == "mesh" and shape.get("filename"):
                    size = tuple(self.numbers(shape, "scale", 3, (1, 1, 1), where))
                    out.append(Shape(link, role, "mesh", size, (tuple(xyz), tuple(rpy)),
                                     resolve(shape.get("filename"), self.path)))
                    continue
                else:
                    self.warnings.append(f"{where}: a <{shape.tag}> geometry is not drawn")
                    continue
                if min(size) < 0:
                    self.fail(f"{where}: a {shape.tag} of negative size {tuple(float(v) for v in size)}")
                out.append(Shape(link, role, shape.tag, size, (tuple(xyz), tuple(rpy))))
        return out

    def joint(self, elem, links) -> _Joint:
        name = self.name(elem, "joint")
        kind = elem.get("type")
        where = f"joint {name!r}"
        if kind in ("floating", "planar"):
            self.fail(f"{where} is {kind}: spacar.from_urdf builds robots of revolute, continuous, prismatic and "
                      "fixed joints (for a floating base, leave the root link without a joint and call "
                      "from_urdf(path, floating=True))")
        if kind not in MOVING + ("fixed",):
            self.fail(f"{where} has type {kind!r}: use revolute, continuous, prismatic or fixed")
        ends = []
        for tag in ("parent", "child"):
            e = elem.find(tag)
            link = e.get("link") if e is not None else None
            if link is None:
                self.fail(f"{where} has no <{tag} link=...>")
            if link not in links:
                self.fail(f"{where}: its {tag} link {link!r} is not defined")
            ends.append(link)
        xyz, rpy = self.origin(elem, where)
        axis = self.numbers(elem.find("axis"), "xyz", 3, (1, 0, 0), where)
        if kind in MOVING:
            norm = np.linalg.norm(axis)
            if not norm > 0:
                self.fail(f"{where}: the axis has zero length")
            axis = axis / norm
        if elem.find("mimic") is not None:
            self.warnings.append(f"{where}: <mimic> is ignored; the joint is an independent DOF "
                                 "(as in Pinocchio's model without mimic joints)")
        return _Joint(name, kind, ends[0], ends[1], xyz, rpy, axis)

    def read(self, limit: int):
        try:
            root = ET.fromstring(read_input(self.path, limit, "URDF"))
        except ET.ParseError as err:
            self.fail(f"not a well-formed URDF (XML) file: {err}")
        if root.tag != "robot":
            self.fail(f"the root element is <{root.tag}>, not <robot>")
        links = {}
        for elem in root.findall("link"):
            link = self.link(elem)
            if link.name in links:
                self.fail(f"link {link.name!r} is defined twice")
            links[link.name] = link
        if not links:
            self.fail("the robot has no links")
        joints, names = [], set()
        for elem in root.findall("joint"):
            j = self.joint(elem, links)
            if j.name in names:
                self.fail(f"joint {j.name!r} is defined twice")
            names.add(j.name)
            joints.append(j)
        self.ignored(root)
        return links, joints

    def dissipative(self, joint) -> bool:
        dyn, where = joint.find("dynamics"), f"joint {joint.get('name')!r}"
        return any(self.numbers(dyn, a, 1, (0.0,), where)[0] for a in ("damping", "friction"))

    def ignored(self, root):
        """Warnings for what a dynamic model of rigid bodies leaves out."""
        geometry = sum(len(link.findall("collision")) for link in root.findall("link"))
        if geometry:
            self.warnings.append(f"{geometry} <collision> geometries are not used for contact: the model has none "
                                 "(spacar.view3d draws the <visual> shapes)")
        for tag, text in (("transmission", "transmissions (actuators) are not imported"),
                          ("gazebo", "<gazebo> extensions are ignored")):
            n = len(root.findall(tag))
            if n:
                self.warnings.append(f"{n} {text}")
        for tag, text in (("limit", "joint limits are not enforced"),
                          ("dynamics", "joint damping and friction (<dynamics>) are not modelled"),
                          ("safety_controller", "<safety_controller> is ignored"),
                          ("calibration", "<calibration> is ignored")):
            which = [j.get("name") for j in root.findall("joint") if j.find(tag) is not None
                     and (tag != "dynamics" or self.dissipative(j))]
            if which:
                self.warnings.append(f"{text} (joints {', '.join(which)})")


def _tree(reader, links, joints) -> tuple:
    """The root link and the joints in Pinocchio's order: depth first from the root link, the children of a link in
    the order of their joint names (urdfdom keeps the joints in a map by name)."""
    children: dict = {}
    parent_of = {}
    for j in joints:
        if j.child in parent_of:
            reader.fail(f"link {j.child!r} is the child of two joints ({parent_of[j.child].name!r}, {j.name!r}): "
                        "closed loops are not URDF trees")
        parent_of[j.child] = j
        children.setdefault(j.parent, []).append(j)
    roots = [name for name in links if name not in parent_of]
    if len(roots) != 1:
        reader.fail(f"the links must form one tree with one root; roots found: {roots or 'none (a loop)'}")
    order = []
    stack = sorted(children.get(roots[0], []), key=lambda j: j.name, reverse=True)
    while stack:
        j = stack.pop()
        order.append(j)
        stack.extend(sorted(children.get(j.child, []), key=lambda j: j.name, reverse=True))
    if len(order) != len(joints):  # a loop apart from the root's tree
        reader.fail("the joints do not form a tree reachable from the root link")
    return roots[0], order


# --- building -----------------------------------------------------------------------------------

class _Builder:
    def __init__(self, model: Model, scale: float):
        self.m = model
        self.tol = _SAME_POINT * scale
        self.next_node = 1
        self.node_mass: dict = {}
        self.ground_lam = None  # the ground's LAMBDA node (a fixed base), else None

    def node(self):
        n = self.next_node
        self.next_node += 1
        return n

    def lambda_node(self, fixed=False):
        n = self.node()
        self.m.lambda_(n, 1.0, 0.0, 0.0, 0.0)
        if fixed:
            self.m.fix(n)
        return n

    def point(self, body: _Body, p, next_element):
        """The XYZ node of body at p (an existing one if it is there already)."""
        n = self.at(body, p)
        if n is not None:
            return n, next_element
        n = self.node()
        self.m.xyz(n, *p)
        return n, self.attach(body, n, p, next_element)

    def attach(self, body: _Body, node: int, p, next_element):
        """Make the XYZ node at p a point of body: fixed on the ground, else held by a rigid BEAM
        from the body's origin (with its own end orientation node)."""
        if body.lam == self.ground_lam:
            self.m.fix(node)
        else:
            o, origin = body.points[0][1], body.points[0][0]
            self.m.beam(next_element, o, body.lam, node, self.lambda_node(), *_perpendicular(p - origin))
            next_element += 1
        body.points.append((p, node))
        return next_element

    def at(self, body: _Body, p):
        """The node of body at p, or None."""
        return next((n for q, n in body.points if np.abs(q - p).max() <= self.tol), None)


def _perpendicular(d) -> np.ndarray:
    """A vector perpendicular to d (the cross-section axis of a BEAM along d)."""
    k = int(np.argmin(np.abs(d)))
    return np.cross(d, np.eye(3)[k])


def _close_loop(b: _Builder, loop: dict, body_of: dict, frame: dict, next_element: int) -> int:
    """A loop joint: one XYZ node at its point, a point of both bodies (rigid BEAMs from their
    origins, or fixed on the ground); a revolute one also a HINGE between their LAMBDA nodes about
    its axis, its rotation released and its misalignments fixed."""
    parent, child = body_of[loop["parent"]], body_of[loop["child"]]
    if parent is child:
        raise InputError(f"{loop['name']}: {loop['parent']!r} and {loop['child']!r} are one rigid body (fixed joints)")
    R, o = frame[loop["parent"]]
    p = o + R @ loop["xyz"]
    on_parent, on_child = b.at(parent, p), b.at(child, p)
    if on_parent is not None and on_parent == on_child:
        raise InputError(f"{loop['name']}: its point is already a joint of {loop['parent']!r} and {loop['child']!r}")
    if on_parent is not None and on_child is not None:
        raise InputError(f"{loop['name']}: both links already have a point there (joints at one origin): close the "
                         f"loop at another point")
    if on_parent is not None:
        next_element = b.attach(child, on_parent, p, next_element)
    elif on_child is not None:
        next_element = b.attach(parent, on_child, p, next_element)
    else:
        node, next_element = b.point(parent, p, next_element)
        next_element = b.attach(child, node, p, next_element)
    if loop["type"] == "revolute":
        b.m.hinge(next_element, parent.lam, child.lam, *(R @ loop["axis"]))
        b.m.rlse(next_element, 1)
        next_element += 1
    return next_element


# The largest URDF of example-robot-data has 0.2 MB; parsing takes about 20 bytes of memory and
# 0.5 µs per byte of the file (a 20 MB file: 454 MB, 11 s).
MAX_URDF_BYTES = 8 * 2**20


def _three_numbers(value):
    """value as an array of three finite floats, or None."""
    try:
        v = np.array([float(x) for x in value])
    except (TypeError, ValueError, OverflowError):  # OverflowError: an integer beyond double
        return None
    return v if v.shape == (3,) and np.isfinite(v).all() else None


_LOOP_KEYS = {"parent", "child", "xyz", "type", "axis", "name"}
LOOP_TYPES = ("spherical", "revolute")


def _loop_joints(loops, dependent, links, moving, path) -> tuple:
    """The loop joints (dicts with parent, child, xyz, type, axis, name) and the set of dependent
    joint names, checked against the URDF's links and moving joints (InputError naming the file)."""
    def fail(text):
        raise InputError(f"{path}: {text}")

    if isinstance(loops, dict) or not hasattr(loops, "__iter__"):
        fail(f"loops must be a list of loop joints (dicts), got {show(loops)}")
    out = []
    for k, loop in enumerate(loops):
        where = f"loop joint {k}"
        if not isinstance(loop, dict):
            fail(f"{where} must be a dict with 'parent', 'child', 'xyz' (in the parent link's frame) and 'type', "
                 f"got {show(loop)}")
        unknown = set(loop) - _LOOP_KEYS
        if unknown:
            fail(f"{where} has unknown keys {sorted(unknown)} (known: {sorted(_LOOP_KEYS)})")
        name = str(loop.get("name", where))
        for key in ("parent", "child"):
            if loop.get(key) not in links:
                fail(f"{name}: {key} {show(loop.get(key))} is not a link of the URDF")
        if loop["parent"] == loop["child"]:
            fail(f"{name}: parent and child are the same link {loop['parent']!r}")
        kind = loop.get("type", "spherical")
        if kind not in LOOP_TYPES:
            fail(f"{name}: type must be one of {', '.join(map(repr, LOOP_TYPES))}, got {show(kind)}")
        values = {}
        for key, default in (("xyz", (0.0, 0.0, 0.0)), ("axis", None)):
            value = loop.get(key, default)
            if value is None:
                values[key] = None
                continue
            v = _three_numbers(value)
            if v is None:
                fail(f"{name}: {key} must be three finite numbers, got {show(value)}")
            values[key] = v
        if kind == "revolute":
            if values["axis"] is None or not np.any(values["axis"]):
                fail(f"{name}: a revolute loop joint needs a nonzero axis (in the parent link's frame)")
            values["axis"] = values["axis"] / np.linalg.norm(values["axis"])
        elif values["axis"] is not None:
            fail(f"{name}: a spherical loop joint has no axis")
        out.append({"name": name, "parent": loop["parent"], "child": loop["child"], "type": kind, **values})
    if isinstance(dependent, str) or not hasattr(dependent, "__iter__"):
        fail(f"dependent must be a list of joint names, got {show(dependent)}")
    names = {j.name for j in moving}
    dependent = list(dependent)
    for j in dependent:
        if j not in names:
            fail(f"dependent joint {show(j)} is not a moving joint of the URDF")
    if dependent and not out:
        fail("dependent joints need loop joints that determine them (loops=...)")
    constraints = sum(3 if loop["type"] == "spherical" else 5 for loop in out)
    if len(dependent) > constraints:
        fail(f"{len(dependent)} dependent joints for the {constraints} constraints of the loop joints: the loops cannot "
             "determine them")
    return out, set(dependent), constraints


def from_urdf(path, gravity=(0.0, 0.0, -9.81), *, floating: bool = False, loops=(), dependent=(),
              max_bytes: int | None = None) -> Model:
    """A spacar :class:`Model` of the fixed-base robot described by the URDF file ``path``: its
    revolute, continuous, prismatic and fixed joints, branches, link inertias (mass, centre of
    mass, inertia tensor with the origin's rpy), joint origins (xyz, rpy) and axes, in the URDF's
    zero configuration, with ``GRAVITY`` ``gravity`` (default 0 0 −9.81).

    One DOF per moving joint, in Pinocchio's joint order and sign (see :mod:`spacar.urdf`): the
    joint of the k-th DOF (from 1) is HINGE (revolute, continuous) or BEARING (prismatic)
    element k, its e1 DYNE; ``model.urdf_joints`` lists the joint names in that order and
    ``model.urdf_links`` gives each link's ``(position node, orientation node)`` (the origin of
    its frame and the LAMBDA node of its body). Initial joint values and rates are given as for
    any model: ``model.e(k, 1, q0)``, ``model.ed(k, 1, qd0)``; a TIMESTEP is needed to simulate.

    What the model leaves out is listed as warnings (Python warnings and ``model.warnings``):
    geometry (meshes), transmissions, joint limits, damping and friction, mimic relations (the
    mimic joint becomes an independent DOF). Floating and planar joints (a floating base) and
    anything that is not a tree of links raise :class:`spacar.InputError` naming the file; so
    does a file that is not well-formed XML.

    ``floating=True``: the root link is a free body instead of the ground, as Pinocchio's
    ``buildModelFromUrdf(path, JointModelFreeFlyer())``: its origin (XYZ node 1) and its
    orientation (LAMBDA node 2, Euler parameters with the L2MIN1 constraint) are degrees of
    freedom, DYNX 1 1 2 3 and DYNX 2 2 3 4 (λ0 calculable at the start; when it gets small, past
    about 120° from the URDF's frame, a run makes another parameter the calculable one), the first
    six DOFs: ``res.q`` is (x, y, z, λ1, λ2, λ3, the joints).
    ``model.urdf_base`` is (1, 2), None for a fixed base. The model is returned prepared (its
    reference geometry the URDF's zero configuration), so that ``model.x(1, x, y, z)`` and
    ``model.x(2, λ0, λ1, λ2, λ3)`` place the robot and ``model.xd`` set the base's velocity
    (``λ̇ = ½ E(λ)ᵀ ω``); no elements can be added to it. Its runs take the recursive path, the
    base the free root of the articulated-body algorithm (docs/robots.md, "Floating base").

    ``loops``: loop joints beside the URDF's tree, which URDF cannot describe (a four-bar knee, a
    parallel arm): dicts ``{"parent": link, "child": link, "xyz": (x, y, z), "type": "spherical"}``
    (the point ``xyz`` of the parent link's frame is a point of the child link too: a ball joint,
    three constraints) or ``"type": "revolute"`` with ``"axis"`` (in the parent link's frame; the
    links also keep that axis in common: five constraints), optionally a ``"name"``. The point
    must be where the child's link puts it in the zero configuration too (the loop closed there;
    otherwise the assembly closes it and warns of the nodes it moved). ``dependent``: the names
    of the moving joints whose coordinates the loops determine: their rotations (or slides) are
    released (RLSE) instead of DOFs, so that the DOFs are the other joints, in the same order;
    element k is still joint k (``model.urdf_joints``). Such a model takes the recursive path
    with its loops closed at every right-hand side (exact loops; ``recursive=False``: the general
    path, the constraint formulation; docs/robots.md, "Closed loops").

    The file must be a regular file (a FIFO or a device
    is refused at once) of at most ``max_bytes`` bytes (default :data:`MAX_URDF_BYTES`, 8 MiB).
    """
    if not isinstance(path, (str, os.PathLike)) or "\x00" in os.fspath(path):
        raise InputError(f"from_urdf needs the path of a URDF file, got {show(path)}")
    g = _three_numbers(gravity)
    if g is None:
        raise InputError(f"gravity must be three finite numbers (gx, gy, gz), got {show(gravity)}")
    limit = MAX_URDF_BYTES if max_bytes is None else max_bytes
    if isinstance(limit, bool) or not isinstance(limit, int) or limit < 1:
        raise InputError(f"from_urdf: max_bytes must be a positive integer, got {show(max_bytes)}")
    reader = _Reader(os.fspath(path))
    links, joints = reader.read(limit)
    root, order = _tree(reader, links, joints)

    # Link frames in the zero configuration: (rotation, origin) in the global axes.
    frame = {root: (np.eye(3), np.zeros(3))}
    for j in order:
        R, o = frame[j.parent]
        frame[j.child] = (R @ rpy_matrix(j.rpy), o + R @ j.xyz)
    scale = max([1.0] + [float(np.abs(o).max()) for _, o in frame.values()])

    m = Model()
    b = _Builder(m, scale)
    moving = [j for j in order if j.type in MOVING]
    loop_joints, dependent, constraints = _loop_joints(loops, dependent, links, moving, reader.path)
    if len(dependent) < constraints:
        reader.warnings.append(f"the loop joints add {constraints} constraints and {len(dependent)} joints are dependent: "
                               f"unless {constraints - len(dependent)} of the constraints are redundant (a planar loop "
                               "closed by a ball joint), the mechanism is over-constrained (name more dependent joints)")
    element_of = {j.name: k for k, j in enumerate(moving, start=1)}
    next_element = len(moving) + 1  # elements 1..n are the joints: the DOFs in their order
    if not isinstance(floating, bool):
        raise InputError(f"from_urdf: floating must be True or False, got {show(floating)}")
    if floating:  # the root link a free body: its origin and orientation the first six DOFs
        ground = None
        base = _Body(np.zeros(3))
        n_origin = b.node()
        m.xyz(n_origin, 0.0, 0.0, 0.0)
        base.points.append((np.zeros(3), n_origin))
        base.lam = b.lambda_node()
        m.dynx(n_origin, 1, 2, 3)
        m.dynx(base.lam, 2, 3, 4)  # λ1..λ3; λ0 calculable (the L2MIN1 constraint)
        base.add(links[root], np.eye(3), np.zeros(3))
        body_of = {root: base}
        bodies = [base]
        link_nodes = {root: (n_origin, base.lam)}
    else:
        ground = _Body(np.zeros(3))
        ground.lam = b.ground_lam = b.lambda_node(fixed=True)
        body_of = {root: ground}
        bodies = []
        n_origin, next_element = b.point(ground, np.zeros(3), next_element)
        link_nodes = {root: (n_origin, ground.lam)}  # (the ground's inertia does not matter)
    for j in order:
        parent = body_of[j.parent]
        R, o = frame[j.child]
        if j.type == "fixed":
            body_of[j.child] = parent
            n, next_element = b.point(parent, o, next_element)
        else:
            k = element_of[j.name]
            child = _Body(o)
            child.lam = b.lambda_node()
            axis = R @ j.axis
            if j.type == "prismatic":
                p, next_element = b.point(parent, o, next_element)
                n = b.node()
                m.xyz(n, *o)
                m.bearing(k, p, parent.lam, n, child.lam, *axis)  # e2..e6 stay fixed
            else:
                n, next_element = b.point(parent, o, next_element)
                m.hinge(k, parent.lam, child.lam, *axis)
            if j.name in dependent:
                m.rlse(k, 1)  # determined by the loops
            else:
                m.dyne(k, 1)
            child.points.append((o, n))
            body_of[j.child] = child
            bodies.append(child)
        link_nodes[j.child] = (n, body_of[j.child].lam)
        if body_of[j.child] is not ground:
            body_of[j.child].add(links[j.child], R, o)

    for loop in loop_joints:
        next_element = _close_loop(b, loop, body_of, frame, next_element)

    for body in bodies:
        c, J = body.centre_and_inertia()
        if c is not None:
            n, next_element = b.point(body, c, next_element)
            b.node_mass[n] = b.node_mass.get(n, 0.0) + body.mass
        if np.any(J):
            m.mass(body.lam, J[0, 0], J[0, 1], J[0, 2], J[1, 1], J[1, 2], J[2, 2])
    for n, mass in sorted(b.node_mass.items()):
        m.mass(n, mass)
    if np.any(g):
        m.gravity(*g)

    m.urdf_joints = [j.name for j in moving]
    m.urdf_base = (n_origin, base.lam) if floating else None
    if floating:
        # The reference geometry is the URDF's zero configuration: X 1 and X 2 then place the
        # robot (before the first END they would change its geometry instead).
        m.prepare()
    m.urdf_links = link_nodes
    from .visuals import RobotShapes

    shapes = [shape for link in links.values() for shape in link.shapes]
    m.urdf_shapes = RobotShapes(shapes, {name: (*link_nodes[name], frame[name][0]) for name in link_nodes}) \
        if shapes else None
    for w in reader.warnings:
        m.warnings.append(f"{reader.path}: {w}")
        warnings.warn(f"{reader.path}: {w}", stacklevel=2)
    return m

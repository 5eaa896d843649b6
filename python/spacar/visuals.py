"""The geometry of a URDF robot's links for drawing (docs/robots.md, "Drawing the links"): the
<visual> and <collision> shapes that :func:`spacar.from_urdf` reads beside the inertias, placed
on the links' frames at a state of the results and drawn by :func:`spacar.view3d` as surfaces.

Boxes, cylinders and spheres are triangulated here; meshes (STL, OBJ, PLY; COLLADA .dae with
pycollada) are read by trimesh when it is installed (``pip install trimesh``). A visual shape
that cannot be read is replaced by the link's collision shapes where those can be (the UR5 of
example-robot-data has COLLADA visuals and STL collision meshes), else left out with a warning.
"""
from __future__ import annotations

import functools
import math
import os
import warnings
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Shape", "RobotShapes"]


@dataclass(frozen=True)
class Shape:
    """One geometry of a link: ``role`` "visual" or "collision", ``kind`` "box" (``size`` the
    three sides), "cylinder" (radius, length; along z), "sphere" (radius,) or "mesh" (``size`` its
    scale along x, y, z; ``path`` the file), ``origin`` (xyz, rpy) in the link's frame."""

    link: str
    role: str
    kind: str
    size: tuple
    origin: tuple
    path: str | None = None


@dataclass
class RobotShapes:
    """The shapes of a robot's links and where its links are: ``frames`` maps a link to (its
    position node, its orientation node, its frame's rotation in the zero configuration)."""

    shapes: list
    frames: dict
    skipped: list = field(default_factory=list)

    def surfaces(self, node_coordinates) -> list:
        """[(link, role, vertices (n, 3) in global axes, faces (m, 3))] at a state, given
        {node: coordinates} of its x row: the visual shapes, a link's collision shapes in place
        of visuals that cannot be read."""
        from .geometry import rotation
        from .urdf import rpy_matrix

        out = []
        for link, shapes in self._drawn().items():
            pos_node, lam_node, R0 = self.frames[link]
            R = rotation(node_coordinates[lam_node]) @ R0
            o = np.asarray(node_coordinates[pos_node], dtype=float)
            for shape in shapes:
                V, F = triangles(shape)
                xyz, rpy = shape.origin
                local = V @ rpy_matrix(rpy).T + np.asarray(xyz)
                out.append((link, shape.role, local @ R.T + o, F))
        return out

    def _drawn(self) -> dict:
        """{link: shapes drawn}: its readable visual shapes; where a visual cannot be read, the
        link's readable collision shapes instead (if it has any); a link with collision shapes
        alone is drawn with them. Every mesh that cannot be read is named in a warning."""
        by_link: dict = {}
        for shape in self.shapes:
            by_link.setdefault(shape.link, {"visual": [], "collision": []})[shape.role].append(shape)
        drawn = {}
        for link, roles in by_link.items():
            visuals = [s for s in roles["visual"] if _readable(s)]
            collision = [s for s in roles["collision"] if _readable(s)]
            if (len(visuals) < len(roles["visual"]) or not roles["visual"]) and collision:
                visuals = collision
            unread = [s.path for s in roles["visual"] if not _readable(s)]
            if unread:
                missing = [p for p in unread if not os.path.isfile(p)]
                why = (f"no such file: {', '.join(missing)}" if missing else
                       "cannot be read (pip install trimesh; pycollada for .dae)")
                instead = "drawn with its collision shapes" if visuals is collision and collision else \
                    "the rest of the link is drawn" if visuals else "the link is not drawn"
                warnings.warn(f"link {link!r}: its mesh{'es' if len(unread) > 1 else ''} {', '.join(unread)}: {why}; "
                              f"{instead}", stacklevel=4)
            if visuals:
                drawn[link] = visuals
        return drawn


def _readable(shape: Shape) -> bool:
    if shape.kind != "mesh":
        return True
    return _mesh(shape.path) is not None


@functools.lru_cache(maxsize=64)
def _mesh(path):
    """(vertices, faces) of a mesh file, or None if it cannot be read (no trimesh, no such file,
    a format trimesh cannot read without extra packages)."""
    if path is None or not os.path.isfile(path):
        return None
    try:
        import trimesh
    except ImportError:
        return None
    try:
        mesh = trimesh.load(path, force="mesh")
        V, F = np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=int)
    except Exception:  # noqa: BLE001 - any reader error: the shape is not drawn
        return None
    return (V, F) if len(V) and len(F) else None


def triangles(shape: Shape, n: int = 24):
    """(vertices (k, 3), faces (m, 3)) of a shape in its own frame."""
    if shape.kind == "box":
        hx, hy, hz = (v / 2 for v in shape.size)
        V = np.array([[sx * hx, sy * hy, sz * hz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        F = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
        return V, F
    if shape.kind == "cylinder":
        r, length = shape.size
        a = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
        ring = np.column_stack([r * np.cos(a), r * np.sin(a)])
        V = np.vstack([np.column_stack([ring, np.full(n, -length / 2)]), np.column_stack([ring, np.full(n, length / 2)]),
                       [[0.0, 0.0, -length / 2], [0.0, 0.0, length / 2]]])
        i = np.arange(n)
        j = (i + 1) % n
        F = np.vstack([np.column_stack([i, j, n + j]), np.column_stack([i, n + j, n + i]),
                       np.column_stack([np.full(n, 2 * n), j, i]), np.column_stack([np.full(n, 2 * n + 1), n + i, n + j])])
        return V, F
    if shape.kind == "sphere":
        (r,) = shape.size
        polar, around = np.linspace(0.0, math.pi, n // 2 + 1), np.linspace(0.0, 2 * math.pi, n, endpoint=False)
        P, A = np.meshgrid(polar, around, indexing="ij")
        V = r * np.column_stack([(np.sin(P) * np.cos(A)).ravel(), (np.sin(P) * np.sin(A)).ravel(), np.cos(P).ravel()])
        rows, cols = P.shape
        F = []
        for p in range(rows - 1):
            for q in range(cols):
                a0, a1 = p * cols + q, p * cols + (q + 1) % cols
                F += [[a0, a1, a1 + cols], [a0, a1 + cols, a0 + cols]]
        return V, np.array(F)
    mesh = _mesh(shape.path)
    if mesh is None:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=int)
    V, F = mesh
    return V * np.asarray(shape.size, dtype=float), F


def resolve(filename: str, urdf_path: str) -> str:
    """The file of a URDF mesh name: package://PKG/rest under the nearest ancestor directory of
    the URDF named PKG (or holding a directory PKG), or under the directories of ROS_PACKAGE_PATH;
    file:// paths and relative paths from the URDF's directory."""
    here = os.path.dirname(os.path.abspath(urdf_path))
    if filename.startswith("file://"):
        return filename[len("file://"):]
    if not filename.startswith("package://"):
        return filename if os.path.isabs(filename) else os.path.join(here, filename)
    package, _, rest = filename[len("package://"):].lstrip("/").partition("/")
    if not package:
        return os.path.join(here, rest)
    d = here
    while True:
        if os.path.basename(d) == package:
            return os.path.join(d, rest)
        if os.path.isdir(os.path.join(d, package)):
            return os.path.join(d, package, rest)
        parent = os.path.dirname(d)
        if parent == d:
            break
        d = parent
    for root in filter(None, os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep)):
        if os.path.isdir(os.path.join(root, package)):
            return os.path.join(root, package, rest)
    return os.path.join(here, package, rest)

"""Plots of results and drawings of mechanisms, with matplotlib only (imported when this module
is; ``import spacar`` does not import it).

* :func:`plot` — any coordinate, deformation, stress or reaction against time or against another
  (``plot(res, "e(2,2)")``, ``plot(res, ("X", 8, 1), x=("X", 2, 1))``).
* :func:`draw` — the mechanism at one output time: beams with their cubic deflection shape
  (deflections of flexible beams magnified on request), trusses as lines, pins and supports as
  symbols (a clamp as a hatched wall), rigid links of three or more nodes as filled bodies,
  wheels and pulleys as circles, rigid bodies (LAMBDA nodes with inertia) as body-frame triads;
  2-D for planar models, 3-D otherwise.
* :func:`spacar.animate` (module :mod:`spacar.animation`) — the same drawing over all output times.
"""
from __future__ import annotations

import numpy as np

import matplotlib.pyplot as plt

from ._util import show
from .errors import InputError
from .geometry import frame_coordinates, magnified, shapes
from .results import _ARRAYS, STATE_ARRAYS, Results, require_results

STYLE = {
    "beam": dict(color="C0", lw=2.5, solid_capstyle="round", zorder=3),
    "truss": dict(color="C1", lw=2.0, zorder=3),
    "link": dict(color="0.4", lw=1.2, ls="--", zorder=2),
    "belt": dict(color="C2", lw=1.5, zorder=3),
    "wheel": dict(color="k", lw=2.0, zorder=3),
    "spoke": dict(color="k", lw=1.0, zorder=3),
    "axis": dict(color="0.35", lw=1.2, zorder=3),
    "triad-x": dict(color="tab:red", lw=2.0, zorder=4),
    "triad-y": dict(color="tab:green", lw=2.0, zorder=4),
    "triad-z": dict(color="tab:blue", lw=2.0, zorder=4),
    "pin": dict(marker="o", ms=7, mfc="white", mec="k", mew=1.5, ls="none", zorder=6),
    "ground": dict(marker="^", ms=13, mfc="0.6", mec="0.3", ls="none", zorder=1),
    "clamp": dict(color="0.15", lw=1.6, solid_capstyle="butt", zorder=1),
    "body": dict(facecolor="C0", edgecolor="C0", alpha=0.25, lw=1.0, zorder=2),
    "slider": dict(marker="s", ms=13, mfc="0.75", mec="k", ls="none", zorder=5),
    "mass": dict(marker="o", ms=9, mfc="k", mec="k", ls="none", zorder=5),
    "point": dict(marker="x", ms=8, color="k", ls="none", zorder=5),
}


# --------------------------------------------------------------------------------------------
# Time histories and transfer plots
# --------------------------------------------------------------------------------------------

def _series(res: Results, spec):
    if isinstance(spec, str) and spec.strip().lower() == "t":
        return res.t, "t"
    attr, col = res.column(spec)
    return getattr(res, attr)[:, col], Results.describe(spec)


def plot(res: Results, y, x="t", ax=None, **kwargs):
    """Plot one or more quantities ``y`` against time (``x="t"``) or against another quantity.

    A quantity is a MATASC label (``"x(8,1)"``, ``"e(2,2)"``, ``"s(2,1)"`` for σ, ``"r(1,1)"``
    for a reaction), a keyword line (``"XD 2 1"``) or a tuple (``("EDD", 2, 3)``). Extra keyword
    arguments go to ``Axes.plot`` (``label`` names a single curve in a legend). Returns the axes."""
    require_results(res, "plot")
    if ax is None:
        _, ax = plt.subplots()
    ys = y if isinstance(y, list) else [y]
    label = kwargs.pop("label", None)  # a legend entry of the user's (single quantity)
    xv, xlabel = _series(res, x)
    for spec in ys:
        yv, ylabel = _series(res, spec)
        ax.plot(xv, yv, label=label if label is not None and len(ys) == 1 else ylabel, **kwargs)
    ax.set_xlabel("t [s]" if xlabel == "t" else xlabel)
    if len(ys) == 1:
        ax.set_ylabel(ylabel)
    else:
        ax.legend()
    ax.grid(True, alpha=0.3)
    return ax


# --------------------------------------------------------------------------------------------
# Drawings of the mechanism
# --------------------------------------------------------------------------------------------

class Scene:
    """The artists of a mechanism drawing, updated frame by frame (:meth:`update`)."""

    def __init__(self, res: Results, ax=None, k: int = 0, *, labels: bool = False, trace=(),
                 beam_points: int = 21, title: bool = True, figsize=None, dpi=None, magnify: float = 1.0,
                 caption=None):
        if res.geometry is None:
            raise InputError("these results have no geometry to draw (results of spacar.simulate have)")
        if len(res.t) == 0:
            raise InputError("these results have no output times")
        self.res = res
        self.geometry = res.geometry
        self.spatial = self.geometry.spatial
        self.dim = 3 if self.spatial else 2
        self.node_columns = res.node_columns
        self.beam_points = beam_points
        self.labels = labels
        if not (isinstance(magnify, (int, float)) and np.isfinite(magnify) and magnify > 0):
            raise InputError(f"magnify must be a positive number, got {magnify!r}")
        self.magnify = float(magnify)
        self.caption = caption if caption is not None else (lambda i: f"t = {self.res.t[i]:.4g} s")
        if ax is None:
            fig = plt.figure(figsize=figsize, dpi=dpi)
            ax = fig.add_subplot(projection="3d") if self.spatial else fig.add_subplot()
        elif self.spatial and getattr(ax, "name", "") != "3d":
            raise InputError("a spatial model needs 3-D axes (projection='3d')")
        self.ax = ax
        self.scale = self._scale()
        self.lines = []
        for sh in self._shapes(k):
            self.lines.append(self._artist(sh))
        self._static_decorations(trace)
        self.node_texts = {}
        if labels:
            self._labels(k)
        self.title = ax.set_title("") if title else None
        self._limits()
        self.update(k)

    def _artist(self, sh):
        """A line for a shape; a filled polygon for a body (``spacar_kind`` and gid name it)."""
        ax, style = self.ax, STYLE.get(sh.kind, dict(color="k"))
        if sh.kind == "body":
            if self.spatial:
                from mpl_toolkits.mplot3d.art3d import Poly3DCollection

                artist = ax.add_collection3d(Poly3DCollection([sh.points], **style))
            else:
                (artist,) = ax.fill(*sh.points.T, **style)
            artist.set_gid(f"body-{sh.node}")
        else:
            (artist,) = ax.plot(*sh.points.T, **style)
            artist.set_gid(f"element-{sh.element}" if sh.element is not None else f"node-{sh.node}")
        artist.spacar_kind = sh.kind
        return artist

    def _labels(self, k):
        """Node numbers beside their nodes, off the symbols: shifted (in points, so at any zoom)
        away from the elements that meet there — into the widest free angle in 2-D, up and to
        the right in 3-D — and kept there as the mechanism moves."""
        from matplotlib.transforms import ScaledTranslation

        coords, ax = self._coords(k), self.ax
        for n in self.geometry.position_nodes:
            if n not in coords:
                continue
            direction = np.array([1.0, 1.0]) / np.sqrt(2.0)
            if not self.spatial:
                direction = self._free_direction(n, coords)
            dx, dy = 11.0 * direction
            offset = ax.transData + ScaledTranslation(dx / 72.0, dy / 72.0, ax.figure.dpi_scale_trans)
            ha = "left" if dx > 3 else "right" if dx < -3 else "center"
            va = "bottom" if dy > 3 else "top" if dy < -3 else "center"
            self.node_texts[n] = ax.text(*self._pos(coords[n]), f"{n}", fontsize=8, color="0.2", zorder=7,
                                         ha=ha, va=va, transform=offset)

    def _free_direction(self, n, coords):
        """The unit bisector of the widest angle between the directions from node n to the
        position nodes it shares an element with (and, at a support, the support below it)."""
        x = self._pos(coords[n])
        angles = []
        for el in self.geometry.elements:
            if n in el.nodes:
                for m in el.nodes:
                    if m != n and m in coords and self.geometry.node_kinds.get(m) in ("XY", "XYZ"):
                        d = self._pos(coords[m]) - x
                        if np.hypot(*d) > 0:
                            angles.append(np.arctan2(d[1], d[0]))
        if self.geometry.supported(n):
            angles.append(-np.pi / 2)   # the ground triangle, the slider block and the clamp's hatching
        if not angles:
            return np.array([1.0, 1.0]) / np.sqrt(2.0)
        a = np.sort(np.mod(angles, 2 * np.pi))
        gaps = np.diff(np.concatenate([a, [a[0] + 2 * np.pi]]))
        i = int(np.argmax(gaps))
        mid = a[i] + gaps[i] / 2
        return np.array([np.cos(mid), np.sin(mid)])

    # --- geometry of frames ------------------------------------------------------------------

    def _coords(self, k):
        coords = frame_coordinates(self.node_columns, self.res.x[k])
        return coords if self.magnify == 1.0 else magnified(self.geometry, coords, self.magnify)

    def _shapes(self, k):
        return shapes(self.geometry, self._coords(k), self.scale, self.beam_points)

    def _pos(self, c):
        p = np.zeros(self.dim)
        c = np.asarray(c)[: self.dim]
        p[: len(c)] = c
        return p

    def _frames_sample(self, limit=200):
        nt = len(self.res.t)
        return np.unique(np.linspace(0, nt - 1, min(nt, limit)).astype(int))

    def _positions(self):
        """Positions of all position nodes at the sampled frames: (frames, nodes, dim)."""
        cols = [self.node_columns[n] for n in self.geometry.position_nodes if n in self.node_columns]
        if not cols:
            return np.zeros((1, 1, self.dim))
        frames = self._frames_sample()
        out = np.zeros((len(frames), len(cols), self.dim))
        for j, c in enumerate(cols):
            v = self.res.x[np.ix_(frames, c)][:, : self.dim]
            out[:, j, : v.shape[1]] = v
        return out

    def _scale(self):
        p = self._positions().reshape(-1, self.dim)
        span = float((p.max(axis=0) - p.min(axis=0)).max()) if len(p) else 0.0
        return span if span > 0 else 1.0

    def _limits(self):
        pts = []
        for k in self._frames_sample(100):
            pts.extend(sh.points for sh in self._shapes(k))
        pts = np.vstack(pts) if pts else np.zeros((1, self.dim))
        lo, hi = np.nanmin(pts, axis=0), np.nanmax(pts, axis=0)
        centre, half = (lo + hi) / 2, (hi - lo) / 2
        pad = 0.08 * max(float(half.max()), 1e-9) + 0.02 * self.scale
        half = half + pad
        ax = self.ax
        if self.spatial:
            r = float(half.max())
            ax.set_xlim(centre[0] - r, centre[0] + r)
            ax.set_ylim(centre[1] - r, centre[1] + r)
            ax.set_zlim(centre[2] - r, centre[2] + r)
            ax.set_box_aspect((1, 1, 1))
            # Four ticks a side in a small font: the default's crowd into each other in 3-D.
            from matplotlib.ticker import MaxNLocator

            for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
                axis.set_major_locator(MaxNLocator(nbins=4))
            ax.tick_params(labelsize=7, pad=0)
            ax.set_xlabel("x")
            ax.set_ylabel("y")
            ax.set_zlabel("z")
        else:
            ax.set_xlim(centre[0] - half[0], centre[0] + half[0])
            ax.set_ylim(centre[1] - half[1], centre[1] + half[1])
            ax.set_aspect("equal", adjustable="box")
            ax.set_xlabel("x")
            ax.set_ylabel("y")
            ax.grid(True, alpha=0.25)

    def _static_decorations(self, trace):
        """Slider guides along the free direction of partly fixed position nodes, and node paths."""
        res, ax = self.res, self.ax
        for n in self.geometry.position_nodes:
            cls = self.geometry.classes(n)
            if n not in self.node_columns or "fixed" not in cls or all(c == "fixed" for c in cls):
                continue
            p = res.x[:, self.node_columns[n]][:, : self.dim]
            lo, hi = p.min(axis=0), p.max(axis=0)
            ext = 0.1 * self.scale
            pts = np.array([lo - ext * (hi > lo), hi + ext * (hi > lo)])
            for i, c in enumerate(cls[: self.dim]):
                if c == "fixed":
                    pts[:, i] = p[0, i]
            ax.plot(*pts.T, color="0.5", lw=1.0, ls=(0, (4, 3)), zorder=1)
        for n in trace or ():
            if n not in self.node_columns:
                raise InputError(f"trace: there is no node {n} in the results")
            p = res.x[:, self.node_columns[n]][:, : self.dim]
            ax.plot(*p.T, color="C3", lw=1.0, alpha=0.6, zorder=2)

    # --- update ----------------------------------------------------------------------------

    def update(self, k: int):
        """Move every artist to output index k; returns the artists."""
        for line, sh in zip(self.lines, self._shapes(k)):
            if sh.kind == "body":
                if self.spatial:
                    line.set_verts([sh.points])
                else:
                    line.set_xy(sh.points)
            elif self.spatial:
                line.set_data_3d(*sh.points.T)
            else:
                line.set_data(*sh.points.T)
        if self.node_texts:
            coords = self._coords(k)
            for n, text in self.node_texts.items():
                p = self._pos(coords[n])
                if self.spatial:
                    text.set_position(p[:2])
                    text.set_3d_properties(p[2], None)
                else:
                    text.set_position(p)
        if self.title is not None:
            self.title.set_text(self.caption(k))
        return self.lines

    def element_lines(self, element: int) -> list:
        """The artists of one element (for inspection and styling)."""
        return [ln for ln in self.lines if ln.get_gid() == f"element-{element}"]


def mode_phases(frames) -> np.ndarray:
    """The amplitudes of an animated mode, cos(2π j / frames) for j = 0 .. frames − 1: the first
    frame (the still picture) at the peak. ``frames``: a whole number from 2 to 1000."""
    if isinstance(frames, bool) or not isinstance(frames, (int, np.integer)) or not 2 <= frames <= 1000:
        raise InputError(f"frames must be a whole number from 2 to 1000, got {show(frames)}")
    return np.cos(2 * np.pi * np.arange(int(frames)) / int(frames))


def _displaced(res: Results, k: int, mode, scale, amplitudes=(1.0,)) -> Results:
    """Results at row k displaced by ``scale`` times the nodal shape ``mode`` (nx), one row per
    amplitude (default one row, amplitude 1); by default scaled so that the largest displacement
    of a position is a tenth of the model's extent. Euler parameters are normalised again."""
    try:
        dx = np.real(np.asarray(mode)).astype(float).reshape(-1)
    except (TypeError, ValueError):
        dx = np.full(1, np.nan)
    if scale is not None and (isinstance(scale, bool) or not isinstance(scale, (int, float, np.number))
                              or not np.isfinite(scale)):
        raise InputError(f"scale must be a finite number (or None: a tenth of the model's size), got {show(scale)}")
    if dx.shape != res.x[k].shape or not np.isfinite(dx).all():
        raise InputError(f"mode must hold {res.x.shape[1]} finite numbers (one per nodal coordinate, as "
                         f"Linearization.buckling_modes()[2][:, i]), got shape {np.shape(mode)}")
    kinds = res.geometry.node_kinds
    cols = res.node_columns
    positions = [c for n, c in cols.items() if kinds.get(n) in ("XY", "XYZ")]
    rows = np.concatenate(positions) if positions else np.arange(len(dx))
    if scale is None:
        xy = np.vstack([res.x[k][c] for c in positions]) if positions else np.zeros((1, 1))
        extent = max(np.ptp(xy, axis=0).max(), 1e-300)
        largest = np.abs(dx[rows]).max() if rows.size else 0.0
        scale = 0.1 * extent / largest if largest > 0 else 1.0
    x = res.x[k] + float(scale) * np.asarray(amplitudes, dtype=float)[:, None] * dx
    for n, c in cols.items():
        if kinds.get(n) == "LAMBDA":
            x[:, c] /= np.linalg.norm(x[:, c], axis=1, keepdims=True)
    many = lambda a: np.repeat(np.asarray(a)[k:k + 1], len(x), axis=0)  # noqa: E731
    arrays = {name: many(getattr(res, name)) for name in _ARRAYS}
    arrays["x"] = x
    return Results(arrays, res.coordinate_labels, res.deformation_labels, res.stats, geometry=res.geometry)


def snapshot(sim, geometry) -> Results:
    """One-row :class:`Results` of the current state of a ``_core.Simulation`` (for drawing a
    state that no run recorded: a linearization's, or one the explorer solved)."""
    d, system = sim.data, sim.system
    arrays = {name: np.array(getattr(d, name), dtype=float)[None, ...]
              for name in STATE_ARRAYS}
    arrays["t"] = np.array([float(d.t)])
    return Results(arrays, system.coord_label, system.def_label, {}, geometry=geometry)


def draw(res: Results, k: int = -1, *, time: float | None = None, ax=None, labels: bool = False,
         trace=(), beam_points: int = 21, figsize=None, mode=None, scale: float | None = None,
         magnify: float = 1.0, stress=None, stress_kind: str = "normal", cmap: str = "plasma"):
    """Draw the mechanism at output index ``k`` (default the last) or at the output time nearest
    to ``time``. ``labels`` writes the node numbers; ``trace`` lists position nodes whose paths
    over the whole run are drawn (e.g. a coupler curve). ``mode``: a shape in the nodal
    coordinates (e.g. a buckling mode, ``Linearization.buckling_modes()[2][:, 0]``, or a
    vibration mode) added to that state, times ``scale`` (default: its largest displacement a
    tenth of the model's size); beams are drawn through the displaced nodes with the cubic
    (Hermite) shape of their displaced end slopes. ``magnify`` multiplies the deflections of the
    flexible beams, relative to their rigid-body motion (:func:`spacar.geometry.magnified`),
    e.g. ``magnify=50`` to see a stiff leaf spring bend. ``stress``: the
    :func:`spacar.section.stresses` of these results; each of its elements is drawn in the colour
    of its largest stress at that output (``stress_kind`` "normal", "shear" or "von_mises"; the
    colour map ``cmap``, a colour bar beside), and the most stressed element is marked with its
    value. Returns the :class:`Scene` (its ``ax`` is the axes)."""
    require_results(res, "draw")
    if time is not None:
        k = res.time_index(time)
    k = range(len(res.t))[k]
    values = None
    if stress is not None:
        values = _stress_values(res, stress, k, stress_kind)
    if mode is not None:
        if res.geometry is None:
            raise InputError("these results have no geometry to draw (results of spacar.simulate have)")
        res, k = _displaced(res, k, mode, scale), 0
    scene = Scene(res, ax, k, labels=labels, trace=trace, beam_points=beam_points, figsize=figsize,
                  magnify=magnify)
    if values:
        _colour_by_stress(scene, values, stress_kind, cmap)
    return scene


def _stress_values(res, stress, k: int, kind: str) -> dict:
    """{element: stress} of ``stress`` (section.Stresses of ``res``) at output k."""
    from .section import Stresses

    if not isinstance(stress, Stresses):
        raise InputError(f"stress must be the spacar.section.stresses of these results, got {type(stress).__name__}")
    if len(stress.t) != len(res.t) or not np.array_equal(np.asarray(stress.t), np.asarray(res.t)):
        raise InputError("stress holds the stresses of other results (their output times differ)")
    return stress.at(k, kind)


def _colour_by_stress(scene, values: dict, kind: str, cmap: str):
    """The elements of ``values`` in the colour of their stress, a colour bar, the peak marked."""
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    try:
        colours = colormaps[cmap]
    except KeyError:
        raise InputError(f"cmap must be a matplotlib colour map name, got {cmap!r}") from None
    peak_element = max(values, key=values.get)
    norm = Normalize(0.0, values[peak_element] or 1.0)
    peak_line = None
    for line in scene.lines:
        gid = line.get_gid() or ""
        if gid.startswith("element-") and int(gid[8:]) in values:
            e = int(gid[8:])
            line.set_color(colours(norm(values[e])))
            line.set_zorder(4)
            if e == peak_element:
                peak_line = line
    ax = scene.ax
    label = {"normal": "largest normal stress", "shear": "largest shear stress",
             "von_mises": "equivalent stress √(σ² + 3τ²)"}[kind]
    scene.colorbar = ax.figure.colorbar(ScalarMappable(norm=norm, cmap=colours), ax=ax, shrink=0.8, label=label)
    if peak_line is not None:
        points = np.column_stack(peak_line.get_data_3d() if scene.spatial else peak_line.get_data())
        middle = points[len(points) // 2]
        ax.plot(*middle, marker="*", ms=12, color="red", zorder=8, linestyle="none")
        ax.text(*middle, f"  {values[peak_element]:.3g} (element {peak_element})", color="red", fontsize=8, zorder=8)
    scene.stress_peak = (peak_element, values[peak_element])

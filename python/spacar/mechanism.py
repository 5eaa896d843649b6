"""Mechanism analysis in the vocabulary of a mechanisms course: the Grashof classification, limit
(toggle) and dead positions and the transmission angle of four-bars, Freudenstein's three-point
synthesis, and, for any single-input mechanism in a model, its limit positions along the input
and the instant centres of its bodies (docs/mechanisms.md).

    fb = spacar.mechanism.FourBar(a=0.1, b=0.35, c=0.3, d=0.4)   # crank, coupler, rocker, ground
    fb.grashof()                       # Grashof(kind='crank-rocker', ...)
    fb.limit_positions()               # crank angles where the rocker reverses
    model = fb.model()                 # the spacar model, crank driven at 1 rad/s
    spacar.mechanism.limit_positions(model, output=(9, 1))   # found along the input, refined
    spacar.mechanism.dead_positions(model)                   # where the input can drive it no further
    spacar.mechanism.instant_centres(model, [1, 2, 3])       # Aronhold–Kennedy, from the velocities

The four-bar's ground pivots are A = (0, 0) and D = (d, 0); the crank AB turns by θ from the x
axis, the rocker DC by ψ; Freudenstein's equation K1 cos ψ − K2 cos θ + K3 = cos(θ − ψ) with
K1 = d/a, K2 = d/c, K3 = (a² − b² + c² + d²)/(2ac) ties them. The general helpers work on any
model from its kinematic analysis (:func:`spacar.transfer`), no masses needed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._util import show
from .errors import InputError
from .model import Model
from .section import PLANAR_BEAMS

__all__ = ["Grashof", "FourBar", "synthesize", "limit_positions", "dead_positions", "instant_centres",
           "transmission_angle"]


def _length(value, name) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        v = math.nan
    if not (math.isfinite(v) and v > 0):
        raise InputError(f"{name} must be a positive length, got {show(value)}")
    return v


@dataclass(frozen=True)
class Grashof:
    """The Grashof classification of a four-bar: ``kind`` is "crank-rocker" (the crank, the
    shortest link next to the ground, turns fully), "double-crank" (the ground is the shortest:
    a drag link), "double-rocker" (the coupler is the shortest), "change point" (s + l = p + q:
    the links can fold into a line) or "triple-rocker" (s + l > p + q: no link turns fully);
    ``grashof``: s + l ≤ p + q; ``s``, ``l``, ``p``, ``q``: the shortest, longest and other two
    lengths."""

    kind: str
    grashof: bool
    s: float
    l: float
    p: float
    q: float


class FourBar:
    """A planar four-bar: crank ``a`` (A–B), coupler ``b`` (B–C), rocker ``c`` (D–C), ground ``d``
    (A–D along x). ``branch`` +1: C on the left of the diagonal B→D (the open assembly for
    θ = 0 when C is above the ground line), −1 the other (crossed) assembly."""

    def __init__(self, a, b, c, d, branch: int = 1):
        self.a, self.b, self.c, self.d = (_length(v, n) for v, n in ((a, "a"), (b, "b"), (c, "c"), (d, "d")))
        if branch not in (1, -1):
            raise InputError(f"branch must be 1 or -1, got {show(branch)}")
        self.branch = branch

    def __repr__(self):
        return f"FourBar(a={self.a:g}, b={self.b:g}, c={self.c:g}, d={self.d:g}, branch={self.branch})"

    def grashof(self) -> Grashof:
        """The Grashof classification (:class:`Grashof`)."""
        links = sorted([(self.a, "crank"), (self.b, "coupler"), (self.c, "rocker"), (self.d, "ground")])
        s, p, q, l = (v for v, _ in links)
        shortest = links[0][1]
        excess = (s + l) - (p + q)
        tol = 1e-12 * l
        if abs(excess) <= tol:
            kind = "change point"
        elif excess > 0:
            kind = "triple-rocker"
        elif shortest == "ground":
            kind = "double-crank"
        elif shortest == "coupler":
            kind = "double-rocker"
        else:
            kind = "crank-rocker"  # the shortest is the crank (or the rocker, which then is the crank)
        return Grashof(kind, excess <= tol, s, l, p, q)

    # --- the closed forms ------------------------------------------------------------------------

    def points(self, theta):
        """(B, C) for the crank angle θ (arrays of shape (2,) or (n, 2)); NaN where the loop cannot
        close."""
        theta = np.asarray(theta, dtype=float)
        B = np.stack([self.a * np.cos(theta), self.a * np.sin(theta)], axis=-1)
        u = np.array([self.d, 0.0]) - B
        f = np.linalg.norm(u, axis=-1)
        along = (self.b**2 - self.c**2 + f**2) / (2 * f)
        with np.errstate(invalid="ignore"):
            across = np.sqrt(self.b**2 - along**2)
        normal = np.stack([-u[..., 1], u[..., 0]], axis=-1) / f[..., None]
        C = B + (along / f)[..., None] * u + (self.branch * across)[..., None] * normal
        return B, C

    def rocker_angle(self, theta):
        """ψ, the rocker's angle at D from the x axis, for the crank angle θ."""
        _, C = self.points(theta)
        return np.arctan2(C[..., 1], C[..., 0] - self.d)

    def coupler_angle(self, theta):
        B, C = self.points(theta)
        return np.arctan2(C[..., 1] - B[..., 1], C[..., 0] - B[..., 0])

    def transmission_angle(self, theta):
        """μ, the angle between the coupler and the rocker at C (0 … π; best near π/2), from
        cos μ = (b² + c² − BD²)/(2bc), BD² = a² + d² − 2ad cos θ."""
        bd2 = self.a**2 + self.d**2 - 2 * self.a * self.d * np.cos(np.asarray(theta, dtype=float))
        with np.errstate(invalid="ignore"):
            return np.arccos((self.b**2 + self.c**2 - bd2) / (2 * self.b * self.c))

    def limit_positions(self) -> list:
        """The crank angles θ (in [−π, π)) at which the rocker reverses, the crank and the
        coupler in line (extended, AC = a + b, and folded, AC = |b − a|), with the rocker angles ψ
        there: [(θ, ψ), ...]; empty where the triangle ACD cannot close. With the rocker driving,
        these are the dead-centre positions: it cannot turn the crank on."""
        out = []
        for length, extended in ((self.b + self.a, True), (abs(self.b - self.a), False)):
            if length <= 0:
                continue
            cos_at_a = (self.d**2 + length**2 - self.c**2) / (2 * self.d * length)
            if abs(cos_at_a) > 1:
                continue
            for phi in (math.acos(cos_at_a), -math.acos(cos_at_a)):  # the direction of AC
                # The crank points along AC, except folded with the coupler the longer (B behind A).
                theta = phi if extended or self.a > self.b else phi + math.pi
                theta = (theta + math.pi) % (2 * math.pi) - math.pi
                C = length * np.array([math.cos(phi), math.sin(phi)])
                if np.abs(self.points(theta)[1] - C).max() <= 1e-9 * max(self.d, length):  # on this assembly
                    out.append((theta, float(self.rocker_angle(theta))))
        return out

    def toggle_positions(self) -> list:
        """The crank angles θ at which the coupler and the rocker are in line (transmission angle
        0 or π): the crank, driving, cannot move the rocker on, and its range of motion ends
        there (a linkage whose crank does not turn fully). [θ, ...], both signs."""
        out = []
        for bd in (self.b + self.c, abs(self.b - self.c)):
            cos_theta = (self.a**2 + self.d**2 - bd**2) / (2 * self.a * self.d)
            if abs(cos_theta) <= 1:
                out.extend([math.acos(cos_theta), -math.acos(cos_theta)])
        return out

    def freudenstein(self, theta, psi):
        """F(θ, ψ) = K1 cos ψ − K2 cos θ + K3 − cos(θ − ψ), zero on the mechanism's positions."""
        K1, K2, K3 = self.d / self.a, self.d / self.c, (self.a**2 - self.b**2 + self.c**2 + self.d**2) / (2 * self.a * self.c)
        return K1 * np.cos(psi) - K2 * np.cos(theta) + K3 - np.cos(np.asarray(theta) - psi)

    def model(self, theta0: float = 0.0, rate: float = 1.0, steps: int = 360, coupler_point=None) -> Model:
        """The spacar model: PLBEAM 1 the crank (nodes 1 A, 3 B; its BETA node 2 the input, turning
        at ``rate`` from θ0), PLBEAM 2 the coupler (3 → 6 C), PLBEAM 3 the rocker (8 D → 6, BETA node 9
        at D: ψ − ψ0); ``coupler_point`` (u, v) in the coupler's frame (along B→C, across) adds node
        11 rigidly on the coupler (PLBEAM 4). One crank revolution in ``steps`` output times."""
        B, C = self.points(theta0)
        if not np.isfinite(C).all():
            raise InputError(f"{self}: the loop cannot close at θ0 = {theta0:g}")
        m = Model()
        m.plbeam(1, 1, 2, 3, 4)
        m.plbeam(2, 3, 5, 6, 7)
        m.plbeam(3, 8, 9, 6, 10)
        m.x(3, *B)
        m.x(6, *C)
        m.x(8, self.d, 0.0)
        if coupler_point is not None:
            u, v = (float(w) for w in coupler_point)
            along = (C - B) / self.b
            m.plbeam(4, 3, 5, 11, 12)
            m.x(11, *(B + u * along + v * np.array([-along[1], along[0]])))
        m.fix(1)
        m.fix(8)
        m.apply("INPUTX", 2, 1)
        m.xd(2, 1, float(rate))
        m.epskin(1e-12)
        m.timestep(int(steps), 2 * math.pi / abs(rate) if rate else 1.0)
        return m


def synthesize(pairs, d: float = 1.0) -> FourBar:
    """Function generation by Freudenstein's three-point method: the four-bar with ground ``d``
    whose crank and rocker angles pass the three precision points ``pairs`` = [(θ1, ψ1), (θ2, ψ2),
    (θ3, ψ3)] (rad), from K1 cos ψ_i − K2 cos θ_i + K3 = cos(θ_i − ψ_i), i = 1, 2, 3:
    a = d/K1, c = d/K2, b² = a² + c² + d² − 2 a c K3, assembled on the branch that takes the first
    point. InputError if the points give no real linkage (a negative length, or a singular
    system)."""
    try:
        pts = np.array(pairs, dtype=float)
    except (TypeError, ValueError, OverflowError):
        pts = np.zeros((0,))
    if pts.shape != (3, 2) or not np.isfinite(pts).all():
        raise InputError(f"synthesize: three (θ, ψ) pairs of finite angles, got {show(pairs)}")
    d = _length(d, "d")
    theta, psi = pts[:, 0], pts[:, 1]
    A = np.stack([np.cos(psi), -np.cos(theta), np.ones(3)], axis=1)
    if abs(np.linalg.det(A)) < 1e-12:
        raise InputError("synthesize: the three precision points do not determine a four-bar (singular system)")
    K1, K2, K3 = np.linalg.solve(A, np.cos(theta - psi))
    a, c = d / K1, d / K2
    b2 = a**2 + c**2 + d**2 - 2 * a * c * K3
    if not (a > 0 and c > 0 and b2 > 0):
        raise InputError(f"synthesize: these precision points give no real four-bar (a = {a:.4g}, c = {c:.4g}, "
                         f"b² = {b2:.4g})")
    # The assembly (branch) on which the rocker takes the precision points' angles: Freudenstein's
    # equation holds on both, and the points may fall on different ones (a branch defect).
    for branch in (1, -1):
        fb = FourBar(a, math.sqrt(b2), c, d, branch)
        miss = [abs(math.remainder(float(fb.rocker_angle(t)) - p, 2 * math.pi)) for t, p in zip(theta, psi)]
        if max(miss) <= 1e-8:
            return fb
    raise InputError("synthesize: the three precision points lie on different assemblies of the synthesized four-bar "
                     "(a branch defect): no one linkage passes all three; choose other points")


# --- any single-input mechanism in a model ---------------------------------------------------------

def _single_input(labels, is_input) -> tuple:
    """The label of the one input of q̂ (``labels``, ``is_input``), if it has nothing else."""
    inputs = [label for label, flag in zip(labels, is_input) if flag]
    if len(inputs) != 1 or len(labels) != 1:
        raise InputError(f"a single-input mechanism (one input, no degrees of freedom) is needed; q̂ is {labels}")
    return inputs[0]


def limit_positions(model, output, steps: int = 360, *, t_end=None, tol: float = 1e-10) -> list:
    """The limit positions of a single-input mechanism along its input's motion (the current
    block, or to ``t_end``): where the output (node, component) or ("e", element, deformation)
    reverses, its velocity ratio changing sign between the ``steps`` samples of
    :func:`spacar.transfer_path`, each refined by the bisection of the velocity ratio to ``tol``
    in the input. Returns [(t, input value, output value), ...]."""
    from scipy.optimize import brentq

    from .transfer import transfer, transfer_path

    path = transfer_path(model, steps, t_end=t_end)
    first = path.at(0)
    wrt = _single_input(first.q_labels, first.is_input)
    ratio = path.ratio(output, wrt)
    q0 = np.zeros(0)
    found = []
    column = first.column(wrt)
    rate = (path.q[-1, column] - path.q[0, column]) / (path.t[-1] - path.t[0]) if len(path.t) > 1 else 1.0
    for k in np.nonzero(np.sign(ratio[:-1]) * np.sign(ratio[1:]) < 0)[0]:
        t = brentq(lambda s: transfer(model, at=(s, q0)).ratio(output, wrt), path.t[k], path.t[k + 1],
                   xtol=tol / max(abs(rate), 1e-300), rtol=4 * np.finfo(float).eps)
        tf = transfer(model, at=(t, q0))
        first, _, row = tf._row(output)
        found.append((float(t), float(tf.q[column]), float((tf.x if first is tf.DF else tf.e)[row])))
    return found


def dead_positions(model, steps: int = 360, *, t_end=None, tol: float = 1e-10) -> list:
    """The dead position of a single-input mechanism along its input's motion (the current block,
    or to ``t_end``): where the input can drive it no further, the Jacobian of the constraints
    singular (a toggle: the crank of a non-Grashof four-bar at the end of its range, a
    slider-crank driven by its slider at a dead centre). Returns [(t, input value)], the first one
    on the way (the motion cannot pass it), or [] where the input drives the mechanism through
    the whole motion.

    Found in two stages. The kinematic analysis is stepped along the input's motion in ``steps``
    samples until it fails; the failing step is retried in eighths, four times over, so that a
    step merely too long for Newton is not taken for a dead position (``steps`` must still be
    fine enough not to jump across the region the input cannot reach). From the last
    configuration it solves, the coordinate whose velocity ratio to the input grows fastest there
    (it moves ever faster as the Jacobian turns singular; not an Euler parameter) drives a copy
    of the model instead, and the input reverses along that motion: the dead position is that
    limit position of the input (:func:`limit_positions`), refined to ``tol`` in the driving
    coordinate; near it the input is stationary, so its value is far more accurate than
    ``tol``. The input must be a coordinate (INPUTX), moving forward in time (``t_end`` after the
    model's current time)."""
    from .errors import KinematicsError
    from .simulate import simulate
    from .transfer import _labels, _q_labels, _simulation, _transfer_here

    sim = _simulation(model, "dead_positions")
    system = sim.system
    labels, is_input = _q_labels(system)
    coordinate_labels, deformation_labels = _labels(system)
    t0 = model.current_time
    t_end = t0 + model.settings.timestep_tp if t_end is None else float(t_end)
    if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 3:
        raise InputError(f"dead_positions: steps must be a whole number of at least 3, got {show(steps)}")
    if not (np.isfinite(t_end) and t_end > t0):
        raise InputError(f"dead_positions: t_end must be after the model's current time {t0:g}, got {show(t_end)}")
    wrt = _single_input(labels, is_input)
    if wrt[0] != "x":
        raise InputError(f"dead_positions: the input must be a coordinate (INPUTX), not the deformation {wrt[1:]}")
    node, comp = wrt[1], wrt[2]

    def walk(times):
        """The samples solved along ``times`` from the start, and the first time that fails."""
        walker, q0, solved = _simulation(model, "dead_positions"), np.zeros(0), []
        for t in times:
            try:
                solved.append((float(t), _transfer_here(walker, t, q0, labels, is_input, coordinate_labels,
                                                        deformation_labels)))
            except KinematicsError:
                return solved, float(t)
        return solved, None

    times = list(np.linspace(t0, t_end, int(steps) + 1))
    good, failed = walk(times)
    for _ in range(4):                          # the failing step again, in eighths
        if failed is None or not good:
            break
        times = [t for t, _ in good] + list(np.linspace(good[-1][0], failed, 9)[1:])
        good, failed = walk(times)
    if failed is None:
        return []
    if len(good) < 3:
        raise InputError("dead_positions: the analysis fails within two steps of the start; start the "
                         "mechanism farther from its dead position or give more steps")
    (_, before), (t_k, tf) = good[-2], good[-1]
    column = tf.column(wrt)
    inp = tf.coordinate_labels.index((node, comp))
    # The driver: among the coordinates whose ratio to the input grows (those of the motion the
    # singular Jacobian lets through; a coordinate turning with the input keeps its ratio), the
    # fastest, positions measured in the mechanism's size against rotations; neither the input
    # nor an Euler parameter.
    kinds = {n: data.kind.name for n, data in model.nodes.items()}
    positions = np.array([tf.x[k] for k, (n, _) in enumerate(tf.coordinate_labels) if kinds[n] in ("XY", "XYZ")])
    size = float(np.ptp(positions)) if positions.size else 1.0
    now, then = np.abs(tf.DF[:, column]), np.abs(before.DF[:, column])
    growth = np.where(now > 0.0, now / np.maximum(then, 1e-300), 0.0)
    for k, (n, _) in enumerate(tf.coordinate_labels):
        if k == inp or kinds[n] == "LAMBDA":
            growth[k] = 0.0
    weight = np.array([1.0 / (size or 1.0) if kinds[n] in ("XY", "XYZ") else 1.0 for n, _ in tf.coordinate_labels])
    speed = np.where(growth >= 0.5 * growth.max(), now * weight, 0.0)
    driver = tf.coordinate_labels[int(np.argmax(speed))]
    ratio = float(tf.DF[tf.coordinate_labels.index(driver), column])
    # The model at the last solved configuration, reached in blocks of the walk's step lengths
    # (finer if its run lands elsewhere: long steps may take another branch).
    from .transfer import transfer

    spacing = np.diff([t for t, _ in good])
    for finer in (1, 8, 64):
        at_k = model.copy()
        at_k.matasc(0)
        start = 0
        while start < len(spacing):
            end = start + 1
            while end < len(spacing) and abs(spacing[end] - spacing[start]) <= 1e-9 * spacing[start]:
                end += 1
            at_k.timestep(finer * (end - start), float(good[end][0] - good[start][0]))
            simulate(at_k, progress=False)
            start = end
        # The same branch (another one differs by the mechanism's size; near the dead position the
        # configuration is ill-conditioned, so Newton's tolerance shows magnified).
        if np.abs(transfer(at_k).x - tf.x).max() <= 1e-3 * max(1.0, np.abs(tf.x).max()):
            break
    else:
        raise KinematicsError(f"dead_positions: the run to t = {t_k:.9g} does not reach the configuration "
                              "the stepped analysis found there; give more steps")
    # The copy driven by that coordinate at unit rate, steadily (no acceleration left from the run).
    driven = at_k.copy()
    driven.calculable(node, comp)
    driven.inputx(*driver)
    driven.xd(*driver, 1.0 if ratio * (tf.q[column] - before.q[column]) > 0 else -1.0)
    driven.xdd(*driver, 0.0)
    # The input's remaining travel is at most one step; near the dead position the input moves as
    # the square of the driver's distance from it, so the driver has about 2 × travel × ratio to
    # go. The span searched is bracketed: too short finds no reversal, too long fails.
    travel = abs(tf.q[column] - before.q[column])
    span, short, long_ = 4.0 * travel * abs(ratio), 0.0, None
    for _ in range(12):
        driven.timestep(24, span)
        try:
            found = limit_positions(driven, (node, comp), steps=24, t_end=driven.current_time + span, tol=tol)
        except (KinematicsError, ValueError):   # past another singularity (brentq: no sign change)
            found = None
        if found:
            value = found[0][2]
            break
        if found is None:
            long_ = span
        else:
            short = span
        span = 2.0 * span if long_ is None else 0.5 * (short + long_)
    else:
        raise KinematicsError(f"dead_positions: the analysis stops after t = {t_k:.9g}, but no dead position "
                              f"was found driving the mechanism by coordinate {driver}")
    # The time at which the input's motion (constant acceleration at most) reaches the value.
    ts = np.array([t for t, _ in good[-3:]])
    qs = np.array([g.q[column] for _, g in good[-3:]])
    a, b, c = np.polyfit(ts - t_k, qs, 2)
    roots = np.roots([a, b, c - value]) if abs(a) > 1e-14 * max(abs(b), 1e-300) else np.array([(value - c) / b])
    roots = roots[np.isreal(roots)].real
    if roots.size == 0:
        raise KinematicsError(f"dead_positions: the input's motion does not reach its dead value {value:.9g}")
    t_dead = t_k + float(roots[np.argmin(np.abs(roots))])
    return [(t_dead, float(value))]


def instant_centres(model, bodies, at=None) -> dict:
    """The instant centres (Aronhold–Kennedy) of pairs of the planar ``bodies`` (element numbers
    of rigid PLBEAMs, 0 for the ground) of a single-input or single-DOF mechanism at its current
    configuration (``at``: as for :func:`spacar.transfer`): {(i, j): (x, y)} for i < j, the point
    where the two bodies have the same velocity; (inf, inf) for a pair that translates relative to
    each other. From the velocities of a unit input rate, ẋ = DF."""
    from .transfer import transfer

    tf = transfer(model, at=at)
    if len(tf.q_labels) != 1:
        raise InputError(f"instant_centres: a mechanism with one input or degree of freedom; q̂ is {tf.q_labels}")
    rows = {label: i for i, label in enumerate(tf.coordinate_labels)}
    elements = model.elements
    motion = {0: (np.zeros(2), np.zeros(2), 0.0)}  # body: (a point, its velocity, ω)
    for e in bodies:
        if e == 0:
            continue
        if e not in elements or elements[e].type_name not in PLANAR_BEAMS:
            raise InputError(f"instant_centres: body {show(e)} must be 0 (the ground) or a PLBEAM of the model")
        p, o = elements[e].nodes[0], elements[e].nodes[1]
        point = np.array([tf.x[rows[(p, 1)]], tf.x[rows[(p, 2)]]])
        velocity = np.array([tf.DF[rows[(p, 1)], 0], tf.DF[rows[(p, 2)], 0]])
        motion[e] = (point, velocity, float(tf.DF[rows[(o, 1)], 0]))
    J = np.array([[0.0, -1.0], [1.0, 0.0]])  # k ×
    out = {}
    ids = sorted(set(bodies))
    for n, i in enumerate(ids):
        for j in ids[n + 1:]:
            (pi, vi, wi), (pj, vj, wj) = motion[i], motion[j]
            scale = max(abs(wi), abs(wj), 1e-300)
            if abs(wi - wj) <= 1e-12 * scale:
                out[(i, j)] = (math.inf, math.inf)
                continue
            rhs = vj - wj * (J @ pj) - vi + wi * (J @ pi)
            P = -J @ rhs / (wi - wj)
            out[(i, j)] = (float(P[0]), float(P[1]))
    return out


def transmission_angle(path_or_transfer, coupler: int, follower: int, model=None):
    """The angle μ (0 … π) between two elements (the coupler and the follower of a four-bar or a
    slider-crank's rod and guide direction), from their end nodes' positions in a
    :class:`spacar.Transfer` or along a :class:`spacar.TransferPath`; ``model`` gives the
    elements' nodes (a Transfer does not keep them)."""
    if model is None:
        raise InputError("transmission_angle: pass model= (the elements' nodes)")
    rows = {label: i for i, label in enumerate(path_or_transfer.coordinate_labels)}
    x = np.atleast_2d(path_or_transfer.x)

    def direction(e):
        if e not in model.elements:
            raise InputError(f"transmission_angle: element {show(e)} is not defined")
        points = [n for n in model.elements[e].nodes if (n, 1) in rows and (n, 2) in rows
                  and model.nodes[n].kind.name in ("XY", "XYZ")]
        if len(points) < 2:
            raise InputError(f"transmission_angle: element {e} has no two position nodes to give it a direction")
        p1, p2 = points[0], points[-1]
        return np.stack([x[:, rows[(p2, 1)]] - x[:, rows[(p1, 1)]], x[:, rows[(p2, 2)]] - x[:, rows[(p1, 2)]]], axis=1)

    u, v = direction(coupler), direction(follower)
    cos = np.einsum("ij,ij->i", u, v) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
    mu = np.arccos(np.clip(cos, -1.0, 1.0))
    return mu if np.ndim(path_or_transfer.x) > 1 else float(mu[0])

"""Generate the reference parts of the documentation:

* ``docs/keywords.md`` — every input keyword (spacar.docgen.keyword_reference),
* ``docs/elements.md`` — the element catalogue (spacar.docgen.element_catalogue_markdown),
* ``docs/figures/elements/<type>.svg`` — a small drawing of every element type with its nodes
  and deformations (matplotlib): its own (FIGURES_BY_TYPE) or, until it has one, the default
  figure (its node slots and deformation names),
* ``docs/img/modelling_<joint>.png`` — the figures of docs/modelling.md: example models run by
  spacar and drawn by ``spacar.draw``, with a note on how each joint is modelled.

Usage: ``python docs/generate.py`` (write), ``python docs/generate.py --check`` (exit 1 if a
generated text file differs from the committed one). The SVG files are written reproducibly
(fixed hash salt, no date), so regenerating them changes nothing unless the drawing changes.
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

import spacar
from spacar.docgen import GENERATED
from spacar.geometry import hermite, rotation

DOCS = Path(__file__).resolve().parent
FIGURES = DOCS / "figures" / "elements"
EXAMPLES = DOCS.parent / "examples"


# --------------------------------------------------------------------------------------------
# Figures
# --------------------------------------------------------------------------------------------

FIG_HEIGHT = 3.6  # inches; the text panel lists up to 6 deformations with their formulas


def _figure(dim3=False):
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(7.6, FIG_HEIGHT))
    ax_draw = fig.add_axes([0.0, 0.02, 0.5, 0.96], projection="3d" if dim3 else None)
    ax_text = fig.add_axes([0.5, 0.0, 0.5, 1.0])
    ax_text.axis("off")
    if not dim3:
        ax_draw.set_aspect("equal")
        ax_draw.axis("off")
    else:
        ax_draw.set_axis_off()
    return fig, ax_draw, ax_text


def _legend(ax_text, t, formulas, note=""):
    """Title, nodes and the deformations of element type t (names from the catalogue), each
    with its formula."""
    import textwrap

    ax_text.text(0.0, 0.97, t.name, transform=ax_text.transAxes, va="top", fontsize=12, weight="bold")
    lines = ["nodes: " + ", ".join(f"{r} {k.name}" for r, k in zip(t.node_roles, t.nodes)), ""]
    for i, name in enumerate(t.deformations):
        lines.append(f"e{i + 1}: {name}")
        if i < len(formulas) and formulas[i]:
            lines.extend("    " + w for w in textwrap.wrap(formulas[i], 46))
    if note:
        lines.append("")
        lines.extend(textwrap.wrap(note, 50))
    ax_text.text(0.0, 0.88, "\n".join(lines), transform=ax_text.transAxes, va="top", fontsize=8,
                 linespacing=1.35, family="DejaVu Sans")


def _node(ax, p, label, offset=(0.0, -0.12), kind="position", **kw):
    if kind == "position":
        ax.plot(*p, "o", ms=7, mfc="white", mec="k", mew=1.5, zorder=5)
    ax.annotate(label, p, xytext=(p[0] + offset[0], p[1] + offset[1]), fontsize=9, ha="center", **kw)


def _arrow(ax, p, d, color="0.2", **kw):
    ax.annotate("", xy=(p[0] + d[0], p[1] + d[1]), xytext=tuple(p),
                arrowprops=dict(arrowstyle="-|>", color=color, lw=1.2, **kw))


def fig_truss(t, planar=True):
    fig, ax, axt = _figure()
    l0 = 1.0
    a = math.radians(20.0)
    p, q0 = np.array([0.0, 0.0]), l0 * np.array([math.cos(a), math.sin(a)])
    q = 1.18 * q0
    ax.plot(*np.array([p, q0]).T, color="0.6", ls="--", lw=1.2)
    ax.plot(*np.array([p, q]).T, color="C1", lw=3)
    _node(ax, p, "p1")
    _node(ax, q, "p2", offset=(0.08, -0.12))
    ax.annotate("l0", (q0 * 0.5), xytext=(q0[0] * 0.5 + 0.05, q0[1] * 0.5 - 0.12), fontsize=9, color="0.4")
    ax.annotate("l", (q * 0.5), xytext=(q[0] * 0.5 - 0.08, q[1] * 0.5 + 0.08), fontsize=9, color="C1")
    ax.set_xlim(-0.2, 1.35)
    ax.set_ylim(-0.3, 0.6)
    _legend(axt, t, ["e1 = l − l0"], "ESTIFF EA: σ1 = EA e1 / l0 (axial force, tension > 0)."
            + ("" if planar else " Drawn in a plane; p1, p2 are XYZ nodes."))
    return fig


def fig_plbeam(t, nonlinear=False, arc=False):
    fig, ax, axt = _figure()
    l0 = 1.0
    p, q = np.array([0.0, 0.0]), np.array([1.0, 0.12])
    bp, bq = math.radians(25.0), math.radians(-12.0)
    tp, tq = np.array([math.cos(bp), math.sin(bp)]), np.array([math.cos(bq), math.sin(bq)])
    ax.plot(*np.array([p, [l0, 0.0]]).T, color="0.6", ls="--", lw=1.2)
    ax.plot(*np.array([p, q]).T, color="0.5", ls=":", lw=1.0)
    ax.plot(*hermite(p, tp, q, tq, l0, 41).T, color="C0", lw=3)
    _arrow(ax, p, 0.35 * tp)
    _arrow(ax, q, 0.35 * tq)
    _node(ax, p, "p1, o1 (β1)")
    _node(ax, q, "p2, o2 (β2)", offset=(0.0, -0.14))
    ax.annotate("tangent φ1 = α0 + β1", p + 0.35 * tp, xytext=(p[0] - 0.05, p[1] + 0.32), fontsize=8)
    ax.annotate("φ2 = α0 + β2", q + 0.35 * tq, xytext=(q[0] + 0.05, q[1] + 0.12), fontsize=8)
    ax.annotate("chord α", (0.5, 0.06), xytext=(0.6, 0.005), fontsize=7, color="0.4")
    ax.set_xlim(-0.25, 1.55)
    ax.set_ylim(-0.35, 0.65)
    if arc:
        lines = ["e1 = l δ/sin δ − l0 + b²/(10 l0), δ = (δ1 + δ2)/2, b = (e2 − e3)/2",
                 "e2 = l0 δ1, δ1 = φ1 − α", "e3 = l0 δ2, δ2 = α − φ2"]
    else:
        e1 = "e1 = l − l0 + (2e2² + e2e3 + 2e3²)/(30 l0)" if nonlinear else "e1 = l − l0"
        lines = [e1, "e2 = l0 sin(φ1 − α)", "e3 = l0 sin(α − φ2)"]
    _legend(axt, t, lines,
            "ESTIFF EA EI: σ1 = EA e1/l0, [σ2 σ3] = EI/l0³ [[4 −2] [−2 4]] [e2 e3]. "
            "Constant curvature κ > 0 gives e2 = e3 < 0" + (" and e1 = 0 along the arc." if arc else "."))
    return fig


def fig_plhinge(t):
    fig, ax, axt = _figure()
    c = np.array([0.0, 0.0])
    b1, b2 = math.radians(15.0), math.radians(70.0)
    for b, name, color in ((b1, "o1", "C0"), (b2, "o2", "C1")):
        d = np.array([math.cos(b), math.sin(b)])
        ax.plot(*np.array([c, d]).T, color=color, lw=3)
        ax.annotate(f"{name}: β = {math.degrees(b):.0f}°", d, xytext=(d[0] + 0.03, d[1] + 0.03), fontsize=9)
    phi = np.linspace(b1, b2, 30)
    ax.plot(0.45 * np.cos(phi), 0.45 * np.sin(phi), color="0.3", lw=1)
    ax.annotate("e1", (0.45 * math.cos(0.7), 0.45 * math.sin(0.7)), xytext=(0.5, 0.45), fontsize=10)
    ax.plot(*c, "o", ms=9, mfc="white", mec="k", mew=1.5)
    ax.set_xlim(-0.3, 1.4)
    ax.set_ylim(-0.3, 1.1)
    _legend(axt, t, ["e1 = β(o2) − β(o1)"], "ESTIFF St: σ1 = St e1 (moment).")
    return fig


def _triad3(ax, origin, R, scale=0.3, labels=("x", "y", "z"), alpha=1.0):
    for j, color in enumerate(("tab:red", "tab:green", "tab:blue")):
        d = R[:, j] * scale
        ax.plot(*np.array([origin, origin + d]).T, color=color, lw=2, alpha=alpha)
        if labels:
            ax.text(*(origin + 1.15 * d), labels[j], fontsize=7, color=color)


def _axes3(ax, lo=(-0.15, -0.45, -0.45), hi=(1.25, 0.45, 0.45)):
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect((hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]))
    ax.view_init(elev=22, azim=-60)


def _quat(axis, angle):
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    return np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * axis])


def fig_beam(t, nonlinear=False, arc=False):
    fig, ax, axt = _figure(dim3=True)
    p, q = np.zeros(3), np.array([1.0, 0.1, 0.15])
    lp = _quat([0.2, -0.5, 0.6], 0.45)
    lq = _quat([0.3, 0.4, -0.5], 0.35)
    Rp, Rq = rotation(lp), rotation(lq)
    ex0 = np.array([1.0, 0.0, 0.0])
    ax.plot(*np.array([p, [1.0, 0, 0]]).T, color="0.6", ls="--", lw=1)
    ax.plot(*hermite(p, Rp @ ex0, q, Rq @ ex0, 1.0, 41).T, color="C0", lw=3)
    _triad3(ax, p, Rp, labels=("ex", "ey", "ez"))
    _triad3(ax, q, Rq, labels=("ex", "ey", "ez"))
    ax.text(*(p + [0, 0, -0.25]), "p1, o1", fontsize=9)
    ax.text(*(q + [0, 0, -0.25]), "p2, o2", fontsize=9)
    _axes3(ax)
    if arc:
        _legend(axt, t, ["e1 = |c|/|g| − l0 + l0 (βy² + βz²)/10", "e2 = l0 φx",
                         "e3, e4 = l0 (−φy/2 ∓ βy)", "e5, e6 = l0 (−φz/2 ∓ βz)"],
                "φ: the rotation vector from the section at p to the one at q; c: the chord in the mid "
                "frame; g: the chord of the unit helix of curvature and twist φ; β: the rotation from g to c.")
        return fig
    e1 = "e1 = l − l0 + (2e3²+e3e4+2e4²+2e5²+e5e6+2e6²)/(30 l0)" if nonlinear else "e1 = l − l0"
    _legend(axt, t, [e1, "e2 = l0 (ez(p)·ey(q) − ey(p)·ez(q))/2",
                     "e3 = l0 el·ez(p)", "e4 = −l0 el·ez(q)", "e5 = −l0 el·ey(p)", "e6 = l0 el·ey(q)"],
            "el: chord direction; ex, ey, ez: the cross-section frames at p and q (red, green, blue).")
    return fig


def fig_hinge(t):
    fig, ax, axt = _figure(dim3=True)
    axis = np.array([0.0, 0.0, 1.0])
    R1 = np.eye(3)
    R2 = rotation(_quat(axis, math.radians(50.0)))
    c = np.array([0.5, 0.0, 0.0])
    ax.plot(*np.array([c - 0.5 * axis, c + 0.5 * axis]).T, color="0.3", lw=1.5)
    ax.text(*(c + 0.55 * axis), "axis", fontsize=8)
    _triad3(ax, c, R1, scale=0.45, labels=("o1", "", ""), alpha=0.5)
    _triad3(ax, c, R2, scale=0.45, labels=("o2", "", ""))
    phi = np.linspace(0, math.radians(50.0), 20)
    ax.plot(c[0] + 0.3 * np.cos(phi), 0.3 * np.sin(phi), np.zeros_like(phi), color="0.2", lw=1)
    ax.text(c[0] + 0.33, 0.15, 0.0, "e1", fontsize=9)
    _axes3(ax, (-0.1, -0.6, -0.6), (1.1, 0.6, 0.6))
    _legend(axt, t, ["right-handed, unwrapped over full turns", "e2 = ex(o1)·ez(o2)", "e3 = −ex(o1)·ey(o2)"],
            "ex = the hinge axis in the frames of o1 and o2. ESTIFF St: σ1 = St e1.")
    return fig


def fig_l2min1(t):
    fig, ax, axt = _figure(dim3=True)
    R = rotation(_quat([1.0, 1.0, 0.5], 0.8))
    _triad3(ax, np.array([0.5, 0.0, 0.0]), R, scale=0.5)
    ax.text(0.1, -0.3, -0.5, "o1: λ = (λ0, λ1, λ2, λ3)", fontsize=9)
    _axes3(ax, (-0.1, -0.6, -0.6), (1.1, 0.6, 0.6))
    _legend(axt, t, ["e1 = λ0² + λ1² + λ2² + λ3² − 1"],
            "Fixed by default (|λ| = 1); created automatically for every LAMBDA node.")
    return fig


def fig_plbear(t):
    fig, ax, axt = _figure()
    p1, b1 = np.array([0.0, 0.0]), math.radians(20.0)
    R = np.array([[math.cos(b1), -math.sin(b1)], [math.sin(b1), math.cos(b1)]])
    d0 = np.array([0.8, 0.0])
    p2 = p1 + R @ (d0 + np.array([0.12, 0.1]))
    for j, name in enumerate(("x1", "y1")):
        _arrow(ax, p1, 0.45 * R[:, j])
        ax.annotate(name, p1 + 0.5 * R[:, j], fontsize=8)
    ax.plot(*np.array([p1, p1 + R @ d0]).T, color="0.6", ls="--", lw=1.2)
    ax.plot(*np.array([p1, p2]).T, color="C2", lw=2.5)
    _node(ax, p1, "p1, o1")
    _node(ax, p2, "p2, o2", offset=(0.05, 0.08))
    ax.set_xlim(-0.3, 1.3)
    ax.set_ylim(-0.3, 0.8)
    _legend(axt, t, ["[e1 e2] = R(β1)ᵀ (x2 − x1) − d0", "", "e3 = β(o2) − β(o1)"],
            "d0 (LGEOMY): the relative position at the reference. ESTIFF Sx Sy St: σ = diag(S) e. "
            "From fixed ground nodes its deformations are the position and heading of a body.")
    return fig


def fig_plbelt(t):
    fig, ax, axt = _figure()
    c1, c2, r1, r2 = np.array([0.0, 0.0]), np.array([1.0, 0.1]), 0.2, 0.32
    d = c2 - c1
    L, delta = np.linalg.norm(d), r2 - r1
    psi = math.atan2(d[1], d[0]) + math.asin(delta / L)
    s_dir = np.array([math.cos(psi), math.sin(psi)])
    m = np.array([s_dir[1], -s_dir[0]])
    T1, T2 = c1 - r1 * m, c2 - r2 * m
    phi = np.linspace(0, 2 * math.pi, 80)
    for c, r, name in ((c1, r1, "p1, o1"), (c2, r2, "p2, o2")):
        ax.plot(c[0] + r * np.cos(phi), c[1] + r * np.sin(phi), color="0.4", lw=1.5)
        _node(ax, c, name, offset=(0.0, -0.1))
    ax.plot(*np.array([T1, T2]).T, color="C3", lw=3)
    ax.annotate("free span s", 0.5 * (T1 + T2), xytext=(0.3, 0.45), fontsize=8, color="C3")
    ax.set_xlim(-0.35, 1.45)
    ax.set_ylim(-0.45, 0.6)
    _legend(axt, t, ["e1 = r1 β1 − r2 β2 + δ (Δα + asin(δ/L) − asin(δ/L0)) + l_f − l_f0"],
            "Open belt, wound counter-clockwise on pulley 1 and clockwise on pulley 2; δ = r2 − r1, "
            "l_f the span length. ESTIFF EA: σ1 = EA e1 / l_f0 (belt tension). EMASS ρA a1 a2.")
    return fig


def fig_plwheel(t):
    fig, ax, axt = _figure()
    p, b1 = np.array([0.4, 0.2]), math.radians(25.0)
    a = np.array([-math.sin(b1), math.cos(b1)])
    tdir = np.array([a[1], -a[0]])
    ax.plot(*np.array([p - 0.35 * tdir, p + 0.35 * tdir]).T, color="k", lw=6, solid_capstyle="round")
    _arrow(ax, p, 0.4 * a)
    ax.annotate("axle a (o1)", p + 0.42 * a, fontsize=8)
    _arrow(ax, p, 0.55 * tdir, color="C0")
    ax.annotate("rolling direction t", p + 0.58 * tdir, fontsize=8, color="C0")
    _node(ax, p, "p1", offset=(-0.12, -0.1))
    ax.set_xlim(-0.2, 1.3)
    ax.set_ylim(-0.2, 0.9)
    _legend(axt, t, ["ė1 = t·ẋ(p1) − r β̇(o2)   (longitudinal slip)", "ė2 = a·ẋ(p1)   (lateral slip)"],
            "Top view of a wheel rolling on the model plane; o2 is the spin about the axle. Both slips "
            "are velocity level: ENHC for rolling without slip, or RLSE with EDAMPP creep damping.")
    return fig


def fig_surface(t):
    fig, ax, axt = _figure(dim3=True)
    u, v = np.meshgrid(np.linspace(-0.5, 0.5, 15), np.linspace(-0.5, 0.5, 15))
    z = 0.6 * (u**2 + 0.5 * v**2)
    ax.plot_wireframe(u + 0.5, v, z - 0.3, color="0.7", lw=0.5)
    p = np.array([0.7, 0.2, 0.6 * (0.2**2 + 0.5 * 0.2**2) - 0.3])
    ax.plot(*p, "o", ms=7, mfc="white", mec="k")
    ax.text(*(p + [0, 0, 0.1]), "p1", fontsize=9)
    _axes3(ax, (-0.1, -0.6, -0.6), (1.1, 0.6, 0.6))
    _legend(axt, t, ["e1 = c1x² + c2y² + c3z² + c4xy + c5yz + c6zx + c7x + c8y + c9z + c10"],
            "Absolute: fixed e1 = 0 keeps p1 on the quadric; σ1 is the multiplier, the contact "
            "force on the point is −σ1 ∇f.")
    return fig


def fig_bearing(t):
    fig, ax, axt = _figure(dim3=True)
    axis = np.array([0.0, 0.0, 1.0])
    R2 = rotation(_quat(axis, math.radians(40.0)))
    c1, c2 = np.array([0.2, 0.0, 0.0]), np.array([0.8, 0.1, 0.15])
    _triad3(ax, c1, np.eye(3), scale=0.35, labels=("", "", "axis"))
    _triad3(ax, c2, R2, scale=0.35, labels=("", "", ""))
    ax.plot(*np.array([c1, c2]).T, color="C2", lw=2)
    ax.text(*(c1 + [0, 0, -0.25]), "p1, o1", fontsize=9)
    ax.text(*(c2 + [0, 0, -0.25]), "p2, o2", fontsize=9)
    _axes3(ax, (-0.1, -0.6, -0.6), (1.1, 0.6, 0.6))
    _legend(axt, t, ["e1..e3: the position of p2 relative to p1 in the frame of o1 (axial, radial y,",
                     "radial z) minus d0", "", "e4: rotation about the axis (as HINGE e1)",
                     "e5 = ex(o1)·ez(o2)", "e6 = −ex(o1)·ey(o2)"],
            "The frame (ex = axis, ey, ez) is the hinge frame of the axis. From fixed ground nodes "
            "the deformations are the position and orientation of a body (vehicle coordinates).")
    return fig


def fig_wheel(t):
    fig, ax, axt = _figure(dim3=True)
    lean = math.radians(20.0)
    a = np.array([0.0, math.cos(lean), math.sin(lean)])
    n = np.array([0.0, 0.0, 1.0])
    r = 0.4
    d = n - (n @ a) * a
    d /= np.linalg.norm(d)
    t1 = np.cross(a, n)
    t1 /= np.linalg.norm(t1)
    centre = np.array([0.5, 0.0, 0.0]) + r * d
    phi = np.linspace(0, 2 * math.pi, 80)
    rim = centre + r * (np.outer(np.cos(phi), d) + np.outer(np.sin(phi), t1))
    ax.plot(*rim.T, color="k", lw=2)
    u, v = np.meshgrid(np.linspace(-0.1, 1.1, 2), np.linspace(-0.6, 0.6, 2))
    ax.plot_surface(u, v, 0 * u, color="0.85", alpha=0.4)
    ax.plot(*np.array([centre, centre + 0.3 * a]).T, color="C1", lw=2)
    ax.text(*(centre + 0.35 * a), "axle", fontsize=8)
    ax.plot(*centre, "o", ms=6, mfc="white", mec="k")
    ax.text(*(centre + [0, 0, 0.08]), "p1, o1", fontsize=9)
    _axes3(ax, (-0.1, -0.6, -0.1), (1.1, 0.6, 0.9))
    _legend(axt, t, ["e1 = n·x(p1) − r √(1 − (n·a)²)   (height of the lowest rim point)",
                     "ė2 = t1·ẋ(p1) − r a·ω   (longitudinal slip)", "ė3 = t2·ẋ(p1) + r s t1·ω   (lateral slip)"],
            "Thin disc on the plane n·x = 0 (extension). Knife-edge rolling: e1 fixed, e2 and e3 ENHC.")
    return fig


def fig_default(t):
    """The figure of a type without its own drawing: its node slots in input order (positions
    as circles, orientations as arrows at the position before them) and its deformations."""
    fig, ax, axt = _figure()
    position, after_position = 0.0, False
    for role, kind in zip(t.node_roles, t.nodes):
        if kind.name in ("XY", "XYZ"):
            position += 1.0
            _node(ax, (position, 0.0), role, offset=(0.0, -0.15))
            after_position = True
        else:
            position += 0.0 if after_position else 1.0
            _arrow(ax, (position, 0.0), (0.3, 0.3))
            ax.annotate(role, (position + 0.3, 0.3), xytext=(position + 0.32, 0.32), fontsize=9)
            after_position = False
    ax.set_xlim(0.4, position + 0.8)
    ax.set_ylim(-0.5, 0.7)
    _legend(axt, t, [], "Default figure: this element type has no drawing of its own in docs/generate.py.")
    return fig


FIGURES_BY_TYPE = {
    "PLBEAR": fig_plbear,
    "PLBELT": fig_plbelt,
    "PLWHEEL": fig_plwheel,
    "SURFACE": fig_surface,
    "BEARING": fig_bearing,
    "WHEEL": fig_wheel,
    "PLTRUSS": lambda t: fig_truss(t, True),
    "TRUSS": lambda t: fig_truss(t, False),
    "PLBEAM": lambda t: fig_plbeam(t, False),
    "PLBEAMNL": lambda t: fig_plbeam(t, True),
    "PLBEAMC": lambda t: fig_plbeam(t, arc=True),
    "PLHINGE": fig_plhinge,
    "BEAM": lambda t: fig_beam(t, False),
    "BEAMNL": lambda t: fig_beam(t, True),
    "BEAMC": lambda t: fig_beam(t, arc=True),
    "HINGE": fig_hinge,
    "L2MIN1": fig_l2min1,
}


def write_figures(directory: Path = FIGURES) -> list:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    matplotlib.rcParams["svg.hashsalt"] = "spacar"
    matplotlib.rcParams["svg.fonttype"] = "none"   # text as text: small files, selectable
    directory.mkdir(parents=True, exist_ok=True)
    written = []
    for t in spacar.element_catalogue():
        fig = FIGURES_BY_TYPE.get(t.name, fig_default)(t)
        path = directory / f"{t.name.lower()}.svg"
        fig.savefig(path, metadata={"Date": None, "Creator": None})
        plt.close(fig)
        written.append(path)
    return written


# --------------------------------------------------------------------------------------------
# The figures of the modelling guide (docs/modelling.md), drawn by spacar itself
# --------------------------------------------------------------------------------------------

# The four-bar of docs/modelling.md, "Closing a loop": C given roughly, the lengths by LENGTHO.
ROUGH_FOURBAR = """\
PLBEAM 1 1 2 3 4
PLBEAM 2 3 5 6 7
PLBEAM 3 8 9 6 10
X 3 0. 1.
X 6 3.2 2.6
X 8 4. 0.
FIX 1
FIX 8
LENGTHO 2 3.605551
LENGTHO 3 3.162278
INPUTX 2
END
"""


def _example(name):
    return spacar.read(EXAMPLES / f"{name}.dat")


def _note(scene, text):
    """How the joint is modelled, in a box under the drawing."""
    scene.ax.text(0.0, -0.25, text, transform=scene.ax.transAxes, fontsize=8, va="top",
                  bbox=dict(boxstyle="round", fc="white", ec="0.7"))
    scene.ax.set_title(scene.ax.get_title(), fontsize=9)


def guide_pin():
    res = spacar.simulate(_example("double_pendulum"), progress=False)
    scene = spacar.draw(res, time=0.3, labels=True, figsize=(4.6, 3.4))
    _note(scene, "pin 3: rods 1 and 2 share XY node 3,\nBETA nodes 4 (rod 1) and 5 (rod 2)\n"
                 "ground pin: FIX 1 (XY only)")
    return scene


def guide_slider():
    res = spacar.simulate(_example("slidercrank"), progress=False)
    scene = spacar.draw(res, time=1.0, labels=True, figsize=(4.6, 3.0))
    _note(scene, "slider 8: FIX 8 2 (y fixed, x calculable)")
    return scene


def guide_weld():
    res = spacar.simulate(_example("fourbar_coupler"), progress=False)
    scene = spacar.draw(res, time=0.6, labels=True, trace=[11], figsize=(4.6, 3.6))
    _note(scene, "weld: B-C (element 2) and B-P (element 4)\nshare BETA node 5 at B = node 3;\n"
                 "trace=[11]: the coupler curve of P")
    return scene


def guide_ground():
    model = _example("cross_spring_pivot")
    model.force(10, 0.35)                     # a large moment: the clamped leaves visibly bent
    scene = spacar.draw(spacar.static(model), figsize=(4.6, 3.4))
    _note(scene, "clamps: FIX 1, FIX 2 and FIX 101, FIX 102\n(XY and BETA of each leaf's foot)")
    return scene


def guide_loop():
    import numpy as np

    model = spacar.read_string(ROUGH_FOURBAR)
    rough = {n: np.array(model.nodes[n].x[:2]) for n in (1, 3, 6, 8)}
    scene = spacar.draw(spacar.simulate(model, progress=False), labels=True, figsize=(4.6, 3.4))
    for a, b in [(1, 3), (3, 6), (8, 6)]:
        scene.ax.plot(*np.array([rough[a], rough[b]]).T, color="0.5", ls="--", lw=1.2)
    _note(scene, "dashed: the rough X positions (C = node 6 at (3.2, 2.6))\n"
                 "solid: assembled with LENGTHO 2 and 3")
    return scene


GUIDE_FIGURES = {"pin": guide_pin, "slider": guide_slider, "weld": guide_weld, "ground": guide_ground,
                 "loop": guide_loop}


def write_guide_figures(directory: Path = DOCS / "img") -> list:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    directory.mkdir(parents=True, exist_ok=True)
    written = []
    for name, make in GUIDE_FIGURES.items():
        fig = make().ax.figure
        path = directory / f"modelling_{name}.png"
        fig.savefig(path, dpi=100, bbox_inches="tight", metadata={"Software": None})
        plt.close(fig)
        written.append(path)
    return written


# --------------------------------------------------------------------------------------------

def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="only check that the generated text files are up to date")
    parser.add_argument("--no-figures", action="store_true", help="do not redraw the element figures")
    args = parser.parse_args(argv)
    stale = []
    for name, make in GENERATED.items():
        path = DOCS / name
        text = make()
        if args.check:
            if not path.exists() or path.read_text(encoding="utf-8") != text:
                stale.append(name)
        else:
            path.write_text(text, encoding="utf-8")
            print(f"wrote {path}")
    if args.check:
        if stale:
            print("out of date: " + ", ".join(stale) + " (run python docs/generate.py)")
            return 1
        print("generated docs are up to date")
        return 0
    if not args.no_figures:
        for path in write_figures() + write_guide_figures():
            print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

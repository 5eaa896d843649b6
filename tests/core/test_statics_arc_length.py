"""Arc-length continuation of the static equilibrium (issue 19, docs/statics.md): the path
followed past limit points (snap-through) to λ = 1, against references computed here:

* a shallow two-bar von Mises truss (PLTRUSS): the limit loads against the closed form of the
  load-displacement curve P(y) = 2 y (1/l(y) − 1/l0), dP/dy = 0 at (1 + y²)^{3/2} = l0, and the
  equilibrium at λ = 1 beyond the snap-through (the truss inverted) against the root of
  P(y) = P_applied on the far branch;
* a shallow pinned circular arch of PLBEAMs under a central point load: the limit load against
  a displacement-controlled solve of the same mesh (the apex moved as an INPUTX, the load read
  as its reaction, maximized over the apex deflection by minimize_scalar): a reference that
  needs no continuation in the load, so it checks the location of the limit point by the arc
  length independently;
* loads beyond the limit point without the arc length stop with StaticError within a time bound.
"""
from __future__ import annotations

import time

import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar

import spacar
from test_statics import plbeam_cantilever, von_mises_truss  # tests/core/test_statics.py


def truss_load(y, h):
    """The downward apex load that holds the apex of von_mises_truss(h, EA=1) at height y."""
    l0 = np.hypot(1.0, h)
    return 2.0 * y * (1.0 / np.hypot(1.0, y) - 1.0 / l0)


def truss_limit(h):
    l0 = np.hypot(1.0, h)
    y = np.sqrt(l0 ** (2.0 / 3.0) - 1.0)
    return y, truss_load(y, h)


def test_von_mises_truss_snaps_through_to_the_far_equilibrium():
    h = 0.1
    y_star, p_star = truss_limit(h)
    assert p_star == pytest.approx(-minimize_scalar(lambda y: -truss_load(y, h), bounds=(0, h), method="bounded",
                                                    options={"xatol": 1e-12}).fun, rel=1e-9)
    P = 1.5 * p_star
    m = von_mises_truss(P, h)
    res = spacar.static(m, steps=20, arc_length=True)
    # Two limit points on the way: the maximum P*/P (snap) and the minimum −P*/P (the truss
    # pulled back through the inverted unstressed state).
    limits = res.stats["limit_points"]
    assert len(limits) == 2
    assert limits[0] == pytest.approx(p_star / P, rel=1e-6)
    assert limits[1] == pytest.approx(-p_star / P, rel=1e-6)
    assert any("limit point at load factor 0.666" in w for w in m.warnings)
    # The last row at λ = 1 exactly, on the far branch (below −h, the bars in tension).
    assert res.t[-1] == 1.0
    y_far = brentq(lambda y: truss_load(y, h) - P, -10.0, -h - 1e-12, xtol=1e-15)
    assert res.node(3).x[-1, 1] == pytest.approx(y_far, rel=1e-9)
    assert m.nodes[3].x[1] == pytest.approx(y_far, rel=1e-9)  # the model holds it
    # Every row is an equilibrium of the closed form; λ rises, falls below zero and rises again.
    y = res.node(3).x[:, 1]
    np.testing.assert_allclose(truss_load(y, h), res.t * P, atol=1e-9 * P)
    assert np.all(np.diff(y) < 0)  # the apex moves down all the way
    assert res.t.min() == pytest.approx(-p_star / P, rel=1e-2)
    assert res.stats["indefinite_at"] is not None  # between the limit points the truss is unstable


def test_arc_length_below_the_limit_agrees_with_load_steps():
    h = 0.1
    P = 0.8 * truss_limit(h)[1]
    arc = spacar.static(von_mises_truss(P, h), steps=5, arc_length=True)
    plain = spacar.static(von_mises_truss(P, h), steps=5)
    assert arc.stats["limit_points"] == [] and plain.stats["limit_points"] == []
    assert arc.t[-1] == 1.0 and np.all(np.diff(arc.t) > 0)
    np.testing.assert_allclose(arc.x[-1], plain.x[-1], atol=1e-12)


def pinned_arch(n, P, H=0.04, EI=1.0, EA=1e4, apex_input=None):
    """A circular arch of n PLBEAMs (n even) over the span (−1, 0)..(1, 0) with rise H, pinned
    at both ends (positions fixed, rotations free), extensible (RLSE with EA, EI), every free
    coordinate a DYNX; a downward load P at the apex. With apex_input = δ the apex height is an
    input instead, moved down by δ over the block (displacement control)."""
    R = (1.0 + H**2) / (2.0 * H)
    half = np.arcsin(1.0 / R)
    m = spacar.Model()
    apex = n + 1  # XY node of the middle
    for k in range(1, n + 1):
        m.plbeam(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2)
        m.rlse(k)
        m.estiff(k, EA, EI)
    for i in range(n + 1):
        phi = -half + 2.0 * half * i / n
        m.x(2 * i + 1, R * np.sin(phi), H - R + R * np.cos(phi))
    m.fix(1)
    m.fix(2 * n + 1)
    for i in range(n + 1):
        node = 2 * i + 1
        if node not in (1, 2 * n + 1):
            if node == apex and apex_input is not None:
                m.dynx(node, 1)
                m.apply("INPUTX", node, 2)
            else:
                m.dynx(node)
        m.dynx(node + 1)
    if apex_input is not None:
        m.xd(apex, 2, -apex_input)
        m.timestep(1, 1.0)
    else:
        m.force(apex, 0.0, -P)
    return m, apex


def test_shallow_arch_limit_load_against_displacement_control():
    n = 16

    def load(delta):  # the apex load that holds the apex deflected by delta
        m, apex = pinned_arch(n, 0.0, apex_input=delta)
        res = spacar.static(m, steps=4)
        col = res.coordinate_labels.index((apex, 2))
        return -res.reaction[-1, col]

    best = minimize_scalar(lambda d: -load(d), bounds=(0.0, 0.08), method="bounded", options={"xatol": 1e-9})
    p_ref = -best.fun
    assert 0.0 < best.x < 0.08 and p_ref > 0.0
    P = 1.25 * p_ref
    m, apex = pinned_arch(n, P)
    res = spacar.static(m, steps=10, arc_length=True)
    limits = res.stats["limit_points"]
    assert len(limits) >= 1
    assert limits[0] * P == pytest.approx(p_ref, rel=1e-6)
    assert res.t[-1] == 1.0
    assert res.node(apex).x[-1, 1] < -0.5 * 0.04  # snapped through: the arch inverted
    # Stable up to the limit point: the symmetric snap comes before any asymmetric bifurcation
    # (the first unstable row follows the row of the largest λ).
    top = int(np.argmax(np.diff(res.t) < 0))  # the row before λ first falls
    assert res.t[top] == pytest.approx(limits[0], rel=0.05)
    unstable = np.flatnonzero(res.t == res.stats["indefinite_at"])
    assert len(unstable) and unstable[0] > top


def test_arc_length_gives_up_after_max_steps_with_the_rows():
    h = 0.1
    P = 1.5 * truss_limit(h)[1]
    m = von_mises_truss(P, h)
    before = m.nodes[3].x.copy()
    with pytest.raises(spacar.StaticError, match="did not reach load factor 1 in 12 steps") as info:
        spacar.static(m, steps=20, arc_length=True, max_steps=12)
    partial = info.value.results
    assert len(partial) == 12
    assert partial.stats["load_reached"] == partial.t[-1]
    np.testing.assert_array_equal(m.nodes[3].x, before)


def test_without_arc_length_a_load_beyond_the_limit_fails_quickly():
    """Not a hang: even with the most step halvings allowed and many load steps, the load
    stepping stops at the limit point with StaticError in well under a few seconds."""
    h = 0.1
    P = 1.5 * truss_limit(h)[1]
    start = time.perf_counter()
    with pytest.raises(spacar.StaticError, match="beyond load factor 0.666") as info:
        spacar.static(von_mises_truss(P, h), steps=100, max_cuts=50)
    assert time.perf_counter() - start < 5.0
    assert "arc_length=True" in info.value.args[0]
    assert info.value.results.stats["load_reached"] == pytest.approx(1 / 1.5, abs=1e-3)


def truss_pushed_through_a_spring(k, drop, h=0.1, s=1.0):
    """The von Mises truss (EA = 1) without load, its apex pushed down through a soft spring
    (a PLTRUSS of stiffness k and length s) whose upper end, node 4, is an input moved down by
    `drop` over the block: displacement control through a compliant drive. When k is less than
    the truss's largest negative stiffness the drive's travel folds back (snap-through under
    displacement control)."""
    m = von_mises_truss(0.0, h)
    m.pltruss(3, 3, 4)
    m.x(4, 0.0, h + s)
    m.fix(4, 1)
    m.apply("INPUTX", 4, 2)
    m.xd(4, 2, -drop)
    m.timestep(1, 1.0)
    m.rlse(3, 1)
    m.estiff(3, k * s)     # PLTRUSS: σ = (EA/l0) e
    return m


def test_arc_length_with_a_moving_input_passes_the_folds_of_the_drive():
    h, s, k = 0.1, 1.0, 0.005
    l0 = np.hypot(1.0, h)
    # Equilibrium of the apex at height y: the drive's end at y4(y) = y + s − P(y)/k.
    drive = lambda y: y + s - truss_load(y, h) / k  # noqa: E731
    # Folds where P'(y) = k: 2/l³ − 2/l0 = k.
    l_fold = (2.0 / (k + 2.0 / l0)) ** (1.0 / 3.0)
    y_fold = np.sqrt(l_fold**2 - 1.0)
    drop = h + s - drive(-1.5 * h)          # the apex ends at −1.5 h, below the inverted state
    m = truss_pushed_through_a_spring(k, drop, h, s)
    with pytest.raises(spacar.StaticError):  # load steps stop at the first fold
        spacar.static(m.copy(), steps=20)
    res = spacar.static(m, steps=20, arc_length=True)
    lam = lambda y: (h + s - drive(y)) / drop  # noqa: E731
    limits = res.stats["limit_points"]
    assert len(limits) == 2
    assert limits[0] == pytest.approx(lam(y_fold), rel=1e-6)     # the drive's travel is largest there
    assert limits[1] == pytest.approx(lam(-y_fold), rel=1e-6)    # and smallest here
    assert res.t[-1] == 1.0
    assert res.node(3).x[-1, 1] == pytest.approx(-1.5 * h, rel=1e-9)
    # Every row is an equilibrium: the drive end where λ puts it, the apex where the spring holds it.
    y, y4 = res.node(3).x[:, 1], res.node(4).x[:, 1]
    np.testing.assert_allclose(y4, h + s - res.t * drop, atol=1e-12)
    np.testing.assert_allclose(drive(y), y4, atol=1e-9)


def test_arc_length_with_moving_inputs_and_no_fold_agrees_with_load_steps():
    m, apex = pinned_arch(8, 0.0, apex_input=0.06)
    arc = spacar.static(m.copy(), steps=6, arc_length=True)
    plain = spacar.static(m, steps=6)
    assert arc.t[-1] == 1.0 and arc.stats["limit_points"] == []
    np.testing.assert_allclose(arc.x[-1], plain.x[-1], atol=1e-11)


def test_arc_length_bad_options():
    for kwargs in ({"arc_length": 1}, {"arc_length": True, "max_steps": 0}):
        with pytest.raises(spacar.InputError):
            spacar.static(von_mises_truss(1e-4), **kwargs)


def test_cli_static_arc_length(tmp_path, capsys):
    from spacar.cli import main

    h = 0.1
    P = 1.5 * truss_limit(h)[1]
    lines = ["PLTRUSS 1 1 3", "PLTRUSS 2 2 3", "X 1 -1 0", "X 2 1 0", f"X 3 0 {h}", "FIX 1", "FIX 2", "FIX 3 1",
             "DYNX 3 2", "RLSE 1 1", "RLSE 2 1", "ESTIFF 1 1", "ESTIFF 2 1", f"FORCE 3 0 {-P:.17g}", "END"]
    path = tmp_path / "truss.dat"
    path.write_text("\n".join(lines) + "\n")
    assert main(["static", str(path), "--arc-length", "--steps", "20", "--dump-digits", "12"]) == 0
    out = capsys.readouterr().out
    assert "limit point passed at load factor 0.66666" in out
    y = [float(line.split()[3]) for line in out.splitlines() if line.startswith("XY") and line.split()[1] == "3"]
    assert y[-1] < -h


def test_arc_length_on_a_large_deflection_cantilever_ends_where_load_steps_end():
    """Many DOFs and no limit point (a PLBEAM cantilever under P L²/EI = 3): λ rises monotonically
    and the last row is the load-stepping equilibrium."""
    arc = spacar.static(plbeam_cantilever(20, force=(0.0, 3.0)), steps=5, arc_length=True)
    plain = spacar.static(plbeam_cantilever(20, force=(0.0, 3.0)), steps=5)
    assert arc.stats["limit_points"] == [] and arc.stats["indefinite_at"] is None
    assert arc.t[-1] == 1.0 and np.all(np.diff(arc.t) > 0)
    np.testing.assert_allclose(arc.x[-1], plain.x[-1], atol=1e-9)

"""Plots, drawings and animations with matplotlib (Agg backend; issue #7).

Independent references: the drawn beam curves are checked as cubics through the nodes with the
nodal material tangents computed here from the node angles / Euler parameters (quaternion
products, not spacar's rotation code) and against the beam deformation definitions of
formulation.md §4.2; frames are checked for blankness by their pixel variance.
"""
import base64
import io
import math
import re
import subprocess
import sys

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import animation as mpl_animation  # noqa: E402

import spacar  # noqa: E402
from spacar.geometry import ElementGeometry, Geometry, shapes  # noqa: E402
from support.paths import EXAMPLES  # noqa: E402

Image = pytest.importorskip("PIL.Image")

EXAMPLE = EXAMPLES / "slidercrank.dat"


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def slidercrank():
    return spacar.simulate(spacar.read(EXAMPLE))


# --------------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------------

def cubic_ends(points):
    """End points and end derivatives dr/dξ of a cubic sampled at ξ = linspace(0, 1, n), by a
    least-squares cubic fit (exact for a cubic)."""
    xi = np.linspace(0.0, 1.0, len(points))
    coeffs = [np.polyfit(xi, points[:, j], 3) for j in range(points.shape[1])]
    residual = max(np.abs(np.polyval(c, xi) - points[:, j]).max() for j, c in enumerate(coeffs))
    d = [np.polyder(c) for c in coeffs]
    start = np.array([np.polyval(c, 0.0) for c in coeffs])
    end = np.array([np.polyval(c, 1.0) for c in coeffs])
    return start, end, np.array([np.polyval(c, 0.0) for c in d]), np.array([np.polyval(c, 1.0) for c in d]), residual


def quat_rotate(lam, v):
    """v' = λ ⊗ (0, v) ⊗ λ* (Hamilton product), the rotation of v by unit Euler parameters λ."""
    def mul(a, b):
        a0, av = a[0], np.asarray(a[1:])
        b0, bv = b[0], np.asarray(b[1:])
        return np.concatenate([[a0 * b0 - av @ bv], a0 * bv + b0 * av + np.cross(av, bv)])

    lam = np.asarray(lam) / np.linalg.norm(lam)
    conj = np.concatenate([[lam[0]], -lam[1:]])
    return mul(mul(lam, np.concatenate([[0.0], v])), conj)[1:]


def line_points(line):
    if hasattr(line, "get_data_3d"):
        return np.column_stack(line.get_data_3d())
    return np.column_stack(line.get_data())


def kinds(scene):
    return [(ln.spacar_kind, ln.get_gid()) for ln in scene.lines]


def not_blank(rgb):
    """A frame with a drawing: grey levels vary, and a fair share of pixels differs from the
    background (the most common value)."""
    grey = np.asarray(Image.fromarray(rgb).convert("L"), dtype=float)
    values, counts = np.unique(grey.astype(int), return_counts=True)
    background = values[np.argmax(counts)]
    return grey.std() > 5.0 and np.mean(np.abs(grey - background) > 30) > 0.005


# --------------------------------------------------------------------------------------------
# plot: time histories and one quantity against another
# --------------------------------------------------------------------------------------------

def test_plot_against_time(slidercrank):
    res = slidercrank
    ax = spacar.plot(res, "e(2,2)")
    (line,) = ax.lines
    np.testing.assert_array_equal(line.get_xdata(), res.t)
    np.testing.assert_array_equal(line.get_ydata(), res.deformation(2, 2))
    assert ax.get_xlabel() == "t [s]"
    assert ax.get_ylabel() == "e(2,2): deformation, element 2, deformation 2"


def test_plot_against_another_quantity(slidercrank):
    res = slidercrank
    ax = res.plot(("X", 8, 1), x="XD 2 1", color="k")
    (line,) = ax.lines
    np.testing.assert_array_equal(line.get_xdata(), res.xd[:, res.coordinate_index(2, 1)])
    np.testing.assert_array_equal(line.get_ydata(), res.node(8).x[:, 0])
    assert ax.get_xlabel().startswith("xd(2,1)")


def test_plot_several_quantities_with_a_legend_on_given_axes(slidercrank):
    res = slidercrank
    fig, ax = plt.subplots()
    out = spacar.plot(res, ["s(2,1)", ("REACTION", 1, 1), "EDD 3 3"], ax=ax)
    assert out is ax and len(ax.lines) == 3
    np.testing.assert_array_equal(ax.lines[0].get_ydata(), res.sigma[:, 3])
    np.testing.assert_array_equal(ax.lines[1].get_ydata(), res.reaction[:, 0])
    np.testing.assert_array_equal(ax.lines[2].get_ydata(), res.edd[:, 8])
    assert [t.get_text() for t in ax.get_legend().get_texts()][0].startswith("s(2,1): stress")


# --------------------------------------------------------------------------------------------
# draw: planar mechanisms
# --------------------------------------------------------------------------------------------

@pytest.mark.parametrize("k", [0, 37, 100])
def test_slidercrank_beams_are_cubics_through_the_nodes_with_the_nodal_tangents(slidercrank, k):
    res = slidercrank
    scene = spacar.draw(res, k, beam_points=31)
    # element: (p, rp, q, rq); l0 = 0.15 and reference chord angle 0 (nodes on the x axis)
    for el, (p, rp, q, rq) in {1: (1, 2, 3, 4), 2: (3, 5, 6, 7), 3: (6, 7, 8, 9)}.items():
        (line,) = scene.element_lines(el)
        pts = line_points(line)
        assert pts.shape == (31, 2)
        start, end, d0, d1, residual = cubic_ends(pts)
        assert residual < 1e-12
        np.testing.assert_allclose(start, res.node(p).x[k], atol=1e-12)
        np.testing.assert_allclose(end, res.node(q).x[k], atol=1e-12)
        bp, bq = res.node(rp).x[k, 0], res.node(rq).x[k, 0]
        np.testing.assert_allclose(d0, 0.15 * np.array([math.cos(bp), math.sin(bp)]), atol=1e-10)
        np.testing.assert_allclose(d1, 0.15 * np.array([math.cos(bq), math.sin(bq)]), atol=1e-10)


def bent_plbeam(alpha0=math.radians(30.0), e2=0.05, e3=-0.02):
    """One PLBEAM at 30° from a clamped node, bent by given bending deformations (DYNE at their
    initial values E; no TIMESTEP: one analysis at the current time)."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.x(3, math.cos(alpha0), math.sin(alpha0))
    m.fix(1)
    m.fix(2)
    m.dyne(1, 2, 3)
    m.e(1, 2, e2)
    m.e(1, 3, e3)
    m.emass(1, 1.0)
    m.estiff(1, 0.0, 1.0)
    return spacar.simulate(m)


def test_bent_beam_end_tangents_reproduce_its_bending_deformations():
    alpha0, e2, e3 = math.radians(30.0), 0.05, -0.02
    res = bent_plbeam(alpha0, e2, e3)
    scene = spacar.draw(res)
    start, end, d0, d1, residual = cubic_ends(line_points(scene.element_lines(1)[0]))
    assert residual < 1e-12
    np.testing.assert_allclose(start, [0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(end, res.node(3).x[0], atol=1e-12)
    # tangent at the clamp: the reference direction α0 (β_p = 0); at q: α0 + β_q
    np.testing.assert_allclose(d0, [math.cos(alpha0), math.sin(alpha0)], atol=1e-10)
    bq = alpha0 + res.node(4).x[0, 0]
    np.testing.assert_allclose(d1, [math.cos(bq), math.sin(bq)], atol=1e-10)
    # formulation.md §4.2: e2 = l0 sin(φp − α), e3 = l0 sin(α − φq) with α the chord angle
    chord = end - start
    alpha = math.atan2(chord[1], chord[0])
    phi_p, phi_q = math.atan2(d0[1], d0[0]), math.atan2(d1[1], d1[0])
    assert math.sin(phi_p - alpha) == pytest.approx(e2, abs=1e-9)
    assert math.sin(alpha - phi_q) == pytest.approx(e3, abs=1e-9)
    assert kinds(scene).count(("clamp", "node-1")) == 1    # clamped: a clamp, no pin, no pin support
    assert ("pin", "node-1") not in kinds(scene) and ("ground", "node-1") not in kinds(scene)


def test_symbols_of_the_slidercrank(slidercrank):
    res = slidercrank
    scene = spacar.draw(res, 10)
    ks = kinds(scene)
    assert ("ground", "node-1") in ks                       # FIX 1
    assert ("slider", "node-8") in ks                       # FIX 8 2: slides along x
    assert {g for kind, g in ks if kind == "pin"} == {"node-1", "node-3", "node-8"}
    for ln in scene.lines:
        if ln.spacar_kind in ("pin", "ground", "slider"):
            n = int(ln.get_gid().split("-")[1])
            np.testing.assert_allclose(line_points(ln)[0], res.node(n).x[10], atol=1e-14)
    # slider guide: a horizontal line at y = 0 through the slider's range
    guides = [ln for ln in scene.ax.lines if ln not in scene.lines]
    assert len(guides) == 1
    gx, gy = guides[0].get_data()
    assert np.all(np.asarray(gy) == 0.0)
    assert min(gx) < res.node(8).x[:, 0].min() and max(gx) > res.node(8).x[:, 0].max()


def test_draw_by_time_labels_and_trace(slidercrank):
    res = slidercrank
    scene = spacar.draw(res, time=2.5, labels=True, trace=[6])
    assert scene.ax.get_title() == "t = 2.5 s"
    assert sorted(scene.node_texts) == [1, 3, 6, 8]
    np.testing.assert_allclose(scene.node_texts[6].get_position(), res.node(6).x[50])
    traces = [ln for ln in scene.ax.lines if ln.get_color() == "C3"]
    assert len(traces) == 1 and len(traces[0].get_xdata()) == 101
    # the axes hold every frame of the mechanism
    x0, x1 = scene.ax.get_xlim()
    assert x0 < res.x[:, res.coordinate_index(3, 1)].min() and x1 > res.node(8).x[:, 0].max()
    with pytest.raises(spacar.InputError, match="no node 99"):
        spacar.draw(res, trace=[99])


def test_draw_on_given_axes_and_update(slidercrank):
    res = slidercrank
    fig, ax = plt.subplots()
    scene = spacar.draw(res, 0, ax=ax)
    assert scene.ax is ax
    scene.update(60)
    np.testing.assert_allclose(line_points(scene.element_lines(1)[0])[-1], res.node(3).x[60], atol=1e-12)
    assert ax.get_title() == "t = 3 s"


def test_results_without_geometry_cannot_be_drawn(slidercrank, tmp_path):
    res = spacar.Results({n: getattr(slidercrank, n) for n in ("t", "x", "xd", "xdd", "e", "ed", "edd", "sigma",
                                                                  "reaction")},
                         slidercrank.coordinate_labels, slidercrank.deformation_labels, {})
    with pytest.raises(spacar.InputError, match="no geometry"):
        spacar.draw(res)
    # ... but saved results keep theirs
    slidercrank.save(tmp_path / "r.npz")
    scene = spacar.draw(spacar.Results.load(tmp_path / "r.npz"), 5)
    np.testing.assert_allclose(line_points(scene.element_lines(2)[0])[0], slidercrank.node(3).x[5], atol=1e-12)


# --------------------------------------------------------------------------------------------
# draw: spatial models
# --------------------------------------------------------------------------------------------

def test_spatial_beam_curve_has_the_rotated_end_tangents():
    m = spacar.Model()
    m.beam(1, 1, 2, 3, 4, 0.0, 1.0, 0.0)
    m.x(3, 1.0, 0.0, 0.0)
    m.fix(1)
    m.fix(2)
    m.dyne(1, 3, 4, 5, 6)
    for i, v in ((2, 0.02), (3, 0.15), (4, -0.1), (5, 0.2), (6, 0.1)):
        m.e(1, i, v)
    m.emass(1, 1.0)
    m.estiff(1, 1.0, 1.0, 1.0, 1.0)
    res = spacar.simulate(m)
    scene = spacar.draw(res, beam_points=25)
    assert scene.ax.name == "3d"
    start, end, d0, d1, residual = cubic_ends(line_points(scene.element_lines(1)[0]))
    assert residual < 1e-12
    np.testing.assert_allclose(start, 0.0, atol=1e-12)
    np.testing.assert_allclose(end, res.node(3).x[0], atol=1e-12)
    ex0 = np.array([1.0, 0.0, 0.0])          # reference chord direction, l0 = 1
    np.testing.assert_allclose(d0, ex0, atol=1e-10)          # the clamp keeps λ2 = (1, 0, 0, 0)
    np.testing.assert_allclose(d1, quat_rotate(res.node(4).x[0], ex0), atol=1e-10)
    assert abs(d1 @ [0, 0, 1]) > 0.02 and abs(d1 @ [0, 1, 0]) > 0.02   # bent in both planes


def free_body(n_out=40):
    """A torque-free body on LAMBDA node 1 (tennis-racket spin about the intermediate axis)."""
    m = spacar.Model()
    m.lambda_(1, 1.0, 0.0, 0.0, 0.0)
    m.mass(1, 1.0, 0.0, 0.0, 2.0, 0.0, 3.0)
    m.dynx(1)
    m.xd(1, 2, 0.005)
    m.xd(1, 3, 0.5)
    m.timestep(n_out, 20.0)
    return spacar.simulate(m)


def test_rigid_body_triad_follows_the_euler_parameters():
    res = free_body()
    scene = spacar.draw(res, 25)
    triads = {ln.spacar_kind: line_points(ln) for ln in scene.lines if ln.spacar_kind.startswith("triad")}
    assert sorted(triads) == ["triad-x", "triad-y", "triad-z"]
    lam = res.node(1).x[25]
    for axis, name in enumerate("xyz"):
        p = triads[f"triad-{name}"]
        np.testing.assert_allclose(p[0], 0.0, atol=1e-14)       # no position node: at the origin
        e = np.zeros(3)
        e[axis] = 1.0
        direction = (p[1] - p[0]) / np.linalg.norm(p[1] - p[0])
        np.testing.assert_allclose(direction, quat_rotate(lam, e), atol=1e-9)


def test_heavy_top_is_drawn_in_3d():
    m = spacar.Model()
    m.beam(1, 1, 2, 3, 4, 1.0, 0.0, 0.0)
    m.x(3, 0.0, 0.0, 0.5)
    m.fix(1)
    lam0 = [math.cos(0.25), math.sin(0.25), 0.0, 0.0]
    m.x(2, *lam0)
    m.x(4, *lam0)
    m.dynx(2)
    m.xd(2, 1, 0.0)
    m.mass(3, 1.0)
    m.mass(4, 0.05, 0.0, 0.0, 0.05, 0.0, 0.08)
    m.gravity(0.0, 0.0, -9.81)
    m.timestep(10, 0.5)
    res = spacar.simulate(m)
    scene = spacar.draw(res, 10, labels=True)
    ks = kinds(scene)
    assert ("beam", "element-1") in ks and ("ground", "node-1") in ks and ("pin", "node-1") in ks
    assert ("mass", "node-3") in ks and ("triad-z", "node-4") in ks
    tz = [line_points(ln) for ln in scene.lines if ln.spacar_kind == "triad-z"][0]
    np.testing.assert_allclose(tz[0], res.node(3).x[10], atol=1e-12)   # body frame at the centre of mass
    text = scene.node_texts[3]                                          # a 3-D text: (x, y) and z
    np.testing.assert_allclose([*text.get_position(), text.get_position_3d()[2]], res.node(3).x[10], atol=1e-12)


# --------------------------------------------------------------------------------------------
# shapes of elements the core does not integrate yet (geometry only)
# --------------------------------------------------------------------------------------------

def test_wheel_and_belt_shapes():
    planar = Geometry(
        node_kinds={1: "XY", 2: "BETA", 3: "BETA", 4: "XY", 5: "BETA", 6: "XY", 7: "BETA"},
        elements=[
            ElementGeometry(1, "PLWHEEL", (1, 2, 3), params=(0.3, 1.0, 0.0)),
            ElementGeometry(2, "PLBELT", (4, 5, 6, 7), l0=2.0, lgeomy=(0.0,), params=(0.5, 0.2)),
        ],
    )
    beta = 0.3
    coords = {1: [1.0, 2.0], 2: [beta], 3: [0.7], 4: [0.0, 0.0], 5: [0.1], 6: [2.0, 0.5], 7: [0.2]}
    sh = {(s.kind, s.element): s.points for s in shapes(planar, coords)}
    # PLWHEEL (top view): a segment of length 2r through the centre, along the rolling
    # direction t = (a_y, −a_x) of the rotated axle a = R(β)(1, 0)
    seg = sh[("wheel", 1)]
    np.testing.assert_allclose(seg.mean(axis=0), [1.0, 2.0])
    np.testing.assert_allclose(seg[1] - seg[0], 0.6 * np.array([math.sin(beta), -math.cos(beta)]), atol=1e-14)
    # PLBELT: the free span is tangent to both pulleys (distance from each centre = its radius)
    a, b = sh[("belt", 2)]
    u = (b - a) / np.linalg.norm(b - a)
    for centre, r in (([0.0, 0.0], 0.5), ([2.0, 0.5], 0.2)):
        w = np.asarray(centre) - a
        assert abs(w[0] * u[1] - w[1] * u[0]) == pytest.approx(r, rel=1e-12)
    # WHEEL: a circle of radius r about the centre, in the plane normal to the rotated axle
    spatial = Geometry(node_kinds={10: "XYZ", 11: "LAMBDA"},
                       elements=[ElementGeometry(3, "WHEEL", (10, 11), params=(0.0, 1.0, 0.0, 0.4))])
    lam = np.array([math.cos(0.2), 0.1, 0.0, math.sin(0.2)])
    lam /= np.linalg.norm(lam)
    ring = {(s.kind, s.element): s.points for s in shapes(spatial, {10: [0.0, 0.0, 0.4], 11: lam})}[("wheel", 3)]
    axle = quat_rotate(lam, [0.0, 1.0, 0.0])
    np.testing.assert_allclose(np.linalg.norm(ring - [0.0, 0.0, 0.4], axis=1), 0.4, rtol=1e-12)
    np.testing.assert_allclose((ring - [0.0, 0.0, 0.4]) @ axle, 0.0, atol=1e-12)


# --------------------------------------------------------------------------------------------
# animation
# --------------------------------------------------------------------------------------------

def html_frames(html):
    found = re.findall(r'frames\[(\d+)\] = "data:image/png;base64,([^"]*)"', html)
    return [np.asarray(Image.open(io.BytesIO(base64.b64decode(data.replace("\\\n", "")))).convert("RGB"))
            for _, data in sorted(found, key=lambda f: int(f[0]))]


def test_slidercrank_animation_to_html(slidercrank):
    anim = spacar.animate(slidercrank, step=10)
    assert isinstance(anim, mpl_animation.FuncAnimation)
    html = anim.to_jshtml()
    frames = html_frames(html)
    assert len(frames) == 11                          # output times 0, 10, ..., 100
    assert all(not_blank(f) for f in frames)
    assert not np.array_equal(frames[0], frames[3])   # the mechanism moves
    # inline display in Jupyter: the animation renders itself as HTML/JavaScript
    shown = anim._repr_html_()
    assert "<script" in shown and len(html_frames(shown)) == 11


def test_slidercrank_animation_to_gif(slidercrank, tmp_path):
    path = spacar.save_animation(slidercrank, tmp_path / "slidercrank.gif", step=5)
    with Image.open(path) as gif:
        assert gif.n_frames == 21
        frames = []
        for i in range(gif.n_frames):
            gif.seek(i)
            frames.append(np.asarray(gif.convert("RGB")))
    assert all(not_blank(f) for f in frames)
    assert not np.array_equal(frames[0], frames[7])


def test_animation_to_html_file_and_bad_suffix(slidercrank, tmp_path):
    anim = spacar.animate(slidercrank, step=25, labels=True)
    path = spacar.save_animation(anim, tmp_path / "a.html")
    assert len(html_frames(path.read_text())) == 5
    with pytest.raises(spacar.InputError, match="use .gif, .mp4 or .html"):
        spacar.save_animation(anim, tmp_path / "a.avi")
    with pytest.raises(spacar.InputError, match="unexpected arguments"):
        spacar.save_animation(anim, tmp_path / "b.gif", step=3)


@pytest.mark.skipif(not mpl_animation.writers.is_available("ffmpeg"), reason="ffmpeg is not installed")
def test_slidercrank_animation_to_mp4(slidercrank, tmp_path):
    path = spacar.save_animation(slidercrank, tmp_path / "slidercrank.mp4", step=10)
    assert path.stat().st_size > 1000


def unrendered(anim):
    """An animation inspected but never rendered: tell matplotlib not to warn when it goes."""
    anim._draw_was_started = True
    return anim


def test_animation_frames_and_interval(slidercrank):
    anim = unrendered(spacar.animate(slidercrank, step=7))
    assert list(anim._iter_gen()) == list(range(0, 101, 7)) + [100]
    assert anim._interval == 200.0             # real time (5 s / 15 frames) is slower than 5 frames/s
    assert unrendered(spacar.animate(slidercrank, step=2))._interval == pytest.approx(100.0)   # real time
    many = unrendered(spacar.animate(slidercrank, max_frames=20))
    assert len(list(many._iter_gen())) <= 21
    spatial = spacar.animate(free_body(), step=10)
    frames = html_frames(spatial.to_jshtml())
    assert len(frames) == 5 and all(not_blank(f) for f in frames)


def test_cli_animate_1_writes_a_gif_next_to_the_input(tmp_path):
    text = EXAMPLE.read_text().replace("Timestep 100 5.0", "TIMESTEP 12 3.0").replace("END", "ANIMATE 1\nEND", 1)
    (tmp_path / "in").mkdir()
    path = tmp_path / "in" / "crank.dat"
    path.write_text(text)
    out = subprocess.run([sys.executable, "-m", "spacar", "run", str(path)], capture_output=True, text=True,
                         cwd=tmp_path, check=True)
    gif = tmp_path / "in" / "crank.gif"
    assert f"* animation: {gif} (13 output times)" in out.stdout
    assert re.search(r"^ANIMATE +1$", out.stdout, re.M)   # the dump keeps the setting
    with Image.open(gif) as im:
        assert im.n_frames == 13
        im.seek(6)
        assert not_blank(np.asarray(im.convert("RGB")))


def test_plot_functions_are_reachable_from_the_package():
    for name in ("plot", "draw", "animate", "save_animation"):
        assert callable(getattr(spacar, name))
        assert name in dir(spacar)
    with pytest.raises(AttributeError):
        spacar.no_such_function  # noqa: B018


def test_a_type_without_a_drawing_of_its_own_is_drawn_through_its_position_nodes():
    """Drawing falls back to the line through an element's position nodes (a point for one,
    nothing for none) for a type whose catalogue family has no drawing, also for a type the
    catalogue does not know (a geometry saved by another version)."""
    g = Geometry(node_kinds={1: "XY", 2: "BETA", 3: "XY", 4: "XY", 5: "BETA"},
                 elements=[ElementGeometry(1, "NEWTYPE", (1, 2, 3, 4)), ElementGeometry(2, "NEWTYPE", (4,)),
                           ElementGeometry(3, "NEWTYPE", (2, 5)), ElementGeometry(4, "PLBEAR", (1, 2, 3, 5))])
    coords = {1: np.array([0.0, 0.0]), 2: np.array([0.1]), 3: np.array([1.0, 0.0]), 4: np.array([1.0, 1.0]),
              5: np.array([0.2])}
    drawn = {}
    for s in shapes(g, coords):
        if s.element is not None:
            drawn.setdefault(s.element, []).append((s.kind, s.points.tolist()))
    assert drawn == {1: [("link", [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])], 2: [("point", [[1.0, 1.0]])],
                     4: [("link", [[0.0, 0.0], [1.0, 0.0]])]}


# --------------------------------------------------------------------------------------------
# drawings that teach: clamps, rigid bodies, magnified deflections, labels off the symbols
# --------------------------------------------------------------------------------------------

def fourbar_with_coupler_triangle(n_out=24):
    """A Grashof crank-rocker A(0,0) B(0.1,0) C(0.3,0.2) D(0.35,0) with the coupler point E
    (0.25, 0.35) on a second rigid PLBEAM from B that shares the coupler's BETA node 5."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.plbeam(2, 3, 5, 6, 7)
    m.plbeam(3, 6, 8, 9, 10)
    m.plbeam(4, 3, 5, 11, 12)
    m.x(3, 0.1, 0.0)
    m.x(6, 0.3, 0.2)
    m.x(9, 0.35, 0.0)
    m.x(11, 0.25, 0.35)
    m.fix(1)
    m.fix(9)
    m.inputx(2, 1)
    m.xd(2, 1, 1.0)
    m.timestep(n_out, 2 * math.pi)
    return spacar.simulate(m)


def test_a_rigid_coupler_triangle_is_one_filled_body_that_moves_with_its_nodes():
    res = fourbar_with_coupler_triangle()
    scene = spacar.draw(res, 5)
    bodies = [a for a in scene.lines if a.spacar_kind == "body"]
    assert [b.get_gid() for b in bodies] == ["body-5"]            # one body, named by its BETA node
    assert isinstance(bodies[0], matplotlib.patches.Polygon) and bodies[0].get_fill()
    for k in (5, 17):
        scene.update(k)
        outline = bodies[0].get_xy()
        np.testing.assert_allclose(outline[0], outline[-1])          # closed
        corners = np.array([res.node(n).x[k] for n in (3, 6, 11)])
        assert len(outline) == 4
        for c in corners:                                             # through B, C and E
            assert np.min(np.linalg.norm(outline[:-1] - c, axis=1)) < 1e-12
    # the two ground pivots are pins on ground triangles (their BETA nodes turn), not clamps
    ks = kinds(scene)
    assert {("pin", "node-1"), ("ground", "node-1"), ("pin", "node-9"), ("ground", "node-9")} <= set(ks)
    assert not [k for k, _ in ks if k == "clamp"]


def test_bars_of_two_nodes_and_the_slider_crank_have_no_body(slidercrank):
    assert not [a for a in spacar.draw(slidercrank, 3).lines if a.spacar_kind == "body"]


def test_a_clamp_is_a_wall_across_the_beam_hatched_on_the_far_side():
    alpha0 = math.radians(30.0)
    scene = spacar.draw(bent_plbeam(alpha0))
    (clamp,) = [ln for ln in scene.lines if ln.spacar_kind == "clamp"]
    pts = line_points(clamp)
    pieces = [p for p in np.split(pts, np.where(np.isnan(pts[:, 0]))[0]) if len(p)]
    pieces = [p[~np.isnan(p[:, 0])] for p in pieces]
    wall, strokes = pieces[0], pieces[1:]
    d = np.array([math.cos(alpha0), math.sin(alpha0)])               # the beam leaves the clamp along α0
    assert abs((wall[1] - wall[0]) @ d) < 1e-12                       # the wall is across the beam
    np.testing.assert_allclose(wall.mean(axis=0), [0.0, 0.0], atol=1e-12)
    assert len(strokes) >= 4
    for s in strokes:
        assert (s[1] - s[0]) @ d < 0                                  # hatching behind the wall


def test_magnified_deflection_of_a_clamped_beam():
    """A clamped beam's rigid-body motion is none: the drawn tip is the reference tip plus
    ``magnify`` times its displacement and the tip slope turns ``magnify`` times as far."""
    alpha0, m = math.radians(30.0), 10.0
    res = bent_plbeam(alpha0)
    plain = line_points(spacar.draw(res).element_lines(1)[0])
    scene = spacar.draw(res, magnify=m, beam_points=31)
    start, end, d0, d1, residual = cubic_ends(line_points(scene.element_lines(1)[0]))
    assert residual < 1e-12
    reference_tip = np.array([math.cos(alpha0), math.sin(alpha0)])    # l0 = 1
    np.testing.assert_allclose(start, 0.0, atol=1e-12)
    np.testing.assert_allclose(end, reference_tip + m * (res.node(3).x[0] - reference_tip), atol=1e-12)
    bq = alpha0 + m * res.node(4).x[0, 0]
    np.testing.assert_allclose(d1 / np.linalg.norm(d1), [math.cos(bq), math.sin(bq)], atol=1e-10)
    np.testing.assert_allclose(d0, [math.cos(alpha0), math.sin(alpha0)], atol=1e-10)
    assert np.abs(plain - line_points(spacar.draw(res, magnify=1.0).element_lines(1)[0])).max() == 0.0
    with pytest.raises(spacar.InputError, match="magnify must be a positive number"):
        spacar.draw(res, magnify=0)


def test_magnify_keeps_rigid_mechanisms_and_their_motion(slidercrank):
    """The slider-crank's flexible coupler and rocker move with their root ends: magnified, the
    crank (rigid) is unchanged and the magnified deflection is m times the drawn one's
    deviation from the rigid motion."""
    res = slidercrank
    k, m = 40, 20.0
    a = spacar.draw(res, k)
    b = spacar.draw(res, k, magnify=m)
    np.testing.assert_array_equal(line_points(a.element_lines(1)[0]), line_points(b.element_lines(1)[0]))
    # element 2 (3 -> 6) moves with node 3 and BETA 5: rigid position of node 6 is 3 + R(β5) l0 e_x
    x3, b5 = res.node(3).x[k], res.node(5).x[k, 0]
    rigid6 = x3 + 0.15 * np.array([math.cos(b5), math.sin(b5)])
    np.testing.assert_allclose(line_points(b.element_lines(2)[0])[-1], rigid6 + m * (res.node(6).x[k] - rigid6),
                               atol=1e-12)


def overlaps(a, b):
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


def test_node_labels_stay_off_the_symbols(slidercrank):
    from matplotlib.transforms import Bbox

    res = slidercrank
    for k in (0, 30, 60):
        scene = spacar.draw(res, k, labels=True)
        fig = scene.ax.figure
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        symbols = [ln for ln in scene.lines if ln.get_marker() not in (None, "None", "")]
        for n, text in scene.node_texts.items():
            tb = text.get_window_extent(renderer)
            for ln in symbols:
                x, y = scene.ax.transData.transform(line_points(ln)[0])
                half = ln.get_markersize() / 2 * fig.dpi / 72.0
                assert not overlaps(tb, Bbox.from_extents(x - half, y - half, x + half, y + half)), (n, ln.get_gid())


def test_3d_tick_labels_do_not_collide():
    """The spatial slider-crank at the animation's figure size: matplotlib's default ticks put
    the x labels -0.1 and 0.0 on top of each other; no two tick or axis labels overlap."""
    res = spacar.simulate(spacar.read(EXAMPLES / "slidercrank3d.dat"))
    for k in (0, -1):
        scene = spacar.draw(res, k, figsize=(6.0, 4.5), labels=True)
        fig = scene.ax.figure
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        boxes = []
        for axis in (scene.ax.xaxis, scene.ax.yaxis, scene.ax.zaxis):
            lo, hi = sorted(axis.get_view_interval())
            shown = [t.label1 for t in axis.get_major_ticks() if lo - 1e-12 <= t.get_loc() <= hi + 1e-12]
            assert len(shown) >= 2
            boxes += [(axis.axis_name, t.get_text(), t.get_window_extent(renderer)) for t in shown]
            boxes.append((axis.axis_name, "label", axis.label.get_window_extent(renderer)))
        for i in range(len(boxes)):
            for j in range(i + 1, len(boxes)):
                assert not overlaps(boxes[i][2], boxes[j][2]), (boxes[i][:2], boxes[j][:2])


# --------------------------------------------------------------------------------------------
# mode-shape animation, the offline player
# --------------------------------------------------------------------------------------------

def clamped_beam_mesh(n=4):
    """A cantilever of n PLBEAMs (L = 1, EI = 1, m = 1 per length): f1 = 1.8751² / 2π Hz
    (Euler-Bernoulli)."""
    m = spacar.Model()
    for i in range(n):
        m.plbeam(i + 1, 2 * i + 1, 2 * i + 2, 2 * i + 3, 2 * i + 4)
        m.x(2 * i + 3, (i + 1) / n, 0.0)
        m.dyne(i + 1, 2, 3)
        m.emass(i + 1, 1.0)
        m.estiff(i + 1, 0.0, 1.0)
    m.fix(1)
    m.fix(2)
    return m


def test_mode_animation_swings_the_hermite_shape_of_the_mode():
    model = clamped_beam_mesh()
    anim = unrendered(spacar.animate_mode(model, 0, frames=8))
    scene = anim.scene
    f1 = 1.8751040687**2 / (2 * math.pi)
    assert float(scene.ax.get_title().split()[2]) == pytest.approx(f1, rel=2e-3)
    assert list(anim._iter_gen()) == list(range(8))
    freqs, _, shapes_x = spacar.linearize(model).mode_shapes()
    res = scene.res
    tip = res.coordinate_index(9, 2)
    rest = (res.x[0] + res.x[4]) / 2                                # cos(0) = 1, cos(π) = −1
    amplitude = res.x[0, tip] - rest[tip]                           # the first frame at the peak
    assert abs(amplitude) > 0.05
    for j in range(8):
        scene.update(j)
        s = math.cos(2 * math.pi * j / 8)
        np.testing.assert_allclose(res.x[j], rest + s * (res.x[0] - rest), atol=1e-12)
        # each beam: the cubic through its displaced nodes with its displaced end slopes
        for el in range(1, 5):
            p, rp, q, rq = 2 * el - 1, 2 * el, 2 * el + 1, 2 * el + 2
            start, end, d0, d1, residual = cubic_ends(line_points(scene.element_lines(el)[0]))
            assert residual < 1e-12
            np.testing.assert_allclose(start, res.node(p).x[j], atol=1e-12)
            np.testing.assert_allclose(end, res.node(q).x[j], atol=1e-12)
            for d, b in ((d0, res.node(rp).x[j, 0]), (d1, res.node(rq).x[j, 0])):
                np.testing.assert_allclose(d, 0.25 * np.array([math.cos(b), math.sin(b)]), atol=1e-12)
    # the displacement is the mode's nodal shape
    dx = res.x[0] - rest
    np.testing.assert_allclose(dx / dx[tip], shapes_x[:, 0] / shapes_x[tip, 0], atol=1e-10)


def test_mode_animation_errors(slidercrank):
    with pytest.raises(spacar.InputError, match="no linearizations"):
        spacar.animate_mode(slidercrank)
    with pytest.raises(spacar.InputError, match="mode must be a mode number 0..3"):
        spacar.animate_mode(clamped_beam_mesh(2), 4)
    with pytest.raises(spacar.InputError, match="no geometry"):
        spacar.animate_mode(spacar.linearize(clamped_beam_mesh(2)))


def test_the_html_player_needs_no_network(slidercrank, tmp_path):
    """matplotlib's player loads Font Awesome from a CDN; spacar's is self-contained."""
    anim = spacar.animate(slidercrank, step=50)
    for html in (anim.to_jshtml(), anim._repr_html_(),
                 spacar.save_animation(anim, tmp_path / "a.html").read_text(encoding="utf-8")):
        assert not re.search(r"https?://", html)
        assert 'class="fa' not in html and "\u25b6" in html           # the play button: a Unicode triangle
        assert len(html_frames(html)) == 3

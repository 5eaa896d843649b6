"""Stress where it is (issue 39): spacar.draw and spacar.view3d colour each beam by its largest
stress from spacar.section.stresses and mark the most stressed one. The guide's leaves bent
S-shaped by a drive force carry their largest bending stress, 3Etu/L², at both ends and none at
the middle, where the colours must say so."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib import colormaps  # noqa: E402

import spacar  # noqa: E402
from spacar import flexure, section  # noqa: E402

LEAF = section.rectangle(b=0.02, h=0.0005, material=section.STEEL)


def driven_guide(spatial=False):
    fx = flexure.Flexure(spatial=spatial)
    stage = fx.body(at=(0.015, 0.05, 0.0) if spatial else (0.015, 0.05))
    for x0 in (0.0, 0.03):
        a, b = ((x0, 0.0, 0.0), (x0, 0.05, 0.0)) if spatial else ((x0, 0.0), (x0, 0.05))
        fx.leaf_spring(fx.ground, stage, a, b, LEAF, n=8, **({"thickness": (1, 0, 0)} if spatial else {}))
    m = fx.model()
    m.force(stage.node, *((1.0, 0.0, 0.0) if spatial else (1.0, 0.0)))
    res = spacar.static(m, steps=2)
    leaves = [e for f in fx.flexures for e in f.elements]
    return res, section.stresses(res, {e: LEAF for e in leaves}), leaves


def test_stresses_at_an_output():
    res, s, leaves = driven_guide()
    normal, shear = s.at(-1), s.at(-1, "shear")
    assert list(normal) == leaves
    assert normal[leaves[0]] == pytest.approx(s.normal[-1, 0]) and shear[leaves[0]] == pytest.approx(s.shear[-1, 0])
    vm = s.at(1, "von_mises")
    assert vm[leaves[3]] == pytest.approx(np.hypot(s.normal[1, 3], np.sqrt(3) * s.shear[1, 3]))
    with pytest.raises(spacar.InputError, match="kind must be one of"):
        s.at(0, "tresca")


def test_draw_colours_each_leaf_by_its_stress_and_marks_the_peak():
    res, s, leaves = driven_guide()
    scene = spacar.draw(res, stress=s)
    values = s.at(-1)
    top = max(values.values())
    cmap = colormaps["plasma"]
    coloured = {}
    for line in scene.lines:
        gid = line.get_gid() or ""
        if gid.startswith("element-"):
            coloured[int(gid[8:])] = matplotlib.colors.to_rgba(line.get_color())
    for e in leaves:
        np.testing.assert_allclose(coloured[e], cmap(values[e] / top), atol=1e-12)
    # The moment falls linearly from the clamp to zero at the leaf's middle: element 4 of 8
    # (from 3L/8 to L/2) carries a quarter of the clamp's stress at its larger end.
    assert values[leaves[0]] == pytest.approx(4 * values[leaves[3]], rel=2e-2)
    assert scene.stress_peak == (max(values, key=values.get), top)
    assert scene.colorbar is not None and "normal stress" in scene.colorbar.ax.get_ylabel()


def test_draw_in_3d_and_bad_stresses():
    res, s, leaves = driven_guide(spatial=True)
    scene = spacar.draw(res, stress=s, stress_kind="von_mises")
    assert scene.stress_peak[0] in leaves
    other, _, _ = driven_guide()
    one_output = section.stresses(other, LEAF)
    one_output.t = one_output.t[:1]
    with pytest.raises(spacar.InputError, match="other results"):
        spacar.draw(other, stress=one_output)
    with pytest.raises(spacar.InputError, match="stresses of these results"):
        spacar.draw(other, stress={1: 2.0})
    with pytest.raises(spacar.InputError, match="colour map"):
        spacar.draw(other, stress=section.stresses(other, LEAF), cmap="no such map")


def test_view3d_colours_and_marks_the_peak():
    pytest.importorskip("plotly")
    res, s, leaves = driven_guide(spatial=True)
    fig = spacar.view3d(res, stress=s)
    names = [t.name for t in fig.data]
    values = s.at(-1)
    peak = max(values, key=values.get)
    assert any(n and n.startswith(f"beam element {peak}:") for n in names)
    assert "peak" in names
    assert any(getattr(t.marker, "showscale", False) for t in fig.data)   # the colour bar


def test_view3d_animates_a_mode_from_its_peak():
    """view3d(res, mode=..., frames=n): n plotly frames of the state plus cos(2πj/n) times the
    mode, the still picture at the peak, a play button; a still picture with frames=0."""
    pytest.importorskip("plotly")
    m = spacar.Model()
    for k in range(4):
        m.plbeam(k + 1, 2 * k + 1, 2 * k + 2, 2 * k + 3, 2 * k + 4)
        m.x(2 * k + 3, (k + 1) / 4, 0.0)
        m.dyne(k + 1, 2, 3)
        m.emass(k + 1, 1.0)
        m.estiff(k + 1, 0.0, 1.0)
    m.fix(1)
    m.fix(2)
    res = spacar.static(m)
    shape = spacar.linearize(m).mode_shapes(1)[2][:, 0]
    fig = spacar.view3d(res, mode=shape, frames=8)
    assert len(fig.frames) == 8 and fig.layout.updatemenus[0].buttons[0].label == "play"
    tip_y = lambda data: next(abs(t.y[-1]) for t in data if t.name == "beam element 4")  # noqa: E731
    assert tip_y(fig.data) == pytest.approx(tip_y(fig.frames[0].data)) and tip_y(fig.data) > 0.05
    assert tip_y(fig.frames[2].data) < 1e-9 * tip_y(fig.data) + 1e-12     # cos(π/2): at rest
    still = spacar.view3d(res, mode=shape)
    assert not still.frames and tip_y(still.data) == pytest.approx(tip_y(fig.data))
    with pytest.raises(spacar.InputError, match="frames must be a whole number from 2 to 1000"):
        spacar.view3d(res, mode=shape, frames=1)
    for bad, match in ((dict(mode="abc"), "mode must hold"), (dict(mode=shape, scale=np.inf), "scale must be a finite"),
                       (dict(mode=shape, scale="big"), "scale must be a finite"), (dict(frames=24), "give mode= too")):
        with pytest.raises(spacar.InputError, match=match):
            spacar.view3d(res, **bad)

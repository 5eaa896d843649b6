"""spacar.explore (ipywidgets, headless) and spacar.view3d (plotly; matplotlib without it).

Independent references: the four-bar drawn at a crank angle is checked by its loop closure
(crank end on the crank circle at that angle, coupler and rocker lengths kept, the coupler point
rigidly attached), not against spacar's own runs.
"""
import math
import re
import sys

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import spacar  # noqa: E402
from spacar.interactive import Explorer  # noqa: E402

A, B, C, D, E = (np.array(p) for p in ([0.0, 0.0], [0.1, 0.0], [0.3, 0.2], [0.35, 0.0], [0.25, 0.35]))


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


@pytest.fixture
def widgets():
    return pytest.importorskip("ipywidgets")


def fourbar(timestep=False):
    """Crank AB (input BETA 2), coupler BC with the coupler point E on a second rigid beam
    sharing the coupler's BETA node 5, rocker CD."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.plbeam(2, 3, 5, 6, 7)
    m.plbeam(3, 6, 8, 9, 10)
    m.plbeam(4, 3, 5, 11, 12)
    for n, p in ((3, B), (6, C), (9, D), (11, E)):
        m.x(n, *p)
    m.fix(1)
    m.fix(9)
    m.inputx(2, 1)
    m.xd(2, 1, 1.0)
    if timestep:
        m.timestep(24, 2 * math.pi)
    return m


def line_points(line):
    return np.column_stack(line.get_data())


def drawn_nodes(scene):
    """Positions of B, C, E as drawn: the ends of the beams' curves."""
    b = line_points(scene.element_lines(1)[0])[-1]
    c = line_points(scene.element_lines(2)[0])[-1]
    e = line_points(scene.element_lines(4)[0])[-1]
    return b, c, e


def test_the_crank_slider_solves_the_four_bar_at_that_angle(widgets):
    w = spacar.explore(fourbar(), trace=[11], quantity="x(10,1)", points=25)
    assert isinstance(w, widgets.VBox)
    ex = w.explorer
    assert list(ex.sliders) == ["x(2,1)"] and ex.sliders["x(2,1)"].max == pytest.approx(2 * math.pi)
    assert ex.image.value[:8] == b"\x89PNG\r\n\x1a\n"
    for theta in (0.7, 2.5, 4.0, 5.9):
        before = ex.image.value
        ex.sliders["x(2,1)"].value = theta
        assert ex.value == theta and ex.image.value != before and ex.message.value == ""
        b, c, e = drawn_nodes(ex.scene)
        np.testing.assert_allclose(b, 0.1 * np.array([math.cos(theta), math.sin(theta)]), atol=1e-9)
        assert np.linalg.norm(c - b) == pytest.approx(np.linalg.norm(C - B), abs=1e-9)
        assert np.linalg.norm(c - D) == pytest.approx(np.linalg.norm(C - D), abs=1e-9)
        assert np.linalg.norm(e - b) == pytest.approx(np.linalg.norm(E - B), abs=1e-9)
        assert np.linalg.norm(e - c) == pytest.approx(np.linalg.norm(E - C), abs=1e-9)
        # the live plot's marker: the rocker's angle (BETA 10) at the drawn state
        mx, my = ex.marker.get_data()
        assert mx[0] == theta and my[0] == pytest.approx(ex.state.node(10).x[0, 0], abs=1e-12)
        assert ex.scene.ax.get_title() == f"x(2,1) = {theta:.4g}"
    # the coupler curve over the whole turn: E's path, closed
    (path,) = [ln for ln in ex.scene.ax.lines if ln.get_color() == "C3"]
    xy = line_points(path)
    assert len(xy) == 25
    np.testing.assert_allclose(xy[0], xy[-1], atol=1e-9)
    assert [a for a in ex.scene.lines if a.spacar_kind == "body"]          # the coupler triangle


def test_a_parameter_slider_changes_the_geometry(widgets):
    ex = spacar.explore(fourbar(), parameters={"x(3,1)": (0.06, 0.12)}, points=13).explorer
    assert ex.sliders["x(3,1)"].value == pytest.approx(0.1)
    ex.sliders["x(2,1)"].value = 1.0
    ex.set_parameter("x(3,1)", 0.08)                                     # a shorter crank
    b, c, _ = drawn_nodes(ex.scene)
    np.testing.assert_allclose(b, 0.08 * np.array([math.cos(1.0), math.sin(1.0)]), atol=1e-9)
    new_coupler = np.linalg.norm(C - [0.08, 0.0])                        # the reference geometry moved B
    assert np.linalg.norm(c - b) == pytest.approx(new_coupler, abs=1e-9)
    # a function of the model as a parameter: the rocker's pivot
    ex = spacar.explore(fourbar(), parameters={"pivot": (0.3, 0.4, lambda m, v: m.x(9, v, 0.0))}, points=7).explorer
    ex.set_parameter("pivot", 0.38)
    ex.sliders["x(2,1)"].value = 2.0
    b, c, _ = drawn_nodes(ex.scene)
    assert np.linalg.norm(c - [0.38, 0.0]) == pytest.approx(np.linalg.norm(C - [0.38, 0.0]), abs=1e-9)


def test_exploring_results_runs_through_the_output_times(widgets):
    res = spacar.simulate(fourbar(timestep=True))
    ex = spacar.explore(res, trace=[11], quantity="x(10,1)").explorer
    assert list(ex.sliders) == ["t"] and ex.sliders["t"].max == 24
    ex.sliders["t"].value = 9
    np.testing.assert_allclose(drawn_nodes(ex.scene)[0], res.node(3).x[9], atol=1e-12)
    assert ex.marker.get_data()[0][0] == res.t[9]
    assert ex.scene.ax.get_title() == f"t = {res.t[9]:.4g} s"


def test_explore_errors(widgets):
    no_input = spacar.Model()
    no_input.plbeam(1, 1, 2, 3, 4)
    no_input.x(3, 1.0, 0.0)
    no_input.fix(1)
    no_input.fix(2)
    with pytest.raises(spacar.InputError, match="no input motion"):
        spacar.explore(no_input)
    with pytest.raises(spacar.InputError, match=r"x\(10,1\) is not an input motion.*its inputs: x\(2,1\)"):
        spacar.explore(fourbar(), input=(10, 1))
    with pytest.raises(spacar.InputError, match="need a Model"):
        spacar.explore(spacar.simulate(fourbar(timestep=True)), parameters={"x(3,1)": (0.0, 1.0)})
    with pytest.raises(spacar.InputError, match="name a node coordinate"):
        spacar.explore(fourbar(), parameters={"e(1,1)": (0.0, 1.0)})
    with pytest.raises(spacar.InputError, match="spacar.Model or spacar.Results"):
        spacar.explore(42)


def test_explore_without_ipywidgets_says_what_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "ipywidgets", None)
    with pytest.raises(ImportError, match=r"pip install ipywidgets .*\.\[classroom\]"):
        Explorer(fourbar())


def test_an_input_deformation_of_a_spatial_mechanism(widgets):
    """The 3-D slider-crank is driven by its hinge angle (INPUTE 4 1): the slider turns it, the
    crank end (crank 0.15) lies on the crank circle at that angle in the x-y plane, and the
    slider follows from the rod's length (0.3, nodes 3-6-8 welded by LAMBDA 7)."""
    from support.paths import EXAMPLES

    ex = spacar.explore(spacar.read(EXAMPLES / "slidercrank3d.dat"), quantity="x(8,1)", trace=[6], points=9).explorer
    assert list(ex.sliders) == ["e(4,1)"] and ex.scene.ax.name == "3d"
    ex.sliders["e(4,1)"].value = 1.0
    np.testing.assert_allclose(ex.state.node(3).x[0], [0.15 * math.cos(1.0), 0.15 * math.sin(1.0), 0.0], atol=1e-9)
    x8 = ex.state.node(8).x[0, 0]                      # slider: 0.15 cos θ + sqrt(0.3² − (0.15 sin θ)²)
    assert x8 == pytest.approx(0.15 * math.cos(1.0) + math.sqrt(0.3**2 - (0.15 * math.sin(1.0))**2), abs=1e-9)
    assert ex.marker.get_data()[1][0] == pytest.approx(x8, abs=1e-12)


# --------------------------------------------------------------------------------------------
# view3d
# --------------------------------------------------------------------------------------------

def spatial_cantilever():
    m = spacar.Model()
    m.beam(1, 1, 2, 3, 4, 0.0, 1.0, 0.0)
    m.x(3, 0.7, 0.3, 0.4)
    m.fix(1)
    m.fix(2)
    return spacar.simulate(m)


def test_view3d_is_a_plotly_figure_of_the_shapes():
    pytest.importorskip("plotly")
    res = spatial_cantilever()
    fig = spacar.view3d(res)
    names = [t.name for t in fig.data]
    assert "beam element 1" in names and "clamp node 1" in names
    beam = fig.data[names.index("beam element 1")]
    np.testing.assert_allclose([beam.x[0], beam.y[0], beam.z[0]], 0.0, atol=1e-14)
    np.testing.assert_allclose([beam.x[-1], beam.y[-1], beam.z[-1]], res.node(3).x[0], atol=1e-12)


def test_view3d_falls_back_to_matplotlib(monkeypatch):
    monkeypatch.setitem(sys.modules, "plotly", None)
    monkeypatch.setitem(sys.modules, "plotly.graph_objects", None)
    scene = spacar.view3d(spatial_cantilever())
    assert scene.ax.name == "3d" and scene.element_lines(1)


def test_a_dead_position_is_named_and_the_explorer_moves_on(widgets):
    """A crank of 0.2 (non-Grashof with these links: s + l = 0.55 > p + q = 0.43) cannot turn
    fully: the range reached and the failing value are said; values inside it still solve."""
    m = fourbar()
    m.x(3, 0.2, 0.0)
    ex = spacar.explore(m, points=41).explorer
    assert ex.samples[-1] < 2 * math.pi - 1
    assert re.match(r"x\(2,1\) moves from 0 to [\d.]+ only: x\(2,1\) = [\d.]+ not reached", ex.message.value)
    ex.set_input(3.0)
    assert "x(2,1) = 3 not reached" in ex.message.value
    ex.set_input(0.5)
    np.testing.assert_allclose(ex.state.node(3).x[0], 0.2 * np.array([math.cos(0.5), math.sin(0.5)]), atol=1e-9)
    assert ex.message.value == ex.note          # back to the note on the range reached

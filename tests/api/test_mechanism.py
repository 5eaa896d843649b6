"""spacar.mechanism (issue 41): the vocabulary of a mechanisms course, each helper against its
closed form: the Grashof classes, the limit and toggle positions and the transmission angle of
four-bars (examples/fourbar_coupler.dat among them) found along the input by the kinematic
analysis, the instant centres of a slider-crank against the Aronhold–Kennedy construction, and a
four-bar synthesized by Freudenstein's three-point method passing its precision points."""
from __future__ import annotations

import math

import numpy as np
import pytest

import spacar
from spacar.mechanism import FourBar, dead_positions, instant_centres, limit_positions, synthesize, transmission_angle
from support.paths import EXAMPLES


@pytest.mark.parametrize("lengths, kind", [
    ((0.1, 0.35, 0.30, 0.40), "crank-rocker"),
    ((0.35, 0.30, 0.40, 0.1), "double-crank"),      # the ground the shortest: a drag link
    ((0.35, 0.1, 0.30, 0.40), "double-rocker"),     # the coupler the shortest
    ((0.3, 0.35, 0.30, 0.40), "triple-rocker"),     # s + l > p + q
    ((0.2, 0.4, 0.3, 0.3), "change point"),         # s + l = p + q
])
def test_grashof_classes(lengths, kind):
    g = FourBar(*lengths).grashof()
    assert g.kind == kind and g.grashof == (kind != "triple-rocker")
    assert (g.s, g.l) == (min(lengths), max(lengths))


def coupler_example():
    """examples/fourbar_coupler.dat: A (0, 0), B (0, 1), C (3, 3), D (4, 0); the crank starts at 90°."""
    return spacar.read(EXAMPLES / "fourbar_coupler.dat"), FourBar(1.0, math.sqrt(13.0), math.sqrt(10.0), 4.0)


def test_the_example_four_bar_s_limit_positions_are_the_closed_form():
    model, fb = coupler_example()
    assert fb.grashof().kind == "crank-rocker"
    B, C = fb.points(math.pi / 2)
    np.testing.assert_allclose(C, [3.0, 3.0], atol=1e-14)  # the assembly of the example
    found = limit_positions(model, (9, 1), steps=36)        # the rocker's rotation (BETA 9 at D)
    expected = sorted(fb.limit_positions(), key=lambda p: (p[0] - math.pi / 2) % (2 * math.pi))
    assert len(found) == 2
    psi0 = float(fb.rocker_angle(math.pi / 2))
    for (t, crank, rocker), (theta, psi) in zip(found, expected):
        assert math.remainder(math.pi / 2 + crank - theta, 2 * math.pi) == pytest.approx(0.0, abs=1e-10)
        assert math.remainder(psi0 + rocker - psi, 2 * math.pi) == pytest.approx(0.0, abs=1e-10)
        assert fb.freudenstein(theta, psi) == pytest.approx(0.0, abs=1e-12)


def test_transmission_angle_along_a_turn_is_the_closed_form():
    fb = FourBar(0.10, 0.35, 0.30, 0.40)
    model = fb.model(steps=72)
    path = spacar.transfer_path(model, steps=72)
    mu = transmission_angle(path, 2, 3, model=model)        # coupler B→C, rocker D→C
    np.testing.assert_allclose(mu, fb.transmission_angle(path.q[:, 0]), rtol=0, atol=1e-12)
    psi = fb.rocker_angle(path.q[:, 0])
    np.testing.assert_allclose(fb.freudenstein(path.q[:, 0], psi), 0.0, atol=1e-12)
    with pytest.raises(spacar.InputError, match="pass model="):
        transmission_angle(path, 2, 3)


@pytest.mark.parametrize("lengths", [(0.1, 0.35, 0.30, 0.40), (0.3, 0.1, 0.35, 0.4)], ids=["a < b", "a > b"])
@pytest.mark.parametrize("branch", [1, -1])
def test_limit_positions_are_where_the_rocker_reverses(lengths, branch):
    """Both limit positions (crank and coupler extended and folded; folded with AC = |b − a|, also
    when the crank is the longer) against the extremes of ψ(θ) sampled finely."""
    fb = FourBar(*lengths, branch=branch)
    found = fb.limit_positions()
    assert len(found) == 2
    for theta, psi in found:
        h = 1e-4
        before, at, after = fb.rocker_angle(np.array([theta - h, theta, theta + h]))
        assert (at - before) * (after - at) <= 0  # ψ reverses there
        assert at == pytest.approx(psi, abs=1e-12) and fb.freudenstein(theta, psi) == pytest.approx(0.0, abs=1e-12)


def test_a_non_grashof_linkage_s_limit_position_found_along_its_input_is_the_closed_form():
    """Issue 41: the triple-rocker (non-Grashof: no link turns fully) driven by its crank within
    the toggle positions (±2.373 rad): the rocker reverses once, where the crank and the coupler
    are in line; spacar's kinematics finds it along the crank's motion as the closed form puts it."""
    fb = FourBar(0.3, 0.35, 0.30, 0.40)
    assert fb.grashof().kind == "triple-rocker" and not fb.grashof().grashof
    theta0 = -2.0
    assert theta0 > -max(fb.toggle_positions())
    model = fb.model(theta0=theta0, steps=72)
    found = limit_positions(model, (9, 1), steps=72, t_end=4.0)     # θ from −2 to 2, inside the toggles
    (theta, psi), = fb.limit_positions()
    assert len(found) == 1
    t, crank, rocker = found[0]
    psi0 = float(fb.rocker_angle(theta0))
    assert theta0 + crank - theta == pytest.approx(0.0, abs=1e-10)
    assert math.remainder(psi0 + rocker - psi, 2 * math.pi) == pytest.approx(0.0, abs=1e-10)


def test_a_non_grashof_linkage_s_toggle_positions_end_its_crank_s_range():
    """A triple-rocker: its crank cannot turn fully; at the toggle positions the coupler and the
    rocker are in line (transmission angle 0 or π) and the loop closes there and nowhere beyond."""
    fb = FourBar(0.3, 0.35, 0.30, 0.40)
    assert fb.grashof().kind == "triple-rocker"
    toggles = fb.toggle_positions()
    assert len(toggles) >= 2
    for theta in toggles:
        mu = fb.transmission_angle(theta)
        assert min(mu, math.pi - mu) == pytest.approx(0.0, abs=1e-7)  # arccos near ±1: √ε
        B, C = fb.points(theta)
        u, v = C - B, C - np.array([fb.d, 0.0])
        cross = u[0] * v[1] - u[1] * v[0]
        assert cross == pytest.approx(0.0, abs=1e-7)
        beyond = theta + 1e-3 * np.sign(theta)
        assert not np.isfinite(fb.points(beyond)[1]).all()  # past the toggle the loop cannot close


@pytest.mark.parametrize("lengths, theta0", [((0.3, 0.35, 0.30, 0.40), 0.0), ((0.2, 0.5, 0.2, 0.3), math.pi)])
@pytest.mark.parametrize("rate", [1.0, -1.0])
def test_dead_positions_found_along_the_input_are_the_toggle_positions(lengths, theta0, rate):
    """Issue 41: a non-Grashof crank driven until it can go no further; the kinematics fails past
    the toggle, and dead_positions locates it: the closed form's toggle position to 1e-10."""
    fb = FourBar(*lengths)
    assert not fb.grashof().grashof
    model = fb.model(theta0=theta0, rate=rate, steps=360)
    (t, value), = dead_positions(model)
    ahead = min(fb.toggle_positions(), key=lambda th: ((th - theta0) * rate) % (2 * math.pi))
    assert math.remainder(theta0 + value - ahead, 2 * math.pi) == pytest.approx(0.0, abs=1e-10)
    assert t == pytest.approx(value / rate, abs=1e-10)           # the crank's angle is rate × t
    inside, beyond = theta0 + value - 1e-6 * rate, theta0 + value + 1e-6 * rate
    assert np.isfinite(fb.points(inside)[1]).all() and not np.isfinite(fb.points(beyond)[1]).all()


def test_dead_positions_do_not_depend_on_units_or_rates(tmp_path, monkeypatch):
    """The same linkage in millimetres (positions against rotations in the choice of the driving
    coordinate), a slider pushed 1000 times faster (the driver's steady rate), MATASC on (no
    files from the runs inside); a t_end behind is refused by name."""
    monkeypatch.chdir(tmp_path)
    fb = FourBar(300.0, 350.0, 300.0, 400.0)
    model = fb.model(theta0=0.0, steps=36)
    model.matasc(1)
    (_, value), = dead_positions(model, steps=36)
    assert value == pytest.approx(max(fb.toggle_positions()), abs=1e-10)
    assert list(tmp_path.iterdir()) == []
    m = rigid_slider_crank()
    m.calculable(11, 1)
    m.apply("INPUTX", 3, 1)
    m.xd(3, 1, 10.0)
    (t, value), = dead_positions(m, steps=100, t_end=0.01)
    x0 = 0.15 * math.cos(0.7) + math.sqrt(0.3**2 - (0.15 * math.sin(0.7)) ** 2)
    assert value == pytest.approx(0.45, abs=1e-10) and t == pytest.approx((0.45 - x0) / 10.0, abs=1e-10)
    with pytest.raises(spacar.InputError, match="t_end must be after"):
        dead_positions(FourBar(0.3, 0.35, 0.30, 0.40).model(), t_end=-1.0)


def test_a_grashof_crank_has_no_dead_position():
    model, _ = coupler_example()
    assert dead_positions(model, steps=72) == []


def test_a_slider_crank_driven_by_its_slider_stops_at_the_dead_centre():
    """The slider pushed outwards: the crank and the rod come in line at x = a + b."""
    m = rigid_slider_crank()
    m.calculable(11, 1)
    m.apply("INPUTX", 3, 1)
    m.xd(3, 1, 0.01)
    x0 = 0.15 * math.cos(0.7) + math.sqrt(0.3**2 - (0.15 * math.sin(0.7)) ** 2)
    (t, value), = dead_positions(m, steps=100, t_end=10.0)
    assert value == pytest.approx(0.15 + 0.3, abs=1e-10)
    assert t == pytest.approx((0.45 - x0) / 0.01, abs=1e-8)


def rigid_slider_crank():
    m = spacar.Model()
    m.plbeam(1, 1, 11, 2, 12)        # crank A → B
    m.plbeam(2, 2, 21, 3, 22)        # rod B → C, C sliding along x
    m.x(1, 0.0, 0.0)
    m.x(2, 0.15 * math.cos(0.7), 0.15 * math.sin(0.7))
    m.x(3, 0.15 * math.cos(0.7) + math.sqrt(0.3**2 - (0.15 * math.sin(0.7)) ** 2), 0.0)
    m.fix(1)
    m.fix(3, 2)
    m.apply("INPUTX", 11, 1)
    m.xd(11, 1, 1.0)
    m.timestep(10, 1.0)
    return m


def test_slider_crank_instant_centres_are_kennedy_s_construction():
    """Crank 1 about A, rod 2; the ground 0. I01 = A, I12 = B, I02 on the line A–B extended and on
    the perpendicular to the slide through C (the slider translates along x)."""
    model = rigid_slider_crank()
    ic = instant_centres(model, [0, 1, 2])
    A, B = np.zeros(2), 0.15 * np.array([math.cos(0.7), math.sin(0.7)])
    xc = B[0] + math.sqrt(0.3**2 - B[1] ** 2)
    np.testing.assert_allclose(ic[(0, 1)], A, atol=1e-14)
    np.testing.assert_allclose(ic[(1, 2)], B, atol=1e-14)
    np.testing.assert_allclose(ic[(0, 2)], [xc, xc * B[1] / B[0]], rtol=1e-12)
    with pytest.raises(spacar.InputError, match="must be 0 .the ground. or a PLBEAM"):
        instant_centres(model, [0, 7])


def test_three_point_synthesis_passes_its_precision_points():
    """Freudenstein's three-point function generation: the synthesized four-bar's rocker takes the
    prescribed angles at the three crank angles, by its closed form and by spacar's kinematic
    analysis of its model (the crank driven from the first point), to 1e-10."""
    pairs = [(math.radians(40), math.radians(70)), (math.radians(60), math.radians(85)),
             (math.radians(80), math.radians(95))]
    fb = synthesize(pairs, d=1.0)
    for theta, psi in pairs:
        assert fb.freudenstein(theta, psi) == pytest.approx(0.0, abs=1e-12)
        assert math.remainder(float(fb.rocker_angle(theta)) - psi, 2 * math.pi) == pytest.approx(0.0, abs=1e-10)
    model = fb.model(theta0=pairs[0][0])
    psi0 = float(fb.rocker_angle(pairs[0][0]))
    for theta, psi in pairs[1:]:
        tf = spacar.transfer(model, at=(theta - pairs[0][0], []))  # the crank turns at 1 rad/s
        rocker = tf.x[tf.coordinate_labels.index((9, 1))]
        assert math.remainder(psi0 + rocker - psi, 2 * math.pi) == pytest.approx(0.0, abs=1e-10)
    with pytest.raises(spacar.InputError, match="three .θ, ψ. pairs"):
        synthesize([(0.1, 0.2)])
    with pytest.raises(spacar.InputError, match="branch defect"):  # the points on both assemblies
        synthesize([(math.radians(46), math.radians(67)), (math.radians(58), math.radians(68)),
                    (math.radians(63), math.radians(86))])


# --- errors that point at the cause (issue 41) ---------------------------------------------------

@pytest.mark.parametrize("line, suggestion", [("TIMSTEP 100 5.0", "TIMESTEP"), ("ESTIF 2 1 2", "ESTIFF"),
                                              ("EPSINTT 1e-6", "EPSINT")])
def test_a_misspelt_keyword_gets_a_suggestion(line, suggestion):
    text = (EXAMPLES / "slidercrank.dat").read_text().replace("Timestep 100 5.0", line)
    with pytest.raises(spacar.InputError, match=rf"unknown keyword .*\(did you mean {suggestion}\b"):
        spacar.read_string(text)


def test_a_model_without_mass_is_pointed_to_the_static_analysis():
    model = spacar.read(EXAMPLES / "parallel_leaf_guide.dat")
    model.timestep(10, 1.0)
    with pytest.raises(spacar.SingularMassError, match="no node or element of the model carries mass: for its "
                                                       "stiffness alone.* spacar static or spacar.static"):
        spacar.simulate(model)


def test_a_loop_that_cannot_close_is_said_by_run_and_check():
    """Issue 41: a rocker shortened by LENGTHO 3 0.5 (of 3.16) cannot close the example four-bar's
    loop: 'Newton iteration ... did not converge' with 50 residuals before; now the least-squares
    configuration shows that no configuration meets the constraints and names the lengths that miss,
    in spacar.simulate and in spacar.check (which called the file OK)."""
    text = (EXAMPLES / "fourbar_coupler.dat").read_text().replace("FIX 1", "LENGTHO 3 0.5\nFIX 1", 1)
    message = r"found no configuration that meets the constraints at t = 0: .* largest residuals .*element [23] \(PLBEAM\)"
    with pytest.raises(spacar.KinematicsError, match=message):
        spacar.simulate(spacar.read_string(text), progress=False)
    check = spacar.check(spacar.read_string(text))
    assert not check.ok and "meets the constraints" in check.assembly and "assembly: the assembly found" in str(check)
    assert spacar.check(spacar.read(EXAMPLES / "fourbar_coupler.dat")).ok

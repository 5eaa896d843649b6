"""Time-dependent loads and input motions (spacar.Table, load functions) against independent
references: scipy's cubic spline, the closed-form steady state of a harmonically forced damped
oscillator, and the same input motion written as the manual's constant-acceleration blocks."""

import numpy as np
import pytest

import spacar

MASS, L0 = 2.0, 0.5


def oscillator(omega, zeta, t_end, n_out, eps=1e-10):
    """A point mass on a PLTRUSS spring with EDAMPP from a fixed node: m ë + c ė + k e = F along
    the truss (its elongation e the DOF), natural frequency omega, damping ratio zeta."""
    k, c = MASS * omega**2, 2.0 * zeta * MASS * omega
    m = spacar.Model()
    m.pltruss(1, 1, 2)
    m.x(1, 0.0, 0.0)
    m.x(2, L0, 0.0)
    m.fix(1)
    m.fix(2, 2)
    m.dyne(1, 1)
    m.mass(2, MASS)
    m.estiff(1, k * L0)
    m.edampp(1, c * L0)
    m.timestep(n_out, t_end)
    m.epsint(eps)
    m.epsind(eps)
    return m


@pytest.mark.parametrize("how,method", [("function", "dop853"), ("table", "dop853"), ("table", "radau5")])
def test_forced_damped_oscillator_reaches_the_closed_form_steady_state(how, method):
    # F = F0 sin ωt on the mass: the steady state is |H| F0 sin(ωt + arg H), H = 1/(k − mω² + icω).
    # After 20 s at ζω0 = 1.26/s the transient has decayed to e⁻²⁵; the last two periods are
    # fitted by A sin ωt + B cos ωt.
    omega0, zeta, F0, w = 2 * np.pi, 0.2, 3.0, 1.3 * 2 * np.pi
    t_end = 20.0
    if how == "function":
        force = lambda t: [F0 * np.sin(w * t), 0.0]  # noqa: E731
    else:
        ts = np.linspace(0.0, t_end, 8001)
        force = spacar.Table(ts, np.c_[F0 * np.sin(w * ts), 0 * ts], kind="cubic")
    res = spacar.simulate(oscillator(omega0, zeta, t_end, 2000), forces={2: force}, method=method, progress=False)
    k, c = MASS * omega0**2, 2 * zeta * MASS * omega0
    H = 1.0 / (k - MASS * w**2 + 1j * c * w)
    last = res.t >= t_end - 2 * 2 * np.pi / w
    t, e = res.t[last], res.deformation(1, 1)[last]
    (A, B), *_ = np.linalg.lstsq(np.c_[np.sin(w * t), np.cos(w * t)], e, rcond=None)
    assert np.hypot(A, B) == pytest.approx(abs(H) * F0, rel=1e-5)
    assert np.arctan2(B, A) == pytest.approx(np.angle(H), abs=1e-5)


def test_load_function_adds_to_force_and_reports_its_cost():
    # A constant function equals FORCE: the same motion (and one call per right-hand side).
    calls = []

    def f(t):
        calls.append(t)
        return [1.5, 0.0]

    a = spacar.simulate(oscillator(2 * np.pi, 0.1, 1.0, 10), forces={2: f}, progress=False)
    m = oscillator(2 * np.pi, 0.1, 1.0, 10)
    m.force(2, 1.5, 0.0)
    b = spacar.simulate(m, progress=False)
    np.testing.assert_allclose(a.x, b.x, rtol=0, atol=1e-12)
    assert len(calls) >= a.stats["rhs_evaluations"]


def base_driven(t_end, n_out, accel=None):
    """The oscillator's fixed node replaced by an input x(1,1) (a base moved along the truss): the
    mass follows through the spring. accel: the block's constant input acceleration."""
    m = spacar.Model()
    m.pltruss(1, 1, 2)
    m.x(1, 0.0, 0.0)
    m.x(2, L0, 0.0)
    m.fix(1, 2)
    m.inputx(1, 1)
    m.fix(2, 2)
    m.dyne(1, 1)
    m.mass(2, MASS)
    m.estiff(1, MASS * (2 * np.pi) ** 2 * L0)
    m.edampp(1, 0.5 * L0)
    m.timestep(n_out, t_end)
    m.epsint(1e-11)
    m.epsind(1e-11)
    if accel is not None:
        m.xdd(1, 1, accel)
    return m


def test_quadratic_input_table_equals_a_constant_acceleration_block():
    # A cubic table reproduces p = ½ a t² exactly: the same motion as the block's XDD.
    a = 0.8
    blocks = spacar.simulate(base_driven(1.5, 30, accel=a), progress=False)
    ts = np.linspace(0.0, 1.5, 7)
    table = spacar.simulate(base_driven(1.5, 30), inputs={(1, 1): spacar.Table(ts, 0.5 * a * ts**2)},
                            progress=False)
    np.testing.assert_allclose(table.x, blocks.x, rtol=0, atol=1e-11)
    np.testing.assert_allclose(table.xd, blocks.xd, rtol=0, atol=1e-10)
    np.testing.assert_allclose(table.xdd, blocks.xdd, rtol=0, atol=1e-8)


def test_input_table_follows_accelerate_decelerate_blocks():
    # Two blocks (XDD +a for 1 s, then −a for 1 s) against one run with a cubic table of the same
    # piecewise-quadratic motion with samples every h: the spline differs from the motion only
    # near the jump of the acceleration, and less with smaller h (measured: 9× per halving).
    a = 0.8
    m = base_driven(1.0, 20, accel=a)
    first = spacar.simulate(m, progress=False)
    m.xdd(1, 1, -a)
    second = spacar.simulate(m, progress=False)
    blocks = spacar.Results.concatenate([first, second])

    def motion(t):
        return np.where(t <= 1.0, 0.5 * a * t**2, 0.5 * a + a * (t - 1.0) - 0.5 * a * (t - 1.0) ** 2)

    errors = []
    for h in (0.01, 0.005):
        ts = np.arange(0.0, 2.0 + h / 2, h)
        run = spacar.simulate(base_driven(2.0, 40), inputs={(1, 1): spacar.Table(ts, motion(ts))}, progress=False)
        # (the block boundary t = 1 appears twice in `blocks`)
        errors.append(np.abs(run.x[:, 2] - np.delete(blocks.x[:, 2], 21)).max())
        np.testing.assert_allclose(run.x[:, 0], motion(run.t), rtol=0, atol=1e-12)
    assert errors[1] < 5e-9 * a  # measured 6.5e-9 and 7.1e-10 m (a = 0.8)
    assert errors[1] < 0.35 * errors[0]


def test_bad_time_loads_are_refused():
    m = oscillator(2 * np.pi, 0.1, 1.0, 10)
    with pytest.raises(spacar.InputError, match="not a node"):
        spacar.simulate(m, forces={9: lambda t: [0, 0]}, progress=False)
    with pytest.raises(spacar.InputError, match="2 coordinates"):
        spacar.simulate(m, forces={2: spacar.Table([0, 1], [1.0, 2.0])}, progress=False)
    with pytest.raises(spacar.InputError, match="not an input coordinate"):
        spacar.simulate(m, inputs={(2, 1): spacar.Table([0, 1], [1.0, 2.0])}, progress=False)
    with pytest.raises(spacar.InputError, match="not an input deformation"):
        spacar.simulate(m, inputs={("e", 1, 1): spacar.Table([0, 1], [1.0, 2.0])}, progress=False)
    with pytest.raises(spacar.InputError, match="increase"):
        spacar.Table([0, 0], [1.0, 2.0])
    with pytest.raises(spacar.InputError, match="must return 2 finite numbers"):
        spacar.simulate(m, forces={2: lambda t: 1.0}, progress=False)


def elongation_driven(accel=None):
    """A truss whose elongation is an input (INPUTE 1 1) pushes node 2 (a mass) along x, which
    carries a damped spring (truss 2, its elongation the DOF) to the mass at node 3."""
    m = spacar.Model()
    m.pltruss(1, 1, 2)
    m.pltruss(2, 2, 3)
    m.x(1, 0.0, 0.0)
    m.x(2, 0.5, 0.0)
    m.x(3, 1.0, 0.0)
    m.fix(1)
    m.fix(2, 2)
    m.fix(3, 2)
    m.inpute(1, 1)
    m.dyne(2, 1)
    m.mass(2, 1.0)
    m.mass(3, 2.0)
    m.estiff(2, 20.0)
    m.edampp(2, 0.2)
    m.timestep(30, 1.5)
    m.epsint(1e-11)
    m.epsind(1e-11)
    if accel is not None:
        m.edd(1, 1, accel)
    return m


def test_quadratic_input_deformation_table_equals_a_block():
    a = -0.3
    blocks = spacar.simulate(elongation_driven(accel=a), progress=False, energy=True)
    ts = np.linspace(0.0, 1.5, 4)
    table = spacar.simulate(elongation_driven(), inputs={("e", 1, 1): spacar.Table(ts, 0.5 * a * ts**2)},
                            progress=False, energy=True)
    np.testing.assert_allclose(table.e, blocks.e, rtol=0, atol=1e-11)
    np.testing.assert_allclose(table.x, blocks.x, rtol=0, atol=1e-11)
    # The driver's work through the input's reaction stress closes the balance.
    scale = max(np.abs(table.energy[k]).max() for k in table.energy)
    assert np.abs(table.energy.balance).max() < 1e-8 * scale
    assert np.abs(table.energy["external_work"]).max() > 1e-3 * scale


def pulled_pendulum(force=None):
    """A point mass m on a rigid massless bar of length l turning about the origin (PLBEAM 1, the
    rotation of its root the DOF), hanging down; `force`: a constant FORCE pulling the mass down
    (None: none, the load then comes from a table)."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.x(1, 0.0, 0.0)
    m.x(3, 0.0, -0.8)
    m.fix(1)
    m.dynx(2)
    m.mass(3, 1.5)
    if force is not None:
        m.force(3, 0.0, -force)
    m.linear(1)
    m.timestep(2, 0.1)
    return m


def test_linearization_at_output_times_sees_the_time_dependent_loads():
    # The pendulum's only stiffness is the pull F on its mass: ω² = F / (m l). With F from a
    # table, the linearizations at the output times must find the same as with FORCE (they used
    # to leave the table out of the residual while its tension entered the geometric stiffness).
    F, mass, length = 30.0, 1.5, 0.8
    ref = spacar.simulate(pulled_pendulum(F), progress=False)
    table = spacar.Table([0.0, 1.0], [[0.0, -F], [0.0, -F]], kind="linear")
    res = spacar.simulate(pulled_pendulum(), forces={3: table}, progress=False)
    expected = np.sqrt(F / (mass * length)) / (2 * np.pi)
    for lin_ref, lin in zip(ref.linearizations, res.linearizations):
        assert lin_ref.eigenfrequencies()[0] == pytest.approx(expected, rel=1e-8)
        assert lin.eigenfrequencies()[0] == pytest.approx(expected, rel=1e-8)


def test_linearization_at_output_times_follows_the_input_table():
    # A spring-mass whose base (INPUTX) moves by a table: the linearization at the output times
    # is taken with the base where the table has it, as the same state written as a block starting
    # there (X, XD, XDD of the base at that time) gives it.
    def spring(base=None):
        m = base_driven(0.3, 1)
        m.linear(1)
        if base is not None:
            p, v, a, e, ed = base
            m.x(1, p, 0.0)
            m.x(2, L0 + p, 0.0)
            m.xd(1, 1, v)
            m.xdd(1, 1, a)
            m.e(1, 1, e)
            m.ed(1, 1, ed)
        return m

    ts = np.linspace(0.0, 1.0, 41)
    table = spacar.Table(ts, 0.05 * np.sin(3 * ts)[:, None], kind="cubic")
    res = spacar.simulate(spring(), inputs={(1, 1): table}, progress=False)
    lin = res.linearizations[-1]
    t = res.t[-1]
    block = spring((table(t)[0], table(t, 1)[0], table(t, 2)[0], res.deformation(1, 1)[-1],
                    res.deformation(1, 1, "ed")[-1]))
    block.timestep(1, 1e-9)
    ref = spacar.simulate(block, progress=False).linearizations[0]
    assert ref.t == pytest.approx(0.0)
    np.testing.assert_allclose(lin.r0, ref.r0, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(lin.M0, ref.M0, rtol=1e-9)

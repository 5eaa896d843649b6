"""The energy balance res.energy: kinetic + potential + strain + dissipated − external_work stays
at its initial value (conservation of energy, the independent reference) on undamped, damped and
driven models, whatever the FORCEMODE; and each term against its closed form where one exists."""

import numpy as np
import pytest

import spacar

G = 9.81


def spring_pendulum(damping=0.0, t_end=3.0):
    """A point mass on an elastic PLTRUSS from a fixed node, under gravity, free in the plane
    (x(2,1), x(2,2) the DOFs, the elongation released with stiffness and damping)."""
    m = spacar.Model()
    m.pltruss(1, 1, 2)
    m.x(1, 0.0, 0.0)
    m.x(2, 0.6, -0.8)
    m.fix(1)
    m.dynx(2, 1, 2)
    m.rlse(1, 1)
    m.mass(2, 1.5)
    m.estiff(1, 400.0)
    m.edampp(1, damping)
    m.gravity(0.0, -G)
    m.xd(2, 1, 0.7)
    m.timestep(150, t_end)
    m.epsint(1e-10)
    m.epsind(1e-10)
    m.epskin(1e-13)
    return m


def flexible_arm(t_end=1.0, damping=0.0):
    """A flexible arm: two PLBEAMs with distributed mass, bending stiffness (and damping) on a
    hinge at the fixed node 1, a tip mass, under gravity; the hinge rotation and the bending
    deformations are the DOFs."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.plbeam(2, 3, 4, 5, 6)
    m.x(3, 0.5, 0.0)
    m.x(5, 1.0, 0.0)
    m.fix(1)
    m.dynx(2, 1)
    m.dyne(1, 2, 3)
    m.dyne(2, 2, 3)
    for e in (1, 2):
        m.emass(e, 2.0)
        m.estiff(e, 0.0, 40.0)
        if damping:
            m.edampp(e, 0.0, damping)
    m.mass(5, 0.5)
    m.gravity(0.0, -G)
    m.timestep(100, t_end)
    m.epsint(1e-10)
    m.epsind(1e-10)
    m.epskin(1e-13)
    return m


def check_balance(res, rel=1e-6):
    energy = res.energy
    scale = max(np.abs(energy[k]).max() for k in energy)
    print(f"balance {np.abs(energy.balance).max() / scale:.2e} of {scale:.3g} J")
    assert np.abs(energy.balance).max() < rel * scale, (np.abs(energy.balance).max(), scale)
    return energy, scale


def test_undamped_spring_pendulum_conserves_energy():
    res = spacar.simulate(spring_pendulum(), energy=True, progress=False)
    energy, _ = check_balance(res)
    assert np.all(energy["dissipated"] == 0) and np.all(energy["external_work"] == 0)
    # The terms in closed form from the recorded state: ½ m v², −m g·y, ½ k e² (k = EA/l0).
    v2 = (res.node(2).xd ** 2).sum(axis=1)
    np.testing.assert_allclose(energy["kinetic"], 0.5 * 1.5 * v2, rtol=1e-12)
    np.testing.assert_allclose(energy["potential"], 1.5 * G * res.node(2).x[:, 1], rtol=1e-12)
    np.testing.assert_allclose(energy["strain"], 0.5 * 400.0 * res.deformation(1, 1) ** 2, rtol=1e-10, atol=1e-15)


@pytest.mark.parametrize("method", ["dop853", "radau5"])
def test_damped_models_balance_their_dissipation(method):
    # radau5: the quadrature states have zero rows in its Newton matrix (nothing depends on them).
    res = spacar.simulate(spring_pendulum(damping=3.0), energy=True, method=method, progress=False)
    energy, _ = check_balance(res)
    # ∫ ėᵀ D ė: positive, growing, most of the initial energy after the decay.
    assert np.all(np.diff(energy["dissipated"]) >= 0) and energy["dissipated"][-1] > 0.1
    res = spacar.simulate(flexible_arm(damping=0.05), energy=True, method=method, progress=False)
    check_balance(res)


def driven_arm_energy(forcemode):
    m = flexible_arm()
    m.forcemode(forcemode)
    ts = np.linspace(0.0, 1.0, 21)
    torque = spacar.Table(ts, 30.0 * np.sin(2 * np.pi * ts), kind="cubic")
    tip = lambda t: [0.0, -5.0 * t]  # noqa: E731
    res = spacar.simulate(m, forces={2: torque, 5: tip}, energy=True, progress=False)
    energy, _ = check_balance(res)
    assert energy["external_work"][-1] != 0
    return energy


def test_driven_arm_balances_the_work_of_a_torque_table_and_a_force_function_whatever_the_forcemode():
    a, b = driven_arm_energy(0), driven_arm_energy(1)
    for k in a:
        np.testing.assert_array_equal(a[k], b[k])


def test_prescribed_input_and_controller_work():
    # The base of a damped spring moved by a cubic table (the driver's reaction does work), and a
    # PD controller (held loads) on the mass: both works enter external_work.
    m = spacar.Model()
    m.pltruss(1, 1, 2)
    m.x(1, 0.0, 0.0)
    m.x(2, 0.5, 0.0)
    m.fix(1, 2)
    m.inputx(1, 1)
    m.fix(2, 2)
    m.dyne(1, 1)
    m.mass(2, 2.0)
    m.mass(1, 0.7)  # a moving mass on the input: its inertia is the driver's work too
    m.estiff(1, 40.0)
    m.edampp(1, 0.3)
    m.timestep(100, 2.0)
    m.epsint(1e-10)
    m.epsind(1e-10)
    ts = np.linspace(0.0, 2.0, 41)
    ctrl = spacar.Controller(lambda t, y: [-30.0 * (y[0] - 0.6) - 2.0 * y[1]], rate=50.0,
                             sensors=[("x", 2, 1), ("xd", 2, 1)], actuators=[(2, 1)])
    res = spacar.simulate(m, inputs={(1, 1): spacar.Table(ts, 0.1 * np.sin(3 * ts))}, controller=ctrl,
                          energy=True, progress=False)
    check_balance(res)


def test_energy_needs_the_request():
    res = spacar.simulate(spring_pendulum(t_end=0.1), progress=False)
    with pytest.raises(spacar.InputError, match="energy=True"):
        res.energy


def test_energy_survives_save_load_and_concatenate(tmp_path):
    # res.energy is written by Results.save and read back; Results.concatenate joins the blocks'
    # balances, the works of each block continuing from the block before.
    import spacar
    from test_damped_oscillator import oscillator

    m = oscillator(2 * np.pi, 0.1, t_end=0.5, n_out=5, eps=1e-9)
    first = spacar.simulate(m, energy=True, progress=False)
    second = spacar.simulate(m, energy=True, progress=False)  # the next block, from where the first ended
    path = tmp_path / "run.npz"
    first.save(path)
    loaded = spacar.Results.load(path)
    for key in first.energy:
        assert np.array_equal(loaded.energy[key], first.energy[key])
    whole = spacar.Results.concatenate([first, second])
    assert len(whole.energy.t) == len(first.t) + len(second.t)
    assert whole.energy["dissipated"][-1] == pytest.approx(first.energy["dissipated"][-1]
                                                         + second.energy["dissipated"][-1])
    # One balance over both blocks: its total stays at the start's.
    scale = np.abs(whole.energy["kinetic"] + whole.energy["strain"]).max()
    assert np.abs(whole.energy.balance).max() < 1e-6 * scale
    # Without a balance in every block, the whole has none.
    plain = spacar.simulate(m, progress=False)
    with pytest.raises(spacar.InputError, match="energy=True"):
        spacar.Results.concatenate([first, plain]).energy
    plain.save(tmp_path / "plain.npz")
    with pytest.raises(spacar.InputError, match="energy=True"):
        spacar.Results.load(tmp_path / "plain.npz").energy

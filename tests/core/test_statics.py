"""Static equilibrium (issue 19, docs/statics.md): spacar.static against references computed
here, independently of spacar:

* small deflections of a PLBEAM cantilever: tip deflection P L³/3EI, tip rotation M L/EI;
* large deflections under a dead tip load (Bisshopp–Drucker elastica, P L²/EI = 1, 3, 10): the
  tip position against a shooting solution of the elastica equation (solve_ivp + brentq), for
  PLBEAM and spatial BEAM meshes of 20 and 30 elements — the error is the elements' O(h²)
  discretization error, and the Richardson extrapolation of the two meshes agrees to 1e-4 L;
* a tip moment M L/EI = 2π rolls the cantilever into a closed circle;
* self-weight, moving inputs, the stresses and reactions of the dynamic path at the same state,
  a buckled column reported as indefinite;
* bad input: a degree of freedom without stiffness names its direction; a load beyond the limit
  point of a shallow truss stops with StaticError at the limit load factor (computed here) and
  keeps the converged steps.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

import spacar
from spacar import _core, _testing
from support.planar_models import compressed_cantilever
from support.spatial_models import cantilever as beam_cantilever


def plbeam_cantilever(n, L=1.0, EI=1.0, force=(0.0, 0.0), moment=0.0, mass=0.0):
    """n PLBEAMs along x from the clamped nodes 1, 2 to the tip nodes 2n+1 (XY), 2n+2 (BETA);
    axially rigid, bending DYNE, no mass unless given; tip load and moment."""
    m = spacar.Model()
    for k in range(1, n + 1):
        m.plbeam(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2)
        m.x(2 * k + 1, k * L / n, 0.0)
        m.estiff(k, 0.0, EI)
        m.dyne(k, 2, 3)
        if mass:
            m.emass(k, mass)
    m.fix(1)
    m.fix(2)
    if any(force):
        m.force(2 * n + 1, *force)
    if moment:
        m.force(2 * n + 2, moment)
    return m


def elastica_tip(alpha):
    """Tip (x, y)/L of an inextensible cantilever clamped along x under a dead load P along y,
    alpha = P L²/EI: θ'' = −alpha cos θ, θ(0) = 0, θ'(1) = 0, shooting on θ'(0)."""
    def shoot(k0):
        rhs = lambda s, y: [y[1], -alpha * np.cos(y[0]), np.cos(y[0]), np.sin(y[0])]
        return solve_ivp(rhs, (0.0, 1.0), [0.0, k0, 0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-14).y[:, -1]

    k0 = brentq(lambda k: shoot(k)[1], 1e-9, alpha, xtol=1e-15)
    return shoot(k0)[2:]


# ------------------------------------------------------------------------------------------------
# small deflections
# ------------------------------------------------------------------------------------------------

def test_small_tip_load_deflection_and_rotation():
    L, EI, P = 2.0, 3.0, 3e-6  # P L²/EI = 4e-6: linear to ~1e-11
    m = plbeam_cantilever(4, L, EI, force=(0.0, P))
    res = spacar.static(m, steps=2)
    x, y, beta = res.x[-1, -3:]
    assert y == pytest.approx(P * L**3 / (3 * EI), rel=1e-6)
    assert beta == pytest.approx(P * L**2 / (2 * EI), rel=1e-6)
    assert x == pytest.approx(L, rel=1e-9)
    np.testing.assert_allclose(res.t, [0.5, 1.0])
    assert res.x[0, -2] == pytest.approx(0.5 * y, rel=1e-6)  # linear in the load


def test_small_tip_moment_rotation():
    L, EI, M = 1.5, 2.0, 2e-6
    res = spacar.static(plbeam_cantilever(5, L, EI, moment=M), steps=1)
    assert res.x[-1, -1] == pytest.approx(M * L / EI, rel=1e-6)
    assert res.x[-1, -2] == pytest.approx(M * L**2 / (2 * EI), rel=1e-6)
    # The clamp reacts with the opposite moment.
    assert res.reaction[-1, 2] == pytest.approx(-M, rel=1e-9)


# ------------------------------------------------------------------------------------------------
# large deflections
# ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("alpha", [1.0, 3.0, 10.0])
def test_elastica_plbeam(alpha):
    ref = elastica_tip(alpha)
    tips = {}
    for n in (20, 30):
        res = spacar.static(plbeam_cantilever(n, force=(0.0, alpha)), steps=10)
        tips[n] = res.x[-1, -3:-1]
        assert np.abs(tips[n] - ref).max() < 1.2e-3 * (20 / n) ** 2  # the mesh's own error, O(h²)
        assert max(res.stats["iterations"]) <= 5  # Newton with the exact tangent: quadratic
        assert res.stats["step_cuts"] == 0
    # O(h²): the Richardson extrapolation of the two meshes is the elastica.
    extrapolated = (30**2 * tips[30] - 20**2 * tips[20]) / (30**2 - 20**2)
    assert np.abs(extrapolated - ref).max() < 1e-4


@pytest.mark.parametrize("alpha", [1.0, 10.0])
def test_elastica_spatial_beam(alpha):
    ref = elastica_tip(alpha)
    tips = {}
    for n in (20, 30):
        m = beam_cantilever(n, EIy=1.0, EIz=1.0, GIp=1.0, rhoA=0.0)
        m.force(n + 1, 0.0, alpha, 0.0)
        res = spacar.static(m, steps=10)
        tip = res.node(n + 1).x[-1]
        assert abs(tip[2]) < 1e-12  # stays in its plane
        tips[n] = tip[:2]
        assert np.abs(tips[n] - ref).max() < 1.2e-3 * (20 / n) ** 2
    extrapolated = (30**2 * tips[30] - 20**2 * tips[20]) / (30**2 - 20**2)
    assert np.abs(extrapolated - ref).max() < 1e-4


def test_tip_moment_rolls_a_circle():
    # M L / EI = 2π: constant curvature 2π/L, the tip back at the root turned by 2π.
    tips = {}
    for n in (30, 60, 100):
        res = spacar.static(plbeam_cantilever(n, moment=2 * np.pi), steps=8)
        tips[n] = res.x[-1, -3:]
        # Every node on the circle of radius L/2π through the root, centred at (0, L/2π).
        xy = res.x[-1].reshape(-1, 3)[:, :2]
        r = np.hypot(xy[:, 0], xy[:, 1] - 1 / (2 * np.pi))
        assert np.abs(r - 1 / (2 * np.pi)).max() < 2e-3
    assert np.hypot(*tips[100][:2]) < 1e-3
    extrapolated = (60**2 * tips[60] - 30**2 * tips[30]) / (60**2 - 30**2)
    assert np.hypot(*extrapolated[:2]) < 1e-4
    assert extrapolated[2] == pytest.approx(2 * np.pi, abs=1e-3)


# ------------------------------------------------------------------------------------------------
# loads, inputs, stresses and the state left in the model
# ------------------------------------------------------------------------------------------------

def test_self_weight_needs_no_tip_load():
    rhoA, g, EI, L = 1e-4, 9.81, 1.0, 1.0  # w L³/EI ≈ 1e-3
    m = plbeam_cantilever(8, L, EI, mass=rhoA)
    m.gravity(0.0, -g)
    res = spacar.static(m, steps=1)
    w = rhoA * g
    assert res.x[-1, -2] == pytest.approx(-w * L**4 / (8 * EI), rel=2e-3)
    assert res.x[-1, -1] == pytest.approx(-w * L**3 / (6 * EI), rel=2e-3)
    assert res.reaction[-1, 1] == pytest.approx(w * L, rel=1e-12)  # the clamp carries the weight


def test_state_stored_at_rest_and_the_dynamic_path_agrees():
    """At the equilibrium found, the dynamic evaluation of the same state (with a mass, at rest)
    has no acceleration, and its stresses and reactions (FORCEMODE) are those of the static
    results."""
    m = plbeam_cantilever(6, force=(0.5, 2.0), moment=0.3, mass=1.0)
    res = spacar.static(m, steps=4)
    tip = m.nodes[13].x
    np.testing.assert_allclose(tip, res.node(13).x[-1], rtol=0, atol=1e-15)
    assert not np.any(m.nodes[13].xd)
    sim = _core.Simulation(m.core)
    sim.assemble()
    nd = sim.system.n_dof
    q = np.array(sim.system.q0)
    sim.evaluate(0.0, q, np.zeros(nd))
    sim.forces()
    assert np.abs(np.array(sim.data.qdd)).max() < 1e-8
    np.testing.assert_allclose(np.array(sim.data.x), res.x[-1], atol=1e-12)
    np.testing.assert_allclose(np.array(sim.data.sigma), res.sigma[-1], atol=1e-8)
    np.testing.assert_allclose(np.array(sim.data.reaction), res.reaction[-1], atol=1e-8)


def test_inputs_move_to_their_block_end_values():
    # The root turned by π/2 over the block (INPUTX with XD over TIMESTEP), a tip load along the
    # turned beam: no bending, the beam along y.
    n = 5
    m = plbeam_cantilever(n, force=(0.0, -0.1))
    m.apply("INPUTX", 2, 1)
    m.xd(2, 1, np.pi / 2)
    m.timestep(10, 1.0)
    res = spacar.static(m, steps=5)
    np.testing.assert_allclose(res.node(2).x[:, 0], np.pi / 2 * res.t, atol=1e-14)  # root angle per step
    np.testing.assert_allclose(res.x[-1, -3:], [0.0, 1.0, np.pi / 2], atol=1e-12)
    assert res.reaction[-1, 1] == pytest.approx(0.1, rel=1e-12)


def test_buckled_column_reported_indefinite():
    m = compressed_cantilever(8)  # PLBEAMNL, EI = 1, L = 1: P_cr = π²/4
    m.force(17, -1.25 * np.pi**2 / 4, 0.0)
    res = spacar.static(m, steps=10)
    assert res.stats["indefinite_at"] == pytest.approx(0.9)  # the first step beyond 1/1.25
    assert any("indefinite" in w for w in m.warnings)
    below = spacar.static(compressed_cantilever(8), steps=2)  # P = 1 < P_cr
    assert below.stats["indefinite_at"] is None


# ------------------------------------------------------------------------------------------------
# bad input
# ------------------------------------------------------------------------------------------------

def test_degree_of_freedom_without_stiffness_is_named():
    m = plbeam_cantilever(2, force=(0.0, 1.0))
    m.estiff(2, 0.0, 0.0)
    before = m.nodes[5].x.copy()
    with pytest.raises(spacar.StaticError, match=r"no stiffness in the direction of DYNE element 2 \(PLBEAM\)") as info:
        spacar.static(m)
    assert isinstance(info.value, spacar.SpacarError)
    assert len(info.value.results) == 0
    np.testing.assert_array_equal(m.nodes[5].x, before)  # the model is not changed


def von_mises_truss(P, h=0.1, EA=1.0):
    """Two PLTRUSSes from (∓1, 0) to the apex (0, h), the apex moving vertically (DYNX), a dead
    downward load P."""
    m = spacar.Model()
    m.pltruss(1, 1, 3)
    m.pltruss(2, 2, 3)
    m.x(1, -1.0, 0.0)
    m.x(2, 1.0, 0.0)
    m.x(3, 0.0, h)
    m.fix(1)
    m.fix(2)
    m.fix(3, 1)
    m.dynx(3, 2)
    for e in (1, 2):
        m.rlse(e, 1)
        m.estiff(e, EA)
    m.force(3, 0.0, -P)
    return m


def test_load_beyond_the_limit_point_stops_there():
    h = 0.1
    l0 = np.hypot(1.0, h)
    load = lambda y: 2.0 * (l0 - np.hypot(1.0, y)) / l0 * y / np.hypot(1.0, y)  # P(y) on the branch
    limit = -minimize_scalar(lambda y: -load(y), bounds=(0.0, h), method="bounded",
                             options={"xatol": 1e-12}).fun
    m = von_mises_truss(1.5 * limit, h)
    with pytest.raises(spacar.StaticError, match="beyond load factor 0.666") as info:
        spacar.static(m, steps=10)
    err = info.value
    assert "worst residual" in err.args[0] and "DYNX node 3 component 2" in err.args[0]
    partial = err.results
    np.testing.assert_allclose(partial.t, [0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    reached = partial.stats["load_reached"]
    assert 1 / 1.5 - 1e-3 < reached <= 1 / 1.5
    # The rows converged before are on the stable branch: apex above its limit height.
    assert np.all(partial.x[:, -1] > h / np.sqrt(3))
    # Below the limit load the same model converges.
    ok = spacar.static(von_mises_truss(0.9 * limit, h), steps=10)
    assert ok.x[-1, -1] > h / np.sqrt(3)


@pytest.mark.parametrize("kwargs", [{"steps": 0}, {"steps": 2.5}, {"max_cuts": -1}, {"tolerance": 0.0},
                                    {"tolerance": True}, {"max_iterations": 0}])
def test_bad_options(kwargs):
    with pytest.raises(spacar.InputError):
        spacar.static(plbeam_cantilever(2, force=(0.0, 1.0)), **kwargs)


def test_cli_static(tmp_path, capsys):
    from spacar.cli import main

    lines = ["PLBEAM 1 1 2 3 4", "PLBEAM 2 3 4 5 6", "X 3 0.5 0", "X 5 1 0", "FIX 1", "FIX 2",
             "DYNE 1 2 3", "DYNE 2 2 3", "ESTIFF 1 0 1", "ESTIFF 2 0 1", "FORCE 5 0 1e-6", "END",
             "FORCE 5 0 2e-6", "END"]
    path = tmp_path / "cantilever.dat"
    path.write_text("\n".join(lines) + "\n")
    assert main(["static", str(path), "--steps", "2", "--dump-digits", "10"]) == 0
    out = capsys.readouterr().out
    tips = [line.split() for line in out.splitlines() if line.startswith("XY") and line.split()[1] == "5"]
    assert len(tips) == 2
    assert float(tips[0][3]) == pytest.approx(1e-6 / 3, rel=1e-6)
    assert float(tips[1][3]) == pytest.approx(2e-6 / 3, rel=1e-6)
    assert "block 2: static equilibrium in 2 load steps" in out


def test_prescribed_deformation_is_applied_with_the_loads():
    """An actuator (PLTRUSS 1, INPUTE elongation +0.1 over the block) and a spring (PLTRUSS 2,
    RLSE with EA) hold the apex 3 under a load F. Reference here: apex and the two axial forces
    from |x3 − x1| = l1 + 0.1 and N1 u1 + N2 u2 = F, N2 = EA (l2 − l2₀)/l2₀."""
    from scipy.optimize import fsolve

    EA, F = 2.0, np.array([0.3, -0.4])
    m = spacar.Model()
    m.pltruss(1, 1, 3)
    m.pltruss(2, 2, 3)
    m.x(1, 0.0, 0.0)
    m.x(2, 1.0, 0.0)
    m.x(3, 0.4, 0.6)
    m.fix(1)
    m.fix(2)
    m.dynx(3, 2)  # x3 calculable from the actuator's length
    m.apply("INPUTE", 1, 1)
    m.ed(1, 1, 0.1)
    m.timestep(1, 1.0)
    m.rlse(2, 1)
    m.estiff(2, EA)
    m.force(3, *F)
    res = spacar.static(m, steps=4)
    x1, x2, x30 = np.zeros(2), np.array([1.0, 0.0]), np.array([0.4, 0.6])
    l1, l20 = np.linalg.norm(x30 - x1) + 0.1, np.linalg.norm(x30 - x2)

    def equations(v):
        x3, N1 = v[:2], v[2]
        u1, u2 = (x3 - x1) / np.linalg.norm(x3 - x1), (x3 - x2) / np.linalg.norm(x3 - x2)
        N2 = EA * (np.linalg.norm(x3 - x2) - l20) / l20
        return [*(N1 * u1 + N2 * u2 - F), np.linalg.norm(x3 - x1) - l1]

    ref = fsolve(equations, [0.45, 0.65, 0.0], xtol=1e-14)
    np.testing.assert_allclose(res.node(3).x[-1], ref[:2], atol=1e-10)
    assert res.deformation(1, 1)[-1] == pytest.approx(0.1, abs=1e-12)
    assert res.stress(1, 1)[-1] == pytest.approx(ref[2], abs=1e-9)  # the actuator's force
    np.testing.assert_allclose(res.deformation(1, 1), 0.1 * res.t, atol=1e-12)


def test_path_starts_at_the_current_state():
    """A second analysis with the same loads starts at the equilibrium and stays there; a block
    with other loads ends where a fresh analysis ends."""
    m = plbeam_cantilever(10, force=(0.0, 3.0))
    first = spacar.static(m, steps=5)
    again = spacar.static(m, steps=5)
    np.testing.assert_allclose(again.x, np.tile(first.x[-1], (5, 1)), atol=1e-12)
    assert again.stats["newton_iterations"] == 0
    m.force(21, 0.0, 6.0)
    more = spacar.static(m, steps=5)
    fresh = spacar.static(plbeam_cantilever(10, force=(0.0, 6.0)), steps=5)
    np.testing.assert_allclose(more.x[-1], fresh.x[-1], atol=1e-10)
    tip_y = more.node(21).x[:, 1]
    assert np.all(np.diff(tip_y) > 0) and tip_y[0] > first.node(21).x[-1, 1]  # from 3 to 6 gradually


def test_follower_torque_rolls_a_spatial_beam_like_the_planar_one():
    """TORQUEL about the body z axis of the tip of a BEAM cantilever bending in its x-y plane is the
    dead moment of the PLBEAM cantilever: the same circle, node for node; its load stiffness is
    unsymmetric, yet the equilibrium is stable (not reported indefinite), and Newton converges
    quadratically."""
    n = 30
    m = beam_cantilever(n, EIy=1.0, EIz=1.0, GIp=1.0, rhoA=0.0)
    m.torquel(101 + n, 0.0, 0.0, 2 * np.pi)
    res = spacar.static(m, steps=8)
    planar = spacar.static(plbeam_cantilever(n, moment=2 * np.pi), steps=8)
    for k in range(n + 1):
        np.testing.assert_allclose(res.node(k + 1).x[:, :2], planar.node(2 * k + 1).x, atol=1e-9)
    assert res.stats["indefinite_at"] is None
    assert max(res.stats["iterations"]) <= 3


def test_mechanism_moved_by_its_input_without_loads():
    """The manual's slider-crank: the crank (INPUTX, XD 1.5 rad/s over TIMESTEP 5 s) turned by
    7.5 rad without loads leaves the flexible coupler straight and unstressed; the slider at the
    rigid-linkage position r cos θ + √(l² − r² sin² θ)."""
    from support.spatial_models import PLANAR_EXAMPLE

    model = spacar.read(PLANAR_EXAMPLE)
    res = spacar.static(model, steps=10)
    theta = res.node(2).x[:, 0]
    np.testing.assert_allclose(theta, 7.5 * res.t, atol=1e-12)
    x3 = res.node(3).x
    r = np.hypot(x3[:, 0], x3[:, 1])
    slider = x3[:, 0] + np.sqrt(0.3**2 - x3[:, 1] ** 2)
    np.testing.assert_allclose(r, 0.15, atol=1e-9)
    np.testing.assert_allclose(res.node(8).x[:, 0], slider, atol=1e-9)
    assert np.abs(res.sigma).max() < 1e-12


def _tangent_models():
    planar = plbeam_cantilever(4, force=(0.3, 1.0), moment=0.2, mass=2.0)
    planar.gravity(0.5, -3.0)
    spatial = beam_cantilever(3, EIy=1.0, EIz=2.0, GIp=0.5, rhoA=1.5)
    spatial.torquel(104, 0.3, -0.2, 0.5)
    spatial.force(4, 0.2, 0.4, -0.3)
    spatial.gravity(0.0, -1.0, -2.0)
    # Coordinates as DOFs with released, stiff deformations, and a support moved by an input.
    frame = spacar.Model()
    frame.plbeam(1, 1, 2, 3, 4)
    frame.plbeam(2, 3, 4, 5, 6)
    frame.x(3, 0.6, 0.1)
    frame.x(5, 1.0, 0.5)
    frame.fix(1, 2)
    frame.fix(2)
    frame.apply("INPUTX", 1, 1)
    frame.dynx(3)
    frame.dynx(4)
    frame.dynx(5)
    frame.dynx(6)
    for e in (1, 2):
        frame.rlse(e)
        frame.estiff(e, 50.0, 1.5)
        frame.emass(e, 1.0)
    frame.force(5, 0.4, -0.7)
    frame.gravity(0.0, -2.0)
    return {"planar DYNE": planar, "spatial TORQUEL": spatial, "planar DYNX RLSE": frame}


@pytest.mark.parametrize("name", list(_tangent_models()))
def test_tangent_stiffness_is_the_derivative_of_the_residual(name):
    """K0 + G0 against central differences of R(q) at a state out of equilibrium, at λ = 0.7 (the
    load stiffness of beam gravity and TORQUEL scaled with the loads). The simulation moves to
    each q (it needs the mass that these models have); static_forces evaluates there."""
    model = _tangent_models()[name]
    model.prepare()
    sim = _core.Simulation(model.core)
    sim.assemble()
    nd = sim.system.n_dof
    q0 = np.array(sim.system.q0) + 0.05 * np.sin(np.arange(nd) + 1.0)
    rest = np.zeros(nd)

    def forces(q):
        sim.move_to(0.0, q, rest)
        R, K = _testing.static_forces(sim, 0.7)
        return np.array(R), np.array(K)

    R, K = forces(q0)
    h = 1e-6
    K_fd = np.column_stack([(forces(q0 + h * d)[0] - forces(q0 - h * d)[0]) / (2 * h) for d in np.eye(nd)])
    assert np.abs(R).max() > 1e-2  # out of equilibrium: the stresses' reaction terms matter
    assert np.abs(K - K_fd).max() < 1e-8 * np.abs(K).max()


def test_results_save_load_and_draw(tmp_path):
    res = spacar.static(plbeam_cantilever(4, force=(0.0, 1.0)), steps=3)
    path = tmp_path / "static.npz"
    res.save(path)
    back = spacar.Results.load(path)
    np.testing.assert_array_equal(back.x, res.x)
    assert back.stats == res.stats  # per-row iterations and indefinite_at None included
    assert res.geometry is not None

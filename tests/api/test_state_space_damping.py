"""state_space(damping=..., rayleigh=...) (issue 40): modal damping ratios, as SPACAR Light's
relative damping, and Rayleigh damping α M + β K, on top of the element damping. Against the
closed form of a mass on a spring (poles −ζω ± iω√(1 − ζ²), the resonance peak 1/(2ζk)) and the
modal ratios of a 20-beam cantilever on the dense and the modal (modes=) state space."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from support.planar_models import spring_mass, tip_loaded_beam

K, MASS = 400.0, 4.0
OMEGA = np.sqrt(K / MASS)  # 10 rad/s


def oscillator(mass=MASS):
    """A mass on a spring (PLTRUSS 1, released, EA/L = K), without element damping."""
    return spring_mass(mass=mass, k=K, c=0.0)


def pole(zeta):
    return complex(-zeta * OMEGA, OMEGA * np.sqrt(1 - zeta**2))


@pytest.mark.parametrize("options, zeta", [
    ({"damping": 0.05}, 0.05),
    ({"rayleigh": (0.4, 0.002)}, 0.4 / (2 * OMEGA) + 0.002 * OMEGA / 2),
    ({"damping": [0.05], "rayleigh": (0.4, 0.0)}, 0.05 + 0.4 / (2 * OMEGA)),
])
def test_a_mass_on_a_spring_gets_the_damping_asked_for(options, zeta):
    ss = spacar.state_space(oscillator(), **options)
    poles = ss.poles()
    assert poles[np.argmax(poles.imag)] == pytest.approx(pole(zeta), abs=1e-12)
    # the resonance peak of the displacement per force, 1/(2 ζ K) at ω = ω_n √(1 − 2ζ²) ≈ ω_n: exactly
    # 1/(2 ζ K) at ω_n itself
    peak = ss.frequency_response([OMEGA], unit="rad/s")[0, 0, 0]
    assert abs(peak) == pytest.approx(1.0 / (2 * zeta * K), rel=1e-12)
    assert ss.static_gain()[0, 0] == pytest.approx(1.0 / K, rel=1e-12)  # damping does not change it


def test_modal_ratios_per_mode_on_the_dense_and_the_modal_state_space():
    """A 20-PLBEAM cantilever: the lowest three modes get ζ = 0.01, 0.02, 0.03, the others stay
    undamped; the modal state space of the lowest five modes has the same poles to 1e-9."""
    beam = tip_loaded_beam(20)
    ratios = [0.01, 0.02, 0.03]

    def lowest(ss, k=5):
        p = ss.poles()
        p = p[p.imag > 0]
        return p[np.argsort(p.imag)][:k]

    dense = lowest(spacar.state_space(beam, damping=ratios))
    np.testing.assert_allclose(-dense.real / np.abs(dense), [0.01, 0.02, 0.03, 0.0, 0.0], rtol=0, atol=1e-10)
    undamped = lowest(spacar.state_space(beam))
    np.testing.assert_allclose(np.abs(dense), np.abs(undamped), rtol=1e-12)  # |λ| = ω_n
    modal = lowest(spacar.state_space(beam, modes=5, damping=ratios))
    np.testing.assert_allclose(modal, dense, rtol=1e-9)
    everywhere = lowest(spacar.state_space(beam, modes=5, damping=0.02))
    np.testing.assert_allclose(-everywhere.real / np.abs(everywhere), 0.02, rtol=1e-9)


@pytest.mark.parametrize("options, match", [
    ({"damping": -0.1}, "damping must be a modal damping ratio"),
    ({"damping": "abc"}, "damping must be a modal damping ratio"),
    ({"damping": [[0.1]]}, "damping must be a modal damping ratio"),
    ({"damping": [0.01, 0.02]}, "damping gives 2 modal ratios for 1 modes"),
    ({"rayleigh": (1.0,)}, r"rayleigh must be \(α, β\)"),
    ({"rayleigh": (1.0, float("nan"))}, r"rayleigh must be \(α, β\)"),
])
def test_bad_damping_is_an_input_error(options, match):
    with pytest.raises(spacar.InputError, match=match):
        spacar.state_space(oscillator(), **options)


def test_damping_of_a_model_without_mass_asks_for_masses():
    model = oscillator(mass=0.0)
    spacar.static(model)
    with pytest.raises(spacar.SingularMassError, match="needs masses"):
        spacar.state_space(model, damping=0.02)


# --- model reduction (issue 40) -----------------------------------------------------------------

@pytest.fixture(scope="module")
def damped_beam():
    return spacar.state_space(tip_loaded_beam(30), damping=0.02)  # 90 DOFs, 180 states


def upper_poles(ss, k=None):
    p = ss.poles()
    p = p[p.imag > 0]
    return p[np.argsort(p.imag)][:k]


def test_modal_reduction_keeps_the_static_gain_and_the_lowest_poles(damped_beam):
    """Five modes with the static correction of the other 85: the static gain exact, the five
    poles the full model's, the tip's response below half the first resonance within 1e-6."""
    reduced = damped_beam.reduce(5)
    assert reduced.A.shape == (10, 10) and reduced.state_labels[0] == "mode(1)"
    np.testing.assert_allclose(reduced.static_gain(), damped_beam.static_gain(), rtol=1e-12)
    np.testing.assert_allclose(upper_poles(reduced), upper_poles(damped_beam, 5), rtol=1e-8)
    first = upper_poles(damped_beam, 1)[0].imag
    f = np.linspace(0.0, 0.5 * first, 200) / (2 * np.pi)
    full, small = damped_beam.frequency_response(f)[:, 0, 0], reduced.frequency_response(f)[:, 0, 0]
    assert np.max(np.abs(small - full) / np.abs(full)) < 1e-6


def test_balanced_truncation_stays_within_its_error_bound(damped_beam):
    """Balanced truncation to 8 states: the reduced model is balanced (both Gramians the diagonal of
    its Hankel singular values) and its error over 6 decades of frequency is within the H∞ bound
    2 Σ_{i>8} σ_i; keeping every state reproduces the model."""
    import scipy.linalg

    reduced = damped_beam.reduce(8, method="balanced")
    hsv = reduced.hankel_singular_values
    assert np.all(np.diff(hsv) <= 0) and reduced.error_bound == pytest.approx(2 * hsv[8:].sum())
    Wc = scipy.linalg.solve_continuous_lyapunov(reduced.A, -reduced.B @ reduced.B.T)
    Wo = scipy.linalg.solve_continuous_lyapunov(reduced.A.T, -reduced.C.T @ reduced.C)
    np.testing.assert_allclose(Wc, np.diag(hsv[:8]), atol=1e-6 * hsv[0])
    np.testing.assert_allclose(Wo, np.diag(hsv[:8]), atol=1e-6 * hsv[0])
    f = np.logspace(-2, 4, 3000)
    error = np.abs(damped_beam.frequency_response(f) - reduced.frequency_response(f)).max()
    assert 0 < error <= reduced.error_bound
    significant = int(np.sum(hsv > np.finfo(float).eps * hsv[0]))  # the states an input reaches and an output sees
    with pytest.raises(spacar.InputError, match=f"only {significant} of the model's Hankel singular values"):
        damped_beam.reduce(significant + 1, method="balanced")
    every = damped_beam.reduce(significant, method="balanced")
    np.testing.assert_allclose(every.frequency_response(f[::100]), damped_beam.frequency_response(f[::100]),
                               rtol=1e-6, atol=1e-9 * np.abs(damped_beam.static_gain()).max())


def test_bad_reductions_are_input_errors(damped_beam):
    with pytest.raises(spacar.InputError, match="needs a stable model"):
        spacar.state_space(tip_loaded_beam(4)).reduce(2, method="balanced")  # undamped: poles on the axis
    with pytest.raises(spacar.InputError, match="method must be 'modal' or 'balanced'"):
        damped_beam.reduce(2, method="pod")
    with pytest.raises(spacar.InputError, match="k must be a positive whole number"):
        damped_beam.reduce(0)
    with pytest.raises(spacar.InputError, match="k = 91 modes of a model of 90"):
        damped_beam.reduce(91)


def test_deformation_and_stress_signals_on_the_modal_state_space():
    # The modal model takes its deformations' rows from the nodal B and S (they were missing:
    # OUTE, OUTS and INPUTS raised AttributeError with modes=); its static gain equals the dense one.
    from spacar import section

    guide = spacar.read("examples/parallel_leaf_guide.dat")
    section.rectangle(0.02, 0.5e-3, section.STEEL).apply(guide, *range(1, 9))
    guide.mass(9, 0.2)
    spacar.static(guide)
    signals = dict(inputs=[("INPUTF", 9, 1), ("INPUTS", 2, 2)], outputs=[("OUTE", 1, 2), ("OUTX", 9, 1)])
    modal = spacar.state_space(guide, modes=3, **signals)
    dense = spacar.state_space(guide, **signals)
    assert modal.static_gain() == pytest.approx(dense.static_gain(), rel=1e-9)


def test_too_many_modes_for_the_masses_is_said_plainly():
    # Only the stage carries mass: one finite mode, not two; ARPACK's own message names workspace.
    guide = spacar.read("examples/parallel_leaf_guide.dat")
    spacar.static(guide)
    guide.mass(9, 0.2)
    with pytest.raises(spacar.SpacarError, match="fewer finite modes than asked"):
        spacar.state_space(guide, modes=2, inputs=[("INPUTF", 9, 1)], outputs=[("OUTX", 9, 1)])


def test_a_leaf_spring_stage_with_massless_leaves_is_its_single_mode():
    # The parallel guide with its stage as a point mass and massless leaves: the leaves' DOFs
    # follow the stage statically (condensed; the dense state space raised a LinAlgError before).
    # With ζ = 0.01 its drive receptance is the single mode C / (1 − r² + 2iζr), r = f / f1, the
    # y mode 70 times higher.
    guide = spacar.read("examples/parallel_leaf_guide.dat")
    guide.mass(9, 0.2)
    spacar.static(guide)
    compliance = spacar.compliance(guide, 9)[0, 0]
    f1 = spacar.linearize(guide).eigenfrequencies()[0]
    assert f1 == pytest.approx(np.sqrt(1 / (compliance * 0.2)) / (2 * np.pi), rel=1e-5)
    ss = spacar.state_space(guide, damping=0.01, inputs=[("INPUTF", 9, 1)], outputs=[("OUTX", 9, 1)])
    assert ss.A.shape == (4, 4)            # the stage's x and y
    assert ss.static_gain()[0, 0] == pytest.approx(compliance, rel=1e-10)
    r = np.array([0.1, 0.5, 0.9, 0.99, 1.0, 1.01, 1.1, 2.0, 3.0])
    single = compliance / (1 - r**2 + 2j * 0.01 * r)
    assert ss.frequency_response(r * f1)[:, 0, 0] == pytest.approx(single, rel=1e-5)


def test_massless_degrees_of_freedom_with_damping_are_refused():
    guide = spacar.read("examples/parallel_leaf_guide.dat")
    guide.mass(9, 0.2)
    for e in range(1, 9):
        guide.edampp(e, 0.0, 1e-4)
    spacar.static(guide)
    with pytest.raises(spacar.InputError, match="without mass but with damping"):
        spacar.state_space(guide, inputs=[("INPUTF", 9, 1)], outputs=[("OUTX", 9, 1)])


def massless_arm(torque=None):
    """Two massless BEAMs with a mass and inertia at the tip; a dead moment at the middle (TORQUEG
    makes the tangent unsymmetric)."""
    m = spacar.Model()
    m.beam(1, 1, 2, 3, 4, 0, 1, 0)
    m.beam(2, 3, 4, 5, 6, 0, 1, 0)
    m.x(1, 0, 0, 0)
    m.x(3, 0.5, 0, 0)
    m.x(5, 1.0, 0, 0)
    m.fix(1)
    m.fix(2)
    for e in (1, 2):
        m.dyne(e, 1, 2, 3, 4, 5, 6)
        m.estiff(e, 1e5, 40.0, 60.0, 50.0)
    m.mass(5, 1.5)
    m.mass(6, 0.02, 0, 0, 0.03, 0, 0.025)
    if torque:
        m.torqueg(4, *torque)
    spacar.static(m)
    return m


@pytest.mark.parametrize("torque", [None, (0.0, 20.0, 15.0)])
def test_massless_directions_condensed_with_an_unsymmetric_stiffness(torque):
    # Against the direct solve of (K − ω²M + iωC) z = Q u, which needs no M⁻¹ (inputs on the
    # massless middle node and on the tip).
    m = massless_arm(torque)
    inputs = [("INPUTF", 3, 2), ("INPUTF", 3, 3), ("INPUTF", 5, 2)]
    outputs = [("OUTX", 5, 2), ("OUTX", 5, 3), ("OUTX", 3, 2)]
    lin = spacar.linearize(m)
    M, C, K = lin.M0, lin.damping, lin.stiffness
    Q = lin.DF[[lin.coordinate_labels.index((n, i)) for _, n, i in inputs]].T
    out = lin.DF[[lin.coordinate_labels.index((n, i)) for _, n, i in outputs]]
    f = np.array([0.0, 0.5, 2.0, 5.0])
    direct = np.array([out @ np.linalg.solve(K - (2 * np.pi * v) ** 2 * M + 2j * np.pi * v * C, Q) for v in f])
    ss = spacar.state_space(m, inputs=inputs, outputs=outputs)
    assert ss.A.shape == (12, 12)     # the tip's six directions with mass
    assert ss.frequency_response(f) == pytest.approx(direct, rel=1e-12, abs=1e-12 * np.abs(direct).max())


def test_stress_outputs_of_massless_leaves_and_an_ill_conditioned_mass_kept():
    # The stress of a massless leaf under the drive force (from the nodal S, B and DF: no motion
    # to evaluate), equal to the static stress per unit force.
    guide = spacar.read("examples/parallel_leaf_guide.dat")
    guide.mass(9, 0.2)
    spacar.static(guide)
    ss = spacar.state_space(guide, inputs=[("INPUTF", 9, 1)], outputs=[("OUTS", 1, 2)])
    unit = spacar.read("examples/parallel_leaf_guide.dat")       # 1 N on the stage
    loaded = spacar.static(unit)
    assert ss.static_gain()[0, 0] == pytest.approx(loaded.stress(1, 2)[-1], rel=1e-3)   # (geometric nonlinearity)
    # Leaves with their steel mass (light against the stage): every DOF carries mass, however
    # ill-conditioned M0 is; the model keeps all its states.
    from spacar import section

    heavy = spacar.read("examples/parallel_leaf_guide.dat")
    section.rectangle(0.02, 0.5e-3, section.STEEL).apply(heavy, *range(1, 9))
    heavy.mass(9, 2.0)
    spacar.static(heavy)
    full = spacar.state_space(heavy, inputs=[("INPUTF", 9, 1)], outputs=[("OUTX", 9, 1)])
    assert full.A.shape[0] == 2 * len(spacar.linearize(heavy).z_labels)

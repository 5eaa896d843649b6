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

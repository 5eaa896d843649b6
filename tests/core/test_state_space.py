"""spacar.state_space (issue 22): state-space models with physical inputs (INPUTF, INPUTS) and
outputs (OUTX, OUTXP, OUTE, OUTEP), each checked against an independent reference: the
cantilever's static compliance L³/3EI and its Euler–Bernoulli frequencies, the closed-form
receptance of a damped single-DOF oscillator, the analytic velocity of a rotating pendulum (the
convective term at a moving state), and scipy.signal's frequency response."""
import numpy as np
import pytest

import spacar
from support.planar_models import spring_mass as oscillator

BETA = [1.8751040687119611, 4.6940911329741745, 7.8547574382376126]  # cos β cosh β = −1


def cantilever(n, L=1.2, EI=2.0, rhoA=3.0):
    """n PLBEAM elements along x, clamped at nodes 1/2, bending deformations DYNE (elongation
    rigid); tip position node 2n+1."""
    m = spacar.Model()
    for k in range(n):
        m.plbeam(k + 1, 2 * k + 1, 2 * k + 2, 2 * k + 3, 2 * k + 4)
    for k in range(n + 1):
        m.x(2 * k + 1, L * k / n, 0.0)
    m.fix(1)
    m.fix(2)
    for k in range(n):
        m.dyne(k + 1, 2, 3)
        m.estiff(k + 1, 0.0, EI)
        m.emass(k + 1, rhoA)
    tip = 2 * n + 1
    m.inputf(1, tip, 2)
    m.outx(1, tip, 2)
    m.outxp(2, tip, 2)
    return m


def pendulum(L=0.8, mass=1.5):
    """A point mass on a rigid rod (PLBEAM, all deformations fixed) about a fixed pin: the rod's
    rotation β2 is the DOF; x3 = L cos β2, y3 = L sin β2."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.x(3, L, 0.0)
    m.fix(1)
    m.dynx(2)
    m.mass(3, mass)
    m.inputf(1, 3, 2)
    m.outx(1, 3, 1)
    m.outxp(2, 3, 1)
    m.outxp(3, 3, 2)
    return m


def test_cantilever_static_gain_is_the_tip_compliance():
    L, EI = 1.2, 2.0
    ss = spacar.state_space(cantilever(6, L=L, EI=EI))
    assert ss.input_labels == ["f(13,2)"] and ss.output_labels == ["x(13,2)", "xd(13,2)"]
    assert ss.A.shape == (24, 24) and ss.B.shape == (24, 1) and ss.C.shape == (2, 24) and ss.D.shape == (2, 1)
    gain = ss.static_gain()
    assert gain[0, 0] == pytest.approx(L**3 / (3 * EI), rel=1e-9)
    assert abs(gain[1, 0]) < 1e-12  # no static velocity
    # the frequency response tends to the static gain
    assert ss.frequency_response([1e-6])[0, 0, 0] == pytest.approx(gain[0, 0], rel=1e-9)


def test_fine_cantilever_keeps_its_static_gain_and_edited_matrices_are_used():
    """100 elements: K0 spans 8 decades; the response is solved from K − ω²M + iωD (not from
    M⁻¹K), so the static compliance stays at 1e-12. A changed A is used as it is."""
    L, EI = 1.2, 2.0
    ss = spacar.state_space(cantilever(100, L=L, EI=EI))
    assert ss.static_gain()[0, 0] == pytest.approx(L**3 / (3 * EI), rel=1e-12)
    assert ss.frequency_response([1e-8])[0, 0, 0].real == pytest.approx(L**3 / (3 * EI), rel=1e-12)
    small = spacar.state_space(cantilever(3, L=L, EI=EI))
    small.A = small.A.copy()
    small.A[6:, 6:] -= 0.1 * np.eye(6)   # extra damping: no longer the linearization's equations
    w = 2.0
    expected = small.C @ np.linalg.solve(1j * w * np.eye(12) - small.A, small.B)
    np.testing.assert_allclose(small.frequency_response([w], unit="rad/s")[0], expected, rtol=1e-12)


def test_cantilever_poles_are_the_euler_bernoulli_frequencies():
    L, EI, rhoA = 1.2, 2.0, 3.0
    exact = np.array(BETA) ** 2 * np.sqrt(EI / (rhoA * L**4))
    errors = []
    for n in (10, 20):
        poles = spacar.state_space(cantilever(n, L=L, EI=EI, rhoA=rhoA)).poles()
        assert np.abs(poles.real).max() < 1e-8 * np.abs(poles).max()  # undamped
        w = np.sort(np.abs(poles.imag))[::2][:3]
        errors.append(w / exact - 1)
    # the mesh's accuracy: above the continuum (consistent mass), 5e-8, 2e-6, 2e-5 with 20
    # elements, falling as h⁴ (cubic Hermite elements)
    assert np.all(errors[1] > 0) and np.all(errors[1] < [1e-7, 3e-6, 2e-5])
    assert np.all((errors[0] / errors[1] > 14) & (errors[0] / errors[1] < 17))


def test_damped_oscillator_frequency_response_is_the_closed_form():
    mass, k, c = 2.0, 50.0, 0.7
    ss = spacar.state_space(oscillator(mass, k, c))
    f = np.array([0.01, 0.5, 5 ** 0.5 * 5 / (2 * np.pi), 2.0, 30.0])
    w = 2 * np.pi * f
    H = ss.frequency_response(f)                    # Hz
    assert np.allclose(H, ss.frequency_response(w, unit="rad/s"), rtol=1e-14, atol=0)
    receptance = 1 / (k - mass * w**2 + 1j * c * w)
    for i, expected in enumerate([receptance, 1j * w * receptance, receptance, 1j * w * receptance]):
        # force input: x, ẋ, e = x − 1, ė; the stress input pulls the mass back with −u
        np.testing.assert_allclose(H[:, i, 0], expected, rtol=1e-10, atol=0)
        np.testing.assert_allclose(H[:, i, 1], -expected, rtol=1e-10, atol=0)
    wn, zeta = np.sqrt(k / mass), c / (2 * np.sqrt(k * mass))
    poles = np.sort_complex(ss.poles())
    assert poles == pytest.approx([-zeta * wn - 1j * wn * np.sqrt(1 - zeta**2),
                                   -zeta * wn + 1j * wn * np.sqrt(1 - zeta**2)], rel=1e-12)


@pytest.mark.parametrize("state", [None, (0.0, [1.1], [0.3])])
def test_stress_output_is_the_spring_damper_force(state):
    mass, k, c = 2.0, 50.0, 0.7
    m = oscillator(mass, k, c)
    m.outs(5, 1, 1)
    ss = spacar.state_space(m, at=state)
    assert ss.output_labels[4] == "sigma(1,1)"
    np.testing.assert_allclose(ss.C[4], [k, c], rtol=1e-9)   # σ = k e + c ė of a unit-length truss
    w = 2 * np.pi * np.array([0.1, 1.0, 3.0])
    H = ss.frequency_response(w, unit="rad/s")
    np.testing.assert_allclose(H[:, 4, 0], (k + 1j * c * w) / (k - mass * w**2 + 1j * c * w), rtol=1e-9)


def test_stress_output_needs_a_constitutive_deformation_and_the_model():
    m = pendulum()
    with pytest.raises(spacar.InputError, match="OUTS needs a DYNE or released deformation"):
        spacar.state_space(m, inputs=[], outputs=[("OUTS", 1, 1)])
    with pytest.raises(spacar.InputError, match="a stress output needs differences .* pass the Model"):
        spacar.state_space(spacar.linearize(oscillator()), inputs=[], outputs=[("OUTS", 1, 1)])


def test_rate_outputs_at_a_moving_state_include_the_convective_term():
    L, th, om = 0.8, 0.6, 2.5
    ss = spacar.state_space(pendulum(L), at=(0.0, [th], [om]))
    # ẋ3 = −L sin β β̇, ẏ3 = L cos β β̇: ∂/∂β at fixed β̇ and ∂/∂β̇
    np.testing.assert_allclose(ss.C, [[-L * np.sin(th), 0.0],
                                      [-L * np.cos(th) * om, -L * np.sin(th)],
                                      [-L * np.sin(th) * om, L * np.cos(th)]], rtol=1e-8, atol=1e-10)
    # the generalized force of a force on y3 is its moment arm L cos β; M0 = m L²
    assert ss.B[1, 0] == pytest.approx(np.cos(th) / (1.5 * L), rel=1e-12)


def test_convective_term_of_an_input_motion():
    """A mass sliding along a rod turned by an input motion at rate Ω (the rod's elongation e1
    the DOF, r = l0 + e1): ẋ = ṙ cos α − r sin α Ω, ẏ = ṙ sin α + r cos α Ω, so even at ṙ = 0
    the rates depend on r."""
    a, r, Om = 0.5, 0.9, 1.7
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.x(3, r * np.cos(a), r * np.sin(a))
    m.fix(1)
    m.inputx(2, 1)
    m.xd(2, 1, Om)
    m.dyne(1, 1)
    m.mass(3, 1.0)
    m.outxp(1, 3, 1)
    m.outxp(2, 3, 2)
    ss = spacar.state_space(m)
    np.testing.assert_allclose(ss.C, [[-np.sin(a) * Om, np.cos(a)], [np.cos(a) * Om, np.sin(a)]], rtol=1e-8)


def test_state_of_results_and_the_default_state():
    m = pendulum()
    m.xd(2, 1, 1.0)
    m.timestep(4, 0.2)
    res = spacar.simulate(m.copy())
    k = 2
    a = spacar.state_space(m, at=(res, res.t[k]))
    b = spacar.state_space(m, at=(res.t[k], res.q[k], res.qd[k]))
    assert a.t == pytest.approx(res.t[k])
    np.testing.assert_allclose(a.C, b.C, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(a.A, b.A, rtol=1e-12, atol=1e-14)
    # results with linearizations (LINEAR 1): the one at the output time
    m.linear(1)
    res = spacar.simulate(m.copy())
    d = spacar.state_space(res, at=res.t[k], inputs=[("INPUTF", 3, 2)], outputs=[("OUTX", 3, 1)])
    assert d.t == pytest.approx(res.t[k])
    np.testing.assert_allclose(d.B, b.B, rtol=1e-9)
    np.testing.assert_allclose(d.C[0], b.C[0], rtol=1e-9, atol=1e-12)
    with pytest.raises(spacar.InputError, match="have no linearizations"):
        spacar.state_space(spacar.simulate(pendulum()), inputs=[], outputs=[])
    # default: the model's current state (t = 0, β̇ = 1)
    c = spacar.state_space(m)
    assert c.C[1, 0] == pytest.approx(-0.8 * 1.0, rel=1e-8)


@pytest.mark.filterwarnings("ignore:Badly conditioned filter coefficients")  # scipy's own ss → tf step
def test_scipy_and_linearization_agree():
    import scipy.signal

    ss = spacar.state_space(oscillator())
    sys = ss.to_scipy()
    w = np.array([0.3, 3.0, 30.0])
    _, h = scipy.signal.freqresp(scipy.signal.StateSpace(ss.A, ss.B[:, :1], ss.C[:1], ss.D[:1, :1]), w)
    np.testing.assert_allclose(h, ss.frequency_response(w, unit="rad/s")[:, 0, 0], rtol=1e-12)
    assert np.allclose(sys.A, ss.A)
    # explicit signals on a Linearization give the same model
    lin = spacar.linearize(oscillator())
    other = spacar.state_space(lin, inputs=[("INPUTF", 2, 1)], outputs=[("OUTX", 2, 1)])
    np.testing.assert_allclose(other.B, ss.B[:, :1])
    np.testing.assert_allclose(other.C, ss.C[:1])
    assert np.allclose(np.sort_complex(ss.poles()), np.sort_complex(lin.eigenvalues()))


def test_to_control():
    control = pytest.importorskip("control")
    ss = spacar.state_space(oscillator())
    sys = ss.to_control()
    assert isinstance(sys, control.StateSpace)
    assert list(sys.input_labels) == ss.input_labels and list(sys.output_labels) == ss.output_labels


def test_bode_draws_every_pair():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = spacar.state_space(oscillator()).bode()
    assert len(fig.axes[0].lines) == 8
    plt.close(fig)


def test_nonholonomic_model_inputs_and_rate_outputs():
    from test_nonholonomic import BICYCLE

    lin = spacar.linearize(spacar.read(BICYCLE))
    assert lin.y_labels  # the kinematic coordinates are states
    node, comp = next(c for c, row in zip(lin.coordinate_labels, lin.DF) if np.any(row))
    ss = spacar.state_space(lin, inputs=[("INPUTF", node, comp)], outputs=[])
    nz, nk = len(lin.z_labels), len(lin.y_labels)
    assert ss.A.shape == (2 * nz + nk,) * 2
    np.testing.assert_allclose(ss.poles(), lin.eigenvalues(), rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(ss.B[nz + nk:, 0], np.linalg.solve(lin.M0, lin.DF[lin.coordinate_labels.index((node, comp))]))
    with pytest.raises(spacar.InputError, match="a position output of a nonholonomic model needs differences.*"
                                                "a Linearization alone cannot be re-evaluated: pass the Model"):
        spacar.state_space(lin, inputs=[], outputs=[("OUTX", node, comp)])


def test_nonholonomic_position_outputs_at_a_moving_state():
    # The wheel rolling down the incline (tests/core/test_radau5_simulate.py): its centre (node 3)
    # is at the kinematic coordinates y^k = (e1, e2) of PLBEAR 1 from the origin, its spin x(5,1)
    # is the DOF z. With y^k fixed the centre does not move with z: x(3,1) = y1, x(3,2) = y2,
    # x(5,1) = z; its velocity follows the spin by the rolling, ẋ(3,1) = DF ż (not ∂x/∂z).
    from test_radau5_simulate import incline_wheel

    m = incline_wheel(1e-10)
    spacar.simulate(m, progress=False)  # to a moving state: rolling at t = 2 s
    outputs = [("OUTX", 3, 1), ("OUTX", 3, 2), ("OUTX", 5, 1), ("OUTE", 1, 1), ("OUTXP", 3, 1)]
    ss = spacar.state_space(m, inputs=[("INPUTF", 3, 1)], outputs=outputs)
    assert ss.state_labels == ["x(5,1)", "e(1,1)", "e(1,2)", "xd(5,1)"]
    lin = ss.linearization
    rolling = lin.DF[lin.coordinate_labels.index((3, 1)), 0]
    assert abs(rolling) > 0.1
    expected = np.array([[0, 1, 0, 0], [0, 0, 1, 0], [1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, rolling]], float)
    np.testing.assert_allclose(ss.C, expected, atol=1e-7)


def test_signal_numbers_without_gaps():
    m = oscillator()
    m.outx(6, 2, 1)
    with pytest.raises(spacar.InputError, match="outputs must be numbered 1, 2, ... without gaps: 1, 2, 3, 4, 6 are "
                                                "defined, 5 is missing"):
        spacar.state_space(m)


def test_input_on_a_fixed_coordinate_names_its_line():
    m = spacar.read_string("PLTRUSS 1 1 2\nX 2 1. 0.\nFIX 1\nFIX 2 2\nDYNX 2 1\nRLSE 1\nMASS 2 1.\nESTIFF 1 1.\n"
                           "INPUTF 1 1 1\nOUTX 1 2 1\nEND\n", "spring.dat")
    with pytest.raises(spacar.InputError, match="spring.dat, line 9, keyword INPUTF: the input does no work"):
        spacar.state_space(m)


def test_bad_arguments():
    m = oscillator()
    with pytest.raises(spacar.InputError, match="a spacar.Model, Linearization or Results"):
        spacar.state_space("model.dat")
    with pytest.raises(spacar.InputError, match="needs inputs= and outputs="):
        spacar.state_space(spacar.linearize(m))
    with pytest.raises(spacar.InputError, match="outputs must be a list of"):
        spacar.state_space(m, outputs=5)
    with pytest.raises(spacar.InputError, match="keyword one of INPUTF, INPUTS"):
        spacar.state_space(m, inputs=[("FORCE", 2, 1)])
    with pytest.raises(spacar.InputError, match="element 1 has no deformation 2"):
        spacar.state_space(m, outputs=[("OUTE", 1, 2)])
    with pytest.raises(spacar.InputError, match="ω = 0 rad/s is a pole of the model"):
        spacar.state_space(pendulum()).frequency_response([0.0])
    with pytest.raises(spacar.InputError, match="A is singular"):
        spacar.state_space(pendulum()).static_gain()
    with pytest.raises(spacar.InputError, match="unit must be"):
        spacar.state_space(m).frequency_response([1.0], unit="kHz")
    with pytest.raises(spacar.InputError, match="a rate output at a moving state"):
        spacar.state_space(spacar.linearize(pendulum()), inputs=[], outputs=[("OUTXP", 3, 1)])

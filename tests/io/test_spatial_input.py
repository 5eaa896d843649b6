"""Bad input of spatial models (issue #4 "Bad input"): a BEAM whose direction vector is parallel
to its axis, a HINGE axis of zero length, an inertia tensor that is not positive semidefinite,
Euler parameters far from unit length — each an ``InputError`` naming file, line and keyword.
A fully fixed LAMBDA node is legal. Kinematic failures of spatial mechanisms are
``KinematicsError``s with the diagnosis of formulation.md §2.2–2.3.

The cases are examples/slidercrank3d.dat with one line changed or inserted; errors found only
at the first END (the BEAM reference frame needs the initial positions) are provoked with
``model.summary()`` and ``spacar.simulate`` and must name the line of the BEAM definition.
"""
import math
import re

import numpy as np
import pytest

import spacar
from spacar import InputError, KinematicsError
from support.spatial_models import RSSR, SPATIAL_EXAMPLE, rssr_model

BASE = SPATIAL_EXAMPLE.read_text().splitlines()
FILE = "file.dat"


def line_of(prefix):
    return 1 + next(i for i, line in enumerate(BASE) if line.startswith(prefix))


def replace(prefix, new):
    """(text with the line starting with `prefix` replaced by `new`, its line number)."""
    k = line_of(prefix)
    lines = list(BASE)
    lines[k - 1] = new
    return "\n".join(lines) + "\n", k


def insert_before(prefix, *new):
    """(text with `new` lines inserted before the line starting with `prefix`, number of the
    first inserted line)."""
    k = line_of(prefix)
    lines = list(BASE)
    lines[k - 1:k - 1] = list(new)
    return "\n".join(lines) + "\n", k


def raises_located(text, line, keyword, reason, action="summary"):
    with pytest.raises(InputError) as info:
        model = spacar.read_string(text, FILE)
        if action == "summary":
            model.summary()
        else:
            spacar.simulate(model)
    message = str(info.value)
    assert message.startswith(f"{FILE}, line {line}, keyword {keyword}: "), message
    assert re.search(reason, message), message
    return message


# ---------------------------------------------------------------------------------------------
# BEAM direction vector parallel to the element axis (found at the first END)
# ---------------------------------------------------------------------------------------------

BEAM_CASES = [
    ("along the axis", "BEAM 2 3 5 6 7 1. 0. 0.", r"direction vector \(1, 0, 0\) is parallel to the element axis \(1, 0, 0\)"),
    ("opposite to the axis", "BEAM 2 3 5 6 7 -3. 0. 0.", r"direction vector \(-3, 0, 0\) is parallel"),
    ("within 1e-5 of the axis", "BEAM 2 3 5 6 7 2. 1e-9 0.", r"direction vector \(2, 1e-09, 0\) is parallel"),
]


@pytest.mark.parametrize("action", ["summary", "simulate"])
@pytest.mark.parametrize("new, reason", [c[1:] for c in BEAM_CASES], ids=[c[0] for c in BEAM_CASES])
def test_beam_direction_parallel_to_its_axis(new, reason, action):
    text, line = replace("BEAM 2 ", new)
    raises_located(text, line, "BEAM", r"BEAM 2: the " + reason, action)


def test_beam_direction_parallel_to_the_axis_set_by_a_later_x_line():
    """BEAM 3 runs from node 6 to node 8; the X line of node 8 (after the BEAM line) makes the
    chord parallel to the y direction vector. The error names the BEAM line, not the X line."""
    text, line = replace("X 8 ", "X 8 0.30 0.5 0.")
    raises_located(text, line_of("BEAM 3 "), "BEAM", r"BEAM 3: the direction vector \(0, 1, 0\) is parallel to the "
                   r"element axis \(0, 1, 0\)", "simulate")


def test_beam_direction_nearly_but_not_parallel_is_accepted():
    text, _ = replace("BEAM 2 ", "BEAM 2 3 5 6 7 1. 1e-4 0.")
    assert spacar.read_string(text, FILE).summary().n_coordinates == 40


def test_beam_direction_parallel_through_the_builder_names_the_element():
    m = spacar.Model()
    m.beam(1, 1, 2, 3, 4, 0.0, 0.0, 2.0)
    m.x(3, 0.0, 0.0, 1.0)
    with pytest.raises(InputError, match=r"BEAM 1: the direction vector \(0, 0, 2\) is parallel"):
        spacar.simulate(m)


# ---------------------------------------------------------------------------------------------
# HINGE axis of zero length
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("action", ["summary", "simulate"])
def test_hinge_axis_of_zero_length(action):
    text, line = replace("HINGE 5 ", "HINGE 5 4 5 0. 0. 0.")
    raises_located(text, line, "HINGE", r"HINGE 5.*zero length", action)


@pytest.mark.parametrize("old, new", [
    ("HINGE 5 ", "HINGE 5 4 5 0. 0. 1e-300"),
    ("HINGE 5 ", "HINGE 5 4 5 0. 0. 1e300"),
    ("BEAM 2 ", "BEAM 2 3 5 6 7 0. 1e-300 0."),
    ("BEAM 2 ", "BEAM 2 3 5 6 7 0. 1e300 0."),
], ids=["tiny hinge axis", "huge hinge axis", "tiny beam direction", "huge beam direction"])
def test_only_the_direction_of_axes_and_direction_vectors_matters(old, new):
    """A tiny but non-zero vector is not of zero length (its norm used to underflow: an
    unlocated 'HINGE: the axis of rotation has zero length' at the first END) and a huge one
    does not overflow: the run equals the example's."""
    text, _ = replace(old, new)
    res = spacar.simulate(spacar.read_string(text, FILE))
    ref = spacar.simulate(spacar.read(SPATIAL_EXAMPLE))
    np.testing.assert_allclose(res.x, ref.x, rtol=0, atol=1e-13)
    np.testing.assert_allclose(res.e, ref.e, rtol=0, atol=1e-13)


# ---------------------------------------------------------------------------------------------
# Inertia tensors (MASS on a LAMBDA node: Ixx Ixy Ixz Iyy Iyz Izz)
# ---------------------------------------------------------------------------------------------

NOT_SEMIDEFINITE = [
    ("negative Ixx", (-1, 0, 0, 1, 0, 1)),
    ("Ixy larger than sqrt(Ixx Iyy)", (1, 2, 0, 1, 0, 3)),
    # passes the leading principal minors (0, 0, 0): principal moments -0.618, 0, 1.618
    ("zero Ixx, Iyz = Iyy", (0, 0, 0, 1, 1, 0)),
    # all 2x2 minors positive, determinant negative: principal moments -0.2, 1.6, 1.6
    ("negative determinant", (1, -0.6, -0.6, 1, -0.6, 1)),
]


@pytest.mark.parametrize("tensor", [c[1] for c in NOT_SEMIDEFINITE], ids=[c[0] for c in NOT_SEMIDEFINITE])
def test_inertia_tensor_not_positive_semidefinite(tensor):
    J = np.array([[tensor[0], tensor[1], tensor[2]], [tensor[1], tensor[3], tensor[4]], [tensor[2], tensor[4], tensor[5]]])
    assert np.linalg.eigvalsh(J).min() < -0.1
    text, line = insert_before("ED 4 1", "MASS 5 " + " ".join(str(v) for v in tensor))
    raises_located(text, line, "MASS", r"the inertia tensor of node 5 is not positive semidefinite")


@pytest.mark.parametrize("tensor", [(0, 0, 0, 0, 0, 0), (0, 0, 0, 1e-3, 0, 1e-3), (2, 0.1, -0.2, 3, 0.3, 4)],
                         ids=["zero", "thin rod", "general"])
def test_semidefinite_inertia_tensors_are_accepted(tensor):
    """On the fixed ground orientation 11, so that the run is the example's."""
    text, _ = insert_before("ED 4 1", "MASS 11 " + " ".join(str(v) for v in tensor))
    model = spacar.read_string(text, FILE)
    assert model.nodes[11].mass == list(map(float, tensor))
    assert spacar.simulate(model).t[-1] == 5.0


# ---------------------------------------------------------------------------------------------
# Euler parameters far from unit length
# ---------------------------------------------------------------------------------------------

EULER_CASES = [
    ("LAMBDA line", "LAMBDA 11 0.9 0.1 0. 0.", "LAMBDA", r"Euler parameters of node 11 have norm 0\.905\d*; they must be of unit length"),
    ("LAMBDA slightly long", "LAMBDA 11 1.002 0. 0. 0.", "LAMBDA", r"norm 1\.002"),
    ("X with four values", "X 11 0.5 0.5 0.5 0.6", "X", r"norm 1\.05\d*"),
    ("X with one value", "X 11 0.5", "X", r"Euler parameters of node 11 have norm 0\.5\b"),
    ("zero vector", "LAMBDA 11 0. 0. 0. 0.", "LAMBDA", r"norm 0\b"),
]


@pytest.mark.parametrize("new, keyword, reason", [c[1:] for c in EULER_CASES], ids=[c[0] for c in EULER_CASES])
def test_euler_parameters_far_from_unit_length(new, keyword, reason):
    text, line = insert_before("INPUTE 4 1", new)
    raises_located(text, line, keyword, reason)


# ---------------------------------------------------------------------------------------------
# Fully fixed LAMBDA nodes are legal
# ---------------------------------------------------------------------------------------------

def test_fully_fixed_lambda_node_runs():
    """FIX 10 and FIX 11 fix all Euler parameters of the ground orientations; their L2MIN1
    rows are checked instead of solved and the mechanism runs."""
    model = spacar.read(SPATIAL_EXAMPLE)
    assert model.summary().coordinates["fixed"] == 3 + 4 + 4 + 1
    res = spacar.simulate(model)
    assert res.t[-1] == 5.0
    np.testing.assert_array_equal(res.node(11).x[-1], [1.0, 0.0, 0.0, 0.0])


def test_fully_fixed_rotated_lambda_node_with_four_digit_euler_parameters_runs():
    """The slider's ground orientation rotated by 90° about z, typed with four digits (norm
    0.99999, accepted within 1e-3): nothing can move a fully fixed node, so the Euler parameters
    are normalised at END instead of failing its L2MIN1 check. The motion is that of the
    original (the hinge axis z is invariant under the rotation)."""
    text, _ = insert_before("INPUTE 4 1", "LAMBDA 11 0.7071 0. 0. 0.7071")
    rotated = spacar.simulate(spacar.read_string(text, FILE))
    original = spacar.simulate(spacar.read(SPATIAL_EXAMPLE))
    h = math.sqrt(0.5)
    np.testing.assert_allclose(rotated.node(11).x, np.tile([h, 0.0, 0.0, h], (len(rotated.t), 1)), rtol=0, atol=1e-15)
    for n in (3, 6, 8):
        np.testing.assert_allclose(rotated.node(n).x, original.node(n).x, rtol=0, atol=1e-12)
    # and the dump of the rotated model (four digits again) restarts
    model = spacar.read_string(text, FILE)
    spacar.simulate(model)
    assert spacar.simulate(spacar.read_string(model.dump(), "dump.dat")).t[-1] == 10.0


def test_fully_fixed_lambda_node_clamping_a_beam():
    """A cantilever clamp: FIX of the XYZ and the LAMBDA node at the root."""
    m = spacar.Model()
    m.beam(1, 1, 2, 3, 4, 0.0, 1.0, 0.0)
    m.x(3, 1.0, 0.0, 0.0)
    m.fix(1)
    m.fix(2)
    m.dyne(1, 5, 6)
    m.estiff(1, 0.0, 0.0, 0.0, 1.0)
    m.emass(1, 1.0)
    m.e(1, 6, 0.01)
    m.timestep(10, 1.0)
    res = spacar.simulate(m)
    np.testing.assert_array_equal(res.node(2).x, np.tile([1.0, 0.0, 0.0, 0.0], (11, 1)))
    assert np.abs(res.node(3).x[:, 1]).max() > 1e-3


# ---------------------------------------------------------------------------------------------
# Kinematic failures of spatial mechanisms (as the planar ones of issue #3)
# ---------------------------------------------------------------------------------------------

def test_over_constrained_spatial_slider_crank_names_the_hinge_misalignments():
    """Without releasing the misalignments of the slider hinge the 3-D slider-crank is
    over-constrained by 2; the diagnosis names them as the release set."""
    text = "\n".join(line for line in BASE if line not in ("RLSE 6 2", "RLSE 6 3")) + "\n"
    with pytest.raises(KinematicsError) as info:
        spacar.simulate(spacar.read_string(text, FILE))
    message = str(info.value)
    assert "over-constrained by 2" in message
    assert "RLSE 6 2" in message and "RLSE 6 3" in message


def test_singular_constraint_block_at_assembly_is_diagnosed():
    """The slider's z fixed (one more constraint) and a misalignment of the crank-rod hinge
    released (one less): 27 equations for 27 coordinates, but rank 26 — the rod can turn
    about the x axis while the out-of-plane rows of the loop are dependent. The LU has an
    exactly zero pivot that Eigen's rcond estimate missed (it returned 0.083, and the run used
    to end in an IntegrationError about NaN residuals); now a KinematicsError at t = 0 with the
    diagnosis."""
    text, _ = replace("FIX 8 2", "FIX 8 2 3")
    text = text.replace("RLSE 5 1\n", "RLSE 5 1\nRLSE 5 2\n")
    with pytest.raises(KinematicsError) as info:
        spacar.simulate(spacar.read_string(text, FILE))
    message = str(info.value)
    assert "singular at t = 0" in message
    assert "27 calculable coordinates; rank 26" in message
    assert "nan" not in message.lower()
    assert re.search(r"free motion: node 5 component 2 .*node 7 component 2 .*node 9 component 2", message), message


def test_spatial_four_bar_that_cannot_be_assembled():
    """A coupler longer than the largest crank-to-rocker distance: the assembly (t = 0) cannot
    meet the constraints, and the error says so from the least-squares configuration, naming the
    deformations that miss most (issue 41; before: 'did not converge in 50 iterations')."""
    model = rssr_model("truss")
    model.lengtho(3, 1.2)
    with pytest.raises(KinematicsError) as info:
        spacar.simulate(model)
    message = str(info.value)
    assert re.search(r"found no configuration that meets the constraints at t = 0: .*least squares", message), message
    assert "the largest residuals element" in message


@pytest.mark.parametrize("Lc", [0.62, 0.65])
def test_driven_spatial_four_bar_stops_at_its_dead_point(Lc):
    """A coupler too short for a full crank turn: the crank driven at 1.5 rad/s reaches the
    dead point θ* of the closed-form loop equation (|R| = √(P² + Q²)); the kinematic analysis
    fails with KinematicsError at the first output time after t* = θ*/1.5."""
    def excess(theta):
        P, Q, R = RSSR.loop_coefficients(theta, Lc)
        return abs(R) / math.hypot(P, Q) - 1.0

    thetas = np.linspace(0.0, 2 * math.pi, 4001)
    assert excess(0.0) < 0
    first = next(th for th in thetas if excess(th) > 0)
    lo, hi = first - thetas[1], first
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if excess(mid) < 0 else (lo, mid)
    t_dead = hi / 1.5
    model = rssr_model("truss")
    model.lengtho(3, Lc)
    with pytest.raises(KinematicsError) as info:
        spacar.simulate(model)
    t_fail = float(re.search(r"at t = ([0-9.eE+-]+)", str(info.value)).group(1))
    assert t_dead < t_fail <= t_dead + 0.05, (t_dead, str(info.value))

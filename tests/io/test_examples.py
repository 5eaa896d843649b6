"""Every example input in examples/ reads, passes `spacar check` (exit 0), runs its analysis
(`spacar run`, or `spacar static` for the flexures) and meets one physical check against an
independent reference computed here: a closed form (four-bar and dyad position analysis by
circle intersection, the inverse kinematics of a Stewart platform, the belt ratio, flexure
formulas), or a conservation law (energy).

Each example is a teaching file: the test also keeps it commented (`*` lines) and short."""
from __future__ import annotations

import re
import subprocess
import sys
import time

import numpy as np
import pytest

import spacar
from support.paths import EXAMPLES, ROOT


def _guide_figures():
    """docs/generate.py, which holds the models of the guide's figures (importing it draws nothing)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("spacar_docs_generate", ROOT / "docs" / "generate.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module

TWO_PI = 2 * np.pi


# --------------------------------------------------------------------------------------------
# Closed-form references
# --------------------------------------------------------------------------------------------

def circles(p, r1, q, r2, side):
    """The intersection of the circles (p, r1) and (q, r2) on the given side (+1: left) of p→q."""
    d = np.linalg.norm(q - p)
    a = (r1**2 - r2**2 + d**2) / (2 * d)
    u = (q - p) / d
    return p + a * u + side * np.sqrt(r1**2 - a**2) * np.array([-u[1], u[0]])


def side(p, q, x):
    u, v = q - p, x - p
    return np.sign(u[0] * v[1] - u[1] * v[0])


def turn(phi):
    return np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])


def angle(v):
    return np.arctan2(v[1], v[0])


def dyad(p, p0, q, x0):
    """Where the pin x of a dyad p-x-q (p moving from p0, q on the ground) goes: the same link
    lengths and the same branch as the initial position x0."""
    return circles(p, np.linalg.norm(x0 - p0), q, np.linalg.norm(x0 - q), side(p0, q, x0))


def rigid(point0, a0, b0, a, b):
    """Where a point of a rigid body goes when two of its points move from a0, b0 to a, b."""
    return a + turn(angle(b - a) - angle(b0 - a0)) @ (point0 - a0)


def fourbar(A, B0, C0, D, crank_angle):
    """The crank-rocker A-B-C-D at every crank angle: B and C by position analysis."""
    B = [A + np.linalg.norm(B0 - A) * np.array([np.cos(t), np.sin(t)]) for t in crank_angle]
    C = [dyad(b, B0, D, C0) for b in B]
    return np.array(B), np.array(C)


def xy(res, n):
    return res.node(n).x


# --------------------------------------------------------------------------------------------
# One physical check per example
# --------------------------------------------------------------------------------------------

A, B0, C0, D = (np.array(p, float) for p in [(0, 0), (0, 1), (3, 3), (4, 0)])


def check_fourbar_coupler(res):
    """The coupler curve of P against the four-bar's closed-form position analysis; the crank
    turns fully (Grashof crank-rocker)."""
    P0 = np.array([2.0, 4.0])
    B, C = fourbar(A, B0, C0, D, np.pi / 2 + res.node(2).x[:, 0])
    P = np.array([rigid(P0, B0, C0, b, c) for b, c in zip(B, C)])
    np.testing.assert_allclose(xy(res, 11), P, atol=1e-7)
    assert res.node(2).x[-1, 0] == pytest.approx(TWO_PI)
    lengths = sorted([1.0, np.sqrt(13), np.sqrt(10), 4.0])
    assert lengths[0] + lengths[3] <= lengths[1] + lengths[2]


def check_watt_sixbar(res):
    """The output rocker G-F: the rocker D-C-E of loop 1 (closed form) drives loop 2 (a dyad)."""
    E0, F0, G = np.array([5.5, 2.0]), np.array([7.5, 3.0]), np.array([8.0, 0.0])
    B, C = fourbar(A, B0, C0, D, np.pi / 2 + res.node(2).x[:, 0])
    E = [rigid(E0, D, C0, D, c) for c in C]
    F = np.array([dyad(e, E0, G, F0) for e in E])
    np.testing.assert_allclose(xy(res, 14), F, atol=1e-7)


def check_stephenson_sixbar(res):
    """The dyad's pin F follows from the coupler point E of the four-bar (closed form)."""
    E0, F0, G = np.array([2.0, 4.0]), np.array([0.0, 5.0]), np.array([-1.0, 3.0])
    B, C = fourbar(A, B0, C0, D, np.pi / 2 + res.node(2).x[:, 0])
    E = [rigid(E0, B0, C0, b, c) for b, c in zip(B, C)]
    F = np.array([dyad(e, E0, G, F0) for e in E])
    np.testing.assert_allclose(xy(res, 14), F, atol=1e-7)


def check_double_pendulum(res):
    """Energy conservation: ½ m (|v3|² + |v6|²) + m g (y3 + y6) stays at its initial value
    (0: at rest with both rods horizontal), computed here from the nodes' positions and rates."""
    m, g = 1.0, 9.81
    kinetic = 0.5 * m * sum((res.node(n).xd ** 2).sum(axis=1) for n in (3, 6))
    potential = m * g * (res.node(3).x[:, 1] + res.node(6).x[:, 1])
    energy = kinetic + potential
    assert abs(energy).max() < 1e-5 * kinetic.max()
    assert kinetic.max() > 10.0                         # it did swing


def check_belt_drive(res):
    """β1 = ½ T t² / (J1 + J2 (r1/r2)²) from rest under the torque T; β2 = (r1/r2) β1."""
    T, J1, J2, ratio = 0.2, 1e-4, 2e-3, 0.05 / 0.10
    beta1 = 0.5 * T / (J1 + J2 * ratio**2) * res.t**2
    np.testing.assert_allclose(res.node(2).x[:, 0], beta1, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(res.node(4).x[:, 0], ratio * beta1, rtol=1e-6, atol=1e-9)


def check_stewart_platform(res):
    """Pure heave: every platform node keeps its x, y and rises to sqrt(l² − 0.75) for the leg
    length l = sqrt(1.75) + 0.2 t (the inverse kinematics of the symmetric platform)."""
    height = np.sqrt((np.sqrt(1.75) + 0.2 * res.t) ** 2 - 0.75)
    for n in (11, 12, 13):
        x = res.node(n).x
        np.testing.assert_allclose(x[:, :2], np.repeat(x[:1, :2], len(res.t), axis=0), atol=1e-9)
        np.testing.assert_allclose(x[:, 2], height, rtol=1e-9)


EI, L = 2.1e11 * 0.02 * 0.0005**3 / 12, 0.05      # the leaves of the flexure examples


def check_parallel_leaf_guide(res):
    """The stage moves F / (24 EI / L³) under the drive force F = 1 N (two clamped-guided
    leaves; their axial compliance adds 3e-4), and it does not tilt (to first order)."""
    u = res.node(9).x[-1, 0]
    assert u == pytest.approx(1.0 / (24 * EI / L**3), rel=1e-3)
    assert abs(res.node(10).x[-1, 0]) < 1e-3 * u / L


def check_cross_spring_pivot(res):
    """The body turns M / (2 EI / L) under the moment M (leaves crossing at their midpoints:
    circular arcs, Haringx 1949)."""
    assert res.node(10).x[-1, 0] == pytest.approx(0.0175 / (2 * EI / L), rel=1e-4)


def check_flexible_arm(res):
    """Energy conservation without damping: kinetic + gravity + strain (res.energy) constant;
    the links do bend (strain energy), and the tip falls."""
    energy = res.energy
    assert abs(energy.balance).max() < 1e-6 * energy["kinetic"].max()
    assert energy["strain"].max() > 0.0 and abs(res.deformation(2, 2)).max() > 1e-4
    assert res.node(10).x[-1, 0] < 1.0


def check_bricard_linkage(res):
    """The loop closes as a chain of screw motions (product of exponentials, computed here
    from the hinge angles: the ground link comes back to itself); the released misalignment
    stays zero (the linkage is mobile although over-constrained); threefold symmetry
    θ1 = θ3 = θ5, θ2 = θ4 = θ6."""
    from scipy.spatial.transform import Rotation

    points = np.array([(1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1), (1, 0, 1)], float)
    axes = np.eye(3)[[0, 2, 1, 0, 2, 1]]
    angles = np.array([res.deformation(e, 1) for e in range(7, 13)]).T
    for theta in angles:
        loop = np.eye(4)
        for u, p, t in zip(axes, points, theta):
            screw = np.eye(4)
            screw[:3, :3] = Rotation.from_rotvec(u * t).as_matrix()
            screw[:3, 3] = (np.eye(3) - screw[:3, :3]) @ p
            loop = loop @ screw
        np.testing.assert_allclose(loop, np.eye(4), atol=1e-7)
    assert abs(res.deformation(12, 3)).max() < 1e-7
    np.testing.assert_allclose(angles[:, [2, 4]], angles[:, [0, 0]], atol=1e-7)
    np.testing.assert_allclose(angles[:, [3, 5]], angles[:, [1, 1]], atol=1e-7)
    assert angles[-1, 0] == pytest.approx(0.5) and abs(angles[-1, 1]) > 1.0


EXAMPLES_CHECKED = {
    "fourbar_coupler": ("run", check_fourbar_coupler),
    "watt_sixbar": ("run", check_watt_sixbar),
    "stephenson_sixbar": ("run", check_stephenson_sixbar),
    "double_pendulum": ("run", check_double_pendulum),
    "belt_drive": ("run", check_belt_drive),
    "stewart_platform": ("run", check_stewart_platform),
    "parallel_leaf_guide": ("static", check_parallel_leaf_guide),
    "cross_spring_pivot": ("static", check_cross_spring_pivot),
    "flexible_arm": ("energy", check_flexible_arm),
    "bricard_linkage": ("run", check_bricard_linkage),
}
EXISTING = ["andrews_squeezer", "bicycle", "slidercrank", "slidercrank3d"]


def cli(*args):
    return subprocess.run([sys.executable, "-m", "spacar", *args], capture_output=True, text=True, cwd=ROOT)


def analyse(name, how):
    model = spacar.read(EXAMPLES / f"{name}.dat")
    start = time.perf_counter()
    if how == "static":
        res = spacar.static(model)
    else:
        res = spacar.simulate(model, progress=False, energy=how == "energy")
    return model, res, time.perf_counter() - start


@pytest.mark.parametrize("name", sorted(EXAMPLES_CHECKED))
def test_example(name):
    how, check = EXAMPLES_CHECKED[name]
    out = cli("check", str(EXAMPLES / f"{name}.dat"))
    assert out.returncode == 0, out.stdout + out.stderr
    assert "warning" not in out.stdout
    model, res, seconds = analyse(name, how)
    assert model.warnings == []           # the X positions close every loop, nothing is checked only
    check(res)
    assert seconds < 5.0     # a short run (~2 s on a loaded 2-core machine)


def test_bricard_without_its_release_is_over_constrained_and_check_release_names_it(tmp_path):
    text = (EXAMPLES / "bricard_linkage.dat").read_text()
    assert "\nRLSE 12 3\n" in text
    path = tmp_path / "bricard.dat"
    path.write_text(text.replace("\nRLSE 12 3\n", "\n"))
    plain = cli("check", str(path))
    assert plain.returncode == 1 and "over-constrained by 1" in plain.stdout
    released = cli("check", "--release", str(path))
    assert released.returncode == 0, released.stdout + released.stderr
    assert "* RLSE 12 3 " in released.stdout


def test_the_modelling_guide_runs_its_python_blocks_and_shows_every_example():
    text = (ROOT / "docs" / "modelling.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 2
    for block in blocks:
        out = subprocess.run([sys.executable, "-c", block], capture_output=True, text=True, cwd=ROOT)
        assert out.returncode == 0, out.stderr
    for name in set(EXAMPLES_CHECKED) | set(EXISTING):
        assert f"`{name}.dat`" in text, name


# The guide's rough four-bar, as docs/generate.py draws it for docs/modelling.md.
ROUGH_FOURBAR = _guide_figures().ROUGH_FOURBAR


def test_a_loop_that_the_x_positions_do_not_close_warns_with_the_node_and_the_distance():
    model = spacar.read_string(ROUGH_FOURBAR)
    res = spacar.simulate(model)
    np.testing.assert_allclose(res.node(6).x[0], [3.0, 3.0], atol=1e-5)
    [warning] = model.warnings
    assert "moved node 6 by 0.4472 from its X position (3.2, 2.6) to (3, 3)" in warning
    # The crank's input starting at 0.5 rad from positions drawn at 0: B and C move.
    turned = spacar.read_string(ROUGH_FOURBAR.replace("X 6 3.2 2.6", "X 6 3. 3.").replace("INPUTX 2", "INPUTX 2\nX 2 0.5"))
    spacar.simulate(turned)
    assert [w.split(" by ")[0] for w in turned.warnings] == ["the assembly moved node 3", "the assembly moved node 6"]
    spacar.simulate(turned)                    # later blocks do not warn again
    assert len(turned.warnings) == 2


def test_a_turned_ground_that_moves_every_node_warns_of_three_and_sums_up_the_rest():
    from spacar.compare import models
    model = models.spatial_chain(6, seed=3, n_out=1, t_end=0.01)  # the ground turned 0.4 rad: all 6 nodes move
    given = {i: np.array(model.nodes[i].x) for i in range(2, 8)}
    res = spacar.simulate(model)
    assert [w.split(" by ")[0] for w in model.warnings[:3]] == [f"the assembly moved node {i}" for i in (2, 3, 4)]
    moved = {i: np.linalg.norm(res.node(i).x[0] - given[i]) for i in (5, 6, 7)}
    far = max(moved, key=moved.get)
    assert model.warnings[3:] == [
        f"the assembly moved 3 more nodes from their X positions, the farthest node {far} by {moved[far]:.4g}"]


def test_a_crank_driven_past_a_dead_position_says_so_and_names_the_input_reached():
    """The four-bar of fourbar_coupler.dat with a crank of 3 (B = (0, 3)) and C = (2, 4): the
    coupler (√5) is the shortest link, so the crank cannot turn fully; coupler and rocker fall in
    line when |BD| = √5 + √20, i.e. at the crank turn θ with 25 + 24 sin θ = (√5 + √20)²."""
    text = (EXAMPLES / "fourbar_coupler.dat").read_text()
    model = spacar.read_string(text.replace("X 3 0. 1.", "X 3 0. 3.").replace("X 6 3. 3.", "X 6 2. 4."))
    with pytest.raises(spacar.KinematicsError, match="did not converge") as info:
        spacar.simulate(model)
    message = str(info.value)
    assert "dead (limit) position" in message and "Grashof" in message
    toggle = np.arcsin(((np.sqrt(5) + np.sqrt(20)) ** 2 - 25) / 24)
    reached = info.value.results.node(2).x[-1, 0]
    assert f"inputs node 2 x1 = {reached:.6g} (heading for" in message
    assert reached < toggle < reached + TWO_PI / 36


@pytest.mark.parametrize("name", sorted(EXAMPLES_CHECKED))
def test_example_is_commented(name):
    lines = (EXAMPLES / f"{name}.dat").read_text().splitlines()
    assert lines[0].startswith("*") and sum(line.startswith("*") for line in lines) >= 5


def test_every_example_is_tested():
    files = {p.stem for p in EXAMPLES.glob("*.dat")}
    assert files == set(EXAMPLES_CHECKED) | set(EXISTING)
    assert len(EXAMPLES_CHECKED) >= 10

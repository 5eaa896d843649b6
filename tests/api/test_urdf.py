"""spacar.from_urdf (issue 21): URDF robots against Pinocchio, which reads the same files with
its own parser (urdfdom): the joint order, the link frames' positions, M(q) against
pinocchio.crba, q̈ against pinocchio.aba at random (q, q̇, τ), spacar.inverse_dynamics against
pinocchio.rnea, a gravity swing against ABA
integrated by SciPy; and the reporting of what a URDF holds that the model leaves out.

The small robots are hand-written (tests/data/*.urdf); UR5 and Panda come from the PyPI package
example-robot-data (the ``robots`` extra), skipped when it is absent."""
from __future__ import annotations

import importlib.metadata
import warnings
from pathlib import Path

import numpy as np
import pytest

import spacar
from spacar import _core
from support.paths import DATA

SMALL = ["two_link_arm", "branched_tree", "prismatic", "fixed_joints"]


def robot_file(package: str, name: str) -> Path:
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed (pip install 'spacar[robots]')")
    return Path(dist.locate_file(f"cmeel.prefix/share/example-robot-data/robots/{package}/urdf/{name}"))


def urdf_path(name: str) -> Path:
    return {"ur5": lambda: robot_file("ur_description", "ur5_robot.urdf"),
            "panda": lambda: robot_file("panda_description", "panda.urdf"),
            "xarm7": lambda: robot_file("xarm_description", "xarm7.urdf"),
            "g1": lambda: robot_file("g1_description", "g1_29dof_rev_1_0.urdf")}.get(name, lambda: DATA / f"{name}.urdf")()


def load(path) -> spacar.Model:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # what the model leaves out: tested below
        model = spacar.from_urdf(path)
    model.epskin(1e-13)
    return model


# --- the model itself (no peer needed) -----------------------------------------------------------

def test_two_link_arm_elements_and_dofs():
    model = load(DATA / "two_link_arm.urdf")
    assert model.urdf_joints == ["shoulder", "elbow"]
    types = {e: el.type_name for e, el in model.elements.items()}
    assert types[1] == types[2] == "HINGE"
    model.timestep(2, 0.01)
    res = spacar.simulate(model)
    assert res.dof_labels == ["e(1,1) HINGE", "e(2,1) HINGE"]
    np.testing.assert_array_equal(res.q[0], [0.0, 0.0])
    # the elbow's link origin: (0, 0, 0.3) + Rz(0.5) (0.4, 0, 0.05) in the zero configuration
    node, _ = model.urdf_links["fore"]
    c, s = np.cos(0.5), np.sin(0.5)
    np.testing.assert_allclose(res.node(node).x[0], [0.4 * c, 0.4 * s, 0.35], atol=1e-14)


def test_prismatic_joints_are_bearings():
    model = load(DATA / "prismatic.urdf")
    assert [model.elements[k].type_name for k in (1, 2, 3)] == ["BEARING", "HINGE", "BEARING"]
    assert model.urdf_joints == ["slide", "turn", "grip"]


def test_fixed_joints_merge_into_one_body():
    model = load(DATA / "fixed_joints.urdf")
    lam = {link: nodes[1] for link, nodes in model.urdf_links.items()}
    assert lam["link2"] == lam["flange"] == lam["tool"] == lam["tcp"]
    assert lam["world"] == lam["base"] != lam["link1"]
    assert model.urdf_joints == ["j1", "j2"]
    copy = model.copy()
    assert copy.urdf_joints == model.urdf_joints and copy.urdf_links == model.urdf_links
    copy.urdf_joints.append("x")
    assert model.urdf_joints == ["j1", "j2"]


def test_what_is_left_out_is_reported(tmp_path):
    path = tmp_path / "mimic.urdf"
    path.write_text("""<robot name="r"><link name="a"/>
      <link name="b"><visual><geometry><mesh filename="b.stl"/></geometry></visual>
        <inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
      <link name="c"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
      <joint name="j1" type="continuous"><parent link="a"/><child link="b"/><dynamics damping="0.5"/></joint>
      <joint name="j2" type="revolute"><parent link="b"/><child link="c"/><origin xyz="1 0 0"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="j1" multiplier="2"/></joint>
      <transmission name="t"/></robot>""")
    with pytest.warns(UserWarning) as caught:
        model = spacar.from_urdf(path)
    text = " ".join(str(w.message) for w in caught)
    for part in ("mimic", "geometries", "transmissions", "limits are not enforced (joints j2)",
                 "damping and friction", str(path)):
        assert part in text
    assert len(model.warnings) == len(caught)
    assert model.urdf_joints == ["j1", "j2"]  # the mimic joint stays an independent DOF


@pytest.mark.parametrize("body, message", [
    ("<robot><link name='a'/><link name='b'/>", "not a well-formed"),
    ("<model/>", "not <robot>"),
    ("<robot><link name='a'/><link name='b'/><joint name='j' type='floating'><parent link='a'/>"
     "<child link='b'/></joint></robot>", "floating base is not supported"),
    ("<robot><link name='a'/><link name='b'/><joint name='j' type='planar'><parent link='a'/>"
     "<child link='b'/></joint></robot>", "is planar"),
    ("<robot><link name='a'/><link name='b'/><joint name='j' type='screw'><parent link='a'/>"
     "<child link='b'/></joint></robot>", "type 'screw'"),
    ("<robot><link name='a'/><link name='b'/></robot>", "one root"),
    ("<robot><link name='a'/><joint name='j' type='fixed'><parent link='a'/><child link='x'/></joint></robot>",
     "'x' is not defined"),
    ("<robot><link name='a'/><link name='b'/><joint name='j' type='revolute'><parent link='a'/>"
     "<child link='b'/><axis xyz='0 0 0'/></joint></robot>", "zero length"),
    ("<robot><link name='a'/><link name='b'/><joint name='j' type='revolute'><parent link='a'/>"
     "<child link='b'/><origin xyz='1 nan 0'/></joint></robot>", "3 finite numbers"),
    ("<robot><link name='a'/><link name='b'><inertial><mass value='-1'/></inertial></link>"
     "<joint name='j' type='revolute'><parent link='a'/><child link='b'/></joint></robot>", "negative mass"),
    ("<robot><link name='a'/><link name='a'/></robot>", "defined twice"),
    ("<robot><link name='a'/><link name='b'/><link name='c'/><joint name='j' type='fixed'><parent link='a'/>"
     "<child link='c'/></joint><joint name='k' type='fixed'><parent link='b'/><child link='c'/></joint></robot>",
     "child of two joints"),
])
def test_bad_files_name_the_file(tmp_path, body, message):
    path = tmp_path / "bad.urdf"
    path.write_text(body)
    with pytest.raises(spacar.InputError, match=message) as err:
        spacar.from_urdf(path)
    assert str(path) in str(err.value)


def test_bad_arguments():
    with pytest.raises(spacar.InputError, match="cannot read"):
        spacar.from_urdf(DATA / "no_such_robot.urdf")
    with pytest.raises(spacar.InputError, match="path of a URDF"):
        spacar.from_urdf(3)
    with pytest.raises(spacar.InputError, match="gravity"):
        spacar.from_urdf(DATA / "two_link_arm.urdf", gravity=(0, 0))


# --- against Pinocchio --------------------------------------------------------------------------

pin = pytest.importorskip("pinocchio")


class Peer:
    """The spacar model of a URDF, Pinocchio's model of the same file, and spacar's core
    simulation moved between states by continuation (steps of at most 0.25 in every joint, so
    that Newton stays on the assembled branch)."""

    def __init__(self, name, gravity=(0.0, 0.0, -9.81), torques=None):
        self.path = urdf_path(name)
        self.model = load(self.path)
        if gravity != (0.0, 0.0, -9.81):
            self.model.gravity(*gravity)
        self.pin = pin.buildModelFromUrdf(str(self.path))
        self.pin.gravity.linear = np.array(gravity, dtype=float)
        self.data = self.pin.createData()
        self.tau = np.zeros(self.pin.nv)
        if torques is not None:
            self.apply_torques(torques)
        self.sim = _core.Simulation(self.model.core)
        self.sim.assemble()
        self.q = np.zeros(self.pin.nv)
        system = self.sim.system
        self.column = {tuple(lbl): i for i, lbl in enumerate(system.coord_label)}

    def apply_torques(self, rng):
        """Random joint torques τ on the revolute joints, as equal and opposite body-fixed torques
        (TORQUEL) about the hinge axis on the child and parent bodies: the axis is fixed in both,
        at its zero-configuration direction in their reference frames. (Prismatic joints: τ = 0.)"""
        torque: dict = {}
        elements = self.model.elements
        for k in range(1, self.pin.nv + 1):
            el = elements[k]
            if el.type_name != "HINGE":
                continue
            tau = rng.uniform(-2.0, 2.0)
            self.tau[k - 1] = tau
            axis = np.array(el.params) / np.linalg.norm(el.params)
            parent, child = el.nodes
            torque[child] = torque.get(child, 0.0) + tau * axis
            torque[parent] = torque.get(parent, 0.0) - tau * axis
        for node, t in torque.items():
            self.model.torquel(node, *t)

    def pin_q(self, q):
        # continuous joints: Pinocchio's q holds (cos θ, sin θ); its tangent is θ as for the others
        return pin.integrate(self.pin, pin.neutral(self.pin), q)

    def move(self, q, qd):
        steps = max(1, int(np.ceil(np.abs(q - self.q).max() / 0.25)))
        for s in np.linspace(0.0, 1.0, steps + 1)[1:]:
            self.sim.evaluate(0.0, self.q + s * (q - self.q), qd)
        self.q = q.copy()
        return self.sim.data

    def link_position_error(self, x, q):
        pin.framesForwardKinematics(self.pin, self.data, self.pin_q(q))
        err = 0.0
        for link, (node, _) in self.model.urdf_links.items():
            p = self.data.oMf[self.pin.getFrameId(link)].translation
            cols = [self.column[(node, c)] for c in (1, 2, 3)]
            err = max(err, float(np.abs(x[cols] - p).max()))
        return err


ROBOTS = SMALL + ["ur5", "panda", "xarm7", "g1"]


@pytest.mark.parametrize("name", ROBOTS)
def test_joint_order_and_names_are_pinocchio_s(name):
    peer = Peer(name)
    assert peer.model.urdf_joints == list(peer.pin.names)[1:]
    assert peer.sim.system.n_dof == peer.pin.nv


@pytest.mark.parametrize("name", ROBOTS)
def test_mass_matrix_and_accelerations_match_crba_and_aba(name):
    rng = np.random.default_rng(sum(map(ord, name)))
    peer = Peer(name, torques=rng)
    nv = peer.pin.nv
    for _ in range(4):
        q, qd = rng.uniform(-1.5, 1.5, nv), rng.uniform(-2.0, 2.0, nv)
        d = peer.move(q, qd)
        qp = peer.pin_q(q)
        assert peer.link_position_error(np.array(d.x), q) < 1e-12
        M = pin.crba(peer.pin, peer.data, qp)
        M = np.triu(M) + np.triu(M, 1).T
        a = pin.aba(peer.pin, peer.data, qp, qd, peer.tau)
        assert np.abs(np.array(d.Mbar) - M).max() <= 1e-10 * max(1.0, np.abs(M).max())
        assert np.abs(np.array(d.qdd) - a).max() <= 1e-10 * max(1.0, np.abs(a).max())


@pytest.mark.parametrize("name", ROBOTS)
def test_inverse_dynamics_matches_rnea(name):
    """spacar.inverse_dynamics against pinocchio.rnea on a batch of states, and the recursive path's
    q̈ against pinocchio.aba: every robot here is a tree of the recursive path (since issue 37 also
    xArm7's and G1's joints at one origin, Panda's sliding fingers on bodies without a beam, the
    prismatic joints of tests/data/prismatic.urdf)."""
    rng = np.random.default_rng(sum(map(ord, name)) + 1)
    peer = Peer(name)
    nv = peer.pin.nv
    end = rng.uniform(-1.5, 1.5, nv)
    q = np.outer(np.linspace(0.0, 1.0, 16), end)  # steps of at most 0.1 rad
    qd, qdd = rng.uniform(-2.0, 2.0, (16, nv)), rng.uniform(-3.0, 3.0, (16, nv))
    force, path = peer.sim.inverse_dynamics(q, qd, qdd)
    assert path == "tree"  # every robot here (issue 37: joints at one origin, sliding joints)
    for k in (0, 7, 15):  # and the tree's forward dynamics against pinocchio.aba
        a = pin.aba(peer.pin, peer.data, peer.pin_q(q[k]), qd[k], np.zeros(nv))
        qdd_tree = peer.sim.recursive_state(q[k], qd[k])["qdd"]
        assert np.abs(qdd_tree - a).max() <= 1e-10 * max(1.0, np.abs(a).max())
    ref = np.array([pin.rnea(peer.pin, peer.data, peer.pin_q(q[k]), qd[k], qdd[k]) for k in range(len(q))])
    assert np.abs(np.asarray(force) - ref).max() <= 1e-10 * max(1.0, np.abs(ref).max())
    # the public function: one state, the same numbers
    one = spacar.inverse_dynamics(peer.model, q[3], qd[3], qdd[3])
    assert one.shape == (nv,) and np.abs(one - ref[3]).max() <= 1e-10 * max(1.0, np.abs(ref).max())


def test_ur5_gravity_swing_matches_aba_integrated_by_scipy():
    from scipy.integrate import solve_ivp

    peer = Peer("ur5")
    model = load(peer.path)
    model.ed(2, 1, 0.5)  # the shoulder lift starts turning
    for eps in (model.epsint, model.epsind):
        eps(1e-11)
    model.timestep(10, 0.5)
    res = spacar.simulate(model)
    n = peer.pin.nv
    qd0 = np.zeros(n)
    qd0[1] = 0.5
    tau = np.zeros(n)

    def f(t, y):
        return np.concatenate((y[n:], pin.aba(peer.pin, peer.data, y[:n], y[n:], tau)))

    ref = solve_ivp(f, (0.0, 0.5), np.concatenate((np.zeros(n), qd0)), method="DOP853", t_eval=res.t,
                    rtol=1e-13, atol=1e-13)
    assert ref.success
    assert np.abs(res.q).max() > 1.0  # it swings
    np.testing.assert_allclose(res.q, ref.y[:n].T, rtol=0, atol=1e-9)
    np.testing.assert_allclose(res.qd, ref.y[n:].T, rtol=0, atol=1e-8)


def test_initial_joint_values_place_the_links_as_pinocchio_does():
    peer = Peer("panda")
    model = load(peer.path)
    q0 = np.array([0.3, -0.8, 0.5, -2.0, 0.4, 1.5, 0.7, 0.01, 0.02])
    for k, (value, rate) in enumerate(zip(q0, np.linspace(0.1, 0.9, 9)), start=1):
        model.e(k, 1, value)
        model.ed(k, 1, rate)
    model.timestep(2, 0.01)
    res = spacar.simulate(model)
    np.testing.assert_allclose(res.q[0], q0, rtol=0, atol=1e-14)
    np.testing.assert_allclose(res.qd[0], np.linspace(0.1, 0.9, 9), rtol=0, atol=1e-14)
    peer.column = {lbl: i for i, lbl in enumerate(res.coordinate_labels)}
    assert peer.link_position_error(res.x[0], q0) < 1e-12


# Of the URDFs of example-robot-data that from_urdf reads, those not on the recursive path, and why.
NOT_TREES = {"simple_humanoid.urdf": "turns a body with no point", "simple_humanoid_classical.urdf":
             "turns a body with no point"}


def test_example_robot_data_takes_the_recursive_path():
    """Every URDF of example-robot-data that from_urdf accepts is a tree of the recursive path, but
    the simple humanoid (a link with no point of its own that carries another joint)."""
    robots = robot_file("ur_description", "ur5_robot.urdf").parents[2]
    seen = 0
    for path in sorted(robots.glob("*/urdf/*.urdf")):
        try:
            model = load(path)
            sim = _core.Simulation(model.core)
            sim.assemble()
        except spacar.SpacarError:
            continue  # refused by from_urdf (a missing mesh package, an inertia that is not positive)
        seen += 1
        why = sim.recursive_refusal()
        assert (NOT_TREES[path.name] in why) if path.name in NOT_TREES else why == "", (path.name, why)
    assert seen >= 40

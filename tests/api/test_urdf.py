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
from support.paths import DATA, EXAMPLES

SMALL = ["two_link_arm", "branched_tree", "prismatic", "fixed_joints", "pivot", "slider_pivot"]


def robot_file(package: str, name: str, folder: str = "urdf") -> Path:
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed (pip install 'spacar[robots]')")
    return Path(dist.locate_file(f"cmeel.prefix/share/example-robot-data/robots/{package}/{folder}/{name}"))


def urdf_path(name: str) -> Path:
    return {"ur5": lambda: robot_file("ur_description", "ur5_robot.urdf"),
            "panda": lambda: robot_file("panda_description", "panda.urdf"),
            "xarm7": lambda: robot_file("xarm_description", "xarm7.urdf"),
            "g1": lambda: robot_file("g1_description", "g1_29dof_rev_1_0.urdf"),
            "simple_humanoid": lambda: robot_file("simple_humanoid_description", "simple_humanoid.urdf"),
            }.get(name, lambda: DATA / f"{name}.urdf")()


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
        <collision><geometry><box size="1 1 1"/></geometry></collision>
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
     "<child link='b'/></joint></robot>", "floating=True"),
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


ROBOTS = SMALL + ["ur5", "panda", "xarm7", "g1", "simple_humanoid"]


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


@pytest.mark.parametrize("name", ROBOTS)
def test_dynamics_derivatives_match_compute_aba_derivatives(name):
    """spacar.dynamics_derivatives against pinocchio.computeABADerivatives at random states and
    torques, over a batch in one call: q̈, ∂q̈/∂q, ∂q̈/∂q̇ and ∂q̈/∂τ = M⁻¹ to 1e-10 (relative to
    each matrix's largest entry). Exact derivatives: analytic on the spatial tree
    (spatial_derivatives.cpp, issue 37)."""
    rng = np.random.default_rng(sum(map(ord, name)) + 2)
    peer = Peer(name)
    nv = peer.pin.nv
    end = rng.uniform(-1.5, 1.5, nv)
    q = np.outer(np.linspace(0.2, 1.0, 5), end)
    qd, tau = rng.uniform(-2.0, 2.0, (5, nv)), rng.uniform(-3.0, 3.0, (5, nv))
    qdd, dq, dqd, dtau = spacar.dynamics_derivatives(peer.model, q, qd, tau)
    assert qdd.shape == (5, nv) and dq.shape == dqd.shape == dtau.shape == (5, nv, nv)
    for k in range(5):
        ref = pin.computeABADerivatives(peer.pin, peer.data, peer.pin_q(q[k]), qd[k], tau[k])
        expected_qdd = pin.aba(peer.pin, peer.data, peer.pin_q(q[k]), qd[k], tau[k])
        assert np.abs(qdd[k] - expected_qdd).max() <= 1e-10 * max(1.0, np.abs(expected_qdd).max())
        minv = np.triu(ref[2]) + np.triu(ref[2], 1).T
        for ours, theirs in zip((dq[k], dqd[k], dtau[k]), (ref[0], ref[1], minv)):
            assert np.abs(ours - theirs).max() <= 1e-10 * max(1.0, np.abs(theirs).max())
    one = spacar.dynamics_derivatives(peer.model, q[0], qd[0], tau[0])
    assert one[1].shape == (nv, nv) and np.abs(one[1] - dq[0]).max() == 0.0


def test_dynamics_derivatives_need_a_tree_of_the_recursive_path():
    model = spacar.read(EXAMPLES / "slidercrank.dat")  # a closed loop: the general path
    with pytest.raises(spacar.InputError, match="not a tree of rigid bodies of the recursive path"):
        spacar.dynamics_derivatives(model, [0.0] * 5, [0.0] * 5, [0.0] * 5)
    peer = Peer("ur5")
    with pytest.raises(spacar.InputError, match="q, qd and tau must have the same shape"):
        spacar.dynamics_derivatives(peer.model, np.zeros(6), np.zeros(6), np.zeros(5))


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


# --- floating base (issue 37) -------------------------------------------------------------------------

def base_velocity_map(lam):
    """T(λ) of (v, ω) of the base in its own axes, Pinocchio's free-flyer velocity, from the rates of
    spacar's base DOFs (ẋ, λ̇1, λ̇2, λ̇3) in global axes: v = Rᵀ ẋ, ω = Rᵀ 2 E(λ) λ̇, λ̇0 following
    from the L2MIN1 constraint λ · λ̇ = 0."""
    from spacar.geometry import euler_e, rotation

    R = rotation(lam)
    dlam = np.vstack([-lam[1:] / lam[0], np.eye(3)])
    T = np.zeros((6, 6))
    T[:3, :3] = R.T
    T[3:, 3:] = R.T @ (2.0 * euler_e(lam)) @ dlam
    return T


@pytest.mark.parametrize("name", ["solo12", "ur5"])
def test_floating_base_matches_pinocchio_s_free_flyer(name):
    """from_urdf(floating=True): the root link a free body (its origin and Euler parameters the
    first six DOFs, L2MIN1 holding λ0). At random states (base pose and twist, joints and rates):
    the reduced mass matrix is Pinocchio's crba with JointModelFreeFlyer in spacar's coordinates
    (Tᵀ M T), and the accelerations, the bias forces with them, are its aba's: the classical
    acceleration of the base origin, the base's angular acceleration and the joints' q̈."""
    from spacar.geometry import euler_e, rotation

    path = robot_file("solo_description", "solo12.urdf", "robots") if name == "solo12" else urdf_path(name)
    model = spacar.from_urdf(path, floating=True)
    model.epskin(1e-14)  # the positions to round-off: the comparison is at 1e-10
    assert model.urdf_base == (1, 2)
    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    data = pm.createData()
    sim = _core.Simulation(model.core)
    sim.assemble()
    column = {tuple(lbl): i for i, lbl in enumerate(sim.system.coord_label)}
    nv, rng, now = pm.nv, np.random.default_rng(7), np.zeros(pm.nv)
    assert sim.system.n_dof == nv and model.urdf_joints == list(pm.names)[2:]
    for _ in range(3):
        axis = rng.normal(size=3)
        lam = np.r_[np.cos(0.35), np.sin(0.35) * axis / np.linalg.norm(axis)]
        q = np.r_[rng.uniform(-0.5, 0.5, 3), lam[1:], rng.uniform(-1.0, 1.0, nv - 6)]
        qd = rng.uniform(-1.5, 1.5, nv)
        for s in np.linspace(0.0, 1.0, 9)[1:]:  # by continuation, on the assembled branch
            sim.evaluate(0.0, now + s * (q - now), qd)
        now = q
        d = sim.data
        T = np.eye(nv)
        T[:6, :6] = base_velocity_map(lam)
        q_pin = np.r_[q[:3], lam[1:], lam[0], q[6:]]
        v_pin = T @ qd
        M = pin.crba(pm, data, q_pin)
        M = np.triu(M) + np.triu(M, 1).T
        assert np.abs(np.array(d.Mbar) - T.T @ M @ T).max() <= 1e-10 * np.abs(M).max()
        a = pin.aba(pm, data, q_pin, v_pin, np.zeros(nv))
        R = rotation(lam)
        xdd = np.array(d.xdd)
        origin = xdd[[column[(1, c)] for c in (1, 2, 3)]]
        lam_dd = xdd[[column[(2, c)] for c in (1, 2, 3, 4)]]
        scale = max(1.0, np.abs(a).max())
        assert np.abs(origin - R @ (a[:3] + np.cross(v_pin[3:6], v_pin[:3]))).max() <= 1e-10 * scale
        assert np.abs(2.0 * euler_e(lam) @ lam_dd - R @ a[3:6]).max() <= 1e-10 * scale
        assert np.abs(np.array(d.qdd)[6:] - a[6:]).max() <= 1e-10 * scale


def test_floating_base_free_fall_matches_pinocchio_integrated_by_scipy():
    """Solo12 thrown with its joint torques off: 1 s of spacar against Pinocchio's aba with the
    free flyer's quaternion integrated by SciPy's DOP853 at 1e-12. The base is placed with X 1 and
    X 2 after from_urdf (the model comes prepared, its geometry the URDF's)."""
    from scipy.integrate import solve_ivp

    from spacar.compare.pinocchio import free_flyer_rhs

    from spacar.geometry import euler_e, rotation

    path = robot_file("solo_description", "solo12.urdf", "robots")
    model = spacar.from_urdf(path, floating=True)
    nj = len(model.urdf_joints)
    rng = np.random.default_rng(2)
    axis = rng.normal(size=3)
    lam = np.r_[np.cos(0.2), np.sin(0.2) * axis / np.linalg.norm(axis)]
    p, qj = np.array([0.0, 0.0, 0.5]), rng.normal(size=nj) * 0.3
    v, w, qdj = rng.normal(size=3) * 0.5, rng.normal(size=3), rng.normal(size=nj)
    model.x(1, *p)
    model.x(2, *lam)
    lam_d = 0.5 * euler_e(lam).T @ w
    for i in range(3):
        model.xd(1, i + 1, v[i])
    for i in range(4):
        model.xd(2, i + 1, lam_d[i])
    for k in range(nj):
        model.e(k + 1, 1, qj[k])
        model.ed(k + 1, 1, qdj[k])
    model.timestep(10, 1.0)
    for eps in (model.epsint, model.epsind):
        eps(1e-10)
    res = spacar.simulate(model)
    assert res.stats["path"] == "tree"

    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    data = pm.createData()
    R = rotation(lam)

    f = free_flyer_rhs(pm, data)

    y0 = np.r_[p, lam[1:], lam[0], qj, R.T @ v, R.T @ w, qdj]
    ref = solve_ivp(f, (0.0, 1.0), y0, method="DOP853", rtol=1e-12, atol=1e-12)
    assert ref.success
    qT = ref.y[:pm.nq, -1]
    quat = qT[3:7] / np.linalg.norm(qT[3:7])
    assert res.node(1).x[-1][2] < 0.0  # it fell
    np.testing.assert_allclose(res.node(1).x[-1], qT[:3], rtol=0, atol=1e-9)
    np.testing.assert_allclose(res.node(2).x[-1], np.r_[quat[3], quat[:3]], rtol=0, atol=1e-9)
    np.testing.assert_allclose(res.q[-1][6:], qT[7:], rtol=0, atol=1e-8)


def solo12_floating():
    model = spacar.from_urdf(robot_file("solo_description", "solo12.urdf", "robots"), floating=True)
    model.epskin(1e-14)
    return model


def ur5_floating_loaded():
    """The UR5 on a floating base with a FORCE on a link and gravity off the axes (other
    dependent Euler parameters and turned references: the tumbling run below)."""
    model = spacar.from_urdf(urdf_path("ur5"), floating=True)
    model.force(model.urdf_links["forearm_link"][0], 0.5, -1.0, 2.0)  # at the forearm's origin
    model.gravity(2.0, 1.0, -9.0)
    model.epskin(1e-14)
    return model


@pytest.mark.parametrize("build", [solo12_floating, ur5_floating_loaded], ids=["solo12", "ur5 loaded"])
def test_floating_base_takes_the_recursive_path(build):
    """A floating base on the recursive path (issue 37): the free root of the articulated-body
    algorithm, its DOFs the origin and three Euler parameters. At random states (base pose and
    twist, joints and rates) the tree's q̈ and its inverse dynamics equal the general path's (the
    constraint formulation with L2MIN1, itself equal to Pinocchio's free flyer above)."""
    model = build()
    tree = _core.Simulation(model.copy().core)
    tree.assemble()
    assert tree.recursive_refusal() == ""
    general = _core.Simulation(model.copy().core)
    general.assemble()
    nv = general.system.n_dof
    rng, now = np.random.default_rng(3), np.array(general.system.q0)
    for _ in range(3):  # states a small step away from the assembled one, in its partition
        q = now + rng.uniform(-0.2, 0.2, nv)
        qd = rng.uniform(-2.0, 2.0, nv)
        for s in np.linspace(0.0, 1.0, 9)[1:]:  # by continuation, on the assembled branch
            general.evaluate(0.0, now + s * (q - now), qd)
        now = q
        ref = np.array(general.data.qdd)
        scale = max(1.0, np.abs(ref).max())
        assert np.abs(np.array(tree.recursive_state(q, qd)["qdd"]) - ref).max() <= 1e-10 * scale
        qdd = rng.uniform(-3.0, 3.0, nv)
        force = np.array(general.data.Mbar) @ (qdd - ref)
        assert np.abs(spacar.inverse_dynamics(model, q, qd, qdd) - force).max() <= 1e-10 * max(1.0, np.abs(force).max())
    q[3:6] = 0.7  # three Euler parameters of a norm above 1: no orientation
    assert tree.recursive_state(q, qd) is None
    with pytest.raises(spacar.InputError, match="norm of 1"):
        spacar.inverse_dynamics(model, q, qd, qdd)
    with pytest.raises(spacar.InputError, match="norm of 1 or more at state 0"):
        spacar.dynamics_derivatives(model, q, qd, qdd)


FLOATING_ROBOTS = {"go1": ("go1_description", "go1.urdf", "urdf"),
                   "anymal_c": ("anymal_c_simple_description", "anymal.urdf", "urdf"),
                   "g1": ("g1_description", "g1_29dof_rev_1_0.urdf", "urdf"),
                   "talos_reduced": ("talos_data", "talos_reduced.urdf", "robots"),
                   "simple_humanoid": ("simple_humanoid_description", "simple_humanoid.urdf", "urdf")}


@pytest.mark.parametrize("name", FLOATING_ROBOTS)
def test_floating_robots_take_the_recursive_path(name):
    """Quadrupeds and humanoids of example-robot-data on a floating base: on the recursive path,
    the tree's q̈ equal to the general path's at a state near the assembled one (measured 1e-15 to
    2e-13 relative)."""
    model = spacar.from_urdf(robot_file(*FLOATING_ROBOTS[name]), floating=True)
    model.epskin(1e-13)
    tree, general = (_core.Simulation(model.copy().core) for _ in range(2))
    for sim in (tree, general):
        sim.assemble()
    assert tree.recursive_refusal() == ""
    nv, rng = general.system.n_dof, np.random.default_rng(1)
    q0 = np.array(general.system.q0)
    q, qd = q0 + rng.uniform(-0.05, 0.05, nv), rng.uniform(-1.0, 1.0, nv)
    for s in np.linspace(0.0, 1.0, 5)[1:]:
        general.evaluate(0.0, q0 + s * (q - q0), qd)
    ref = np.array(general.data.qdd)
    assert np.abs(np.array(tree.recursive_state(q, qd)["qdd"]) - ref).max() <= 1e-10 * max(1.0, np.abs(ref).max())


def solo12_tumbling():
    """Solo12 thrown spinning (6 rad/s) for 2 s: its orientation passes the half turn, where the
    dependent Euler parameter is exchanged."""
    model = solo12_floating()
    model.xd(2, 2, 3.0)
    model.xd(1, 1, 0.4)
    model.timestep(20, 2.0)
    for eps in (model.epsint, model.epsind):
        eps(1e-10)
    return model


def test_a_tumbling_floating_base_matches_the_general_path():
    """Solo12 tumbling past the exchange of its dependent Euler parameter (the tree recognized
    again in the new partition): the tree's run equals the general path's."""
    model = solo12_tumbling()
    tree = spacar.simulate(model.copy())
    general = spacar.simulate(model.copy(), recursive=False)
    assert tree.stats["path"] == "tree" and general.stats["path"] == "general"
    assert tree.node(2).x[:, 0].min() < 0.0  # past the half turn
    assert np.abs(tree.x - general.x).max() <= 1e-9


def solo12_turned(t_end):
    """Solo12 after t_end of the tumble: at 0.6 s λ0 near 0 (λ = (0.07, 0.997, …)), so that λ1 is
    the dependent Euler parameter; at 1.2 s λ0 dependent again, negative (λ0 = −0.99)."""
    def build():
        model = solo12_tumbling()
        model.timestep(round(10 * t_end), t_end)
        spacar.simulate(model)
        return model
    return build


@pytest.mark.parametrize("build, dependent, sign",
                         [(solo12_floating, 1, 1.0), (ur5_floating_loaded, 1, 1.0), (solo12_turned(0.6), 2, 1.0),
                          (solo12_turned(1.2), 1, -1.0)],
                         ids=["solo12", "ur5 loaded", "solo12 turned, λ1 dependent", "solo12 turned, λ0 < 0"])
def test_floating_base_dynamics_derivatives_match_the_inverse_dynamics(build, dependent, sign):
    """dynamics_derivatives on a floating base (issue 37), analytic: the base a joint of six
    world axes in the passes, taken to its DOFs (origin, three Euler parameters) by the chain
    rule. Checked against the inverse dynamics (equal to the general path's at random states
    above, whose mass matrix and accelerations equal Pinocchio's free flyer), independently of
    the derivative code: τ(q̈) = tau; M⁻¹ from the columns of τ in q̈ (linear: exact);
    ∂q̈/∂q = −M⁻¹ ∂τ/∂q and ∂q̈/∂q̇ = −M⁻¹ ∂τ/∂q̇ with ∂τ from fourth-order central differences
    (h = 3e-4), each row to its own scale (the Euler parameters' rows are small), over a batch
    of states in one call; with λ0, λ1 and a negative λ0 as the dependent parameter."""
    model = build()
    dyn = spacar.Dynamics(model)
    assembled = _core.Simulation(model.copy().core)
    assembled.assemble()
    nv, q0 = dyn.n_dof, np.array(assembled.system.q0)
    independent = [label for label in dyn.dof_labels if label.startswith("x(2,")]
    assert f"x(2,{dependent})" not in independent and len(independent) == 3
    assert np.sign(model.core.nodes[2].x[dependent - 1]) == sign
    rng = np.random.default_rng(11)
    q = q0 + rng.uniform(-0.1, 0.1, (3, nv))
    qd, tau = rng.uniform(-2.0, 2.0, (3, nv)), rng.uniform(-3.0, 3.0, (3, nv))
    qdd, dq, dqd, dtau = dyn.dynamics_derivatives(q, qd, tau)
    assert dq.shape == (3, nv, nv)
    h, unit = 3e-4, np.eye(nv)

    def slope(f):  # ∂f/∂z column by column, fourth order
        return np.column_stack([(8.0 * (f(h * e) - f(-h * e)) - (f(2 * h * e) - f(-2 * h * e))) / (12.0 * h)
                                for e in unit])

    for k in range(3):
        force = dyn.inverse_dynamics(q[k], qd[k], qdd[k])
        assert np.abs(force - tau[k]).max() <= 1e-10 * max(1.0, np.abs(tau[k]).max(), np.abs(force).max())
        M = np.column_stack([(dyn.inverse_dynamics(q[k], qd[k], qdd[k] + e) -
                              dyn.inverse_dynamics(q[k], qd[k], qdd[k] - e)) / 2.0 for e in unit])
        minv = np.linalg.inv(M)
        expected = (minv,
                    -minv @ slope(lambda s: dyn.inverse_dynamics(q[k] + s, qd[k], qdd[k])),
                    -minv @ slope(lambda s: dyn.inverse_dynamics(q[k], qd[k] + s, qdd[k])))
        for ours, theirs, tol in zip((dtau[k], dq[k], dqd[k]), expected, (1e-10, 1e-7, 1e-7)):
            row_scale = np.abs(theirs).max(axis=1)
            assert np.all(np.abs(ours - theirs).max(axis=1) <= tol * row_scale + 1e-13 * np.abs(theirs).max())


def test_a_floating_base_that_moves_no_mass_is_said():
    """A massless root link whose only joint turns about an axis through its origin: turning the
    base one way and the joint the other moves nothing (singular mass), named as such."""
    model = spacar.from_urdf(DATA / "wrist.urdf", floating=True)
    model.timestep(1, 0.01)
    with pytest.raises(spacar.SingularMassError, match="singular"):
        spacar.simulate(model)


def test_example_robot_data_takes_the_recursive_path():
    """Every URDF of example-robot-data that from_urdf accepts is a tree of the recursive path."""
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
        assert why == "", (path.name, why)  # the simple humanoid too since its elbows (a link of no point)
    assert seen >= 40

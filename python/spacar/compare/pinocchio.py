"""The equivalent Pinocchio model of a spacar model of rigid links, and side-by-side results.

Supported (anything else raises :class:`spacar.compare.UnsupportedModelError` naming the node or
element): kinematic *trees* of rigid bodies built from rigid PLBEAM/PLBEAMNL (planar) or
BEAM/BEAMNL (spatial) elements, with

* masses: ``MASS`` on position nodes (point masses), on BETA nodes (Izz) and LAMBDA nodes (the
  body-frame inertia tensor), ``EMASS`` ρA of the rigid beams (exact rigid-bar inertia) and the
  BEAM rotary-inertia extension (ρIp ρIy ρIz);
* joints: a position node shared by two bodies — a revolute joint about z (planar), about the
  HINGE axis if a HINGE joins the two bodies, or a spherical joint (spatial, no HINGE);
  PLHINGE/HINGE ``ESTIFF``/``EDAMPP`` on e1 become joint springs and dampers
  (τ = −St θ − d θ̇, which is exactly spacar's σ1 = St e1 + d ė1);
* the ground: fully fixed position nodes and fixed BETA/LAMBDA nodes (any constant rotation);
* ``GRAVITY``.

Not supported: closed loops (use :mod:`spacar.compare.exudyn`), flexible beams, prescribed
motions (INPUTX/INPUTE), FORCE/TORQUEL, free-floating bodies.

Coordinates. Pinocchio's joint coordinates are the rotations of each child body relative to its
parent: for a revolute joint θ = ±e1 of its hinge element, or β_child − β_parent (planar); for a
spherical joint the unit quaternion of R_parentᵀ R_child and the relative angular velocity in the
child frame. spacar's degrees of freedom may be any admissible choice (relative hinge angles with
DYNE, absolute BETA rotations with DYNX, Euler parameters); the map between the two velocity
spaces, T = ∂v_pin/∂q̇ (computed exactly from spacar's first-order transfer function DF), relates
the mass matrices: M̄ = Tᵀ M_crba T. With DYNE on the hinge elements of a chain oriented from the
ground outwards, T = I and spacar's q, q̇, q̈ are Pinocchio's q, v, a.
"""
from __future__ import annotations

import numpy as np

try:
    import pinocchio as pin
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise ImportError("spacar.compare.pinocchio needs Pinocchio: pip install 'spacar[compare]' (from a clone of spacar: pip install '.[compare]') (package pin)") from exc

from .. import _core
from ._topology import UnsupportedModelError, analyse


def _quat_xyzw(R: np.ndarray) -> np.ndarray:
    q = pin.Quaternion(R)
    q.normalize()
    return np.array([q.x, q.y, q.z, q.w])


class PinocchioModel:
    """A Pinocchio model equivalent to a spacar model, with the maps between the two sets of
    coordinates.

    ``model``/``data``: the ``pinocchio.Model`` and its ``Data``; ``joints``: (topology joint,
    parent body, child body) in Pinocchio's joint order; ``topology``: the analysis of
    :mod:`spacar.compare._topology`; ``sim``: the spacar ``_core.Simulation`` used for the maps.
    """

    def __init__(self, spacar_model):
        self.spacar_model = spacar_model
        self.sim = _core.Simulation(spacar_model.core)
        self.sim.assemble()
        topo = analyse(spacar_model, self.sim)
        self.topology = topo
        if topo.flexible:
            raise UnsupportedModelError(
                f"elements {[f.element for f in topo.flexible]} are flexible; Pinocchio models rigid links only "
                "(use spacar.compare.exudyn)")
        if topo.partial_fix:
            raise UnsupportedModelError(
                f"nodes {sorted(topo.partial_fix)} are partly fixed (sliders); Pinocchio's trees have no such constraint")
        for b in topo.bodies:
            if b.driven is not None:
                raise UnsupportedModelError(f"BETA node {b.driven.node} is prescribed (INPUTX); not converted to Pinocchio")
        self.joints = topo.tree()
        pm = pin.Model()
        pm.gravity.linear = np.array(topo.gravity, dtype=float)
        jid_of_body = {0: 0}
        origin_of_body = {0: np.zeros(3)}
        self.idx_q, self.idx_v = [], []
        for k, (j, p, c) in enumerate(self.joints):
            bp, bc = topo.bodies[p], topo.bodies[c]
            pivot_p = bp.points[j.node]
            if p == 0:
                placement = pin.SE3(topo.ground_rotation, pivot_p)
            else:
                placement = pin.SE3(np.eye(3), pivot_p - origin_of_body[p])
            if j.kind == "revolute":
                a = np.asarray(j.axis, dtype=float)
                if np.allclose(a, [0, 0, 1], atol=0, rtol=0):
                    jm = pin.JointModelRZ()
                elif np.allclose(a, [1, 0, 0], atol=0, rtol=0):
                    jm = pin.JointModelRX()
                elif np.allclose(a, [0, 1, 0], atol=0, rtol=0):
                    jm = pin.JointModelRY()
                else:
                    jm = pin.JointModelRevoluteUnaligned(a)
            else:
                jm = pin.JointModelSpherical()
            jid = pm.addJoint(jid_of_body[p], jm, placement, f"joint_{k}_node_{j.node}")
            origin = bc.points[j.node]
            origin_of_body[c] = origin
            jid_of_body[c] = jid
            if bc.mass > 0 or np.abs(bc.inertia_com).max() > 0:
                inertia = pin.Inertia(bc.mass, bc.com - origin, bc.inertia_com)
            else:
                inertia = pin.Inertia.Zero()
            pm.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
            self.idx_q.append(pm.joints[jid].idx_q)
            self.idx_v.append(pm.joints[jid].idx_v)
        self.model = pm
        self.data = pm.createData()
        self.revolute_only = all(j.kind == "revolute" for j, _, _ in self.joints)
        self._k = np.array([j.stiffness if j.kind == "revolute" else 0.0 for j, _, _ in self.joints])
        self._d = np.array([j.damping if j.kind == "revolute" else 0.0 for j, _, _ in self.joints])
        self.has_springs = bool(np.any(self._k) or np.any(self._d))
        self._jid_of_body = jid_of_body
        self._origin_of_body = origin_of_body
        self._last_q = np.array(self.sim.system.q0, dtype=float)

    # --- coordinates ----------------------------------------------------------------------

    @property
    def nq(self) -> int:
        return self.model.nq

    @property
    def nv(self) -> int:
        return self.model.nv

    def configuration(self, x, xd, e, ed):
        """Pinocchio (q, v) of the spacar state with nodal coordinates x, ẋ and deformations
        e, ė (arrays in spacar's coordinate and deformation order)."""
        topo = self.topology
        q = np.zeros(self.nq)
        v = np.zeros(self.nv)
        for (j, p, c), iq, iv in zip(self.joints, self.idx_q, self.idx_v):
            if j.kind == "revolute":
                if j.hinge is not None:
                    col = topo.def_index[(j.hinge[0], 1)]
                    q[iq] = j.hinge[1] * e[col]
                    v[iv] = j.hinge[1] * ed[col]
                else:
                    q[iq] = topo.body_angle(c, x) - topo.body_angle(p, x)
                    v[iv] = topo.body_omega(c, x, xd)[2] - topo.body_omega(p, x, xd)[2]
            else:
                Rp, Rc = topo.body_rotation(p, x), topo.body_rotation(c, x)
                q[iq:iq + 4] = _quat_xyzw(Rp.T @ Rc)
                v[iv:iv + 3] = Rc.T @ (topo.body_omega(c, x, xd) - topo.body_omega(p, x, xd))
        return q, v

    def accelerations(self, x, xd, xdd, e, ed, edd):
        """Pinocchio joint accelerations of a spacar state (from ẍ and ë)."""
        topo = self.topology
        a = np.zeros(self.nv)
        for (j, p, c), iv in zip(self.joints, self.idx_v):
            if j.kind == "revolute":
                if j.hinge is not None:
                    a[iv] = j.hinge[1] * edd[topo.def_index[(j.hinge[0], 1)]]
                else:
                    a[iv] = topo.body_omega(c, x, xdd)[2] - topo.body_omega(p, x, xdd)[2]
            else:
                Rc = topo.body_rotation(c, x)
                wp, wc = topo.body_omega(p, x, xd), topo.body_omega(c, x, xd)
                # ω̇ = 2 E(λ) λ̈ because E(λ̇) λ̇ = 0
                dwp, dwc = topo.body_omega(p, x, xdd), topo.body_omega(c, x, xdd)
                a[iv:iv + 3] = Rc.T @ (dwc - dwp + np.cross(wc, wp))
        return a

    def velocity_map(self, x, DF, DFe, columns) -> np.ndarray:
        """T = ∂v/∂q̂̇ restricted to ``columns`` of DF (e.g. the DOF columns): v = T q̇."""
        topo = self.topology
        T = np.zeros((self.nv, len(columns)))
        DFc, DFec = DF[:, columns], DFe[:, columns]
        for (j, p, c), iv in zip(self.joints, self.idx_v):
            if j.kind == "revolute":
                if j.hinge is not None:
                    T[iv] = j.hinge[1] * DFec[topo.def_index[(j.hinge[0], 1)]]
                else:
                    T[iv] = topo.body_omega_rows(c, x, DFc)[2] - topo.body_omega_rows(p, x, DFc)[2]
            else:
                Rc = topo.body_rotation(c, x)
                T[iv:iv + 3] = Rc.T @ (topo.body_omega_rows(c, x, DFc) - topo.body_omega_rows(p, x, DFc))
        return T

    # --- dynamics -------------------------------------------------------------------------

    def joint_torques(self, q, v) -> np.ndarray:
        """Torques of the joint springs and dampers (PLHINGE/HINGE ESTIFF, EDAMPP)."""
        if not self.has_springs:
            return np.zeros(self.nv)
        tau = np.zeros(self.nv)
        for k, ((j, _, _), iq, iv) in enumerate(zip(self.joints, self.idx_q, self.idx_v)):
            if j.kind == "revolute":
                tau[iv] = -self._k[k] * q[iq] - self._d[k] * v[iv]
        return tau

    def mass_matrix(self, q) -> np.ndarray:
        """CRBA mass matrix (symmetric)."""
        M = pin.crba(self.model, self.data, q)
        return np.triu(M) + np.triu(M, 1).T

    def aba(self, q, v) -> np.ndarray:
        """ABA joint accelerations with gravity and the joint springs/dampers."""
        return np.array(pin.aba(self.model, self.data, q, v, self.joint_torques(q, v)))

    def rhs(self):
        """f(t, y) of the first-order system y = (q, v) (revolute joints only), for integrators."""
        if not self.revolute_only:
            raise UnsupportedModelError("rhs(): spherical joints need a Lie-group integrator; revolute joints only")
        n = self.nq
        model, data = self.model, self.data
        aba = pin.aba
        if self.has_springs:
            k, d = self._k, self._d

            def f(t, y):
                q, v = y[:n], y[n:]
                return np.concatenate((v, aba(model, data, q, v, -k * q - d * v)))
        else:
            zero = np.zeros(n)

            def f(t, y):
                q, v = y[:n], y[n:]
                return np.concatenate((v, aba(model, data, q, v, zero)))
        return f

    # --- spacar side ----------------------------------------------------------------------

    def position_error(self, q, x) -> float:
        """Largest distance between the points of the bodies placed by Pinocchio's forward
        kinematics at q and spacar's nodal positions x: zero when both describe the same
        configuration."""
        topo = self.topology
        pin.forwardKinematics(self.model, self.data, q)
        err = 0.0
        for (_, _, c) in self.joints:
            oMi = self.data.oMi[self._jid_of_body[c]]
            origin = self._origin_of_body[c]
            for n, r in topo.bodies[c].points.items():
                err = max(err, float(np.abs(oMi.act(r - origin) - topo.point_position(n, x)).max()))
        return err

    def evaluate_spacar(self, t, q, qd, max_step=0.25):
        """``Simulation.evaluate`` at (t, q, q̇), reached from the previously evaluated q in
        steps of at most ``max_step`` in every DOF. spacar's Newton starts from the last state;
        after a large jump it can converge to another solution of the rigid-link constraints
        (a PLBEAM whose chord points backwards satisfies e1 = e2 = e3 = 0 too), so a far state
        is approached by continuation."""
        q = np.asarray(q, dtype=float)
        qd = np.asarray(qd, dtype=float)
        steps = max(1, int(np.ceil(np.abs(q - self._last_q).max() / max_step)))
        for s in np.linspace(0.0, 1.0, steps + 1)[1:]:
            self.sim.evaluate(float(t), self._last_q + s * (q - self._last_q), qd)
        self._last_q = q.copy()
        return self.sim.data

    def spacar_state(self, t, q, qd):
        """Evaluate spacar at (t, q, q̇) (its DOFs; see :meth:`evaluate_spacar`) and return a
        dict with spacar's Mbar, qdd and the Pinocchio quantities of the same state: q_pin,
        v_pin, T, M_crba, a_spacar (spacar's joint accelerations), a_aba, and position_error
        (Pinocchio's forward kinematics against spacar's positions)."""
        sim = self.sim
        d = self.evaluate_spacar(t, q, qd)
        x, xd, xdd = (np.array(a) for a in (d.x, d.xd, d.xdd))
        e, ed, edd = (np.array(a) for a in (d.e, d.ed, d.edd))
        qp, vp = self.configuration(x, xd, e, ed)
        T = self.velocity_map(x, np.array(d.DF), np.array(d.DFe), list(sim.system.dof_cols))
        return {
            "Mbar": np.array(d.Mbar), "qdd": np.array(d.qdd),
            "q_pin": qp, "v_pin": vp, "T": T,
            "M_crba": self.mass_matrix(qp),
            "a_spacar": self.accelerations(x, xd, xdd, e, ed, edd),
            "a_aba": self.aba(qp, vp),
            "position_error": self.position_error(qp, x),
        }

    def trajectory(self, results):
        """Pinocchio (q, v) over the output times of spacar ``results`` (a :class:`spacar.Results`
        of the same model): arrays (nt, nq), (nt, nv)."""
        qs = np.empty((len(results.t), self.nq))
        vs = np.empty((len(results.t), self.nv))
        for k in range(len(results.t)):
            qs[k], vs[k] = self.configuration(results.x[k], results.xd[k], results.e[k], results.ed[k])
        return qs, vs


def build(spacar_model) -> PinocchioModel:
    """The equivalent :class:`PinocchioModel` of a spacar model (see the module docstring for
    what is supported)."""
    return PinocchioModel(spacar_model)


def random_states(spacar_model, n: int, seed=0, scale_q=1.0, scale_qd=1.0):
    """n random spacar states (t, q, q̇) around the model's initial DOF values."""
    sim = _core.Simulation(spacar_model.core)
    sim.assemble()
    q0 = np.array(sim.system.q0)
    rng = np.random.default_rng(seed)
    return [(spacar_model.current_time, q0 + scale_q * rng.uniform(-1, 1, q0.size),
             scale_qd * rng.uniform(-1, 1, q0.size)) for _ in range(n)]


def side_by_side(spacar_model, states):
    """spacar and Pinocchio at the given spacar states [(t, q, q̇), ...]: a dict of stacked
    arrays ``Mbar`` (spacar's reduced mass matrix), ``M_pinocchio`` (Tᵀ M_crba T, the CRBA
    matrix in spacar's DOFs), ``a_spacar``, ``a_pinocchio`` (joint accelerations: spacar's from
    its ẍ, ë; Pinocchio's ABA), ``qdd`` (spacar's DOF accelerations), ``T``, the joint states
    ``q_pin``, ``v_pin`` and ``position_error`` (see :meth:`PinocchioModel.position_error`)."""
    pm = build(spacar_model)
    rows = [pm.spacar_state(*s) for s in states]
    out = {k: np.array([r[k] for r in rows])
           for k in ("Mbar", "qdd", "q_pin", "v_pin", "T", "a_spacar", "position_error")}
    out["M_pinocchio"] = np.array([r["T"].T @ r["M_crba"] @ r["T"] for r in rows])
    out["a_pinocchio"] = np.array([r["a_aba"] for r in rows])
    out["M_crba"] = np.array([r["M_crba"] for r in rows])
    return out


def simulate(spacar_model, t_end=None, n_out=None, rtol=None, atol=None, integrator="dop853"):
    """Integrate the Pinocchio model (ABA) from the spacar model's initial state and return
    ``(t, q, v, stats)`` at n_out + 1 equally spaced times up to t_end (defaults: the model's
    TIMESTEP; EPSINT as rtol, 1e-3·rtol as atol, as spacar's error control).

    ``integrator``: ``"dop853"`` — spacar's C++ DOP853 (the same method and error norm as
    spacar, with the right-hand side called from C++ into Python), or ``"scipy"`` — SciPy's
    ``solve_ivp(method="DOP853")``."""
    pm = build(spacar_model)
    s = spacar_model.settings
    t0 = spacar_model.current_time
    t_end = t0 + s.timestep_tp if t_end is None else t_end
    n_out = s.timestep_n if n_out is None else n_out
    rtol = s.epsint if rtol is None else rtol
    atol = 1e-3 * rtol if atol is None else atol
    d = pm.sim.data
    q0, v0 = pm.configuration(np.array(d.x), np.array(d.xd), np.array(d.e), np.array(d.ed))
    y0 = np.concatenate((q0, v0))
    f = pm.rhs()
    touts = list(np.linspace(t0, t_end, n_out + 1))
    if integrator == "dop853":
        r = _core.solve_ode("dop853", f, None, t0, y0, t_end, touts, rtol, atol)
        Y, stats = np.asarray(r["y"]), {"rhs_evaluations": r["nfev"], "accepted": r["naccept"], "rejected": r["nreject"]}
    elif integrator == "scipy":
        import scipy.integrate

        r = scipy.integrate.solve_ivp(f, (t0, t_end), y0, method="DOP853", t_eval=touts, rtol=rtol, atol=atol)
        if not r.success:
            raise RuntimeError(f"solve_ivp failed: {r.message}")
        Y, stats = r.y.T, {"rhs_evaluations": r.nfev}
    else:
        raise ValueError("integrator must be 'dop853' or 'scipy'")
    n = pm.nq
    return np.array(touts), Y[:, :n], Y[:, n:], stats


def free_flyer_rhs(model, data):
    """The first-order equations y' = f(t, y) of a Pinocchio model whose first joint is a
    JointModelFreeFlyer, y = (q, v) with q = (position, quaternion (x, y, z, w), joints) and v =
    (the base's linear and angular velocity in its own axes, the joints' rates), for SciPy's
    solve_ivp: the position's rate R v, the quaternion's ½ q ⊗ (0, ω) (normalized where it is
    read), ``pinocchio.aba`` with no joint torques. The reference of the floating-base tests and
    benchmark (issue 37)."""
    zero = np.zeros(model.nv)

    def f(t, y):
        q, v = y[:model.nq].copy(), y[model.nq:]
        q[3:7] /= np.linalg.norm(q[3:7])
        x, y_, z, s = q[3:7]
        wx, wy, wz = v[3:6]
        quat_d = 0.5 * np.array([s * wx + y_ * wz - z * wy, s * wy + z * wx - x * wz, s * wz + x * wy - y_ * wx,
                                 -x * wx - y_ * wy - z * wz])
        R = pin.Quaternion(s, x, y_, z).matrix()
        return np.r_[R @ v[:3], quat_d, v[6:], pin.aba(model, data, q, v, zero)]

    return f


def point_constrained(model, joint1, point1, joint2, point2):
    """q, v → q̈ of Pinocchio's constrained dynamics of ``model`` (no joint torques) with a rigid
    3-D point constraint between point1 (in joint1's frame) and point2 (in joint2's): the
    independent reference of spacar's closed loops (tests/peers/test_closed_loops.py,
    benchmarks/closed_loops.py). Proximal settings at 1e-14."""
    data = model.createData()
    cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, joint1, pin.SE3(np.eye(3), point1),
                                  joint2, pin.SE3(np.eye(3), point2), pin.ReferenceFrame.LOCAL)
    cms = pin.StdVec_RigidConstraintModel()
    cms.append(cm)
    cds = pin.StdVec_RigidConstraintData()
    cds.append(cm.createData())
    pin.initConstraintDynamics(model, data, cms, cds)
    settings = pin.ProximalSettings(1e-14, 1e-12, 100)
    tau = np.zeros(model.nv)

    def accelerations(q, v):
        return pin.constraintDynamics(model, data, q, v, tau, cms, cds, settings)

    return accelerations

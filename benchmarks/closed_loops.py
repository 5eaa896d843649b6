"""Closed loops on the recursive path (issue 37): spacar's tree with its loops closed by Newton's
method in the passive joints (cpp/include/spacar/recursive/closed_loop.hpp) against spacar's
general path (the constraint formulation) and Pinocchio's constrained dynamics. Three loops: the
free four-bar of ``spacar.compare.models.four_bar`` (planar PLBEAMs, the crank's rotation the DOF,
the coupler's and rocker's passive; 2 constraints), the spatial RSUR linkage of
tests/data/rsur_loop.urdf (a crank, a rocker with a universal joint to the coupler, the loop
closed by a ball joint beside the URDF; 1 DOF, 3 passive joints, 3 constraints), and the 7R loop
of ``spacar.compare.models.seven_r_loop`` (a random 6-link chain closed at a point and at a
seventh hinge; 1 DOF, 5 passive joints, 5 constraints). Gravity, the crank started at 2 (four-bar),
1.5 (RSUR) and 1 rad/s (7R), T = 1 s. Error: the largest joint-angle change error at T
against spacar's general path at EPSINT = EPSIND = 1e-12 (EPSKIN 1e-14), which its tree at the
same tolerance equals to the figure given. Pinocchio: the four-bar as three revolute joints and the
URDF, each loop closed by a 3-D point constraint (``pinocchio.constraintDynamics``, proximal
settings at 1e-14), integrated by SciPy's DOP853 (rtol = EPS, atol = 1e-3 EPS) from spacar's
initial state; it has no revolute closure for the 7R loop. Every model built outside the timing; time per right-hand side: spacar's
C++ block over its right-hand sides, Pinocchio's ``constraintDynamics`` call from Python. And
``spacar.dynamics_derivatives`` per state, in one call on a batch of states along the tree's run
(random τ), on these loops and on the 7R loop cut between two of its links (``last=4``).

    python benchmarks/closed_loops.py [--quick] [--no-write]
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

import _common as C
import spacar
from spacar.compare import models

URDF = Path(__file__).resolve().parents[1] / "tests" / "data" / "rsur_loop.urdf"
BALL = {"parent": "crank", "child": "coupler", "xyz": (0.2, 0.0, 0.0), "type": "spherical"}
T_END, QUICK_T_END = 1.0, 0.1
EPS, QUICK_EPS = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10], [1e-4, 1e-6]
TARGETS = [1e-4, 1e-6, 1e-8]
PROGRAMS = ["spacar (tree)", "spacar (general path)", "Pinocchio constraintDynamics + DOP853"]


def rsur(t_end, eps):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the joint limits, not enforced
        m = spacar.from_urdf(URDF, loops=[BALL], dependent=["rocker", "cross", "coupler"])
    m.ed(1, 1, 1.5)
    m.epsint(eps)
    m.epsind(eps)
    m.epskin(max(1e-14, 1e-3 * eps))
    m.timestep(1, t_end)
    return m


def seven_r(t_end, eps):
    return models.seven_r_loop(t_end=t_end, n_out=1, eps=eps, epskin=max(1e-14, 1e-3 * eps))


def four_bar(t_end, eps):
    return models.four_bar(t_end=t_end, n_out=1, eps=eps, epskin=max(1e-14, 1e-3 * eps))


def hinge_angles(elements):
    """The joints' angles (rates) over a run: the hinges' e1 (zero at the start)."""
    return lambda res, rate=False: np.column_stack([res.deformation(k, 1, "ed" if rate else "e") for k in elements])


def four_bar_angles(res, rate=False):
    """Pinocchio's joint angles (rates) of the four-bar: the crank's, the coupler's relative to the
    crank and the rocker's, from the start (spacar's BETA nodes 11, 21, 31 hold the links' angles)."""
    b = {n: res.coordinate(n, 1, "xd" if rate else "x") for n in (11, 21, 31)}
    if not rate:
        b = {n: v - v[0] for n, v in b.items()}
    return np.column_stack([b[11], b[21] - b[11], b[31]])


# name → (builder, the joints' angles of a run, its passive joints)
MODELS = {"four-bar (planar)": (four_bar, four_bar_angles, 2),
          "RSUR (URDF, ball joint)": (rsur, hinge_angles([1, 2, 3, 4]), 3),
          "7R loop": (seven_r, hinge_angles([models.HINGE + i for i in range(1, 7)]), 5)}


def rod(pin, mass_per_length, p0, p1, origin):
    """A uniform thin rod from p0 to p1 as a Pinocchio inertia about `origin`."""
    d = p1 - p0
    length = np.linalg.norm(d)
    u = d / length
    m = mass_per_length * length
    return pin.Inertia(m, (p0 + p1) / 2 - origin, m * length**2 / 12 * (np.eye(3) - np.outer(u, u)))


def pinocchio_four_bar():
    """The four-bar in Pinocchio (as tests/peers/test_closed_loops.py): three revolute joints about
    z, rods and the point mass, the loop closed at the coupler–rocker pin."""
    import pinocchio as pin

    A, B, C_, D = (np.array(p, float) for p in ([0, 0, 0], [0, 1, 0], [2, 1.5, 0], [2.5, 0, 0]))
    pm = pin.Model()
    pm.gravity.linear = np.array([0.0, -models.G, 0.0])
    crank = pm.addJoint(0, pin.JointModelRZ(), pin.SE3(np.eye(3), A), "crank")
    pm.appendBodyToJoint(crank, rod(pin, 1.0, A, B, A), pin.SE3.Identity())
    coupler = pm.addJoint(crank, pin.JointModelRZ(), pin.SE3(np.eye(3), B - A), "coupler")
    pm.appendBodyToJoint(coupler, rod(pin, 1.5, B, C_, B), pin.SE3.Identity())
    pm.appendBodyToJoint(coupler, pin.Inertia(0.3, C_ - B, np.zeros((3, 3))), pin.SE3.Identity())
    rocker = pm.addJoint(0, pin.JointModelRZ(), pin.SE3(np.eye(3), D), "rocker")
    pm.appendBodyToJoint(rocker, rod(pin, 1.2, D, C_, D), pin.SE3.Identity())
    return constrained_dynamics(pm, coupler, C_ - B, rocker, C_ - D)


def pinocchio_rsur():
    """Pinocchio's model of the URDF with the ball joint."""
    import pinocchio as pin

    pm = pin.buildModelFromUrdf(str(URDF))
    crank, coupler = pm.getJointId("crank"), pm.getJointId("coupler")
    B = np.array(BALL["xyz"])
    C_ = np.asarray(pm.jointPlacements[pm.getJointId("cross")].translation) + \
        np.asarray(pm.jointPlacements[pm.getJointId("rocker")].translation)
    return constrained_dynamics(pm, crank, B, coupler, B - C_)


def constrained_dynamics(pm, joint1, point1, joint2, point2):
    """Pinocchio's nq and q, v → q̈ of its model with a 3-D point constraint."""
    from spacar.compare.pinocchio import point_constrained

    return pm.nq, point_constrained(pm, joint1, point1, joint2, point2)


def pinocchio_run(nq, qdd, q0, v0, t_end, eps):
    from scipy.integrate import solve_ivp

    def f(t, y):
        return np.concatenate([y[nq:], qdd(y[:nq], y[nq:])])

    sol = solve_ivp(f, (0.0, t_end), np.concatenate([q0, v0]), method="DOP853", rtol=eps, atol=1e-3 * eps)
    return sol.y[:nq, -1], sol.nfev


PINOCCHIO = {"four-bar (planar)": pinocchio_four_bar, "RSUR (URDF, ball joint)": pinocchio_rsur}


def run_model(name, t_end, eps_list):
    build, angles, passive = MODELS[name]
    ref = spacar.simulate(build(t_end, 1e-12), recursive=False)
    ref_tree = spacar.simulate(build(t_end, 1e-12))
    exact = angles(ref)[-1]
    out = {"agreement": float(np.abs(angles(ref_tree)[-1] - exact).max()), "path": ref_tree.stats["path"],
           "passive": passive}
    for program, recursive in (("spacar (tree)", True), ("spacar (general path)", False)):
        runs = []
        for eps in eps_list:
            res, t = C.simulate_best(build(t_end, eps), recursive=recursive, min_time=0.3)
            runs.append((float(np.abs(angles(res)[-1] - exact).max()), t, eps, res.stats["rhs_evaluations"]))
            C.log(name, program, eps, runs[-1])
        out[program] = runs
        per_rhs, _ = C.in_run_per_rhs(build(t_end, 1e-8), recursive=recursive)
        out[program + " per rhs"] = per_rhs
    if name in PINOCCHIO:
        try:
            nq, qdd = PINOCCHIO[name]()
        except ImportError:
            return out
        # Pinocchio's q are the joint angles of both models, zero at the reference pose where both start.
        q0, v0 = np.zeros(nq), angles(ref, rate=True)[0]
        runs = []
        for eps in eps_list:
            t, (q, nfev) = C.best_time(lambda: pinocchio_run(nq, qdd, q0, v0, t_end, eps), repeat=3, budget=20.0,
                                       min_time=0.3)
            runs.append((float(np.abs(q - exact).max()), t, eps, nfev))
            C.log(name, "Pinocchio", eps, runs[-1])
        out["Pinocchio constraintDynamics + DOP853"] = runs
        q, v = np.zeros(nq), v0
        out["Pinocchio constraintDynamics + DOP853 per rhs"] = C.per_call(lambda: qdd(q, v))
    return out


def seven_r_cut_inside(t_end, eps):
    return models.seven_r_loop(t_end=t_end, n_out=1, eps=eps, epskin=max(1e-14, 1e-3 * eps), last=4)


DERIVATIVE_MODELS = {"four-bar": four_bar, "RSUR (URDF)": rsur, "7R loop, cut at its hinge to the ground": seven_r,
                     "7R loop, cut between two links": seven_r_cut_inside}


def derivative_timings(t_end, states):
    """Wall time per state of one spacar.dynamics_derivatives call on `states` states along the
    tree's run at EPS 1e-8 (random τ), best of three; the Dynamics made outside the timing."""
    out = {}
    for name, build in DERIVATIVE_MODELS.items():
        model = build(t_end, 1e-8)
        model.timestep(states, t_end)
        res = spacar.simulate(model.copy())
        q, qd = np.array(res.q)[1:], np.array(res.qd)[1:]
        tau = np.random.default_rng(0).uniform(-1.0, 1.0, q.shape)
        dyn = spacar.Dynamics(model)
        t, _ = C.best_time(lambda: dyn.dynamics_derivatives(q, qd, tau), repeat=3, min_time=0.3)
        out[name] = {"per_state": t / len(q), "states": len(q)}
        C.log("derivatives", name, out[name])
    return out


def run(a) -> dict:
    t_end, eps = (QUICK_T_END, QUICK_EPS) if a.quick else (T_END, EPS)
    return {"quick": a.quick, "t_end": t_end, "machine": C.machine(peers=True),
            "models": {name: run_model(name, t_end, eps) for name in MODELS},
            "derivatives": derivative_timings(t_end, 100 if a.quick else 1000)}


def section(r: dict, plots=None) -> str:
    lines = ["## Closed loops on the recursive path: spacar's tree, its general path and Pinocchio", "",
             __doc__.split("\n\n")[0].replace("\n", " "), "", *C.machine_table(r["machine"]), ""]
    lines += ["| model | passive joints | target [rad] | " + " | ".join(PROGRAMS) +
              " | general path / tree | Pinocchio / tree |", "|" + "---|" * (len(PROGRAMS) + 5)]
    for name, x in r["models"].items():
        for target in TARGETS:
            t = {p: C.time_to_accuracy([(e, s) for e, s, *_ in x.get(p, [])], target) for p in PROGRAMS}
            lines.append(f"| {name} | {x['passive']} | {target:g} | " + " | ".join(C.fmt_time(t[p]) for p in PROGRAMS) +
                         f" | {C.fmt_ratio(t['spacar (general path)'], t['spacar (tree)'])} | "
                         f"{C.fmt_ratio(t['Pinocchio constraintDynamics + DOP853'], t['spacar (tree)'])} |")
    lines += ["", "Time per right-hand side (spacar: inside a run at EPS = 1e-8; Pinocchio: one call from Python):", "",
              "| model | spacar (tree) | spacar (general path) | Pinocchio constraintDynamics | general path / tree |",
              "|---|---|---|---|---|"]
    for name, x in r["models"].items():
        tree, general = x["spacar (tree) per rhs"], x["spacar (general path) per rhs"]
        pin = x.get("Pinocchio constraintDynamics + DOP853 per rhs")
        lines.append(f"| {name} | {C.fmt_time(tree)} | {C.fmt_time(general)} | {C.fmt_time(pin)} | "
                     f"{C.fmt_ratio(general, tree)} |")
    if r.get("derivatives"):
        lines += ["", "`spacar.dynamics_derivatives` (q̈ and its derivatives in q, q̇ and τ, exact on dual numbers), "
                  "one call on a batch of states along the tree's run:", "", "| model | states | per state |", "|---|---|---|"]
        for name, x in r["derivatives"].items():
            lines.append(f"| {name} | {x['states']} | {C.fmt_time(x['per_state'])} |")
    lines += ["", "Every run (EPS → error in wall time, right-hand sides); the tree at EPS = 1e-12 equals the "
              "reference to " + ", ".join(f"{x['agreement']:.1e} ({name})" for name, x in r["models"].items()) + ":", ""]
    for name, x in r["models"].items():
        for p in PROGRAMS:
            if p in x:
                runs = ", ".join(f"{s:g} → {e:.1e} in {C.fmt_time(t)} ({n})" for e, t, s, n in x[p])
                lines.append(f"* {name}, {p}: {runs}")
    return "\n".join(lines) + "\n"


def plot(r):
    return None


def main(argv=None) -> int:
    return C.standard_main("closed_loops", __doc__, run, section, plot, argv)


if __name__ == "__main__":
    import sys

    sys.exit(main())

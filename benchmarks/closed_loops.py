"""Closed loops on the recursive path (issue 37): spacar's tree with its loops closed by Newton's
method in the passive joints (cpp/include/spacar/recursive/closed_loop.hpp) against spacar's
general path (the constraint formulation) and Pinocchio's constrained dynamics. Two loops: the
spatial RSUR linkage of tests/data/rsur_loop.urdf (a crank, a rocker with a universal joint to
the coupler, the loop closed by a ball joint beside the URDF; 1 DOF, 3 passive joints, 3
constraints), and the 7R loop of ``spacar.compare.models.seven_r_loop`` (a random 6-link chain
closed at a point and at a seventh hinge; 1 DOF, 5 passive joints, 5 constraints). Gravity, the
crank started at 1.5 (RSUR) and 1 rad/s (7R), T = 1 s. Error: the largest joint-angle error at T
against spacar's general path at EPSINT = EPSIND = 1e-12 (EPSKIN 1e-14), which its tree at the
same tolerance equals to the figure given. Pinocchio: the same URDF with the ball joint as a 3-D
point constraint (``pinocchio.constraintDynamics``, proximal settings at 1e-14), integrated by
SciPy's DOP853 (rtol = EPS, atol = 1e-3 EPS) from spacar's initial state; it has no revolute
closure for the 7R loop. Every model built outside the timing; time per right-hand side: spacar's
C++ block over its right-hand sides, Pinocchio's ``constraintDynamics`` call from Python.

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


# name → (builder, elements of its joints in the error)
MODELS = {"RSUR (URDF, ball joint)": (rsur, [1, 2, 3, 4]),
          "7R loop": (seven_r, [models.HINGE + i for i in range(1, 7)])}


def joints(res, elements, what="e"):
    return np.array([res.deformation(k, 1, what)[-1] for k in elements])


def pinocchio_rsur():
    """Pinocchio's model of the URDF, its data and constraint, and q, v → q̈."""
    import pinocchio as pin

    pm = pin.buildModelFromUrdf(str(URDF))
    pd = pm.createData()
    crank, coupler = pm.getJointId("crank"), pm.getJointId("coupler")
    B = np.array(BALL["xyz"])
    C_ = np.asarray(pm.jointPlacements[pm.getJointId("cross")].translation) + \
        np.asarray(pm.jointPlacements[pm.getJointId("rocker")].translation)
    cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, pm, crank, pin.SE3(np.eye(3), B), coupler,
                                  pin.SE3(np.eye(3), B - C_), pin.ReferenceFrame.LOCAL)
    cms = pin.StdVec_RigidConstraintModel()
    cms.append(cm)
    cds = pin.StdVec_RigidConstraintData()
    cds.append(cm.createData())
    pin.initConstraintDynamics(pm, pd, cms, cds)
    settings = pin.ProximalSettings(1e-14, 1e-12, 100)
    tau = np.zeros(pm.nv)

    def qdd(q, v):
        return pin.constraintDynamics(pm, pd, q, v, tau, cms, cds, settings)

    return pm.nq, qdd


def pinocchio_run(nq, qdd, q0, v0, t_end, eps):
    from scipy.integrate import solve_ivp

    def f(t, y):
        return np.concatenate([y[nq:], qdd(y[:nq], y[nq:])])

    sol = solve_ivp(f, (0.0, t_end), np.concatenate([q0, v0]), method="DOP853", rtol=eps, atol=1e-3 * eps)
    return sol.y[:nq, -1], sol.nfev


def run_model(name, t_end, eps_list):
    build, elements = MODELS[name]
    ref = spacar.simulate(build(t_end, 1e-12), recursive=False)
    ref_tree = spacar.simulate(build(t_end, 1e-12))
    exact = joints(ref, elements)
    out = {"agreement": float(np.abs(joints(ref_tree, elements) - exact).max()), "path": ref_tree.stats["path"],
           "passive": len(elements) - 1}
    for program, recursive in (("spacar (tree)", True), ("spacar (general path)", False)):
        runs = []
        for eps in eps_list:
            res, t = C.simulate_best(build(t_end, eps), recursive=recursive, min_time=0.3)
            runs.append((float(np.abs(joints(res, elements) - exact).max()), t, eps, res.stats["rhs_evaluations"]))
            C.log(name, program, eps, runs[-1])
        out[program] = runs
        per_rhs, _ = C.in_run_per_rhs(build(t_end, 1e-8), recursive=recursive)
        out[program + " per rhs"] = per_rhs
    if name.startswith("RSUR"):
        try:
            nq, qdd = pinocchio_rsur()
        except ImportError:
            return out
        q0, v0 = joints(ref, elements, "e") * 0.0, np.array([ref.deformation(k, 1, "ed")[0] for k in elements])
        assert np.abs(np.array([ref.deformation(k, 1, "e")[0] for k in elements])).max() < 1e-12  # the zero pose
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


def run(a) -> dict:
    t_end, eps = (QUICK_T_END, QUICK_EPS) if a.quick else (T_END, EPS)
    return {"quick": a.quick, "t_end": t_end, "machine": C.machine(peers=True),
            "models": {name: run_model(name, t_end, eps) for name in MODELS}}


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

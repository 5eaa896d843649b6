"""Robots from example-robot-data (issue 37): the UR5 (6 revolute joints) and the Panda (7 revolute
joints, 2 sliding fingers), read from the same URDF by spacar (``spacar.from_urdf``, on the
recursive path), Pinocchio (``buildModelFromUrdf``; its ABA integrated by SciPy's DOP853) and
MuJoCo (the URDF without visuals, collisions, limits, mimics and joint dynamics, compiled once per
step size outside its timing; RK4 and its implicit-in-velocity integrator ``implicitfast`` at
fixed steps). Released from rest at the zero configuration under gravity, 1 s; error: the largest
joint difference at the end against Pinocchio's ABA integrated by DOP853 at rtol = atol = 1e-13.
Time to 1e-4, 1e-6 and 1e-8 rad: the fastest run of each program whose error is at most the
target, its model built outside the timing (spacar: ``spacar.simulate`` on a copy made outside
it, EPSINT = EPSIND = EPS; Pinocchio: ``solve_ivp`` with rtol = EPS, atol = 1e-3 EPS; MuJoCo:
``mj_step`` in a loop, which ``mujoco.rollout`` does not beat: 2.05 against 2.12 ms for the UR5's
200 RK4 steps). The Panda's fingers slide freely (no limits, as in all three models), so its
motion is fast and the 1e-8 target is out of every program's reach here. A floating base: Solo12
(12 joints on a free base) thrown for 1 s, spacar on its recursive path and on the general path
against Pinocchio's free flyer integrated by DOP853 (run_floating).

    python benchmarks/robots.py [--quick] [--no-write]
"""
from __future__ import annotations

import re
import warnings

import numpy as np

import _common as C

ROBOTS = {"UR5": ("ur_description", "ur5_robot.urdf"), "Panda": ("panda_description", "panda.urdf")}
T_END = 1.0
TARGETS = [1e-4, 1e-6, 1e-8]
# Every program scanned as finely as the others, from loose settings on: the tolerances at half
# decades from 1e-2, MuJoCo's steps T_END / n for n in ratios of about 10^(1/8) from 25 (its RK4's
# error, ∝ h⁴, in half decades too). A coarser or shorter scan takes a program's time to a target
# at up to ten (a hundred) times the accuracy it asks for.
EPS = [float(f"{10 ** (-k / 2):.1g}") for k in range(4, 21)]
STEPS = [T_END / n for n in sorted({round(25 * 10 ** (k / 8)) for k in range(21)})]
QUICK = {"eps": [1e-4, 1e-6], "steps": [5e-3, 1e-3], "t_end": 0.1}
REPEAT, BUDGET, MIN_TIME = 5, 3.0, 0.05


def urdf_file(package: str, name: str):
    import importlib.metadata
    from pathlib import Path

    dist = importlib.metadata.distribution("example-robot-data")
    return Path(dist.locate_file(f"cmeel.prefix/share/example-robot-data/robots/{package}/urdf/{name}"))


def spacar_model(path, eps, t_end):
    import spacar

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # what the model leaves out (visuals, limits): the same for all
        m = spacar.from_urdf(path)
    m.epsint(eps)
    m.epsind(eps)
    m.timestep(1, t_end)
    return m


def mujoco_model(path, step, integrator):
    """The URDF as MuJoCo reads it, without what the other two leave out."""
    import mujoco

    text = path.read_text()
    text = re.sub(r"<visual>.*?</visual>|<collision>.*?</collision>", "", text, flags=re.S)
    text = re.sub(r"<(limit|mimic|dynamics|safety_controller)[^>]*/>", "", text)
    text = re.sub(r"(<robot[^>]*>)", r'\1<mujoco><compiler discardvisual="true" fusestatic="false" '
                  r'balanceinertia="false" autolimits="false"/></mujoco>', text, count=1)
    m = mujoco.MjModel.from_xml_string(text)
    m.opt.timestep = step
    m.opt.integrator = {"RK4": mujoco.mjtIntegrator.mjINT_RK4,
                        "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST}[integrator]
    return m


def mujoco_run(model, data, t_end, step):
    import mujoco

    mujoco.mj_resetData(model, data)
    for _ in range(int(round(t_end / step))):
        mujoco.mj_step(model, data)
    return np.array(data.qpos)


def pinocchio_run(pm, pd, nv, t_end, rtol, atol):
    import pinocchio as pin
    from scipy.integrate import solve_ivp

    zero = np.zeros(nv)

    def f(t, y):
        return np.concatenate((y[nv:], pin.aba(pm, pd, y[:nv], y[nv:], zero)))

    sol = solve_ivp(f, (0.0, t_end), np.zeros(2 * nv), method="DOP853", rtol=rtol, atol=atol)
    return sol.y[:nv, -1]


FLOATING = ("solo_description", "solo12.urdf", "robots")  # package, file, folder
FLOATING_PROGRAMS = ["spacar (tree)", "spacar (general path)", "Pinocchio ABA + DOP853"]


def floating_file():
    import importlib.metadata
    from pathlib import Path

    dist = importlib.metadata.distribution("example-robot-data")
    package, name, folder = FLOATING
    return Path(dist.locate_file(f"cmeel.prefix/share/example-robot-data/robots/{package}/{folder}/{name}"))


def floating_state(nj):
    """Solo12 thrown: the base at 0.5 m, turned by 0.4 rad about a random axis, moving and
    spinning, the joints turned and moving (seeded)."""
    rng = np.random.default_rng(2)
    axis = rng.normal(size=3)
    lam = np.r_[np.cos(0.2), np.sin(0.2) * axis / np.linalg.norm(axis)]
    return (np.array([0.0, 0.0, 0.5]), lam, rng.normal(size=3) * 0.5, rng.normal(size=3), rng.normal(size=nj) * 0.3,
            rng.normal(size=nj))


def floating_spacar(path, eps, t_end):
    import spacar
    from spacar.geometry import euler_e

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = spacar.from_urdf(path, floating=True)
    nj = len(m.urdf_joints)
    p, lam, v, w, qj, qdj = floating_state(nj)
    m.x(1, *p)
    m.x(2, *lam)
    lam_d = 0.5 * euler_e(lam).T @ w
    for i in range(3):
        m.xd(1, i + 1, v[i])
    for i in range(4):
        m.xd(2, i + 1, lam_d[i])
    for k in range(nj):
        m.e(k + 1, 1, qj[k])
        m.ed(k + 1, 1, qdj[k])
    m.epsint(eps)
    m.epsind(eps)
    m.timestep(1, t_end)
    return m


def floating_pinocchio(pm, pd, t_end, rtol, atol):
    """Pinocchio's free flyer: its ABA, the base's quaternion and position rates from its twist,
    integrated by SciPy's DOP853; (base position, Euler parameters (λ0, λ1, λ2, λ3), joints) at the end."""
    from scipy.integrate import solve_ivp

    from spacar.compare.pinocchio import free_flyer_rhs
    from spacar.geometry import rotation

    nq, nv = pm.nq, pm.nv
    p, lam, v, w, qj, qdj = floating_state(nv - 6)
    R = rotation(lam)
    y0 = np.r_[p, lam[1:], lam[0], qj, R.T @ v, R.T @ w, qdj]
    sol = solve_ivp(free_flyer_rhs(pm, pd), (0.0, t_end), y0, method="DOP853", rtol=rtol, atol=atol)
    q = sol.y[:nq, -1]
    quat = q[3:7] / np.linalg.norm(q[3:7])
    return np.r_[q[:3], quat[3], quat[:3], q[7:]]


def floating_result(res):
    """(base position, Euler parameters, joints) at the end of a spacar run."""
    return np.r_[res.node(1).x[-1], res.node(2).x[-1], res.q[-1][6:]]


def run_floating(quick):
    """Solo12 with a floating base thrown for 1 s: spacar on the tree and on the general path,
    Pinocchio's free flyer with DOP853; error: the largest difference of the base position, its
    Euler parameters and the joints at the end against Pinocchio at rtol = atol = 1e-13."""
    import pinocchio as pin

    path = floating_file()
    t_end = QUICK["t_end"] if quick else T_END
    eps_list = QUICK["eps"] if quick else [e for e in EPS if e >= 1e-8]
    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    pd = pm.createData()
    ref = floating_pinocchio(pm, pd, t_end, 1e-13, 1e-13)
    out = {p: [] for p in FLOATING_PROGRAMS}
    for eps in eps_list:
        for program, recursive in (("spacar (tree)", True), ("spacar (general path)", False)):
            res, wall = C.simulate_best(floating_spacar(path, eps, t_end), repeat=REPEAT, budget=BUDGET, min_time=MIN_TIME,
                                        progress=False, recursive=recursive)
            err = float(np.abs(floating_result(res) - ref).max())
            out[program].append((err, wall, eps, res.stats["steps"]))
            C.log(f"floating Solo12 {program} EPS {eps:g}: {wall * 1e3:.3f} ms, error {err:.1e}, "
                  f"{res.stats['steps']} steps, {res.stats['path']} path")
        wall, q = C.best_time(lambda: floating_pinocchio(pm, pd, t_end, eps, 1e-3 * eps), repeat=REPEAT, budget=BUDGET,
                              min_time=MIN_TIME)
        err = float(np.abs(q - ref).max())
        out["Pinocchio ABA + DOP853"].append((err, wall, eps, None))
        C.log(f"floating Solo12 Pinocchio DOP853 rtol {eps:g}: {wall * 1e3:.3f} ms, error {err:.1e}")
    out["nv"] = pm.nv
    out["derivatives"] = floating_derivatives(path, pm, pd)
    return out


def floating_derivatives(path, pm, pd, n_states=1000):
    """Seconds for the dynamics derivatives of n_states random Solo12 states on a floating base:
    one call of a spacar.Dynamics (made outside the timing, as Pinocchio's model is) on the batch
    against as many calls of pinocchio.computeABADerivatives on its free flyer, and one state per
    call. The coordinates differ (spacar: origin and three Euler parameters; Pinocchio: the free
    flyer's tangent), so each is checked against itself before it is timed: spacar's q̈ gives
    back tau through its inverse dynamics (the derivatives are checked against the inverse
    dynamics' differences in tests/api/test_urdf.py), one state per call equals the batch's, and
    Pinocchio's q̈ is its aba's."""
    import pinocchio as pin
    import spacar
    from spacar import _core

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = spacar.from_urdf(path, floating=True)
    dyn = spacar.Dynamics(model)
    assembled = _core.Simulation(model.copy().core)
    assembled.assemble()
    rng = np.random.default_rng(4)
    nv = pm.nv
    q = np.array(assembled.system.q0) + rng.uniform(-0.1, 0.1, (n_states, nv))
    qd, tau = rng.uniform(-1.0, 1.0, (n_states, nv)), rng.uniform(-1.0, 1.0, (n_states, nv))
    ours = dyn.dynamics_derivatives(q, qd, tau)
    for k in range(0, n_states, 97):
        assert np.abs(dyn.inverse_dynamics(q[k], qd[k], ours[0][k]) - tau[k]).max() <= 1e-9
    assert np.array_equal(dyn.dynamics_derivatives(q[0], qd[0], tau[0])[1], ours[1][0])
    pin_q = [pin.integrate(pm, pin.neutral(pm), rng.uniform(-1.0, 1.0, nv)) for _ in range(n_states)]
    for k in range(0, n_states, 97):
        pin.computeABADerivatives(pm, pd, pin_q[k], qd[k], tau[k])
        ddq = pd.ddq.copy()  # a view of Pinocchio's data, which aba overwrites
        expected = pin.aba(pm, pd, pin_q[k], qd[k], tau[k]).copy()
        assert np.abs(ddq - expected).max() <= 1e-9 * max(1.0, np.abs(expected).max())
    t_ours, _ = C.best_time(lambda: dyn.dynamics_derivatives(q, qd, tau), repeat=REPEAT, budget=BUDGET,
                            min_time=MIN_TIME)
    t_pin, _ = C.best_time(lambda: [pin.computeABADerivatives(pm, pd, pin_q[k], qd[k], tau[k])
                                    for k in range(n_states)], repeat=REPEAT, budget=BUDGET, min_time=MIN_TIME)
    one = {"handle": C.per_call(lambda: dyn.dynamics_derivatives(q[0], qd[0], tau[0]), min_time=0.2),
           "pinocchio": C.per_call(lambda: pin.computeABADerivatives(pm, pd, pin_q[0], qd[0], tau[0]), min_time=0.2)}
    C.log(f"floating Solo12 derivatives of {n_states} states: spacar {t_ours * 1e3:.2f} ms, Pinocchio "
          f"{t_pin * 1e3:.2f} ms; one state per call: Dynamics {one['handle'] * 1e6:.1f} µs, Pinocchio "
          f"{one['pinocchio'] * 1e6:.1f} µs")
    return {"states": n_states, "spacar": t_ours, "pinocchio": t_pin, "per_call": one}


def series(points, label):
    return {"label": label, "points": points}


def have_mujoco() -> bool:
    try:
        import mujoco  # noqa: F401
    except ImportError:
        return False
    return True


def run_robot(name, quick):
    import pinocchio as pin

    path = urdf_file(*ROBOTS[name])
    t_end = QUICK["t_end"] if quick else T_END
    eps_list, steps = (QUICK["eps"], QUICK["steps"]) if quick else (EPS, STEPS)
    pm = pin.buildModelFromUrdf(str(path))
    pd = pm.createData()
    nv = pm.nv
    ref = pinocchio_run(pm, pd, nv, t_end, 1e-13, 1e-13)
    out = {"nv": nv, "spacar": [], "Pinocchio ABA + DOP853": [], "MuJoCo RK4": [], "MuJoCo implicitfast": []}
    path_name = None
    for eps in eps_list:
        res, wall = C.simulate_best(spacar_model(path, eps, t_end), repeat=REPEAT, budget=BUDGET, min_time=MIN_TIME,
                                    progress=False)
        path_name = res.stats["path"]
        err = float(np.abs(res.q[-1] - ref).max())
        out["spacar"].append((err, wall, eps, res.stats["steps"]))
        C.log(f"robots {name} spacar EPS {eps:g}: {wall * 1e3:.3f} ms, error {err:.1e}, {res.stats['steps']} steps, "
              f"{path_name} path")
    for eps in eps_list:
        wall, q = C.best_time(lambda: pinocchio_run(pm, pd, nv, t_end, eps, 1e-3 * eps), repeat=REPEAT, budget=BUDGET,
                              min_time=MIN_TIME)
        err = float(np.abs(q - ref).max())
        out["Pinocchio ABA + DOP853"].append((err, wall, eps, None))
        C.log(f"robots {name} Pinocchio DOP853 rtol {eps:g}: {wall * 1e3:.3f} ms, error {err:.1e}")
    for integrator in ("RK4", "implicitfast") if have_mujoco() else ():  # pip install mujoco (the bench extra)
        import mujoco

        for h in steps:
            mm = mujoco_model(path, h, integrator)
            md = mujoco.MjData(mm)
            wall, q = C.best_time(lambda: mujoco_run(mm, md, t_end, h), repeat=REPEAT, budget=BUDGET, min_time=MIN_TIME)
            err = float(np.abs(q - ref).max())
            out[f"MuJoCo {integrator}"].append((err, wall, h, int(round(t_end / h))))
            C.log(f"robots {name} MuJoCo {integrator} h {h:g}: {wall * 1e3:.3f} ms, error {err:.1e}")
    out["path"] = path_name
    out["derivatives"] = derivatives_batch(path, pm, pd)
    return out


def derivatives_batch(path, pm, pd, n_states=1000):
    """(spacar, Pinocchio) seconds for the dynamics derivatives of n_states random states: one
    spacar.dynamics_derivatives call on the batch against as many calls of
    pinocchio.computeABADerivatives from Python (as a Pinocchio user writes it), each checked
    against the other first; the same for the inverse dynamics against pinocchio.rnea."""
    import pinocchio as pin
    import spacar

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # what the URDF leaves out, said once by the runs above
        model = spacar.from_urdf(str(path))
    rng = np.random.default_rng(3)
    nv = pm.nv
    q, qd, tau = (rng.uniform(-1.0, 1.0, (n_states, nv)) for _ in range(3))
    pin_q = [pin.integrate(pm, pin.neutral(pm), q[k]) for k in range(n_states)]  # continuous joints: (cos, sin)
    ours = spacar.dynamics_derivatives(model, q, qd, tau)
    for k in range(0, n_states, 97):
        ref = pin.computeABADerivatives(pm, pd, pin_q[k], qd[k], tau[k])
        assert np.abs(ours[1][k] - ref[0]).max() <= 1e-9 * max(1.0, np.abs(ref[0]).max())
    t_ours, _ = C.best_time(lambda: spacar.dynamics_derivatives(model, q, qd, tau), repeat=REPEAT, budget=BUDGET,
                            min_time=MIN_TIME)
    t_pin, _ = C.best_time(lambda: [pin.computeABADerivatives(pm, pd, pin_q[k], qd[k], tau[k])
                                    for k in range(n_states)], repeat=REPEAT, budget=BUDGET, min_time=MIN_TIME)
    t_id, _ = C.best_time(lambda: spacar.inverse_dynamics(model, q, qd, tau), repeat=REPEAT, budget=BUDGET,
                          min_time=MIN_TIME)
    t_rnea, _ = C.best_time(lambda: [pin.rnea(pm, pd, pin_q[k], qd[k], tau[k]) for k in range(n_states)],
                            repeat=REPEAT, budget=BUDGET, min_time=MIN_TIME)
    C.log(f"derivatives of {n_states} states: spacar {t_ours * 1e3:.2f} ms, Pinocchio {t_pin * 1e3:.2f} ms; "
          f"inverse dynamics: spacar {t_id * 1e3:.2f} ms, Pinocchio rnea {t_rnea * 1e3:.2f} ms")
    # One state per call, as a controller or an optimizer's step calls them: the functions (their
    # set-up at every call) and a spacar.Dynamics made once, against Pinocchio's calls.
    dyn = spacar.Dynamics(model)
    assert np.abs(dyn.dynamics_derivatives(q[0], qd[0], tau[0])[1] - ours[1][0]).max() == 0.0
    one = {"function": lambda: spacar.dynamics_derivatives(model, q[0], qd[0], tau[0]),
           "handle": lambda: dyn.dynamics_derivatives(q[0], qd[0], tau[0]),
           "function_id": lambda: spacar.inverse_dynamics(model, q[0], qd[0], tau[0]),
           "handle_id": lambda: dyn.inverse_dynamics(q[0], qd[0], tau[0]),
           "pinocchio": lambda: pin.computeABADerivatives(pm, pd, pin_q[0], qd[0], tau[0]),
           "pinocchio_rnea": lambda: pin.rnea(pm, pd, pin_q[0], qd[0], tau[0])}
    per_call = {k: C.per_call(f, min_time=0.2) for k, f in one.items()}
    C.log("one state per call: " + ", ".join(f"{k} {v * 1e6:.1f} µs" for k, v in per_call.items()))
    return {"states": n_states, "spacar": t_ours, "pinocchio": t_pin, "spacar_id": t_id, "pinocchio_rnea": t_rnea,
            "per_call": per_call}


def run(a) -> dict:
    return {"quick": a.quick, "t_end": QUICK["t_end"] if a.quick else T_END, "machine": C.machine(peers=True),
            "robots": {name: run_robot(name, a.quick) for name in ROBOTS}, "floating": run_floating(a.quick)}


PROGRAMS = ["spacar", "Pinocchio ABA + DOP853", "MuJoCo RK4", "MuJoCo implicitfast"]


def section(r: dict, plots=None) -> str:
    lines = ["## Robots: UR5 and Panda, spacar, Pinocchio and MuJoCo", "", __doc__.split("\n\n")[0].replace("\n", " "),
             "", *C.machine_table(r["machine"]), ""]
    lines += ["| robot | DOFs | spacar's path | target [rad] | " + " | ".join(PROGRAMS) +
              " | MuJoCo RK4 / spacar | Pinocchio / spacar |", "|" + "---|" * (len(PROGRAMS) + 6)]
    for name, x in r["robots"].items():
        for target in TARGETS:
            times = {p: C.time_to_accuracy([(e, t) for e, t, *_ in x[p]], target) for p in PROGRAMS}
            lines.append(f"| {name} | {x['nv']} | {x['path']} | {target:g} | " +
                         " | ".join(C.fmt_time(times[p]) for p in PROGRAMS) +
                         f" | {C.fmt_ratio(times['MuJoCo RK4'], times['spacar'])} | "
                         f"{C.fmt_ratio(times['Pinocchio ABA + DOP853'], times['spacar'])} |")
    lines += ["", "Every run (setting → error in wall time; spacar and Pinocchio: EPS, MuJoCo: the step h):", ""]
    for name, x in r["robots"].items():
        for p in PROGRAMS:
            runs = ", ".join(f"{s:g} → {e:.1e} in {C.fmt_time(t)}" for e, t, s, *_ in x[p])
            lines.append(f"* {name}, {p}: {runs}")
    lines += ["", "Issue 37 target, time to 1e-6 rad on the Panda and the UR5 over 1 s at least 1.5× faster than "
              "MuJoCo compiled once and 3× faster than Pinocchio + DOP853: " + target_verdict(r) + "."]
    lines += ["", "**Derivatives and inverse dynamics of a batch of states.** One `spacar.dynamics_derivatives` "
              "(`spacar.inverse_dynamics`) call on a batch of random states against as many calls of "
              "`pinocchio.computeABADerivatives` (`pinocchio.rnea`) from Python, the results checked against "
              "each other first (to 1e-9):", "",
              "| robot | states | spacar derivatives | Pinocchio derivatives | Pinocchio / spacar | spacar "
              "inverse dynamics | Pinocchio rnea | Pinocchio / spacar |", "|---|---|---|---|---|---|---|---|"]
    for name, x in r["robots"].items():
        d = x.get("derivatives")
        if d:
            lines.append(f"| {name} | {d['states']} | {C.fmt_time(d['spacar'])} | {C.fmt_time(d['pinocchio'])} | "
                         f"{C.fmt_ratio(d['pinocchio'], d['spacar'])} | {C.fmt_time(d['spacar_id'])} | "
                         f"{C.fmt_time(d['pinocchio_rnea'])} | {C.fmt_ratio(d['pinocchio_rnea'], d['spacar_id'])} |")
    lines += ["", "Issue 37 target, a batch of 1000 derivative evaluations of the UR5 no slower than 1000 calls of "
              "computeABADerivatives: " + derivatives_verdict(r) + "."]
    if any("per_call" in (x.get("derivatives") or {}) for x in r["robots"].values()):
        lines += ["", "**One state per call** (as a controller's or an optimizer's step calls them): the functions "
                  "`spacar.dynamics_derivatives` and `spacar.inverse_dynamics`, which compile and assemble the model "
                  "at every call, a `spacar.Dynamics` made once, and Pinocchio's calls:", "",
                  "| robot | derivatives: function | `Dynamics` | Pinocchio | Pinocchio / `Dynamics` | inverse "
                  "dynamics: function | `Dynamics` | `rnea` | `rnea` / `Dynamics` |", "|---|---|---|---|---|---|---|---|---|"]
        for name, x in r["robots"].items():
            c = (x.get("derivatives") or {}).get("per_call")
            if c:
                lines.append(f"| {name} | {C.fmt_time(c['function'])} | {C.fmt_time(c['handle'])} | "
                             f"{C.fmt_time(c['pinocchio'])} | {C.fmt_ratio(c['pinocchio'], c['handle'])} | "
                             f"{C.fmt_time(c['function_id'])} | {C.fmt_time(c['handle_id'])} | "
                             f"{C.fmt_time(c['pinocchio_rnea'])} | {C.fmt_ratio(c['pinocchio_rnea'], c['handle_id'])} |")
    f = r.get("floating")
    if f:
        lines += ["", "**A floating base.** " + run_floating.__doc__.replace("\n    ", " ") + " Time to a target: "
                  "the fastest run that reached it (EPSINT = EPSIND = EPS; Pinocchio: rtol = EPS, atol = 1e-3 EPS):", "",
                  f"| robot | DOFs | target | " + " | ".join(FLOATING_PROGRAMS) + " | general path / tree | "
                  "Pinocchio / tree |", "|" + "---|" * (len(FLOATING_PROGRAMS) + 5)]
        for target in TARGETS:
            t = {p: C.time_to_accuracy([(e, s) for e, s, *_ in f[p]], target) for p in FLOATING_PROGRAMS}
            lines.append(f"| Solo12 | {f['nv']} | {target:g} | " + " | ".join(C.fmt_time(t[p]) for p in FLOATING_PROGRAMS) +
                         f" | {C.fmt_ratio(t['spacar (general path)'], t['spacar (tree)'])} | "
                         f"{C.fmt_ratio(t['Pinocchio ABA + DOP853'], t['spacar (tree)'])} |")
        for p in FLOATING_PROGRAMS:
            runs = ", ".join(f"{s:g} → {e:.1e} in {C.fmt_time(t)}" for e, t, s, *_ in f[p])
            lines.append(f"* Solo12 floating, {p}: {runs}")
        d = f.get("derivatives")
        if d:
            lines += ["", "**Derivatives on the floating base.** Solo12 on a floating base, 1000 random states: one "
                      "call of a `spacar.Dynamics` (made outside the timing) on the batch against as many calls of "
                      "`pinocchio.computeABADerivatives` on its free flyer, and one state per call. The coordinates "
                      "differ (spacar: the origin and three Euler parameters; Pinocchio: the free flyer's tangent), "
                      "so each is checked against itself before it is timed (spacar's q̈ gives back τ through its "
                      "inverse dynamics, and its derivatives are checked against the inverse dynamics' differences "
                      "in tests/api/test_urdf.py; Pinocchio's q̈ is its `aba`'s).",
                      "", "| robot | states | spacar batch | Pinocchio calls | Pinocchio / spacar | one state: "
                      "`Dynamics` | one state: Pinocchio | Pinocchio / `Dynamics` |", "|---|---|---|---|---|---|---|---|",
                      f"| Solo12 floating | {d['states']} | {C.fmt_time(d['spacar'])} | {C.fmt_time(d['pinocchio'])} | "
                      f"{C.fmt_ratio(d['pinocchio'], d['spacar'])} | {C.fmt_time(d['per_call']['handle'])} | "
                      f"{C.fmt_time(d['per_call']['pinocchio'])} | "
                      f"{C.fmt_ratio(d['per_call']['pinocchio'], d['per_call']['handle'])} |"]
    return "\n".join(lines) + "\n"


def target_verdict(r) -> str:
    parts, met = [], True
    for name, x in r["robots"].items():
        t = {p: C.time_to_accuracy([(e, s) for e, s, *_ in x[p]], 1e-6) for p in PROGRAMS}
        mj = min((v for v in (t["MuJoCo RK4"], t["MuJoCo implicitfast"]) if v is not None), default=None)
        pi = t["Pinocchio ABA + DOP853"]
        if t["spacar"] is None or mj is None or pi is None:
            parts.append(f"{name}: not reached by every program")
            met = False
            continue
        parts.append(f"{name}: MuJoCo / spacar {mj / t['spacar']:.3g}×, Pinocchio / spacar {pi / t['spacar']:.3g}×")
        met = met and mj / t["spacar"] >= 1.5 and pi / t["spacar"] >= 3.0
    return ("**met** (" if met else "**NOT met** (") + "; ".join(parts) + ")"


def derivatives_verdict(r) -> str:
    d = r["robots"].get("UR5", {}).get("derivatives")
    if not d:
        return "not measured"
    ratio = d["pinocchio"] / d["spacar"]
    return ("**met**" if ratio >= 1.0 else "**NOT met**") + f" (Pinocchio / spacar {ratio:.2f}×)"


def plot(r):
    return None


def main(argv=None) -> int:
    return C.standard_main("robots", __doc__, run, section, plot, argv)


if __name__ == "__main__":
    import sys

    sys.exit(main())

"""Benchmark: rigid planar N-link pendulum chains (N = 2 … 100), spacar against exudyn and
Pinocchio, and rigid spatial chains (N = 6, 20) against exudyn, Pinocchio and MuJoCo, side by
side in one process.

Model (spacar.compare.models.planar_chain): N uniform rigid links (PLBEAM, EMASS 1, total
length 1 m), PLHINGE joints whose angles are the DOFs, released from rest horizontally under
gravity, simulated over T = 0.3 s.

* time per right-hand side: spacar — block wall time / right-hand-side evaluations of a run
  (EPSINT = 1e-6) on its default recursive path (a planar tree of rigid bodies: the
  articulated-body algorithm, cpp/include/spacar/recursive/planar_tree.hpp) and on the general path
  (``recursive=False``: the sparse constraint formulation every other model takes), and
  ``Simulation.evaluate`` called from Python; Pinocchio — ``aba`` called
  from Python; exudyn — kinematic tree (``ObjectKinematicTree``) with fixed-step RK44, wall
  time / (4 · steps);
* time-to-accuracy: every program at a range of tolerances (steps); error = largest joint-angle
  error at T against a reference (Pinocchio's ABA integrated by DOP853 at rtol 1e-13); the
  time to reach an error is the shortest run that reached it. spacar on both paths. Peers: exudyn's kinematic tree
  with its error-controlled DOPRI5, exudyn's redundant coordinates with generalized-α (its
  default), Pinocchio's ABA with spacar's C++ DOP853 (right-hand side called into Python);
* growth of the cost per right-hand side with N: log-log fit for N ≥ 10.

Spatial chains (spacar.compare.models.spatial_chain, seed N): N rigid BEAMs of random directions
on HINGEs about random axes (DYNE e1), EMASS with rotary inertia, point masses and full inertia
tensors, a rotated ground, gravity along a random direction; spacar takes the recursive path of
spatial trees (cpp/include/spacar/recursive/spatial_tree.hpp). The same tables, with MuJoCo (the same tree
written as MJCF: ``mj_forward`` per right-hand side, its RK4 at fixed steps for time to accuracy)
in place of exudyn's redundant coordinates, and spacar's block time also over a run ten times as
long: the line through the two (time against right-hand sides) splits it into the run's fixed
costs and the integration loop's cost per right-hand side. MuJoCo is a benchmark-only, optional import
(``pip install mujoco``); without it its columns are empty.

    python benchmarks/chains.py [--quick] [--no-write] [--no-plot] [--from-results] [--spatial-only]

``--spatial-only``: measure the spatial chains only, keeping the planar results of
benchmarks/results/chains.json.
"""
from __future__ import annotations

import sys
import time

import numpy as np

import _common as C
import spacar
from spacar.compare import models

TITLE = "Rigid N-link chains: spacar, exudyn, Pinocchio"
SIZES, QUICK_SIZES = [2, 5, 10, 20, 50, 100], [2, 3]
T_END, QUICK_T_END = 0.3, 0.05
TOLS, QUICK_TOLS = [1e-4, 1e-6, 1e-8, 1e-10, 1e-12], [1e-4, 1e-6]
# spacar's DOP853 at EPSINT = 1e-12 needs 111 000 steps for N = 20 (400 at 1e-10, 246 s): the
# Newton-solved right-hand side carries round-off noise of about that size, which the error
# estimator cannot tell from truncation error. exudyn's DOPRI5 on the kinematic tree behaves the
# same way at N = 50, rtol = 1e-10 (no result after 9 minutes, against 4 s at 1e-8). Tolerance
# floors per N keep every case within minutes.
def tolerance_floor(n):
    return 1e-12 if n <= 10 else 1e-10 if n <= 20 else 1e-8
GA_STEPS, QUICK_GA_STEPS = [1e-3, 1e-4], [1e-3]
TARGETS = [1e-4, 1e-6, 1e-8]
# Every program's run at a setting: the best of at least REPEAT runs repeated for at least
# MIN_TIME seconds, within REPEAT_BUDGET seconds. The runs of small chains take a few hundred
# microseconds: three of them, back to back, all fall into one burst of load on the shared
# machine (which slowed spacar's 2-link runs by 20–70 % in some benchmark runs and not in others).
REPEAT, MIN_TIME, REPEAT_BUDGET = 3, 0.25, 2.0
RUN_BUDGET = 10.0  # s: a tool stops tightening its tolerance once a run took a third of it
# (each tightening by 100 costs at least about three times as much; exudyn's DOPRI5 at N = 100
# took 9 s at rtol 1e-6 and did not finish in 25 minutes at 1e-8)


SPATIAL_SIZES, QUICK_SPATIAL_SIZES = [6, 20], [3]
# The spatial chains' tolerances at half decades from 1e-2 down to 1e-8, as MuJoCo's steps below:
# a scan by decades, or from 1e-4 only, would give the tolerance-driven programs (spacar, exudyn,
# Pinocchio + DOP853) a target's time at up to ten (a hundred) times the accuracy it asks for.
SPATIAL_TOLS = [1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 3e-7, 1e-7, 3e-8, 1e-8, 1e-10, 1e-12]
# MuJoCo's RK4 at fixed steps (s); a Python loop of mj_step, stopped like the others at RUN_BUDGET / 3.
# T_END in 8 … 10 000 steps, their number in ratios of about 10^(1/8): RK4's error (∝ h⁴) in steps
# of half a decade, the granularity of the other programs' tolerances (SPATIAL_TOLS), so that no
# program's time to a target is taken at much more accuracy than it asks for. Whole numbers of
# steps, so that each run ends at T_END; 8 steps (0.0375 s) are past RK4's stability at 20 links.
MUJOCO_STEPS = [T_END / n for n in sorted({round(8 * 10 ** (k / 8)) for k in range(25)} | {10000})]
QUICK_MUJOCO_STEPS = [1e-2, 1e-3]


def chain(n, t_end, eps=1e-6):
    return models.planar_chain(n, rho_a=1.0, angle=0.0, t_end=t_end, n_out=1, eps=eps,
                               epskin=max(1e-13, 1e-3 * eps))


def spatial_chain(n, t_end, eps=1e-6):
    return models.spatial_chain(n, seed=n, t_end=t_end, n_out=1, eps=eps, epskin=max(1e-13, 1e-3 * eps))


def mujoco_model(pm, step):
    """The MuJoCo model (MJCF: nested bodies with hinge joints and full inertias, RK4 at ``step``)
    of the Pinocchio model ``pm`` of a spacar chain (spacar.compare.pinocchio): the same joint
    placements, axes, inertias and gravity, so that its qpos, qvel are Pinocchio's q, v."""
    import mujoco
    import pinocchio as pin

    pmod = pm.model

    def fmt(v):
        return " ".join(f"{x:.17g}" for x in v)

    children = {}
    for jid in range(1, pmod.njoints):
        children.setdefault(pmod.parents[jid], []).append(jid)
    axes = {pm._jid_of_body[c]: np.asarray(j.axis, dtype=float) for j, _, c in pm.joints}

    def body(jid):
        M, inertia = pmod.jointPlacements[jid], pmod.inertias[jid]
        q, J = pin.Quaternion(M.rotation), inertia.inertia
        return (f'<body pos="{fmt(M.translation)}" quat="{fmt([q.w, q.x, q.y, q.z])}">'
                f'<joint type="hinge" axis="{fmt(axes[jid])}"/>'
                f'<inertial pos="{fmt(inertia.lever)}" mass="{inertia.mass:.17g}" '
                f'fullinertia="{fmt([J[0, 0], J[1, 1], J[2, 2], J[0, 1], J[0, 2], J[1, 2]])}"/>'
                + "".join(body(c) for c in children.get(jid, [])) + "</body>")

    xml = (f'<mujoco><option gravity="{fmt(pmod.gravity.linear)}" integrator="RK4" timestep="{step:.17g}"/>'
           f'<worldbody>{"".join(body(c) for c in children[0])}</worldbody></mujoco>')
    return mujoco.MjModel.from_xml_string(xml)


def mujoco_run(model, data, q0, t_end, step):
    """Joint angles at t_end from (q0, 0) by MuJoCo's RK4 at a fixed step, with the model compiled
    and its data made before (outside the timing, as a MuJoCo user does and as spacar's model is
    built outside its own): the run resets the data and steps."""
    import mujoco

    mujoco.mj_resetData(model, data)
    data.qpos[:] = q0
    mj_step = mujoco.mj_step
    for _ in range(int(round(t_end / step))):
        mj_step(model, data)
    return np.array(data.qpos)


def have_mujoco():
    try:
        import mujoco  # noqa: F401
    except ImportError:
        return False
    return True


def hinge_columns(labels, n):
    return [labels.index((models.HINGE + i, 1)) for i in range(1, n + 1)]


def run_spacar(n, t_end, eps, recursive=True, build=chain):
    """Best wall time of ``spacar.simulate`` (each run on a fresh copy of the model, built outside
    the timing; see REPEAT); joint angles at T and the run's statistics."""
    res, best = C.simulate_best(build(n, t_end, eps), REPEAT, REPEAT_BUDGET, recursive=recursive,
                                min_time=MIN_TIME)
    q = res.e[-1, hinge_columns(res.deformation_labels, n)]
    return q, best, res.stats


def next_block_fixed(model, t_loop, min_time):
    """The fixed cost of a `spacar.simulate` call that runs the model's next block (the model
    simulated before, unchanged since: its kept simulation renewed, issue 37): each call's time
    beyond its right-hand sides at the loop's cost ``t_loop``, the best over calls for at least
    ``min_time`` seconds (each block continues the motion, so its right-hand sides vary)."""
    spacar.simulate(model)
    best, spent = float("inf"), 0.0
    while spent < min_time or best == float("inf"):
        start = time.perf_counter()
        res = spacar.simulate(model)
        wall = time.perf_counter() - start
        spent += wall
        best = min(best, wall - t_loop * res.stats["rhs_evaluations"])
    return best


def per_rhs(n, t_end, quick, build=chain):
    """Time per right-hand side of spacar (in its EPSINT = 1e-6 run, and `evaluate` from Python),
    Pinocchio (ABA), exudyn (tree, RK44) and, for the spatial chains, MuJoCo (``mj_forward``)."""
    from spacar import _core
    from spacar.compare import exudyn as sx
    from spacar.compare import pinocchio as sp

    import exudyn as exu

    model = build(n, 1.0)
    model.prepare()
    sim = _core.Simulation(model._core)
    sim.assemble()
    q0 = np.array(sim.system.q0) + min(0.1, 1.0 / n)  # a curled chain, reached by Newton from the straight one
    qd0 = np.full(q0.size, 0.3)
    t_eval = C.per_call(lambda: sim.evaluate(0.0, q0, qd0), min_time=0.1 if quick else 0.5)
    t_run, run_stats = C.in_run_per_rhs(build(n, t_end, 1e-6), min_time=0.1 if quick else 0.5)
    t_general, general_stats = C.in_run_per_rhs(build(n, t_end, 1e-6), min_time=0.1 if quick else 0.5,
                                                recursive=False)
    pm = sp.build(build(n, 1.0))
    tau = np.zeros(n)
    aba = sp.pin.aba
    t_aba = C.per_call(lambda: aba(pm.model, pm.data, q0, qd0, tau), min_time=0.1 if quick else 0.5)
    f = pm.rhs()
    y = np.concatenate((q0, qd0))
    t_rhs_py = C.per_call(lambda: f(0.0, y), min_time=0.1 if quick else 0.5)
    em = sx.build(build(n, 1.0), formulation="tree")
    steps = 50 if quick else 400
    h = 1e-5
    st = em.settings(0.0, steps * h, "rk44", None, None, h)
    wall, _ = C.best_time(lambda: em.mbs.SolveDynamic(st, solverType=exu.DynamicSolverType.RK44), repeat=3)
    t_exu = wall / (4 * steps)
    t_mujoco = t_long = t_loop = t_fixed = t_rollout_fixed = t_simulate_fixed = t_simulate_next_fixed = t_batch_one = t_batch_all = None
    if build is spatial_chain:  # the same, over a run 10 times as long: the fixed costs spread thinner
        t_long, long_stats = C.in_run_per_rhs(build(n, 10 * t_end, 1e-6), min_time=0.1 if quick else 0.5)
        # The block's time as fixed costs (assembly, recognition of the tree, output times) plus
        # the integration loop's cost per right-hand side: the line through the two runs.
        rhs_short, rhs_long = run_stats["rhs_evaluations"], long_stats["rhs_evaluations"]
        t_loop = (t_long * rhs_long - t_run * rhs_short) / (rhs_long - rhs_short)
        t_fixed = t_run * rhs_short - t_loop * rhs_short
        # spacar.Rollout: the set-up made once (its first call), each call from Python then
        # integrates alone; its fixed cost per call is the call's time beyond the loop's.
        # The same line through a short and a 10× longer rollout of one Rollout, from Python.
        roll = spacar.Rollout(build(n, t_end, 1e-6), threads=1)
        short, long = np.array([0.0, t_end]), np.array([0.0, 10 * t_end])
        rhs_roll = [int(roll(t=t).stats["rhs_evaluations"][0]) for t in (short, long)]
        t_roll = [C.per_call(lambda: roll(t=t), min_time=0.1 if quick else 0.5) for t in (short, long)]
        slope = (t_roll[1] - t_roll[0]) / (rhs_roll[1] - rhs_roll[0])
        t_rollout_fixed = t_roll[0] - slope * rhs_roll[0]
        # A batch of 64 states from random joint angles and rates: one thread against all cores.
        rng = np.random.default_rng(n)
        q_batch = np.array(roll().q[0]) + 0.2 * rng.standard_normal((64, n))
        qd_batch = rng.standard_normal((64, n))
        roll_threads = spacar.Rollout(build(n, t_end, 1e-6), threads=None)
        roll_threads(q_batch, qd_batch)  # each thread's copy assembled
        t_batch_one, _ = C.best_time(lambda: roll(q_batch, qd_batch), repeat=5, min_time=0.1 if quick else 0.5)
        t_batch_all, _ = C.best_time(lambda: roll_threads(q_batch, qd_batch), repeat=5, min_time=0.1 if quick else 0.5)
        t_simulate_call, _ = C.best_time(spacar.simulate, repeat=20, min_time=0.1 if quick else 0.5,
                                         setup=build(n, t_end, 1e-6).copy)  # each call on a fresh copy
        t_simulate_fixed = t_simulate_call - t_loop * rhs_short
        t_simulate_next_fixed = next_block_fixed(build(n, t_end, 1e-6), t_loop, min_time=0.1 if quick else 0.5)
    if build is spatial_chain and have_mujoco():
        import mujoco

        mm = mujoco_model(pm, 1e-3)
        md = mujoco.MjData(mm)
        md.qpos[:], md.qvel[:] = q0, qd0
        t_mujoco = C.per_call(lambda: mujoco.mj_forward(mm, md), min_time=0.1 if quick else 0.5)
    return {"rollout_batch_one_thread": t_batch_one, "rollout_batch_threads": t_batch_all, "rollout_fixed": t_rollout_fixed, "simulate_fixed": t_simulate_fixed, "simulate_next_fixed": t_simulate_next_fixed, "mujoco_forward": t_mujoco, "spacar_in_long_run": t_long, "spacar_loop": t_loop, "spacar_fixed": t_fixed, "spacar_in_run": t_run, "spacar_recursive": run_stats["recursive"], "spacar_general_in_run": t_general,
            "spacar_newton_per_rhs": general_stats["newton_iterations"] / general_stats["rhs_evaluations"],
            "spacar_evaluate": t_eval, "pinocchio_aba": t_aba, "pinocchio_rhs_python": t_rhs_py, "exudyn_tree_rk44": t_exu}


def accuracy_runs(n, t_end, tols, ga_steps, build=chain, mujoco_steps=()):
    """(error, wall time) of every program and setting against the reference."""
    tols = [t for t in tols if t >= tolerance_floor(n) * 0.999]
    from spacar.compare import exudyn as sx
    from spacar.compare import pinocchio as sp

    pm_model = build(n, t_end)
    _, q_ref, _, _ = sp.simulate(pm_model, rtol=1e-13, atol=1e-16)
    q_start, q_ref = q_ref[0], q_ref[-1]
    out = {"spacar": [], "spacar general path": [], "exudyn tree DOPRI5": [], "exudyn redundant GA": [],
           "Pinocchio ABA + DOP853": []}
    if mujoco_steps:
        out["MuJoCo RK4"] = []
        pm = sp.build(build(n, t_end))
        import mujoco

        for h in mujoco_steps:
            mm = mujoco_model(pm, h)
            md = mujoco.MjData(mm)
            wall, q = C.best_time(lambda: mujoco_run(mm, md, q_start, t_end, h), repeat=REPEAT, budget=REPEAT_BUDGET,
                                  min_time=MIN_TIME)
            out["MuJoCo RK4"].append((float(np.abs(q - q_ref).max()), wall, h))
            C.log(f"  N={n} MuJoCo RK4 h={h:g}: err {out['MuJoCo RK4'][-1][0]:.2e}, {wall:.3f} s")
            if wall > RUN_BUDGET / 3:
                break
    stats = {}
    for key, recursive in (("spacar", True), ("spacar general path", False)):
        for eps in tols:
            q, wall, st = run_spacar(n, t_end, eps, recursive=recursive, build=build)
            out[key].append((float(np.abs(q - q_ref).max()), wall, eps))
            stats.setdefault(key, {})[eps] = (st["rhs_evaluations"], st["steps"], st["rejected"])
            C.log(f"  N={n} {key} eps={eps:g}: err {out[key][-1][0]:.2e}, {wall:.3f} s")
            if wall > RUN_BUDGET / 3:
                break
    if build is spatial_chain:  # compiled, assembled and its tree recognized once, as MuJoCo's model
        out["spacar Rollout"] = []
        for eps in tols:
            roll = spacar.Rollout(build(n, t_end, eps))
            roll()  # the set-up of its first call: the assembly and the recognition of the tree
            wall, res = C.best_time(roll, repeat=REPEAT, budget=REPEAT_BUDGET, min_time=MIN_TIME)
            out["spacar Rollout"].append((float(np.abs(res.q[-1] - q_ref).max()), wall, eps))
            C.log(f"  N={n} spacar Rollout eps={eps:g}: err {out['spacar Rollout'][-1][0]:.2e}, {wall:.3f} s")
            if wall > RUN_BUDGET / 3:
                break
    em = sx.build(build(n, t_end), formulation="tree")
    for eps in tols:
        wall, er = C.best_time(lambda: em.solve(t_end=t_end, n_out=1, solver="dopri5", rtol=eps, atol=1e-3 * eps),
                               repeat=REPEAT, budget=REPEAT_BUDGET,
                               min_time=MIN_TIME)
        out["exudyn tree DOPRI5"].append((float(np.abs(er.q[-1] - q_ref).max()), wall, eps))
        C.log(f"  N={n} exudyn tree DOPRI5 rtol={eps:g}: err {out['exudyn tree DOPRI5'][-1][0]:.2e}, {wall:.3f} s")
        if wall > RUN_BUDGET / 3:
            break
    if ga_steps:
        em = sx.build(build(n, t_end), formulation="redundant")
        cols = hinge_columns(em.def_labels, n)
    for h in ga_steps:
        wall, er = C.best_time(lambda: em.solve(t_end=t_end, n_out=1, solver="generalized_alpha", step=h),
                               repeat=REPEAT, budget=REPEAT_BUDGET,
                               min_time=MIN_TIME)
        out["exudyn redundant GA"].append((float(np.abs(er.e[-1, cols] - q_ref).max()), wall, h))
        C.log(f"  N={n} exudyn GA h={h:g}: err {out['exudyn redundant GA'][-1][0]:.2e}, {wall:.3f} s")
        if wall > RUN_BUDGET / 3:
            break
    for eps in tols:
        wall, (_, q, _, _) = C.best_time(lambda: sp.simulate(pm_model, rtol=eps, atol=1e-3 * eps), repeat=REPEAT,
                                         budget=REPEAT_BUDGET, min_time=MIN_TIME)
        out["Pinocchio ABA + DOP853"].append((float(np.abs(q[-1] - q_ref).max()), wall, eps))
        if wall > RUN_BUDGET / 3:
            break
    return out, stats


def run(quick: bool = False) -> dict:
    C.quiet_exudyn()
    sizes = QUICK_SIZES if quick else SIZES
    t_end = QUICK_T_END if quick else T_END
    tols = QUICK_TOLS if quick else TOLS
    ga_steps = QUICK_GA_STEPS if quick else GA_STEPS
    result = {"quick": quick, "sizes": sizes, "t_end": t_end, "machine": C.machine(peers=True), "rhs": {}, "acc": {}, "stats": {}}
    for n in sizes:
        C.log(f"chains: N = {n}")
        result["rhs"][n] = per_rhs(n, t_end, quick)
        result["acc"][n], result["stats"][n] = accuracy_runs(n, t_end, tols, ga_steps)
    result["spatial"] = run_spatial(quick)
    return result


def run_spatial(quick: bool = False) -> dict:
    """The spatial chains: time per right-hand side and time to accuracy, MuJoCo included."""
    C.quiet_exudyn()
    sizes = QUICK_SPATIAL_SIZES if quick else SPATIAL_SIZES
    t_end = QUICK_T_END if quick else T_END
    tols = QUICK_TOLS if quick else SPATIAL_TOLS
    steps = (QUICK_MUJOCO_STEPS if quick else MUJOCO_STEPS) if have_mujoco() else ()
    result = {"sizes": sizes, "t_end": t_end, "machine": C.machine(peers=True), "mujoco": bool(steps),
              "rhs": {}, "acc": {}, "stats": {}}
    for n in sizes:
        C.log(f"spatial chains: N = {n}")
        result["rhs"][n] = per_rhs(n, t_end, quick, build=spatial_chain)
        result["acc"][n], result["stats"][n] = accuracy_runs(n, t_end, tols, (), build=spatial_chain,
                                                             mujoco_steps=steps)
    return result


def run_spatial_only(quick: bool) -> dict:
    """The planar results of the last full run (benchmarks/results/chains.json), the spatial ones new."""
    result = C.load_results("chains")
    result["spatial"] = run_spatial(quick)
    if quick:
        result["quick"] = True
    return result


def section(r: dict, plots: dict | None = None) -> str:
    sizes = r["sizes"]
    lines = [f"## {TITLE}", "",
             f"`python benchmarks/chains.py{' --quick' if r['quick'] else ''}` (or `benchmarks/run_all.py`): "
             f"N uniform rigid links (PLBEAM, EMASS 1 kg/m, total length 1 m), PLHINGE angles as DOFs, "
             f"released from rest horizontally under gravity, T = {r['t_end']} s. All programs run in one process, "
             "one after the other.", "", *C.machine_table(r["machine"]), "",
             "### Time per right-hand side", "",
             "| N | spacar in a run | spacar general path in a run | spacar `evaluate()` from Python | "
             "Pinocchio `aba` from Python | ratio spacar/ABA | ratio general path/ABA | "
             "Pinocchio rhs in Python (ABA + packing) | exudyn tree, RK44 stage |",
             "|---|---|---|---|---|---|---|---|---|"]
    for n in sizes:
        x = r["rhs"][n]
        lines.append(f"| {n} | {C.fmt_time(x['spacar_in_run'])} | {C.fmt_time(x['spacar_general_in_run'])} | "
                     f"{C.fmt_time(x['spacar_evaluate'])} | {C.fmt_time(x['pinocchio_aba'])} | "
                     f"{C.fmt_ratio(x['spacar_in_run'], x['pinocchio_aba'])} | "
                     f"{C.fmt_ratio(x['spacar_general_in_run'], x['pinocchio_aba'])} | "
                     f"{C.fmt_time(x['pinocchio_rhs_python'])} | {C.fmt_time(x['exudyn_tree_rk44'])} |")
    big = [n for n in sizes if n >= 10]
    if len(big) >= 2:
        fits = {k: C.fit_exponent(big, [r["rhs"][n][k] for n in big])
                for k in ("spacar_in_run", "spacar_general_in_run", "spacar_evaluate", "pinocchio_aba", "exudyn_tree_rk44")}
        lines += ["", f"Growth of the cost per right-hand side for N = {big[0]}…{big[-1]} (log-log fit t ∝ Nᵖ): "
                  f"spacar p = {fits['spacar_in_run']:.2f} (in a run), {fits['spacar_general_in_run']:.2f} (general path "
                  f"in a run), {fits['spacar_evaluate']:.2f} (`evaluate`); "
                  f"Pinocchio ABA p = {fits['pinocchio_aba']:.2f}; exudyn tree p = {fits['exudyn_tree_rk44']:.2f}."]
    lines += ["", "'spacar in a run': the best block wall time (the C++ integration loop, with the assembly and the "
              "output times) of the EPSINT = 1e-6 run, repeated for at least 0.5 s like "
              "the peers' calls, over its right-hand sides; on the default path, which for these chains (a planar tree "
              "of rigid bodies) is the recursive one" + (
                  "" if all(r["rhs"][n].get("spacar_recursive", True) for n in sizes) else " (NOT taken in every run)") +
              ", and on the general path (`recursive=False`), whose Newton iterations per right-hand side are: " + ", ".join(
        f"N = {n}: {r['rhs'][n].get('spacar_newton_per_rhs', float('nan')):.2f}" for n in sizes) + "."]
    if 20 in r["rhs"]:
        x = r["rhs"][20]
        ratio = x["spacar_in_run"] / x["pinocchio_aba"]
        lines += ["", f"Issue #8 target, time per right-hand side within 3× of Pinocchio's ABA at N = 20: "
                  f"**{'met' if ratio <= 3 else 'NOT met'}** (spacar {C.fmt_time(x['spacar_in_run'])} in a run, "
                  f"ABA {C.fmt_time(x['pinocchio_aba'])}: {ratio:.2f}×; the general path "
                  f"{C.fmt_time(x['spacar_general_in_run'])}: {x['spacar_general_in_run'] / x['pinocchio_aba']:.2f}×)."]
    lines += ["", "### Time to accuracy", "",
              "Error: largest joint-angle error (rad) at T against Pinocchio's ABA integrated by DOP853 at rtol 1e-13. "
              "Time: wall time of the shortest run that reached the error (model building excluded; spacar's time "
              f"includes its assembly); every program's run at a setting is the best of at least {REPEAT} runs repeated "
              f"for at least {MIN_TIME:g} s (within {REPEAT_BUDGET:g} s). '—': no run reached it within the run budget.",
              "",
              "| N | target | spacar | spacar general path | exudyn tree DOPRI5 | exudyn redundant GA | "
              "Pinocchio ABA + DOP853 | exudyn best / spacar | exudyn best / spacar general path |",
              "|---|---|---|---|---|---|---|---|---|"]
    verdicts = []
    for n in sizes:
        acc = r["acc"][n]
        for target in TARGETS:
            t = {k: C.time_to_accuracy([(e, w) for e, w, _ in v], target) for k, v in acc.items()}
            ex = [v for k, v in t.items() if k.startswith("exudyn") and v is not None]
            best_ex = min(ex) if ex else None
            ratio = C.fmt_ratio(best_ex, t["spacar"])
            general = C.fmt_ratio(best_ex, t["spacar general path"])
            if best_ex is not None and t["spacar"] is not None:
                verdicts.append(best_ex / t["spacar"])
            lines.append(f"| {n} | {target:.0e} | {C.fmt_time(t['spacar'])} | {C.fmt_time(t['spacar general path'])} | "
                         f"{C.fmt_time(t['exudyn tree DOPRI5'])} | {C.fmt_time(t['exudyn redundant GA'])} | "
                         f"{C.fmt_time(t['Pinocchio ABA + DOP853'])} | {ratio} | {general} |")
    if verdicts:
        lines += ["", f"Issue #8 target, time-to-accuracy at least 3× better than exudyn on the rigid chains: "
                  f"**{'met' if min(verdicts) >= 3 else 'NOT met'}** (exudyn's best / spacar ranges from "
                  f"{min(verdicts):.3g}× to {max(verdicts):.3g}× over the rows above)."]
    lines += ["", "Runs (error at T, wall time) per program:", ""]
    for n in sizes:
        parts = []
        for k, v in r["acc"][n].items():
            parts.append(f"{k}: " + ", ".join(f"{s:g} → {C.fmt_err(e)} in {C.fmt_time(w)}" for e, w, s in v))
        lines.append(f"* N = {n}: " + "; ".join(parts) + ".")
    lines += ["", "spacar's work per run (EPSINT → right-hand sides / steps / rejected; the same on both paths up to "
              "round-off): " + "; ".join(
        f"N = {n}: " + ", ".join(f"{e:g} → {a}/{b}/{c}" for e, (a, b, c) in r["stats"][n].get("spacar", {}).items())
        for n in sizes) + "."]
    if "spatial" in r:
        lines += [""] + spatial_section(r["spatial"], r["quick"])
    if plots:
        lines += [""] + [f"![{k}]({v})" for k, v in plots.items()]
    return "\n".join(lines) + "\n"


def spatial_section(r: dict, quick: bool) -> list:
    sizes = r["sizes"]

    def verdict(fixed):
        return "met" if fixed < 1e-4 else "NOT met"

    lines = ["### Spatial chains", "",
             f"`python benchmarks/chains.py{' --quick' if quick else ''} --spatial-only` (also part of the full run): "
             "`spacar.compare.models.spatial_chain(N, seed=N)` — N rigid BEAMs of random directions and lengths on "
             "HINGEs about random axes (DYNE e1), EMASS with rotary inertia, point masses and full inertia tensors, a "
             f"rotated ground, gravity along a random direction, released from rest, T = {r['t_end']} s. spacar takes "
             "the recursive path of spatial trees (`cpp/include/spacar/recursive/spatial_tree.hpp`); MuJoCo runs the same tree "
             "written as MJCF (qpos = Pinocchio's q), compiled once per step size outside its timing (its run: "
             "`mj_resetData` and the steps), as spacar's model is built outside spacar's; `spacar.Rollout` (python-api.md, "
             "\"Rollouts\") is made and called once outside its timing (its compilation, assembly and recognition of "
             "the tree, as MuJoCo's compilation and `MjData`), its runs then timed as MuJoCo's" +
             ("" if r["mujoco"] else " — not installed in this run") + ". "
             "All programs in one process, one after the other.", "", *C.machine_table(r["machine"]), "",
             "| N | spacar in a run | spacar in a 10× longer run | spacar general path in a run (Newton iterations "
             "per rhs) | Pinocchio `aba` | ratio spacar/ABA | MuJoCo `mj_forward` | exudyn tree, RK44 stage | "
             "general path / spacar |",
             "|---|---|---|---|---|---|---|---|---|"]
    for n in sizes:
        x = r["rhs"][n]
        lines.append(f"| {n} | {C.fmt_time(x['spacar_in_run'])} | {C.fmt_time(x['spacar_in_long_run'])} | "
                     f"{C.fmt_time(x['spacar_general_in_run'])} "
                     f"({x['spacar_newton_per_rhs']:.2f}) | {C.fmt_time(x['pinocchio_aba'])} | "
                     f"{C.fmt_ratio(x['spacar_in_run'], x['pinocchio_aba'])} | {C.fmt_time(x['mujoco_forward'])} | "
                     f"{C.fmt_time(x['exudyn_tree_rk44'])} | "
                     f"{C.fmt_ratio(x['spacar_general_in_run'], x['spacar_in_run'])} |")
    if 20 in r["rhs"] and r["rhs"][20].get("spacar_loop"):
        x = r["rhs"][20]
        ratio = x["spacar_loop"] / x["pinocchio_aba"]
        lines += ["", "The two runs, the block's C++ time against its right-hand sides, split it into fixed costs per "
                  "run (the assembly from the X positions, the recognition of the tree, the output times) and the "
                  "integration loop's cost per right-hand side (the slope): " + "; ".join(
                      f"N = {n}: {C.fmt_time(r['rhs'][n]['spacar_fixed'])} + {C.fmt_time(r['rhs'][n]['spacar_loop'])} "
                      "per right-hand side" for n in sizes if r["rhs"][n].get("spacar_loop")) + ".",
                  "", "The fixed costs of a call from Python (its time beyond the loop's right-hand sides, "
                  "compilation and results included; a Rollout's from the line through its own short and long "
                  "calls): " + "; ".join(
                      f"N = {n}: `spacar.simulate` of a new model (a fresh copy each call) "
                      f"{C.fmt_time(r['rhs'][n]['simulate_fixed'])}, of the model's next block (simulated before, "
                      f"unchanged since) {C.fmt_time(r['rhs'][n]['simulate_next_fixed'])}, a `spacar.Rollout` "
                      f"made before {C.fmt_time(r['rhs'][n]['rollout_fixed'])}" for n in sizes
                      if r["rhs"][n].get("simulate_next_fixed") is not None) + ". Issue #37 target, fixed costs per "
                  "run of the 6-link chain below 0.1 ms: " + (
                      f"with `spacar.Rollout` **{verdict(r['rhs'][6]['rollout_fixed'])}** "
                      f"({C.fmt_time(r['rhs'][6]['rollout_fixed'])}); with `spacar.simulate`, the next block of a "
                      f"model **{verdict(r['rhs'][6]['simulate_next_fixed'])}** "
                      f"({C.fmt_time(r['rhs'][6]['simulate_next_fixed'])}: the simulation of the last block kept "
                      "and renewed, the tree kept, the block continued from the state the last block's last "
                      "output solved; it solves the complete state at its other output times), the first block of "
                      "a new model "
                      f"**{verdict(r['rhs'][6]['simulate_fixed'])}** ({C.fmt_time(r['rhs'][6]['simulate_fixed'])}: "
                      "it also compiles the model, assembles it, recognizes the tree and solves its first output; "
                      "MuJoCo's compilation is likewise a model's first cost)"
                      if r["rhs"].get(6, {}).get("simulate_next_fixed") is not None else "not measured") + ".",
                  "", f"A batch of 64 states (random joint angles and rates) in one `spacar.Rollout` call, one thread "
                  f"against `threads=None` (cores: {r['machine'].get('cores', '?')}): " + "; ".join(
                      f"N = {n}: {C.fmt_time(r['rhs'][n]['rollout_batch_one_thread'])} against "
                      f"{C.fmt_time(r['rhs'][n]['rollout_batch_threads'])} "
                      f"({r['rhs'][n]['rollout_batch_threads'] / r['rhs'][n]['rollout_batch_one_thread']:.2f}×)"
                      for n in sizes if r["rhs"][n].get("rollout_batch_threads")) + ".",
                  "", f"Issue #21 target, time per right-hand side of the 20-link spatial chain inside a run no more "
                  f"than `pinocchio.aba` per call: in the integration loop **{'met' if ratio <= 1 else 'NOT met'}** "
                  f"({C.fmt_time(x['spacar_loop'])} against {C.fmt_time(x['pinocchio_aba'])}: {ratio:.2f}×); as the "
                  f"average over the {r['t_end']:g} s run, its fixed costs included, "
                  f"**{'met' if x['spacar_in_run'] <= x['pinocchio_aba'] else 'NOT met'}** "
                  f"({C.fmt_time(x['spacar_in_run'])}, {x['spacar_in_run'] / x['pinocchio_aba']:.2f}×); over the 10× "
                  f"longer run {C.fmt_time(x['spacar_in_long_run'])} ({x['spacar_in_long_run'] / x['pinocchio_aba']:.2f}×). "
                  "The slope rests on two best-of timings and moves with the machine's load."]
    lines += ["", "Time to accuracy (error: largest joint-angle error at T against Pinocchio's ABA integrated by "
              "DOP853 at rtol 1e-13; time: the shortest run that reached it, best of repeats as above; spacar, "
              "exudyn and Pinocchio + DOP853 at the tolerances " + ", ".join(f"{t:g}" for t in SPATIAL_TOLS) +
              " (half decades); MuJoCo: its RK4 at fixed steps from " + f"{MUJOCO_STEPS[0]:g} s down to "
              f"{MUJOCO_STEPS[-1]:g} s in ratios of 10^(1/8) (its error, ∝ h⁴, in half decades as well), a Python "
              "loop of `mj_step`):", "",
              "| N | target | spacar `simulate` | spacar `Rollout` | spacar general path | exudyn tree DOPRI5 | "
              "MuJoCo RK4 | Pinocchio ABA + DOP853 | exudyn / spacar | MuJoCo / spacar | MuJoCo / Rollout | "
              "general path / spacar |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    verdicts, rollout_verdicts = [], []
    for n in sizes:
        for target in TARGETS:
            t = {k: C.time_to_accuracy([(e, w) for e, w, _ in v], target) for k, v in r["acc"][n].items()}
            mj, roll = t.get("MuJoCo RK4"), t.get("spacar Rollout")
            lines.append(f"| {n} | {target:.0e} | {C.fmt_time(t['spacar'])} | {C.fmt_time(roll)} | "
                         f"{C.fmt_time(t['spacar general path'])} | "
                         f"{C.fmt_time(t['exudyn tree DOPRI5'])} | {C.fmt_time(mj)} | "
                         f"{C.fmt_time(t['Pinocchio ABA + DOP853'])} | "
                         f"{C.fmt_ratio(t['exudyn tree DOPRI5'], t['spacar'])} | {C.fmt_ratio(mj, t['spacar'])} | "
                         f"{C.fmt_ratio(mj, roll)} | {C.fmt_ratio(t['spacar general path'], t['spacar'])} |")
            for peer in (t["exudyn tree DOPRI5"], mj):
                if peer is not None and t["spacar"] is not None:
                    verdicts.append(peer / t["spacar"])
                if peer is not None and roll is not None:
                    rollout_verdicts.append(peer / roll)
    if verdicts:
        lines += ["", f"Issue #21 target, time to accuracy better than MuJoCo and exudyn's kinematic tree on the "
                  f"6- and 20-link spatial chains: **{'met' if min(verdicts) > 1 else 'NOT met'}** (peer / spacar "
                  f"from {min(verdicts):.3g}× to {max(verdicts):.3g}× over the rows above where both reached the target)"
                  + (f"; with a `spacar.Rollout` made before the timing, as MuJoCo's model is compiled before its, "
                     f"**{'met' if min(rollout_verdicts) > 1 else 'NOT met'}** (peer / Rollout from "
                     f"{min(rollout_verdicts):.3g}× to {max(rollout_verdicts):.3g}×)" if rollout_verdicts else "") + "."]
    if 20 in r["stats"] and 1e-6 in r["stats"][20].get("spacar", {}):
        x = r["rhs"][20]
        rhs = r["stats"][20]["spacar"][1e-6][0]
        total = next(w for e, w, s in r["acc"][20]["spacar"] if s == 1e-6)
        lines += ["", f"Where spacar's time goes (N = 20, EPSINT = 1e-6): the run took {C.fmt_time(total)}; its C++ "
                  f"block {C.fmt_time(rhs * x['spacar_in_run'])} (best of repeats), of which the {rhs} recursive "
                  f"right-hand sides about {C.fmt_time(rhs * (x.get('spacar_loop') or x['spacar_in_long_run']))} "
                  "(at the integration loop's cost per right-hand side) and the rest the fixed costs: the assembly "
                  "from the X positions (Newton's method on all coordinates: the ground is turned), the recognition "
                  "of the tree and the two output times (positions and velocities by the general path, the "
                  "accelerations from the tree, the stresses from their equilibrium); outside the block, the "
                  "model's compilation and the Python results — fixed costs that MuJoCo's loop does not have."]
    lines += ["", "Runs (error at T, wall time) per program:", ""]
    for n in sizes:
        parts = [f"{k}: " + ", ".join(f"{s:g} → {C.fmt_err(e)} in {C.fmt_time(w)}" for e, w, s in v)
                 for k, v in r["acc"][n].items() if v]
        lines.append(f"* N = {n}: " + "; ".join(parts) + ".")
    return lines


def plot(r: dict) -> dict:
    sizes = r["sizes"]
    fig, ax = C.new_figure("Rigid planar chains: time per right-hand side")
    for key, label in (("spacar_in_run", "spacar (in a run)"), ("spacar_general_in_run", "spacar general path (in a run)"),
                       ("pinocchio_aba", "Pinocchio ABA (from Python)"),
                       ("exudyn_tree_rk44", "exudyn kinematic tree (RK44 stage)")):
        ax.loglog(sizes, [r["rhs"][n][key] for n in sizes], "o-", label=label)
    ax.set_xlabel("N links")
    ax.set_ylabel("seconds per right-hand side")
    ax.legend()
    out = {"time per right-hand side": C.save_figure(fig, "chains_rhs.png")}
    n = 20 if 20 in sizes else sizes[-1]
    fig, ax = C.new_figure(f"Rigid planar chain, N = {n}: work-precision")
    for k, v in r["acc"][n].items():
        if v:
            ax.loglog([w for _, w, _ in v], [max(e, 1e-16) for e, _, _ in v], "o-", label=k)
    ax.set_xlabel("wall time (s)")
    ax.set_ylabel(f"joint-angle error at T = {r['t_end']} s (rad)")
    ax.legend(fontsize=8)
    out[f"work-precision N = {n}"] = C.save_figure(fig, "chains_work_precision.png")
    return out


def main(argv=None) -> int:
    def extra(p):
        p.add_argument("--spatial-only", action="store_true",
                       help="measure the spatial chains only; the planar results from benchmarks/results/chains.json")

    return C.standard_main("chains", __doc__, lambda a: run_spatial_only(a.quick) if a.spatial_only else run(a.quick),
                           section, plot, argv, extra_args=extra)


if __name__ == "__main__":
    sys.exit(main())

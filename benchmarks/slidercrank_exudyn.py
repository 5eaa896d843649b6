"""Benchmark: the SPACAR95 manual's flexible slider-crank (manual §5.7), spacar against exudyn's
ANCF cable model of it (spacar.compare.exudyn), side by side in one process.

The two programs discretise the connecting rod differently (PLBEAM with a rigid elongation and
co-rotational bending deformations against ANCF cables with a penalty axial stiffness; see
docs/comparison.md), so each is measured against its own tight reference: spacar at EPSINT =
EPSIND = 1e-12, exudyn's generalized-α at h = 1e-5. Error = largest position error of the rod's
middle node 6 and the slider node 8 at t = 5 s (m). The difference between the two references is
reported as the model difference.

    python benchmarks/slidercrank_exudyn.py [--quick] [--no-write] [--no-plot] [--from-results]
"""
from __future__ import annotations

import sys

import numpy as np

import _common as C
from spacar.compare import models

TITLE = "Manual slider-crank: spacar, exudyn (ANCF)"
T_END, QUICK_T_END = 5.0, 0.2
TOLS, QUICK_TOLS = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10], [1e-3]
STEPS, QUICK_STEPS = [2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5], [1e-3]
REF_STEP, QUICK_REF_STEP = 1e-5, 1e-4
TARGETS = [1e-4, 1e-6, 1e-8]


def model(t_end, eps):
    return models.slider_crank(2, t_end=t_end, n_out=1, eps=eps, epskin=min(1e-5, max(1e-13, 1e-3 * eps)))


def positions(x, labels):
    return x[[labels.index(k) for k in ((6, 1), (6, 2), (8, 1))]]


def spacar_run(t_end, eps, repeat=3):
    res, best = C.simulate_best(model(t_end, eps), repeat)
    return positions(res.x[-1], res.coordinate_labels), best, res.stats


def run(quick: bool = False) -> dict:
    from spacar import _core
    from spacar.compare import exudyn as sx

    C.quiet_exudyn()
    t_end = QUICK_T_END if quick else T_END
    tols = QUICK_TOLS if quick else TOLS
    steps = QUICK_STEPS if quick else STEPS
    ref_sp, _, _ = spacar_run(t_end, 1e-12, repeat=1)
    em = sx.build(model(t_end, 1e-3))
    er = em.solve(t_end=t_end, n_out=1, step=QUICK_REF_STEP if quick else REF_STEP)
    ref_ex = positions(er.x[-1], em.labels)
    acc = {"spacar": [], "exudyn generalized-α": []}
    for eps in tols:
        x, wall, _ = spacar_run(t_end, eps)
        acc["spacar"].append((float(np.abs(x - ref_sp).max()), wall, eps))
        C.log(f"slider-crank spacar eps={eps:g}: err {acc['spacar'][-1][0]:.2e} in {wall:.4f} s")
    for h in steps:
        wall, er = C.best_time(lambda: em.solve(t_end=t_end, n_out=1, step=h), repeat=3, budget=2.0)
        acc["exudyn generalized-α"].append((float(np.abs(positions(er.x[-1], em.labels) - ref_ex).max()), wall, h))
        C.log(f"slider-crank exudyn h={h:g}: err {acc['exudyn generalized-α'][-1][0]:.2e} in {wall:.4f} s")
    m = model(1.0, 1e-3)
    m.prepare()
    sim = _core.Simulation(m._core)
    sim.assemble()
    q0, qd0 = np.array(sim.system.q0), np.array(sim.system.qd0)
    t_eval = C.per_call(lambda: sim.evaluate(0.0, q0, qd0), min_time=0.1 if quick else 0.5)
    t_run, _ = C.in_run_per_rhs(model(t_end, tols[0]), min_time=0.1 if quick else 0.5)
    n = 100 if quick else 2000
    wall, _ = C.best_time(lambda: em.solve(t_end=n * 1e-4, n_out=1, step=1e-4), repeat=3)
    return {"quick": quick, "t_end": t_end, "machine": C.machine(peers=True), "acc": acc,
            "model_difference": float(np.abs(ref_sp - ref_ex).max()),
            "spacar_evaluate": t_eval, "spacar_in_run": t_run,
            "spacar_manual_run": acc["spacar"][0][1], "exudyn_ga_step": wall / n}


def section(r: dict, plots: dict | None = None) -> str:
    lines = [f"## {TITLE}", "",
             f"`python benchmarks/slidercrank_exudyn.py{' --quick' if r['quick'] else ''}` (or `benchmarks/run_all.py`): "
             f"the manual's slider-crank (`examples/slidercrank.dat`), T = {r['t_end']} s; exudyn: the model built by "
             "`spacar.compare.exudyn` (rigid crank driven at 1.5 rad/s by a velocity constraint, two ANCF cable "
             "elements, slider constraint and mass), generalized-α with fixed steps. Each program against its own "
             "tight reference (spacar EPSINT = EPSIND = 1e-12; exudyn h = 1e-5); error: largest position error of the "
             "nodes 6 and 8 at T (m).", "", *C.machine_table(r["machine"]), "",
             "| figure | value |", "|---|---|",
             f"| spacar, the manual's settings (EPSINT = EPSIND = 1e-3), whole run | {C.fmt_time(r['spacar_manual_run'])} |",
             f"| spacar time per right-hand side in that run | {C.fmt_time(r['spacar_in_run'])} |",
             f"| spacar `evaluate()` from Python | {C.fmt_time(r['spacar_evaluate'])} |",
             f"| exudyn generalized-α, time per step (h = 1e-4) | {C.fmt_time(r['exudyn_ga_step'])} |",
             f"| model difference: spacar reference − exudyn reference (m) | {C.fmt_err(r['model_difference'])} |",
             "", "| target | spacar | exudyn generalized-α | exudyn / spacar |", "|---|---|---|---|"]
    for target in TARGETS:
        t = {k: C.time_to_accuracy([(e, w) for e, w, _ in v], target) for k, v in r["acc"].items()}
        lines.append(f"| {target:.0e} | {C.fmt_time(t['spacar'])} | {C.fmt_time(t['exudyn generalized-α'])} | "
                     f"{C.fmt_ratio(t['exudyn generalized-α'], t['spacar'])} |")
    lines += ["", "Runs (setting → error at T, wall time):", ""]
    for k, v in r["acc"].items():
        lines.append(f"* {k}: " + ", ".join(f"{s:g} → {C.fmt_err(e)} in {C.fmt_time(w)}" for e, w, s in v) + ".")
    if plots:
        lines += [""] + [f"![{k}]({v})" for k, v in plots.items()]
    return "\n".join(lines) + "\n"


def plot(r: dict) -> dict:
    fig, ax = C.new_figure("Manual slider-crank: work-precision (each against its own reference)")
    for k, v in r["acc"].items():
        ax.loglog([w for _, w, _ in v], [max(e, 1e-16) for e, _, _ in v], "o-", label=k)
    ax.axhline(r["model_difference"], color="k", ls="--", lw=0.8, label="spacar − exudyn (model difference)")
    ax.set_xlabel("wall time (s)")
    ax.set_ylabel(f"position error at T = {r['t_end']} s (m)")
    ax.legend(fontsize=8)
    return {"slider-crank work-precision": C.save_figure(fig, "slidercrank_work_precision.png")}


def main(argv=None) -> int:
    return C.standard_main("slidercrank_exudyn", __doc__, lambda a: run(a.quick), section, plot, argv)


if __name__ == "__main__":
    sys.exit(main())

"""Benchmark: a flexible cantilever of n = 10 … 1000 beam elements — how the cost of a
right-hand side grows with the model size, spacar against exudyn's ANCF cable elements.

Model (spacar.compare.models.cantilever): n PLBEAM elements, clamped, axially rigid, bending
deformations DYNE (2n DOFs, 3(n+1) nodal coordinates), EI = 25, ρA = 1, L = 1, under gravity.
exudyn: n ``ObjectANCFCable2D`` elements (4(n+1) coordinates, clamped by coordinate
constraints, which its explicit solvers eliminate) with EA = 1e4 EI/L² (slenderness L/r = 100;
the converter's default penalty, 1e4 EI/l0² per element, makes exudyn's Newton iteration stall
for fine meshes), exudyn's sparse solver above 200 coordinates.

* spacar: one right-hand side of the integration as the integrator does it
  (``Simulation.solve_state`` at the initial state, called from Python: positions, velocities,
  the sparse equations of motion), and for comparison ``Simulation.evaluate``, which adds the
  dense transfer functions DF and the reduced mass matrix M̄ (for users and the linearization);
* exudyn: fixed-step RK44 (explicit: a residual and a solve with the constant, factorised mass
  matrix per stage), wall time / (4 · steps), and implicit generalized-α (sparse solver above
  200 coordinates), wall time per step;
* growth: log-log fit t ∝ nᵖ from the smallest to the largest n.

A full simulation is not timed at large n: the beam's highest eigenfrequency grows as n², so any
explicit integrator (spacar's DOP853 included) needs O(n²) steps; the issue's target is about the
cost per evaluation, which this script measures.

    python benchmarks/cantilever.py [--quick] [--no-write] [--no-plot] [--from-results] [--sizes 10 20 ...]
"""
from __future__ import annotations

import sys
import time

import numpy as np

import _common as C
from spacar.compare import models

TITLE = "Flexible cantilever, 10 to 1000 elements: cost growth"
SIZES, QUICK_SIZES = [10, 20, 50, 100, 200, 500, 1000], [4, 8]
EVAL_BUDGET = 25.0   # s of spacar evaluations per size (at least 2 evaluations)


def _best(call, budget):
    start = time.perf_counter()
    call()
    first = time.perf_counter() - start
    k = max(2, min(200, int(budget / max(first, 1e-6))))
    best = first
    for _ in range(k - 1):
        start = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - start)
    return best, k


def spacar_evaluate(n, quick):
    from spacar import _core

    m = models.cantilever(n)
    m.prepare()
    start = time.perf_counter()
    sim = _core.Simulation(m._core)
    sim.assemble()
    t_assemble = time.perf_counter() - start
    q0, qd0 = np.array(sim.system.q0), np.array(sim.system.qd0)
    budget = 0.3 if quick else EVAL_BUDGET
    rhs, k = _best(lambda: sim.solve_state(0.0, q0, qd0), budget / 2)
    newton = sim.data.newton_iterations
    full = _best(lambda: sim.evaluate(0.0, q0, qd0), budget / 2)[0] if n <= 500 or quick else float("nan")
    return {"rhs": rhs, "evaluate": full, "assemble": t_assemble, "evaluations": k, "newton": newton,
            "nx": sim.system.nx, "ndof": sim.system.n_dof}


def exudyn_costs(n, quick):
    import exudyn as exu
    from spacar.compare import exudyn as sx

    em = sx.build(models.cantilever(n), formulation="redundant", axial_stiffness=1e4 * 25.0)
    nc = len(em.mbs.systemData.GetODE2Coordinates())
    steps = 10 if quick else max(5, min(200, int(20000 / n)))
    h = 1e-7
    st = em.settings(0.0, steps * h, "rk44", None, None, h)
    wall, _ = C.best_time(lambda: em.mbs.SolveDynamic(st, solverType=exu.DynamicSolverType.RK44), repeat=3)
    rk = wall / (4 * steps)
    ga_steps = 5 if quick else max(5, min(100, int(5000 / n)))
    st = em.settings(0.0, ga_steps * 1e-4, "generalized_alpha", None, None, 1e-4)
    # exudyn's default Newton tolerance (1e-8 relative) stalls at round-off for fine meshes
    st.timeIntegration.newton.relativeTolerance = 1e-6
    wall, _ = C.best_time(lambda: em.mbs.SolveDynamic(st, solverType=exu.DynamicSolverType.GeneralizedAlpha), repeat=3)
    return {"rk44_stage": rk, "ga_step": wall / ga_steps, "coordinates": nc}


def run(quick: bool = False, sizes=None) -> dict:
    C.quiet_exudyn()
    sizes = sizes or (QUICK_SIZES if quick else SIZES)
    out = {"quick": quick, "sizes": sizes, "machine": C.machine(peers=True), "spacar": {}, "exudyn": {}}
    for n in sizes:
        out["spacar"][n] = spacar_evaluate(n, quick)
        out["exudyn"][n] = exudyn_costs(n, quick)
        C.log(f"cantilever n={n}: spacar {out['spacar'][n]['rhs']:.3e} s/rhs, {out['spacar'][n]['evaluate']:.3e} s/evaluate, "
              f"exudyn RK44 {out['exudyn'][n]['rk44_stage']:.3e} s/stage, GA {out['exudyn'][n]['ga_step']:.3e} s/step")
    return out


def section(r: dict, plots: dict | None = None) -> str:
    sizes = r["sizes"]
    sp = [r["spacar"][n]["rhs"] for n in sizes]
    full = [(n, r["spacar"][n]["evaluate"]) for n in sizes if np.isfinite(r["spacar"][n]["evaluate"])]
    p_full = C.fit_exponent([n for n, _ in full], [t for _, t in full])
    rk = [r["exudyn"][n]["rk44_stage"] for n in sizes]
    ga = [r["exudyn"][n]["ga_step"] for n in sizes]
    p_sp, p_rk, p_ga = C.fit_exponent(sizes, sp), C.fit_exponent(sizes, rk), C.fit_exponent(sizes, ga)
    lines = [f"## {TITLE}", "",
             f"`python benchmarks/cantilever.py{' --quick' if r['quick'] else ''}` (or `benchmarks/run_all.py`): "
             "n PLBEAM elements, clamped, axially rigid, bending DYNE (2n DOFs), EI = 25, ρA = 1, L = 1, gravity; "
             "exudyn: n ANCF cable elements (EA = 1e4 EI/L², sparse solver above 200 coordinates). spacar: best of repeated right-hand sides of the integration (`Simulation.solve_state` at the initial state) and, for comparison, of `Simulation.evaluate` (which adds the dense transfer functions and M̄); "
             "exudyn: fixed-step RK44, wall time per stage (one right-hand side), and generalized-α (Newton tolerance 1e-6 relative: exudyn's default 1e-8 stalls at round-off above ~100 elements), wall time per step.",
             "", *C.machine_table(r["machine"]), "",
             "| n | spacar coordinates / DOFs | spacar per right-hand side | spacar `evaluate()` with DF, M̄ | "
             "exudyn coordinates | exudyn RK44 per stage | exudyn generalized-α per step | spacar / exudyn stage |",
             "|---|---|---|---|---|---|---|---|"]
    for n in sizes:
        s, e = r["spacar"][n], r["exudyn"][n]
        ev = C.fmt_time(s['evaluate']) if np.isfinite(s['evaluate']) else "not timed"
        lines.append(f"| {n} | {s['nx']} / {s['ndof']} | {C.fmt_time(s['rhs'])} | {ev} | {e['coordinates']} | "
                     f"{C.fmt_time(e['rk44_stage'])} | {C.fmt_time(e['ga_step'])} | {s['rhs'] / e['rk44_stage']:.3g}× |")
    lines += ["", f"Growth from n = {sizes[0]} to {sizes[-1]} (log-log fit t ∝ nᵖ): spacar right-hand side p = {p_sp:.2f} "
              f"(`evaluate()` with the dense transfer functions: p = {p_full:.2f}); "
              f"exudyn RK44 stage p = {p_rk:.2f}, generalized-α step p = {p_ga:.2f}.", "",
              f"Issue #8 target, cost growth with the number of beam elements no worse than about O(n^1.2) from 10 to "
              f"1000 elements: **{'met' if p_sp <= 1.25 else 'NOT met'}** (spacar p = {p_sp:.2f} per right-hand side: "
              "sparse constraint blocks and sparse equations of motion, docs/architecture.md). The dense transfer "
              "functions DF and M̄ of `evaluate()` grow with the cube of the DOFs; they are computed only on request."]
    if plots:
        lines += [""] + [f"![{k}]({v})" for k, v in plots.items()]
    return "\n".join(lines) + "\n"


def plot(r: dict) -> dict:
    sizes = r["sizes"]
    fig, ax = C.new_figure("Flexible cantilever: cost per right-hand side")
    ax.loglog(sizes, [r["spacar"][n]["rhs"] for n in sizes], "o-", label="spacar right-hand side")
    full = [(n, r["spacar"][n]["evaluate"]) for n in sizes if np.isfinite(r["spacar"][n]["evaluate"])]
    ax.loglog([n for n, _ in full], [t for _, t in full], "o:", color="0.5", label="spacar evaluate() (with DF, M̄)")
    ax.loglog(sizes, [r["exudyn"][n]["rk44_stage"] for n in sizes], "s-", label="exudyn ANCF, RK44 stage")
    ax.loglog(sizes, [r["exudyn"][n]["ga_step"] for n in sizes], "^-", label="exudyn ANCF, generalized-α step")
    n0, t0 = sizes[0], r["spacar"][sizes[0]]["rhs"]
    ax.loglog(sizes, [t0 * (n / n0) ** 1.2 for n in sizes], "k--", lw=0.8, label="n^1.2 (issue #8 target)")
    ax.set_xlabel("beam elements n")
    ax.set_ylabel("seconds")
    ax.legend(fontsize=8)
    return {"cantilever cost growth": C.save_figure(fig, "cantilever_rhs.png")}


def main(argv=None) -> int:
    def extra(p):
        p.add_argument("--sizes", type=int, nargs="*", help="element counts (default 10 … 1000)")

    return C.standard_main("cantilever", __doc__, lambda a: run(a.quick, a.sizes), section, plot, argv, extra)


if __name__ == "__main__":
    sys.exit(main())

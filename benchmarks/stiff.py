"""Benchmark: the steel cantilever of docs/stiff-integration.md — spacar's DOP853, Radau IIA and
automatic choice over a range of EPSINT, against exudyn's generalized-α on ANCF cable elements
over a range of step sizes: tip accuracy at t = 0.2 s against wall time; then (stiff_scaling.py)
step counts and time to a tip accuracy for the slider-crank with its rod's EI × 1 … 10⁴ and the
cantilever with 4 … 32 elements, against exudyn's generalized-α and trapezoidal rule.

Model (spacar.compare.models.cantilever): 8 PLBEAMs, 1 m, clamped, axially rigid, bending DYNE
(16 DOFs), EI = 175 N m², ρA = 0.785 kg/m (steel, 10 × 10 mm), released from the straight state
under gravity, 0.2 s in one output interval; undamped and with stiffness-proportional damping
EDAMPP = 0.001·EI. EPSINT = EPSIND = EPS.

exudyn: 8 ``ObjectANCFCable2D`` elements of the same length, EI, ρA and gravity, with the axial
stiffness EA = 1e4 EI/L² (as benchmarks/cantilever.py; spacar's beam is axially rigid),
generalized-α (exudyn's default spectral radius) with fixed steps; undamped only (the converter
does not carry EDAMPP over).

Error: |tip y(0.2 s) − reference|. spacar's reference is its Radau solution at EPS = 1e-11;
exudyn's ANCF discretization differs from spacar's PLBEAMs (cubic interpolation of positions
against the beam's exact deformation modes, finite EA), so exudyn's error is measured against its
own solution at its smallest step. Times: spacar — best wall time of ``spacar.simulate`` over
repeats (whole call, Python included); exudyn — best wall time of ``SolveDynamic``.

    python benchmarks/stiff.py [--quick] [--no-write] [--no-plot] [--from-results] [--scaling-case CASE]
"""
from __future__ import annotations

import sys
import time

import spacar
import _common as C
import stiff_scaling
from spacar.compare import models

TITLE = "Stiff integration: steel cantilever, time to tip accuracy"
EI, RHO_A, DAMPING = 175.0, 0.785, 1e-3
FULL = {"n": 8, "t_end": 0.2, "eps": [5e-1, 2e-1, 1e-1, 5e-2, 3e-2, 2e-2, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8], "ref_eps": 1e-11,
        "steps": [2e-3, 1e-3, 5e-4, 3e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6]}
QUICK = {"n": 2, "t_end": 0.02, "eps": [1e-2, 1e-4], "ref_eps": 1e-8, "steps": [1e-3, 5e-4, 2.5e-4]}
TARGETS = [1e-4, 1e-6]
METHODS = ["dop853", "radau5", "auto"]
RUN_BUDGET = 3.0  # s: a method stops tightening once one run took longer (then it is run once only)


def cantilever(n, t_end, eps, damped):
    m = models.cantilever(n, ei=EI, rho_a=RHO_A, t_end=t_end, n_out=1, eps=eps)
    if damped:
        for i in range(1, n + 1):
            m.edampp(i, 0.0, DAMPING * EI)
    return m


def tip_y(res, n):
    return float(res.node(n + 1).x[-1, 1])


def spacar_runs(cfg, damped, method, ref, quick):
    out = []
    for eps in cfg["eps"]:
        # Best of 3; a run longer than RUN_BUDGET is made once (two would exceed the budget).
        res, wall = C.simulate_best(cantilever(cfg["n"], cfg["t_end"], eps, damped), repeat=3,
                                    budget=2 * RUN_BUDGET if not quick else 0.2, method=method, progress=False)
        st = res.stats
        out.append({"eps": eps, "wall": wall, "error": abs(tip_y(res, cfg["n"]) - ref), "steps": st["steps"],
                    "rhs": st["rhs_evaluations"], "method": st.get("method", method),
                    "switches": len(st.get("switches", []))})
        C.log(f"stiff {'damped' if damped else 'undamped'} {method} eps={eps:g}: {wall:.3g} s, "
              f"error {out[-1]['error']:.2e}, {st['steps']} steps")
        if wall >= RUN_BUDGET:
            break
    return out


def exudyn_runs(cfg, quick):
    from spacar.compare import exudyn as sx

    em = sx.build(cantilever(cfg["n"], cfg["t_end"], 1e-6, False), axial_stiffness=1e4 * EI)
    runs = []
    for h in cfg["steps"]:
        best, y = float("inf"), None
        for _ in range(1 if quick else 3):
            r = em.solve(t_end=cfg["t_end"], n_out=1, solver="generalized_alpha", step=h)
            best, y = min(best, r.stats["wall_time"]), float(r.coordinate(cfg["n"] + 1, 2)[-1])
        runs.append({"step": h, "wall": best, "tip_y": y})
        C.log(f"stiff exudyn GA h={h:g}: {best:.3g} s, tip y {y:.9f}")
    ref = runs[-1]["tip_y"]
    for r in runs:
        r["error"] = abs(r["tip_y"] - ref)
    return runs[:-1], ref


def run(a) -> dict:
    C.quiet_exudyn()
    quick = a.quick
    if a.scaling_case:   # one case of the scaling tables, merged into the last full run's results
        r = C.load_results("stiff")
        cfg = stiff_scaling.QUICK if quick else stiff_scaling.FULL
        r["scaling"][a.scaling_case] = stiff_scaling.run_case(a.scaling_case, quick)
        r["scaling"]["config"][a.scaling_case] = cfg[a.scaling_case]
        r["scaling"].setdefault("measured_apart", {})[a.scaling_case] = dict(C.machine(peers=True),
                                                                          date=time.strftime("%Y-%m-%d %H:%M"),
                                                                          eps=list(cfg["eps"]))
        r["quick"] = quick
        return r
    cfg = QUICK if quick else FULL
    out = {"quick": quick, "config": cfg, "machine": C.machine(peers=True), "spacar": {}, "reference": {}}
    for damped in (False, True):
        key = "damped" if damped else "undamped"
        start = time.perf_counter()
        ref_res = spacar.simulate(cantilever(cfg["n"], cfg["t_end"], cfg["ref_eps"], damped), method="radau5",
                                  progress=False)
        ref = tip_y(ref_res, cfg["n"])
        out["reference"][key] = {"tip_y": ref, "wall": time.perf_counter() - start}
        C.log(f"stiff {key} reference tip y {ref:.12f} ({out['reference'][key]['wall']:.2f} s)")
        out["spacar"][key] = {m: spacar_runs(cfg, damped, m, ref, quick) for m in METHODS}
    out["exudyn"], out["exudyn_reference"] = exudyn_runs(cfg, quick)
    spacar_ref = out["reference"]["undamped"]["tip_y"]
    out["exudyn_vs_spacar"] = abs(out["exudyn_reference"] - spacar_ref)
    for x in out["exudyn"]:
        x["error_vs_spacar"] = abs(x["tip_y"] - spacar_ref)
    out["scaling"] = stiff_scaling.run(quick)
    return out


def _points(runs):
    return [(r["error"], r["wall"]) for r in runs]


def _steady_time(runs, target):
    """Smallest wall time among the runs from which on every tighter setting of the series
    (runs ordered loose to tight) reaches the target; None if the tightest does not."""
    best = None
    for r in reversed(runs):
        if r["error"] > target:
            break
        best = r["wall"] if best is None else min(best, r["wall"])
    return best


def section(r: dict, plots: dict | None = None) -> str:
    cfg = r["config"]
    lines = [f"## {TITLE}", "",
             f"`python benchmarks/stiff.py{' --quick' if r['quick'] else ''}` (or `benchmarks/run_all.py`): "
             f"the steel cantilever of [stiff integration](stiff-integration.md), {cfg['n']} PLBEAMs, 1 m, "
             f"EI = {EI:g} N m², ρA = {RHO_A} kg/m, axially rigid, released under gravity, {cfg['t_end']} s in one "
             f"output interval; undamped and with EDAMPP = {DAMPING:g}·EI. spacar: `method=` dop853, radau5, auto at "
             "EPSINT = EPSIND = EPS; best wall time of `spacar.simulate` over repeats (a run longer than "
             f"{RUN_BUDGET:g} s is run once and ends that method's series). exudyn: {cfg['n']} ANCFCable2D elements, "
             "same length, EI, ρA and gravity, axial stiffness EA = 1e4 EI/L² (spacar's beam is axially rigid), "
             "generalized-α (default spectral radius) with fixed steps, best wall time of `SolveDynamic`; "
             "undamped only.", "",
             f"Tip error: |tip y(t = {cfg['t_end']} s) − reference|. spacar's reference: radau5 at EPS = "
             f"{cfg['ref_eps']:g}. The ANCF and PLBEAM discretizations differ (their converged tip deflections "
             f"differ by {r['exudyn_vs_spacar']:.1e} m), so exudyn's error is measured against its own solution "
             f"at its smallest step, h = {cfg['steps'][-1]:g} s.", "",
             *C.machine_table(r["machine"]), ""]
    for key in ("undamped", "damped"):
        sp = r["spacar"][key]
        lines += [f"**{key.capitalize()}{' (EDAMPP 0.001·EI)' if key == 'damped' else ''}**, spacar: "
                  "wall time / tip error [m] / steps", "",
                  "| EPS | " + " | ".join(METHODS) + " |", "|---" * (len(METHODS) + 1) + "|"]
        for eps in cfg["eps"]:
            cells = []
            for m in METHODS:
                run_ = next((x for x in sp[m] if x["eps"] == eps), None)
                cells.append("skipped (budget)" if run_ is None else
                             f"{C.fmt_time(run_['wall'])} / {C.fmt_err(run_['error'])} / {run_['steps']}"
                             + (f" ({run_['method']})" if m == "auto" else ""))
            lines.append(f"| {eps:g} | " + " | ".join(cells) + " |")
        lines.append("")
    lines += ["**exudyn generalized-α, undamped**: wall time / tip error [m] (against h = "
              f"{cfg['steps'][-1]:g} s)", "", "| h [s] | steps | wall | tip error | (error against spacar's reference) |", "|---|---|---|---|---|"]
    for x in r["exudyn"]:
        lines.append(f"| {x['step']:g} | {round(cfg['t_end'] / x['step'])} | {C.fmt_time(x['wall'])} | "
                     f"{C.fmt_err(x['error'])} | ({C.fmt_err(x['error_vs_spacar'])}) |")
    lines += ["", "The errors at a single time are not monotone in EPS or h (the tip's vibration can cancel or add "
              "at t = 0.2 s), for both programs: a loose setting can land closer than a tighter one. Hence two "
              "measures of the time to a tip accuracy: *any run*, the smallest wall time among the runs whose error "
              "is at most the target (it may rest on one lucky setting), and *steady*, the smallest wall time among "
              "the runs from which every tighter setting of the series also reaches the target.", ""]
    ex = r["exudyn"]
    for label, measure in (("any run", lambda runs, tg: C.time_to_accuracy(_points(runs), tg)),
                           ("steady", _steady_time)):
        lines += [f"**Time to tip accuracy, {label}:**", "",
                  "| case | target [m] | dop853 | radau5 | auto | exudyn GA | dop853 / best spacar | exudyn / best spacar |",
                  "|---|---|---|---|---|---|---|---|"]
        for key in ("undamped", "damped"):
            sp = r["spacar"][key]
            for target in TARGETS:
                t = {m: measure(sp[m], target) for m in METHODS}
                best = min((v for v in (t["radau5"], t["auto"]) if v is not None), default=None)
                te = measure(ex, target) if key == "undamped" else None
                lines.append(f"| {key} | {target:g} | {C.fmt_time(t['dop853'])} | {C.fmt_time(t['radau5'])} | "
                             f"{C.fmt_time(t['auto'])} | {C.fmt_time(te) if key == 'undamped' else 'not run'} | "
                             f"{C.fmt_ratio(t['dop853'], best)} | {C.fmt_ratio(te, best)} |")
        lines.append("")
    lines += ["\"best spacar\": the faster of radau5 and auto. A dash: no run of the series reached the target "
              "(or, for a ratio, one side did not). The damped DOP853 series is a single run (its step count, "
              "about 10⁵, is set by stability, not by EPS)."]
    if plots:
        lines += [""] + [f"![{k}]({v})" for k, v in plots.items()]
    if "scaling" in r:
        lines += ["", *stiff_scaling.section_lines(r["scaling"])]
    return "\n".join(lines) + "\n"


def plot(r: dict) -> dict:
    out = {}
    for key in ("undamped", "damped"):
        fig, ax = C.new_figure(f"Steel cantilever, {key}: tip error against wall time")
        for m, mark in zip(METHODS, "os^"):
            pts = r["spacar"][key][m]
            ax.loglog([p["wall"] for p in pts], [max(p["error"], 1e-14) for p in pts], mark + "-", label=f"spacar {m}")
        if key == "undamped":
            ax.loglog([p["wall"] for p in r["exudyn"]], [max(p["error"], 1e-14) for p in r["exudyn"]], "d-",
                      label="exudyn generalized-α (own reference)")
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("tip error at t = 0.2 s [m]")
        ax.legend(fontsize=8)
        out[f"steel cantilever {key}"] = C.save_figure(fig, f"stiff_{key}.png")
    return out


def main(argv=None) -> int:
    def extra(p):
        p.add_argument("--scaling-case", choices=stiff_scaling.CASES,
                       help="measure only this case of the step-count tables (stiff_scaling.py) and merge it into "
                            "benchmarks/results/stiff.json")
    return C.standard_main("stiff", __doc__, run, section, plot, argv, extra_args=extra)


if __name__ == "__main__":
    sys.exit(main())

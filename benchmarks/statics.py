"""Benchmark: the static solve of a large-deflection cantilever (the elastica P L²/EI = 3 of
docs/statics.md) — spacar.static against exudyn's SolveStatic, wall time and tip accuracy.

Model: a cantilever of length 1 clamped along x, EI = 1, a dead tip load P = 3 along y (the tip
turns by 66°). spacar: n PLBEAMs, axially rigid, bending DYNE, ``spacar.static`` in a number of
load steps (the whole call, Python included, model copied outside the timing). exudyn: n
``ObjectBeamGeometricallyExact2D`` elements (spacar.compare.exudyn_static: EA = 1e4 EI/l² of an
element, shear stiffness 100 EA), ``SolveStatic`` with the same number of load steps, full
Newton (the wall time of SolveStatic alone; building the model is not timed). Both start from
the straight beam. Error: the tip's distance from the elastica (a shooting solution at rtol
1e-12) over the length.

    python benchmarks/statics.py [--quick] [--no-write] [--no-plot] [--from-results]
"""
from __future__ import annotations

import sys

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import spacar
import _common as C

TITLE = "Static analysis: large-deflection cantilever, spacar.static and exudyn SolveStatic"
ALPHA = 3.0
FULL = {"sizes": [8, 16, 32, 64, 128], "steps": [1, 2, 5, 10]}
QUICK = {"sizes": [4, 8], "steps": [2]}
TARGETS = [1e-3, 1e-4]


def elastica_tip(alpha):
    """Tip (x, y) of the inextensible elastica: θ'' = −alpha cos θ, θ(0) = 0, θ'(1) = 0."""
    def shoot(k0):
        rhs = lambda s, y: [y[1], -alpha * np.cos(y[0]), np.cos(y[0]), np.sin(y[0])]  # noqa: E731
        return solve_ivp(rhs, (0.0, 1.0), [0.0, k0, 0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-14).y[:, -1]

    return shoot(brentq(lambda k: shoot(k)[1], 1e-9, alpha, xtol=1e-15))[2:]


def cantilever(n):
    m = spacar.Model()
    for k in range(1, n + 1):
        m.plbeam(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2)
        m.x(2 * k + 1, k / n, 0.0)
        m.estiff(k, 0.0, 1.0)
        m.dyne(k, 2, 3)
    m.fix(1)
    m.fix(2)
    m.force(2 * n + 1, 0.0, ALPHA)
    return m


def spacar_runs(n, steps, ref):
    model = cantilever(n)
    wall, res = C.best_time(lambda m: spacar.static(m, steps=steps), repeat=5, budget=2.0, min_time=0.2, setup=model.copy)
    tip = res.x[-1, -3:-1]
    return {"n": n, "steps": steps, "wall": wall, "error": float(np.linalg.norm(tip - ref)),
            "iterations": int(sum(res.stats["iterations"]))}


def exudyn_runs(n, steps, ref):
    from spacar.compare import exudyn_static

    walls, peer = [], None
    for _ in range(3):
        try:
            peer = exudyn_static.solve(cantilever(n), steps=steps, subdivide=1)
        except RuntimeError:
            return {"n": n, "steps": steps, "wall": None, "error": None}
        walls.append(peer.stats["wall"])
    tip = peer.node(2 * n + 1)
    return {"n": n, "steps": steps, "wall": min(walls), "error": float(np.linalg.norm(tip - ref))}


def run(a) -> dict:
    C.quiet_exudyn()
    cfg = QUICK if a.quick else FULL
    ref = elastica_tip(ALPHA)
    out = {"quick": a.quick, "cfg": cfg, "machine": C.machine(peers=True), "spacar": [], "exudyn": []}
    for n in cfg["sizes"]:
        for s in cfg["steps"]:
            out["spacar"].append(spacar_runs(n, s, ref))
            out["exudyn"].append(exudyn_runs(n, s, ref))
            C.log(f"n={n} steps={s}: spacar {out['spacar'][-1]['wall']:.3e} s, exudyn {out['exudyn'][-1]['wall']}")
    return out


def _best_to(runs, target):
    """The least wall time of a run whose error is at most target."""
    walls = [r["wall"] for r in runs if r["wall"] is not None and r["error"] <= target]
    return min(walls) if walls else None


def _fastest(runs, n):
    """The fastest converged run with n elements (any number of load steps)."""
    ok = [r for r in runs if r["n"] == n and r["wall"] is not None]
    return min(ok, key=lambda r: r["wall"]) if ok else None


def section(r: dict, plots: dict | None = None) -> str:
    cfg = r["cfg"]
    lines = [f"## {TITLE}", "",
             "`python benchmarks/statics.py` (or `benchmarks/run_all.py`): the cantilever of length 1, EI = 1, "
             f"under a dead tip load P L²/EI = {ALPHA:g} ([static analysis](statics.md)); spacar: n PLBEAMs, "
             "axially rigid, `spacar.static` (whole call, best of repeats); exudyn: n geometrically exact 2D beams "
             "(`spacar.compare.exudyn_static`, EA = 1e4 EI/l², shear 100 EA), `SolveStatic` (its wall time alone), "
             "full Newton, the same number of load steps, best of 3. Tip error: distance from the elastica over "
             "the length.", "", *C.machine_table(r["machine"]), "",
             "**Each mesh and number of load steps**: wall time / tip error (spacar's Newton iterations in all)", "",
             "| n | load steps | spacar | exudyn | exudyn / spacar |", "|---|---|---|---|---|"]
    for s, e in zip(r["spacar"], r["exudyn"]):
        ex = "did not converge" if e["wall"] is None else f"{C.fmt_time(e['wall'])} / {C.fmt_err(e['error'])}"
        lines.append(f"| {s['n']} | {s['steps']} | {C.fmt_time(s['wall'])} / {C.fmt_err(s['error'])} "
                     f"({s['iterations']}) | {ex} | {C.fmt_ratio(e['wall'], s['wall'])} |")
    lines += ["", "**Fastest solve per mesh** (the fewest load steps that converge):", "",
              "| n | spacar | exudyn | exudyn / spacar |", "|---|---|---|---|"]
    for n in cfg["sizes"]:
        s, e = _fastest(r["spacar"], n), _fastest(r["exudyn"], n)
        lines.append(f"| {n} | {C.fmt_time(s and s['wall'])} ({s and s['steps']} steps) | "
                     f"{C.fmt_time(e and e['wall'])} ({e and e['steps']} steps) | {C.fmt_ratio(e and e['wall'], s and s['wall'])} |")
    lines += ["", "**Time to a tip accuracy** (the least wall time of any mesh and step count reaching it):", "",
              "| target (/ L) | spacar | exudyn | exudyn / spacar |", "|---|---|---|---|"]
    for target in TARGETS:
        ts, te = _best_to(r["spacar"], target), _best_to(r["exudyn"], target)
        lines.append(f"| {target:g} | {C.fmt_time(ts)} | {C.fmt_time(te)} | {C.fmt_ratio(te, ts)} |")
    lines += ["", "Both discretizations converge as h² (spacar's co-rotational cubic beams, exudyn's linear "
              "Simo–Reissner beams); their constants differ, hence the time to accuracy as the fair measure."]
    if plots:
        lines += [""] + [f"![{k}]({v})" for k, v in plots.items()]
    return "\n".join(lines) + "\n"


def plot(r: dict) -> dict:
    fig, ax = C.new_figure(f"Elastica P L²/EI = {ALPHA:g}: tip error against wall time")
    for name, mark in (("spacar", "o"), ("exudyn", "d")):
        pts = [x for x in r[name] if x["wall"] is not None]
        ax.loglog([p["wall"] for p in pts], [p["error"] for p in pts], mark, label=name)
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("tip error / L")
    ax.legend(fontsize=8)
    return {"static cantilever": C.save_figure(fig, "static_cantilever.png")}


def main(argv=None) -> int:
    return C.standard_main("statics", __doc__, run, section, plot, argv)


if __name__ == "__main__":
    sys.exit(main())

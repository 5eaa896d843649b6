"""Benchmark: the static solve of a large-deflection cantilever (the elastica P L²/EI = 3 of
docs/statics.md) — spacar.static against exudyn's SolveStatic on two beam elements: wall time per
mesh, growth with the mesh, time to a tip accuracy, peak memory.

Model: a cantilever of length L = 1 clamped along x, EI = 1, a dead tip load P = 3 along y (the
tip turns by 56.5°), n = 16 … 2048 elements, each solver from the straight beam in the fewest
load steps that converge (one, for all three):

* spacar: n PLBEAMs, axially rigid, bending DYNE, ``spacar.static`` (the whole call, Python
  included; the model built and copied outside the timing); for the time to accuracy also n
  PLBEAMCs (the extension exact for constant curvature) the same way;
* exudyn, geometrically exact beam: n ``ObjectBeamGeometricallyExact2D`` (the model of
  spacar.compare.exudyn_static, EA = 1e4 EI/l², but shear stiffness GA = EA instead of its 100 EA,
  with which Newton needs adaptive load stepping);
* exudyn, ANCF cable: n ``ObjectANCFCable2D`` on ``NodePoint2DSlope1`` nodes, clamped by
  coordinate constraints on the root's x, y and slope y, EA = 1e4 EI/l² (benchmarks/_exudyn_ancf.py).

exudyn: ``SolveStatic`` alone is timed (models built and assembled outside), its sparse solver,
full Newton, adaptive load stepping, convergence on the Newton increment at 1e-8 (its default
residual test stops early with wrong tips at these axial stiffnesses; the probes table shows it).
Each exudyn answer is checked before it is timed: against a solve at tolerance 1e-10 and against
the elastica. Wall time: best of repeats. Tip error: the tip's distance from the inextensible
elastica (closed form in elliptic integrals, checked against a shooting solution to 1e-10) over
the length. Time to accuracy: the least mesh (bisection on n) that reaches the target, timed.
Memory: each solve in a fresh process, ``ru_maxrss`` after the imports, after the build, after the
solve; exudyn's module without range checks (``EXUDYN_MODULE=fast``) timed the same way.

    python benchmarks/statics.py [--quick] [--no-write] [--no-plot] [--from-results]
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

import spacar
import _common as C

TITLE = "Static analysis: large-deflection cantilever, spacar.static and exudyn SolveStatic"
ALPHA = 3.0
HERE = Path(__file__).resolve().parent
FULL = {"sizes": [16, 32, 64, 128, 256, 512, 1024, 2048], "targets": [1e-4, 1e-6], "memory": [512, 2048],
        "probe": 512, "fit_from": 64, "repeat": 7, "budget": 4.0, "min_time": 0.5, "max_n": 16384, "passes": 2}
QUICK = {"sizes": [4, 8], "targets": [1e-2, 1e-3], "memory": [8], "probe": 8, "fit_from": 4,
         "repeat": 3, "budget": 0.3, "min_time": 0.02, "max_n": 64, "passes": 1}
SOLVERS = ("spacar", "ge", "ancf")
ARC = "spacar_arc"                   # PLBEAMC: in the time to accuracy only
PREPARED = "spacar_solver"           # spacar.StaticSolver, set up outside the timing: in the meshes' table only
NAMES = {"spacar": "spacar PLBEAM", "ge": "exudyn GE beam", "ancf": "exudyn ANCF cable", ARC: "spacar PLBEAMC",
         PREPARED: "spacar StaticSolver"}
STEP_CHOICES = (1, 2, 5, 10, 20)   # load steps tried, the fewest first
TOL, TIGHT = 1e-8, 1e-10           # exudyn's Newton increment tolerance: timed, answer check
SANE = 0.05                        # a tip farther than this from the elastica (/ L) is no answer
DENSE_MAX = 200                    # exudyn coordinates up to which its dense solver is timed too


# --- the reference ------------------------------------------------------------------------

def elastica_tip_shooting(alpha):
    """Tip (x, y) of the inextensible elastica: θ'' = −alpha cos θ, θ(0) = 0, θ'(1) = 0."""
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq

    def shoot(k0):
        rhs = lambda s, y: [y[1], -alpha * np.cos(y[0]), np.cos(y[0]), np.sin(y[0])]  # noqa: E731
        return solve_ivp(rhs, (0.0, 1.0), [0.0, k0, 0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-14).y[:, -1]

    return shoot(brentq(lambda k: shoot(k)[1], 1e-9, alpha, xtol=1e-15))[2:]


def elastica_tip(alpha):
    """Tip (x, y) of the same elastica in closed form. With the first integral
    θ'²/2 = alpha (sin θ_L − sin θ) and 1 + sin θ = 2 k² sin²φ (k = sin(π/4 + θ_L/2)), ds =
    dφ / (√alpha √(1 − k² sin²φ)) from sin φ₁ = 1/(k√2) at the root to φ = π/2 at the tip:
    √alpha = K(k) − F(φ₁, k) fixes k; x = √(2 sin θ_L / alpha) with sin θ_L = 2k² − 1, and
    y = 1 − 2 (E(k) − E(φ₁, k)) / √alpha (scipy's parameter m = k²)."""
    from scipy.optimize import brentq
    from scipy.special import ellipe, ellipeinc, ellipk, ellipkinc

    phi1 = lambda m: np.arcsin(1.0 / np.sqrt(2.0 * m))  # noqa: E731
    m = brentq(lambda m: ellipk(m) - ellipkinc(phi1(m), m) - np.sqrt(alpha), 0.5, 1.0 - 1e-15,
               xtol=1e-16, rtol=4 * np.finfo(float).eps, maxiter=500)
    x = np.sqrt(2.0 * (2.0 * m - 1.0) / alpha)
    y = 1.0 - 2.0 * (ellipe(m) - ellipeinc(phi1(m), m)) / np.sqrt(alpha)
    return np.array([x, y])


# --- the solvers --------------------------------------------------------------------------

def cantilever(n, element="plbeam"):
    m = spacar.Model()
    for k in range(1, n + 1):
        getattr(m, element)(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2)
        m.x(2 * k + 1, k / n, 0.0)
        m.estiff(k, 0.0, 1.0)
        m.dyne(k, 2, 3)
    m.fix(1)
    m.fix(2)
    m.force(2 * n + 1, 0.0, ALPHA)
    return m


class SpacarRunner:
    """spacar.static on n PLBEAMs (or PLBEAMCs); ``solve`` copies the model outside the timing.
    PREPARED: a spacar.StaticSolver of the PLBEAM model, made once outside the timing (as exudyn's
    model is built and assembled once), called for each solve."""

    def __init__(self, n, kind="spacar"):
        self.n, self.kind = n, kind
        self.model = cantilever(n, "plbeamc" if kind == ARC else "plbeam")
        self.solver = spacar.StaticSolver(self.model) if kind == PREPARED else None

    def solve(self, steps, tolerance=None):
        m = self.model.copy() if self.solver is None else None
        start = time.perf_counter()
        try:
            res = spacar.static(m, steps=steps) if self.solver is None else self.solver(steps=steps)
        except spacar.StaticError:
            return {"ok": False, "tip": None, "iterations": None, "steps": None, "wall": None}
        wall = time.perf_counter() - start
        return {"ok": True, "tip": np.asarray(res.x[-1, -3:-1], dtype=float), "wall": wall,
                "iterations": int(sum(res.stats["iterations"])), "steps": len(res.stats["iterations"]),
                "cuts": int(res.stats.get("step_cuts", 0))}


class ExudynRunner:
    """exudyn's SolveStatic on a model of benchmarks/_exudyn_ancf.py, built once (the model
    starts from its initial state at each solve)."""

    def __init__(self, kind, n, **options):
        import _exudyn_ancf as X

        self.X, self.kind, self.n = X, kind, n
        self.case = (X.build_ge if kind == "ge" else X.build_ancf)(n, P=ALPHA, **options)

    def solve(self, steps, tolerance=TOL, **options):
        return self.X.solve(self.case, self.X.settings(steps, tolerance, **options))


def runner(kind, n):
    return SpacarRunner(n, kind) if _spacar(kind) else ExudynRunner(kind, n)


def _spacar(kind):
    return kind in ("spacar", ARC, PREPARED)


def _fewest_steps(run, ref):
    """The fewest load steps (of STEP_CHOICES) with which the solver converges to a checked
    answer: near the elastica (within SANE), and for exudyn the same tip as a solve at the tight
    tolerance TIGHT (within 5 % of its error + 1e-9 L). Returns (steps, out, gap) or Nones."""
    for steps in STEP_CHOICES:
        out = run.solve(steps)
        if not out["ok"] or np.linalg.norm(out["tip"] - ref) > SANE:
            continue
        gap = None
        if not _spacar(run.kind):
            tight = run.solve(steps, TIGHT, max_iterations=100)
            if tight["ok"]:
                gap = float(np.linalg.norm(out["tip"] - tight["tip"]))
                if gap > 0.05 * np.linalg.norm(tight["tip"] - ref) + 1e-9:
                    continue
        return steps, out, gap
    return None, None, None


def _interleaved(calls, cfg):
    """Best solver wall times (``out["wall"]``) of several solves timed in turns, one call of
    each per round, so that a burst of load on the shared machine hits all of them; each with
    C.best_time's rule: at least cfg["repeat"] calls lasting cfg["min_time"] in all, fewer once
    the next would pass cfg["budget"]. ``calls``: {key: call}; returns {key: (seconds or None, last output)}."""
    best = {k: float("inf") for k in calls}
    spent, count, outs, active = dict.fromkeys(calls, 0.0), dict.fromkeys(calls, 0), {}, list(calls)
    while active:
        for k in list(active):
            out = outs[k] = calls[k]()
            if not out["ok"]:
                best[k] = None
                active.remove(k)
                continue
            best[k], spent[k], count[k] = min(best[k], out["wall"]), spent[k] + out["wall"], count[k] + 1
            if spent[k] * (count[k] + 1) / count[k] > cfg["budget"] or (count[k] >= cfg["repeat"] and spent[k] >= cfg["min_time"]):
                active.remove(k)
    return {k: (best[k], outs[k]) for k in calls}


def measure(jobs, ref, cfg, timed=True):
    """Solvers on meshes, ``jobs`` [(kind, n), …]: for each the fewest load steps and the
    checked answer, then the best wall times, all timed in turns (exudyn on small systems with
    its sparse and its dense solver, the faster kept). Returns {(kind, n): row}."""
    rows, calls = {}, {}
    for job in jobs:
        kind, n = job
        run = runner(kind, n)
        steps, out, gap = _fewest_steps(run, ref)
        row = rows[job] = {"n": n, "steps": steps, "wall": None, "error": None, "iterations": None, "newton_gap": gap}
        if steps is None:
            continue
        row.update(error=float(np.linalg.norm(out["tip"] - ref)), iterations=out["iterations"],
                   steps_taken=out["steps"], tip=[float(v) for v in out["tip"]])
        calls[job + ("EigenSparse",)] = lambda run=run, steps=steps: run.solve(steps)
        if not _spacar(kind):
            row.update(coordinates=run.case.coordinates(), linear_solver="EigenSparse")
            if row["coordinates"] <= DENSE_MAX:   # small systems: exudyn's dense solver may be faster
                calls[job + ("EigenDense",)] = lambda run=run, steps=steps: run.solve(steps, linear_solver="EigenDense")
    if timed:
        for (kind, n, linear), (wall, out) in _interleaved(calls, cfg).items():
            row = rows[(kind, n)]
            if not _spacar(kind):
                row["wall_" + linear] = wall
            if wall is not None and (row["wall"] is None or wall < row["wall"]):
                row.update(wall=wall, iterations=out["iterations"], steps_taken=out["steps"])
                if not _spacar(kind):
                    row["linear_solver"] = linear
    return rows


def least_mesh(kind, target, rows, ref, cfg):
    """The smallest mesh whose tip error is at most target (errors fall with n: bisection between
    the grid's meshes, doubling past its largest); with the meshes tried. Not timed."""
    errors = {r["n"]: r["error"] for r in rows if r["error"] is not None}
    ok = [n for n in sorted(errors) if errors[n] <= target]
    tried = []

    def error(n):
        e = measure([(kind, n)], ref, cfg, timed=False)[(kind, n)]["error"]
        tried.append((n, e))
        return e

    if ok:
        hi = ok[0]
        below = [n for n in errors if n < hi]
        lo = max(below) if below else 1
    else:
        lo, hi, n = max(errors), None, 2 * max(errors)
        while n <= cfg["max_n"]:
            e = error(n)
            if e is not None and e <= target:
                hi = n
                break
            lo, n = n, 2 * n
        if hi is None:
            return None, tried
    while hi - lo > 1:
        mid = (lo + hi) // 2
        e = error(mid)
        if e is not None and e <= target:
            hi = mid
        else:
            lo = mid
    return hi, tried


def _keep_faster(rows, row):
    """Put row into rows (one per n), unless a row of the same n is already faster."""
    old = next((i for i, r in enumerate(rows) if r["n"] == row["n"]), None)
    if old is None:
        rows.append(row)
    elif row["wall"] is not None and (rows[old]["wall"] is None or row["wall"] < rows[old]["wall"]):
        rows[old] = row


# --- peak memory and exudyn's fast module, each solve in a fresh process ------------------

_WORKER = r'''
import json, resource, sys
solver, n, here, repeats = sys.argv[1], int(sys.argv[2]), sys.argv[3], int(sys.argv[4])
sys.path.insert(0, here)
rss = lambda: resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0   # MiB (Linux: KiB)
if solver == "spacar":
    import time
    import spacar, statics
    imports = rss()
    model = statics.cantilever(n)
    spare = [model.copy() for _ in range(repeats)]
    built = rss()
    res = spacar.static(model, steps=1)
    peak = rss()
    tip, iterations, walls = res.x[-1, -3:-1].tolist(), int(sum(res.stats["iterations"])), []
    for m in spare:
        start = time.perf_counter()
        spacar.static(m, steps=1)
        walls.append(time.perf_counter() - start)
else:
    import _exudyn_ancf as X
    X.quiet()
    imports = rss()
    case = (X.build_ge if solver == "ge" else X.build_ancf)(n, P=float(sys.argv[5]))
    settings = X.settings(1)
    built = rss()
    out = X.solve(case, settings)
    peak = rss()
    tip, iterations = out["tip"].tolist(), out["iterations"]
    walls = [X.solve(case, settings)["wall"] for _ in range(repeats)]
hwm = None
try:
    hwm = next(int(line.split()[1]) / 1024.0 for line in open("/proc/self/status") if line.startswith("VmHWM"))
except (OSError, StopIteration):
    pass
print(json.dumps({"imports": imports, "built": built, "peak": peak, "vmhwm": hwm, "tip": tip,
                  "iterations": iterations, "wall": min(walls) if walls else None}))
'''


def in_fresh_process(kind, n, repeats=0, fast=False):
    """One solve of ``kind`` on n elements in a new interpreter (``repeats`` more timed):
    ru_maxrss in MiB after the imports, after the build, after the solve; None on failure
    (C.fresh_process)."""
    env = dict(os.environ)
    env.pop("EXUDYN_MODULE", None)
    if fast:
        env["EXUDYN_MODULE"] = "fast"
    return C.fresh_process(_WORKER, [kind, n, HERE, repeats, ALPHA], timeout=600, env=env,
                           what=f"{kind} n={n} in a fresh process")


def memory(kind, n, ref):
    r = in_fresh_process(kind, n)
    if r is None:
        return {"solver": kind, "n": n}
    return {"solver": kind, "n": n, "imports": r["imports"], "build": r["built"] - r["imports"],
            "solve": r["peak"] - r["built"], "peak": r["peak"], "vmhwm": r["vmhwm"], "iterations": r["iterations"],
            "error": float(np.linalg.norm(np.asarray(r["tip"]) - ref))}


# --- what "exudyn at its best" is: the settings tried -------------------------------------

def probes(n, ref, cfg):
    """Single settings changed from the chosen ones, on n elements (the dense solver on the
    smallest mesh): converged?, iterations and load steps taken, tip error, best wall time."""
    small = cfg["sizes"][0]
    cases = [
        ("ge", n, "GE, shear 100 EA (spacar.compare.exudyn_static), 1 step, no adaptive stepping",
         {"shear": 100.0}, {"adaptive": False}),
        ("ge", n, "GE, shear 100 EA, adaptive load stepping from 1 step", {"shear": 100.0}, {}),
        ("ge", n, "GE, shear 100 EA, 20 load steps, no adaptive stepping", {"shear": 100.0},
         {"steps": 20, "adaptive": False}),
        ("ge", n, "GE, GA = EA, exudyn's default residual criterion (relative 1e-8)", {}, {"residual_mode": 0}),
        ("ge", n, "GE, GA = EA, increment criterion 1e-8, 1 step (chosen)", {}, {}),
        ("ancf", n, "ANCF, exudyn's default residual criterion (relative 1e-8)", {}, {"residual_mode": 0}),
        ("ancf", n, "ANCF, full Gauss integration (useReducedOrderIntegration = 0)", {"reduced": 0}, {}),
        ("ancf", n, "ANCF, all four root coordinates fixed (slope x too)", {"clamp": (0, 1, 2, 3)}, {}),
        ("ancf", n, "ANCF, EA L²/EI = 4800 (exudyn's ANCF_cantilever_test: E A L²/E I with h = L/20)",
         {"ea_factor": 4800.0 / n**2}, {}),
        ("ancf", n, "ANCF, reduced integration, increment criterion 1e-8, 1 step (chosen)", {}, {}),
        ("ge", small, "GE, exudyn's dense solver (EXUdense)", {}, {"linear_solver": "EXUdense"}),
        ("ge", small, "GE, Eigen's dense LU (EigenDense)", {}, {"linear_solver": "EigenDense"}),
        ("ge", small, "GE, sparse LU (EigenSparse)", {}, {}),
        ("ancf", small, "ANCF, exudyn's dense solver (EXUdense)", {}, {"linear_solver": "EXUdense"}),
        ("ancf", small, "ANCF, Eigen's dense LU (EigenDense)", {}, {"linear_solver": "EigenDense"}),
        ("ancf", small, "ANCF, sparse LU (EigenSparse)", {}, {}),
    ]
    calls = {}
    for i, (kind, size, label, model_options, solve_options) in enumerate(cases):
        run = ExudynRunner(kind, size, **model_options)
        options = {"steps": 1, **solve_options}
        steps = options.pop("steps")
        calls[i] = lambda run=run, steps=steps, options=options: run.solve(steps, **options)
    timed = _interleaved(calls, {**cfg, "repeat": 3, "budget": min(cfg["budget"], 1.5)})
    rows = []
    for i, (kind, size, label, _, _) in enumerate(cases):
        wall, out = timed[i]
        rows.append({"solver": kind, "n": size, "setting": label, "ok": out["ok"], "wall": wall,
                     "iterations": out["iterations"], "steps": out["steps"],
                     "error": None if not out["ok"] else float(np.linalg.norm(out["tip"] - ref))})
    return rows


def converter_check(ref):
    """The GE model of _exudyn_ancf with shear 100 EA against spacar.compare.exudyn_static's on 8
    elements in 10 load steps: the same tip (the converter is the model this benchmark changes)."""
    from spacar.compare import exudyn_static

    n = 8
    peer = exudyn_static.solve(cantilever(n), steps=10, subdivide=1).node(2 * n + 1)
    ours = ExudynRunner("ge", n, shear=100.0).solve(10, TIGHT)
    return {"n": n, "difference": float(np.linalg.norm(ours["tip"] - peer)), "error": float(np.linalg.norm(peer - ref))}


# --- the run ------------------------------------------------------------------------------

def run(a) -> dict:
    C.quiet_exudyn()
    import _exudyn_ancf as X

    X.quiet()
    cfg = QUICK if a.quick else FULL
    ref = elastica_tip(ALPHA)
    shooting = float(np.max(np.abs(ref - elastica_tip_shooting(ALPHA))))
    if shooting > 1e-10:
        raise RuntimeError(f"the elastica's closed form and shooting solution differ by {shooting:.1e}")
    out = {"quick": a.quick, "cfg": cfg, "machine": C.machine(peers=True),
           "reference": {"tip": [float(v) for v in ref], "shooting_difference": shooting},
           "exudyn_settings": {"tolerance": TOL, "check_tolerance": TIGHT, "ea_factor": X.EA_FACTOR},
           "runs": {k: [] for k in SOLVERS + (PREPARED,)}}
    least = {}   # target: {kind: (the smallest mesh reaching it, the meshes tried)}
    accuracy = SOLVERS + (ARC,)
    out["accuracy"] = {k: [] for k in accuracy}
    # PLBEAMC's errors on the smallest meshes, to start its bisections from.
    out["runs"][ARC] = list(measure([(ARC, n) for n in cfg["sizes"][:2]], ref, cfg, timed=False).values())
    for p in range(cfg["passes"]):   # two passes over everything timed: a quiet spell for each figure
        for n in cfg["sizes"]:
            for (kind, _), row in measure([(k, n) for k in SOLVERS + (PREPARED,)], ref, cfg).items():
                _keep_faster(out["runs"][kind], row)
            C.log(f"pass {p + 1}, n={n}: " + ", ".join(f"{k} {C.fmt_time(_row(out['runs'][k], n)['wall'])} "
                                                      f"({C.fmt_err(_row(out['runs'][k], n)['error'])})" for k in SOLVERS))
        for i, target in enumerate(cfg["targets"]):
            if target not in least:
                least[target] = {k: least_mesh(k, target, out["runs"][k], ref, cfg) for k in accuracy}
            rows = measure([(k, n) for k, (n, _) in least[target].items() if n is not None], ref, cfg)
            for k, (n, tried) in least[target].items():
                row = {"target": target, **(rows[(k, n)] if n is not None else {"n": None, "wall": None}), "tried": tried}
                if p == 0:
                    out["accuracy"][k].append(row)
                elif row["wall"] is not None and (out["accuracy"][k][i]["wall"] is None or row["wall"] < out["accuracy"][k][i]["wall"]):
                    out["accuracy"][k][i] = row
        for k in accuracy:
            C.log(f"pass {p + 1}, {k}: " + ", ".join(f"{r['target']:g} at n={r['n']} in {C.fmt_time(r['wall'])}"
                                                     for r in out["accuracy"][k]))
        if p == 0:
            out["memory"] = [memory(k, n, ref) for n in cfg["memory"] for k in SOLVERS]
    out["fast_module"] = []
    for n in cfg["memory"]:
        for kind in ("ge", "ancf"):
            walls = {"default": [], "fast": []}
            for _ in range(2):   # in turns, twice
                for module in walls:
                    r = in_fresh_process(kind, n, repeats=cfg["repeat"], fast=module == "fast")
                    if r is not None:
                        walls[module].append(r["wall"])
            out["fast_module"].append({"solver": kind, "n": n, **{m: min(w) if w else None for m, w in walls.items()}})
    out["probes"] = probes(cfg["probe"], ref, cfg)
    out["converter_check"] = converter_check(ref)
    return out


# --- the section --------------------------------------------------------------------------

def _row(runs, n):
    return next((r for r in runs if r["n"] == n), None)


def _cell(r):
    if r is None or r["wall"] is None:
        return "did not converge"
    steps = r.get("steps_taken", r["steps"])
    dense = ", dense" if r.get("linear_solver") == "EigenDense" else ""
    return (f"{C.fmt_time(r['wall'])} ({r['iterations']} it., {steps} step{'s' if steps != 1 else ''}{dense}) / "
            f"{C.fmt_err(r['error'])}")


def _mib(v):
    return "—" if v is None else f"{v:.1f}"


ERROR_FIT_TO = 128   # above, the ANCF cable's error nears its stretch (about 1e-4/n² L) and roundoff


def _order(runs):
    pts = [(r["n"], r["error"]) for r in runs if r["n"] <= ERROR_FIT_TO and r["error"]]
    return C.fit_exponent(*zip(*pts)) if len(pts) >= 2 else float("nan")


def _iterations(runs):
    its = [r["iterations"] for r in runs if r["iterations"] is not None]
    return f"{min(its)}–{max(its)}" if its and min(its) != max(its) else (str(its[0]) if its else "—")


def _exponent(runs, lo):
    pts = [(r["n"], r["wall"]) for r in runs if r["n"] >= lo and r["wall"] is not None]
    return C.fit_exponent(*zip(*pts)) if len(pts) >= 2 else float("nan")


def _words(r) -> list:
    """Where spacar loses, from the figures."""
    cfg, runs = r["cfg"], r["runs"]
    sizes = cfg["sizes"]
    lines = []
    for k in ("ge", "ancf"):
        slower = [n for n in sizes if _row(runs[k], n)["wall"] and _row(runs["spacar"], n)["wall"]
                  and _row(runs[k], n)["wall"] < _row(runs["spacar"], n)["wall"]]
        if slower:
            lines.append(f"* Per mesh, {NAMES[k]} is faster than spacar at n = {', '.join(map(str, slower))} "
                         f"(of {sizes[0]}…{sizes[-1]}).")
        else:
            lines.append(f"* Per mesh, spacar is faster than {NAMES[k]} at every n of {sizes[0]}…{sizes[-1]}.")
    prepared = [(n, _row(runs["ge"], n)["wall"] / _row(runs[PREPARED], n)["wall"]) for n in sizes
                if (_row(runs.get(PREPARED, []), n) or {}).get("wall") and _row(runs["ge"], n)["wall"]]
    if prepared:
        lines.append(f"* A `spacar.StaticSolver` (set up once, as exudyn's model is) against {NAMES['ge']}: "
                     + ", ".join(f"{v:.3g}× at {n}" for n, v in prepared) + " (exudyn's time / spacar's).")
    for t_i, target in enumerate(cfg["targets"]):
        acc = {k: r["accuracy"][k][t_i] for k in r["accuracy"]}
        s = acc["spacar"]
        c = acc.get(ARC)
        if c is not None and c["wall"] is not None:
            peers = [f"{NAMES[k]} {C.fmt_ratio(acc[k]['wall'], c['wall'])}" for k in ("ge", "ancf") if acc[k]["wall"]]
            lines.append(f"* To {target:g} L, PLBEAMC needs {c['n']} elements and {C.fmt_time(c['wall'])} "
                         f"(PLBEAM {s['n']}): against it " + ", ".join(peers) + " (peer's time / PLBEAMC's).")
        for k in ("ge", "ancf"):
            e = acc[k]
            if s["wall"] is None or e["wall"] is None:
                continue
            if e["wall"] < s["wall"]:
                lines.append(f"* To {target:g} L, {NAMES[k]} needs {e['n']} elements and {C.fmt_time(e['wall'])}, "
                             f"spacar {s['n']} and {C.fmt_time(s['wall'])}: spacar loses by "
                             f"{C.fmt_ratio(s['wall'], e['wall'])}.")
            else:
                lines.append(f"* To {target:g} L, spacar ({s['n']} elements, {C.fmt_time(s['wall'])}) beats "
                             f"{NAMES[k]} ({e['n']} elements, {C.fmt_time(e['wall'])}) by {C.fmt_ratio(e['wall'], s['wall'])}.")
    for n in cfg["memory"]:
        mem = {m["solver"]: m for m in r["memory"] if m["n"] == n and m.get("solve") is not None}
        if len(mem) == len(SOLVERS):
            use = {k: mem[k]["build"] + mem[k]["solve"] for k in SOLVERS}
            worse = [NAMES[k] for k in ("ge", "ancf") if use[k] < use["spacar"]]
            verdict = f"spacar loses to {' and '.join(worse)}" if worse else "spacar needs the least"
            lines.append(f"* Memory at n = {n}, building and solving: "
                         + ", ".join(f"{NAMES[k]} {use[k]:.1f} MiB" for k in SOLVERS) + f"; {verdict}.")
    n_big = sizes[-1]
    const = {k: _row(runs[k], n_big)["error"] * n_big**2 for k in ("spacar", "ge") if _row(runs[k], n_big)["error"]}
    orders = {k: _order(runs[k]) for k in SOLVERS}
    small = cfg["targets"][-1]
    least = {k: r["accuracy"][k][-1]["n"] for k in SOLVERS}
    lines += ["",
              "Why: PLBEAM's bending deformations are l₀ times the sines of the end rotations (the manual's "
              "definition, [static analysis](statics.md#accuracy)), so its tip error falls as h² "
              f"(fit q = {orders['spacar']:.2f}), with a constant (error · n² at n = {n_big}: "
              + ", ".join(f"{NAMES[k]} {v:.3f}" for k, v in const.items())
              + f") larger than the geometrically exact beam's (q = {orders['ge']:.2f}); the ANCF cable "
              "interpolates positions and slopes by cubic Hermite polynomials and its error falls faster "
              f"(q = {orders['ancf']:.2f}): to {small:g} L it needs {least['ancf']} elements, the geometrically "
              f"exact beam {least['ge']}, spacar {least['spacar']}. Newton "
              "iterations over the meshes: " + ", ".join(f"{NAMES[k]} {_iterations(runs[k])}" for k in SOLVERS)
              + " (spacar's tangent is exact, quadratic convergence; exudyn's geometrically exact beam's "
              "increments end in a slow, linear tail on fine meshes)."]
    return lines


def section(r: dict, plots: dict | None = None) -> str:
    cfg, runs = r["cfg"], r["runs"]
    st = r["exudyn_settings"]
    steps = sorted({x["steps"] for k in SOLVERS for x in runs[k] if x["steps"] is not None})
    fewest = "one, for all" if steps == [1] else "from " + ", ".join(map(str, steps))
    turn = np.degrees(np.arcsin(ALPHA * r["reference"]["tip"][0] ** 2 / 2))   # sin θ_L = alpha x² / 2
    lines = [f"## {TITLE}", "",
             "`python benchmarks/statics.py` (or `benchmarks/run_all.py`): the cantilever of length L = 1, EI = 1, "
             f"under a dead tip load P L²/EI = {ALPHA:g} along y ([static analysis](statics.md); the tip turns by "
             f"{turn:.1f}°), n elements, each solver from the straight beam in the fewest load steps that converge "
             f"(tried {', '.join(map(str, STEP_CHOICES))}: {fewest}). **spacar**: n PLBEAMs, axially rigid, `spacar.static` "
             "(the whole call, the model copied outside the timing); **spacar StaticSolver**: the same model in a "
             "`spacar.StaticSolver` made once outside the timing (compiled, its chain recognized, its tangent's "
             "pattern ordered, as exudyn's model is assembled once), each solve a call of it. **exudyn GE beam**: n "
             "`ObjectBeamGeometricallyExact2D` (the model of `spacar.compare.exudyn_static`, EA = "
             f"{st['ea_factor']:g} EI/l² with l = L/n, but shear stiffness GA = EA instead of its 100 EA). "
             "**exudyn ANCF cable**: n `ObjectANCFCable2D` on `NodePoint2DSlope1` nodes, EA = "
             f"{st['ea_factor']:g} EI/l² (stretch about P/EA = 3e-4/n² L), clamped as exudyn's examples do "
             "(coordinate constraints on the root's x, y and slope y), reduced Gauss integration, tip load a "
             "`LoadForceVector` (`benchmarks/_exudyn_ancf.py`). exudyn: `SolveStatic` alone timed (the model built "
             f"and assembled outside), sparse solver (EigenSparse; up to {DENSE_MAX} coordinates also the dense "
             "EigenDense, the faster kept and marked \"dense\"), full Newton, adaptive load stepping on, "
             f"convergence on the Newton increment (`newton.residualMode = 1`, tolerance {st['tolerance']:g}), no "
             "loads Jacobian (dead loads); each answer checked before it is timed against a solve at "
             f"{st['check_tolerance']:g} and against the elastica. Wall time: best of at least {cfg['repeat']} "
             f"solves lasting {cfg['min_time']:g} s in all, the solvers of a mesh in turns, best of {cfg['passes']} "
             f"pass{'es' if cfg['passes'] > 1 else ''} over the meshes. Tip error: distance from the inextensible elastica (closed form in elliptic integrals, "
             f"equal to a shooting solution within {r['reference']['shooting_difference']:.0e}) over the length.",
             "", *C.machine_table(r["machine"]), "",
             "**Each mesh**: wall time (Newton iterations, load steps) / tip error (/ L)", "",
             "| n | spacar | exudyn GE beam | exudyn ANCF cable | GE / spacar | ANCF / spacar | spacar StaticSolver | "
             "GE / StaticSolver | ANCF / StaticSolver |",
             "|---|---|---|---|---|---|---|---|---|"]
    for n in cfg["sizes"]:
        s, g, a = (_row(runs[k], n) for k in SOLVERS)
        p = _row(runs.get(PREPARED, []), n) or {"wall": None}
        lines.append(f"| {n} | {_cell(s)} | {_cell(g)} | {_cell(a)} | {C.fmt_ratio(g['wall'], s['wall'])} | "
                     f"{C.fmt_ratio(a['wall'], s['wall'])} | {C.fmt_time(p['wall'])} | "
                     f"{C.fmt_ratio(g['wall'], p['wall'])} | {C.fmt_ratio(a['wall'], p['wall'])} |")
    lo = cfg["fit_from"]
    exps = {k: _exponent(runs[k], lo) for k in SOLVERS}
    orders = {k: _order(runs[k]) for k in SOLVERS}
    lines += ["", f"Growth from n = {lo} to {cfg['sizes'][-1]} (log-log fit t ∝ nᵖ): "
              + ", ".join(f"{NAMES[k]} p = {exps[k]:.2f}" for k in SOLVERS) + ". Tip error against n (fit e ∝ nᵠ, "
              f"n = {cfg['sizes'][0]}…{min(ERROR_FIT_TO, cfg['sizes'][-1])}): " + ", ".join(f"{NAMES[k]} q = {orders[k]:.2f}" for k in SOLVERS)
              + ".", "",
              "**Time to a tip accuracy**: the least wall time of any mesh and number of load steps reaching the "
              "target — the smallest mesh that does (bisection on n; one load step is the fastest for all), "
              "timed as above; beside PLBEAM the extension PLBEAMC, the planar beam exact for constant curvature "
              "([static analysis](statics.md#accuracy))", "",
              "| target (/ L) | spacar PLBEAM | spacar PLBEAMC | exudyn GE beam | exudyn ANCF cable | GE / PLBEAM | "
              "ANCF / PLBEAM | GE / PLBEAMC | ANCF / PLBEAMC |",
              "|---|---|---|---|---|---|---|---|---|"]
    arc = r["accuracy"].get(ARC)
    for i, target in enumerate(cfg["targets"]):
        s, g, a = (r["accuracy"][k][i] for k in SOLVERS)
        c = arc[i] if arc else {"wall": None}
        cells = [("not reached" if x["wall"] is None else
                  f"{C.fmt_time(x['wall'])} (n = {x['n']}, {x['iterations']} it."
                  f"{', dense' if x.get('linear_solver') == 'EigenDense' else ''}) / {C.fmt_err(x['error'])}")
                 for x in (s, c, g, a)]
        lines.append(f"| {target:g} | {' | '.join(cells)} | {C.fmt_ratio(g['wall'], s['wall'])} | "
                     f"{C.fmt_ratio(a['wall'], s['wall'])} | {C.fmt_ratio(g['wall'], c['wall'])} | "
                     f"{C.fmt_ratio(a['wall'], c['wall'])} |")
    lines += ["", "**Peak memory** (each solve in a fresh process, `ru_maxrss` in MiB): after the imports; what "
              "building the model adds (exudyn: with `Assemble`); what the solve adds over the built model; the "
              "process's peak", "",
              "| n | solver | after imports | build | solve | peak |", "|---|---|---|---|---|---|"]
    for m in r["memory"]:
        lines.append(f"| {m['n']} | {NAMES[m['solver']]} | {_mib(m.get('imports'))} | +{_mib(m.get('build'))} | "
                     f"+{_mib(m.get('solve'))} | {_mib(m.get('peak'))} |")
    lines += ["", "**exudyn's settings**: one change from the chosen settings at a time (best of up to 3 solves; "
              "iterations and load steps in all; \"converged\" is exudyn's verdict)", "",
              "| setting | n | converged | iterations, load steps | tip error | wall time |", "|---|---|---|---|---|---|"]
    for p in r["probes"]:
        lines.append(f"| {p['setting']} | {p['n']} | {'yes' if p['ok'] else 'no'} | {p['iterations']}, {p['steps']} | "
                     f"{C.fmt_err(p['error'])} | {C.fmt_time(p['wall'])} |")
    fm = r["fast_module"]
    if fm:
        lines += ["", "exudyn's module without range checks (`EXUDYN_MODULE=fast`, `exudynCPPfast`) against the "
                  "default one, each in a fresh process, two processes each in turns, best of the same solves: "
                  + "; ".join(f"{NAMES[f['solver']]}, n = {f['n']}: {C.fmt_time(f['fast'])} against "
                              f"{C.fmt_time(f['default'])} ({C.fmt_ratio(f['fast'], f['default'])})" for f in fm)
                  + ". The tables use the default module, as the other benchmarks do."]
    cc = r["converter_check"]
    lines += ["", f"The GE model with shear 100 EA gives `spacar.compare.exudyn_static`'s tip on {cc['n']} elements "
              f"within {cc['difference']:.0e} L.", "", "**Where spacar loses**", "", *_words(r)]
    if plots:
        lines += [""] + [f"![{k}]({v})" for k, v in plots.items()]
    return "\n".join(lines) + "\n"


def plot(r: dict) -> dict:
    marks = {"spacar": "o-", "ge": "d-", "ancf": "s-"}
    fig, ax = C.new_figure(f"Elastica P L²/EI = {ALPHA:g}: tip error against wall time (n = "
                           f"{r['cfg']['sizes'][0]}…{r['cfg']['sizes'][-1]})")
    for k in SOLVERS:
        pts = [x for x in r["runs"][k] if x["wall"] is not None and x["error"]]
        line, = ax.loglog([p["wall"] for p in pts], [p["error"] for p in pts], marks[k], label=NAMES[k])
        acc = [x for x in r["accuracy"][k] if x["wall"] is not None]
        ax.loglog([p["wall"] for p in acc], [p["error"] for p in acc], marks[k][0], mfc="none", ms=11,
                  color=line.get_color())
    for t in r["cfg"]["targets"]:
        ax.axhline(t, color="grey", lw=0.8, ls=":")
    ax.set_xlabel("wall time [s] (open: the least mesh reaching a target, dotted)")
    ax.set_ylabel("tip error / L")
    ax.legend(fontsize=8)
    out = {"static cantilever": C.save_figure(fig, "static_cantilever.png")}
    fig, ax = C.new_figure(f"Elastica P L²/EI = {ALPHA:g}: wall time of the static solve against n")
    for k in SOLVERS:
        pts = [x for x in r["runs"][k] if x["wall"] is not None]
        ax.loglog([p["n"] for p in pts], [p["wall"] for p in pts], marks[k], label=NAMES[k])
    ax.set_xlabel("elements n")
    ax.set_ylabel("wall time [s]")
    ax.legend(fontsize=8)
    out["static cantilever scaling"] = C.save_figure(fig, "static_cantilever_scaling.png")
    return out


def main(argv=None) -> int:
    return C.standard_main("statics", __doc__, run, section, plot, argv)


if __name__ == "__main__":
    sys.exit(main())

"""Benchmark: the lowest eigenfrequencies of a clamped-free planar beam — spacar's sparse
eigen-analysis (``spacar.linearize`` then ``eigenfrequencies(k=...)``) against exudyn's
``ComputeODE2Eigenvalues`` with its sparse solver on two beam elements: wall time per mesh,
growth with the mesh, accuracy against Euler–Bernoulli, peak memory.

Model: a cantilever of length L = 1 clamped at x = 0, EI = 1, ρA = 1, EA = 1e4 (axially
"practically rigid": yet its first axial modes, (2j − 1)/4 · √(EA/ρA)/L = 25, 75, … Hz, lie among
the ten lowest, between the 4th and 5th and the 8th and 9th bending modes), n = 50 … 3200
elements; the 10 lowest frequencies:

* spacar: n PLBEAMs, all three deformations DYNE (ESTIFF EA, EI; EMASS ρA), nodes 1, 2 fixed;
  timed: ``lin = spacar.linearize(model); lin.eigenfrequencies(k=10, method="sparse")`` (the whole
  call, the model built and copied outside the timing): the sparse nodal matrices at rest and
  ARPACK in shift-invert mode on the saddle-point system. Up to n = DENSE_MAX also the dense
  reduced path (``method="dense"``, linearize included), which must agree to 1e-9 relative.
* exudyn, ANCF cable: n ``ObjectANCFCable2D`` on ``NodePoint2DSlope1`` nodes (cubic Hermite,
  Euler–Bernoulli), full Gauss integration; the root's x, y and slope y clamped;
* exudyn, geometrically exact beam: n ``ObjectBeamGeometricallyExact2D`` on ``NodeRigidBody2D``
  nodes (linear interpolation, Simo–Reissner), shear stiffness GA = 100 EA (the converter's rule of
  spacar.compare.exudyn_static), a tiny rotary inertia (1e-10 ρA L²: with none M is singular and
  ARPACK fails on small meshes; its effect on the frequencies is below 1e-9); the root's x, y and
  rotation clamped.

exudyn: ``mbs.Assemble()`` outside the timing, then ``mbs.ComputeODE2Eigenvalues`` timed with
its sparse solver (``useSparseSolver=True``, ``numberOfEigenvalues=10``,
``computeComplexEigenvalues=False``, ``convert2Frequencies=True``), the clamp as exudyn's own
eigenvalue examples do it: no constraint objects, the clamped coordinates erased from M and K
(``constrainedCoordinates``), simulation settings with the sparse linear solver (EigenSparse).
The alternatives (CoordinateConstraint objects with ``ignoreAlgebraicEquations``, their nullspace
projection, the dense solver, exudyn's default settings) are timed once on a mid-size mesh (the
probes table). Each answer is checked against the analytic frequencies before it is timed;
frequencies below 1e-3 of the first analytic one (rigid-body or constraint modes) would be
dropped and counted (none are: the clamped coordinates are removed).

Reference: Euler–Bernoulli bending, f = β² √(EI/(ρA L⁴)) / 2π with cos β cosh β = −1 (roots to
machine precision by bisection; the first five equal the tabulated 1.8751040687119611, …), and
the axial rod, f = (2j − 1)/4 · √(EA/ρA) / L; the ten lowest of both families, sorted.
Wall time: best of repeats, the solvers of a mesh timed in turns. Memory: each solve in a fresh
process, ``ru_maxrss`` after the imports, after building the model (exudyn: with Assemble), after
the solve.

    python benchmarks/modes.py [--quick] [--no-write] [--no-plot] [--from-results]
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

import spacar
import _common as C

HERE = Path(__file__).resolve()
TITLE = "Eigenfrequencies: clamped-free beam, spacar's sparse eigen-analysis and exudyn ComputeODE2Eigenvalues"
K_MODES = 10
FULL = {"sizes": [50, 200, 800, 3200], "dense_max": 200, "memory": [800, 3200], "probe": 200, "fit_from": 200,
        "repeat": 5, "min_time": 1.0, "budget": 45.0}
QUICK = {"sizes": [16, 32], "dense_max": 32, "memory": [32], "probe": 16, "fit_from": 16,
         "repeat": 2, "min_time": 0.0, "budget": 0.5}
SOLVERS = ("spacar", "ancf", "ge")
NAMES = {"spacar": "spacar PLBEAM", "ancf": "exudyn ANCF cable", "ge": "exudyn GE beam"}
SANE = 0.2           # a first-five bending error above this (relative) is no answer: not timed
ZERO = 1e-3          # exudyn frequencies below ZERO · (first analytic) are zero modes
AGREE = 1e-9         # spacar sparse against dense, relative

# --- exudyn (self-contained: the memory worker executes this block alone, without spacar) ---
import time as _time  # noqa: E402

import numpy as _np  # noqa: E402

L, EI, RHO_A, EA = 1.0, 1.0, 1.0, 1e4
GA_FACTOR = 100.0    # the GE beam's shear stiffness GA = GA_FACTOR · EA
RHO_I_GE = 1e-10     # the GE beam's rotary inertia per length (radius of gyration 1e-5 L): without
                     # any, M is singular and ARPACK fails on small meshes (scipy's eigh always)


class ExudynCase:
    """An assembled exudyn model of the cantilever: ``mbs`` (its ``SC`` kept alive), the element
    kind, n, and the clamped ODE2 coordinates."""

    def __init__(self, SC, mbs, kind, n, clamped, constraints):
        self.SC, self.mbs, self.kind, self.n, self.clamped, self.constraints = SC, mbs, kind, n, clamped, constraints

    def coordinates(self):
        return len(self.mbs.systemData.GetODE2Coordinates())


def _exudyn_clamp(mbs, node, coordinates):
    from exudyn.itemInterface import CoordinateConstraint, MarkerNodeCoordinate, NodePointGround

    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    for i in coordinates:
        mbs.AddObject(CoordinateConstraint(markerNumbers=[ground, mbs.AddMarker(
            MarkerNodeCoordinate(nodeNumber=node, coordinate=i))]))


def build_ancf(n, constraints=False, reduced=0):
    """n ANCF cable elements along x, assembled; the root's x, y, slope y (ODE2 coordinates 0, 1,
    3) clamped: erased at the eigen-analysis, or with ``constraints`` also CoordinateConstraints."""
    import exudyn as exu
    from exudyn.itemInterface import NodePoint2DSlope1, ObjectANCFCable2D

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    l = L / n
    nodes = [mbs.AddNode(NodePoint2DSlope1(referenceCoordinates=[k * l, 0.0, 1.0, 0.0])) for k in range(n + 1)]
    for a, b in zip(nodes[:-1], nodes[1:]):
        mbs.AddObject(ObjectANCFCable2D(nodeNumbers=[a, b], length=l, massPerLength=RHO_A, bendingStiffness=EI,
                                        axialStiffness=EA, useReducedOrderIntegration=reduced))
    if constraints:
        _exudyn_clamp(mbs, nodes[0], (0, 1, 3))
    mbs.Assemble()
    return ExudynCase(SC, mbs, "ancf", n, [0, 1, 3], constraints)


def build_ge(n, constraints=False, shear=GA_FACTOR):
    """n geometrically exact 2D beams along x (GA = shear · EA, rotary inertia RHO_I_GE),
    assembled; the root's x, y, rotation (ODE2 coordinates 0, 1, 2) clamped as in build_ancf."""
    import exudyn as exu
    from exudyn.itemInterface import NodeRigidBody2D, ObjectBeamGeometricallyExact2D

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    l = L / n
    nodes = [mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[k * l, 0.0, 0.0])) for k in range(n + 1)]
    for a, b in zip(nodes[:-1], nodes[1:]):
        mbs.AddObject(ObjectBeamGeometricallyExact2D(nodeNumbers=[a, b], length=l, massPerLength=RHO_A,
                                                     crossSectionInertia=RHO_I_GE, bendingStiffness=EI, axialStiffness=EA,
                                                     shearStiffness=shear * EA))
    if constraints:
        _exudyn_clamp(mbs, nodes[0], (0, 1, 2))
    mbs.Assemble()
    return ExudynCase(SC, mbs, "ge", n, [0, 1, 2], constraints)


def exudyn_settings(linear_solver="EigenSparse"):
    import exudyn as exu

    s = exu.SimulationSettings()
    if linear_solver is not None:
        s.linearSolver.solverType = getattr(exu.LinearSolverType, linear_solver)
    return s


def exudyn_modes(case, k=10, sparse=True, treatment="erase", settings=None, zero=0.0):
    """One ComputeODE2Eigenvalues: {"ok", "f" (Hz, the k lowest after dropping zero modes),
    "zero_modes", "wall", "error"}. ``treatment``: "erase" (constrainedCoordinates; with
    constraint objects in the model also ignoreAlgebraicEquations=True) or "project" (the
    constraint objects, exudyn's nullspace projection; dense only). ``zero``: frequencies below
    it are zero modes, dropped (then k more are asked for)."""
    settings = exudyn_settings() if settings is None else settings
    options = dict(useSparseSolver=sparse, convert2Frequencies=True, computeComplexEigenvalues=False)
    if treatment == "erase":
        options.update(constrainedCoordinates=list(case.clamped), ignoreAlgebraicEquations=case.constraints)
    elif treatment != "project":
        raise ValueError(treatment)
    ask, wall, dropped = k, 0.0, 0
    while True:
        start = _time.perf_counter()
        try:
            f = case.mbs.ComputeODE2Eigenvalues(settings, numberOfEigenvalues=ask, **options)[0]
        except Exception as e:  # noqa: BLE001 - exudyn and scipy raise various errors
            return {"ok": False, "f": None, "zero_modes": None, "wall": None,
                    "error": f"{type(e).__name__}: {str(e).splitlines()[0][:160] if str(e) else ''}"}
        wall = _time.perf_counter() - start
        f = _np.sort(_np.asarray(f, dtype=float))
        dropped = int(_np.sum(f < zero))
        if dropped == 0 or ask > k + dropped or ask >= k + 20:
            break
        ask = k + dropped
    f = f[f >= zero][:k]
    return {"ok": len(f) == k and bool(_np.all(_np.isfinite(f))), "f": f, "zero_modes": dropped, "wall": wall,
            "error": None}
# --- end exudyn ---


# --- spacar -------------------------------------------------------------------------------

def beam(n):
    """n PLBEAMs along x, all deformations DYNE, clamped at x = 0."""
    m = spacar.Model()
    for k in range(1, n + 1):
        m.plbeam(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2)
        m.x(2 * k + 1, k / n * L, 0.0)
        m.estiff(k, EA, EI)
        m.emass(k, RHO_A)
        m.dyne(k, 1, 2, 3)
    m.fix(1)
    m.fix(2)
    return m


def spacar_modes(model, method="sparse", k=K_MODES):
    """The timed call on a copy of the model (copied outside the timing): (seconds, frequencies)."""
    m = model.copy()
    start = time.perf_counter()
    lin = spacar.linearize(m)
    f = lin.eigenfrequencies(k=k, method=method)
    return time.perf_counter() - start, np.asarray(f, dtype=float)


# --- the reference ------------------------------------------------------------------------

BETA_TABLE = [1.8751040687119611, 4.694091132974175, 7.854757438237613, 10.995540734875467, 14.13716839104647]


def bending_betas(count):
    """β_i L of the clamped-free Euler–Bernoulli beam: the roots of cos β + 1/cosh β = 0 (that is
    cos β cosh β = −1), one in each ((i − 1)π, iπ)."""
    from scipy.optimize import brentq

    g = lambda b: np.cos(b) + 1.0 / np.cosh(b)  # noqa: E731
    return np.array([brentq(g, (i - 1) * np.pi + 1e-9, i * np.pi, xtol=1e-15, rtol=4 * np.finfo(float).eps)
                     for i in range(1, count + 1)])


def reference(k=K_MODES):
    """The k lowest analytic frequencies [Hz], sorted: [(f, "bending" | "axial", index)]."""
    betas = bending_betas(k)
    bending = [(float(b ** 2 * np.sqrt(EI / (RHO_A * L ** 4)) / (2 * np.pi)), "bending", i + 1) for i, b in enumerate(betas)]
    axial = [(float((2 * j - 1) / (4 * L) * np.sqrt(EA / RHO_A)), "axial", j) for j in range(1, k + 1)]
    return sorted(bending + axial)[:k]


def errors(f, ref):
    """Relative errors f/f_ref − 1 of the sorted frequencies against the sorted reference:
    {"all": [...], "bending5": the first five bending modes, "worst": max |·| over all k}."""
    f = np.sort(np.asarray(f, dtype=float))
    rel = [float(a / r[0] - 1.0) for a, r in zip(f, ref)]
    bending = [e for e, r in zip(rel, ref) if r[1] == "bending"][:5]
    i = int(np.argmax(np.abs(rel)))
    return {"all": rel, "bending5": bending, "worst": abs(rel[i]), "worst_mode": f"{ref[i][1][0]}{ref[i][2]}"}


# --- timing ---------------------------------------------------------------------------------

def _interleaved(calls, cfg):
    """Best wall times of several calls timed in turns (one call of each per round, so that a
    burst of load on the shared machine hits all of them), each with C.best_time's rule: at least
    cfg["repeat"] calls lasting cfg["min_time"] in all, fewer once the next would pass
    cfg["budget"]. ``calls``: {key: call returning (seconds or None, output)}; returns
    {key: (best seconds or None, calls made, last output)}."""
    best = {k: float("inf") for k in calls}
    spent, count, outs, active = dict.fromkeys(calls, 0.0), dict.fromkeys(calls, 0), {}, list(calls)
    while active:
        for k in list(active):
            wall, outs[k] = calls[k]()
            if wall is None:
                best[k] = None
                active.remove(k)
                continue
            best[k], spent[k], count[k] = min(best[k], wall), spent[k] + wall, count[k] + 1
            if spent[k] * (count[k] + 1) / count[k] > cfg["budget"] or (count[k] >= cfg["repeat"] and spent[k] >= cfg["min_time"]):
                active.remove(k)
    return {k: (best[k], count[k], outs.get(k)) for k in calls}


def _exudyn_call(case, **options):
    def call():
        out = exudyn_modes(case, K_MODES, **options)
        return out["wall"], out
    return call


def _spacar_call(model, method):
    def call():
        wall, f = spacar_modes(model, method)
        return wall, {"f": f}
    return call


def measure(n, ref, cfg):
    """All solvers on n elements: each answer checked against the reference (untimed), then the
    solvers timed in turns. Returns {solver: row}."""
    f1 = ref[0][0]
    model = beam(n)
    cases = {"ancf": build_ancf(n), "ge": build_ge(n)}
    rows, calls = {}, {}
    _, f_sparse = spacar_modes(model, "sparse")
    err = errors(f_sparse, ref)
    rows["spacar"] = {"n": n, "dofs": 3 * n, "f": f_sparse.tolist(), "errors": err, "ok": True}
    calls["spacar"] = _spacar_call(model, "sparse")
    if n <= cfg["dense_max"]:
        _, f_dense = spacar_modes(model, "dense")
        rows["spacar"]["dense_agreement"] = float(np.max(np.abs(f_dense - f_sparse) / np.abs(f_dense)))
        calls["spacar_dense"] = _spacar_call(model, "dense")
    for kind, case in cases.items():
        out = exudyn_modes(case, K_MODES, zero=ZERO * f1)
        row = rows[kind] = {"n": n, "dofs": case.coordinates() - len(case.clamped), "coordinates": case.coordinates(),
                            "ok": out["ok"], "failure": out["error"], "zero_modes": out["zero_modes"]}
        if out["ok"]:
            row.update(f=out["f"].tolist(), errors=errors(out["f"], ref))
            if max(abs(e) for e in row["errors"]["bending5"]) > SANE:
                row.update(ok=False, failure="answer off the reference by more than "
                                             f"{SANE:g}: not timed")
        if row["ok"]:
            calls[kind] = _exudyn_call(case, zero=ZERO * f1)
            if n <= cfg["dense_max"] and kind == "ancf":   # the GE beam's M is near singular: probes only
                dense = exudyn_modes(case, K_MODES, sparse=False, zero=ZERO * f1)
                row["dense_ok"], row["dense_failure"] = dense["ok"], dense["error"]
                if dense["ok"]:
                    row["dense_errors"] = errors(dense["f"], ref)
                    calls[kind + "_dense"] = _exudyn_call(case, sparse=False, zero=ZERO * f1)
    for key, (wall, count, out) in _interleaved(calls, cfg).items():
        kind, dense = (key[:-6], True) if key.endswith("_dense") else (key, False)
        rows[kind]["wall_dense" if dense else "wall"] = wall
        rows[kind]["calls_dense" if dense else "calls"] = count
        if kind != "spacar" and not dense and out is not None and out.get("f") is not None:
            # the timed answers (ARPACK's start vector is random in scipy's eigsh) against the checked one
            rows[kind]["timed_vs_checked"] = float(np.max(np.abs(np.asarray(out["f"]) - rows[kind]["f"])
                                                          / np.asarray(rows[kind]["f"])))
    C.log(f"modes n={n}: " + ", ".join(
        f"{k} {C.fmt_time(rows[k].get('wall'))} (err {C.fmt_err(rows[k]['errors']['worst']) if rows[k].get('errors') else '—'})"
        for k in SOLVERS))
    return rows


# --- what "exudyn at its best" is: the settings tried -------------------------------------

def probes(n, ref, cfg):
    """Single changes from exudyn's chosen settings on n elements: answer ok?, worst relative
    error of the ten, zero modes dropped, best wall time of up to 3 calls (or the failure)."""
    f1 = ref[0][0]
    plans = [
        ("chosen: constrainedCoordinates, EigenSparse settings, sparse solver", {}, {}),
        ("exudyn's default SimulationSettings (EXUdense)", {}, {"settings": "default"}),
        ("CoordinateConstraints in the model + ignoreAlgebraicEquations=True", {"constraints": True}, {}),
        ("CoordinateConstraints, nullspace projection (dense only)", {"constraints": True},
         {"treatment": "project", "sparse": False}),
        ("dense solver (useSparseSolver=False, all eigenvalues)", {}, {"sparse": False}),
        ("ANCF: reduced integration (useReducedOrderIntegration=1)", {"reduced": 1}, {}),
        ("GE: shear stiffness GA = EA (instead of 100 EA)", {"shear": 1.0}, {}),
    ]
    out = []
    for kind, build in (("ancf", build_ancf), ("ge", build_ge)):
        for label, bopts, sopts in plans:
            if ("reduced" in bopts and kind != "ancf") or ("shear" in bopts and kind != "ge"):
                continue
            case = build(n, **bopts)
            sopts = dict(sopts)
            if sopts.get("settings") == "default":
                sopts["settings"] = exudyn_settings(None)
            walls, res = [], None
            for _ in range(3):
                res = exudyn_modes(case, K_MODES, zero=ZERO * f1, **sopts)
                if not res["ok"]:
                    break
                walls.append(res["wall"])
                if sum(walls) > cfg["budget"] / 3:
                    break
            row = {"solver": kind, "setting": label, "n": n, "ok": res["ok"], "failure": res["error"],
                   "zero_modes": res["zero_modes"], "wall": min(walls) if res["ok"] else None}
            if res["ok"]:
                row["worst"] = errors(res["f"], ref)["worst"]
            out.append(row)
            C.log(f"modes probe {kind} n={n} {label}: {C.fmt_time(row['wall'])}"
                  + (f" worst {row['worst']:.1e}" if res["ok"] else f" failed: {res['error']}"))
    return out


# --- peak memory, each solve in a fresh process ---------------------------------------------

_WORKER = r'''
import json, resource, sys, time
solver, n, path = sys.argv[1], int(sys.argv[2]), sys.argv[3]
rss = lambda: resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0   # MiB (Linux: KiB)
import numpy, scipy.linalg, scipy.sparse.linalg
if solver == "spacar":
    sys.path.insert(0, path.rsplit("/", 1)[0])
    import spacar, modes
    imports = rss()
    model = modes.beam(n)
    built = rss()
    wall, f = modes.spacar_modes(model)
    f = f.tolist()
else:
    import exudyn, exudyn.itemInterface
    exudyn.SetWriteToConsole(False)
    text = open(path).read()
    block = text.split("# --- exudyn (self-contained")[1].split("# --- end exudyn ---")[0]
    ns = {"__name__": "modes_exudyn"}
    exec(compile("#" + block, path, "exec"), ns)
    imports = rss()
    case = ns["build_" + solver](n)
    built = rss()
    out = ns["exudyn_modes"](case)
    wall, f = out["wall"], (out["f"].tolist() if out["ok"] else None)
peak = rss()
hwm = None
try:
    hwm = next(int(line.split()[1]) / 1024.0 for line in open("/proc/self/status") if line.startswith("VmHWM"))
except (OSError, StopIteration):
    pass
print(json.dumps({"imports": imports, "built": built, "peak": peak, "vmhwm": hwm, "wall": wall, "f": f}))
'''


def in_fresh_process(kind, n):
    """One solve of ``kind`` on n elements in a new interpreter: ru_maxrss in MiB after the
    imports, after the build, after the solve; None on failure (C.fresh_process)."""
    return C.fresh_process(_WORKER, [kind, n, HERE], timeout=900,
                           env=dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1"),
                           what=f"modes {kind} n={n} in a fresh process")


def memory(kind, n, ref):
    r = in_fresh_process(kind, n)
    if r is None:
        return {"solver": kind, "n": n}
    out = {"solver": kind, "n": n, "imports": r["imports"], "build": r["built"] - r["imports"],
           "solve": r["peak"] - r["built"], "peak": r["peak"], "vmhwm": r["vmhwm"], "wall": r["wall"]}
    if r["f"] is not None:
        out["worst"] = errors(r["f"], ref)["worst"]
    C.log(f"modes memory {kind} n={n}: solve +{out['solve']:.0f} MiB, peak {out['peak']:.0f} MiB")
    return out


# --- the run ------------------------------------------------------------------------------

def single_threaded_blas() -> list:
    """Limit the OpenBLAS libraries loaded in this process (numpy's, scipy's) to one thread, as
    threadpoolctl would: on the shared 2-core machine a second BLAS thread competing with another
    process made a 600 x 600 ``eigh`` 40–65 times slower (5 s instead of 0.1 s). Returns the
    libraries set. The fresh processes of the memory table get OPENBLAS_NUM_THREADS=1."""
    import ctypes

    done = []
    try:
        paths = sorted({line.split()[-1] for line in open("/proc/self/maps") if "openblas" in line.split()[-1].lower()})
    except OSError:  # pragma: no cover - not Linux
        return done
    for path in paths:
        try:
            lib = ctypes.CDLL(path)
        except OSError:  # pragma: no cover
            continue
        for sym in ("scipy_openblas_set_num_threads64_", "scipy_openblas_set_num_threads",
                    "openblas_set_num_threads64_", "openblas_set_num_threads"):
            fn = getattr(lib, sym, None)
            if fn is not None:
                fn(ctypes.c_int(1))
                done.append(path.rsplit("/", 1)[-1])
                break
    return done


def _extension_mtime():
    try:
        return Path(spacar._core.__file__).stat().st_mtime
    except OSError:  # pragma: no cover
        return None


def run(a) -> dict:
    C.quiet_exudyn()
    import scipy.linalg  # noqa: F401 - load scipy's OpenBLAS before limiting its threads
    import scipy.sparse.linalg  # noqa: F401
    blas = single_threaded_blas()
    mtime = _extension_mtime()
    try:
        import exudyn
        exudyn.config.printToConsole = False
    except Exception:  # pragma: no cover
        pass
    cfg = QUICK if a.quick else FULL
    ref = reference()
    betas = bending_betas(5)
    out = {"quick": a.quick, "cfg": cfg, "machine": C.machine(peers=True), "k": K_MODES,
           "model": {"L": L, "EI": EI, "rhoA": RHO_A, "EA": EA, "GA_factor": GA_FACTOR, "rhoI_GE": RHO_I_GE},
           "reference": {"f": [r[0] for r in ref], "kind": [r[1] for r in ref], "index": [r[2] for r in ref],
                         "beta_vs_table": float(np.max(np.abs(betas - BETA_TABLE) / BETA_TABLE))}}
    # Warm-up (imports of scipy's sparse eigensolvers, first calls), untimed.
    spacar_modes(beam(8))
    exudyn_modes(build_ancf(8))
    runs = {k: [] for k in SOLVERS}
    for n in cfg["sizes"]:
        rows = measure(n, ref, cfg)
        for k in SOLVERS:
            runs[k].append(rows[k])
    out["runs"] = runs
    out["probes"] = probes(cfg["probe"], ref, cfg)
    out["memory"] = [memory(k, n, ref) for n in cfg["memory"] for k in SOLVERS]
    out["blas_single_thread"] = blas
    out["extension_rebuilt"] = _extension_mtime() != mtime
    try:
        out["load_at_end"] = " / ".join(f"{v:.2f}" for v in os.getloadavg())
    except OSError:  # pragma: no cover
        pass
    return out


# --- the section --------------------------------------------------------------------------

def _mib(v):
    return "—" if v is None else f"{v:.0f}"


def _signed(e):
    return "—" if e is None else f"{e:+.1e}"


def _row(rows, n):
    return next((r for r in rows if r["n"] == n), {})


def _exponent(rows, lo, key="wall"):
    pts = [(r["n"], r[key]) for r in rows if r.get(key) and r["n"] >= lo]
    return C.fit_exponent([p[0] for p in pts], [p[1] for p in pts]) if len(pts) >= 2 else float("nan")


def _axial_errors(r) -> str:
    """spacar's error of the first axial frequency on each mesh, as words."""
    ref = r["reference"]
    i = next(j for j, (k, m) in enumerate(zip(ref["kind"], ref["index"])) if k == "axial" and m == 1)
    return ", ".join(f"{C.fmt_err(abs(x['errors']['all'][i]))} at n = {x['n']}" for x in r["runs"]["spacar"]
                     if x.get("errors"))


def _words(r) -> list:
    cfg, runs = r["cfg"], r["runs"]
    sp = runs["spacar"]
    lines = []
    slower = [(n, k, _row(runs[k], n)["wall"], _row(sp, n)["wall"]) for n in cfg["sizes"] for k in ("ancf", "ge")
              if _row(runs[k], n).get("wall") and _row(sp, n).get("wall") and _row(runs[k], n)["wall"] < _row(sp, n)["wall"]]
    if slower:
        lines.append("* Wall time: spacar's sparse path is slower than " + "; ".join(
            f"{NAMES[k]} at n = {n} ({C.fmt_time(sw)} against {C.fmt_time(ew)})" for n, k, ew, sw in slower) + ".")
    else:
        lines.append("* Wall time: nowhere in these meshes; spacar's sparse path is the fastest at every n.")
    small = [x for x in sp if x.get("wall_dense") and x.get("wall") and x["wall_dense"] < x["wall"]]
    if small:
        lines.append("* On small meshes spacar's own dense reduced path is faster than its sparse one ("
                     + ", ".join(f"n = {x['n']}: {C.fmt_time(x['wall_dense'])} against {C.fmt_time(x['wall'])}" for x in small)
                     + "); `eigenfrequencies(k=...)` with the default `method=\"auto\"` takes the dense path up to "
                     "`Linearization.SPARSE_ABOVE` = 200 degrees of freedom (n ≤ 66 here), the sparse one above.")
    auto_slow = [x for x in sp if 3 * x["n"] <= 200 and x.get("wall_dense") and x.get("wall") and x["wall_dense"] > x["wall"]]
    if auto_slow:
        lines.append("* spacar's default `method=\"auto\"` takes the dense path up to `Linearization.SPARSE_ABOVE` = 200 "
                     "degrees of freedom (n ≤ 66 here), and there it is the slower one: " + ", ".join(
                         f"n = {x['n']}: dense {C.fmt_time(x['wall_dense'])} against sparse {C.fmt_time(x['wall'])}"
                         for x in auto_slow) + ".")
    dd = [(x["n"], x["wall_dense"], _row(runs["ancf"], x["n"]).get("wall_dense")) for x in sp if x.get("wall_dense")]
    dd = [(n, s_, e_) for n, s_, e_ in dd if e_ is not None and e_ < s_]
    if dd:
        lines.append("* Dense against dense: spacar's `method=\"dense\"` is slower than exudyn's dense solver on the ANCF "
                     "cable (" + ", ".join(f"n = {n}: {C.fmt_time(s_)} against {C.fmt_time(e_)}" for n, s_, e_ in dd)
                     + "): it forms the dense reduced matrices on first use (moving the simulation to the state and "
                     "linearizing it, most of its time at n = 200), exudyn's dense export is cheap and its `eigh` the "
                     "same LAPACK.")
    dense_ex = [(x["n"], k, x["wall_dense"]) for k in ("ancf", "ge") for x in runs[k] if x.get("wall_dense")]
    beat = [(n, k, w) for n, k, w in dense_ex if _row(sp, n).get("wall") and w < _row(sp, n)["wall"]]
    if beat:
        lines.append("* exudyn's dense solver beats spacar's sparse path at " + ", ".join(
            f"n = {n} ({NAMES[k]}, {C.fmt_time(w)})" for n, k, w in beat) + ".")
    # accuracy
    worse = []
    for n in cfg["sizes"]:
        s = _row(sp, n).get("errors")
        for k in ("ancf", "ge"):
            e = _row(runs[k], n).get("errors")
            if s and e and e["worst"] < s["worst"]:
                worse.append((n, k, (e["worst"], e.get("worst_mode")), (s["worst"], s.get("worst_mode"))))
    if worse:
        lines.append("* Accuracy: " + "; ".join(f"at n = {n} {NAMES[k]}'s worst error of the ten, {C.fmt_err(e[0])} "
                                                f"({e[1]}), is below spacar's {C.fmt_err(s[0])} ({s[1]})"
                                                for n, k, e, s in worse) + "."
                     + (" spacar's worst mode there is axial: the PLBEAM interpolates the axial displacement linearly, "
                        f"so its axial frequencies converge as n⁻² (the first axial frequency: {_axial_errors(r)}), the ANCF "
                        "cable's cubic field much faster; its bending frequencies agree with the ANCF cable's on coarse "
                        "meshes and are far more accurate on fine ones."
                        if all(str(s[1]).startswith("a") for _, _, _, s in worse) else ""))
    else:
        lines.append("* Accuracy: nowhere; spacar's worst error of the ten is the smallest at every n.")
    mem = {(m["solver"], m["n"]): m for m in r["memory"]}
    heavier = [(n, k) for n in cfg["memory"] for k in ("ancf", "ge")
               if mem.get((k, n), {}).get("solve") is not None and mem.get(("spacar", n), {}).get("solve") is not None
               and mem[(k, n)]["solve"] < mem[("spacar", n)]["solve"]]
    if heavier:
        lines.append("* Memory: the solve adds more to spacar's process than to exudyn's at " + ", ".join(
            f"n = {n} ({NAMES[k]})" for n, k in heavier) + ".")
    else:
        lines.append("* Memory: nowhere; exudyn's `ComputeODE2Eigenvalues` forms M and K as dense matrices (its "
                     "documentation says so) before handing them to scipy's sparse `eigsh`, so its solve grows with "
                     "the square of the coordinates, spacar's linearly.")
    return lines


def section(r: dict, plots: dict | None = None) -> str:
    cfg, runs, ref = r["cfg"], r["runs"], r["reference"]
    mdl = r["model"]
    kinds = ", ".join(f"{f:.4g} ({'b' if k == 'bending' else 'a'}{i})" for f, k, i in
                      zip(ref["f"], ref["kind"], ref["index"]))
    lines = [f"## {TITLE}", "",
             "`python benchmarks/modes.py` (or `benchmarks/run_all.py`): the lowest "
             f"{r['k']} eigenfrequencies of a clamped-free planar beam, L = {mdl['L']:g}, EI = {mdl['EI']:g}, "
             f"ρA = {mdl['rhoA']:g}, EA = {mdl['EA']:g}, n = {', '.join(map(str, cfg['sizes']))} elements. The axial "
             "stiffness is finite: the first axial modes, (2j − 1)/4 · √(EA/ρA)/L = 25 and 75 Hz, are among the "
             f"ten lowest. Reference [Hz] (b: Euler–Bernoulli bending, cos β cosh β = −1 solved to machine precision, "
             f"its first five β equal the tabulated ones to {ref['beta_vs_table']:.0e}; a: axial rod): {kinds}. "
             "Errors are f/f_ref − 1 of the sorted frequencies against the sorted reference.", "",
             "**spacar**: n PLBEAMs, all three deformations DYNE (ESTIFF EA, EI; EMASS ρA), the root's nodes fixed; "
             f"timed `lin = spacar.linearize(model); lin.eigenfrequencies(k={r['k']}, method=\"sparse\")` (the whole "
             "call: the sparse nodal matrices at rest and ARPACK in shift-invert mode on the saddle-point system; the "
             f"model copied outside the timing). Up to n = {cfg['dense_max']} also `method=\"dense\"` (the dense reduced "
             "matrices, linearize included) for reference. "
             f"**exudyn** (`ComputeODE2Eigenvalues`, `mbs.Assemble()` outside the timing): `useSparseSolver=True`, "
             f"`numberOfEigenvalues={r['k']}`, `computeComplexEigenvalues=False`, `convert2Frequencies=True`, the clamp "
             "as exudyn's own eigenvalue examples do it (no constraint objects; the root's coordinates erased from M "
             "and K by `constrainedCoordinates`), SimulationSettings with the sparse linear solver (EigenSparse); "
             f"frequencies below {ZERO:g} of the first analytic one would be dropped as rigid-body or constraint modes "
             "and counted (none occur: the clamped coordinates are removed, not constrained). **exudyn ANCF cable**: "
             "n `ObjectANCFCable2D` on `NodePoint2DSlope1` nodes (cubic Hermite, Euler–Bernoulli), full Gauss "
             "integration, the root's x, y and slope y clamped. **exudyn GE beam**: n "
             "`ObjectBeamGeometricallyExact2D` on `NodeRigidBody2D` nodes (linear interpolation, shear deformable), "
             f"GA = {mdl['GA_factor']:g} EA (the rule of `spacar.compare.exudyn_static`), rotary inertia "
             f"{mdl.get('rhoI_GE', RHO_I_GE):g} ρA L² (with none, M is singular and ARPACK fails on small meshes; the "
             "frequencies move by less than 1e-9), the root's x, y and rotation clamped. Each answer checked against the reference before it is timed. Wall time: best "
             f"of at least {cfg['repeat']} calls lasting {cfg['min_time']:g} s in all (fewer once a solver's calls pass "
             f"{cfg['budget']:g} s), the solvers of a mesh timed in turns. BLAS and LAPACK (numpy's and scipy's "
             "OpenBLAS) run on one thread for both programs: on this shared 2-core machine a second BLAS thread "
             "competing with another process made a 600 × 600 `eigh` 40–65 times slower.", "",
             *C.machine_table(r["machine"]),
             *([f"| load average at end | {r['load_at_end']} |"] if r.get("load_at_end") else []), "",
             *(["**The spacar extension module was rebuilt by another process during this run**: the figures may "
                "mix two builds.", ""] if r.get("extension_rebuilt") else []),
             f"**Wall time** of the {r['k']} lowest (calls timed); degrees of freedom: spacar 3n, ANCF 4n + 1, GE 3n", "",
             "| n | spacar (sparse) | exudyn ANCF cable | exudyn GE beam | ANCF / spacar | GE / spacar |",
             "|---|---|---|---|---|---|"]
    for n in cfg["sizes"]:
        s, a, g = (_row(runs[k], n) for k in SOLVERS)

        def cell(x):
            if not x.get("ok"):
                return f"failed ({x.get('failure')})"
            return f"{C.fmt_time(x.get('wall'))} ({x.get('calls')})"
        lines.append(f"| {n} | {cell(s)} | {cell(a)} | {cell(g)} | {C.fmt_ratio(a.get('wall'), s.get('wall'))} | "
                     f"{C.fmt_ratio(g.get('wall'), s.get('wall'))} |")
    lo = cfg["fit_from"]
    lines += ["", f"Growth from n = {lo} to {cfg['sizes'][-1]} (log-log fit t ∝ nᵖ): "
              + ", ".join(f"{NAMES[k]} p = {_exponent(runs[k], lo):.2f}" for k in SOLVERS) + ".", "",
              f"**Dense paths, n ≤ {cfg['dense_max']}**: spacar `method=\"dense\"` (linearize included) and its "
              "agreement with the sparse path (max relative difference of the ten, required ≤ 1e-9); exudyn with "
              "`useSparseSolver=False` (scipy `eigh` of all eigenvalues, then the ten lowest) on the ANCF cable (the "
              "GE beam's nearly singular M makes `eigh` slow and inaccurate: in the probes only)", "",
              "| n | spacar dense | sparse vs dense | exudyn ANCF dense | exudyn ANCF dense / spacar dense |",
              "|---|---|---|---|---|"]
    for n in [n for n in cfg["sizes"] if n <= cfg["dense_max"]]:
        s, a = _row(runs["spacar"], n), _row(runs["ancf"], n)

        def dcell(x):
            if x.get("dense_ok") is False:
                return f"failed ({x.get('dense_failure')})"
            return C.fmt_time(x.get("wall_dense"))
        lines.append(f"| {n} | {C.fmt_time(s.get('wall_dense'))} | {C.fmt_err(s.get('dense_agreement'))} | "
                     f"{dcell(a)} | {C.fmt_ratio(a.get('wall_dense'), s.get('wall_dense'))} |")
    agree = [x["dense_agreement"] for x in runs["spacar"] if x.get("dense_agreement") is not None]
    if agree:
        lines += ["", f"spacar's sparse and dense paths agree to {max(agree):.0e} relative "
                  f"({'within' if max(agree) <= AGREE else 'NOT within'} the required {AGREE:g})."]
    lines += ["", "**Accuracy**: f/f_ref − 1 of the first five bending modes and the worst |f/f_ref − 1| of all ten "
              "(bending and axial)", "",
              "| n | solver | b1 | b2 | b3 | b4 | b5 | worst of ten |", "|---|---|---|---|---|---|---|---|"]
    for n in cfg["sizes"]:
        for k in SOLVERS:
            x = _row(runs[k], n)
            e = x.get("errors")
            if not e:
                lines.append(f"| {n} | {NAMES[k]} | failed: {x.get('failure')} | | | | | |")
                continue
            lines.append(f"| {n} | {NAMES[k]} | " + " | ".join(_signed(v) for v in e["bending5"]) +
                         f" | {C.fmt_err(e['worst'])} ({e.get('worst_mode')}) |")
    zeros = sorted({x.get("zero_modes") for k in ("ancf", "ge") for x in runs[k] if x.get("zero_modes") is not None})
    drift = max((x.get("timed_vs_checked") or 0.0) for k in ("ancf", "ge") for x in runs[k])
    lines += ["", f"Zero modes dropped from exudyn's answers: {', '.join(map(str, zeros)) or '—'}. exudyn's timed "
              f"answers (scipy's `eigsh` starts from a random vector) differ from the checked ones by at most "
              f"{drift:.0e} relative.", "",
              "**Peak memory** (each solve in a fresh process, `ru_maxrss` in MiB): after the imports (numpy, scipy's "
              "eigensolvers, and spacar or exudyn); what building the model adds (exudyn: with `Assemble`); what the "
              "solve adds over the built model; the process's peak", "",
              "| n | solver | after imports | build | solve | peak | wall (one call) |", "|---|---|---|---|---|---|---|"]
    for m in r["memory"]:
        lines.append(f"| {m['n']} | {NAMES[m['solver']]} | {_mib(m.get('imports'))} | +{_mib(m.get('build'))} | "
                     f"+{_mib(m.get('solve'))} | {_mib(m.get('peak'))} | {C.fmt_time(m.get('wall'))} |")
    lines += ["", "**exudyn's settings**: one change from the chosen settings at a time, n = "
              f"{r['probes'][0]['n'] if r['probes'] else '—'} (best of up to 3 calls; worst |f/f_ref − 1| of the ten)",
              "", "| element | setting | answer | worst error | wall time |", "|---|---|---|---|---|"]
    for p in r["probes"]:
        lines.append(f"| {NAMES[p['solver']]} | {p['setting']} | "
                     f"{'ok' if p['ok'] else 'failed: ' + str(p['failure'])} | {C.fmt_err(p.get('worst'))} | "
                     f"{C.fmt_time(p.get('wall'))} |")
    lines += ["", "**Where spacar loses**", "", *_words(r), "",
              "Fairness: both programs end in scipy's ARPACK (`eigsh`) in shift-invert mode about 0; spacar's "
              "operator is a solve of its own sparse LDLᵀ of the saddle-point system, and its frequencies are the "
              "Rayleigh quotients of the vectors from the elements' energies; exudyn's is scipy's SuperLU of the "
              "clamped K, after M and K are exported as dense arrays (exudyn 1.13 has no sparse export in "
              "`ComputeODE2Eigenvalues`), which is what its wall time and memory grow with. spacar's timed call includes "
              "compiling and assembling its model (`spacar.linearize` starts from the `Model`), exudyn's "
              "`Assemble` is outside the timing. The three discretizations differ: the ANCF cable is cubic in positions like spacar's PLBEAM in bending (their "
              "bending errors match on coarse meshes), the GE beam is linear and shear-deformable (GA = 100 EA: a "
              "floor of the order of EI/(GA L²) = 1e-6 on the first mode), so the accuracy table compares "
              "discretizations and rounding together. Errors that grow with n on fine meshes are rounding: the "
              "condition of the assembled K and M of a fine mesh grows as n⁴ (the stiffest bending mode of an element "
              "against the first mode of the beam), the lowest eigenvalues of the pencil carry ε times it, and "
              "ARPACK's Ritz values keep that; spacar recomputes each frequency as the Rayleigh quotient of its "
              "vector from the elements' energies, which does not."]
    if plots:
        lines += [""] + [f"![{k}]({v})" for k, v in plots.items()]
    return "\n".join(lines) + "\n"


def plot(r: dict) -> dict:
    """No figure: the tables carry the figures (this benchmark writes no image under docs/img)."""
    return {}


def main(argv=None) -> int:
    return C.standard_main("modes", __doc__, run, section, plot, argv)


if __name__ == "__main__":
    sys.exit(main())

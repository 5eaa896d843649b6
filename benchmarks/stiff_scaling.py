"""Part of benchmarks/stiff.py: step counts and time to a tip accuracy as the stiffness grows —
the manual's slider-crank with its rod's EI × k, a steel cantilever of n elements and its spatial
twin of 16 BEAMs bending about both axes — spacar's
DOP853, Radau IIA and automatic choice against exudyn's generalized-α (several spectral radii,
its best reported; a step size at which its Newton iteration fails counts as a miss) and trapezoidal rule on ANCF cable elements
(planar) and geometrically exact beams (spatial, benchmarks/_exudyn_beam3d.py), side by side in one run.

Every series is a sweep from a loose to a tight setting (spacar: EPSINT = EPSIND = EPS; exudyn:
fixed step h) that ends as soon as two settings in a row reach the target (tighter ones only cost
more), or a run exceeds RUN_BUDGET, or a run would exceed RUN_LIMIT (spacar: ``time_limit``;
exudyn: its time per step so far times the steps asked for). Each program's error is measured
against its own tight solution (the ANCF and PLBEAM discretizations differ).
"""
from __future__ import annotations

import numpy as np

import spacar
import _common as C
from spacar.compare import models

METHODS = ["dop853", "radau5", "auto"]
RHO = [0.6, 0.8, 1.0]                 # exudyn generalized-α spectral radii ρ∞ (its default: 0.9)
GA_RHO = [0.8, 1.0]                   # spacar's generalized-α: the spectral radii tried (best reported)
GA_FIXED_EPS = [1e-7, 1e-5, 1e-3]     # its fixed-step runs: EPSINT = EPSIND, which only stop its Newton iterations
# exudyn's Newton relative tolerance, swept as spacar's EPS of the fixed-step runs (None: its default
# 1e-8, or the reference's where that stalls): each program at its best settings.
EXUDYN_NEWTON_RTOL = [None, 1e-6, 1e-4]
EI_ROD = 0.0012723                    # the manual's rod
RHO_I = 6.5e-6                        # spatial case: rotary inertia ρIy = ρIz [kg m] (a 10 mm steel square's)
RUN_BUDGET = 3.0    # s: a series ends after a run this long
RUN_LIMIT = 10.0    # s: no single run longer than this

FULL = {
    "slidercrank": {"variants": [1, 10, 100, 1000, 10000], "t_end": 1.0, "relative_target": 1e-3, "ref_eps": 1e-11,
                    "ref_step": 5e-6},
    "cantilever": {"variants": [4, 8, 16, 32, 64, 128], "t_end": 0.2, "target": 1e-6, "ref_eps": 1e-9, "ref_step": 2e-6},
    # exudyn's beams need seconds per run here: its series go on past RUN_BUDGET, up to RUN_LIMIT
    "spatial": {"variants": [16], "t_end": 0.2, "target": 1e-6, "ref_step": 2e-6, "exudyn_budget": RUN_LIMIT},
    # half decades down to 1e-7, as exudyn's steps come at three a decade
    "eps": [1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 3e-7, 1e-7, 1e-8, 1e-9],
    "steps": [2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5],
}
QUICK = {
    "slidercrank": {"variants": [1, 100], "t_end": 0.05, "relative_target": 1e-3, "ref_eps": 1e-9, "ref_step": 2e-5},
    "cantilever": {"variants": [2, 4], "t_end": 0.02, "target": 1e-6, "ref_eps": 1e-9, "ref_step": 2e-5},
    "spatial": {"variants": [2], "t_end": 0.02, "target": 1e-6, "ref_step": 2e-5},
    "eps": [1e-2, 1e-4, 1e-6],
    "steps": [1e-3, 2e-4],
}


# --- the models and their quantity of interest ---------------------------------------------------

def slidercrank(k, t_end, eps, n_out=1):
    m = models.slider_crank(2, t_end=t_end, n_out=n_out, eps=eps, epskin=min(1e-5, max(1e-13, 1e-3 * eps)))
    for e in (2, 3):
        m.estiff(e, 0.0, k * EI_ROD)
    return m


def cantilever(n, t_end, eps, n_out=1):
    import stiff

    m = stiff.cantilever(n, t_end, eps, damped=False)
    m.timestep(n_out, t_end)
    return m


def spatial(n, t_end, eps, n_out=1):
    import error_control

    m = error_control.spatial(n, eps, rotary=RHO_I)
    m.epskin(1e-10)    # as the planar cantilever's (models.cantilever)
    m.timestep(n_out, t_end)
    return m


BUILD = {"slidercrank": slidercrank, "cantilever": cantilever, "spatial": spatial}
CASES = tuple(BUILD)


def tip(case, variant, x, labels):
    """The quantity whose error is measured. Slider-crank: the deflection of the rod's middle
    (node 6) from the chord between the crank pin (node 3) and the slider (node 8) — its
    positions follow the prescribed crank to within this deflection, which shrinks as 1/k;
    cantilever: the tip's y; spatial: the tip's y and z."""
    def at(n, i):
        return x[labels.index((n, i))]
    if case == "cantilever":
        return np.array([at(variant + 1, 2)])
    if case == "spatial":
        return np.array([at(variant + 1, 2), at(variant + 1, 3)])
    chord = np.array([at(8, 1) - at(3, 1), at(8, 2) - at(3, 2)])
    mid = np.array([at(6, 1) - at(3, 1), at(6, 2) - at(3, 2)])
    return np.array([(chord[0] * mid[1] - chord[1] * mid[0]) / np.hypot(*chord)])




# --- sweeps ------------------------------------------------------------------------------------

def _sweep(settings, run_one, target, budget):
    """run_one(setting) -> dict with wall, error (or None: over the limit); loose to tight."""
    out, hits = [], 0
    for s in settings:
        r = run_one(s)
        if r is None:
            out.append({"setting": s, "over_limit": True})
            break
        r["setting"] = s
        out.append(r)
        hits = hits + 1 if r["error"] <= target else 0
        if hits >= 2 or r["wall"] >= budget:    # (a failed run has a NaN wall time: go on)
            break
    return out


def _spacar_series(case, cfg, variant, method, ref, target, quick, eps_list, fixed=None, **options):
    """A sweep of EPS (fixed None) or, for generalized_alpha with fixed = an EPS, of the fixed step h
    at EPS = fixed (a number); options: further arguments of simulate (rho_inf)."""
    def one(setting):
        eps = fixed if fixed else setting
        run_options = dict(options, **({"fixed_step": setting} if fixed else {}))
        m = BUILD[case](variant, cfg["t_end"], eps)
        label = f"{method} {' '.join(f'{k}={v:g}' for k, v in run_options.items())} {'h' if fixed else 'eps'}={setting:g}"
        try:
            res, wall = C.simulate_best(m, repeat=1 if quick else 3, budget=0.2 if quick else 2 * RUN_BUDGET,
                                        method=method, progress=False, time_limit=RUN_LIMIT, **run_options)
        except spacar.TimeLimitError:
            C.log(f"stiff scaling {case} {variant} {label}: over {RUN_LIMIT:g} s")
            return None
        err = float(np.abs(tip(case, variant, res.x[-1], res.coordinate_labels) - ref).max())
        st = res.stats
        C.log(f"stiff scaling {case} {variant} {label}: {wall:.3g} s, error {err:.2e}, "
              f"{st['steps']} steps, {st.get('method', method)}")
        return {"wall": wall, "error": err, "steps": st["steps"], "rhs": st["rhs_evaluations"],
                "method": st.get("method", method)}

    return _sweep(eps_list, one, target, RUN_BUDGET)


def _exudyn_solver(em, case, cfg, variant, solver, rho, h, newton_rtol=None):
    def configure(s):
        if rho is not None:
            s.timeIntegration.generalizedAlpha.spectralRadius = rho
        if newton_rtol is not None:
            s.timeIntegration.newton.relativeTolerance = newton_rtol
    r = em.solve(t_end=cfg["t_end"], n_out=1, solver=solver, step=h, configure=configure)
    return r, tip(case, variant, r.x[-1], em.labels)


def _exudyn_reference(em, case, cfg, variant):
    """exudyn's tight solution, generalized-α at ρ∞ = 1 and cfg["ref_step"]; where its Newton
    iteration stalls at round-off with the default tolerance (1e-8 relative; the stiffest rods),
    with 1e-6 as in benchmarks/cantilever.py. Returns (value, Newton tolerance used) or (None, None)."""
    import exudyn as exu

    for rtol in (None, 1e-6):
        try:
            return _exudyn_solver(em, case, cfg, variant, "generalized_alpha", 1.0, cfg["ref_step"], rtol)[1], rtol
        except (RuntimeError, exu.SolverError):
            C.log(f"stiff scaling {case} {variant} exudyn reference failed with Newton rtol {rtol or 1e-8:g}")
    return None, None


def _exudyn_series(em, case, cfg, variant, solver, rho, ref, target, quick, steps, newton_rtol):
    import exudyn as exu

    per_step = [0.0]

    def one(h):
        n = round(cfg["t_end"] / h)
        if per_step[0] * n > RUN_LIMIT:
            return None
        try:
            wall, (r, x) = C.best_time(lambda: _exudyn_solver(em, case, cfg, variant, solver, rho, h, newton_rtol),
                                       repeat=1 if quick else 3, budget=2 * RUN_BUDGET)
        except (RuntimeError, exu.SolverError) as exc:   # Newton did not converge at this step size
            C.log(f"stiff scaling {case} {variant} exudyn {solver} rho={rho} h={h:g}: failed ({exc})")
            return {"wall": float("nan"), "error": float("inf"), "steps": n, "failed": True}
        per_step[0] = wall / n
        err = float(np.abs(x - ref).max())
        C.log(f"stiff scaling {case} {variant} exudyn {solver} rho={rho} h={h:g}: {wall:.3g} s, error {err:.2e}")
        return {"wall": wall, "error": err, "steps": n}

    return _sweep(steps, one, target, cfg.get("exudyn_budget", RUN_BUDGET))


def richardson_reference(case, cfg, variant):
    """The tip at the end from generalized-α (ρ∞ = 1) at fixed steps 4e-5 and 2e-5 s, extrapolated
    for its second order."""
    def at(h):
        res = spacar.simulate(BUILD[case](variant, cfg["t_end"], 1e-10), method="generalized_alpha", rho_inf=1.0,
                              fixed_step=h, progress=False)
        return tip(case, variant, res.x[-1], res.coordinate_labels)
    coarse, fine = at(4e-5), at(2e-5)
    return fine + (fine - coarse) / 3.0


def run_case(case, quick):
    from spacar.compare import exudyn as sx

    cfg_all = QUICK if quick else FULL
    cfg = cfg_all[case]
    out = {}
    for variant in cfg["variants"]:
        # DOP853's steps on these models are set by stability: at a tight EPS it is accurate far
        # beyond the target and cheaper than Radau (whose undamped 32-element cantilever at EPS 1e-9
        # takes 474 000 steps). Beyond 32 elements its steps (∝ n²) take minutes: there the
        # reference is generalized-α's, Richardson-extrapolated from fixed steps 4e-5 and 2e-5 s (as
        # benchmarks/error_control.py; within 2e-10 m of DOP853's at 16 elements); the spatial
        # beam's too (its torsion adds modes DOP853 must resolve).
        if case == "spatial" or (case == "cantilever" and variant > 32):
            ref = richardson_reference(case, cfg, variant)
            ref_res = None
        else:
            ref_res = spacar.simulate(BUILD[case](variant, cfg["t_end"], cfg["ref_eps"], n_out=50), method="dop853",
                                      progress=False)
            ref = tip(case, variant, ref_res.x[-1], ref_res.coordinate_labels)
        if case == "slidercrank":   # a fraction of the rod's largest deflection over the run
            amplitude = max(abs(tip(case, variant, x, ref_res.coordinate_labels)[0]) for x in ref_res.x)
            target = cfg["relative_target"] * amplitude
        else:
            amplitude, target = None, cfg["target"]
        row = {"target": target, "amplitude": amplitude,
               "spacar": {m: _spacar_series(case, cfg, variant, m, ref, target, quick, cfg_all["eps"])
                          for m in METHODS}}
        row["spacar_ga"] = {f"ρ∞={rho:g}": _spacar_series(case, cfg, variant, "generalized_alpha", ref, target, quick,
                                                          cfg_all["eps"], rho_inf=rho) for rho in GA_RHO}
        row["spacar_ga_fixed"] = {f"ρ∞={rho:g}, EPS {eps:g}": _spacar_series(
            case, cfg, variant, "generalized_alpha", ref, target, quick, cfg_all["steps"], fixed=eps, rho_inf=rho)
            for rho in GA_RHO for eps in GA_FIXED_EPS}
        if case == "spatial":
            import _exudyn_beam3d

            em = _exudyn_beam3d.build(variant, rotary=RHO_I)
        else:
            em = sx.build(BUILD[case](variant, cfg["t_end"], 1e-6),
                          **({"axial_stiffness": 1e4 * 175.0} if case == "cantilever" else {}))
        ex_ref, row["exudyn_reference_newton_rtol"] = _exudyn_reference(em, case, cfg, variant)
        if ex_ref is None:
            row["model_difference"], row["exudyn"], row["exudyn_trapezoidal"] = None, {}, {}
            out[variant] = row
            continue
        row["model_difference"] = float(np.abs(ex_ref - ref).max())
        rtols = list(dict.fromkeys(r or row["exudyn_reference_newton_rtol"] for r in EXUDYN_NEWTON_RTOL))
        newton = lambda r: f", Newton {r:g}" if r else ""   # noqa: E731
        row["exudyn"] = {f"GA ρ∞={rho:g}{newton(r)}": _exudyn_series(em, case, cfg, variant, "generalized_alpha", rho,
                                                                     ex_ref, target, quick, cfg_all["steps"], r)
                         for rho in RHO for r in rtols}
        row["exudyn_trapezoidal"] = {f"trapezoidal{newton(r)}": _exudyn_series(
            em, case, cfg, variant, "trapezoidal", None, ex_ref, target, quick, cfg_all["steps"], r) for r in rtols}
        out[variant] = row
    return out


def run(quick):
    cfg = QUICK if quick else FULL
    return {"config": cfg, **{case: run_case(case, quick) for case in CASES}}


# --- section -----------------------------------------------------------------------------------

def steady(series, target):
    """The fastest run from which on every tighter run of the series reaches the target (the
    series ends with two such runs, see _sweep); None if the series did not end on target. A last
    setting stopped at (spacar) or refused for (exudyn) the time limit counts as neither, as the
    settings after a run past the budget: the run before it may be the only one on target."""
    if series and series[-1].get("over_limit"):
        series = series[:-1]
    best = None
    for r in reversed(series):
        if r["error"] > target:
            break
        if best is None or r["wall"] < best["wall"]:
            best = r
    return best


def _cell(r, fmt_setting):
    if r is None:
        return "—"
    return f"{C.fmt_time(r['wall'])} / {r['steps']} / {fmt_setting(r['setting'])}"


def _steps_at(series, eps):
    r = next((x for x in series if x["setting"] == eps), None)
    return "—" if r is None or r.get("over_limit") else str(r["steps"])


def _best_of(series_by_key, target):
    """The steady run of the fastest series (key, run), or (None, None)."""
    ok = {k: steady(v, target) for k, v in series_by_key.items()}
    ok = {k: v for k, v in ok.items() if v is not None}
    key = min(ok, key=lambda k: ok[k]["wall"]) if ok else None
    return key, ok.get(key)


def _table(res, case, cfg):
    head = "k (rod EI × k)" if case == "slidercrank" else "n (elements)"
    eps0 = cfg["eps"][0]
    lines = [f"| {head} | target [m] | dop853 | radau5 | auto | generalized_alpha (EPS), best ρ∞ | generalized_alpha "
             f"(fixed h), best ρ∞ | exudyn GA, best ρ∞ | exudyn trapezoidal | exudyn best / spacar best | "
             f"exudyn best / auto (the default, EPS alone) | dop853 / spacar best | model difference [m] | "
             f"steps at EPS {eps0:g}: dop853 / radau5 / auto |",
             "|---" * 14 + "|"]
    for variant, row in res[case].items():
        target = row["target"]
        sp = {m: steady(row["spacar"][m], target) for m in METHODS}
        sga_key, sga = _best_of(row.get("spacar_ga", {}), target)
        sgf_key, sgf = _best_of(row.get("spacar_ga_fixed", {}), target)
        ga_key, ga = _best_of(row["exudyn"], target)
        tr_key, tr = _best_of(row["exudyn_trapezoidal"], target)
        best_sp = min((v["wall"] for v in [*(v for k, v in sp.items() if k != "dop853"), sga, sgf] if v is not None),
                      default=None)
        best_ex = min((v["wall"] for v in (ga, tr) if v is not None), default=None)
        eps = lambda s: f"EPS {s:g}"   # noqa: E731
        step = lambda s: f"h {s:g}"    # noqa: E731
        keyed = lambda r, k, fmt: "—" if r is None else f"{_cell(r, fmt)} ({k.replace('GA ', '')})"  # noqa: E731
        lines.append(f"| {variant} | {target:.1e} | {_cell(sp['dop853'], eps)} | {_cell(sp['radau5'], eps)} | {_cell(sp['auto'], eps)} | "
                     f"{keyed(sga, sga_key, eps)} | {keyed(sgf, sgf_key, step)} | "
                     f"{keyed(ga, ga_key, step)} | {keyed(tr, tr_key, step)} | {C.fmt_ratio(best_ex, best_sp)} | "
                     f"{C.fmt_ratio(best_ex, sp['auto'] and sp['auto']['wall'])} | "
                     f"{C.fmt_ratio(sp['dop853'] and sp['dop853']['wall'], best_sp)} | "
                     f"{C.fmt_err(row['model_difference'])} | {' / '.join(_steps_at(row['spacar'][m], eps0) for m in METHODS)} |")
    return lines


def section_lines(res) -> list:
    cfg = res["config"]
    sc, ca = cfg["slidercrank"], cfg["cantilever"]
    lines = ["### Step counts against stiffness: slider-crank with a stiffer rod, cantilever with more elements", "",
             "Written by the same script (`benchmarks/stiff_scaling.py`). Time to the same accuracy, each program "
             "against its own tight solution, side by side in one run:",
             "",
             f"* the manual's slider-crank (`examples/slidercrank.dat`, rod of 2 PLBEAMs) with the rod's EI × k, "
             f"{sc['t_end']:g} s; error: of the rod middle's deflection from the chord crank pin–slider at the end "
             "(the positions themselves follow the prescribed crank to within this deflection, which shrinks as 1/k); "
             f"target: {sc['relative_target']:g} × the largest deflection over the run. exudyn: the model converted by "
             "`spacar.compare.exudyn` (ANCF cables with the penalty axial stiffness 1e4·EI/l0²);",
             f"* the steel cantilever above with n PLBEAMs (2n DOFs), undamped, {ca['t_end']:g} s; error: tip y at the "
             f"end; target {ca['target']:g} m. exudyn: n ANCF cables, EA = 1e4·EI/L²;",
             "* its spatial twin (benchmarks/error_control.py's `spatial`): n BEAMs bending about both axes "
             f"(EIz = 4 EIy, torsion GJ = EI, gravity off both axes, rotary inertia ρIy = ρIz = {RHO_I:g} kg m), "
             "undamped, same span; error: the larger of the tip's "
             "y and z errors at the end; target as the cantilever's. exudyn: n `ObjectBeamGeometricallyExact` "
             "(Simo–Reissner, interpolated on SE(3); Tait–Bryan nodes, since its Lie-group nodes do not converge under "
             "generalized-α; without the rotary inertia its error falls only as h¹), penalty EA = GA = 1e4·EI "
             "(benchmarks/_exudyn_beam3d.py); its runs take seconds, so its "
             f"series go on past a run of {RUN_BUDGET:g} s up to the limit below. Where the table has no "
             "spatial row, the run predates it.",
             "",
             f"spacar's reference: dop853 at EPS = {sc['ref_eps']:g} (slider-crank), {ca['ref_eps']:g} (cantilever up to 32 elements; "
             "beyond, where DOP853's steps take minutes, and the spatial cantilever: generalized-α at fixed steps 4e-5 "
             "and 2e-5 s, Richardson-extrapolated); exudyn's: its generalized-α at ρ∞ = 1 and h = "
             f"{sc['ref_step']:g} s (slider-crank), {ca['ref_step']:g} s (cantilevers) (\"model difference\": between "
             "the two references). spacar: EPSINT = EPSIND = EPS "
             f"from {cfg['eps'][0]:g} down to {cfg['eps'][-1]:g}; exudyn: fixed steps h from {cfg['steps'][0]:g} s "
             f"down to {cfg['steps'][-1]:g} s, generalized-α with ρ∞ = {', '.join(f'{r:g}' for r in RHO)} (the best "
             "reported) and the trapezoidal rule (`TrapezoidalIndex2`). A series ends after two settings in a row "
             f"reach the target, after a run of {RUN_BUDGET:g} s, or before a run beyond {RUN_LIMIT:g} s. Cell: the "
             "*steady* time to the target (the fastest run from which on every tighter run of the series reaches it; "
             "a last setting stopped at the time limit counts as neither, so a cell may rest on one run on target) "
             "/ its steps / its setting; \"—\": the series did not reach the target within the limits. spacar's "
             f"generalized-α: ρ∞ = {', '.join(f'{r:g}' for r in GA_RHO)} (the best reported), with its error control "
             f"(EPS as above) and with fixed steps h as exudyn's (EPS = {', '.join(f'{e:g}' for e in GA_FIXED_EPS)} "
             "then only stops its Newton iterations; the best reported); exudyn's Newton relative tolerance "
             f"{', '.join('its default' if r is None else f'{r:g}' for r in EXUDYN_NEWTON_RTOL)} (the best reported). "
             "Ratios against the fastest of radau5, auto and generalized-α. The last column, the steps at the loosest setting (run "
             "by every series that did not stop before it), shows the growth with the stiffness itself: DOP853's steps are set by "
             "stability there.", ""]
    loose = [f"{case} {v}" for case in CASES for v, row in res.get(case, {}).items()
             if row.get("exudyn_reference_newton_rtol")]
    if loose:
        lines += [f"exudyn's reference with Newton tolerance 1e-6 relative (its default 1e-8 stalls at its reference step; "
                  f"then also in place of the default in the sweep): "
                  f"{', '.join(loose)}.", ""]
    for case, info in res.get("measured_apart", {}).items():
        eps = f", spacar's EPS {', '.join(f'{e:g}' for e in info['eps'])}" if info.get("eps") else ""
        lines += [f"The {case} case was measured apart (`python benchmarks/stiff.py --scaling-case {case}`) on "
                  f"{info.get('date', '?')}, on {info.get('CPU', '?')}{eps}; compare its ratios, not its times, with "
                  "the other tables.", ""]
    for case, title in (("slidercrank", "Slider-crank, rod EI × k"), ("cantilever", "Steel cantilever, n PLBEAMs"),
                        ("spatial", "Spatial steel cantilever, n BEAMs")):
        if case not in res:
            continue
        lines += [f"**{title}**: wall time / steps / setting", "", *_table(res, case, cfg), ""]
    return lines

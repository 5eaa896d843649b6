"""The spin-up case of issue 36 (docs/stiff-integration.md#tolerances-that-fit-together): a
steel beam of 16 PLBEAMs (EI 175 N m², ρA 0.785 kg/m, 1 m, no gravity, undamped) whose root
BETA is an input driven by a cubic ``spacar.Table``: from rest to 3 rad/s over a ramp of 1 s
(rate ½·3·(1 − cos πt), smooth in rate and acceleration), then at 3 rad/s, a knot every 0.025 s.
EPSINT = EPSIND = EPS; each method with SPACAR's default EPSKIN 1e-5 (which the position solves
tighten to 1e-4 EPS: ``kinematic_tolerance`` in cpp/src/kinematics/kinematics.cpp) and with EPSKIN
1e-12. Printed: wall time, steps, rejected steps, Jacobians, and the tip's distance
from the first run's (the answers agree).

With ``--reference``, also each run's largest tip error over the outputs, as a multiple of EPS,
against generalized-α at fixed steps of 2e-5 and 1e-5 s (ρ∞ = 1, EPS 1e-10 for its Newton
iterations) extrapolated (Richardson, second order): about 25 s per second of motion; the two
fixed-step runs agree with the extrapolation to 1.3e-9 and 3.2e-10 m over 3 s, and a Radau5 run
at EPS 1e-10 with it to 7e-11 m.

    python benchmarks/spin_up.py                  # 3 s, EPS 1e-8, radau5, auto, generalized_alpha
    python benchmarks/spin_up.py 20 1e-8 radau5   # t_end, EPS, methods (comma-separated)
    python benchmarks/spin_up.py --reference 3 1e-6
"""
from __future__ import annotations

import sys
import time

import numpy as np

import spacar
from spacar.compare import models

RATE, RAMP, KNOT = 3.0, 1.0, 0.025
TIP = 17


def model(t_end: float, eps: float, epskin: float):
    m = models.cantilever(16, ei=175.0, rho_a=0.785, t_end=t_end, n_out=20, eps=eps, epskin=epskin)
    m.gravity(0.0, 0.0)
    m.inputx(10001, 1)
    t = np.linspace(0.0, t_end, round(t_end / KNOT) + 1)
    ramp = 0.5 * RATE * (t - np.sin(np.pi * t / RAMP) * RAMP / np.pi)
    angle = np.where(t < RAMP, ramp, 0.5 * RATE * RAMP + RATE * (t - RAMP))
    return m, {(10001, 1): spacar.Table(t, angle, kind="cubic")}


def tips(res: spacar.Results) -> np.ndarray:
    return res.node(TIP).x[:, :2]


def reference(t_end: float) -> np.ndarray:
    """The tip at the outputs: generalized-α at fixed steps h and h/2, extrapolated."""
    runs = []
    for h in (2e-5, 1e-5):
        m, inputs = model(t_end, 1e-10, 1e-12)
        runs.append(tips(spacar.simulate(m, method="generalized_alpha", fixed_step=h, rho_inf=1.0,
                                         inputs=inputs, progress=False)))
    coarse, fine = runs
    return fine + (fine - coarse) / 3.0


def main(t_end=3.0, eps=1e-8, methods=("radau5", "auto", "generalized_alpha"), with_reference=False) -> None:
    print(f"spin-up over {t_end:g} s, EPS {eps:g}\n")
    ref = reference(t_end) if with_reference else None
    error_head = " largest tip error / EPS |" if with_reference else ""
    print(f"| method | EPSKIN | wall | steps | rejected | Jacobians | tip − first run's [m] |{error_head}\n"
          f"|---|---|---|---|---|---|---|{'---|' if with_reference else ''}")
    first = None
    for method in methods:
        for epskin in (1e-5, 1e-12):
            m, inputs = model(t_end, eps, epskin)
            start = time.perf_counter()
            try:
                res = spacar.simulate(m, method=method, inputs=inputs, progress=False, time_limit=600)
            except spacar.TimeLimitError as exc:
                print(f"| {method} | {epskin:g} | over 600 s ({exc}) | | | | |{' |' if with_reference else ''}", flush=True)
                continue
            wall = time.perf_counter() - start
            path = tips(res)
            tip = path[-1]
            first = tip if first is None else first
            s = res.stats
            error = (f" {np.linalg.norm(path - ref, axis=1).max() / eps:.2g} |" if with_reference else "")
            print(f"| {s.get('method', method)} | {epskin:g} | {wall:.2f} s | {s['steps']} | "
                  f"{s.get('rejected', '—')} | {s.get('jacobians', '—')} | {np.abs(tip - first).max():.1e} |{error}",
                  flush=True)


if __name__ == "__main__":
    flags = [v for v in sys.argv[1:] if v.startswith("--")]
    if set(flags) - {"--reference"}:
        sys.exit(f"unknown option {', '.join(sorted(set(flags) - {'--reference'}))}; usage: see the module's docstring")
    a = [v for v in sys.argv[1:] if not v.startswith("--")]
    main(float(a[0]) if a else 3.0, float(a[1]) if len(a) > 1 else 1e-8,
         tuple(a[2].split(",")) if len(a) > 2 else ("radau5", "auto", "generalized_alpha"),
         with_reference="--reference" in sys.argv[1:])

"""The spin-up case of issue 36 (docs/stiff-integration.md#tolerances-that-fit-together): a
steel beam of 16 PLBEAMs (EI 175 N m², ρA 0.785 kg/m, 1 m, no gravity, undamped) whose root
BETA is an input driven by a cubic ``spacar.Table``: from rest to 3 rad/s over a ramp of 1 s
(rate ½·3·(1 − cos πt), smooth in rate and acceleration), then at 3 rad/s, a knot every 0.025 s.
EPSINT = EPSIND = EPS; each method with SPACAR's default EPSKIN 1e-5 (which the position solves
tighten to 1e-4 EPS: ``kinematic_tolerance`` in cpp/src/kinematics/kinematics.cpp) and with EPSKIN
1e-12. Printed: wall time, steps, rejected steps, Jacobians, and the tip's distance
from the first run's (the answers agree).

    python benchmarks/spin_up.py                  # 3 s, EPS 1e-8, radau5, auto, generalized_alpha
    python benchmarks/spin_up.py 20 1e-8 radau5   # t_end, EPS, methods (comma-separated)
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


def main(t_end=3.0, eps=1e-8, methods=("radau5", "auto", "generalized_alpha")) -> None:
    print(f"spin-up over {t_end:g} s, EPS {eps:g}\n")
    print("| method | EPSKIN | wall | steps | rejected | Jacobians | tip − first run's [m] |\n|---|---|---|---|---|---|---|")
    first = None
    for method in methods:
        for epskin in (1e-5, 1e-12):
            m, inputs = model(t_end, eps, epskin)
            start = time.perf_counter()
            try:
                res = spacar.simulate(m, method=method, inputs=inputs, progress=False, time_limit=600)
            except spacar.TimeLimitError as exc:
                print(f"| {method} | {epskin:g} | over 600 s ({exc}) | | | | |", flush=True)
                continue
            wall = time.perf_counter() - start
            tip = res.node(TIP).x[-1, :2]
            first = tip if first is None else first
            s = res.stats
            print(f"| {s.get('method', method)} | {epskin:g} | {wall:.2f} s | {s['steps']} | "
                  f"{s.get('rejected', '—')} | {s.get('jacobians', '—')} | {np.abs(tip - first).max():.1e} |", flush=True)


if __name__ == "__main__":
    a = sys.argv[1:]
    main(float(a[0]) if a else 3.0, float(a[1]) if len(a) > 1 else 1e-8,
         tuple(a[2].split(",")) if len(a) > 2 else ("radau5", "auto", "generalized_alpha"))

"""Benchmark: the cost of time-dependent loads (docs/mechatronics.md). The flexible arm of
tests/core/test_energy.py (2 PLBEAMs, 5 DOFs, 1 s, EPSINT 1e-10) without load, and driven by the
hinge torque 30 sin 2πt given as a cubic spacar.Table (evaluated in C++) and as a Python function
f(t) (one call per right-hand side); and the table run with energy=True. Best wall time of
spacar.simulate over repeats; the function's cost per right-hand side is the difference to the
table run divided by its right-hand sides.

    python benchmarks/time_loads.py [--repeats N]
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

import spacar

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "core"))
from test_energy import flexible_arm  # noqa: E402


def best(run, repeats):
    times, res = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = run()
        times.append(time.perf_counter() - t0)
    return min(times), res


def main(repeats=5):
    ts = np.linspace(0.0, 1.0, 201)
    table = spacar.Table(ts, 30.0 * np.sin(2 * np.pi * ts))
    cases = {
        "no load": lambda: spacar.simulate(flexible_arm(), progress=False),
        "table": lambda: spacar.simulate(flexible_arm(), forces={2: table}, progress=False),
        "function": lambda: spacar.simulate(flexible_arm(), forces={2: lambda t: [30.0 * np.sin(2 * np.pi * t)]},
                                            progress=False),
        "table + energy": lambda: spacar.simulate(flexible_arm(), forces={2: table}, energy=True, progress=False),
    }
    out = {name: best(run, repeats) for name, run in cases.items()}
    base = out["table"][0]
    for name, (t, res) in out.items():
        print(f"{name:16s} {t * 1e3:8.2f} ms  {res.stats['rhs_evaluations']:6d} rhs  "
              f"{t / res.stats['rhs_evaluations'] * 1e6:6.2f} µs/rhs  ×{t / base:.2f} of the table run")
    (tf, rf), (tt, rt) = out["function"], out["table"]
    print(f"Python function: {(tf - tt) / rf.stats['rhs_evaluations'] * 1e6:.2f} µs per right-hand side more than the table")


if __name__ == "__main__":
    main(int(sys.argv[sys.argv.index("--repeats") + 1]) if "--repeats" in sys.argv else 5)

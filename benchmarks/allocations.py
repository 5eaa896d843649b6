"""Heap allocations in the integration loop: counts malloc calls during `spacar.simulate` of the
manual's slider-crank over 5 s and over 50 s (ten times the right-hand sides, the same number of
output times), and of a 20-link chain (benchmarks/chains.py) over 0.3 s and 3 s. The difference
divided by the extra right-hand sides is the number of allocations per right-hand side: 0 (the
factorizations replay their pivot sequence in arrays allocated at the first one).

Needs a C compiler (to build a malloc-counting shim, preloaded into a child Python process).
Usage: python benchmarks/allocations.py
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

SHIM = r"""
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stddef.h>
static long n = 0;
static void* (*real_malloc)(size_t) = 0;
void* malloc(size_t s) { if (!real_malloc) real_malloc = dlsym(RTLD_NEXT, "malloc"); n++; return real_malloc(s); }
long spacar_malloc_count(void) { return n; }
"""

CHILD = r"""
import ctypes, sys, spacar
count = ctypes.CDLL(None).spacar_malloc_count
count.restype = ctypes.c_long
from spacar.compare import models
chain = sys.argv[1].startswith("chain:")
for period in ((0.3, 3.0) if chain else (5.0, 50.0)):
    if chain:
        model = models.planar_chain(int(sys.argv[1][6:]), t_end=period, n_out=10, eps=1e-6)
    else:
        model = spacar.read(sys.argv[1])
        model.timestep(100, period)
    model.prepare()
    before = count()
    res = spacar.simulate(model)
    print(period, res.stats["rhs_evaluations"], count() - before)
"""


def measure(example):
    with tempfile.TemporaryDirectory() as tmp:
        shim = Path(tmp) / "count.so"
        src = Path(tmp) / "count.c"
        src.write_text(SHIM)
        subprocess.run(["cc", "-shared", "-fPIC", "-O2", "-o", str(shim), str(src), "-ldl"], check=True)
        env = dict(os.environ, LD_PRELOAD=str(shim))
        out = subprocess.run([sys.executable, "-c", CHILD, example], env=env, check=True,
                             capture_output=True, text=True).stdout
    rows = [tuple(float(v) for v in line.split()) for line in out.splitlines()]
    (_, rhs1, m1), (_, rhs2, m2) = rows
    return rhs1, m1, rhs2, m2, (m2 - m1) / (rhs2 - rhs1)


def main():
    example = Path(__file__).resolve().parents[1] / "examples" / "slidercrank.dat"
    for name, case in (("slider-crank", str(example)), ("20-link chain", "chain:20")):
        rhs1, m1, rhs2, m2, per_rhs = measure(case)
        print(f"{name}: {rhs1:.0f} right-hand sides, {m1:.0f} allocations; {rhs2:.0f} right-hand sides, "
              f"{m2:.0f} allocations; {per_rhs:.3f} allocations per right-hand side")


if __name__ == "__main__":
    main()

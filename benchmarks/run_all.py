"""Run every benchmark and write its section of docs/performance.md (and the plots under
docs/img/): the manual's slider-crank (spacar alone, benchmarks/slidercrank.py), then spacar
side by side with the peers — rigid chains (chains.py), the UR5 and Panda robots (robots.py), closed
loops on the recursive path (closed_loops.py), the four-bar (fourbar.py), Newton's
iterations of the general path with its predictor and chord (newton.py, spacar alone), the flexible
cantilever (cantilever.py), the manual's slider-crank against exudyn (slidercrank_exudyn.py) and
the steel cantilever's time to tip accuracy with the stiff integrator (stiff.py) and the
static solve of a large-deflection cantilever against exudyn's SolveStatic (statics.py).

    python benchmarks/run_all.py [--quick] [--no-write] [--only chains fourbar ...]

``--quick`` runs tiny sizes in seconds (the smoke test of tests/peers/test_benchmarks.py; it writes
nothing unless asked to, so the committed figures stay those of a full run). A full run takes
about 25–30 minutes on the machine of docs/performance.md: about 10 in the stiff integration's
step-count series (stiff.py), most of the rest in the 1000-element cantilever and the chains.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import cantilever  # noqa: E402
import chains  # noqa: E402
import closed_loops  # noqa: E402
import fourbar  # noqa: E402
import modes  # noqa: E402
import newton  # noqa: E402
import robots  # noqa: E402
import slidercrank  # noqa: E402
import slidercrank_exudyn  # noqa: E402
import statics  # noqa: E402
import stiff  # noqa: E402

CASES = {
    "slidercrank": slidercrank,
    "chains": chains,
    "robots": robots,
    "closed_loops": closed_loops,
    "fourbar": fourbar,
    "newton": newton,
    "cantilever": cantilever,
    "slidercrank_exudyn": slidercrank_exudyn,
    "stiff": stiff,
    "statics": statics,
    "modes": modes,
}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="tiny sizes (smoke test); implies --no-write unless --write")
    p.add_argument("--write", action="store_true", help="write docs/performance.md even with --quick")
    p.add_argument("--no-write", action="store_true", help="do not update docs/performance.md")
    p.add_argument("--only", nargs="*", choices=sorted(CASES), help="run only these cases")
    a = p.parse_args(argv)
    write = not a.no_write and (a.write or not a.quick)
    for name in a.only or list(CASES):
        mod = CASES[name]
        args = []
        if name == "slidercrank":
            args = ["-n", "2", "--cli-repeats", "0"] if a.quick else []
        elif a.quick:
            args = ["--quick"]
        if not write:
            args.append("--no-write")
        start = time.perf_counter()
        print(f"=== {name} ===", flush=True)
        rc = mod.main(args)
        print(f"=== {name}: {time.perf_counter() - start:.1f} s ===", flush=True)
        if rc:
            return rc
    return 0


if __name__ == "__main__":
    sys.exit(main())

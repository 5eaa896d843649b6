"""Instructions per run, counted by callgrind inside `Simulation::run` (deterministic, whatever the
machine's load): the check that a reorganisation changed no work done per run (issues 18 and 35,
docs/performance.md). Each case runs in its own valgrind process.

    python benchmarks/instructions.py                 # every case
    python benchmarks/instructions.py spatial5 ...    # some cases
    python benchmarks/instructions.py --run CASE      # one run, in the process valgrind watches

Needs valgrind on the PATH (Debian: apt install valgrind)."""
from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples"


def cases():
    """name → (model, simulate's keyword arguments): the paths and steppers of a run."""
    import spacar
    from spacar.compare import models

    chain20 = lambda: models.planar_chain(20, rho_a=1.0, angle=0.0, t_end=0.3, n_out=1, eps=1e-6,  # noqa: E731
                                         epskin=1e-9)
    beam8 = lambda: models.cantilever(8, t_end=0.1, n_out=5, eps=1e-6)  # noqa: E731
    return {
        "slidercrank": lambda: (spacar.read(EXAMPLES / "slidercrank.dat"), {}),
        "chain20_general": lambda: (chain20(), {"recursive": False, "method": "dop853"}),
        "chain20_tree": lambda: (chain20(), {"method": "dop853"}),
        "spatial5": lambda: (models.spatial_chain(5, seed=5, t_end=0.3, n_out=1, eps=1e-6, epskin=1e-9),
                             {"method": "dop853"}),
        "cantilever8_dop853": lambda: (beam8(), {"method": "dop853"}),
        "cantilever8_radau5": lambda: (beam8(), {"method": "radau5"}),
        "cantilever8_ga": lambda: (beam8(), {"method": "generalized_alpha"}),
        "steel8_auto": lambda: (models.cantilever(8, ei=175.0, rho_a=0.785, t_end=0.2, n_out=1, eps=1e-2),
                                {"method": "auto"}),
        "cantilever40_ga_sparse": lambda: (models.cantilever(40, t_end=0.02, n_out=5, eps=1e-5),
                                           {"method": "generalized_alpha"}),
    }


def run_case(name: str) -> None:
    import spacar

    model, kwargs = cases()[name]()
    spacar.simulate(model, progress=False, **kwargs)


def count(name: str) -> int:
    out = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null",
                          "--toggle-collect=spacar::Simulation::run(spacar::BlockResults&*",
                          sys.executable, __file__, "--run", name], capture_output=True, text=True, check=True)
    return int(re.search(r"refs:\s+([\d,]+)", out.stderr).group(1).replace(",", ""))


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["--run"]:
        run_case(argv[1])
        return 0
    if shutil.which("valgrind") is None:
        print("valgrind is not on the PATH", file=sys.stderr)
        return 1
    for name in argv or list(cases()):
        print(f"{name} {count(name)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""What EPSINT bounds (issue 36, docs/stiff-integration.md "What EPSINT bounds, measured"): the tip
error of steel cantilevers (EI 175 N m², ρA 0.785 kg/m, gravity, 0.2 s, EPSKIN 1e-12) against a
Richardson-extrapolated reference (generalized-α, ρ∞ = 1, fixed steps 4e-5 and 2e-5 s), as a
multiple of the EPSINT asked for, with the step counts:

* planar, n PLBEAMs, undamped and with stiffness-proportional damping (EDAMPP 1e-3 EI, as
  benchmarks/stiff.py): generalized-α on meshes of 8 … 128 elements, DOP853 and Radau5 on the
  small meshes (they resolve every mode and take seconds);
* spatial, 16 BEAMs bending about both axes (EIz = 4 EIy, gravity off both), undamped.

    python benchmarks/error_control.py            # every case (about five minutes)
    python benchmarks/error_control.py 8 32       # the planar cases of some meshes, and the spatial one
    python benchmarks/error_control.py --all-methods 64 32 64   # DOP853 and Radau5 up to 64 elements
                                                  # (undamped and damped; minutes per run beyond 16)
    python benchmarks/error_control.py --case damped --methods radau5 16 32 64 128 256
                                                  # one case (undamped, damped or spatial) on the
                                                  # meshes given (default 16); --methods (comma-
                                                  # separated, after the case) on every mesh, else
                                                  # the methods main() runs on that case
"""
from __future__ import annotations

import sys

import spacar
from spacar.compare import models

TOLERANCES = (1e-4, 1e-6)
EI, RHO_A, DAMPING, G = 175.0, 0.785, 1e-3, 9.81


def planar(n: int, eps: float, damped: bool) -> spacar.Model:
    m = models.cantilever(n, ei=EI, rho_a=RHO_A, t_end=0.2, n_out=1, eps=eps, epskin=1e-12)
    if damped:
        for i in range(1, n + 1):
            m.edampp(i, 0.0, DAMPING * EI)
    return m


def spatial(n: int, eps: float, damped: bool = False, rotary: float = 0.0) -> spacar.Model:
    """n BEAMs along x, clamped at x = 0, bending about y and z (EIz = 4 EIy), gravity off both;
    ``rotary``: the sections' rotary inertia ρIy = ρIz per length (EMASS's extension; none here)."""
    m = spacar.Model()
    for i in range(n):
        m.beam(i + 1, i + 1, 101 + i, i + 2, 102 + i, 0.0, 1.0, 0.0)
    for i in range(n + 1):
        m.xyz(i + 1, i / n, 0.0, 0.0)
    m.fix(1)
    m.fix(101)
    for i in range(n):
        m.dyne(i + 1, 2, 3, 4, 5, 6)
        m.estiff(i + 1, 0.0, EI, EI, 4.0 * EI)
        m.emass(i + 1, RHO_A, 1e-4, rotary, rotary)
    m.gravity(0.0, -G, -0.5 * G)
    m.epsint(eps)
    m.epsind(eps)
    m.epskin(1e-12)
    m.timestep(1, 0.2)
    return m


def tip(build, n: int, method: str, eps: float, **options):
    """The tip's displacement vector at the end (y, and z in space) and the run's step count."""
    res = spacar.simulate(build(n, eps), method=method, progress=False, **options)
    return res.node(n + 1).x[-1, 1:], res.stats["steps"]


def error(build, n: int):
    coarse, _ = tip(build, n, "generalized_alpha", 1e-10, rho_inf=1.0, fixed_step=4e-5)
    fine, _ = tip(build, n, "generalized_alpha", 1e-10, rho_inf=1.0, fixed_step=2e-5)
    reference = fine + (fine - coarse) / 3.0  # second order
    return lambda y: float(abs(y - reference).max())


# name: (label, model builder, the largest mesh on which main() runs DOP853 and Radau5)
CASES = {"undamped": ("planar, undamped", lambda n, eps: planar(n, eps, False), 16),
         "damped": ("planar, damped", lambda n, eps: planar(n, eps, True), 8),
         "spatial": ("spatial, undamped", spatial, 0)}
METHODS = ("generalized_alpha", "dop853", "radau5")
HEADER = "| case | elements | method | EPSINT | tip error / EPSINT | steps |\n|---|---|---|---|---|---|"


def table(name, build, meshes, small=16, methods=None) -> None:
    """``methods``: these on every mesh; None: generalized-α, and DOP853 and Radau5 up to ``small``."""
    for n in meshes:
        err = error(build, n)
        on_mesh = methods or (METHODS if n <= small else METHODS[:1])
        for method in on_mesh:
            for eps in TOLERANCES:
                y, steps = tip(build, n, method, eps)
                print(f"| {name} | {n} | {method} | {eps:.0e} | {err(y) / eps:.3g} | {steps} |", flush=True)


def main(meshes, all_methods=None) -> None:
    """``all_methods``: DOP853 and Radau5 on the meshes up to this size (default 16 undamped, 8
    damped, where they take seconds)."""
    print(HEADER)
    for case in ("undamped", "damped"):
        label, build, small = CASES[case]
        table(label, build, meshes, small=all_methods or small)
    if all_methods is None:
        label, build, small = CASES["spatial"]
        table(label, build, [16], small=small)


if __name__ == "__main__":
    args = sys.argv[1:]
    limit = None
    if args[:1] == ["--case"]:
        if len(args) < 2 or args[1] not in CASES:
            sys.exit(f"--case needs one of {', '.join(CASES)}")
        (label, build, small), args = CASES[args[1]], args[2:]
        methods = None
        if args[:1] == ["--methods"]:
            methods = tuple(args[1].split(",")) if len(args) > 1 else ()
            if not methods or any(m not in METHODS for m in methods):
                sys.exit(f"--methods needs a comma-separated list of {', '.join(METHODS)}")
            args = args[2:]
        print(HEADER)
        table(label, build, [int(a) for a in args] or [16], small=small, methods=methods)
        sys.exit()
    if args[:1] == ["--all-methods"]:
        limit, args = int(args[1]), args[2:]
    main([int(a) for a in args] or [8, 16, 32, 64, 128], limit)

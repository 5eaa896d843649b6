"""What EPSINT bounds (issue 36, docs/stiff-integration.md "What EPSINT bounds, measured"): the tip
error of the undamped steel cantilever (PLBEAMs, EI 175 N m², ρA 0.785 kg/m, gravity, 0.2 s,
EPSKIN 1e-12) against a Richardson-extrapolated reference (generalized-α, ρ∞ = 1, fixed steps 4e-5
and 2e-5 s), as a multiple of the EPSINT asked for, with the step counts: generalized-α (its error estimate
in the nodal positions) on meshes of 8 … 128 elements, DOP853 and Radau5 on the small meshes
(they resolve every mode and take seconds).

    python benchmarks/error_control.py            # n = 8, 16, 32, 64, 128 (about two minutes)
    python benchmarks/error_control.py 8 32       # some meshes
"""
from __future__ import annotations

import sys

import spacar
from spacar.compare import models

TOLERANCES = (1e-4, 1e-6)


def tip(n: int, method: str, eps: float, **options):
    """The tip's vertical position at the end, and the run's step count."""
    model = models.cantilever(n, ei=175.0, rho_a=0.785, t_end=0.2, n_out=1, eps=eps, epskin=1e-12)
    res = spacar.simulate(model, method=method, progress=False, **options)
    return res.node(n + 1).x[-1, 1], res.stats["steps"]


def reference(n: int) -> float:
    coarse, _ = tip(n, "generalized_alpha", 1e-10, rho_inf=1.0, fixed_step=4e-5)
    fine, _ = tip(n, "generalized_alpha", 1e-10, rho_inf=1.0, fixed_step=2e-5)
    return fine + (fine - coarse) / 3.0  # second order


def main(meshes) -> None:
    print("| elements | method | EPSINT | tip error / EPSINT | steps |")
    print("|---|---|---|---|---|")
    for n in meshes:
        ref = reference(n)
        methods = ("generalized_alpha", "dop853", "radau5") if n <= 16 else ("generalized_alpha",)
        for method in methods:
            for eps in TOLERANCES:
                y, steps = tip(n, method, eps)
                print(f"| {n} | {method} | {eps:.0e} | {abs(y - ref) / eps:.3g} | {steps} |", flush=True)


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [8, 16, 32, 64, 128])

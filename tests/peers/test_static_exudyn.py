"""spacar.static against exudyn's SolveStatic on the same flexures with exudyn's geometrically
exact (Simo–Reissner) beams, converted by spacar.compare.exudyn_static (issue 19): the parallel
leaf-spring guide driven to a tenth of its leaf length, and the cross-spring pivot turned by
0.2 rad. Both programs' meshes are refined and Richardson-extrapolated (both converge as h²:
spacar's co-rotational cubic beams and exudyn's linear ones), so what is compared is the two
beam theories' answer to the same geometry, not one mesh's error."""
from __future__ import annotations

import numpy as np
import pytest

import spacar

pytest.importorskip("exudyn")
from spacar.compare import UnsupportedModelError, exudyn_static  # noqa: E402

import support.flexures as flexures  # noqa: E402


def _with_mesh(module, build, n):
    """The model that build() makes with n elements per leaf (support.flexures' node numbers
    follow its N)."""
    saved, module.N = module.N, n
    try:
        return build()[0]
    finally:
        module.N = saved


def _richardson(fine, coarse):
    """Two meshes of h and 2h of an O(h²) method: the extrapolated value."""
    return fine + (fine - coarse) / 3.0


def _guide(n, drive):
    m = _with_mesh(flexures, lambda: flexures.leaf_guide("plbeamnl"), n)
    m.force(2 * n + 1, drive, 0.0)
    return m, 2 * n + 1


def _pivot(n, moment):
    m = _with_mesh(flexures, lambda: flexures.pivot("plbeamnl"), n)
    m.force(2 * n + 2, moment)
    return m, 2 * n + 1


def _stage_state(build, value, n, exudyn_subdivide):
    """(spacar, exudyn): the stage's (x, y, β) at the full load."""
    m, node = build(n, value)
    peer = exudyn_static.solve(m, steps=4, subdivide=exudyn_subdivide)
    res = spacar.static(m, steps=4)
    mine = np.concatenate([res.node(node).x[-1], res.node(node + 1).x[-1]])
    theirs = np.concatenate([peer.node(node), peer.node(node + 1)])
    return mine, theirs


@pytest.mark.parametrize("case", ["guide", "pivot"])
def test_flexure_equilibrium_equals_exudyn(case):
    # The guide: 40 N drive, u ≈ 4.7 mm (L/10); the pivot: 0.35 N m, θ ≈ 0.2 rad.
    build, value = (_guide, 40.0) if case == "guide" else (_pivot, 0.35)
    coarse = _stage_state(build, value, 8, 8)      # exudyn: 64 and 128 elements per leaf
    fine = _stage_state(build, value, 16, 8)
    mine = _richardson(fine[0], coarse[0])
    theirs = _richardson(fine[1], coarse[1])
    if case == "guide":
        u, drop, rotation = mine[0], flexures.L - mine[1], mine[2]
        assert u == pytest.approx(theirs[0], rel=1e-5)        # found 9e-7
        assert drop == pytest.approx(flexures.L - theirs[1], rel=1e-4)   # the parasitic drop, 0.27 mm (5e-6)
        assert rotation == pytest.approx(theirs[2], rel=1e-2)              # the stage's tilt, 1.3e-4 rad (4e-3: exudyn's stage is 1e5 EI, not rigid)
        assert 0.09 < u / flexures.L < 0.1
    else:
        theta = mine[2]
        assert theta == pytest.approx(theirs[2], rel=2e-5)   # found 5e-6
        np.testing.assert_allclose(mine[:2], theirs[:2], atol=1e-4 * flexures.L)
        assert 0.19 < theta < 0.21


def test_unsupported_models_are_named():
    m = spacar.Model()
    m.pltruss(1, 1, 2)
    m.x(2, 1.0, 0.0)
    with pytest.raises(UnsupportedModelError, match="element 1 \\(PLTRUSS\\)"):
        exudyn_static.solve(m)

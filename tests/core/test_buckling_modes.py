"""Buckling mode shapes (issue 19, Linearization.buckling_modes, spacar.draw(mode=...)): the
Euler column (a cantilever under a compressive tip load) against P_cr = π²EI/4L² and the
mode shape 1 − cos(πx/2L) computed here, and the drawing of the mode."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from support.planar_models import compressed_cantilever


def test_euler_column_factor_and_mode_shape():
    n = 12
    model = compressed_cantilever(n)  # unit length, EI = 1, unit compressive tip load
    lin = spacar.linearize(model)
    mu, shapes_z, shapes_x = lin.buckling_modes()
    assert mu[0] == pytest.approx(np.pi**2 / 4, rel=1e-4)
    np.testing.assert_allclose(mu[:4], lin.buckling_factors()[:4], rtol=1e-10)
    assert shapes_z.shape == (len(lin.z_labels), len(mu)) and shapes_x.shape == (lin.DF.shape[0], len(mu))
    assert np.abs(shapes_z).max(axis=0) == pytest.approx(1.0)
    # The lateral deflection of the nodes along the column: 1 − cos(πx/2L), largest at the tip.
    labels = [tuple(c) for c in lin.coordinate_labels]
    y = np.array([shapes_x[labels.index((2 * k + 1, 2)), 0] for k in range(n + 1)])
    x = np.arange(n + 1) / n
    np.testing.assert_allclose(y / y[-1], 1 - np.cos(np.pi * x / 2), atol=2e-4)
    # The second mode: μ2 = 9π²/4 of the continuum, its shape 1 − cos(3πx/2L).
    assert mu[1] == pytest.approx(9 * np.pi**2 / 4, rel=2e-3)
    y2 = np.array([shapes_x[labels.index((2 * k + 1, 2)), 1] for k in range(n + 1)])
    np.testing.assert_allclose(y2 / y2[-1], 1 - np.cos(3 * np.pi * x / 2), atol=5e-3)


def test_draw_a_buckling_mode():
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    model = compressed_cantilever(6)
    res = spacar.static(model, steps=1)   # the straight column under its load
    lin = spacar.linearize(model)
    _, _, shapes_x = lin.buckling_modes()
    scene = spacar.draw(res, mode=shapes_x[:, 0])
    ys = np.concatenate([ln.get_ydata() for ln in scene.lines if getattr(ln, "spacar_kind", "") == "beam"])
    assert np.abs(ys).max() == pytest.approx(0.1, rel=1e-6)  # a tenth of the column's length
    tip = res.coordinate_index(13, 2)
    scene = spacar.draw(res, mode=shapes_x[:, 0], scale=0.5 / abs(shapes_x[tip, 0]))
    ys = np.concatenate([ln.get_ydata() for ln in scene.lines if getattr(ln, "spacar_kind", "") == "beam"])
    assert np.abs(ys).max() == pytest.approx(0.5, rel=1e-6)
    assert np.abs(res.x[-1][1::3]).max() == 0.0  # the results themselves are not changed
    with pytest.raises(spacar.InputError, match="one per nodal coordinate"):
        spacar.draw(res, mode=np.ones(3))
    plt.close("all")

"""spacar.Table (cpp/src/model/table.cpp): interpolation of values over time, against scipy's
cubic spline and numpy's linear interpolation; its refusals."""
import numpy as np
import pytest
from scipy.interpolate import CubicSpline

import spacar


@pytest.mark.parametrize("kind", ["linear", "cubic"])
def test_table_interpolates_as_scipy(kind):
    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(0.1, 1.0, 12))
    y = rng.normal(size=(12, 2))
    table = spacar.Table(t, y, kind=kind)
    ts = np.linspace(t[0], t[-1], 157)
    got = np.array([[table(s, d) for s in ts] for d in range(3)])  # (derivative, time, component)
    if kind == "cubic":
        ref = CubicSpline(t, y)  # not-a-knot by default
        want = np.array([ref(ts, d) for d in range(3)])
    else:
        interval = np.clip(np.searchsorted(t, ts, side="right") - 1, 0, len(t) - 2)
        slopes = np.diff(y, axis=0) / np.diff(t)[:, None]
        want = np.array([np.c_[[np.interp(ts, t, y[:, c]) for c in range(2)]].T, slopes[interval],
                         np.zeros((len(ts), 2))])
        interior = ~np.isin(ts, t)  # the rate jumps at the samples
        got, want = got[:, interior], want[:, interior]
    np.testing.assert_allclose(got, want, rtol=1e-11, atol=1e-11)
    # Outside the samples: the end values held, rates zero.
    np.testing.assert_allclose(table(t[-1] + 1.0), y[-1])
    np.testing.assert_allclose(table(t[0] - 1.0, 1), 0.0)


def test_cubic_table_of_three_samples_is_the_parabola():
    table = spacar.Table([0.0, 1.0, 3.0], [1.0, 2.0, 10.0])  # 1 + 0.5 t + 0.5 t² ... fitted
    c = np.polyfit([0.0, 1.0, 3.0], [1.0, 2.0, 10.0], 2)
    for s in (0.3, 2.2):
        assert table(s) == pytest.approx(np.polyval(c, s), rel=1e-13)
        assert table(s, 2) == pytest.approx(2 * c[0], rel=1e-13)


def test_bad_tables_are_refused():
    with pytest.raises(spacar.InputError, match="increase"):
        spacar.Table([0, 0], [1.0, 2.0])
    with pytest.raises(spacar.InputError, match="kind must be 'linear' or 'cubic'"):
        spacar.Table([0, 1], [1.0, 2.0], kind="spline")

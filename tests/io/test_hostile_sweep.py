"""Issue 24, finding 3: a sweep of a MATASC model gives every case its own files.

Before, every case wrote the same `<stem>_*.asc` in parallel (102 rows, fragments of lines).
Now case k writes `<stem>_case<k>_*.asc`; each file holds exactly its case's output times, equal
to the case's own results. Checked with the default threads and with two processes.
"""
from pathlib import Path

import numpy as np
import pytest

import spacar
from support.paths import EXAMPLES

SPEEDS = [1.0, 1.5, 2.0, 2.5]


def matasc_model(tmp_path):
    path = Path(tmp_path) / "crank.dat"
    path.write_text((EXAMPLES / "slidercrank.dat").read_text().replace("END", "MATASC 1\nTIMESTEP 20 0.5\nEND", 1))
    return path


def rows(path):
    lines = Path(path).read_text().splitlines(keepends=True)
    assert all(line.endswith("\n") for line in lines)
    return np.loadtxt([line for line in lines if not line.startswith("%")], ndmin=2)


@pytest.mark.parametrize("workers", [None, 2])
def test_each_case_writes_its_own_matasc_files(tmp_path, workers):
    path = matasc_model(tmp_path)
    result = spacar.sweep(spacar.read(path), {"XD 2 1": SPEEDS}, outputs="history", workers=workers,
                          progress=False)
    assert not result.errors
    assert not (tmp_path / "crank_x.asc").exists()
    for k, speed in enumerate(SPEEDS):
        assert result.cases[k] == {"XD 2 1": speed}
        for suffix, name in (("x", "x"), ("xd", "xd"), ("e", "e")):
            data = rows(tmp_path / f"crank_case{k}_{suffix}.asc")
            assert data.shape[0] == 21
            np.testing.assert_array_equal(data[:, 0], result.values["t"][k])
            np.testing.assert_allclose(data[:, 1:], result.values[name][k], rtol=1e-14, atol=1e-300)
    # the crank speed of each case is in its files: XD 2 1 is column 3 of _xd (x(2,1) after x(1,1), x(1,2))
    for k, speed in enumerate(SPEEDS):
        assert rows(tmp_path / f"crank_case{k}_xd.asc")[0, 3] == speed


def test_case_numbers_are_padded_to_the_number_of_cases(tmp_path):
    path = matasc_model(tmp_path)
    model = spacar.read(path)
    model.apply("TIMESTEP", 2, 0.01)
    result = spacar.sweep(model, {"XD 2 1": list(np.linspace(1, 2, 11))}, workers=1, progress=False)
    assert not result.errors
    names = sorted(p.name for p in tmp_path.glob("crank_case*_x.asc"))
    assert names == [f"crank_case{k:02d}_x.asc" for k in range(11)]


def test_factory_models_get_their_own_stems_too(tmp_path):
    path = matasc_model(tmp_path)

    def make(params):
        model = spacar.read(path)
        model.apply("XD", 2, 1, params["speed"])
        return model

    result = spacar.sweep(make, {"speed": [1.0, 3.0]}, progress=False)
    assert not result.errors
    assert rows(tmp_path / "crank_case1_xd.asc")[0, 3] == 3.0

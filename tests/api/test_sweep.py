"""spacar.sweep (issue #9): parameter studies over keyword values, serial, in local processes and
on a Dask cluster, with identical numbers; failed cases are reported, never dropped.
"""
from __future__ import annotations

import concurrent.futures
import os
import pickle

import numpy as np
import pytest

import spacar
from spacar import InputError
from support.paths import EXAMPLES

EXAMPLE = EXAMPLES / "slidercrank.dat"

SPEEDS = np.linspace(1.0, 2.0, 8)            # crank speed XD 2 1 [rad/s]; the manual: 1.5
ROD_EI = np.linspace(0.8e-3, 1.6e-3, 8)      # bending stiffness of the rod (ESTIFF 2 and 3); 1.2723e-3
ARRAYS = ("t", "x", "xd", "xdd", "e", "ed", "edd", "sigma", "reaction")


def serial_run(speed, ei):
    """One case the plain way: read the manual's input, set the values, simulate."""
    model = spacar.read(EXAMPLE)
    model.xd(2, 1, speed)
    model.estiff(2, 0.0, ei)
    model.estiff(3, 0.0, ei)
    res = spacar.simulate(model)
    return {name: getattr(res, name)[-1] for name in ARRAYS}


@pytest.fixture(scope="module")
def serial_grid():
    return [serial_run(w, k) for w in SPEEDS for k in ROD_EI]


GRID = {"XD 2 1": SPEEDS, ("ESTIFF 2", "ESTIFF 3"): [(0.0, k) for k in ROD_EI]}


def assert_same_as_serial(result, serial):
    assert result.ok.all(), result.errors
    assert len(result) == len(serial) == 64
    for name in ARRAYS:
        expected = np.array([case[name] for case in serial])
        np.testing.assert_array_equal(result.values[name], expected, err_msg=name)  # bit for bit


def test_local_cluster_sweep_of_the_slider_crank_matches_serial_runs(serial_grid, tmp_path):
    """The issue's demonstration: 64 cases (8 crank speeds x 8 rod stiffnesses) on a dask
    LocalCluster of two worker processes give the same numbers as serial runs."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  local_directory=str(tmp_path), silence_logs=40) as cluster, \
            distributed.Client(cluster) as client:
        outputs = {name: name + "_final" for name in ARRAYS}
        outputs["pid"] = lambda res: os.getpid()  # a lambda: the functions travel with cloudpickle
        result = spacar.sweep(spacar.read(EXAMPLE), GRID, outputs=outputs, client=client, progress=False)
        worker_pids = set(client.run(os.getpid).values())
    assert_same_as_serial(result, serial_grid)
    pids = set(result.values["pid"].tolist())
    assert pids <= worker_pids and os.getpid() not in pids
    assert result.shape == (8, 8) and result.reshaped("x").shape == (8, 8, 13)
    np.testing.assert_array_equal(result.parameters["XD 2 1"], np.repeat(SPEEDS, 8))
    np.testing.assert_array_equal(result.parameters["ESTIFF 2 & ESTIFF 3"][:, 1], np.tile(ROD_EI, 8))


def test_local_processes_and_threads_match_serial_runs(serial_grid):
    base = spacar.read(EXAMPLE)
    in_processes = spacar.sweep(base, GRID, workers=2, progress=False)
    assert_same_as_serial(in_processes, serial_grid)
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        in_threads = spacar.sweep(base, GRID, executor=pool, progress=False)
    assert_same_as_serial(in_threads, serial_grid)
    assert base.current_time == 0.0 and not base.core.frozen  # the sweep works on copies


def test_failed_cases_are_reported_with_their_parameters():
    base = spacar.read(EXAMPLE)
    sample = [{"ESTIFF 2": (0.0, 1e-3), "TIMESTEP": (4, 0.2)},
              {"ESTIFF 2": (0.0, 1e308), "TIMESTEP": (4, 0.2)},        # overflows
              {"ESTIFF 2": (0.0, 1e-3, 2.0, 3.0), "TIMESTEP": (4, 0.2)},    # PLBEAM takes 3 stiffnesses
              {"ESTIFF 2": (0.0, 2e-3), "TIMESTEP": (4, 0.2)}]
    result = spacar.sweep(base, sample, workers=1, time_limit=30)
    assert result.ok.tolist() == [True, False, False, True]
    assert [e.index for e in result.errors] == [1, 2]
    e1, e2 = result.errors
    assert e1.parameters == {"ESTIFF 2": (0.0, 1e308), "TIMESTEP": (4, 0.2)}
    assert e1.type == "spacar.SpacarError" and "the accelerations at t = 0 are not finite" in e1.message
    assert e2.type == "spacar.InputError"
    assert e2.message.startswith("sweep parameter 'ESTIFF 2' = (0.0, 0.001, 2.0, 3.0): ESTIFF of PLBEAM takes 1 to 3")
    assert np.isnan(result.values["x"][1:3]).all() and np.isfinite(result.values["x"][[0, 3]]).all()
    assert result.values["t"].tolist()[0] == 0.2
    with pytest.raises(spacar.SpacarError, match=r"2 of 4 cases failed:\ncase 1 .*SpacarError: the accelerations"):
        result.raise_errors()


def test_lengths_follow_the_nodes_of_an_unprepared_model():
    """X lines replace the geometry: element lengths are computed from them at the first END."""
    base = spacar.read(EXAMPLE)
    crank = [(0.10, 0.0), (0.15, 0.0), (0.20, 0.0)]
    result = spacar.sweep(base, {"X 3": crank, "TIMESTEP": [(2, 0.1)]}, workers=1,
                          outputs={"l0": lambda res: res.coordinate(3, 1)[0]})  # x of node 3 at t = 0
    np.testing.assert_allclose(result.values["l0"], [0.10, 0.15, 0.20])

    def factory(params):
        model = spacar.read(EXAMPLE)
        model.x(3, params["crank"], 0.0)
        model.timestep(2, 0.1)
        return model

    by_factory = spacar.sweep(factory, {"crank": [0.10, 0.15, 0.20]}, workers=1, outputs="final")
    np.testing.assert_array_equal(by_factory.values["x"], spacar.sweep(
        base, {"X 3": crank, "TIMESTEP": [(2, 0.1)]}, workers=1).values["x"])


def test_linearize_gives_eigenfrequencies():
    base = spacar.read(EXAMPLE)
    masses = [0.01, 0.033375, 0.1]
    result = spacar.sweep(base, {"MASS 8": masses}, analysis="linearize", workers=1)
    assert result.values["eigenfrequencies"].shape == (3, 4)
    for mass, row in zip(masses, result.values["eigenfrequencies"]):
        model = spacar.read(EXAMPLE)
        model.mass(8, mass)
        np.testing.assert_array_equal(row, spacar.linearize(model).eigenfrequencies())
    ds = result.to_xarray()
    assert ds["eigenfrequencies"].dims == ("MASS 8", "mode")
    np.testing.assert_array_equal(ds["MASS 8"].values, masses)


def test_outputs_history_names_functions_and_xarray():
    base = spacar.read(EXAMPLE)
    params = {"XD 2 1": [1.0, 2.0], "TIMESTEP": [(4, 0.2)]}
    history = spacar.sweep(base, params, outputs="history", workers=1)
    assert history.values["x"].shape == (2, 5, 13) and history.values["t"].shape == (2, 5)
    ds = history.to_xarray()
    assert ds["x"].dims == ("XD 2 1", "TIMESTEP", "time", "coordinate")
    assert ds["e"].dims == ("XD 2 1", "TIMESTEP", "time", "deformation")
    assert ds["node"].values.tolist()[:3] == [1, 1, 2]
    named = spacar.sweep(base, params, outputs=["e_final", "sigma"], workers=1)
    assert list(named.values) == ["e_final", "sigma"] and named.values["sigma"].shape == (2, 5, 9)

    def slider(res):
        return {"slider": res.node(8).x[-1, 0], "max_sigma": np.abs(res.sigma).max()}

    by_function = spacar.sweep(base, params, outputs=slider, workers=1)
    assert by_function.values["slider"].shape == (2,)
    slider_column = history.coordinate_labels.index((8, 1))
    np.testing.assert_array_equal(by_function.values["slider"], history.values["x"][:, -1, slider_column])
    sample = spacar.sweep(base, [{"XD 2 1": 1.0}, {"XD 2 1": 2.0}], outputs=lambda r: r.t[-1], workers=1)
    assert sample.values["value"].tolist() == [5.0, 5.0] and sample.shape == (2,)
    ds = sample.to_xarray()
    assert ds["value"].dims == ("case",) and ds["XD 2 1"].values.tolist() == [1.0, 2.0]
    assert pickle.loads(pickle.dumps(sample)).values["value"].tolist() == [5.0, 5.0]


def test_progress_callback_and_chunks():
    seen = []
    spacar.sweep(spacar.read(EXAMPLE), {"XD 2 1": [1.0, 1.1, 1.2, 1.3, 1.4], "TIMESTEP": [(1, 0.05)]}, workers=1,
                 chunksize=2, progress=lambda done, total: seen.append((done, total)))
    assert seen == [(2, 5), (4, 5), (5, 5)]


@pytest.mark.parametrize("parameters, reason", [
    ({"ESTIFF": [(0, 1)]}, r"a ESTIFF line is named by 'ESTIFF e' \(1 number after the keyword\)"),
    ({"XD 2": [1.0]}, r"a XD line is named by 'XD n i' \(2 numbers"),
    ({"TIMESTEP 1": [(1, 1.0)]}, r"named by 'TIMESTEP' \(0 numbers"),
    ({"FIX 8": [2]}, r"FIX lines define the model's structure .* use a factory"),
    ({"PLBEAM 1": [(1, 2, 3, 4)]}, r"PLBEAM lines define the model's structure"),
    ({"NOSUCH 1": [1]}, r"unknown keyword 'NOSUCH'"),
    ({"XD a b": [1]}, r"n i must be integers"),
    ({"XD 2 1": [1.5, float("nan")]}, r"'XD 2 1' = nan: XD: x must be a finite number"),
    ({"XD 2 1": [float("inf")]}, r"must be a finite number"),
    ({"XD 2 1": [np.array(np.nan)]}, r"must be a finite number"),  # a 0-d array is a number
    ({"ESTIFF 2": [np.array([0.0, np.inf])]}, r"must be a finite number"),
    ({"ESTIFF 2": [(0.0, float("-inf"))]}, r"'ESTIFF 2' = \(0\.0, -inf\): ESTIFF: x must be a finite number"),
    ({"TIMESTEP": [(10.5, 1.0)]}, r"TIMESTEP: n must be an integer"),
    ({"XD 2 1": 1.5}, r"give a sequence of values"),
    ({"XD 2 1": []}, r"no values"),
    ({}, r"no parameters"),
    ([{"XD 2 1": 1.0}, {"MASS 8": 1.0}], r"case 1 has the parameters \['MASS 8'\]"),
    ({42: [1]}, r"name it by a string"),
], ids=lambda v: str(v)[:40] if not isinstance(v, str) else None)
def test_bad_parameters_are_refused_at_once(parameters, reason):
    with pytest.raises(InputError, match=reason):
        spacar.sweep(spacar.read(EXAMPLE), parameters, workers=1)


def test_bad_options_are_refused_at_once():
    base = spacar.read(EXAMPLE)
    grid = {"XD 2 1": [1.0]}
    for kwargs, reason in [({"analysis": "eigen"}, "analysis must be"), ({"time_limit": float("nan")}, "time_limit"),
                           ({"workers": 0}, "workers must be a positive integer"), ({"chunksize": 1.5}, "chunksize"),
                           ({"method": "euler"}, "unknown integration method"),
                           ({"outputs": "nope"}, "unknown output 'nope'"), ({"outputs": 3}, "sweep outputs"),
                           ({"analysis": "linearize", "outputs": "x"}, "unknown output 'x'"),
                           ({"analysis": "linearize", "outputs": "M0_final"}, "unknown output 'M0_final'"),
                           ({"workers": "2"}, "workers must be a positive integer"),
                           ({"executor": 5}, "executor must be a dask.distributed.Client or a concurrent.futures"),
                           ({"client": "tcp://x"}, "client must be")]:
        with pytest.raises(InputError, match=reason):
            spacar.sweep(base, grid, **{"workers": 1, **kwargs})
    with pytest.raises(InputError, match="must be a spacar.Model"):
        spacar.sweep(42, grid)


def test_a_factory_that_fails_or_returns_garbage_is_reported():
    def factory(params):
        if params["k"] == 2:
            raise ValueError("no model for k = 2")
        return "not a model" if params["k"] == 3 else spacar.read(EXAMPLE)

    result = spacar.sweep(factory, {"k": [1, 2, 3]}, outputs=lambda r: r.t[-1], workers=1)
    assert result.ok.tolist() == [True, False, False]
    assert [(e.type, e.message) for e in result.errors] == [
        ("ValueError", "no model for k = 2"), ("spacar.InputError", "the factory returned str, not a spacar.Model")]


def test_progress_bar(capsys):
    pytest.importorskip("tqdm")
    spacar.sweep(spacar.read(EXAMPLE), {"XD 2 1": [1.0, 2.0], "TIMESTEP": [(1, 0.05)]}, workers=1, progress=True)
    err = capsys.readouterr().err
    assert "spacar.sweep" in err and "2/2" in err


def test_default_sweep_runs_threads_without_pickling(monkeypatch):
    """Short runs must not pay for processes (issue 23: the process default made a sweep of
    short runs 1.45× slower than a plain loop): the default shares the task with threads."""
    import sys

    sweep_module = sys.modules["spacar.sweep"]

    def no_pickling(obj):
        raise AssertionError("the default sweep pickled its task")

    monkeypatch.setattr(sweep_module, "_dumps", no_pickling)
    model = spacar.read(EXAMPLES / "slidercrank.dat")
    values = list(np.linspace(0.1, 0.4, 6))
    result = spacar.sweep(model, {"EMASS 3": values}, progress=False)
    assert result.ok.all() and result.workers == min(os.cpu_count() or 1, 6)
    for v, x in zip(values, result.values["x"]):
        m = model.copy()
        m.emass(3, v)
        np.testing.assert_array_equal(x, spacar.simulate(m, progress=False).x[-1])

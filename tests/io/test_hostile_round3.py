"""Issue 38, the third adversarial round (docs/robustness.md, "Third round"). Finding 1: runs on
one model from several threads. A run starts from the model's
state and leaves its end state there; threads simulating the same model all started at its time
and their blocks overwrote each other (six 5 s runs left the model at t = 5, not 30). Now the runs
on one model take turns: the model ends where the same runs one after the other end, and each
run's rows continue the last one's. Findings 12, 14 and 15 (in part): raw errors at entry points
and a NaN time index."""
from __future__ import annotations

import threading

import numpy as np
import pytest

import spacar
from support.paths import DATA, EXAMPLES


def test_runs_on_one_model_from_threads_take_turns():
    model = spacar.read(EXAMPLES / "slidercrank.dat")
    serial = model.copy()
    results, errors = [], []

    def run():
        try:
            results.append(spacar.simulate(model, progress=False))
        except Exception as err:  # pragma: no cover - reported below
            errors.append(err)

    threads = [threading.Thread(target=run) for _ in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert model.current_time == 30.0
    starts = sorted(r.t[0] for r in results)
    assert starts == [0.0, 5.0, 10.0, 15.0, 20.0, 25.0]
    for _ in range(6):
        last = spacar.simulate(serial, progress=False)
    ended = max(results, key=lambda r: r.t[-1])
    np.testing.assert_array_equal(ended.x[-1], last.x[-1])


def test_runs_on_copies_do_not_wait_for_each_other():
    """Each copy is its own model: its runs start at its own time."""
    model = spacar.read(EXAMPLES / "slidercrank.dat")
    copies = [model.copy() for _ in range(3)]
    threads = [threading.Thread(target=spacar.simulate, args=(c,), kwargs={"progress": False}) for c in copies]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert [c.current_time for c in copies] == [5.0, 5.0, 5.0]
    assert model.current_time == 0.0


@pytest.mark.parametrize("bad", [42, None, "model.dat"])
def test_static_of_something_else_is_an_input_error(bad):
    with pytest.raises(spacar.InputError, match="static: model must be a spacar.Model"):
        spacar.static(bad)


def test_from_urdf_bad_path_and_gravity_are_input_errors():
    with pytest.raises(spacar.InputError, match="path of a URDF file"):
        spacar.from_urdf("a\x00b")  # was a raw ValueError (embedded null byte)
    with pytest.raises(spacar.InputError, match="gravity must be three finite numbers"):
        spacar.from_urdf(DATA / "two_link_arm.urdf", gravity=(0, 0, 10**400))  # was a raw OverflowError


@pytest.mark.parametrize("bad, match", [(float("nan"), "finite"), (float("inf"), "finite"), ("x", "a number"),
                                        (10**400, "a number")])
def test_time_index_of_no_time_is_an_input_error(bad, match):
    res = spacar.simulate(spacar.read(EXAMPLES / "slidercrank.dat"), progress=False)
    with pytest.raises(spacar.InputError, match=match):
        res.time_index(bad)  # NaN gave row 0
    assert res.time_index(2.51) == 50

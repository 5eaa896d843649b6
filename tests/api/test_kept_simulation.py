"""spacar.simulate keeps the simulation of a model's last run on the recursive path (issue 37): the
next run of the unchanged model renews it (its state read from the model again, its data reset)
instead of compiling the model and recognizing its tree again. A run on the kept simulation must
give what a run on a fresh copy of the model gives (the tree was recognized at another state:
equal to rounding), and any change of the model between the runs must discard it."""
from __future__ import annotations

import pickle

import numpy as np
import pytest

import spacar
from spacar.compare import models
from spacar.simulate import _runs


def spatial(n=4):
    return models.spatial_chain(n, seed=n, t_end=0.05, n_out=2, eps=1e-8, epskin=1e-11)


def planar(n=4):
    return models.planar_chain(n, angle=0.3, t_end=0.05, n_out=2, eps=1e-8, epskin=1e-11)


def assert_same_run(kept, fresh):
    """The two runs' outputs equal to rounding (the tree recognized at another state)."""
    assert kept.stats["path"] == fresh.stats["path"] == "tree"
    assert kept.stats["rhs_evaluations"] == fresh.stats["rhs_evaluations"]
    np.testing.assert_array_equal(kept.t, fresh.t)
    for name in ("x", "xd", "xdd", "e", "ed", "edd", "sigma"):
        a, b = getattr(kept, name), getattr(fresh, name)
        np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-10 * max(1.0, np.abs(b).max()), err_msg=name)


@pytest.mark.parametrize("build", [spatial, planar])
def test_later_blocks_on_the_kept_simulation_match_fresh_copies(build):
    model = build()
    fresh = model.copy()
    for _ in range(4):
        kept_run = spacar.simulate(model)
        assert _runs(model).simulation is not None  # kept for the next block
        fresh = fresh.copy()  # a copy has no kept simulation: compiled and recognized afresh
        assert_same_run(kept_run, spacar.simulate(fresh))
        assert model.warnings == fresh.warnings
    assert pickle.loads(pickle.dumps(model)).current_time == pytest.approx(0.2)


# Changes between two blocks: each must reach the next run (the kept simulation discarded).
CHANGES = {
    "gravity": lambda m: m.gravity(0.0, -3.0, 1.0),
    "mass": lambda m: m.mass(3, 2.5),
    "period": lambda m: m.timestep(3, 0.02),
    "tolerance": lambda m: m.epsint(1e-6),
    "rate": lambda m: m.ed(models.HINGE + 2, 1, 0.7),
    "time": lambda m: m.time(1.0),
    "another analysis": lambda m: spacar.linearize(m),
}


@pytest.mark.parametrize("change", CHANGES)
def test_a_change_between_blocks_reaches_the_next(change):
    model = spatial()
    spacar.simulate(model)
    fresh = model.copy()
    CHANGES[change](model)
    CHANGES[change](fresh)
    assert_same_run(spacar.simulate(model), spacar.simulate(fresh))


def test_runs_off_the_tree_keep_nothing():
    model = spatial()
    spacar.simulate(model, recursive=False)
    assert _runs(model).simulation is None
    spacar.simulate(model)
    res = spacar.simulate(model, recursive=False)  # the kept tree is not used
    assert res.stats["path"] != "tree" and _runs(model).simulation is None
    fresh = model.copy()
    assert_same_run(spacar.simulate(model), spacar.simulate(fresh))


def test_a_failed_run_keeps_nothing():
    model = spatial()
    spacar.simulate(model)
    model.timestep(1, 1e300)  # refused before any work (the end time is not finite)
    with pytest.raises(spacar.InputError):
        spacar.simulate(model)
    assert _runs(model).simulation is None

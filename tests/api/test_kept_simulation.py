"""spacar.simulate keeps the simulation of a model's last run on the recursive path (issue 37): the
next run of the unchanged model renews it (its state read from the model again; the block
continued from the data of the last block's last output) instead of compiling the model, assembling
it and recognizing its tree again. A run on the kept simulation must
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


def assert_same_run(kept, fresh, path="tree"):
    """The two runs' outputs equal to rounding (the tree recognized at another state, the first
    output solved by the block before, the LUs' pivots of another state)."""
    assert kept.stats["path"] == fresh.stats["path"] == path
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
    fresh = model.copy()
    res = spacar.simulate(model, recursive=False)  # renewed, but the kept tree is not used
    assert_same_run(res, spacar.simulate(fresh, recursive=False), path="general")
    assert _runs(model).simulation is None
    assert_same_run(spacar.simulate(model), spacar.simulate(fresh))


def test_a_failed_run_keeps_nothing():
    model = spatial()
    spacar.simulate(model)
    model.timestep(1, 1e300)  # refused before any work (the end time is not finite)
    with pytest.raises(spacar.InputError):
        spacar.simulate(model)
    assert _runs(model).simulation is None


def test_the_continued_first_output_is_complete():
    """A block continued on the kept tree records its first output from the last block's: the
    reactions (FORCEMODE 1) and what on_output receives are those a fresh copy solves."""
    model = spatial()
    model.forcemode(1)
    spacar.simulate(model)
    fresh = model.copy()
    seen = {}
    kept = spacar.simulate(model, on_output=lambda k, state: seen.setdefault(k, state))
    fresh_seen = {}
    again = spacar.simulate(fresh, on_output=lambda k, state: fresh_seen.setdefault(k, state))
    assert_same_run(kept, again)
    np.testing.assert_allclose(kept.reaction, again.reaction, rtol=1e-10, atol=1e-10 * np.abs(again.reaction).max())
    assert np.abs(again.reaction[0]).max() > 0.0
    assert sorted(seen) == sorted(fresh_seen) == [0, 1, 2]
    for name in ("t", "x", "xd", "xdd", "e", "sigma", "reaction"):
        np.testing.assert_allclose(seen[0][name], fresh_seen[0][name], rtol=1e-10,
                                   atol=1e-10 * max(1.0, np.abs(fresh_seen[0][name]).max()), err_msg=name)


@pytest.mark.parametrize("change", ["gravity", "mass", "period"])
def test_a_change_during_a_block_reaches_the_next(change):
    """A change made while a block runs (from on_output here; another thread alike) is not the
    block's own: the next block compiles the changed model (review of issue 37's first version)."""
    model, fresh = spatial(), spatial()

    def on_output(k, state):
        if k == 1:
            CHANGES[change](model)

    spacar.simulate(model, on_output=on_output)
    spacar.simulate(fresh)
    CHANGES[change](fresh)
    assert_same_run(spacar.simulate(model), spacar.simulate(fresh.copy()))


def test_closed_loops_are_recognized_at_every_block():
    """A tree with loops closed starts its loop closure from the state it was recognized at: it is
    not kept for the next block."""
    model = models.seven_r_loop(t_end=0.05, n_out=2)
    res = spacar.simulate(model)
    assert res.stats["path"] == "tree" and _runs(model).simulation is None


def test_a_renewed_simulation_that_evaluated_another_state_assembles_again():
    """The core's Simulation used directly: after evaluating another state, a renewed run does
    not take the data for its start (they no longer hold the last block's last output)."""
    model = spatial()
    spacar.simulate(model)
    fresh = model.copy()
    sim = _runs(model).simulation
    n = len(sim.system.x_dyn) + len(sim.system.e_dyn)
    sim.evaluate(model.current_time + 0.3, np.full(n, 0.2), np.full(n, -0.5))
    assert sim.renew()
    arrays = sim.run()
    np.testing.assert_allclose(arrays["t"][0], fresh.current_time)
    again = spacar.simulate(fresh)
    np.testing.assert_allclose(arrays["x"], again.x, rtol=1e-10, atol=1e-10)


def test_a_change_after_the_renewal_is_not_taken_for_the_runs_own():
    """A change between renew() and the run (another thread; the core used directly) leaves the
    run's system older than the model: its tree is not kept for a later block."""
    model = spatial()
    spacar.simulate(model)
    sim = _runs(model).simulation
    assert sim.renew()
    model.mass(3, 2.5)
    sim.run()
    assert not sim.renewable

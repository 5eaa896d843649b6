"""The right-hand-side path a run chooses once (cpp/include/spacar/analyses/rhs_path.hpp): the tree
of rigid bodies, the open chain or the general constraint formulation, reported in
``res.stats["path"]``. That the paths give the same motion is checked in test_recursive_trees.py
(tree against general) and test_chain.py (chain against general)."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar.compare import models


CASES = {
    "planar tree": (lambda: (models.planar_chain(3), {}), "tree"),
    "spatial tree": (lambda: (models.spatial_chain(3, seed=3), {}), "tree"),
    "flexible chain": (lambda: (models.cantilever(3, t_end=0.01, n_out=2), {}), "chain"),
    "closed loop": (lambda: (models.four_bar(), {}), "tree"),
    "closed loop, recursive=False": (lambda: (models.four_bar(), {"recursive": False}), "general"),
    "input-driven closed loop": (lambda: (models.slider_crank(n_rod=2, t_end=0.01, n_out=1), {}), "general"),
    "tree, recursive=False": (lambda: (models.planar_chain(3), {"recursive": False}), "general"),
    "chain, recursive=False": (lambda: (models.cantilever(3, t_end=0.01, n_out=2), {"recursive": False}), "general"),
    "chain with the energy balance": (lambda: (models.cantilever(3, t_end=0.01, n_out=2), {"energy": True}),
                                      "general"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_the_run_reports_the_path_it_chose(name):
    build, path = CASES[name]
    model, options = build()
    model.timestep(2, 0.01)
    res = spacar.simulate(model, **options)
    assert res.stats["path"] == path
    assert res.stats["recursive"] == (path == "tree")


def test_a_chain_and_the_general_path_give_the_same_run():
    def model():
        m = models.cantilever(4, t_end=0.02, n_out=4, eps=1e-9)
        m.timestep(4, 0.02)
        return m
    chain = spacar.simulate(model())
    general = spacar.simulate(model(), recursive=False)
    assert (chain.stats["path"], general.stats["path"]) == ("chain", "general")
    np.testing.assert_allclose(chain.x, general.x, rtol=0, atol=1e-7)

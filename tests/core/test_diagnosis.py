"""The constraint diagnosis (cpp/src/kinematics/diagnosis.cpp), called after a failure: on a
slider-crank whose crank and rod share their orientation node (welded: one constraint too many)
it counts the constraints and the rank by hand and names a redundant deformation whose release
makes the mechanism move again."""
import pytest

import spacar
from spacar import _core

R, L = 0.15, 0.35


def slider_crank(welded):
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.plbeam(2, 3, 4 if welded else 5, 6, 7)
    m.fix(1)
    m.fix(6, 2)
    m.x(3, R, 0.0)
    m.x(6, R + L, 0.0)
    m.inputx(2, 1)
    m.xd(2, 1, 1.0)
    m.timestep(4, 0.2)
    return m


def test_a_welded_slider_crank_is_diagnosed_by_counting():
    sim = _core.Simulation(slider_crank(welded=True).core)
    d = sim.diagnose()
    # 6 rigid deformations; x3, y3, β4, x6, β7 calculable; the rank of the position block is 5
    assert (d["n_constraints"], d["n_calculable"], d["rank"]) == (6, 5, 5)
    assert len(d["redundant"]) == 1 and d["undetermined"] == []
    assert "over-constrained by 1" in d["text"]


def test_releasing_the_named_deformation_makes_it_move():
    d = _core.Simulation(slider_crank(welded=True).core).diagnose()
    (element, deformation), = d["redundant"]
    m = slider_crank(welded=True)
    m.rlse(element, deformation)
    res = spacar.simulate(m, progress=False)
    assert res.node(6).x[-1, 0] < R + L  # the slider moved towards the crank


def test_the_pinned_slider_crank_runs_and_the_welded_one_fails_with_the_diagnosis():
    spacar.simulate(slider_crank(welded=False), progress=False)
    with pytest.raises(spacar.KinematicsError, match="RLSE"):
        spacar.simulate(slider_crank(welded=True), progress=False)

"""Results in DOF coordinates (issue 21): res.q, res.qd, res.qdd and res.dof_labels for planar
and spatial models, DYNX and DYNE DOFs, simulate and static, checked against the model's own
definitions of its DOFs (the BETA rotations and hinge angles they are), against the core's
reduced accelerations at the recorded states and against the order of spacar.linearize."""
from __future__ import annotations

import pickle

import numpy as np
import pytest

import spacar
from spacar import _core
from spacar.compare import models
from spacar.compare.models import END, HINGE, START
from support.paths import EXAMPLES


def test_planar_relative_angles_are_the_hinge_rotations():
    n = 3
    res = spacar.simulate(models.planar_chain(n, angle=0.3))
    assert res.dof_labels == [f"e({HINGE + i},1) PLHINGE" for i in range(1, n + 1)]
    assert res.q.shape == res.qd.shape == res.qdd.shape == (len(res.t), n)
    # the relative angle of hinge i is β(START+i) − β(END+i−1), and END+i turns with link i
    beta = {k: res.node(k).x[:, 0] for k in [END] + [START + i for i in range(1, n + 1)]}
    for i in range(1, n + 1):
        parent = beta[END] if i == 1 else res.node(END + i - 1).x[:, 0]
        np.testing.assert_allclose(res.q[:, i - 1], beta[START + i] - parent, atol=1e-12)
        np.testing.assert_array_equal(res.qd[:, i - 1], res.deformation(HINGE + i, 1, "ed"))
        np.testing.assert_array_equal(res.qdd[:, i - 1], res.deformation(HINGE + i, 1, "edd"))


def test_absolute_angles_are_the_beta_coordinates():
    res = spacar.simulate(models.planar_chain(2, dof="absolute"))
    assert res.dof_labels == [f"x({START + 1},1)", f"x({START + 2},1)"]
    np.testing.assert_array_equal(res.q, np.column_stack([res.node(START + i).x[:, 0] for i in (1, 2)]))
    np.testing.assert_array_equal(res.qdd, np.column_stack([res.node(START + i).xdd[:, 0] for i in (1, 2)]))
    assert res["x(100001,1)"] is not None and res[res.dof_labels[1]].shape == (len(res.t),)


def mixed_model():
    """A planar double pendulum: link 1 turned by the DYNX rotation of its BETA node, link 2 by
    the DYNE rotation of its hinge (numbered so that DYNE's element comes before DYNX's node)."""
    m = models.planar_chain(2, dof="relative", n_out=4)
    m.rlse(HINGE + 1, 1)
    m.dynx(START + 1, 1)
    return m


def test_dynx_then_dyne_in_the_order_of_linearize_and_the_core():
    model = mixed_model()
    res = spacar.simulate(model.copy())
    assert res.dof_labels == [f"x({START + 1},1)", f"e({HINGE + 2},1) PLHINGE"]
    lin = spacar.linearize(model.copy())
    assert [f"{k}({a},{b})" for k, a, b in lin.z_labels] == [lbl.split()[0] for lbl in res.dof_labels]
    # the core's q̈ at each recorded (q, q̇) is the recorded q̈
    sim = _core.Simulation(model.core)
    sim.assemble()
    np.testing.assert_array_equal(res.q[0], sim.system.q0)
    for k in range(len(res.t)):
        sim.evaluate(float(res.t[k]), res.q[k], res.qd[k])
        np.testing.assert_allclose(np.array(sim.data.qdd), res.qdd[k], rtol=0, atol=1e-9)


def test_spatial_dyne_and_dynx_rotations():
    res = spacar.simulate(spacar.read(EXAMPLES / "slidercrank3d.dat"))
    assert res.dof_labels == ["e(2,5) BEAM", "e(2,6) BEAM", "e(3,5) BEAM", "e(3,6) BEAM"]
    np.testing.assert_array_equal(res.q[:, 1], res.deformation(2, 6))
    chain = models.spatial_chain(2, joints="spherical")
    res = spacar.simulate(chain)
    # a freely rotating LAMBDA node: three of its Euler parameters are the DOFs
    assert len(res.dof_labels) == 6 and all(lbl.startswith(f"x({START + 1},") or lbl.startswith(f"x({START + 2},")
                                            for lbl in res.dof_labels)
    for j, lbl in enumerate(res.dof_labels):
        np.testing.assert_array_equal(res.q[:, j], res[lbl])


def test_static_results_have_the_dofs():
    model = models.cantilever(3)
    res = spacar.static(model, steps=2)
    assert res.dof_labels == [f"e({i},{k}) PLBEAM" for i in (1, 2, 3) for k in (2, 3)]
    np.testing.assert_array_equal(res.q, res.e[:, [res.deformation_index(i, k) for i in (1, 2, 3) for k in (2, 3)]])
    assert res.q.shape == (2, 6) and not res.qd.any() and not res.qdd.any()


def test_without_dofs_q_is_empty():
    m = spacar.Model()  # a crank driven by INPUTX: no degrees of freedom
    m.plbeam(1, 1, 2, 3, 4)
    m.x(3, 1.0, 0.0)
    m.fix(1)
    m.inputx(2, 1)
    m.xd(2, 1, 1.0)
    m.timestep(2, 1.0)
    res = spacar.simulate(m)
    assert res.dof_labels == [] and res.q.shape == (3, 0)


def test_save_load_pickle_concatenate_keep_the_dofs(tmp_path):
    res = spacar.simulate(mixed_model())
    res.save(tmp_path / "r.npz")
    back = spacar.Results.load(tmp_path / "r.npz")
    assert back.dof_labels == res.dof_labels
    np.testing.assert_array_equal(back.qdd, res.qdd)
    again = pickle.loads(pickle.dumps(res))
    np.testing.assert_array_equal(again.q, res.q)
    both = spacar.Results.concatenate([res, res])
    assert both.dof_labels == res.dof_labels and both.q.shape == (2 * len(res.t), 2)


def test_dof_labels_parse_as_keys():
    res = spacar.simulate(models.planar_chain(1))
    np.testing.assert_array_equal(res[f"e({HINGE + 1},1) PLHINGE"], res.q[:, 0])
    with pytest.raises(spacar.InputError):
        res["e(1,1) PLHINGE extra"]
    with pytest.raises(spacar.InputError, match="not an element type"):
        res[f"e({HINGE + 1},1) FIX"]

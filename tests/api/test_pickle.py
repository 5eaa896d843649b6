"""Pickling a model (issue #9: models travel to worker processes and dask workers) is lossless:
every field of the C++ model — geometry, classes, state, given flags, origins, settings, the
prepared (frozen) flag — and the Python attributes (blocks, source, warnings, continuation step)
come back exactly, and the copy computes bit-identical results.
"""
from __future__ import annotations

import pickle

import cloudpickle
import numpy as np
import pytest

import spacar
from spacar import InputError
from support.paths import EXAMPLES

EXAMPLE = EXAMPLES / "slidercrank.dat"

SPATIAL = """\
BEAM 1 1 2 3 4 0 1 0
X 3 1.0 0 0
LAMBDA 4 0.6 0.8 0 0
HINGE 2 4 6 0 0 1
TRUSS 3 3 5
X 5 1.0 0.5 0.25
FIX 1
FIX 2
DYNX 6
RLSE 1 2 3
LINE 3 1
ENHC 1 1 1 5
MASS 6 1 0.1 0 2 0 3
MASS 5 0.5
EMASS 1 0.3 0.01
ESTIFF 1 1 2 3 4
EDAMPP 1 0.1
FORCE 5 1 2 3
TORQUEL 6 0.5 0.25
GRAVITY 0 0 -9.81
XD 6 2 0.125
E 3 1 0.001
ED 1 4 0.2
TIME 0.1
JOBID 42
LINEAR 1
HMAX 0.01
EPSKIN 1e-7
TIMESTEP 7 0.3
END
TIMESTEP 3 0.1
END
"""


def snapshot(model: spacar.Model):
    """Every field of the model that pickling must keep, as plain data."""
    core = model.core
    nodes = {nid: (n.id, n.kind.name, n.x, [c.name for c in n.cls], n.xd, n.xdd, n.force, n.mass, n.torquel,
                   n.used, n.origin) for nid, n in core.nodes.items()}
    elements = {eid: (el.id, el.type_name, el.nodes, el.params, el.l0, el.lgeomy, el.estiff, el.edampp, el.emass,
                      [c.name for c in el.cls], el.e, el.ed, el.edd, el.e_given, el.kinematic_of, el.automatic,
                      el.origin) for eid, el in core.elements.items()}
    s = core.settings
    settings = (s.timestep_n, s.timestep_tp, s.hmax, s.maxiterat, s.epskin, s.epsint, s.epsind, s.forcemode,
                s.animate, s.matasc, s.jobid, s.restart, s.linear)
    return (nodes, elements, settings, core.time, core.gravity, core.gravity_given, core.frozen, model.blocks,
            model.source, model.warnings, model._continue_step)


def exact(value):
    """The value with every float replaced by its hex form (tells -0.0 from 0.0, bit for bit)."""
    if isinstance(value, float):
        return ("float", value.hex())
    if isinstance(value, dict):
        return {k: exact(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return type(value)(exact(v) for v in value)
    return value


def same(a, b) -> bool:
    return exact(a) == exact(b) and a == b


def roundtrip(model, dumps=pickle.dumps):
    return pickle.loads(dumps(model))


@pytest.mark.parametrize("dumps", [pickle.dumps, cloudpickle.dumps], ids=["pickle", "cloudpickle"])
def test_the_manual_example_round_trips_exactly_before_and_after_a_run(dumps):
    model = spacar.read(EXAMPLE)
    copy = roundtrip(model, dumps)
    assert same(snapshot(copy), snapshot(model))
    assert copy.dump(digits=17) == model.dump(digits=17)
    assert not copy.core.frozen
    # The same results, bit for bit, and the same state afterwards.
    res_a, res_b = spacar.simulate(model), spacar.simulate(copy)
    for name in ("t", "x", "xd", "xdd", "e", "ed", "edd", "sigma", "reaction"):
        np.testing.assert_array_equal(getattr(res_a, name), getattr(res_b, name))
    assert same(snapshot(copy), snapshot(model))
    # After the run: state at t = 5, prepared, with the continuation step of RESTART 0.
    after = roundtrip(model, dumps)
    assert after.core.frozen and after.current_time == 5.0 and after._continue_step == model._continue_step > 0
    assert same(snapshot(after), snapshot(model))
    res_c, res_d = spacar.simulate(model), spacar.simulate(after)
    np.testing.assert_array_equal(res_c.x, res_d.x)
    np.testing.assert_array_equal(res_c.ed, res_d.ed)
    assert res_c.stats["steps"] == res_d.stats["steps"]


def test_a_spatial_model_with_every_kind_of_field_round_trips_exactly():
    model = spacar.read_string(SPATIAL, "spatial.dat")
    model.warnings.append("a warning")
    copy = roundtrip(model)
    assert same(snapshot(copy), snapshot(model))
    assert len(copy.blocks) == 2 and copy.blocks == model.blocks and copy.source == "spatial.dat"
    model.prepare()  # automatic L2MIN1 elements, reference geometry, frozen
    prepared = roundtrip(model)
    assert same(snapshot(prepared), snapshot(model))
    assert [el.automatic for el in prepared.elements.values()].count(True) == 3  # LAMBDA nodes 2, 4, 6
    assert prepared.dump(digits=17) == model.dump(digits=17)
    # Values that need all 17 digits, negative zero, and extremes survive.
    model = spacar.read_string(SPATIAL)
    for value in (0.1 + 0.2, -0.0, 5e-324, 1.7976931348623157e308, np.nextafter(1.0, 2.0)):
        model.xd(6, 3, value)
        assert roundtrip(model).core.nodes[6].xd[2] == value
        assert str(roundtrip(model).core.nodes[6].xd[2]) == str(value)


def test_an_unprepared_copy_still_takes_new_geometry():
    """Pickling must not freeze the model: lengths follow X until the first END."""
    copy = roundtrip(spacar.read(EXAMPLE))
    copy.x(3, 0.2, 0.0)
    copy.prepare()
    assert copy.elements[1].l0 == pytest.approx(0.2)
    assert copy.elements[2].l0 == pytest.approx(0.1)


def test_a_corrupt_state_is_an_input_error():
    state = spacar._core.Model().__getstate__()
    good = spacar.read(EXAMPLE).core.__getstate__()
    bad_version = (99,) + tuple(good[1:])
    bad_node = list(good)
    bad_node[1] = [tuple(good[1][0][:2]) + ([0.0],) + tuple(good[1][0][3:])]  # node with 1 coordinate
    bad_element = list(good)
    bad_element[2] = [(1, "NOSUCHTYPE") + tuple(good[2][0][2:])]
    for s in (bad_version, tuple(bad_node), tuple(bad_element)):
        with pytest.raises(InputError, match="invalid pickled spacar model"):
            spacar._core.Model.__new__(spacar._core.Model).__setstate__(s)
    assert state[0] == 1


def test_copy_keeps_everything_as_well():
    model = spacar.read_string(SPATIAL)
    assert same(snapshot(model.copy()), snapshot(model))

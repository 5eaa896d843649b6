"""Issue 38, "keep it true": the hostile-input fuzzing extended to the surfaces added since the
reader's fuzzing (test_fuzz.py, test_hostile_fuzz.py): from_urdf, Table, Controller and the
sweep's values. Each hypothesis case (derandomized: the same every run) ends in a result or a
SpacarError (an InputError naming what is wrong) within seconds: never a raw Python error, a
crash or a hang. Also run by the sanitizer job (.ci/sanitizers) on the core built with ASan and
UBSan."""
from __future__ import annotations

import faulthandler
import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import spacar
from support.paths import DATA, EXAMPLES

FUZZ = settings(max_examples=60, derandomize=True, deadline=None, database=None,
                suppress_health_check=list(HealthCheck))

# Values a hostile user (or a bug upstream) passes where numbers belong.
ODD_NUMBERS = st.sampled_from([0.0, -0.0, 1.0, -1.0, 1e-300, 5e-324, 1e300, 1e308, -1e308, math.inf, -math.inf,
                               math.nan, 10**400, -(10**30), 2**63, 1j, True])
ODD_VALUES = st.one_of(ODD_NUMBERS, st.floats(allow_nan=True, allow_infinity=True),
                       st.integers(-10**6, 10**6), st.sampled_from(["", "x", "1e3", "nan", None, (), [], {}, {"a": 1},
                                                                       object(), b"1", "\x00", "1" * 5000]))
NUMBER_LISTS = st.lists(st.one_of(st.floats(-1e6, 1e6), ODD_NUMBERS), max_size=8)


def mostly(good, bad):
    """Three cases in four from ``good``: hostile input is found at the edges of working input."""
    return st.one_of(good, good, good, bad)


@pytest.fixture(autouse=True)
def bounded():
    faulthandler.dump_traceback_later(120, exit=True)  # a hang ends the run with a traceback
    yield
    faulthandler.cancel_dump_traceback_later()


def outcome(call):
    """The call's result, or None for a SpacarError; any other exception fails the test."""
    try:
        return call()
    except spacar.SpacarError:
        return None


# --- from_urdf: a valid URDF with its numbers, names and elements mutated ------------------------

WRIST = (DATA / "wrist.urdf").read_text()
NUMBER = re.compile(r'(?<=")-?[0-9.][0-9.eE+ -]*(?=")')
TAGS = ["<link name=\"extra\"/>", "<joint name=\"j\" type=\"revolute\"><parent link=\"world\"/><child link=\"x\"/></joint>",
        "<joint name=\"f\" type=\"floating\"><parent link=\"world\"/><child link=\"turret\"/></joint>", "<robot>",
        "</link>", "<!DOCTYPE r [<!ENTITY a \"aaaa\">]>", "&a;", "<inertial><mass value=\"-1\"/></inertial>", "\x00"]


@st.composite
def mutated_urdf(draw):
    text = WRIST
    spans = [m.span() for m in NUMBER.finditer(text)]
    for _ in range(draw(st.integers(0, 3))):
        start, end = spans[draw(st.integers(0, len(spans) - 1))]
        plausible = st.floats(-2, 2).map(lambda v: f"{v:.3g}")
        value = draw(st.one_of(plausible, plausible, plausible, ODD_VALUES, st.text(max_size=12)))
        text = text[:start] + str(value).replace('"', "'")[:200] + text[end:]
        spans = [m.span() for m in NUMBER.finditer(text)]
    if draw(st.integers(0, 3)) == 0:
        cut = draw(st.integers(0, len(text)))
        text = text[:cut] + draw(st.sampled_from(TAGS)) + text[cut:]
    if draw(st.integers(0, 9)) == 0:
        text = text[:draw(st.integers(0, len(text)))]  # a truncated file
    return text


@FUZZ
@given(mutated_urdf(), mostly(st.just((0.0, 0.0, -9.81)), st.sampled_from([(0, 0, 10**400), (math.nan, 0, 0), "down",
                                                                           (1.0,)])))
def test_fuzzed_urdf(tmp_path_factory, text, gravity):
    path = tmp_path_factory.mktemp("urdf") / "robot.urdf"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    model = outcome(lambda: spacar.from_urdf(path, gravity=gravity))
    if model is not None:  # a robot read: its dynamics evaluate or say why not
        n = len(model.urdf_joints)
        forces = outcome(lambda: spacar.inverse_dynamics(model, np.zeros(n), np.zeros(n), np.zeros(n),
                                                          time_limit=10))
        assert forces is None or np.isfinite(forces).all()


# --- Table: samples, kinds and times of every odd kind ---------------------------------------------

@st.composite
def table_samples(draw):
    """(t, values): increasing times and as many values (one or two components), one entry in
    four replaced by a hostile one, or hostile as a whole."""
    if draw(st.integers(0, 5)) == 0:
        return draw(st.one_of(NUMBER_LISTS, ODD_VALUES)), draw(st.one_of(NUMBER_LISTS, ODD_VALUES))
    steps = draw(st.lists(mostly(st.floats(1e-3, 10), st.sampled_from([1e-300, 1e-12, 1e300])), min_size=1,
                          max_size=6))
    t = list(np.cumsum([draw(st.floats(-10, 10))] + steps))
    values = [draw(mostly(st.floats(-1e3, 1e3), st.sampled_from([1e300, -1e308])))
              for _ in t]
    if draw(st.booleans()):
        values = [[v, 2 * v] for v in values]
    for _ in range(draw(st.integers(0, 1))):
        target = draw(st.sampled_from([t, values]))
        target[draw(st.integers(0, len(target) - 1))] = draw(ODD_VALUES)
    return t, values


@FUZZ
@given(table_samples(), mostly(st.sampled_from(["linear", "cubic"]), st.sampled_from(["nearest", None, 1])),
       st.lists(st.one_of(st.floats(-20, 1e3), st.floats(-20, 1e3), ODD_VALUES), max_size=4),
       st.sampled_from([0, 1, 2, 0, 1, 2, 3, -1, 1.5]))
def test_fuzzed_table(samples, kind, times, derivative):
    t, values = samples
    table = outcome(lambda: spacar.Table(t, values, kind=kind))
    if table is None:
        return
    for time in times:
        value = outcome(lambda: table(time, derivative))
        assert value is None or np.isfinite(value).all(), (t, values, kind, time, derivative, value)


# --- Controller: sensors, actuators, rates and what the law returns ----------------------------------

# Mostly sensible (nodes 1..9 of the slider-crank, coordinates 1..3), some hostile: most cases run.
NODE = st.one_of(st.integers(1, 9), st.integers(1, 9), st.integers(-1, 12), ODD_VALUES)
COORDINATE = st.one_of(st.integers(1, 3), st.integers(1, 3), st.integers(0, 4), ODD_VALUES)
SENSORS = st.lists(st.tuples(st.sampled_from(["x", "xd", "xdd", "x", "v", 1]), NODE, COORDINATE), max_size=3)
ACTUATORS = st.lists(st.one_of(st.sampled_from([(3, 1), (3, 2), (5, 1), (2, 1)]), st.tuples(NODE, COORDINATE)),
                     min_size=1, max_size=3)
RETURNS = st.one_of(st.just("ones"), st.just("ones"), ODD_VALUES, NUMBER_LISTS)


@FUZZ
@given(SENSORS, ACTUATORS, st.one_of(st.floats(1, 1e3), st.floats(-10, 1e4), ODD_NUMBERS), RETURNS)
def test_fuzzed_controller(sensors, actuators, rate, returned):
    def law(t, y):
        return np.ones(len(actuators)) if isinstance(returned, str) and returned == "ones" else returned

    controller = outcome(lambda: spacar.Controller(law, rate=rate, sensors=sensors, actuators=actuators))
    if controller is None:
        return
    model = spacar.read(EXAMPLES / "slidercrank.dat")
    model.timestep(4, 0.2)
    res = outcome(lambda: spacar.simulate(model, controller=controller, time_limit=10, progress=False))
    assert res is None or np.isfinite(res.x).all()


# --- sweep values: every kind of value on a line's parameter --------------------------------------

KEYS = mostly(st.sampled_from(["XD 2 1", "ESTIFF 2", "EPSINT", "X 3", "GRAVITY"]),
              st.sampled_from(["TIMESTEP", "ESTIFF 99", "FIX 1", "XD 2", "XD two 1", ""]))
SWEEP_VALUES = mostly(st.one_of(st.floats(0.5, 2), st.tuples(st.floats(-1, 1), st.floats(-1, 1)), st.floats(-10, 10)),
                      st.one_of(ODD_VALUES, st.tuples(ODD_VALUES, ODD_VALUES)))


@FUZZ
@given(st.dictionaries(KEYS, mostly(st.lists(SWEEP_VALUES, min_size=1, max_size=3), st.lists(SWEEP_VALUES, max_size=0)),
                       min_size=1, max_size=2))
def test_fuzzed_sweep_values(parameters):
    model = spacar.read(EXAMPLES / "slidercrank.dat")
    model.timestep(2, 0.2)
    result = outcome(lambda: spacar.sweep(model, parameters, workers=1, time_limit=10, progress=False))
    if result is None:
        return
    for error in result.errors:  # a case that failed did so with spacar's error, not a raw one
        assert error.type.startswith("spacar."), error

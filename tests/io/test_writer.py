"""Tests of the state dump (manual §5.7; formulation.md §9.3).

The reference layout is the manual's printed output after 5 s, stored verbatim (tabs, the page
break's blank lines and the manual's mixed spacing included, only the Markdown code fences of the
text version removed) in ``tests/data/manual_output.dat``. The values after 5 s are checked
elsewhere; here the order of the lines, their integer fields, their number of real fields and
the number format are checked, and that dumps are restartable input.
"""
import math
import re

import pytest

import spacar
from support.manual import OUTPUT
from support.paths import EXAMPLES

EXAMPLE = EXAMPLES / "slidercrank.dat"
MANUAL_OUTPUT = OUTPUT

INT_FIELD = re.compile(r"[+-]?\d+")
REAL_FIELD = re.compile(r"-?\d\.\d{3}E[+-]\d{2}")  # %10.3E, as the manual prints


def layout(text):
    """(KEYWORD, integer fields, number of real fields) for every input line of a text."""
    out = []
    for line in text.splitlines():
        words = line.split()
        if not words or line.startswith("*"):
            continue
        ints = tuple(int(w) for w in words[1:] if INT_FIELD.fullmatch(w))
        out.append((words[0].upper(), ints, len(words) - 1 - len(ints)))
    return out


@pytest.fixture(scope="module")
def manual_layout():
    return layout(MANUAL_OUTPUT.read_text())


@pytest.fixture(scope="module")
def run_model():
    """The manual's example after its first block (t = 5 s)."""
    model = spacar.read(EXAMPLE)
    spacar.simulate(model)
    return model


def test_manual_output_file_is_the_manual_block(manual_layout):
    # Spot checks of the transcription against the manual's text.
    assert len(manual_layout) == 58
    assert manual_layout[0] == ("PLBEAM", (1, 1, 2, 3, 4), 0)
    assert manual_layout[3] == ("XY", (1,), 2)
    assert ("MAXITERAT", (10,), 0) in manual_layout
    assert manual_layout[-2] == ("TIMESTEP", (100,), 1)
    assert manual_layout[-1] == ("END", (), 0)


def test_dump_before_running_has_the_manual_layout(manual_layout):
    dump = spacar.read(EXAMPLE).dump()
    assert layout(dump) == manual_layout


def test_dump_after_running_has_the_manual_layout(manual_layout, run_model):
    assert layout(run_model.dump()) == manual_layout


def test_dump_keeps_the_manual_layout_at_any_precision(manual_layout, run_model):
    assert layout(run_model.dump(digits=17)) == manual_layout


def test_dump_before_running_does_not_freeze_the_model():
    model = spacar.read(EXAMPLE)
    model.dump()
    model.pltruss(4, 1, 8)  # new elements are still allowed before the first END
    assert layout(model.dump())[3] == ("PLTRUSS", (4, 1, 8), 0)


def test_number_and_keyword_format(run_model):
    for line in run_model.dump().splitlines():
        keyword = line.split()[0]
        # keyword left-justified in 8 columns (longer keywords in full), then the fields
        if line == "END":
            continue
        head = f"{keyword:<8s}"
        assert line.startswith(head), line
        fields = line[len(head):]
        assert re.fullmatch(r"(( {1,}[+-]?\d+)|( [ -]\d\.\d{3}E[+-]\d{2}))*", fields), line
        for word in line.split()[1:]:
            assert INT_FIELD.fullmatch(word) or REAL_FIELD.fullmatch(word), word
        assert line == line.rstrip()


def test_number_format_examples():
    """Lines built from known values, written as the manual prints them (%3d, %10.3E)."""
    text = EXAMPLE.read_text().replace("X 3 0.15 0.", "X 3 0.051994 0.1407").replace(
        "END", "BETA 5 -0.44431899\nTIME 5\nEND")
    lines = spacar.read_string(text).dump().splitlines()
    assert "XY         3  5.199E-02  1.407E-01" in lines
    assert "BETA       5 -4.443E-01" in lines
    assert "TIME      5.000E+00" in lines
    assert "XD         2   1  1.500E+00" in lines
    assert "PLBEAM     1   1   2   3   4" in lines
    assert "ESTIFF     2  0.000E+00  1.272E-03" in lines
    assert "HMAX      9.999E+03" in lines
    assert "MAXITERAT  10" in lines
    assert "EPSKIN    1.000E-05" in lines
    assert "TIMESTEP 100  5.000E+00" in lines
    assert "LENGTHO    1  1.500E-01" in lines  # reference length of the initial positions
    assert lines[-1] == "END"


def test_settings_lines_match_the_manual(run_model):
    """Lines that do not depend on the motion are the manual's, up to white space."""
    def norm(line):
        return " ".join(line.split())

    ours = {norm(l) for l in run_model.dump().splitlines()}
    static = [norm(l) for l in MANUAL_OUTPUT.read_text().splitlines()
              if l.split() and l.split()[0] in ("PLBEAM", "FIX", "INPUTX", "DYNE", "TIME", "XD", "XDD", "LENGTHO",
                                                 "LGEOMY", "EMASS", "ESTIFF", "HMAX", "MAXITERAT", "EPSKIN",
                                                 "EPSINT", "EPSIND", "FORCEMODE", "ANIMATE", "MATASC", "RESTART",
                                                 "TIMESTEP", "END")]
    assert len(static) == 36
    assert [l for l in static if l not in ours] == []


@pytest.mark.parametrize("run", [False, True], ids=["before run", "after run"])
def test_round_trip_is_identical(run):
    model = spacar.read(EXAMPLE)
    if run:
        spacar.simulate(model)
    for digits in (4, 17):
        first = model.dump(digits=digits)
        again = spacar.read_string(first, "dump.dat").dump(digits=digits)
        assert again == first


def _dumped_state(model):
    nodes = {nid: list(n.x) for nid, n in model.nodes.items()}
    rates = {nid: (list(n.xd), list(n.xdd)) for nid, n in model.nodes.items()}
    dc = spacar._core.DefClass
    moving = (dc.input, dc.dynamic, dc.kinematic)
    es = {(eid, i + 1): (el.e[i], el.ed[i], el.edd[i])
          for eid, el in model.elements.items() for i, c in enumerate(el.cls) if c in moving}
    return nodes, rates, es, model.current_time


def test_restart_with_17_digits_is_lossless(run_model):
    restart = spacar.read_string(run_model.dump(digits=17), "restart.dat")
    nodes, rates, es, t = _dumped_state(run_model)
    nodes2, rates2, es2, t2 = _dumped_state(restart)
    assert t2 == t == 5.0
    assert nodes2 == nodes  # exact equality of every coordinate
    assert es2 == es  # E, ED, EDD of the degrees of freedom
    assert [rates2[n] for n in (2,)] == [rates[n] for n in (2,)]  # the input coordinate
    assert len(es) == 4
    # The 4-digit dump is not lossless (otherwise this test would prove nothing).
    short = spacar.read_string(run_model.dump(), "short.dat")
    assert _dumped_state(short)[0] != nodes


def test_manual_output_parses_as_input():
    model = spacar.read(MANUAL_OUTPUT)
    assert model.warnings == []
    assert len(model.blocks) == 1 and len(model.blocks[0].commands) == 57
    assert model.current_time == 5.0
    assert model.nodes[3].x == [5.199e-02, 1.407e-01]
    assert model.nodes[5].x == [-4.443e-01]
    assert model.elements[2].e[1] == 2.673e-03 and model.elements[3].e[2] == 1.996e-03
    assert all(el.l0 == 0.15 for el in model.elements.values())
    assert model.settings.timestep_n == 100 and model.settings.timestep_tp == 5.0


def test_manual_output_has_the_same_summary_as_the_example():
    s_out = spacar.read(MANUAL_OUTPUT).summary()
    s_in = spacar.read(EXAMPLE).summary()
    for s in (s_out, s_in):
        assert dict(s.coordinates) == {"fixed": 3, "input": 1, "calculable": 9}
        assert dict(s.deformations) == {"fixed": 5, "dynamic": 4}
        assert s.degrees_of_freedom == 4
    assert (s_out.nodes, s_out.elements) == (s_in.nodes, s_in.elements)


def test_manual_output_dump_has_the_manual_layout(manual_layout):
    assert layout(spacar.read(MANUAL_OUTPUT).dump()) == manual_layout


def test_manual_output_runs():
    model = spacar.read(MANUAL_OUTPUT)
    res = spacar.simulate(model)
    assert res.t[0] == 5.0 and math.isclose(res.t[-1], 10.0) and len(res.t) == 101
    assert model.current_time == 10.0
    # The crank turns at the input rate 1.5 rad/s from the dumped angle 7.5 rad.
    assert math.isclose(model.nodes[2].x[0], 7.5 + 1.5 * 5.0, rel_tol=1e-12)


def _model_data(model):
    nodes = {nid: (n.kind.name, list(n.x), [c.name for c in n.cls], list(n.xd), list(n.mass))
             for nid, n in model.nodes.items()}
    elements = {eid: (el.type_name, list(el.nodes), list(el.params), [c.name for c in el.cls], list(el.estiff),
                      list(el.emass)) for eid, el in model.elements.items()}
    s = model.settings
    settings = (s.timestep_n, s.timestep_tp, s.hmax, s.maxiterat, s.epskin, s.epsint, s.epsind, s.forcemode,
                s.animate, s.matasc, s.restart)
    return nodes, elements, settings, model.current_time


def _flat(data):
    """All numbers of a nested structure, in order; strings kept as they are."""
    if isinstance(data, dict):
        return [x for k in sorted(data) for x in [k, *_flat(data[k])]]
    if isinstance(data, (list, tuple)):
        return [x for item in data for x in _flat(item)]
    return [data]


def test_round_trip_gives_the_same_model():
    """Issue #2: parse the manual's example, write the dump, parse it again: same model --
    exactly with 17 digits; with the manual's 4 digits up to that rounding (MASS 0.033375 is
    written 3.338E-02 and ESTIFF 0.0012723 as 1.272E-03, as in the manual's output)."""
    original = spacar.read(EXAMPLE)
    exact = spacar.read_string(original.dump(digits=17), "dump17.dat")
    assert _model_data(exact) == _model_data(original)
    rounded = _flat(_model_data(spacar.read_string(original.dump(), "dump.dat")))
    expected = _flat(_model_data(original))
    assert len(rounded) == len(expected)
    for a, b in zip(rounded, expected):
        assert a == b if isinstance(b, str) else math.isclose(a, b, rel_tol=5e-4), (a, b)
    # The dump also carries the reference geometry computed at the first END.
    assert [el.l0 for el in exact.elements.values()] == pytest.approx([0.15, 0.15, 0.15], rel=1e-15)

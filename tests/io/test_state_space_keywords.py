"""The state-space keywords INPUTF, INPUTS, OUTX, OUTXP, OUTE, OUTEP (issue 22): read, applied to
the model, written by the dump and read back to the same signals and the same state-space
model; bad lines are input errors naming the file, line and keyword."""
import numpy as np
import pytest

import spacar

TEXT = """\
PLTRUSS 1 1 2
PLTRUSS 2 2 3
X 2 1. 0.
X 3 2. 0.
FIX 1
FIX 2 2
FIX 3 2
DYNX 2 1
DYNX 3 1
RLSE 1
RLSE 2
ESTIFF 1 30.
ESTIFF 2 20.
EDAMPP 2 0.4
MASS 2 1.
MASS 3 2.
inputf 2 3 1
INPUTS 1 1 1
OUTX 1 3 1
OUTXP 2 3 1
OUTE 4 2 1
OUTEP 3 2 1
OUTS 5 1 1
END
"""


def test_keywords_are_read_into_the_model():
    m = spacar.read_string(TEXT, "chain.dat")
    assert {k: s[:3] for k, s in m.state_space_inputs.items()} == {1: ("INPUTS", 1, 1), 2: ("INPUTF", 3, 1)}
    assert {k: s[:3] for k, s in m.state_space_outputs.items()} == {
        1: ("OUTX", 3, 1), 2: ("OUTXP", 3, 1), 3: ("OUTEP", 2, 1), 4: ("OUTE", 2, 1), 5: ("OUTS", 1, 1)}
    assert m.state_space_inputs[2].origin == "chain.dat, line 17, keyword INPUTF"


def test_dump_round_trip():
    m = spacar.read_string(TEXT)
    text = m.dump(digits=17)
    for line in ("INPUTF     2   3   1", "INPUTS     1   1   1", "OUTX       1   3   1", "OUTXP      2   3   1",
                 "OUTEP      3   2   1", "OUTE       4   2   1", "OUTS       5   1   1"):
        assert line in text.splitlines()
    again = spacar.read_string(text)
    assert {k: s[:3] for k, s in again.state_space_inputs.items()} == {k: s[:3] for k, s in m.state_space_inputs.items()}
    assert {k: s[:3] for k, s in again.state_space_outputs.items()} == {
        k: s[:3] for k, s in m.state_space_outputs.items()}
    a, b = spacar.state_space(m), spacar.state_space(again)
    for name in "ABCD":
        np.testing.assert_allclose(getattr(a, name), getattr(b, name), rtol=1e-12, atol=1e-14)
    assert a.input_labels == ["sigma(1,1)", "f(3,1)"] and a.output_labels == ["x(3,1)", "xd(3,1)", "ed(2,1)", "e(2,1)",
                                                                           "sigma(1,1)"]
    # and the copy keeps them
    assert m.copy().state_space_outputs == m.state_space_outputs


def test_a_later_line_replaces_the_signal():
    m = spacar.read_string(TEXT)
    m.outx(1, 2, 1)
    assert m.state_space_outputs[1][:3] == ("OUTX", 2, 1)


@pytest.mark.parametrize("line, message", [
    ("OUTX 1 9 1", "line 17, keyword OUTX: node 9 does not exist"),
    ("OUTX 1 3 3", "line 17, keyword OUTX: node 3 has coordinates 1..2, not 3"),
    ("INPUTS 1 7 1", "line 17, keyword INPUTS: element 7 does not exist"),
    ("OUTEP 1 2 2", "line 17, keyword OUTEP: element 2 has deformations 1..1, not 2"),
    ("INPUTF 0 3 1", "line 17, keyword INPUTF: the number k of an input or output must be 1 or more, got 0"),
    ("OUTE 1 2", "line 17, keyword OUTE: OUTE expects OUTE k e i: too few values"),
    ("OUTXP 1 2 1 4", "line 17, keyword OUTXP: OUTXP expects OUTXP k n i: too many values"),
    ("INPUTF 1.5 3 1", "line 17, keyword INPUTF: '1.5' is not an integer"),
])
def test_bad_lines_name_the_file_line_and_keyword(line, message):
    lines = TEXT.splitlines()
    lines[16] = line
    with pytest.raises(spacar.InputError, match=message):
        spacar.read_string("\n".join(lines) + "\n", "chain.dat")

"""Bad input (issue #2): every error is a ``spacar.InputError`` whose message names the file, the
line number, the keyword and the reason; nothing else is ever raised, nothing crashes.

Each case is the manual's slider-crank (§5.7) with one line changed, inserted or appended, so
the expected line number and keyword are known from the text itself. Errors that can only be
found at the first END (zero length, unused node) are provoked with ``model.summary()`` and must
name the line that defined the element or node.
"""
import re

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import spacar
from spacar import InputError
from support.fuzzing import LINE_EDITS, mutated_lines
from support.paths import EXAMPLES

EXAMPLE = EXAMPLES / "slidercrank.dat"

BASE = EXAMPLE.read_text().splitlines()  # 23 lines, END on line 23


def replace(lineno, new):
    lines = list(BASE)
    lines[lineno - 1] = new
    return "\n".join(lines) + "\n"


def insert(lineno, new):
    """Insert ``new`` so that it becomes line ``lineno``."""
    lines = list(BASE)
    lines.insert(lineno - 1, new)
    return "\n".join(lines) + "\n"


def append(*new):
    return "\n".join(BASE + list(new)) + "\n"


SPATIAL = "BEAM 1 1 2 3 4 0 1 0\nX 3 1.0 0 0\n"

# (id, text, line, keyword, reason regex)
CASES = [
    ("unknown keyword", replace(3, "PLBEEM 3 6 7 8 9"), 3, "PLBEEM", r"unknown keyword"),
    ("too few values", replace(2, "PLBEAM 2 3 5 6"), 2, "PLBEAM", r"too few values"),
    ("too many values", replace(14, "TIMESTEP 100 5.0 7"), 14, "TIMESTEP", r"too many values"),
    ("surplus value on an element", replace(1, "PLBEAM 1 1 2 3 4 5"), 1, "PLBEAM", r"too many values"),
    ("value on END", replace(23, "END 1"), 23, "END", r"too many values"),
    ("wrong type", replace(10, "DYNE two 2"), 10, "DYNE", r"'two' is not an integer"),
    ("number does not parse", replace(6, "X 3 0.15 0.0.1"), 6, "X", r"'0\.0\.1' is not a number"),
    ("lone sign", replace(15, "MASS 8 -"), 15, "MASS", r"'-' is not a number"),
    ("non-integral integer", replace(5, "FIX 8 2.5"), 5, "FIX", r"'2\.5' is not an integer"),
    ("nan", replace(6, "X 3 nan 0."), 6, "X", r"'nan' is not a number.*NaN"),
    ("inf", replace(15, "MASS 8 inf"), 15, "MASS", r"'inf' is not a number.*infinity"),
    ("-Infinity", insert(14, "EPSKIN -Infinity"), 14, "EPSKIN", r"not a number.*infinity"),
    ("overflowing real", replace(15, "MASS 8 1e400"), 15, "MASS", r"finite"),
    ("huge integer", replace(5, "FIX 99999999999 2"), 5, "FIX", r"out of range"),
    ("node with two kinds (element)", replace(2, "PLBEAM 2 3 5 4 7"), 2, "PLBEAM",
     r"node 4 is a BETA node and cannot be the p2 \(XY\) node of PLBEAM 2"),
    ("node with two kinds (keyword)", insert(4, "XY 2 0.0 0.0"), 4, "XY", r"node 2 is a BETA node, not a XY node"),
    ("component out of range (XY)", replace(5, "FIX 8 3"), 5, "FIX", r"node 8 \(XY\) has components 1\.\.2, not 3"),
    ("component out of range (BETA)", replace(9, "INPUTX 2 2"), 9, "INPUTX", r"node 2 \(BETA\) has components 1\.\.1"),
    ("too many coordinates for the kind", insert(9, "X 2 1.0 2.0"), 9, "X", r"node 2 \(BETA\) has 1 coordinates, got 2"),
    ("element defined twice", replace(3, "PLBEAM 2 6 7 8 9"), 3, "PLBEAM", r"element 2 is already defined"),
    ("undefined element", replace(10, "DYNE 4 2"), 10, "DYNE", r"element 4 is not defined"),
    ("undefined node", replace(5, "FIX 10 2"), 5, "FIX", r"node 10 is not defined"),
    ("mass on an undefined node", replace(15, "MASS 10 0.1"), 15, "MASS", r"node 10 is not defined"),
    ("node used twice by an element", replace(1, "PLBEAM 1 1 2 1 4"), 1, "PLBEAM", r"uses node 1 twice"),
    ("negative node number", replace(4, "FIX -1"), 4, "FIX", r"node -1 is not defined|positive"),
    ("zero element number", replace(1, "PLBEAM 0 1 2 3 4"), 1, "PLBEAM", r"element numbers must be positive"),
    # Zero length is found at the first END; the message names the element's own line.
    ("zero-length element", replace(8, "X 8 0.30 0."), 3, "PLBEAM", r"PLBEAM 3 has zero length"),
    ("unused node", insert(9, "X 20 1.0 0.0"), 9, "X", r"node 20 is not used by any element"),
    ("negative mass", replace(15, "MASS 8 -0.033375"), 15, "MASS", r"negative"),
    ("negative distributed mass", replace(16, "EMASS 1 -0.2225"), 16, "EMASS", r"negative"),
    ("negative stiffness", replace(19, "ESTIFF 2 0. -0.0012723"), 19, "ESTIFF", r"negative"),
    ("wrong number of MASS values", replace(15, "MASS 8 1 2"), 15, "MASS", r"takes 1 value"),
    ("text after EOF", append("EOF", "FIX 1"), 25, "FIX", r"text after EOF"),
    ("LAMBDA far from unit length", SPATIAL + "LAMBDA 2 0.9 0.1 0 0\nEND\n", 3, "LAMBDA",
     r"Euler parameters of node 2 have norm 0\.90\d*; they must be of unit length"),
    ("X sets Euler parameters off the unit sphere", SPATIAL + "X 4 0.5\nEND\n", 3, "X",
     r"Euler parameters of node 4 have norm 0\.5"),
    ("Euler parameters given before the node is a LAMBDA node", "X 2 2 0 0 0\n" + SPATIAL + "END\n", 2, "BEAM",
     r"Euler parameters of node 2 have norm 2"),
    ("DIR without direction vector", insert(4, "DIR 1 0 0 1"), 4, "DIR", r"PLBEAM has no direction vector"),
    ("ESTIFF without stiffness", "SURFACE 1 1 1 1 1 0 0 0 0 0 0 -1\nESTIFF 1 1.0\nEND\n", 2, "ESTIFF",
     r"SURFACE has no stiffness"),
    ("EMASS without distributed mass", insert(4, "PLHINGE 4 2 4\nEMASS 4 1.0"), 5, "EMASS",
     r"PLHINGE has no distributed mass"),
    ("E index out of range", insert(22, "E 2 4 0.1"), 22, "E", r"element 2 \(PLBEAM\) has deformations 1\.\.3, not 4"),
    ("ENHC kinematic coordinate not fixed", insert(14, "ENHC 1 1 2 2"), 14, "ENHC", r"must be a fixed deformation"),
    ("TIMESTEP negative count", replace(14, "TIMESTEP -100 5.0"), 14, "TIMESTEP", r"must not be negative"),
    ("MAXITERAT 0", insert(14, "MAXITERAT 0"), 14, "MAXITERAT", r"MAXITERAT must be between 1 and"),
    ("EPSKIN negative", insert(14, "EPSKIN -1e-5"), 14, "EPSKIN", r"EPSKIN must be a positive tolerance"),
    ("HMAX zero", insert(14, "HMAX 0"), 14, "HMAX", r"HMAX must be positive"),
    ("FORCEMODE 3", insert(14, "FORCEMODE 3"), 14, "FORCEMODE", r"between 0 and 2"),
    ("LENGTHO negative", insert(14, "LENGTHO 1 -0.15"), 14, "LENGTHO", r"must be positive"),
    ("keyword starting with a digit", insert(5, "8FIX 2"), 5, "8FIX", r"must start with a keyword"),
    ("asterisk not in column 1", insert(5, " * a comment?"), 5, "*", r"must start with a keyword"),
]


@pytest.mark.parametrize("text, line, keyword, reason", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_input_names_file_line_keyword_and_reason(tmp_path, text, line, keyword, reason):
    path = tmp_path / "bad_input.dat"
    path.write_text(text)
    with pytest.raises(InputError) as info:
        spacar.read(path).summary()
    message = str(info.value)
    assert message.startswith(f"{path}, line {line}, keyword {keyword}: "), message
    assert re.search(reason, message), message


def test_at_least_15_distinct_cases():
    assert len({c[0] for c in CASES}) == len(CASES) >= 15


def test_the_cases_are_single_changes_of_a_valid_file():
    """The unchanged example is valid, so each case's error is caused by its change."""
    model = spacar.read(EXAMPLE)
    model.summary()
    spacar.read_string(SPATIAL + "END\n").summary()


def test_zero_length_is_also_reported_by_simulate():
    model = spacar.read_string(replace(8, "X 8 0.30 0."), "zero.dat")
    with pytest.raises(InputError, match=r"^zero\.dat, line 3, keyword PLBEAM: PLBEAM 3 has zero length"):
        spacar.simulate(model)


def test_zero_length_with_the_builder_names_the_element():
    m = spacar.Model()
    m.pltruss(7, 1, 2)
    with pytest.raises(InputError, match=r"PLTRUSS 7 has zero length"):
        m.summary()


def test_a_failing_line_leaves_the_model_unchanged():
    m = spacar.Model()
    m.beam(1, 1, 2, 3, 4, 0, 1, 0)
    with pytest.raises(InputError):
        m.x(2, 0.5)  # would make the Euler parameters of node 2 non-unit
    assert m.nodes[2].x == [1.0, 0.0, 0.0, 0.0]
    with pytest.raises(InputError):
        m.lambda_(5, 2, 0, 0, 0)  # a new node with bad Euler parameters is not created
    assert 5 not in m.nodes


def test_builder_rejects_wrong_types():
    m = spacar.Model()
    with pytest.raises(InputError, match="integer"):
        m.pltruss(1.5, 1, 2)
    with pytest.raises(InputError, match="number"):
        m.pltruss("1", 1, 2)
    m.pltruss(1, 1, 2)
    with pytest.raises(InputError, match="finite"):
        m.x(2, float("nan"), 0.0)
    with pytest.raises(InputError, match="too many"):
        m.pltruss(2, 1, 2, 3)


def test_new_element_after_the_first_end_is_an_error(example_text):
    model = spacar.read_string(example_text + "PLTRUSS 4 1 8\nEND\n", "two.dat")
    spacar.simulate(model)
    with pytest.raises(InputError, match=r"^two\.dat, line 24, keyword PLTRUSS: .*after the first END"):
        spacar.io.reader.apply_block(model, model.blocks[1])


# --- property: random mutations of the example only ever raise InputError ----------------------

KEYWORD_NAMES = sorted(spacar.KEYWORDS)
GARBAGE_TOKENS = ["nan", "NaN", "inf", "-inf", "Infinity", "1e400", "-1e400", "1e-400", "0", "-0", "-1", "2.5",
                  "99999999999999999999", "2147483648", "-2147483649", "4294967297", "1.0D-3", ".5", "1.",
                  "1e", "e1", "--1", "+-1", "0x10", "1_000", "\u0663", "*", "#", "END", "EOF", "\x00", "é"]
EXTRA_LINES = ["BEAM 4 10 11 12 13 0 1 0", "LAMBDA 11 0.6 0.8 0 0", "HINGE 5 11 13 0 0 1", "PLTRUSS 6 1 8",
               "PLHINGE 7 2 4", "PLBELT 8 1 2 3 4 0.1 0.2", "PLWHEEL 9 1 2 4 0.1 1 0",
               "SURFACE 10 10 1 1 1 0 0 0 0 0 0 -1", "L2MIN1 11 11", "ENHC 1 1 2 1", "LGEOMY 1 0.5",
               "LENGTHO 1 0.2", "DIR 4 0 0 1", "RLSE 1", "LINE 1 1", "TORQUEL 11 1", "FORCE 8 1", "GRAVITY 0 -9.81",
               "EDAMPP 2 1 1", "MASS 11 1 0 0 1 0 1", "BEARING 12 10 11 12 13 1 0 0", "TRUSS 13 10 12",
               "PLBEAR 14 1 2 3 4", "PLBEAMNL 15 1 2 3 4", "INPUTE 1 1", "DYNX 3 1", "E 1 1 0.1", "TIME 1",
               "LINEAR 1", "JOBID 3", "EOF", "END", "* comment", ""]

tokens = st.one_of(
    st.sampled_from(GARBAGE_TOKENS),
    st.sampled_from(KEYWORD_NAMES),
    st.integers(min_value=-(2**70), max_value=2**70).map(str),
    st.integers(min_value=-3, max_value=15).map(str),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.text(alphabet=st.characters(blacklist_categories=("Cs",), blacklist_characters="\r\n"),
            min_size=1, max_size=6).filter(lambda s: s.split() == [s]),
)


def mutated_example():
    return mutated_lines(BASE, LINE_EDITS, max_edits=5, token=tokens, keyword=st.sampled_from(KEYWORD_NAMES),
                         new_line=st.sampled_from(EXTRA_LINES))


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated_example())
def test_random_mutations_raise_only_input_error(text):
    try:
        model = spacar.read_string(text, "mutant.dat")
        model.summary()
    except InputError as err:
        message = str(err)
        # Every error of the reader names the file (and, from the file, a line).
        assert message.startswith("mutant.dat"), message
        assert re.match(r"mutant\.dat, line \d+, keyword \S+: .", message), message

"""Tests of the reader (manual §5, formulation.md §9.1-9.2) on the manual's slider-crank example.

Expectations come from the manual: the example input of §5.7 (transcribed line by line in
support/manual.py), the lexical rules of §5 (keywords of at most 8 significant characters in any
case, ``*`` comment lines, Fortran numbers, blocks ended by END, EOF) and the counts required by
issue #2.
"""
import math

import pytest

import spacar
from spacar import InputError
from support.manual import INPUT

MANUAL_EXAMPLE = INPUT  # the manual's example input (§5.7), as (keyword, values)


def build_slidercrank_with_builder():
    """The manual's example through the builder API, one method call per input line."""
    m = spacar.Model()
    for keyword, values in MANUAL_EXAMPLE:
        getattr(m, keyword.lower())(*values)
    return m


def test_manual_example_parses(example_path, example_text):
    blocks = spacar.parse(example_text, str(example_path))
    assert len(blocks) == 1
    cmds = blocks[0].commands
    assert [(c.keyword, c.args) for c in cmds] == MANUAL_EXAMPLE
    # One command per line, numbered from 1; END (line 23) closes the block.
    assert [c.line for c in cmds] == list(range(1, 23))
    assert blocks[0].ended
    # Integer fields are ints, real fields floats, whatever their spelling in the file.
    assert all(type(v) is int for v in cmds[0].args)
    assert type(cmds[5].args[1]) is float and type(cmds[5].args[2]) is float


def test_read_returns_model_with_blocks_and_line_numbers(example_path):
    model = spacar.read(example_path)
    assert isinstance(model, spacar.Model)
    assert model.source == str(example_path)
    assert len(model.blocks) == 1
    cmd = model.blocks[0].commands[13]
    assert (cmd.keyword, cmd.line, cmd.file) == ("TIMESTEP", 14, str(example_path))
    assert cmd.where() == f"{example_path}, line 14, keyword TIMESTEP"
    # The first block is applied: the model has the manual's elements and settings.
    assert sorted(model.elements) == [1, 2, 3]
    assert model.settings.timestep_n == 100 and model.settings.timestep_tp == 5.0
    assert model.nodes[8].mass == [0.033375]
    assert model.nodes[2].xd == [1.5]


def test_summary_counts_of_issue_2(example_path):
    s = spacar.read(example_path).summary()
    assert s.n_coordinates == 13
    assert dict(s.coordinates) == {"fixed": 3, "input": 1, "calculable": 9}
    assert s.n_deformations == 9
    assert dict(s.deformations) == {"fixed": 5, "dynamic": 4}
    assert s.degrees_of_freedom == 4
    assert dict(s.nodes) == {"XY": 4, "BETA": 5}
    assert dict(s.elements) == {"PLBEAM": 3}
    text = str(s)
    assert "nodal coordinates: 13 (3 fixed, 1 input, 9 calculable)" in text
    assert "deformations: 9 (5 fixed, 4 dynamic)" in text
    assert "degrees of freedom: 4" in text


def test_summary_does_not_freeze_the_model(example_path):
    model = spacar.read(example_path)
    model.summary()
    model.plbeam(4, 8, 9, 10, 11)  # still open for new elements before the first END
    assert 4 in model.elements


@pytest.mark.parametrize("spelling", ["Timestep", "timestep", "TIMESTEP", "tImEsTeP"])
def test_keywords_are_case_insensitive(spelling):
    (block,) = spacar.parse(f"{spelling} 100 5.0\nEND\n")
    assert block.commands[0].keyword == "TIMESTEP"
    assert block.commands[0].args == (100, 5.0)


def test_case_insensitive_builder_dispatch(example_text):
    lower = spacar.read_string(example_text.lower())
    assert lower.dump() == spacar.read_string(example_text).dump()


@pytest.mark.parametrize(
    "token, keyword",
    [
        ("MAXITERAT", "MAXITERAT"),
        ("MAXITERATIONS", "MAXITERAT"),
        ("FORCEMODE", "FORCEMODE"),
        ("FORCEMOD", "FORCEMODE"),
        ("TIMESTEPXYZ", "TIMESTEP"),
        ("EPSKIN", "EPSKIN"),
        ("LENGTH0", "LENGTHO"),  # alias of the manual's LENGTHO (formulation §9.1)
    ],
)
def test_only_the_first_8_characters_of_a_keyword_count(token, keyword):
    args = {"MAXITERAT": "20", "FORCEMODE": "2", "TIMESTEP": "10 1.0", "EPSKIN": "1e-6", "LENGTHO": "1 0.2"}
    (block,) = spacar.parse(f"{token} {args[keyword]}\nEND\n")
    assert block.commands[0].keyword == keyword


def test_truncated_keywords_set_the_settings(example_text):
    text = example_text.replace("END", "MAXITERATIONS 20\nFORCEMODEX 2\nTIMESTEPXYZ 10 1.0\nEND")
    s = spacar.read_string(text).settings
    assert (s.maxiterat, s.forcemode, s.timestep_n, s.timestep_tp) == (20, 2, 10, 1.0)


@pytest.mark.parametrize("token", ["TIMESTOP", "EPSKINEMATIC", "TIMESTE"])
def test_a_keyword_differing_within_8_characters_is_unknown(token):
    with pytest.raises(InputError, match=rf"line 1, keyword {token}: unknown keyword"):
        spacar.parse(f"{token} 10 1.0\nEND\n")


def test_comment_lines(example_text):
    lines = example_text.splitlines()
    commented = ["* the manual's slider-crank", "*PLBEAM 99 1 2 3 4", "*"]
    lines[3:3] = commented
    lines.insert(0, "**** header")
    text = "\n".join(lines) + "\n* trailer\n"
    (block,) = spacar.parse(text)
    assert [(c.keyword, c.args) for c in block.commands] == MANUAL_EXAMPLE
    # Line numbers count the comment lines.
    assert block.commands[0].line == 2
    assert block.commands[3].line == 8


def test_blank_lines_and_white_space_are_ignored():
    text = "\n   \nPLTRUSS\t1   1\t 2\n\n X 2 1.0 0.0 \r\nEND\n"
    (block,) = spacar.parse(text)
    assert [(c.keyword, c.args, c.line) for c in block.commands] == [
        ("PLTRUSS", (1, 1, 2), 3),
        ("X", (2, 1.0, 0.0), 5),
    ]


def test_line_numbers_count_only_real_line_breaks():
    # A form feed inside a line is white space, not a line break (str.splitlines() would split).
    with pytest.raises(InputError, match=r"line 2, keyword FOO"):
        spacar.parse("PLTRUSS 1 1 \f 2\nFOO\n")


@pytest.mark.parametrize(
    "token, value",
    [
        ("1.", 1.0),
        (".5", 0.5),
        ("1e-3", 1e-3),
        ("1E-3", 1e-3),
        ("1.0D-3", 1e-3),
        ("1.0d-3", 1e-3),
        ("2.5E+01", 25.0),
        ("-.25", -0.25),
        ("+3.", 3.0),
        ("7", 7.0),
        ("1.5D0", 1.5),
    ],
)
def test_fortran_real_numbers(token, value):
    (block,) = spacar.parse(f"EPSKIN {token}\nMASS 8 {token}\nEND\n")
    assert block.commands[0].args == (value,)
    assert block.commands[1].args == (8, value)
    assert type(block.commands[0].args[0]) is float


@pytest.mark.parametrize("token", ["8", "+8", "8.", "8.0", "8.0D0", "0.8E1"])
def test_integer_fields_accept_integral_numbers(token):
    (block,) = spacar.parse(f"FIX {token} 2\nEND\n")
    assert block.commands[0].args == (8, 2)
    assert type(block.commands[0].args[0]) is int


def test_omitted_index_means_all_components(example_path):
    model = spacar.read(example_path)
    fixed = spacar._core.CoordClass.fixed
    assert list(model.nodes[1].cls) == [fixed, fixed]  # FIX 1 fixes x and y
    calc = spacar._core.CoordClass.calculable
    assert list(model.nodes[8].cls) == [calc, fixed]  # FIX 8 2 only y


def test_omitted_index_means_all_deformations():
    model = spacar.read_string("PLBEAM 1 1 2 3 4\nX 3 1 0\nDYNE 1\nRLSE 1 1\nEND\n")
    dc = spacar._core.DefClass
    assert list(model.elements[1].cls) == [dc.released, dc.dynamic, dc.dynamic]


def test_index_lists():
    model = spacar.read_string("PLBEAM 1 1 2 3 4\nX 3 1 0\nFIX 3 2 1\nDYNE 1 3 2\nEND\n")
    cc, dc = spacar._core.CoordClass, spacar._core.DefClass
    assert list(model.nodes[3].cls) == [cc.fixed, cc.fixed]
    assert list(model.elements[1].cls) == [dc.fixed, dc.dynamic, dc.dynamic]


def test_blocks_are_split_at_end(example_text):
    text = example_text + "* second block\nTIMESTEP 10 1.0\nXD 2 1 2.0\nEND\nEPSKIN 1e-6\nEND\n"
    blocks = spacar.parse(text)
    assert [len(b.commands) for b in blocks] == [22, 2, 1]
    assert [(c.keyword, c.line) for c in blocks[1].commands] == [("TIMESTEP", 25), ("XD", 26)]
    assert blocks[2].commands[0].line == 28
    model = spacar.read_string(text)
    assert len(model.blocks) == 3
    # Only the first block is applied by read_string; the others wait for the analysis.
    assert model.settings.timestep_n == 100


def test_eof_ends_the_input(example_text):
    text = example_text + "EOF\n* comments and blank lines after EOF are fine\n\n"
    blocks = spacar.parse(text)
    assert len(blocks) == 1
    assert spacar.read_string(text).warnings == []


def test_eof_is_case_insensitive_and_ends_an_open_block_with_a_warning(example_text):
    text = example_text + "TIMESTEP 10 1.0\neof\n"
    model = spacar.read_string(text, "two.dat")
    assert len(model.blocks) == 1
    (warning,) = model.warnings
    assert "two.dat" in warning and "line" in warning and "24" in warning


def test_block_without_end_is_a_warning_not_an_error(example_text):
    text = example_text.replace("END\n", "")
    model = spacar.read_string(text, "noend.dat")
    assert model.blocks == []
    assert len(model.elements) == 0  # nothing is applied
    (warning,) = model.warnings
    assert "noend.dat" in warning and "END" in warning and "1..22" in warning


@pytest.mark.parametrize("text", ["", "\n\n", "* only\n* comments\n", "*\n   \n*END\n"])
def test_empty_input_is_nothing(text):
    model = spacar.read_string(text, "empty.dat")
    assert model.blocks == [] and model.warnings == []
    s = model.summary()
    assert (s.n_coordinates, s.n_deformations, s.degrees_of_freedom) == (0, 0, 0)


def test_builder_api_gives_the_same_model_as_the_file(example_path):
    from_file = spacar.read(example_path)
    built = build_slidercrank_with_builder()
    assert built.dump() == from_file.dump()
    assert built.dump(digits=17) == from_file.dump(digits=17)
    s1, s2 = built.summary(), from_file.summary()
    assert (s1.coordinates, s1.deformations) == (s2.coordinates, s2.deformations)


def test_builder_api_and_file_agree_after_a_run(example_path):
    from_file = spacar.read(example_path)
    built = build_slidercrank_with_builder()
    r1 = spacar.simulate(from_file)
    r2 = spacar.simulate(built)
    assert r1.t[-1] == r2.t[-1] == 5.0
    assert built.dump(digits=17) == from_file.dump(digits=17)


def test_builder_apply_is_the_reader_dispatch():
    m = spacar.Model()
    m.apply("PLTRUSS", 1, 1, 2)
    m.apply("x", 2, 1.0, 0.0)
    assert m.nodes[2].x == [1.0, 0.0]
    with pytest.raises(InputError, match="unknown keyword"):
        m.apply("END")


def test_beta_and_lambda_node_keywords():
    m = spacar.read_string(
        "PLBEAM 1 1 2 3 4\nBETA 2 0.25\nXY 3 1.0 0.0\n"
        "BEAM 2 5 6 7 8 0 1 0\nXYZ 7 1 0 0\nLAMBDA 8 0.6 0.8 0 0\nEND\n")
    assert m.nodes[2].x == [0.25]
    assert m.nodes[3].x == [1.0, 0.0]
    assert m.nodes[8].x == [0.6, 0.8, 0.0, 0.0]
    assert m.nodes[6].x == [1.0, 0.0, 0.0, 0.0]  # implicit LAMBDA node: no rotation (§5.1 note 1)
    assert math.isclose(sum(v * v for v in m.nodes[8].x), 1.0)

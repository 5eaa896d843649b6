"""Tests of the ``spacar`` command line (``spacar check``, ``spacar run``) as a user runs it: in a
subprocess, both as ``python -m spacar`` and as the ``spacar`` console script installed next to
the interpreter. Expectations: issue #2 (the counts of ``check``), formulation.md §9.3 (the
output of ``run`` is valid input: the dump plus ``*`` comment lines) and §9.2 (blocks).

The subprocesses are started together (each spends most of its time importing), then awaited;
further cases run ``spacar.cli.main`` in-process.
"""
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import spacar
from spacar.keywords import LOOKUP
from support.paths import EXAMPLES

EXAMPLE = EXAMPLES / "slidercrank.dat"

SCRIPT = Path(sys.executable).parent / ("spacar.exe" if os.name == "nt" else "spacar")

SECOND_BLOCK = "* continue for one second\nTIMESTEP 10 1.0\nEND\n"
NEW_ELEMENT_BLOCK = "* a new element after the first END is an error\nPLTRUSS 4 1 8\nEND\n"
BAD_LINE = "FIX 8 3"  # node 8 is an XY node: components 1..2


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("cli")
    example = EXAMPLE.read_text()
    paths = {"two": tmp / "two.dat", "bad": tmp / "bad.dat"}
    paths["two"].write_text(example + SECOND_BLOCK)
    paths["bad"].write_text(example.replace("FIX 8 2", BAD_LINE))
    module = [sys.executable, "-m", "spacar"]
    commands = {
        "check_module": module + ["check", str(EXAMPLE)],
        "check_script": [str(SCRIPT), "check", str(EXAMPLE)],
        "run": module + ["run", str(EXAMPLE)],
        "run_two": [str(SCRIPT), "run", str(paths["two"])],
        "run_bad": module + ["run", str(paths["bad"])],
    }
    procs = {name: subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for name, cmd in commands.items()}
    out = {}
    for name, p in procs.items():
        stdout, stderr = p.communicate(timeout=120)
        out[name] = (p.returncode, stdout, stderr)
    out["paths"] = paths
    return out


def dumps(stdout):
    """The dumps of a ``spacar run`` output: the blocks of lines ending with END."""
    blocks, current = [], []
    for line in stdout.splitlines():
        if line.startswith("*"):
            continue
        current.append(line)
        if line.split()[:1] == ["END"]:
            blocks.append("\n".join(current) + "\n")
            current = []
    return blocks


def test_console_script_is_installed():
    assert SCRIPT.exists(), SCRIPT


@pytest.mark.parametrize("how", ["check_module", "check_script"])
def test_check_reports_the_counts_of_issue_2(runs, how):
    code, stdout, stderr = runs[how]
    assert code == 0, stderr
    lines = stdout.splitlines()
    assert all(line.startswith("*") for line in lines), stdout
    text = "\n".join(line.lstrip("* ") for line in lines)
    assert re.search(r"^nodal coordinates: 13 \(3 fixed, 1 input, 9 calculable\)$", text, re.M), text
    assert re.search(r"^deformations: 9 \(5 fixed, 4 dynamic\)$", text, re.M), text
    assert re.search(r"^degrees of freedom: 4$", text, re.M), text
    assert re.search(r"^nodes: 9 \(5 BETA, 4 XY\)$", text, re.M), text
    assert re.search(r"^elements: 3 \(3 PLBEAM\)$", text, re.M), text


def test_check_output_is_the_same_both_ways(runs):
    assert runs["check_module"][1] == runs["check_script"][1]


def test_run_prints_a_dump_that_is_valid_input(runs):
    code, stdout, stderr = runs["run"]
    assert code == 0, stderr
    for line in stdout.splitlines():
        words = line.split()
        # every line is a comment or a keyword line
        assert line.startswith("*") or LOOKUP.get(words[0].upper()[:8]) is not None, line
    (dump,) = dumps(stdout)
    model = spacar.read_string(stdout, "stdout")
    assert model.warnings == []
    assert model.current_time == 5.0
    assert len(model.blocks) == 1
    # The printed dump is what the API writes for the same run.
    api = spacar.read(EXAMPLE)
    spacar.simulate(api)
    assert dump == api.dump()


def test_run_two_blocks_prints_two_dumps(runs):
    code, stdout, stderr = runs["run_two"]
    assert code == 0, stderr
    first, second = dumps(stdout)
    m1 = spacar.read_string(first, "first")
    m2 = spacar.read_string(second, "second")
    assert m1.current_time == 5.0
    assert m2.current_time == 6.0  # continued from t = 5 over TIMESTEP 10 1.0
    assert (m1.settings.timestep_n, m1.settings.timestep_tp) == (100, 5.0)
    assert (m2.settings.timestep_n, m2.settings.timestep_tp) == (10, 1.0)
    assert "TIMESTEP  10  1.000E+00" in second.splitlines()
    # The crank angle grows at the input rate 1.5 rad/s.
    assert m1.nodes[2].x == [7.5]
    assert m2.nodes[2].x == [9.0]


def test_input_error_exits_1_with_file_line_keyword_on_stderr(runs):
    path = runs["paths"]["bad"]
    code, stdout, stderr = runs["run_bad"]
    assert code == 1
    assert f"{path}, line 5, keyword FIX: node 8 (XY) has components 1..2, not 3" in stderr, stderr
    assert "InputError" in stderr
    assert "Traceback" not in stderr
    assert dumps(stdout) == []


# --- in-process: spacar.cli.main ---------------------------------------------------------------

def run_main(capsys, *argv):
    from spacar.cli import main

    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_check_input_error_in_process(tmp_path, capsys):
    path = tmp_path / "bad.dat"
    path.write_text(EXAMPLE.read_text().replace("FIX 8 2", BAD_LINE))
    code, stdout, stderr = run_main(capsys, "check", str(path))
    assert code == 1
    assert f"{path}, line 5, keyword FIX: node 8 (XY) has components 1..2, not 3" in stderr


def test_zero_length_is_reported_with_the_element_line(tmp_path, capsys):
    path = tmp_path / "zero.dat"
    path.write_text(EXAMPLE.read_text().replace("X 8 0.45 0.", "X 8 0.30 0."))
    for command in ("check", "run"):
        code, stdout, stderr = run_main(capsys, command, str(path))
        assert code == 1
        assert f"{path}, line 3, keyword PLBEAM: PLBEAM 3 has zero length" in stderr, stderr


def test_error_in_the_second_block_after_the_first_dump(tmp_path, capsys):
    path = tmp_path / "block2.dat"
    path.write_text(EXAMPLE.read_text() + NEW_ELEMENT_BLOCK)
    code, stdout, stderr = run_main(capsys, "run", str(path))
    assert code == 1
    assert len(dumps(stdout)) == 1  # the first block ran and was printed
    assert re.search(rf"{re.escape(str(path))}, line 25, keyword PLTRUSS: .*after the first END", stderr), stderr


@pytest.mark.parametrize("text", ["", "* nothing but a comment\n"])
def test_empty_input_is_nothing(tmp_path, capsys, text):
    path = tmp_path / "empty.dat"
    path.write_text(text)
    for command in ("run", "check"):
        code, stdout, stderr = run_main(capsys, command, str(path))
        assert code == 1, stderr   # nothing analysed, an empty model: a gate must not pass it
        assert stderr == ""
        assert stdout and all(line.startswith("*") for line in stdout.splitlines()), stdout
    assert "degrees of freedom: 0" in stdout


def test_block_without_end_is_a_warning(tmp_path, capsys):
    path = tmp_path / "open.dat"
    path.write_text(EXAMPLE.read_text() + "TIMESTEP 10 1.0\n")
    code, stdout, stderr = run_main(capsys, "run", str(path))
    assert code == 0, stderr
    assert len(dumps(stdout)) == 1
    assert re.search(r"^\* warning: .*line.*24.*without a closing END", stdout, re.M), stdout


def test_missing_file_is_an_input_error(tmp_path, capsys):
    code, stdout, stderr = run_main(capsys, "check", str(tmp_path / "missing.dat"))
    assert code == 1
    assert "missing.dat" in stderr and "cannot read" in stderr


def test_dump_digits_option(capsys):
    code, stdout, stderr = run_main(capsys, "run", "--dump-digits", "17", str(EXAMPLE))
    assert code == 0, stderr
    assert re.search(r"^XY\s+3\s+-?\d\.\d{16}E[+-]\d\d\s", stdout, re.M), stdout
    restart = spacar.read_string(stdout)
    assert restart.current_time == 5.0


@pytest.mark.parametrize("digits", ["0", "18", "x"])
def test_dump_digits_out_of_range_is_a_usage_error(capsys, digits):
    from spacar.cli import main

    with pytest.raises(SystemExit) as info:
        main(["run", "--dump-digits", digits, str(EXAMPLE)])
    assert info.value.code == 2
    out = capsys.readouterr()
    assert "--dump-digits" in out.err and "Traceback" not in out.err
    assert out.out == ""  # rejected before any analysis


def test_run_blocks_from_python_continues_like_the_command_line():
    """Model.run_blocks analyses the blocks in order: the second block starts where the first
    ended (t = 5) and runs its own TIMESTEP."""
    import numpy as np
    text = EXAMPLE.read_text() + "TIMESTEP 10 1.0\nEND\n"
    model = spacar.read_string(text, "two_blocks.dat")
    first, second = list(model.run_blocks())
    assert first.t[-1] == 5.0 and second.t[0] == 5.0 and second.t[-1] == 6.0
    assert len(second.t) == 11
    assert np.allclose(second.x[0], first.x[-1], atol=1e-9)


@pytest.mark.parametrize("forcemode", [0, 1, 2])
def test_run_prints_reactions_and_stresses_as_comments(tmp_path, capsys, forcemode):
    """FORCEMODE 1: the reactions on the fixed and input coordinates at the dump's time as
    ``* REACTION n i value``; 2: also ``* SIGMA e i value``; the output still reads as input."""
    text = EXAMPLE.read_text()
    end = text.upper().index("\nEND")
    path = tmp_path / "forces.dat"
    path.write_text(text[:end] + f"\nFORCEMODE {forcemode}" + text[end:])
    code, stdout, stderr = run_main(capsys, "run", "--dump-digits", "17", str(path))
    assert code == 0, stderr
    res = spacar.simulate(spacar.read(path))
    reactions = {(int(n), int(i)): float(v)
                 for n, i, v in re.findall(r"^\* REACTION\s+(\d+)\s+(\d+)\s+(\S+)$", stdout, re.M)}
    stresses = {(int(e), int(i)): float(v)
                for e, i, v in re.findall(r"^\* SIGMA\s+(\d+)\s+(\d+)\s+(\S+)$", stdout, re.M)}
    if forcemode == 0:
        assert not reactions and not stresses
        return
    # Fixed: node 1 (x, y), node 8 (y); input: the crank angle, node 2.
    assert sorted(reactions) == [(1, 1), (1, 2), (2, 1), (8, 2)]
    for (n, i), v in reactions.items():
        assert v == pytest.approx(res.reaction[-1, res.coordinate_index(n, i)], rel=1e-12, abs=1e-15)
    assert bool(stresses) == (forcemode == 2)
    if stresses:
        assert sorted(stresses) == sorted(res.deformation_labels)
        for (e, i), v in stresses.items():
            assert v == pytest.approx(res.sigma[-1, res.deformation_index(e, i)], rel=1e-12, abs=1e-15)
    assert spacar.read_string(stdout).current_time == 5.0


def test_forcemode_1_prints_the_driving_force_of_an_input_deformation(tmp_path, capsys):
    """A crank driven through its hinge angle (INPUTE): FORCEMODE 1 prints the hinge's stress,
    the driving torque, next to the reactions; no other stresses."""
    path = tmp_path / "crank.dat"
    path.write_text("PLHINGE 1 1 2\nPLBEAM 2 3 2 4 5\nX 4 0.2 0\nFIX 1\nFIX 3\nINPUTE 1 1\nED 1 1 2.0\n"
                    "EMASS 2 1.5\nGRAVITY 0 -9.81\nFORCEMODE 1\nTIMESTEP 4 0.5\nEND\n")
    code, stdout, stderr = run_main(capsys, "run", "--dump-digits", "17", str(path))
    assert code == 0, stderr
    res = spacar.simulate(spacar.read(path))
    stresses = re.findall(r"^\* SIGMA\s+(\d+)\s+(\d+)\s+(\S+)$", stdout, re.M)
    assert [(int(e), int(i)) for e, i, _ in stresses] == [(1, 1)]
    assert float(stresses[0][2]) == pytest.approx(res.sigma[-1, res.deformation_index(1, 1)], rel=1e-12)
    assert abs(float(stresses[0][2])) > 0.1  # it lifts the crank against gravity
    assert re.search(r"^\* REACTION\s+3\s+2\s", stdout, re.M)

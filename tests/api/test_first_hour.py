"""The error paths and messages a new user meets first (issue 23): drawing a model instead of
results, reprs that say what a node or element is, a FIX that a later DYNX frees, and the exit
status of ``spacar check`` as a gate."""
from __future__ import annotations

import pytest

import spacar
from spacar.cli import main
from support.paths import EXAMPLES

pytest.importorskip("matplotlib")


@pytest.fixture(scope="module")
def crank():
    return spacar.read(EXAMPLES / "slidercrank.dat")


@pytest.mark.parametrize("call, name", [
    (lambda m: spacar.plot(m, "x(3,1)"), "plot"),
    (lambda m: spacar.draw(m), "draw"),
    (lambda m: spacar.animate(m), "animate"),
])
def test_drawing_a_model_says_simulate_first(crank, call, name):
    with pytest.raises(spacar.SpacarError, match=rf"spacar.{name} draws results, not a model: simulate first"):
        call(crank)
    with pytest.raises(spacar.InputError, match="needs spacar.Results"):
        call([1, 2])


def test_reprs_say_what_a_node_and_an_element_are(crank):
    assert repr(crank.nodes[1]) == "<Node 1 XY x = (0, 0) [fixed, fixed]>"
    assert repr(crank.nodes[3]) == "<Node 3 XY x = (0.15, 0) [calculable, calculable]>"
    assert repr(crank.elements[3]) == "<Element 3 PLBEAM nodes (6, 7, 8, 9) e = (0, 0, 0) [fixed, dynamic, dynamic]>"
    assert repr(crank).startswith("<spacar.Model: 9 nodes, 3 elements")


def test_a_fix_freed_by_dynx_warns_with_the_line():
    m = spacar.read_string("PLBEAM 1 1 2 3 4\nX 3 1 0\nFIX 1\nFIX 2\nDYNX 2\nEND\nEND\n")
    assert m.warnings == ["<string>, line 5, keyword DYNX: DYNX 2 1 frees component 1 of node 2, "
                          "fixed by an earlier FIX"]
    built = spacar.Model()
    built.plbeam(1, 1, 2, 3, 4)
    built.fix(1)
    built.inputx(1, 2)
    built.dynx(3)                   # never fixed: no warning
    assert built.warnings == ["INPUTX 1 2 frees component 2 of node 1, fixed by an earlier FIX"]


def test_check_exit_status_is_a_gate(tmp_path, capsys):
    assert main(["check", str(EXAMPLES / "slidercrank.dat")]) == 0
    open_block = tmp_path / "open.dat"
    open_block.write_text("PLBEAM 1 1 2 3 4\nX 3 1 0\nFIX 1\nFIX 2\n")
    assert main(["check", str(open_block)]) == 1
    out = capsys.readouterr().out
    assert "the model is empty (no input block ended with END)" in out
    assert main(["run", str(open_block)]) == 1
    assert "end the input with a line END" in capsys.readouterr().out


def test_bicycle_run_prints_no_round_off_frequencies(capsys):
    assert main(["run", str(EXAMPLES / "bicycle.dat")]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("* eigenfrequencies"))
    head, values = line.rsplit(":", 1)
    assert "(1 zero)" in head
    assert all(abs(float(v)) > 1e-3 for v in values.split())

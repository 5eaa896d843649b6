"""MATASC files (manual §5.6, formulation.md §9.4, issue #7): with MATASC 1 every output time is
a line in `<stem>_x.asc`, `_xd`, `_xdd`, `_e`, `_ed`, `_edd`, `_rx` (FORCEMODE ≥ 1), `_sig`
(FORCEMODE 2), `_lin`/`_eig` (linearizations), written and flushed as the run proceeds.

The files are read back with numpy.loadtxt and compared with the Results arrays; the expected
columns are counted from the input file, not from the writer's code.
"""
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import spacar
from support.paths import EXAMPLES
from support.planar_models import compressed_cantilever

EXAMPLE = EXAMPLES / "slidercrank.dat"
STATE = {"x": "x", "xd": "xd", "xdd": "xdd", "e": "e", "ed": "ed", "edd": "edd"}
NUMBER = re.compile(r"^-?\d\.\d{15}E[+-]\d{2,3}$")

# Column labels of the manual's example, from its input: nodes 1..9 (XY 1 3 6 8, BETA 2 4 5 7 9),
# three PLBEAMs with three deformations each.
X_LABELS = ["x(1,1)", "x(1,2)", "x(2,1)", "x(3,1)", "x(3,2)", "x(4,1)", "x(5,1)", "x(6,1)", "x(6,2)",
            "x(7,1)", "x(8,1)", "x(8,2)", "x(9,1)"]
E_LABELS = [f"e({k},{i})" for k in (1, 2, 3) for i in (1, 2, 3)]
RX_LABELS = ["r(1,1)", "r(1,2)", "r(2,1)", "r(8,2)"]   # FIX 1, INPUTX 2 1, FIX 8 2
RX_COLUMNS = [0, 1, 2, 11]


def example(tmp_path, extra="MATASC 1", name="slidercrank.dat", blocks=""):
    """The manual's input with extra lines in its block (and further blocks), in tmp_path."""
    text = EXAMPLE.read_text().replace("END", f"{extra}\nEND", 1) + blocks
    path = tmp_path / name
    path.write_text(text)
    return path


def data_lines(path):
    return [ln for ln in Path(path).read_text().splitlines() if not ln.startswith("%")]


def header(path):
    return [ln for ln in Path(path).read_text().splitlines() if ln.startswith("%")]


def columns(path):
    (line,) = [ln for ln in header(path) if ln.startswith("% columns:")]
    return line.split()[2:]


@pytest.fixture(scope="module")
def manual(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("matasc")
    path = example(tmp)
    res = spacar.simulate(spacar.read(path))
    return tmp, res


def test_files_of_the_manual_example(manual):
    tmp, _ = manual
    names = sorted(p.name for p in tmp.glob("*.asc"))
    assert names == sorted(f"slidercrank_{s}.asc" for s in ("x", "xd", "xdd", "e", "ed", "edd", "rx"))


@pytest.mark.parametrize("suffix", list(STATE))
def test_one_line_per_output_time_matching_the_results(manual, suffix):
    tmp, res = manual
    path = tmp / f"slidercrank_{suffix}.asc"
    assert len(data_lines(path)) == 101      # TIMESTEP 100: k = 0..100
    data = np.loadtxt(path, comments="%")
    array = getattr(res, STATE[suffix])
    assert data.shape == (101, 1 + array.shape[1])
    np.testing.assert_allclose(data[:, 0], res.t, rtol=1e-15, atol=0)
    np.testing.assert_allclose(data[:, 1:], array, rtol=2e-15, atol=1e-300)
    labels = X_LABELS if suffix.startswith("x") else E_LABELS
    prefix = suffix
    assert columns(path) == ["t"] + [lbl.replace("x(", f"{prefix}(", 1) if prefix.startswith("x")
                                     else lbl.replace("e(", f"{prefix}(", 1) for lbl in labels]


def test_reactions_on_the_fixed_and_input_coordinates(manual):
    tmp, res = manual
    path = tmp / "slidercrank_rx.asc"
    assert columns(path) == ["t"] + RX_LABELS
    data = np.loadtxt(path, comments="%")
    assert data.shape == (101, 5)
    np.testing.assert_allclose(data[:, 1:], res.reaction[:, RX_COLUMNS], rtol=2e-15, atol=1e-300)
    assert np.abs(data[:, 1:]).max() > 0  # the supports do carry loads


def test_number_format_and_header(manual):
    tmp, _ = manual
    path = tmp / "slidercrank_e.asc"
    head = header(path)
    assert head[0].startswith("% spacar ") and "MATASC" in head[0]
    assert head[1] == f"% input: {tmp / 'slidercrank.dat'}"
    assert head[2] == "% JOBID: none"
    for line in data_lines(path):
        tokens = line.split(" ")
        assert len(tokens) == 10                     # t + 9 deformations, one space apart
        assert all(NUMBER.match(tok) for tok in tokens), line
    assert data_lines(path)[-1].startswith("5.000000000000000E+00 ")


def test_jobid_forcemode_2_and_forcemode_0(tmp_path):
    path = example(tmp_path, "MATASC 1\nJOBID 42\nFORCEMODE 2")
    res = spacar.simulate(spacar.read(path))
    assert "% JOBID: 42" in header(tmp_path / "slidercrank_x.asc")
    sig = tmp_path / "slidercrank_sig.asc"
    assert columns(sig) == ["t"] + [lbl.replace("e(", "s(") for lbl in E_LABELS]
    np.testing.assert_allclose(np.loadtxt(sig, comments="%")[:, 1:], res.sigma, rtol=2e-15, atol=1e-300)
    other = tmp_path / "zero"
    other.mkdir()
    spacar.simulate(spacar.read(example(other, "MATASC 1\nFORCEMODE 0")))
    assert not (other / "slidercrank_rx.asc").exists()
    assert not (other / "slidercrank_sig.asc").exists()
    assert (other / "slidercrank_x.asc").exists()


def test_no_files_without_matasc(tmp_path):
    spacar.simulate(spacar.read(example(tmp_path, "MATASC 0")))
    assert list(tmp_path.glob("*.asc")) == []


def test_lines_are_flushed_as_the_run_proceeds(tmp_path):
    path = example(tmp_path)
    seen = []

    def look(k, state):
        # Inside the run: the line of output time k is already in every file.
        seen.append(len(data_lines(tmp_path / "slidercrank_x.asc")))
        last = data_lines(tmp_path / "slidercrank_edd.asc")[-1].split()
        assert float(last[0]) == state["t"]
        np.testing.assert_allclose([float(v) for v in last[1:]], state["edd"], rtol=2e-15, atol=1e-300)

    spacar.simulate(spacar.read(path), on_output=look)
    assert seen == list(range(1, 102))


def test_an_aborted_run_keeps_what_was_computed(tmp_path):
    full = spacar.simulate(spacar.read(EXAMPLE))
    path = example(tmp_path)

    def stop(k, state):
        if k == 40:
            raise KeyboardInterrupt("stopped by the user")

    with pytest.raises(KeyboardInterrupt):
        spacar.simulate(spacar.read(path), on_output=stop)
    data = np.loadtxt(tmp_path / "slidercrank_x.asc", comments="%")
    assert data.shape == (41, 14)
    np.testing.assert_allclose(data[:, 1:], full.x[:41], rtol=2e-15, atol=1e-300)


def test_multi_block_run_appends(tmp_path):
    path = example(tmp_path, blocks="TIMESTEP 50 2.5\nEND\nXD 2 1 3.0\nTIMESTEP 10 1.0\nEND\n")
    model = spacar.read(path)
    results = [spacar.simulate(model)]
    for block in model.blocks[1:]:
        spacar.io.reader.apply_block(model, block)
        results.append(spacar.simulate(model))
    both = spacar.Results.concatenate(results)
    x = tmp_path / "slidercrank_x.asc"
    assert len(data_lines(x)) == 101 + 51 + 11
    assert sum(ln.startswith("% columns:") for ln in header(x)) == 1   # one header: appended
    data = np.loadtxt(x, comments="%")
    np.testing.assert_allclose(data[:, 0], both.t, rtol=1e-15, atol=0)
    assert data[100, 0] == data[101, 0] == 5.0 and data[151, 0] == data[152, 0] == 7.5
    np.testing.assert_allclose(data[:, 1:], both.x, rtol=2e-15, atol=1e-300)
    np.testing.assert_allclose(np.loadtxt(tmp_path / "slidercrank_ed.asc", comments="%")[:, 1:], both.ed,
                               rtol=2e-15, atol=1e-300)


def test_later_blocks_may_add_files_and_change_the_reaction_columns(tmp_path):
    """Block 2 frees the crank (DYNX instead of INPUTX: no reaction on it any more) and asks for
    the stresses (FORCEMODE 2): `_rx` gets a new column line, `_sig` starts with block 2."""
    path = example(tmp_path, blocks="DYNX 2 1\nFORCEMODE 2\nTIMESTEP 20 0.5\nEND\n")
    out = subprocess.run([sys.executable, "-m", "spacar", "run", str(path)], capture_output=True, text=True,
                         check=True)
    assert "MATASC files" in out.stdout
    rx = (tmp_path / "slidercrank_rx.asc").read_text().splitlines()
    column_lines = [i for i, ln in enumerate(rx) if ln.startswith("% columns:")]
    assert len(column_lines) == 2
    assert rx[column_lines[1]].split()[2:] == ["t", "r(1,1)", "r(1,2)", "r(8,2)"]
    before = [ln for ln in rx[:column_lines[1]] if not ln.startswith("%")]
    after = rx[column_lines[1] + 1:]
    assert len(before) == 101 and all(len(ln.split()) == 5 for ln in before)
    assert len(after) == 21 and all(len(ln.split()) == 4 for ln in after)
    sig = np.loadtxt(tmp_path / "slidercrank_sig.asc", comments="%")
    assert sig.shape == (21, 10) and sig[0, 0] == 5.0
    assert len(data_lines(tmp_path / "slidercrank_x.asc")) == 122


def test_cli_writes_the_files_next_to_the_input(tmp_path):
    (tmp_path / "in").mkdir()
    path = example(tmp_path / "in", blocks="TIMESTEP 20 1.0\nEND\n")
    elsewhere = tmp_path / "cwd"
    elsewhere.mkdir()
    out = subprocess.run([sys.executable, "-m", "spacar", "run", str(path)], capture_output=True, text=True,
                         cwd=elsewhere, check=True)
    assert f"* MATASC files: {tmp_path / 'in' / 'slidercrank'}_*.asc" in out.stdout
    assert list(elsewhere.iterdir()) == []
    x = tmp_path / "in" / "slidercrank_x.asc"
    assert len(data_lines(x)) == 101 + 21
    model = spacar.read(EXAMPLE)
    res = spacar.simulate(model)
    np.testing.assert_allclose(np.loadtxt(x, comments="%")[:101, 1:], res.x, rtol=2e-15, atol=1e-300)


def test_a_new_run_starts_new_files(tmp_path):
    path = example(tmp_path)
    spacar.simulate(spacar.read(path))
    spacar.simulate(spacar.read(path))
    assert len(data_lines(tmp_path / "slidercrank_x.asc")) == 101


def test_models_built_in_python_write_spacar_files(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    model = spacar.Model()
    model.plbeam(1, 1, 2, 3, 4)
    model.x(3, 1.0, 0.0)
    model.fix(1)
    model.inputx(2, 1)
    model.xd(2, 1, 1.0)
    model.timestep(10, 1.0)
    model.matasc(1)
    res = spacar.simulate(model)
    data = np.loadtxt(tmp_path / "spacar_x.asc", comments="%")
    np.testing.assert_allclose(data[:, 1:], res.x, rtol=2e-15, atol=1e-300)
    assert header(tmp_path / "spacar_x.asc")[1] == "% input: (model built in Python)"
    # A stem given by the user: argument, then model attribute.
    spacar.simulate(model, output_stem=tmp_path / "out" / "run1")
    assert len(data_lines(tmp_path / "out" / "run1_e.asc")) == 11
    model.output_stem = "run2"
    spacar.simulate(model)
    assert len(data_lines(tmp_path / "run2_xd.asc")) == 11
    np.testing.assert_allclose(np.loadtxt(tmp_path / "run2_x.asc", comments="%")[0, 4],
                               math.cos(2.0), rtol=1e-12)  # the crank end after 2 s at 1 rad/s


def test_linearization_files(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    n = 3
    model = compressed_cantilever(n)
    model.matasc(1)
    model.timestep(4, 0.2)
    res = spacar.simulate(model)
    nz = 2 * n
    lin = np.loadtxt("spacar_lin.asc", comments="%")
    assert lin.shape == (5, 3 + 6 * nz * nz + nz)
    assert any(ln.startswith("% z: e(1,2) e(1,3) e(2,2)") for ln in header("spacar_lin.asc"))
    for row, L in zip(lin, res.linearizations):
        assert row[0] == pytest.approx(L.t, rel=1e-15) and row[1] == nz and row[2] == 0
        mats = row[3:3 + 6 * nz * nz].reshape(6, nz * nz)
        for m, name in zip(mats, ("M0", "C0", "D0", "K0", "N0", "G0")):
            np.testing.assert_allclose(m.reshape(nz, nz, order="F"), getattr(L, name), rtol=2e-15, atol=1e-300)
        np.testing.assert_allclose(row[3 + 6 * nz * nz:], L.r0, rtol=2e-15, atol=1e-300)
    eig = np.loadtxt("spacar_eig.asc", comments="%")
    assert eig.shape == (5, 1 + 4 * nz)
    lam = eig[0, 1::2] + 1j * eig[0, 2::2]
    np.testing.assert_allclose(lam, res.linearizations[0].eigenvalues(), rtol=1e-14, atol=1e-12)
    buck = np.loadtxt("spacar_buck.asc", comments="%")
    assert buck.shape == (5, 1 + nz)
    assert buck[0, 1] == pytest.approx(res.linearizations[0].buckling_factors()[0], rel=1e-14)
    assert 2.46 < buck[0, 1] < 2.47      # π²/4 = 2.4674 (formulation.md §10.4, 3 elements)


def test_linearization_files_of_a_nonholonomic_model_are_written_as_the_run_proceeds(tmp_path):
    """The bicycle (4 kinematic coordinates): each _lin line holds nz, nk and the matrices with
    K_k, AK0, BK0; the lines are on disk at each output time, not only at the end."""
    import spacar
    model = spacar.read("examples/bicycle.dat")
    model.matasc(1)
    model.timestep(2, 0.01)
    stem = tmp_path / "bike"
    seen = []

    def probe(k, state):
        seen.append(sum(1 for line in open(f"{stem}_lin.asc") if not line.startswith("%")))

    res = spacar.simulate(model, output_stem=stem, on_output=probe)
    assert seen == [1, 2, 3]
    rows = np.loadtxt(f"{stem}_lin.asc", comments="%")
    nz, nk = int(rows[0, 1]), int(rows[0, 2])
    assert (nz, nk) == (3, 4)
    lin = res.linearizations[-1]
    expected = np.concatenate([[lin.t, nz, nk]] + [np.asarray(getattr(lin, n)).ravel(order="F") for n in
                                                    ("M0", "C0", "D0", "K0", "N0", "G0", "Kk", "AK0", "BK0")]
                              + [lin.r0])
    assert np.allclose(rows[-1], expected, rtol=1e-14, atol=0)
    eig = np.loadtxt(f"{stem}_eig.asc", comments="%")
    assert eig.shape[1] == 1 + 2 * (2 * nz + nk)

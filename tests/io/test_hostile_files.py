"""Issue 24, findings 2 and 6: output files under faults and planted links.

- A write error in the middle of a run (a file size limit, RLIMIT_FSIZE, in a subprocess: the
  same EFBIG path as a full disk's ENOSPC) ends in a SpacarError naming the file, and leaves the
  MATASC files with the same output times in whole lines.
- An output file that is a symbolic link is refused (its target is untouched); a FIFO or device
  in its place is refused without blocking; an existing regular file is overwritten, as before.
"""
import os
import resource
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import spacar
from support.paths import EXAMPLES, spacar_env

EXAMPLE = EXAMPLES / "slidercrank.dat"
SUFFIXES = ("x", "xd", "xdd", "e", "ed", "edd", "rx")


def example(directory, extra="MATASC 1\nFORCEMODE 1\nLINEAR 1"):
    path = Path(directory) / "slidercrank.dat"
    path.write_text(EXAMPLE.read_text().replace("END", f"{extra}\nEND", 1))
    return path


def data_rows(path):
    lines = Path(path).read_text().splitlines(keepends=True)
    assert all(line.endswith("\n") for line in lines), "a truncated last line"
    rows = [line for line in lines if not line.startswith("%")]
    return np.loadtxt(rows, ndmin=2) if rows else np.zeros((0, 0))


def _limit_file_size(nbytes):
    def set_limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # writes beyond the limit fail with EFBIG
        resource.setrlimit(resource.RLIMIT_FSIZE, (nbytes, nbytes))
    return set_limit


@pytest.mark.parametrize("limit", [3000, 20000, 60000])
def test_a_write_error_leaves_the_matasc_files_consistent(tmp_path, limit):
    path = example(tmp_path)
    env = spacar_env()
    out = subprocess.run([sys.executable, "-m", "spacar", "run", str(path)], capture_output=True, text=True,
                         cwd=tmp_path, env=env, preexec_fn=_limit_file_size(limit), timeout=120)
    assert out.returncode == 1, out.stderr
    assert "Traceback" not in out.stderr
    message = out.stderr.strip().splitlines()[-1]
    assert message.startswith("spacar: SpacarError: "), message
    assert "cannot write the MATASC file (File too large)" in message
    assert str(tmp_path / "slidercrank_") in message
    times = {}
    for suffix in (*SUFFIXES, "lin", "eig"):
        f = tmp_path / f"slidercrank_{suffix}.asc"
        if f.exists():
            rows = data_rows(f)
            times[suffix] = rows[:, 0] if rows.size else np.zeros(0)
    assert set(SUFFIXES) <= set(times)
    reference = times["x"]
    assert len(reference) < 101  # the limit stopped the run
    for suffix, t in times.items():
        if suffix in ("lin", "eig") and len(t) == 0 and len(reference) == 0:
            continue
        np.testing.assert_array_equal(t, reference, err_msg=suffix)


def test_a_write_error_in_python_is_a_spacar_error(tmp_path):
    """The same through the API, in a subprocess (the limit applies to the whole process)."""
    path = example(tmp_path, extra="MATASC 1")
    code = (f"import spacar\nm = spacar.read({str(path)!r})\n"
            "try:\n    spacar.simulate(m, progress=False)\n"
            "except spacar.SpacarError as err:\n"
            "    print(type(err).__name__, err.__cause__, err.__suppress_context__)\n")
    env = spacar_env()
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, env=env,
                         preexec_fn=_limit_file_size(10000), timeout=120)
    assert out.returncode == 0, out.stderr
    words = out.stdout.split()
    assert words == ["SpacarError", "None", "True"]  # no chained OSError
    rows = len(data_rows(tmp_path / "slidercrank_x.asc"))
    for suffix in SUFFIXES[:6]:
        assert len(data_rows(tmp_path / f"slidercrank_{suffix}.asc")) == rows


def test_a_planted_symlink_is_refused(tmp_path):
    path = example(tmp_path, extra="MATASC 1")
    target = tmp_path / "precious.txt"
    target.write_text("keep me\n")
    (tmp_path / "slidercrank_xd.asc").symlink_to(target)
    model = spacar.read(path)
    with pytest.raises(spacar.InputError, match=r"slidercrank_xd\.asc: refusing to write through a symbolic link"):
        spacar.simulate(model, progress=False)
    assert target.read_text() == "keep me\n"
    # a dangling link is refused as well (it would create the target)
    (tmp_path / "slidercrank_xd.asc").unlink()
    (tmp_path / "slidercrank_xd.asc").symlink_to(tmp_path / "new.txt")
    with pytest.raises(spacar.InputError, match="symbolic link"):
        spacar.simulate(spacar.read(path), progress=False)
    assert not (tmp_path / "new.txt").exists()


def test_a_symlinked_results_file_is_refused(tmp_path):
    res = spacar.simulate(spacar.read(EXAMPLE), progress=False)
    target = tmp_path / "precious.npz"
    target.write_bytes(b"keep")
    (tmp_path / "res.npz").symlink_to(target)
    with pytest.raises(spacar.InputError, match="symbolic link"):
        res.save(tmp_path / "res.npz")
    assert target.read_bytes() == b"keep"


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs")
def test_a_fifo_in_place_of_an_output_file_is_refused_without_blocking(tmp_path):
    path = example(tmp_path, extra="MATASC 1")
    os.mkfifo(tmp_path / "slidercrank_e.asc")
    with pytest.raises(spacar.InputError, match="not a regular file"):
        spacar.simulate(spacar.read(path), progress=False)


def test_existing_files_are_overwritten_as_before(tmp_path):
    path = example(tmp_path, extra="MATASC 1")
    (tmp_path / "slidercrank_x.asc").write_text("old\n" * 5000)
    spacar.simulate(spacar.read(path), progress=False)
    assert len(data_rows(tmp_path / "slidercrank_x.asc")) == 101
    res = spacar.simulate(spacar.read(EXAMPLE), progress=False)
    (tmp_path / "r.npz").write_bytes(b"x" * 10**6)
    res.save(tmp_path / "r.npz")
    assert len(spacar.Results.load(tmp_path / "r.npz")) == 101

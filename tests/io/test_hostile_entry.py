"""Issue 24, finding 7: public entry points given a wrong type raise an InputError naming the
argument (before, AttributeError/TypeError from inside), and Ctrl-C in `spacar run` prints one
line and exits with status 130 (before, a traceback; and it waited for the C++ run to end).
"""
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import spacar
from spacar import Results
from support.paths import EXAMPLES, spacar_env

EXAMPLE = EXAMPLES / "slidercrank.dat"
WRONG = [42, None, "slidercrank.dat", 1.5, [1], object()]


@pytest.mark.parametrize("name, call", [
    ("simulate", spacar.simulate),
    ("linearize", spacar.linearize),
    ("dump", spacar.dump),
    ("check", spacar.check),
    ("summary", spacar.summary),
])
@pytest.mark.parametrize("value", WRONG, ids=lambda v: type(v).__name__)
def test_a_model_argument_of_the_wrong_type(name, call, value):
    with pytest.raises(spacar.InputError, match=f"^{name}: model must be a spacar.Model, got "):
        call(value)


@pytest.mark.parametrize("value", [3, None, 2.5, ["a"], object()], ids=lambda v: type(v).__name__)
def test_results_load_of_the_wrong_type(value):
    with pytest.raises(spacar.InputError, match="Results.load: path must be a file name or path"):
        Results.load(value)


@pytest.mark.parametrize("value, match", [
    (["a"], r"results\[0\] is not a spacar.Results, got 'a'"),
    ([3, 4], r"results\[0\]"),
    (3, "must be a list of spacar.Results"),
    ("abc", "must be a list of spacar.Results"),
    ([], "at least one"),
])
def test_results_concatenate_of_the_wrong_type(value, match):
    with pytest.raises(spacar.InputError, match=match):
        Results.concatenate(value)


@pytest.mark.parametrize("values", [[object()], ["fast"], [{}], [None], [1 + 2j], [np.array([1.0, 2.0])],
                                    [(1.0, 2.0)]], ids=repr)
def test_sweep_values_of_the_wrong_kind(values):
    model = spacar.read(EXAMPLE)
    with pytest.raises(spacar.InputError, match=r"^sweep parameter 'XD 2 1' = "):
        spacar.sweep(model, {"XD 2 1": values}, workers=1, progress=False)


@pytest.mark.parametrize("values", [5, "abc", None])
def test_sweep_value_lists_of_the_wrong_kind(values):
    with pytest.raises(spacar.InputError, match="sweep parameter 'XD 2 1': give a sequence of values"):
        spacar.sweep(spacar.read(EXAMPLE), {"XD 2 1": values}, workers=1, progress=False)


def _start_long_run(tmp_path, extra=""):
    path = tmp_path / "long.dat"
    path.write_text(EXAMPLE.read_text().replace("Timestep 100 5.0", f"TIMESTEP 100000 100000.0\n{extra}"))
    env = spacar_env()
    return subprocess.Popen([sys.executable, "-m", "spacar", "run", str(path)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=tmp_path, env=env)


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
@pytest.mark.parametrize("extra, sig, message", [
    ("", "SIGINT", "interrupted"), ("MATASC 1", "SIGINT", "interrupted"),
    ("MATASC 1\nLINEAR 1", "SIGINT", "interrupted"),
    # Issue 38, finding 7: SIGTERM and SIGHUP killed the process between the rows of an output
    # time (MATASC files of 2451 and 2450 rows), status 143/129, no message.
    ("MATASC 1", "SIGTERM", "terminated (SIGTERM)"), ("MATASC 1\nLINEAR 1", "SIGHUP", "terminated (SIGHUP)")])
def test_ctrl_c_in_spacar_run_prints_one_line_and_exits_130(tmp_path, extra, sig, message):
    """Ctrl-C (and SIGTERM, SIGHUP) during `spacar run`: one line, the shell's status 128 + the
    signal's number, the MATASC files complete and of equal length."""
    proc = _start_long_run(tmp_path, extra)
    time.sleep(2.5)  # inside the C++ integration by now
    assert proc.poll() is None
    signum = getattr(signal, sig)
    proc.send_signal(signum)
    start = time.perf_counter()
    try:
        out, err = proc.communicate(timeout=20)
    finally:
        proc.kill()
    assert time.perf_counter() - start < 5
    assert proc.returncode == 128 + signum
    assert err == f"spacar: {message}\n"
    if extra:
        counts = {p.name: sum(not line.startswith("%") for line in p.read_text().splitlines())
                  for p in tmp_path.glob("long_*.asc")}
        assert len(counts) == (9 if "LINEAR" in extra else 7) and len(set(counts.values())) == 1, counts
        for p in tmp_path.glob("long_*.asc"):
            assert p.read_text().endswith("\n")

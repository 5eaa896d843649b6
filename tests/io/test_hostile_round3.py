"""Issue 38, the third adversarial round (docs/robustness.md, "Third round"). Finding 1: runs on
one model from several threads. A run starts from the model's
state and leaves its end state there; threads simulating the same model all started at its time
and their blocks overwrote each other (six 5 s runs left the model at t = 10, not 30). Now the runs
on one model take turns: the model ends where the same runs one after the other end, and each
run's rows continue the last one's. Findings 12, 14 and 15 (in part): raw errors at entry points
and a NaN time index."""
from __future__ import annotations

import threading

import numpy as np
import pytest

import spacar
from support.paths import DATA, EXAMPLES


def test_runs_on_one_model_from_threads_take_turns():
    model = spacar.read(EXAMPLES / "slidercrank.dat")
    serial = model.copy()
    results, errors = [], []

    def run():
        try:
            results.append(spacar.simulate(model, progress=False))
        except Exception as err:  # pragma: no cover - reported below
            errors.append(err)

    threads = [threading.Thread(target=run) for _ in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert model.current_time == 30.0
    starts = sorted(r.t[0] for r in results)
    assert starts == [0.0, 5.0, 10.0, 15.0, 20.0, 25.0]
    for _ in range(6):
        last = spacar.simulate(serial, progress=False)
    ended = max(results, key=lambda r: r.t[-1])
    np.testing.assert_array_equal(ended.x[-1], last.x[-1])


def test_runs_on_copies_do_not_wait_for_each_other():
    """Each copy is its own model: its runs start at its own time."""
    model = spacar.read(EXAMPLES / "slidercrank.dat")
    copies = [model.copy() for _ in range(3)]
    threads = [threading.Thread(target=spacar.simulate, args=(c,), kwargs={"progress": False}) for c in copies]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert [c.current_time for c in copies] == [5.0, 5.0, 5.0]
    assert model.current_time == 0.0


@pytest.mark.parametrize("bad", [42, None, "model.dat"])
def test_static_of_something_else_is_an_input_error(bad):
    with pytest.raises(spacar.InputError, match="static: model must be a spacar.Model"):
        spacar.static(bad)


def test_from_urdf_bad_path_and_gravity_are_input_errors():
    with pytest.raises(spacar.InputError, match="path of a URDF file"):
        spacar.from_urdf("a\x00b")  # was a raw ValueError (embedded null byte)
    with pytest.raises(spacar.InputError, match="gravity must be three finite numbers"):
        spacar.from_urdf(DATA / "two_link_arm.urdf", gravity=(0, 0, 10**400))  # was a raw OverflowError


@pytest.mark.parametrize("bad, match", [(float("nan"), "finite"), (float("inf"), "finite"), ("x", "a number"),
                                        (10**400, "a number")])
def test_time_index_of_no_time_is_an_input_error(bad, match):
    res = spacar.simulate(spacar.read(EXAMPLES / "slidercrank.dat"), progress=False)
    with pytest.raises(spacar.InputError, match=match):
        res.time_index(bad)  # NaN gave row 0
    assert res.time_index(2.51) == 50


@pytest.mark.parametrize("bad, match", [("x", "a number"), ((1.0, 1.0), "a number"), (10**400, "a number"),
                                        (float("nan"), "finite")])
def test_a_table_at_no_time_is_an_input_error(bad, match):
    table = spacar.Table(np.linspace(0.0, 1.0, 5), np.sin(np.linspace(0.0, 1.0, 5)))
    with pytest.raises(spacar.InputError, match=match):
        table(bad)  # raw ValueError, TypeError, OverflowError; NaN returned NaN


@pytest.mark.parametrize("spacing", [1e-300, 1e-160])
def test_a_cubic_table_of_samples_too_close_is_refused(spacing):
    """Times 1e-300 apart gave −inf, NaN and inf from a successful call; the linear table's slopes
    stay finite there and it is kept."""
    t, y = np.arange(4) * spacing, np.array([0.0, 1.0, 4.0, 2.0])
    with pytest.raises(spacar.InputError, match="too close for the cubic interpolation"):
        spacar.Table(t, y, kind="cubic")
    linear = spacar.Table(t, y, kind="linear")
    assert all(np.isfinite(linear(0.5 * spacing, d)) for d in (0, 1, 2))


@pytest.mark.parametrize("sensors, actuators, match", [
    (None, [(2, 1)], "sensors must be a list"),
    ([("x", "a", 1)], [(2, 1)], "a sensor is"),
    ([("x", 2, 1)], [(2, float("nan"))], "an actuator is"),
    ([("x", 2.7, 1)], [(2, 1)], "a sensor is"),  # was node 2, silently
])
def test_controller_sensors_and_actuators_are_checked(sensors, actuators, match):
    with pytest.raises(spacar.InputError, match=match):
        spacar.Controller(lambda t, s: np.zeros(1), rate=100.0, sensors=sensors, actuators=actuators)
    whole = spacar.Controller(lambda t, s: np.zeros(1), rate=100.0, sensors=[("x", 2.0, 1)], actuators=[(2, 1)])
    assert whole.sensors == [("x", 2, 1)]


def test_input_without_end_is_said_at_once():
    """Finding 12: read_string of a text with no END gave an empty model silently."""
    with pytest.warns(UserWarning, match="lines 1..3: input without a closing END is ignored"):
        model = spacar.read_string("PLBEAM 1 1 2 3 4\nX 3 1 0\nFIX 1\n")
    assert model.blocks == [] and any("closing END" in w for w in model.warnings)


def test_results_save_keeps_the_file_s_mode_and_hard_links(tmp_path):
    """Finding 16: a save replaced the file by mkstemp's (mode 0600) and broke its hard links; a
    statistic that JSON cannot hold gave a raw TypeError."""
    import os

    res = spacar.simulate(spacar.read(EXAMPLES / "slidercrank.dat"), progress=False)
    path = tmp_path / "run.npz"
    res.save(path)
    os.chmod(path, 0o640)
    res.save(path)
    assert os.stat(path).st_mode & 0o777 == 0o640
    link = tmp_path / "link.npz"
    os.link(path, link)
    res.save(path)
    assert os.path.samefile(path, link) and os.stat(path).st_nlink == 2
    np.testing.assert_array_equal(spacar.Results.load(link).x, res.x)
    res.stats["extra"] = {"not": "a number"}
    with pytest.raises(spacar.InputError, match="the statistic 'extra' is not a number"):
        res.save(path)
    np.testing.assert_array_equal(spacar.Results.load(path).x, res.x)  # the file is as it was


@pytest.mark.skipif(not __import__("os").path.exists("/dev/full"), reason="needs /dev/full")
def test_cli_into_a_full_disk_says_so_in_one_line():
    """Finding 16: `spacar run x.dat > /dev/full` printed a raw OSError traceback."""
    import subprocess
    import sys

    with open("/dev/full", "w") as full:
        done = subprocess.run([sys.executable, "-m", "spacar", "run", str(EXAMPLES / "slidercrank.dat")],
                              stdout=full, stderr=subprocess.PIPE, text=True, timeout=120)
    assert done.returncode == 1
    assert done.stderr.strip() == "spacar: cannot write the output: No space left on device"



INTERRUPTED_RUN = r"""
import os, signal, sys, threading, time
import spacar
from spacar.compare import models
m = models.cantilever(8, ei=175.0, rho_a=0.785, t_end=20.0, n_out=200, eps=1e-8)  # DOP853: minutes
threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
start = time.perf_counter()
try:
    spacar.simulate(m, method="dop853", progress=False)
    print("finished")
except KeyboardInterrupt as err:
    res = err.results
    print(round(time.perf_counter() - start, 2), type(res).__name__, len(res.t), m.current_time)
"""


def test_ctrl_c_interrupts_a_run_and_keeps_its_rows():
    """Finding 6: Ctrl-C during spacar.simulate arrived only when the block ended (17.8 s for a
    16.8 s run). The run now polls for it where it checks its deadline (every 20 ms at most) and
    raises KeyboardInterrupt with the rows done as ``err.results``; the model is left as it was."""
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", INTERRUPTED_RUN], capture_output=True, text=True, timeout=120)
    words = done.stdout.split()
    assert len(words) == 4, (done.stdout, done.stderr)
    seconds, kind, rows, model_time = float(words[0]), words[1], int(words[2]), float(words[3])
    assert seconds < 5.0 and kind == "Results" and rows >= 1 and model_time == 0.0


# --- finding 8: the file rules for every file spacar reads or writes -------------------------------

posix = pytest.mark.skipif(not hasattr(__import__("os"), "mkfifo"), reason="POSIX FIFOs and links")


@pytest.fixture(scope="module")
def slider_results():
    return spacar.simulate(spacar.read(EXAMPLES / "slidercrank.dat"), progress=False)


@posix
@pytest.mark.parametrize("suffix", [".gif", ".html"])
def test_an_animation_is_never_written_through_a_link_or_into_a_fifo(tmp_path, slider_results, suffix):
    """Finding 8: ANIMATE output wrote through a planted symbolic link (overwriting its target),
    and a FIFO given as --animation hung. Both are refused at once, as for MATASC files and
    Results.save; an existing file is replaced once the new one is complete and keeps its mode."""
    import os

    target = tmp_path / "precious.txt"
    target.write_text("precious")
    link = tmp_path / f"link{suffix}"
    link.symlink_to(target)
    with pytest.raises(spacar.InputError, match="refusing to write through a symbolic link"):
        spacar.save_animation(slider_results, link)
    assert target.read_text() == "precious"
    fifo = tmp_path / f"fifo{suffix}"
    os.mkfifo(fifo)
    with pytest.raises(spacar.InputError, match="not a regular file"):
        spacar.save_animation(slider_results, fifo)
    existing = tmp_path / f"old{suffix}"
    existing.write_text("old")
    existing.chmod(0o640)
    spacar.save_animation(slider_results, existing)
    assert existing.stat().st_mode & 0o777 == 0o640 and existing.stat().st_size > 1000
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["precious.txt", link.name, fifo.name, existing.name])


@posix
def test_spacar_run_with_a_fifo_as_animation_says_so_and_does_not_hang(tmp_path):
    import os
    import subprocess
    import sys

    model = tmp_path / "anim.dat"
    model.write_text((EXAMPLES / "slidercrank.dat").read_text().replace("END", "ANIMATE 1\nEND", 1))
    fifo = tmp_path / "out.gif"
    os.mkfifo(fifo)
    from support.paths import spacar_env

    done = subprocess.run([sys.executable, "-m", "spacar", "run", str(model), "--animation", str(fifo)],
                          capture_output=True, text=True, timeout=120, cwd=tmp_path, env=spacar_env())
    assert done.returncode == 1 and "not a regular file" in done.stderr, done.stderr


@posix
def test_from_urdf_refuses_a_fifo_a_directory_and_a_file_beyond_its_limit(tmp_path):
    """Finding 8: from_urdf on a FIFO blocked forever, and a 20 MB URDF took 454 MB and 11 s. It
    now follows the reader's rules: regular files only, at most max_bytes (8 MiB by default)."""
    import os
    import time

    fifo = tmp_path / "robot.urdf"
    os.mkfifo(fifo)
    start = time.perf_counter()
    for path in (fifo, tmp_path):
        with pytest.raises(spacar.InputError, match="not a regular file"):
            spacar.from_urdf(path)
    big = tmp_path / "big.urdf"
    big.write_text('<robot name="r">' + " " * (9 * 2**20) + "</robot>")
    with pytest.raises(spacar.InputError, match=r"big.urdf: the URDF file has 9437\d+ bytes, more than the limit"):
        spacar.from_urdf(big)
    assert time.perf_counter() - start < 1.0
    small = DATA / "wrist.urdf"
    with pytest.raises(spacar.InputError, match="more than the limit of 100 bytes"):
        spacar.from_urdf(small, max_bytes=100)
    assert len(spacar.from_urdf(small).elements) > 0


# --- findings 13 and 15, the rest: what a user's function returns, arrays for dicts, huge frequencies

RETURNED = ["abc", {"a": 1}, 1j, (1 + 2j, 0.0), [1.0, "x"], None, (float("nan"), 0.0), 10**400, (1.0, 2.0, 3.0)]


@pytest.mark.parametrize("value", RETURNED, ids=repr)
def test_a_force_function_returning_something_else_is_an_input_error(value):
    """Finding 13: raw ValueError/TypeError from a force callable returning a string, a dict or a
    complex number. The message names the node, what was returned and the time."""
    model = spacar.read(EXAMPLES / "slidercrank.dat")
    with pytest.raises(spacar.InputError, match=r"^forces: the function of node 3 .* must return 2 finite numbers, "
                                                r"got .* at t = 0$"):
        spacar.simulate(model, forces={3: lambda t: value}, progress=False)


@pytest.mark.parametrize("value", RETURNED, ids=repr)
def test_a_controller_law_returning_something_else_is_an_input_error(value):
    model = spacar.read(EXAMPLES / "slidercrank.dat")
    law = spacar.Controller(lambda t, y: value, rate=100.0, sensors=[("x", 3, 1)], actuators=[(3, 1)])
    with pytest.raises(spacar.InputError, match=r"^Controller: fn .* must return 1 finite number, got .* at t = 0$"):
        spacar.simulate(model, controller=law, progress=False)


@pytest.mark.parametrize("keyword", ["forces", "inputs"])
def test_forces_or_inputs_given_as_an_array_are_an_input_error(keyword):
    """Finding 13: forces=np.array(...) gave the raw 'truth value of an array is ambiguous'."""
    model = spacar.read(EXAMPLES / "slidercrank.dat")
    with pytest.raises(spacar.InputError, match=rf"^{keyword} must be a dict: .* got array"):
        spacar.simulate(model, **{keyword: np.array([1.0, 2.0])}, progress=False)


def test_a_frequency_response_beyond_double_precision_is_an_input_error():
    """Finding 15: StateSpace.frequency_response([1e308]) returned NaN from a successful call."""
    from support.planar_models import tip_loaded_beam

    ss = spacar.state_space(tip_loaded_beam(4))
    with pytest.raises(spacar.InputError, match="1e[+]308 Hz is beyond the angular frequencies double precision"):
        ss.frequency_response([1e308])
    with pytest.raises(spacar.InputError, match="the response overflows double precision"):
        ss.frequency_response([1e200])
    assert np.isfinite(ss.frequency_response([1e150, 1.0])).all()

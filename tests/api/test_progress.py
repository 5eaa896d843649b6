"""The progress bar over simulated time (issue #7): tqdm, optional, advanced at the output times
only; off when not interactive or when asked."""
import sys

import pytest

import spacar
import spacar.progress
from support.paths import EXAMPLES

EXAMPLE = EXAMPLES / "slidercrank.dat"


def run(**kwargs):
    calls = []
    res = spacar.simulate(spacar.read(EXAMPLE), on_output=lambda k, s: calls.append(k), **kwargs)
    assert calls == list(range(101))  # the user's callback still sees every output time
    return res


def test_bar_when_asked(capsys):
    pytest.importorskip("tqdm")
    run(progress=True)
    err = capsys.readouterr().err
    assert "spacar:" in err and "100%" in err
    assert "5/5 s simulated" in err   # the simulated time reached


def test_no_bar_when_asked_not_to(capsys, monkeypatch):
    monkeypatch.setattr(spacar.progress, "interactive", lambda: True)
    run(progress=False)
    assert capsys.readouterr().err == ""


def test_no_bar_when_not_interactive(capsys):
    assert not spacar.progress.interactive()   # pytest captures standard error
    run()
    assert capsys.readouterr().err == ""


def test_automatic_bar_in_an_interactive_session(capsys, monkeypatch):
    pytest.importorskip("tqdm")
    monkeypatch.setattr(spacar.progress, "interactive", lambda: True)
    monkeypatch.setattr(spacar.progress, "DELAY", 0.0)
    run()
    assert "100%" in capsys.readouterr().err


def test_automatic_bar_waits_for_long_runs(capsys, monkeypatch):
    pytest.importorskip("tqdm")
    monkeypatch.setattr(spacar.progress, "interactive", lambda: True)
    run()  # about 40 ms: shorter than the delay, so nothing is shown
    assert "100%" not in capsys.readouterr().err


def test_environment_variable_turns_the_automatic_bar_off(capsys, monkeypatch):
    monkeypatch.setattr(spacar.progress, "interactive", lambda: True)
    monkeypatch.setattr(spacar.progress, "DELAY", 0.0)
    monkeypatch.setenv("SPACAR_PROGRESS", "0")
    run()
    assert capsys.readouterr().err == ""


def test_without_tqdm_there_is_no_bar_and_no_error(capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "tqdm", None)   # import tqdm now fails
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    run(progress=True)
    assert capsys.readouterr().err == ""


def test_no_bar_without_a_time_interval(capsys):
    model = spacar.read(EXAMPLE)
    model.timestep(0, 0.0)
    spacar.simulate(model, progress=True)
    assert capsys.readouterr().err == ""

"""Issue 24: fuzzing of the reader's file path and of Results.load, and the replay of their corpus.

- every file of tests/data/fuzz/reader/ read with spacar.read gives what read_string gives (the
  same dump or the same error), only SpacarErrors, in bounded time;
- every file of tests/data/fuzz/results/ loads into consistent Results or is refused with an
  InputError naming the file (compression bombs before they are inflated);
- then a fixed budget of new hypothesis cases of each (derandomized: the same every run).

The corpus grows with `python -c "from support import fuzzing; fuzzing.grow_corpus('results', N, seed)"`
(from tests/) and by coverage-guided fuzzing (`python tests/support/coverage_fuzz.py results
-max_total_time=300 --keep`, atheris); a short coverage-guided run of each is part of the suite
where atheris is installed (the `fuzz` extra). See docs/robustness.md.
"""
import faulthandler
import os
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings

import spacar
from support.fuzzing import cases_text, corpus_files, results_file, run_reader_file, run_results_file


@pytest.fixture(autouse=True)
def keep_memory_limit():
    old = spacar.memory_limit()
    faulthandler.dump_traceback_later(120, exit=True)  # a hang ends the run with a traceback
    yield
    faulthandler.cancel_dump_traceback_later()
    spacar.set_memory_limit(old)


READER_CORPUS = corpus_files("reader")
RESULTS_CORPUS = corpus_files("results")


def test_the_corpus_is_there():
    assert len(READER_CORPUS) >= 10 and len(RESULTS_CORPUS) >= 10


@pytest.mark.parametrize("path", READER_CORPUS, ids=lambda p: p.name)
def test_replay_reader_corpus(path, tmp_path):
    run_reader_file(path.read_bytes().decode("utf-8", "replace"), tmp_path)


@pytest.mark.parametrize("path", RESULTS_CORPUS, ids=lambda p: p.name)
def test_replay_results_corpus(path, tmp_path):
    run_results_file(path.read_bytes(), tmp_path)


@settings(max_examples=200, derandomize=True, deadline=None, database=None,
          suppress_health_check=list(HealthCheck))
@given(results_file())
def test_200_fuzzed_results_files(tmp_path_factory, data):
    run_results_file(data, tmp_path_factory.mktemp("fuzz"))


@settings(max_examples=200, derandomize=True, deadline=None, database=None,
          suppress_health_check=list(HealthCheck))
@given(cases_text())
def test_200_fuzzed_input_files(tmp_path_factory, text):
    run_reader_file(text, tmp_path_factory.mktemp("fuzz"))


@pytest.mark.parametrize("kind", ["reader", "results"])
def test_a_short_coverage_guided_run(kind, tmp_path):
    # libFuzzer over the instrumented reader or loader, from the corpus: 3000 mutated inputs
    # with the same oracle; a finding would end it with a non-zero status and a crash file.
    pytest.importorskip("atheris")
    harness = Path(__file__).resolve().parents[1] / "support" / "coverage_fuzz.py"
    run = subprocess.run([sys.executable, str(harness), kind, "-runs=3000", "-seed=1", "--work", str(tmp_path / "new")],
                         cwd=tmp_path, capture_output=True, text=True, timeout=600,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(   # the spacar imported here
                             [str(Path(spacar.__file__).parents[1]), os.environ.get("PYTHONPATH", "")])})
    assert run.returncode == 0, run.stderr[-3000:]
    assert "Done 3000 runs" in run.stderr

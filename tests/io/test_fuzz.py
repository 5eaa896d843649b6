"""Fuzzing (issue #9): hostile input texts and Python API calls raise only spacar errors — no
crash, no hang, no other exception, no silent non-finite result. The harness is tests/support/fuzzing.py
(what is generated and checked: its docstring and docs/robustness.md).

The default run tries 10^3 cases (derandomized: the same cases every run); the long campaign of
10^5 random cases in worker processes runs with ``pytest -m slow``.
"""
from __future__ import annotations

import faulthandler
import json
import os

import pytest
from hypothesis import HealthCheck, event, given, settings

import spacar
from support.fuzzing import FUZZ_MEMORY_LIMIT, campaign, cases, run_case


@pytest.fixture(autouse=True, scope="module")
def fuzz_memory_limit():
    old = spacar.memory_limit()
    spacar.set_memory_limit(FUZZ_MEMORY_LIMIT)
    yield
    spacar.set_memory_limit(old)


@settings(max_examples=1000, derandomize=True, deadline=None, suppress_health_check=list(HealthCheck))
@given(cases(max_size=60))
def test_1000_fuzzed_inputs_raise_only_spacar_errors(case):
    # A hang ends the process with a traceback after 60 s (the analyses have a 2 s limit).
    faulthandler.dump_traceback_later(60, exit=True)
    try:
        event(f"{case.source}: {run_case(case, max_outputs=4)}")  # pytest --hypothesis-show-statistics
    finally:
        faulthandler.cancel_dump_traceback_later()


@pytest.mark.slow
def test_fuzz_campaign_of_100000_inputs(tmp_path):
    """10^5 random cases in worker processes (no cap on TIMESTEP n, chains up to 300 elements);
    crashes and hangs are caught by the parent. The report is kept in $SPACAR_FUZZ_REPORT."""
    report = tmp_path / "fuzz-report.json"
    data = campaign(100_000, workers=os.cpu_count() or 1, report=report, max_size=300)
    keep = os.environ.get("SPACAR_FUZZ_REPORT")
    if keep:
        with open(keep, "w") as fh:
            json.dump(data, fh, indent=1, default=str)
    assert data["cases"] >= 100_000
    assert not data["incidents"], json.dumps(data["incidents"], indent=1)[:5000]
    assert not data["findings"], json.dumps(data["findings"][:5], indent=1)[:5000]

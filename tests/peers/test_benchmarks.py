"""Smoke test of the benchmark scripts (benchmarks/*.py): they run on tiny sizes
(``run_all.py --quick``, a few seconds) and print every section; nothing is written to docs/."""
from __future__ import annotations

import subprocess
import sys

import pytest

from support.paths import ROOT

pytest.importorskip("pinocchio")
pytest.importorskip("exudyn")



def test_run_all_quick(tmp_path):
    doc = ROOT / "docs" / "performance.md"
    before = doc.read_text() if doc.exists() else None
    out = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "run_all.py"), "--quick"],
                         capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    for title in ("## Manual slider-crank", "## Rigid N-link chains", "## Four-bar linkage",
                  "## Flexible cantilever", "## Manual slider-crank: spacar, exudyn", "## Stiff integration",
                  "## Newton's iterations on the general path", "## Closed loops on the recursive path"):
        assert title in out.stdout
    assert "Time per right-hand side" in out.stdout and "Growth from n" in out.stdout
    assert (doc.read_text() if doc.exists() else None) == before

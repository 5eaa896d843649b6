"""Factories for the sweep's fault-injection tests (tests/api/test_sweep_faults.py): cases that
kill the process running them, or take their time. Sent to workers by value (cloudpickle), so
that spawned processes and Dask workers need not import this module."""
from __future__ import annotations

import os
import signal
import time

from spacar.compare import models


def small_model():
    return models.cantilever(2, ei=175.0, rho_a=0.785, t_end=0.01, n_out=5, eps=1e-6)


def kill_case_3(params):
    """Case k = 3 kills its process, as a crash in a callable or the kernel's OOM killer would."""
    if params["k"] == 3:
        os.kill(os.getpid(), signal.SIGKILL)
    return small_model()


def slow(params):
    time.sleep(1.0)
    return small_model()

"""A progress bar over simulated time (tqdm, optional), and the one detection of where a bar
belongs, shared with :func:`spacar.sweep`.

The bar advances at the output times (Python never runs inside the integration). ``progress``
of :func:`spacar.simulate`: ``None`` (default) shows it only in an interactive session (a
terminal on standard error, or a Jupyter kernel) and only for runs that last longer than
``DELAY`` seconds; ``True`` always (when tqdm is installed); ``False`` never. The environment
variable ``SPACAR_PROGRESS=0`` turns the automatic bar off.
"""
from __future__ import annotations

import os
import sys

DELAY = 1.0  # seconds before an automatic bar appears: short runs stay quiet


def in_kernel() -> bool:
    """Running inside a Jupyter kernel (not merely with ipykernel imported, as a notebook
    client or exporter does)."""
    if "ipykernel" not in sys.modules:
        return False
    try:
        from IPython import get_ipython
    except ImportError:
        return False
    return getattr(get_ipython(), "kernel", None) is not None


def interactive() -> bool:
    """A terminal on standard error or a Jupyter kernel."""
    if in_kernel():
        return True
    try:
        return sys.stderr is not None and sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


def automatic() -> bool:
    """Whether ``progress=None`` shows a bar: in an interactive session, unless
    ``SPACAR_PROGRESS`` turns it off."""
    if os.environ.get("SPACAR_PROGRESS", "").strip() in ("0", "false", "no", "off"):
        return False
    return interactive()


def tqdm_class():
    """The tqdm bar class for this session, None without tqdm: the notebook bar in a Jupyter
    kernel with ipywidgets (without them the notebook bar cannot show), the text bar otherwise."""
    try:
        if in_kernel():
            try:
                import ipywidgets  # noqa: F401  (tqdm.auto needs it for the notebook bar)

                from tqdm.auto import tqdm
                return tqdm
            except ImportError:
                pass
        from tqdm import tqdm
        return tqdm
    except ImportError:
        return None


class ProgressBar:
    """Callback ``bar(k, state)`` advancing a tqdm bar to the simulated time ``state["t"]``."""

    def __init__(self, t0: float, period: float, delay: float, desc: str = "spacar"):
        tqdm = tqdm_class()
        self.t0, self.period = t0, period
        # n and total are simulated seconds since the start of the block
        self.bar = tqdm(total=period, desc=desc, delay=delay, leave=True, file=sys.stderr,
                        bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.4g}/{total:.4g} s simulated "
                                   "[{elapsed}<{remaining}]")
        self.done = 0.0

    def __call__(self, k: int, state: dict) -> None:
        t = float(state["t"])
        target = min(max(t - self.t0, 0.0), self.period)
        if target > self.done:
            self.bar.update(target - self.done)
            self.done = target

    def close(self) -> None:
        self.bar.close()


def make(progress, t0: float, period: float):
    """A :class:`ProgressBar` or None, by the ``progress`` argument (see the module docs)."""
    if progress is False or not period > 0.0:
        return None
    if progress is None:
        if not automatic():
            return None
        delay = DELAY
    else:
        delay = 0.0
    if tqdm_class() is None:
        return None
    return ProgressBar(t0, period, delay)

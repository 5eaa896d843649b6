"""Shared pieces of the benchmark scripts: machine description, timing, time-to-accuracy,
log-log fits, plots and writing a section of docs/performance.md."""
from __future__ import annotations

import math
import os
import platform
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import spacar

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "performance.md"
IMG = ROOT / "docs" / "img"
HEADER = "# Performance\n\nMeasured figures of spacar; each section is written by the script named in it.\n\n"



# --- fresh processes ------------------------------------------------------------------------------

def fresh_process(worker: str, args, timeout: float, env: dict | None = None, what: str = "a fresh process"):
    """Run the Python source ``worker`` in a new interpreter with the arguments ``args`` and return
    the JSON of its last line of output; None (logged) if it fails. The interpreter is started
    by a shell, not by this process: Linux carries the high-water mark of the process that execs
    into ru_maxrss, and a child spawned from a benchmark would start from its own peak (the
    shell's is about 2 MiB), so memory measured in the worker is its own."""
    import json

    proc = subprocess.run(["/bin/sh", "-c", '"$0" "$@"; exit $?', sys.executable, "-c", worker, *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, env=env)
    if proc.returncode:
        log(f"{what} failed: {proc.stderr[-500:]}")
        return None
    return json.loads(proc.stdout.strip().splitlines()[-1])

# --- machine --------------------------------------------------------------------------------

def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def compiler() -> str:
    """Compiler of the extension module: from the CMake build directory next to it (build-tree
    installs) or the repository's build/ (editable installs, which copy the module), else the
    system's c++."""
    here = Path(spacar._core.__file__).resolve()
    repo_builds = sorted((Path(__file__).resolve().parents[1] / "build").glob("*/CMakeCache.txt"))
    for cache in [p / "CMakeCache.txt" for p in list(here.parents)[:5]] + repo_builds:
        parent = cache.parent
        if not cache.is_file():
            continue
        text = cache.read_text(errors="replace")
        build_type = re.search(r"^CMAKE_BUILD_TYPE:\w+=(.*)$", text, re.M)
        flags = None
        if build_type:
            flags = re.search(rf"^CMAKE_CXX_FLAGS_{build_type.group(1).upper()}:\w+=(.*)$", text, re.M)
        for info in sorted(parent.glob("CMakeFiles/*/CMakeCXXCompiler.cmake")):
            ctext = info.read_text(errors="replace")
            cid = re.search(r'set\(CMAKE_CXX_COMPILER_ID "([^"]*)"\)', ctext)
            ver = re.search(r'set\(CMAKE_CXX_COMPILER_VERSION "([^"]*)"\)', ctext)
            if cid and ver:
                desc = f"{cid.group(1)} {ver.group(1)}"
                if build_type:
                    desc += f", {build_type.group(1)}"
                if flags and flags.group(1).strip():
                    desc += f" ({flags.group(1).strip()})"
                return desc
    try:
        out = subprocess.run(["c++", "--version"], capture_output=True, text=True, timeout=10).stdout
        return out.splitlines()[0].strip() + " (system c++; build directory not found)"
    except (OSError, IndexError, subprocess.SubprocessError):
        return "unknown"


def machine(peers: bool = False) -> dict:
    info = {
        "CPU": cpu_model(),
        "cores": f"{os.cpu_count()} logical",
        "OS": f"{platform.system()} {platform.release()}",
        "compiler": compiler(),
        "Python": platform.python_version(),
        "NumPy": np.__version__,
        "spacar": spacar.__version__,
    }
    try:
        info["load average at start (1/5/15 min)"] = " / ".join(f"{v:.2f}" for v in os.getloadavg()) + \
            " (other processes share the machine; timings are best-of-repeats)"
    except OSError:  # pragma: no cover
        pass
    if peers:
        import exudyn
        import pinocchio
        import scipy

        info["SciPy"] = scipy.__version__
        info["exudyn"] = exudyn.__version__
        info["Pinocchio"] = pinocchio.__version__
    return info


def machine_table(info: dict) -> list:
    return ["| machine | |", "|---|---|", *[f"| {k} | {v} |" for k, v in info.items()]]


# --- timing ---------------------------------------------------------------------------------

def best_time(fn, repeat: int = 3, budget: float = 5.0, min_time: float = 0.0, setup=None):
    """Best wall time of fn() over at least ``repeat`` calls that together last at least
    ``min_time`` seconds (short calls are repeated over a window long enough that a burst of
    load on the shared machine cannot cover all of them); fewer once the next call would exceed
    ``budget`` seconds in all. With ``setup``, each call is fn(setup()), setup outside the timing.
    Returns (seconds, last return value)."""
    best, value, spent, k = float("inf"), None, 0.0, 0
    while True:
        args = () if setup is None else (setup(),)
        start = time.perf_counter()
        value = fn(*args)
        dt = time.perf_counter() - start
        best, spent, k = min(best, dt), spent + dt, k + 1
        if spent * (k + 1) / k > budget or (k >= repeat and spent >= min_time):
            return best, value


def simulate_best(model, repeat: int = 3, budget: float = 2.0, recursive: bool = True, min_time: float = 0.0,
                  **options):
    """Best wall time of ``spacar.simulate`` as :func:`best_time`, each run on a fresh copy of the
    model (copied outside the timing); returns (results of the last run, seconds).
    ``recursive=False``: the general path only; ``options``: further arguments of simulate
    (``method=``, ``progress=``)."""
    best, res = best_time(lambda m: spacar.simulate(m, recursive=recursive, **options), repeat, budget, min_time,
                          setup=model.copy)
    return res, best


def in_run_per_rhs(model, min_time: float = 0.5, min_runs: int = 3, recursive: bool = True):
    """Seconds per right-hand side inside a run of ``spacar.simulate``: the best block wall time
    (``stats["wall_time"]``, the C++ integration loop) over runs repeated for at least
    ``min_time`` seconds, divided by the run's right-hand sides (the same in every run); with
    the statistics of the last run. The protocol of :func:`per_call` for the peers' calls.
    ``recursive=False``: the general path only."""
    best, spent, runs, stats = float("inf"), 0.0, 0, None
    while runs < min_runs or spent < min_time:
        m = model.copy()
        start = time.perf_counter()
        stats = spacar.simulate(m, recursive=recursive).stats
        spent += time.perf_counter() - start
        runs += 1
        best = min(best, stats["wall_time"])
    return best / stats["rhs_evaluations"], stats


def per_call(fn, min_time: float = 0.2, max_calls: int = 100000, min_calls: int = 1) -> float:
    """Seconds per call of fn(), from a loop of at least min_time seconds (best of 3 loops)."""
    start = time.perf_counter()
    fn()
    first = time.perf_counter() - start
    n = max(min_calls, min(max_calls, int(min_time / max(first, 1e-7))))
    best = float("inf")
    for _ in range(3 if first * n < 2.0 else 1):
        start = time.perf_counter()
        for _ in range(n):
            fn()
        best = min(best, (time.perf_counter() - start) / n)
    return best


def time_to_accuracy(points, target):
    """Smallest wall time among runs [(error, seconds), ...] whose error is ≤ target; None if no
    run reached it."""
    ok = [t for e, t in points if e <= target]
    return min(ok) if ok else None


def fit_exponent(ns, ts):
    """Exponent p of a least-squares fit t ≈ c nᵖ on log-log axes."""
    ns, ts = np.asarray(ns, dtype=float), np.asarray(ts, dtype=float)
    if len(ns) < 2:
        return float("nan")
    return float(np.polyfit(np.log(ns), np.log(ts), 1)[0])


def fmt_time(s) -> str:
    if s is None or (isinstance(s, float) and not math.isfinite(s)):
        return "—"
    if s < 1e-3:
        return f"{s * 1e6:.1f} µs"
    if s < 1.0:
        return f"{s * 1e3:.2f} ms"
    return f"{s:.2f} s"


def fmt_ratio(a, b) -> str:
    if a is None or b is None:
        return "—"
    return f"{a / b:.3g}×"  # three digits: 2.96× must not read as 3×


def fmt_err(e) -> str:
    return "—" if e is None else f"{e:.1e}"


# --- output ---------------------------------------------------------------------------------

RESULTS = ROOT / "benchmarks" / "results"


def _restore_keys(obj):
    if isinstance(obj, dict):
        out = {}
        for k, v in obj.items():
            key = k
            if isinstance(k, str):
                for conv in (int, float):
                    try:
                        key = conv(k)
                        break
                    except ValueError:
                        pass
            out[key] = _restore_keys(v)
        return out
    if isinstance(obj, list):
        return [_restore_keys(v) for v in obj]
    return obj


def save_results(name: str, result: dict) -> Path:
    """Raw figures of a full run (benchmarks/results/<name>.json), so that the section and the
    plots can be regenerated without measuring again (``--from-results``)."""
    import json

    RESULTS.mkdir(parents=True, exist_ok=True)
    path = RESULTS / f"{name}.json"
    path.write_text(json.dumps(result, indent=1, default=float) + "\n")
    return path


def load_results(name: str) -> dict:
    import json

    return _restore_keys(json.loads((RESULTS / f"{name}.json").read_text()))


def standard_main(module_name, doc, run, section, plot, argv=None, extra_args=None):
    """The command line shared by the benchmark scripts: --quick, --no-write, --no-plot,
    --from-results (regenerate the section and plots from benchmarks/results/<name>.json)."""
    import argparse

    p = argparse.ArgumentParser(description=doc.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="tiny sizes, few settings (smoke test); writes nothing")
    p.add_argument("--no-write", action="store_true", help="do not update docs/performance.md")
    p.add_argument("--no-plot", action="store_true", help="do not write docs/img/*.png")
    p.add_argument("--from-results", action="store_true", help="do not measure: use benchmarks/results/<case>.json")
    if extra_args:
        extra_args(p)
    a = p.parse_args(argv)
    if a.from_results:
        r = load_results(module_name)
    else:
        r = run(a)
        if not a.quick:
            save_results(module_name, r)
    plots = None if (a.no_plot or r.get("quick")) else plot(r)
    text = section(r, plots)
    print(text)
    if not a.no_write and not r.get("quick"):
        write_section(section_title(text), text)
    return 0


def section_title(text: str) -> str:
    return text.splitlines()[0][3:].strip()

def write_section(title: str, text: str, path: Path = DOC) -> None:
    """Replace (or append) the section ``## title`` of docs/performance.md."""
    doc = path.read_text() if path.exists() else HEADER
    heading = f"## {title}"
    pattern = re.compile(rf"^{re.escape(heading)}\n.*?(?=^## |\Z)", re.M | re.S)
    if pattern.search(doc):
        doc = pattern.sub(lambda _: text.rstrip("\n") + "\n\n", doc, count=1)
    else:
        doc = doc.rstrip("\n") + "\n\n" + text.rstrip("\n") + "\n"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(doc.rstrip("\n") + "\n")


def new_figure(title: str):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4), dpi=110)
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    return fig, ax


def save_figure(fig, name: str) -> str:
    IMG.mkdir(parents=True, exist_ok=True)
    path = IMG / name
    fig.tight_layout()
    fig.savefig(path)
    import matplotlib.pyplot as plt

    plt.close(fig)
    return f"img/{name}"


def quiet_exudyn():
    """exudyn prints deprecation notes and solver banners; keep the benchmark output readable."""
    import warnings

    warnings.filterwarnings("ignore", category=DeprecationWarning)
    try:
        import exudyn

        exudyn.SetWriteToConsole(False)
    except Exception:  # pragma: no cover
        pass


def log(*args):
    print(*args, file=sys.stderr, flush=True)

"""The ``spacar`` command line.

``spacar run FILE``    process the blocks of an input file in order: at every END run the
                       analysis and print the state dump (a restartable input block). With
                       MATASC 1 the state goes to the files ``<stem>_x.asc``, ... as the run
                       proceeds; with ANIMATE 1 the animation of those blocks is written to
                       ``<stem>.gif`` (``--animation`` for another file or format), where
                       ``<stem>`` is the input file name without extension.
``spacar static FILE`` the static equilibrium of every block under its loads (docs/statics.md),
                       in load steps (or past limit points with ``--arc-length``), with the
                       state dump after every END.
``spacar check FILE``  summary of the model of the first block: nodes and elements by type,
                       coordinates and deformations per class, degrees of freedom; with
                       ``--release`` the redundant constraints named are released first.
                       Exits 1 when it reports problems (an empty model, redundant or missing
                       constraints), so that it can gate a script or a grading run.

Exit status: 0 success; 1 an error (printed as ``spacar: <Error>: ...`` on stderr), or problems
reported by ``check``, or no input block ended with END (``run``, ``static``); 2 bad arguments.

Everything that is not the dump is printed as ``*`` comment lines, so the output is valid input.
"""
from __future__ import annotations

import argparse
import contextlib
import itertools
import os
import signal
import sys
import threading
from pathlib import Path

import numpy as np

from . import __version__, _core
from .errors import SpacarError
from .io.reader import read
from .io.matasc import WRITING, default_stem
from .io.writer import dump
from .results import Results


def _comment(text: str, stream=None):
    # sys.stdout is looked up at call time, so that redirecting it (tests, embedding) works.
    for line in str(text).splitlines():
        print(f"* {line}", file=stream or sys.stdout)


def _print_linearization(res) -> None:
    """Eigenfrequencies at the end of a block that asked for linearization (LINE, LINEAR)."""
    if not res.linearizations:
        return
    lin = res.linearizations[-1]
    _comment(f"linearized equations at t = {lin.t:g}: {len(lin.z_labels)} coordinates")
    if not lin.z_labels:  # no degrees of freedom and no LINE parameters
        return
    # Zero frequencies (rigid-body motions, a neutral direction) come out as round-off: counted, not
    # printed, as the zero eigenvalues are.
    freqs = np.asarray(lin.eigenfrequencies(), dtype=float)
    big = max(1.0, float(np.abs(freqs).max(initial=0.0)))
    shown = [f for f in freqs if abs(f) > 1e-6 * big]
    zero = f" ({len(freqs) - len(shown)} zero)" if len(shown) < len(freqs) else ""
    _comment(f"eigenfrequencies [Hz] (undamped; negative: unstable){zero}: " + " ".join(f"{f:.6g}" for f in shown))
    lam = lin.eigenvalues()
    scale = max(1.0, float(np.abs(lam).max(initial=0.0)))
    nonzero = [z for z in lam if abs(z) > 1e-6 * scale]
    _comment(f"eigenvalues [1/s] ({len(lam) - len(nonzero)} zero): " +
             " ".join(f"{z.real:.8g}{z.imag:+.8g}i" if abs(z.imag) > 0 else f"{z.real:.8g}" for z in nonzero))
    if res.settings_linear == 2:
        _comment("buckling factors: " + " ".join(f"{m:.6g}" for m in lin.buckling_factors()))


def _print_forces(res, model, digits: int) -> None:
    """FORCEMODE 1: the reactions on the fixed and input coordinates and the driving forces of
    the input deformations at the dump's time, as comment lines keyed like the dump
    (``* REACTION n i value``, ``* SIGMA e i value``); FORCEMODE 2: the stresses of all
    deformations. The dump format has no place for them."""
    forcemode = model.settings.forcemode
    if forcemode < 1 or len(res.t) == 0:
        return
    real = f" {{:{digits + 6}.{digits - 1}E}}"
    _comment(f"FORCEMODE {forcemode} at t = {res.t[-1]:g}: reactions on the fixed and input coordinates, "
             + ("stresses of the elements" if forcemode >= 2 else "driving forces of the input deformations"))
    for i in res.supported_columns():
        n, c = res.coordinate_labels[i]
        _comment(f"{'REACTION':<8s} {n:3d} {c:3d}" + real.format(res.reaction[-1, i]))
    elements = model.elements  # a new dict on every access
    for k, (e, i) in enumerate(res.deformation_labels):
        if forcemode >= 2 or elements[e].cls[i - 1].name == "input":
            _comment(f"{'SIGMA':<8s} {e:3d} {i:3d}" + real.format(res.sigma[-1, k]))


def _read_for_analysis(args, analysis: str = ""):
    """The model of the input file, its header and reader warnings printed; None (said in a comment)
    if no block ended with END."""
    model = read(args.file)
    _comment(f"spacar {__version__}{analysis}: {args.file}")
    for w in model.warnings:
        _comment(f"warning: {w}")
    if not model.blocks:
        _comment("no input block ended with END: nothing to analyse (end the input with a line END)")
        return None
    return model


def _run(args) -> int:
    model = _read_for_analysis(args)
    if model is None:
        return 1
    if args.output_stem:
        model.output_stem = args.output_stem
    animated = []
    n_warn = len(model.warnings)
    blocks = model.run_blocks(method=args.method, progress=args.progress, time_limit=args.time_limit,
                              rho_inf=args.rho_inf, fixed_step=args.fixed_step)
    for k in itertools.count():
        try:
            res = next(blocks)
        except StopIteration:
            break
        except SpacarError as err:
            partial = getattr(err, "results", None)
            if partial is not None:  # say how far the block got
                err.args = (f"{err} ({len(partial)} of {model.settings.timestep_n + 1} output times computed)",)
            raise
        if model.settings.animate == 1:
            animated.append(res)
        for w in model.warnings[n_warn:]:
            _comment(f"warning: {w}")
        n_warn = len(model.warnings)
        s = res.stats
        _comment(f"block {k + 1}: t = {res.t[0]:g} .. {res.t[-1]:g}, {len(res.t)} output times, "
                 f"{s['rhs_evaluations']} right-hand sides, {s['accepted']} steps "
                 f"({s['rejected']} rejected), {s['wall_time'] * 1e3:.1f} ms")
        _print_linearization(res)
        _print_forces(res, model, args.dump_digits)
        if model.settings.matasc == 1:
            _comment(f"MATASC files: {default_stem(model)}_*.asc")
        sys.stdout.write(dump(model, digits=args.dump_digits))
        sys.stdout.flush()
    if animated:
        _write_animation(Results.concatenate(animated), args.animation or default_stem(model) + ".gif")
    return 0


def _write_animation(res, path) -> None:
    """ANIMATE 1: the animation of the blocks that asked for it (matplotlib, pillow for GIF)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        from .animation import save_animation
    except ImportError:
        _comment("warning: ANIMATE 1 needs matplotlib (pip install matplotlib pillow): no animation written")
        return
    try:
        path = save_animation(res, path)
    except SpacarError:  # e.g. an unknown suffix: an error, not a warning (InputError is also a ValueError)
        raise
    except (RuntimeError, ValueError) as err:
        _comment(f"warning: no animation written: {err}")
        return
    _comment(f"animation: {os.fspath(Path(path))} ({len(res.t)} output times)")


def _static(args) -> int:
    from .statics import static_blocks

    model = _read_for_analysis(args, " static")
    if model is None:
        return 1
    n_warn = len(model.warnings)
    blocks = static_blocks(model, steps=args.steps, max_cuts=args.max_cuts, tolerance=args.tolerance,
                           arc_length=args.arc_length, max_steps=args.max_steps, time_limit=args.time_limit)
    for k, res in enumerate(blocks):
        for w in model.warnings[n_warn:]:
            _comment(f"warning: {w}")
        n_warn = len(model.warnings)
        s = res.stats
        _comment(f"block {k + 1}: static equilibrium in {len(res.t)} load steps, {s['newton_iterations']} Newton "
                 f"iterations ({s['step_cuts']} step cuts), {s['wall_time'] * 1e3:.1f} ms")
        for limit in s["limit_points"]:
            _comment(f"limit point passed at load factor {limit:.10g}")
        if s["indefinite_at"] is not None:
            _comment(f"the tangent stiffness is indefinite from load factor {s['indefinite_at']:g}: unstable")
        _print_forces(res, model, args.dump_digits)
        sys.stdout.write(dump(model, digits=args.dump_digits))
        sys.stdout.flush()
    return 0


def _html(args) -> int:
    from .notebook import to_html

    out = args.output or str(Path(args.notebook).with_suffix(".html"))
    try:
        to_html(args.notebook, out)
    except ImportError as err:  # nbconvert or plotly missing: one line, not a traceback
        raise SpacarError(str(err)) from None
    print(f"spacar: wrote {out}")
    return 0


def _check(args) -> int:
    model = read(args.file)
    _comment(f"spacar check: {args.file}")
    for w in model.warnings:
        _comment(f"warning: {w}")
    if args.release:
        released = model.release_overconstraints(time_limit=args.time_limit)
        elements = model.elements
        _comment(f"released {len(released)} redundant constraint{'s' if len(released) != 1 else ''}"
                 + (":" if released else " (none is over-constrained)"))
        for e, i in released:
            _comment(f"RLSE {e} {i}   (element {e} ({elements[e].type_name}) deformation {i})")
    result = model.check(time_limit=args.time_limit)
    _comment(result)
    return 0 if result.ok else 1   # a gate: 1 when the check reports problems


def _digits(text: str) -> int:
    value = int(text)
    if not 1 <= value <= 17:
        raise argparse.ArgumentTypeError(f"must be between 1 and 17, got {value}")
    return value


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number of seconds, got {text!r}") from None
    if not (value > 0 and value < float("inf")):
        raise argparse.ArgumentTypeError(f"must be a positive number of seconds, got {text!r}")
    return value


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="spacar", description="Kinematic and dynamic analysis of multibody systems (SPACAR95 input format).")
    parser.add_argument("--version", action="version", version=f"spacar {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run the analysis of every block and print the state dumps")
    run.add_argument("file")
    run.add_argument("--dump-digits", type=_digits, default=4, metavar="N",
                     help="significant digits of the dump (default 4 as the manual; 17 for a lossless restart)")
    run.add_argument("--method", choices=_core.integration_methods, default="auto",
                     help="integration method (default auto: dop853, then radau5 where it detects stiffness or "
                          "generalized_alpha for an undamped structure; "
                          "radau5: implicit, for stiff flexible systems; generalized_alpha: implicit, second order)")
    run.add_argument("--rho-inf", type=float, default=None, metavar="RHO",
                     help="generalized_alpha: spectral radius at infinite frequency, 0..1 (default 0.9; 1: no "
                          "numerical damping)")
    run.add_argument("--fixed-step", type=float, default=None, metavar="H",
                     help="generalized_alpha: fixed steps of H seconds without error control")
    run.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                     help="progress bar over simulated time on standard error (default: in a terminal, "
                          "for runs longer than a second; needs tqdm)")
    run.add_argument("--output-stem", metavar="STEM",
                     help="stem of the MATASC and animation files (default: the input file without extension)")
    run.add_argument("--animation", metavar="FILE",
                     help="file of the ANIMATE 1 animation: .gif (default <stem>.gif), .mp4 (ffmpeg) or .html")
    run.add_argument("--time-limit", type=_seconds, default=None, metavar="SECONDS",
                     help="wall-clock limit per block (default: none); beyond it the run stops with an error")
    run.set_defaults(func=_run)
    static = sub.add_parser("static", help="static equilibrium of every block under its loads; print the state dumps")
    static.add_argument("file")
    static.add_argument("--steps", type=int, default=10, metavar="N", help="equal load steps per block (default 10)")
    static.add_argument("--max-cuts", type=int, default=12, metavar="N",
                        help="halvings of a load step in which Newton fails before giving up (default 12)")
    static.add_argument("--arc-length", action="store_true",
                        help="follow the equilibrium path past limit points (snap-through) by the arc-length method")
    static.add_argument("--max-steps", type=int, default=200, metavar="N",
                        help="arc-length steps per block before giving up (default 200)")
    static.add_argument("--tolerance", type=float, default=1e-10,
                        help="residual relative to the largest load balanced (default 1e-10)")
    static.add_argument("--time-limit", type=_seconds, default=None, metavar="SECONDS",
                        help="wall-clock limit per block (default: none); beyond it the analysis stops with an error")
    static.add_argument("--dump-digits", type=_digits, default=4, metavar="N",
                        help="significant digits of the dump (default 4; 17 for a lossless restart)")
    static.set_defaults(func=_static)
    check = sub.add_parser("check", help="summarise the model: nodes, elements, classes, degrees of freedom")
    check.add_argument("file")
    check.add_argument("--release", action="store_true",
                       help="release (RLSE) the redundant constraints the diagnosis names, then check again")
    check.add_argument("--time-limit", type=_seconds, default=None, metavar="SECONDS",
                       help="wall-clock limit of the set-up and diagnosis (default: none)")
    check.set_defaults(func=_check)
    html = sub.add_parser("html", help="a notebook as an HTML page that keeps spacar's widgets (as their pictures) "
                                       "and 3-D views, offline")
    html.add_argument("notebook")
    html.add_argument("-o", "--output", default=None, metavar="FILE", help="the page (default: NOTEBOOK.html)")
    html.set_defaults(func=_html)
    args = parser.parse_args(argv)
    try:
        with _terminations_as_interrupts():
            return _interruptible(args.func, args)
    except SpacarError as err:
        sys.stdout.flush()
        print(f"spacar: {type(err).__name__}: {err}", file=sys.stderr)
        return 1
    except OSError as err:
        # The dump could not be written (standard output on a full disk, a closed pipe): one line,
        # status 1, and standard output pointed at /dev/null so that the exit's flush is quiet.
        print(f"spacar: cannot write the output: {err.strerror or err}", file=sys.stderr)
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 1
    except KeyboardInterrupt as err:
        # Ctrl-C, SIGTERM or SIGHUP: one line, no traceback, the shell's status for the signal
        # (128 + its number). The analysis thread cannot be stopped inside C++: the process ends
        # here, once an output time being written is complete (the MATASC files hold whole output
        # times).
        signum = getattr(err, "signum", signal.SIGINT)
        with WRITING:
            sys.stdout.flush()
            what = "interrupted" if signum == signal.SIGINT else f"terminated ({signal.Signals(signum).name})"
            print(f"spacar: {what}", file=sys.stderr, flush=True)
            os._exit(128 + signum)


class _Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP, raised in the main thread as Ctrl-C is."""

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum


@contextlib.contextmanager
def _terminations_as_interrupts():
    """SIGTERM and SIGHUP end a run as Ctrl-C does (complete output files, one line), instead of
    killing the process between the rows of an output time; the handlers are restored after."""
    def handler(signum, frame):
        raise _Terminated(signum)

    wanted = [getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name)]
    if threading.current_thread() is not threading.main_thread():
        wanted = []  # signal handlers can only be set in the main thread
    previous = {sig: signal.signal(sig, handler) for sig in wanted}
    try:
        yield
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


def _interruptible(func, args):
    """func(args) in a thread while this (the main) thread waits: the C++ core does not poll
    for signals during a run, so Ctrl-C would otherwise wait for the block to end."""
    outcome = {}

    def target():
        try:
            outcome["value"] = func(args)
        except BaseException as err:  # noqa: BLE001 - handed to the main thread unchanged
            outcome["error"] = err

    worker = threading.Thread(target=target, name="spacar-analysis", daemon=True)
    worker.start()
    while worker.is_alive():
        worker.join(0.1)
    if "error" in outcome:
        raise outcome["error"]
    return outcome["value"]


if __name__ == "__main__":
    sys.exit(main())

"""Animations of a run with matplotlib (no OpenGL): :func:`animate` returns a
``matplotlib.animation.FuncAnimation`` that shows itself inline in Jupyter (HTML/JavaScript),
and :func:`save_animation` writes it as GIF (pillow), MP4 (when ffmpeg is installed) or HTML.
"""
from __future__ import annotations

import os
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
from matplotlib import animation as _mpl_animation

from .errors import InputError
from .plotting import Scene
from .results import Results, require_results


class Animation(_mpl_animation.FuncAnimation):
    """A ``FuncAnimation`` of a mechanism; in Jupyter the last expression of a cell shows it as
    an interactive HTML/JavaScript player. ``scene`` holds the artists and the axes."""

    def _repr_html_(self):
        if matplotlib.rcParams["animation.html"] in ("none", None):
            return self.to_jshtml()
        return super()._repr_html_()


def _non_interactive_backend() -> bool:
    backend = matplotlib.get_backend().lower()
    return "inline" in backend or backend in ("agg", "pdf", "svg", "ps", "cairo", "template")


def animate(res: Results, *, step: int = 1, max_frames: int | None = 200, interval: float | None = None,
            ax=None, figsize=(6.0, 4.5), dpi: int = 80, labels: bool = False, trace=(), beam_points: int = 21,
            close: bool | None = None, repeat: bool = True) -> Animation:
    """Animation of the mechanism over the output times of ``res``.

    ``step`` takes every step-th output time (and at most ``max_frames`` frames); ``interval``
    is the delay between frames in ms (default: real time, clamped to 20..200 ms). ``labels``,
    ``trace``, ``beam_points`` as in :func:`spacar.draw`. ``close`` closes the figure so that a
    notebook shows only the animation, not an extra still image (default: with the inline and
    non-interactive backends). Save with :func:`save_animation` or ``anim.save(...)``."""
    require_results(res, "animate")
    nt = len(res.t)
    if nt == 0:
        raise InputError("these results have no output times")
    step = max(int(step), 1)
    if max_frames is not None and nt / step > max_frames:
        step = -(-nt // max_frames)
    frames = list(range(0, nt, step))
    if frames[-1] != nt - 1:
        frames.append(nt - 1)
    if interval is None:
        dt = (res.t[-1] - res.t[0]) / max(len(frames) - 1, 1)
        interval = min(max(1000.0 * dt, 20.0), 200.0)
    scene = Scene(res, ax, frames[0], labels=labels, trace=trace, beam_points=beam_points, figsize=figsize, dpi=dpi)
    fig = scene.ax.figure
    anim = Animation(fig, scene.update, frames=frames, interval=interval, blit=False, repeat=repeat,
                     cache_frame_data=False)
    anim.scene = scene
    if close if close is not None else _non_interactive_backend():
        plt.close(fig)
    return anim


def save_animation(anim, path, *, fps: float | None = None, dpi: int | None = None, **animate_kwargs):
    """Write an animation (an :class:`Animation`, or :class:`spacar.Results` to animate with
    ``animate_kwargs``) to ``path``: ``.gif`` (pillow), ``.mp4`` (ffmpeg), ``.html``
    (self-contained JavaScript player). Returns the path."""
    if isinstance(anim, Results):
        anim = animate(anim, **animate_kwargs)
    elif animate_kwargs:
        raise InputError(f"unexpected arguments {sorted(animate_kwargs)} for an existing animation")
    path = Path(os.fspath(path))
    suffix = path.suffix.lower()
    if fps is None:
        fps = 1000.0 / anim._interval
    if suffix == ".gif":
        writer = _mpl_animation.PillowWriter(fps=fps)
    elif suffix == ".mp4":
        if not _mpl_animation.writers.is_available("ffmpeg"):
            raise RuntimeError("writing MP4 needs ffmpeg on the PATH; write a .gif or .html instead")
        writer = _mpl_animation.FFMpegWriter(fps=fps)
    elif suffix in (".html", ".htm"):
        path.write_text(anim.to_jshtml(fps=fps), encoding="utf-8")
        return path
    else:
        raise InputError(f"cannot write an animation as {suffix or 'a file without suffix'}: use .gif, .mp4 or .html")
    anim.save(os.fspath(path), writer=writer, dpi=dpi)
    return path

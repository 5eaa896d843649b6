"""Animations of a run with matplotlib (no OpenGL): :func:`animate` returns a
``matplotlib.animation.FuncAnimation`` that shows itself inline in Jupyter (HTML/JavaScript),
and :func:`save_animation` writes it as GIF (pillow), MP4 (when ffmpeg is installed) or HTML.
:func:`animate_mode` animates a vibration mode about a linearized state.

The HTML player works offline: matplotlib's player takes its button icons from Font Awesome on
a CDN; :meth:`Animation.to_jshtml` drops that link and labels the buttons with Unicode symbols.
"""
from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

import matplotlib
import matplotlib.pyplot as plt
from matplotlib import animation as _mpl_animation

from .errors import InputError
from .geometry import Geometry
from .io.files import check_output_path, write_replacing
from .plotting import Scene, _displaced, mode_phases, snapshot
from .results import Results, require_results


class Animation(_mpl_animation.FuncAnimation):
    """A ``FuncAnimation`` of a mechanism; in Jupyter the last expression of a cell shows it as
    an interactive HTML/JavaScript player. ``scene`` holds the artists and the axes."""

    def to_jshtml(self, fps=None, embed_frames=True, default_mode=None):
        """The HTML/JavaScript player of matplotlib, self-contained: no web fonts or other
        network resources (the buttons show Unicode symbols)."""
        return offline_html(super().to_jshtml(fps, embed_frames, default_mode))

    def _repr_html_(self):
        if matplotlib.rcParams["animation.html"] in ("none", None):
            return self.to_jshtml()
        return super()._repr_html_()


_ICONS = {"fa-minus": "\u2212", "fa-fast-backward": "\u23ee", "fa-step-backward": "\u23f4\u2759",
          "fa-play fa-flip-horizontal": "\u25c0", "fa-pause": "\u2759\u2759", "fa-play": "\u25b6",
          "fa-step-forward": "\u2759\u23f5", "fa-fast-forward": "\u23ed", "fa-plus": "+"}


def offline_html(html: str) -> str:
    """An HTML player without resources from the network: the stylesheet links to http(s)
    addresses are dropped and the Font Awesome icons become Unicode symbols."""
    html = re.sub(r"<link[^>]*href=[\"']https?://[^>]*>", "", html)
    return re.sub(r'<i class="fa ([^"]*)"></i>', lambda m: _ICONS.get(m.group(1), ""), html)


def _non_interactive_backend() -> bool:
    backend = matplotlib.get_backend().lower()
    return "inline" in backend or backend in ("agg", "pdf", "svg", "ps", "cairo", "template")


def animate(res: Results, *, step: int = 1, max_frames: int | None = 200, interval: float | None = None,
            ax=None, figsize=(6.0, 4.5), dpi: int = 80, labels: bool = False, trace=(), beam_points: int = 21,
            close: bool | None = None, repeat: bool = True, magnify: float = 1.0, caption=None) -> Animation:
    """Animation of the mechanism over the output times of ``res``.

    ``step`` takes every step-th output time (and at most ``max_frames`` frames); ``interval``
    is the delay between frames in ms (default: real time, clamped to 20..200 ms). ``labels``,
    ``trace``, ``beam_points``, ``magnify`` as in :func:`spacar.draw`; ``caption(k)`` gives the
    title of output index k (default the time). ``close`` closes the figure so that a
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
    scene = Scene(res, ax, frames[0], labels=labels, trace=trace, beam_points=beam_points, figsize=figsize, dpi=dpi,
                  magnify=magnify, caption=caption)
    fig = scene.ax.figure
    anim = Animation(fig, scene.update, frames=frames, interval=interval, blit=False, repeat=repeat,
                     cache_frame_data=False)
    anim.scene = scene
    if close if close is not None else _non_interactive_backend():
        plt.close(fig)
    return anim


def animate_mode(source, mode: int = 0, *, at: int = -1, scale: float | None = None, frames: int = 24,
                 period: float = 1500.0, **animate_kwargs) -> Animation:
    """Animation of vibration mode ``mode`` (0: the lowest frequency) about a linearized state.

    ``source``: :class:`spacar.Results` whose model asked for linearizations (LINEAR, LINE;
    ``at`` picks the output time, default the last), or a :class:`spacar.Model` (linearized at
    its current state, as :func:`spacar.linearize`). The nodal shape
    (``Linearization.mode_shapes()[2]``) is added with ``scale`` times cos(2π j / frames),
    j = 0 .. frames − 1 (the first frame, the still picture of a notebook exported to HTML, at
    the largest amplitude) (``scale`` as in :func:`spacar.draw`'s ``mode``: default the largest
    displacement a tenth of the model's size); beams are drawn through the displaced nodes with
    the cubic (Hermite) shape of their displaced end slopes. One period lasts ``period`` ms.
    Other keyword arguments go to :func:`animate`."""
    res, lin, k = _linearized_state(source, at)
    freqs, _, shapes_x = lin.mode_shapes()
    if isinstance(mode, bool) or not isinstance(mode, (int, np.integer)) or not 0 <= mode < shapes_x.shape[1]:
        raise InputError(f"mode must be a mode number 0..{shapes_x.shape[1] - 1} (0: the lowest frequency), "
                         f"got {mode!r}")
    phases = mode_phases(frames)
    moving = _displaced(res, k, shapes_x[:, mode], scale, phases)
    f = float(freqs[mode])
    animate_kwargs.setdefault("caption", lambda j: f"mode {mode + 1}: {f:.4g} Hz")
    animate_kwargs.setdefault("interval", period / frames)
    return animate(moving, max_frames=None, **animate_kwargs)


def _linearized_state(source, at):
    """(results holding the state, its Linearization, the row of the state)."""
    from .linearize import Linearization, linearized_simulation
    from .model import Model

    if isinstance(source, Model):
        lin, sim, _ = linearized_simulation(source)
        return snapshot(sim, Geometry.from_model(source)), lin, 0
    if isinstance(source, Linearization):
        raise InputError("a Linearization has no geometry to draw: pass the Results it belongs to "
                         "(a model with LINEAR) or the Model")
    require_results(source, "animate_mode")
    if source.geometry is None:
        raise InputError("these results have no geometry to draw (results of spacar.simulate have)")
    if not source.linearizations:
        raise InputError("these results hold no linearizations: add LINEAR 1 to the model (or pass the Model, "
                         "linearized at its current state)")
    k = range(len(source.linearizations))[at]
    return source, source.linearizations[k], k


def save_animation(anim, path, *, fps: float | None = None, dpi: int | None = None, **animate_kwargs):
    """Write an animation (an :class:`Animation`, or :class:`spacar.Results` to animate with
    ``animate_kwargs``) to ``path``: ``.gif`` (pillow), ``.mp4`` (ffmpeg), ``.html``
    (self-contained JavaScript player). Returns the path. As every file spacar writes: never
    through a symbolic link, only a regular file, an existing file replaced once the new one is
    complete (docs/robustness.md, "Files")."""
    try:
        check_output_path(os.fspath(path))  # before the frames are drawn
    except OSError as err:
        raise InputError(f"{path}: cannot write the animation ({err.strerror or err})") from None
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
        html = anim.to_jshtml(fps=fps)
        write_replacing(os.fspath(path), lambda temporary: Path(temporary).write_text(html, encoding="utf-8"),
                        "write the animation")
        return path
    else:
        raise InputError(f"cannot write an animation as {suffix or 'a file without suffix'}: use .gif, .mp4 or .html")
    # Never through a link planted at the path, never into a FIFO; a failed write keeps the old file.
    write_replacing(os.fspath(path), lambda temporary: anim.save(temporary, writer=writer, dpi=dpi),
                    "write the animation")
    return path

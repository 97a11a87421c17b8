"""Animations of a result: GIF (Pillow's encoder), MP4 (H.264 by the ffmpeg binary that the
imageio-ffmpeg package ships) and HTML: the browser app with the run loaded (:mod:`planardyn.app`).

Frames are drawn with matplotlib on its own Agg canvas (no pyplot, no global state): the
mechanism as :func:`planardyn.plot.draw_mechanism` draws it, the paths of the traced points,
and the time.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from . import extras
from .app import write_app
from .playback import auto_speed
from .plot import draw_mechanism, trace_points

if TYPE_CHECKING:
    from .mechanism import Mechanism
    from .result import SimulationResult

#: Frames drawn at most (longer runs are played faster than real time instead).
MAX_FRAMES = 400
FORMATS = (".gif", ".mp4", ".html", ".htm")
DEFAULT_FPS = 20.0
#: Added to the frame count before flooring: a whole count computed in floating point
#: (0.3 / 0.1 * 10 is 29.999...) must not lose its last frame.
FRAME_COUNT_SLACK = 1e-9
#: Frame times are nudged forward by this fraction of the span before the output search, so
#: a frame on an output time picks that output despite round-off in the linspace.
FRAME_TIME_SLACK = 1e-12


def frame_indices(
    t: np.ndarray, fps: float, speed: float | None = None, max_frames: int = MAX_FRAMES
) -> np.ndarray:
    """Indices of the outputs shown at ``fps`` frames per second of playback, ``speed``
    seconds of simulated time per second of playback (default :func:`~planardyn.playback.auto_speed`; the output
    at or before each frame's time). At most ``max_frames`` (then uniformly spaced), at least the first and last output."""
    t = np.asarray(t, dtype=float)
    if len(t) == 0:
        raise ValueError("the result has no output to animate")
    speed = auto_speed(t) if speed is None else speed
    if fps <= 0 or speed <= 0:
        raise ValueError(f"fps and speed must be positive, got fps={fps}, speed={speed}")
    span = t[-1] - t[0]
    n = int(np.floor(span / speed * fps + FRAME_COUNT_SLACK)) + 1
    if n > max_frames:
        n = max_frames
    times = t[0] + np.linspace(0.0, span, max(n, 2) if len(t) > 1 else 1)
    idx = np.searchsorted(t, times + FRAME_TIME_SLACK * max(1.0, abs(span)), side="right") - 1
    return np.clip(idx, 0, len(t) - 1)


def _bounds(mech: Mechanism, pos: np.ndarray) -> tuple[float, float, float, float]:
    """Axis limits that hold every point of the run, the ground marks and a margin (m)."""
    lo, hi = np.nanmin(pos, axis=(0, 1)), np.nanmax(pos, axis=(0, 1))
    pad = 0.12 * mech.scale
    return lo[0] - pad, hi[0] + pad, lo[1] - 1.5 * pad, hi[1] + pad


def render_frames(
    mech: Mechanism,
    result: SimulationResult,
    *,
    fps: float = DEFAULT_FPS,
    speed: float | None = None,
    size: tuple[int, int] = (640, 480),
    traces: list[str] | None = None,
    labels: bool = True,
    max_frames: int = MAX_FRAMES,
):
    """Yield the frames as (H, W, 3) uint8 RGB arrays, ``size`` = (W, H) pixels."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    dpi = 80
    fig = Figure(figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi)
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_axes((0.08, 0.08, 0.9, 0.84))
    pos = mech.point_positions(result.x)  # (N, P, 2)
    x0, x1, y0, y1 = _bounds(mech, pos)
    traces = trace_points(mech, traces)
    trace_idx = [mech.point_names.index(n) for n in traces]
    colors = [f"C{(j + 6) % 10}" for j in range(len(trace_idx))]
    for j, i in enumerate(trace_idx):  # the whole paths, faint, drawn once
        ax.plot(pos[:, i, 0], pos[:, i, 1], ":", color=colors[j], linewidth=1, alpha=0.6)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    title = ax.set_title("", fontsize=10, family="monospace")
    drawn: list[Any] = []
    for k in frame_indices(result.t, fps, speed, max_frames):
        for a in drawn:  # remove the last frame's artists, keep the axes (ticks are costly)
            a.remove()
        drawn = []
        for j, i in enumerate(trace_idx):
            drawn += ax.plot(pos[: k + 1, i, 0], pos[: k + 1, i, 1], "-", color=colors[j], linewidth=1.5)
        drawn += draw_mechanism(mech, result.x[k], ax=ax, labels=labels)
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        title.set_text(f"{mech.name}   t = {result.t[k]:7.3f} s")
        canvas.draw()
        yield np.asarray(canvas.buffer_rgba())[:, :, :3].copy()


def _reporting(frames: Iterable[Any], total: int, progress: Callable[[int, int], Any]) -> Iterator[Any]:
    for done, frame in enumerate(frames, 1):
        yield frame
        progress(done, total)


def write_gif(frames, path: Path, fps: float) -> int:
    """Encode RGB frames as a looping GIF with Pillow. Returns the number of frames."""
    from PIL import Image

    images = [Image.fromarray(f).quantize(colors=128, method=Image.Quantize.MEDIANCUT) for f in frames]
    if not images:
        raise ValueError("no frames to write")
    images[0].save(
        path, save_all=True, append_images=images[1:], duration=int(round(1000 / fps)), loop=0, optimize=True
    )
    return len(images)


def write_mp4(frames, path: Path, fps: float, size: tuple[int, int]) -> int:
    """Encode RGB frames as H.264 MP4 with imageio-ffmpeg's ffmpeg. Returns the frame count."""
    try:
        import imageio_ffmpeg
    except ImportError as e:
        raise extras.missing("mp4", "an MP4 animation", e) from e
    writer = imageio_ffmpeg.write_frames(
        str(path), size, fps=fps, codec="libx264", pix_fmt_in="rgb24", pix_fmt_out="yuv420p",
        macro_block_size=16, output_params=["-movflags", "+faststart"], ffmpeg_log_level="error",
    )
    writer.send(None)
    n = 0
    try:
        for f in frames:
            writer.send(np.ascontiguousarray(f))
            n += 1
    finally:
        writer.close()
    return n


def animate(
    mech: Mechanism,
    result: SimulationResult,
    path: str | os.PathLike[str],
    *,
    fps: float = DEFAULT_FPS,
    speed: float | None = None,
    size: tuple[int, int] = (640, 480),
    traces: list[str] | None = None,
    labels: bool = True,
    max_frames: int = MAX_FRAMES,
    progress: Callable[[int, int], Any] | None = None,
    **run_kw: Any,
) -> Path:
    """Write an animation of ``result``: ``.gif``, ``.mp4`` or ``.html`` (the browser app with
    the model and the run, :func:`planardyn.app.write_app`; ``run_kw`` go to it: ``channels``,
    ``max_frames``, ``title``), by extension.

    Parameters
    ----------
    fps : float
        Frames per second of playback.
    speed : float
        Simulated seconds per second of playback (0.5: slow motion); default
        :func:`planardyn.playback.auto_speed` (the run lasts 3 to 10 s).
    size : (int, int)
        Width and height in pixels (multiples of 16 for MP4).
    traces : list of str
        Points whose paths are drawn (default :func:`planardyn.plot.default_trace_points`).
    progress : callable, optional
        GIF and MP4: ``progress(done, total)`` after each frame is drawn (frame counts).

    Returns the path written.
    """
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in FORMATS:
        raise ValueError(f"{path}: unknown animation format {ext!r} (use .gif, .mp4 or .html)")
    if ext in (".html", ".htm"):
        return write_app(path, mech, result, traces=traces, **run_kw)
    if ext == ".mp4" and (size[0] % 16 or size[1] % 16):
        raise ValueError(f"MP4 frame size must be multiples of 16 pixels, got {size[0]} x {size[1]}")
    frames = render_frames(
        mech, result, fps=fps, speed=speed, size=size, traces=traces, labels=labels, max_frames=max_frames
    )
    if progress is not None:
        frames = _reporting(frames, len(frame_indices(result.t, fps, speed, max_frames)), progress)
    if ext == ".gif":
        write_gif(frames, path, fps)
    else:
        write_mp4(frames, path, fps, size)
    return path

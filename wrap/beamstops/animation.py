"""The beam between its stops over time, from the recorded snapshots, as a GIF or MP4.

:func:`animate` draws ũ(x, t) at (at most ``frames``) snapshots spread evenly over the run,
with the stops as grey blocks and the points of the beam at the stops marked red in the
frames where the record nearest the snapshot has a reaction there. GIF through Pillow
(matplotlib's PillowWriter), MP4 through ffmpeg (FFMpegWriter) when it is installed.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .output_files import IMAGE, check, write
from .plotbase import need_snapshots, stop_geometry, title
from .result import Result
from .transforms import frame_indices

__all__ = ["animate", "FORMATS", "MAX_FRAMES"]

#: File extensions :func:`animate` writes.
FORMATS = (".gif", ".mp4")
#: Default largest number of frames.
MAX_FRAMES = 200


def _writer(path: Path, fps: int) -> object:
    from matplotlib import animation

    suffix = path.suffix.lower()
    if suffix == ".gif":
        return animation.PillowWriter(fps=fps)
    if suffix == ".mp4":
        if not animation.FFMpegWriter.isAvailable():
            raise ValueError(f"{path}: writing MP4 needs ffmpeg, which is not on PATH; write a .gif instead")
        return animation.FFMpegWriter(fps=fps)
    raise ValueError(f"{path}: an animation is written as {' or '.join(FORMATS)}, "
                     f"not {suffix or 'a file without extension'}")


def _contacts(result: Result, snapshot: int) -> np.ndarray:
    """Which stops act at the record nearest a snapshot (a nonzero reaction)."""
    if result.t.size == 0:
        return np.zeros(max(1, result.stops_node.size), dtype=bool)
    row = int(np.clip(np.searchsorted(result.t, result.snapshot_t[snapshot]), 0, result.t.size - 1))
    if result.stops_node.size:
        return result.stops_reaction[row] != 0 if result.stops_reaction.shape[1] else np.zeros(0, dtype=bool)
    return np.array([result.reaction.size > row and result.reaction[row] != 0])


def animate(result: Result, path: str | os.PathLike[str], *, frames: int = MAX_FRAMES, fps: int = 20,
            dpi: int = 100) -> Path:
    """Write the animation of the beam to ``path`` (.gif or .mp4); gives the path.

    ValueError without snapshots, for another extension, or for .mp4 without ffmpeg. The file is
    written as :func:`beamstops.output_files.write` writes (only an image or an empty file is
    written over, through a temporary file renamed into place once complete).
    """
    need_snapshots(result)
    path = Path(path)
    writer = _writer(path, fps)
    shown = frame_indices(result.snapshot_t.size, frames)
    check(path, IMAGE)
    return write(path, IMAGE, lambda tmp: _draw(result, tmp, writer, shown, dpi))


def _draw(result: Result, path: Path, writer: object, shown: np.ndarray, dpi: int) -> None:
    """The frames ``shown`` of the snapshots, written by ``writer`` to ``path``."""
    x, u = result.snapshot_x, result.snapshot_u
    stops_x, lower, upper = stop_geometry(result)
    length = float(x[-1]) if x.size else 1.0
    reach = max(float(np.max(np.abs(u))), *(np.abs(lower)), *(np.abs(upper)), 1e-12) * 1.15

    # The still part (axes, ticks, stops, labels) is drawn once, then laid under every frame as an
    # image; a frame draws only the beam, the contacts and the clock: frames cost milliseconds.
    size = (8.0, 4.0)
    still = Figure(figsize=size, dpi=dpi, layout="constrained")
    ax = still.add_subplot()
    ax.set_xlim(-0.02 * length, 1.04 * length)
    ax.set_ylim(-reach, reach)
    half = 0.012 * length
    for xs, g1, g2 in zip(stops_x, lower, upper):
        ax.fill_between([xs - half, xs + half], g2, reach, color="0.6", linewidth=0)
        ax.fill_between([xs - half, xs + half], -reach, g1, color="0.6", linewidth=0)
    ax.axhline(0.0, color="0.85", linewidth=0.6, zorder=0)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("ũ(x, t) (m)")
    ax.set_title(title(result), fontsize="medium")
    canvas = FigureCanvasAgg(still)
    canvas.draw()
    background = np.asarray(canvas.buffer_rgba()).copy()

    fig = Figure(figsize=size, dpi=dpi)
    fig.figimage(background, 0, 0, origin="upper", resize=False)
    front = fig.add_axes(ax.get_position().bounds)
    front.set_xlim(ax.get_xlim())
    front.set_ylim(ax.get_ylim())
    front.set_axis_off()
    front.set_zorder(1)  # above the figure image
    (beam,) = front.plot(x, u[shown[0]], color="k", linewidth=1.6)
    (at_stops,) = front.plot([], [], "o", color="tab:red", markersize=5)
    clock = front.text(0.02, 0.95, "", transform=front.transAxes, va="top", family="monospace")
    with writer.saving(fig, str(path), dpi):  # type: ignore[attr-defined]
        for i in shown:
            beam.set_ydata(u[i])
            acting = _contacts(result, int(i))
            if stops_x.size and acting.size == stops_x.size and acting.any():
                at_stops.set_data(stops_x[acting], np.interp(stops_x[acting], x, u[i]))
            else:
                at_stops.set_data([], [])
            clock.set_text(f"t = {result.snapshot_t[i]:.5f} s")
            writer.grab_frame()  # type: ignore[attr-defined]

"""What the plot modules share: line styles, decimation for drawing, the stops' geometry,
the checks that a plot's data is there (with the message saying how to get it)."""

from __future__ import annotations

from typing import Any, Optional

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from .result import Result

__all__ = ["LINE", "STOP", "envelope", "new_axes", "title", "tip_stops", "stop_geometry", "placeholder",
           "NO_SNAPSHOTS", "need_records", "need_snapshots", "need_impacts"]

LINE: dict[str, Any] = {"color": "k", "linewidth": 0.6}
STOP: dict[str, Any] = {"color": "tab:red", "linewidth": 0.8, "linestyle": "--"}
# Above this many points a series is drawn through its per-bin minima and maxima:
# the picture is the same at screen resolution, and drawing stays fast.
DRAW_POINTS = 20000

NO_SNAPSHOTS = "no snapshots: run with &output snapshot_every > 0"


def envelope(x: np.ndarray, *ys: np.ndarray, bins: int = 4000) -> tuple[np.ndarray, ...]:
    """Min/max decimation for drawing: per bin of consecutive samples, the samples where y is extreme."""
    n = x.size
    if n <= DRAW_POINTS:
        return (x, *ys)
    width = -(-n // bins)
    cut = (n // width) * width
    index = np.arange(cut).reshape(-1, width)
    keep = [np.arange(cut, n)]
    for y in ys:
        block = y[:cut].reshape(-1, width)
        keep.append(index[np.arange(index.shape[0]), block.argmin(axis=1)])
        keep.append(index[np.arange(index.shape[0]), block.argmax(axis=1)])
    order = np.unique(np.concatenate(keep + [np.array([0, n - 1])]))
    return (x[order], *(y[order] for y in ys))


def new_axes(ax: Optional[Axes]) -> Axes:
    """``ax``, or the Axes of a new figure."""
    if ax is not None:
        return ax
    return Figure(figsize=(8, 4.5), layout="constrained").add_subplot()


def title(result: Result) -> str:
    """The run in a few words: the law, β and Δt."""
    a = result.attrs
    law = {"signorini": "Signorini scheme", "compliance": "normal compliance", "none": "no stops"}.get(
        a.get("law", ""), str(a.get("law", "")))
    if a.get("law") == "compliance" and "stiffness_per_mass" in a:
        law += f" (1/ε = {a['stiffness_per_mass']:.3g} 1/s²)"
    return f"{law}, β = {a.get('beta', float('nan')):g}, Δt = {a.get('dt', float('nan')):g} s"


def tip_stops(result: Result) -> tuple[Optional[float], Optional[float]]:
    """The tip's stops: the tip-only form's, or those of a stop along the span at the tip."""
    if result.attrs.get("law") == "none":
        return None, None
    if result.stops_node.size:
        at_tip = np.flatnonzero(result.stops_node == result.attrs.get("elements"))
        if at_tip.size == 0:
            return None, None
        return float(result.stops_lower[at_tip[0]]), float(result.stops_upper[at_tip[0]])
    return result.attrs.get("lower"), result.attrs.get("upper")


def stop_geometry(result: Result) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every stop as (x, lower, upper) arrays: the stops along the span, or the tip's (empty without stops)."""
    if result.attrs.get("law") == "none":
        return np.empty(0), np.empty(0), np.empty(0)
    if result.stops_node.size:
        return result.stops_x, result.stops_lower, result.stops_upper
    lower, upper = result.attrs.get("lower"), result.attrs.get("upper")
    length = result.attrs.get("length", result.snapshot_x[-1] if result.snapshot_x.size else None)
    if lower is None or upper is None or length is None:
        return np.empty(0), np.empty(0), np.empty(0)
    return np.array([float(length)]), np.array([float(lower)]), np.array([float(upper)])


def stop_label(result: Result, stop: int) -> str:
    """A 1-based stop index of the shock log in words."""
    if result.stops_x.size >= stop >= 1:
        return f"stop {stop} (x = {result.stops_x[stop - 1]:.4g} m)"
    return "tip" if stop == 1 else f"stop {stop}"


def placeholder(ax: Axes, message: str) -> Axes:
    """An empty panel saying why it is empty."""
    ax.text(0.5, 0.5, message, ha="center", va="center", transform=ax.transAxes, wrap=True)
    ax.set_axis_off()
    return ax


def need_records(result: Result) -> None:
    if result.t.size == 0:
        raise ValueError("no records: the run recorded no tip displacement (/tip is empty)")


def need_snapshots(result: Result) -> None:
    if result.snapshot_t.size == 0:
        raise ValueError(NO_SNAPSHOTS)


def need_impacts(result: Result) -> None:
    if not result.impacts:
        if result.attrs.get("enabled") == 0:  # the scene turned the shock log off, not an older beamstops
            raise ValueError("no shock log: the run was made with &statistics enabled = .false. (no /impacts); run it "
                             "with &statistics enabled = .true. (the default)")
        raise ValueError("no shock log: the run has no /impacts (written by a beamstops that did not log shocks)")
    if result.shocks == 0:
        raise ValueError("no shocks: the shock log /impacts is empty (the beam never touched a stop)")

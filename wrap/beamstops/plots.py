"""Plots of a :class:`~beamstops.Result` (matplotlib, without pyplot: safe with no display).

Each ``plot_*`` function draws on a given Axes (or a new figure's) and returns the Axes:

- :func:`plot_tip`: tip displacement against time in the paper's style, stops drawn;
- :func:`plot_shape`: the beam's shape in space-time, a colour map of ũ(x, t);
- :func:`plot_energy`: discrete energy with the work of the load and the energy the stops took;
- :func:`plot_phase`: phase portrait (u, v) of the tip;
- :func:`plot_reaction`: contact reaction at the tip;
- :func:`plot_stop`: displacement of one stop along the span between its stops, contacts marked
  (kind ``'stops'``: one panel per stop).

:func:`figure` builds a whole figure of one kind (or ``'all'``), :func:`save` writes it.
Figures are :class:`matplotlib.figure.Figure` objects not attached to any GUI backend,
so nothing here needs a display; to show one interactively, use pyplot yourself.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np
from matplotlib import rc_context
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from .result import Result

__all__ = ["KINDS", "plot_tip", "plot_shape", "plot_energy", "plot_phase", "plot_reaction", "plot_stop", "figure",
           "save"]

#: Plot kinds understood by :func:`figure`, :func:`save` and ``python -m beamstops plot --kind``.
KINDS = ("tip", "shape", "energy", "phase", "reaction", "stops", "all")

_LINE = {"color": "k", "linewidth": 0.6}
_STOP = {"color": "tab:red", "linewidth": 0.8, "linestyle": "--"}
# Above this many points a series is drawn through its per-bin minima and maxima:
# the picture is the same at screen resolution, and drawing stays fast.
_DRAW_POINTS = 20000


def _envelope(x: np.ndarray, *ys: np.ndarray, bins: int = 4000) -> tuple[np.ndarray, ...]:
    """Min/max decimation for drawing: per bin of consecutive samples, the samples where y is extreme."""
    n = x.size
    if n <= _DRAW_POINTS:
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


def _axes(ax: Optional[Axes]) -> Axes:
    if ax is not None:
        return ax
    return Figure(figsize=(8, 4.5), layout="constrained").add_subplot()


def _title(result: Result) -> str:
    a = result.attrs
    law = {"signorini": "Signorini scheme", "compliance": "normal compliance", "none": "no stops"}.get(
        a.get("law", ""), str(a.get("law", "")))
    if a.get("law") == "compliance" and "stiffness_per_mass" in a:
        law += f" (1/ε = {a['stiffness_per_mass']:.3g} 1/s²)"
    return f"{law}, β = {a.get('beta', float('nan')):g}, Δt = {a.get('dt', float('nan')):g} s"


def _stops(result: Result) -> tuple[Optional[float], Optional[float]]:
    """The tip's stops: the tip-only form's, or those of a stop along the span at the tip."""
    if result.attrs.get("law") == "none":
        return None, None
    if result.stops_node.size:
        at_tip = np.flatnonzero(result.stops_node == result.attrs.get("elements"))
        if at_tip.size == 0:
            return None, None
        return float(result.stops_lower[at_tip[0]]), float(result.stops_upper[at_tip[0]])
    return result.attrs.get("lower"), result.attrs.get("upper")


def plot_tip(result: Result, ax: Optional[Axes] = None, *, stops: bool = True,
             xlim: Optional[tuple[float, float]] = None, ylim: Optional[tuple[float, float]] = None,
             title: Optional[str] = None) -> Axes:
    """Tip displacement u(L, t) against time, as the paper draws it, with the stops."""
    ax = _axes(ax)
    t, u = _envelope(result.t, result.tip_u)
    ax.plot(t, u, **_LINE)
    lower, upper = _stops(result)
    if stops:
        for g in (lower, upper):
            if g is not None:
                ax.axhline(g, **_STOP)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("u(L, t) (m)")
    ax.set_xlim(xlim if xlim is not None else (0.0, float(result.attrs.get("t_end", t[-1] if t.size else 1.0))))
    if ylim is not None:
        ax.set_ylim(ylim)
    ax.set_title(title if title is not None else _title(result), fontsize="medium")
    ax.grid(True, linewidth=0.3, alpha=0.5)
    return ax


def plot_shape(result: Result, ax: Optional[Axes] = None, *, cmap: str = "RdBu_r") -> Axes:
    """The beam's shape in space-time: a colour map of the physical displacement ũ(x, t)."""
    ax = _axes(ax)
    t, x, u = result.snapshot_t, result.snapshot_x, result.snapshot_u
    if t.size == 0:
        ax.text(0.5, 0.5, "no snapshots\n(set &output snapshot_every > 0)", ha="center", va="center",
                transform=ax.transAxes)
        ax.set_axis_off()
        return ax
    limit = float(np.max(np.abs(u))) or 1.0
    mesh = ax.pcolormesh(t, x, u.T, shading="nearest", cmap=cmap, vmin=-limit, vmax=limit, rasterized=True)
    ax.figure.colorbar(mesh, ax=ax, label="ũ(x, t) (m)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("x (m)")
    ax.set_title("shape ũ(x, t)", fontsize="medium")
    return ax


def plot_energy(result: Result, ax: Optional[Axes] = None) -> Axes:
    """Discrete energy E with the work W of the load and the energy D the stops took.

    The dashed line E(0) + W − D lies on E when the energy balance holds.
    """
    ax = _axes(ax)
    t, e, w, d = _envelope(result.t, result.energy, result.work, result.dissipated)
    ax.plot(t, e, color="k", linewidth=0.8, label="energy E")
    ax.plot(t, w, color="tab:blue", linewidth=0.8, label="work of the load W")
    ax.plot(t, d, color="tab:red", linewidth=0.8, label="taken by the stops D")
    if result.energy.size:
        ax.plot(t, result.energy[0] + w - d, color="tab:green", linewidth=0.8, linestyle="--",
                label="E(0) + W − D")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("J")
    ax.set_title("energy", fontsize="medium")
    ax.legend(fontsize="small", loc="best")
    ax.grid(True, linewidth=0.3, alpha=0.5)
    return ax


def plot_phase(result: Result, ax: Optional[Axes] = None) -> Axes:
    """Phase portrait of the tip: velocity against displacement, with the stops."""
    ax = _axes(ax)
    ax.plot(result.tip_u, result.tip_v, color="k", linewidth=0.3)
    for g in _stops(result):
        if g is not None:
            ax.axvline(g, **_STOP)
    ax.set_xlabel("u(L, t) (m)")
    ax.set_ylabel("v(L, t) (m/s)")
    ax.set_title("tip phase portrait", fontsize="medium")
    ax.grid(True, linewidth=0.3, alpha=0.5)
    return ax


def plot_reaction(result: Result, ax: Optional[Axes] = None) -> Axes:
    """Contact reaction at the tip against time (negative at the upper stop)."""
    ax = _axes(ax)
    t, r = _envelope(result.t, result.reaction)
    ax.plot(t, r, **_LINE)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("reaction (N)")
    ax.set_title("contact reaction", fontsize="medium")
    ax.grid(True, linewidth=0.3, alpha=0.5)
    return ax


def plot_stop(result: Result, index: int = 0, ax: Optional[Axes] = None) -> Axes:
    """Physical displacement ũ at stop ``index`` (0-based) along the span against time, between
    its stops; the records where the stop acts (a nonzero reaction) are marked."""
    ax = _axes(ax)
    if result.stops_node.size == 0:
        ax.text(0.5, 0.5, "no stops along the span\n(&stops nodes or x)", ha="center", va="center",
                transform=ax.transAxes)
        ax.set_axis_off()
        return ax
    u = result.stops_u[:, index]
    r = result.stops_reaction[:, index]
    t, ud = _envelope(result.t, u)
    ax.plot(t, 1e3 * ud, **_LINE)
    if result.attrs.get("law") != "none":
        for g in (result.stops_lower[index], result.stops_upper[index]):
            ax.axhline(1e3 * g, **_STOP)
        acting = r != 0
        if acting.any():
            ax.plot(result.t[acting], 1e3 * u[acting], ".", color="tab:red", markersize=1.5, label="stop acts")
    ax.set_ylabel("ũ (mm)")
    ax.set_xlim(0.0, float(result.attrs.get("t_end", result.t[-1] if result.t.size else 1.0)))
    ax.set_title(f"stop {index + 1}: node {int(result.stops_node[index])}, x = {result.stops_x[index]:.4g} m, "
                 f"{np.count_nonzero(r)} records with a reaction", fontsize="medium")
    ax.grid(True, linewidth=0.3, alpha=0.5)
    return ax


def _stops_figure(result: Result) -> Figure:
    """One panel per stop along the span, time shared, the tip at the bottom."""
    m = max(1, result.stops_node.size)
    fig = Figure(figsize=(9, 1.2 + 2.2 * m), layout="constrained")
    axes = np.atleast_1d(fig.subplots(m, 1, sharex=True))
    order = np.argsort(result.stops_x) if result.stops_node.size else [0]
    for ax, index in zip(axes, order):
        plot_stop(result, int(index), ax)
    axes[-1].set_xlabel("t (s)")
    fig.suptitle(_title(result), fontsize="medium")
    return fig


_PLOTS: dict[str, Callable[..., Axes]] = {
    "tip": plot_tip, "shape": plot_shape, "energy": plot_energy, "phase": plot_phase, "reaction": plot_reaction,
}


def figure(result: Result, kind: str = "tip", **options: Any) -> Figure:
    """A figure of one kind (see :data:`KINDS`); ``'all'`` puts every kind on one page."""
    if kind not in KINDS:
        raise ValueError(f"unknown plot kind {kind!r}; allowed: {', '.join(KINDS)}")
    if kind == "stops":
        return _stops_figure(result)
    if kind != "all":
        fig = Figure(figsize=(8, 4.5), layout="constrained")
        _PLOTS[kind](result, fig.add_subplot(), **options)
        return fig
    fig = Figure(figsize=(14, 9), layout="constrained")
    grid = fig.subplots(2, 3)
    plot_tip(result, grid[0, 0], **options)
    plot_shape(result, grid[0, 1])
    plot_energy(result, grid[0, 2])
    plot_phase(result, grid[1, 0])
    plot_reaction(result, grid[1, 1])
    grid[1, 2].set_axis_off()
    a = result.attrs
    grid[1, 2].text(0.0, 1.0, "\n".join([
        f"source: {Path(result.source).name}", f"status: {result.status}", f"law: {a.get('law')}",
        f"dt = {a.get('dt')} s, β = {a.get('beta')}, J = {a.get('elements')}",
        f"steps: {a.get('steps')}, impacts: {a.get('impacts')}",
        f"largest stop violation: {a.get('max_violation', float('nan')):.3g} m",
        f"κ_h = {a.get('kappa_h', float('nan')):.5g} 1/s²", f"engine CPU: {a.get('cpu_seconds', float('nan')):.3g} s",
    ]), va="top", family="monospace", fontsize="small", transform=grid[1, 2].transAxes)
    return fig


def save(result: Result, path: str | os.PathLike[str], kind: str = "tip", dpi: int = 120, **options: Any) -> Path:
    """Draw a figure of one kind and write it (the format follows the file's extension)."""
    fig = figure(result, kind, **options)
    path = Path(path)
    with rc_context({"agg.path.chunksize": 20000}):
        fig.savefig(path, dpi=dpi)
    return path

"""Plots of a :class:`~beamstops.Result` (matplotlib, without pyplot: safe with no display).

Each ``plot_*`` function draws on a given Axes (or a new figure's) and returns the Axes:

- :func:`plot_tip`: tip displacement against time in the paper's style, stops drawn;
- :func:`plot_shape` (= :func:`plot_spacetime`): the beam's shape in space-time, a colour map of ũ(x, t);
- :func:`plot_energy`: discrete energy with the work of the load and the energy the stops took;
- :func:`plot_phase`: phase portrait (u, v) of the tip;
- :func:`plot_reaction`: contact reaction at the tip;
- :func:`plot_stop`: displacement of one stop along the span between its stops, contacts marked
  (kind ``'stops'``: one panel per stop);
- :func:`plot_impulses`, :func:`plot_impact_velocities` (kind ``'impacts'``): histograms over the
  engine's shock log, per stop;
- :func:`plot_pdf`: tip-displacement PDF (the engine's histogram and its 95 % intervals);
- :func:`plot_psd` (kind ``'psd'``: tip displacement and reaction): Welch spectra, log axes;
- :func:`plot_poincare`: the stroboscopic section (u(L, kT), v(L, kT)), T = 2π/ω.

:func:`figure` builds a whole figure of one kind (or ``'all'``: every kind whose data the run
has), :func:`save` writes it; ``save(result, 'OUT.gif', kind='animation')`` (or
:func:`beamstops.animation.animate`) writes the beam moving between its stops. A kind whose
data is absent raises ValueError saying how to get it (``no snapshots: run with &output
snapshot_every > 0``). Figures are :class:`matplotlib.figure.Figure` objects not attached to any
GUI backend, so nothing here needs a display; to show one interactively, use pyplot yourself.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np
from matplotlib import rc_context, rcParams
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from .arguments import MAX_DPI, bounded
from .output_files import IMAGE, check, save_figure
from .plot_kinds import FIGURE_KINDS, KINDS, TRANSIENT, TRANSIENT_KINDS
from .plotbase import LINE as _LINE
from .plotbase import STOP as _STOP
from .plotbase import envelope as _envelope
from .plotbase import need_impacts, need_records, need_snapshots, placeholder
from .plotbase import new_axes as _axes
from .plotbase import tip_stops as _stops
from .plotbase import title as _title
from .plots_dynamics import (MIN_SPECTRUM_RECORDS, engine_pdf, plot_impact_velocities, plot_impulses, plot_pdf,
                             plot_poincare, plot_psd, poincare_period)
from .result import Result
from .transforms import after, stroboscopic

__all__ = ["KINDS", "FIGURE_KINDS", "plot_tip", "plot_shape", "plot_spacetime", "plot_energy", "plot_phase",
           "plot_reaction", "plot_stop", "plot_impulses", "plot_impact_velocities", "plot_pdf", "plot_psd",
           "plot_poincare", "missing", "figure", "save", "check_transient"]


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
    """The beam's shape in space-time: a colour map of the physical displacement ũ(x, t) (kinds
    'shape' and 'spacetime'); ValueError without snapshots."""
    need_snapshots(result)
    ax = _axes(ax)
    t, x, u = result.snapshot_t, result.snapshot_x, result.snapshot_u
    limit = float(np.max(np.abs(u))) or 1.0
    mesh = ax.pcolormesh(t, x, u.T, shading="nearest", cmap=cmap, vmin=-limit, vmax=limit, rasterized=True)
    ax.figure.colorbar(mesh, ax=ax, label="ũ(x, t) (m)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("x (m)")
    ax.set_title("shape ũ(x, t)", fontsize="medium")
    return ax


plot_spacetime = plot_shape


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
    _need_span_stops(result)
    ax = _axes(ax)
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


def _need_span_stops(result: Result) -> None:
    if result.stops_node.size == 0:
        raise ValueError("no stops along the span: the scene has none (&stops nodes or x)")


def _stops_figure(result: Result) -> Figure:
    """One panel per stop along the span, time shared, the tip at the bottom."""
    _need_span_stops(result)
    m = result.stops_node.size
    fig = Figure(figsize=(9, 1.2 + 2.2 * m), layout="constrained")
    axes = np.atleast_1d(fig.subplots(m, 1, sharex=True))
    order = np.argsort(result.stops_x)
    for ax, index in zip(axes, order):
        plot_stop(result, int(index), ax)
    axes[-1].set_xlabel("t (s)")
    fig.suptitle(_title(result), fontsize="medium")
    return fig


_PLOTS: dict[str, Callable[..., Axes]] = {
    "tip": plot_tip, "shape": plot_shape, "spacetime": plot_shape, "energy": plot_energy, "phase": plot_phase,
    "reaction": plot_reaction, "pdf": plot_pdf, "poincare": plot_poincare,
}


def missing(result: Result, kind: str, transient: Optional[float] = None) -> Optional[str]:
    """Why ``kind`` cannot be drawn from ``result`` (the message of the ValueError), or None if it can."""
    try:
        if kind in ("tip", "energy", "phase", "reaction"):
            need_records(result)
        elif kind in ("shape", "spacetime", "animation"):
            need_snapshots(result)
        elif kind == "stops":
            _need_span_stops(result)
        elif kind == "impacts":
            need_impacts(result)
        elif kind == "pdf":
            if not engine_pdf(result, transient):
                need_records(result)
                if not after(result.t, transient).any():
                    return f"no records after the transient: t ≥ {transient} s"
        elif kind == "psd":
            need_records(result)
            count = int(after(result.t, transient).sum())
            if count < MIN_SPECTRUM_RECORDS:
                return (f"too few records for a spectrum: {count} after t = {transient or 0.0:g} s "
                        f"(at least {MIN_SPECTRUM_RECORDS})")
        elif kind == "poincare":
            need_records(result)
            if stroboscopic(result.t, poincare_period(result), transient)[0].size == 0:
                return f"no stroboscopic sample: no kT after t = {transient or 0.0:g} s within the records"
    except ValueError as exc:
        return str(exc)
    return None


def _info(result: Result, ax: Axes) -> None:
    """The run in text: source, law, scheme, counts, the engine's headline statistics."""
    ax.set_axis_off()
    a = result.attrs
    lines = [
        f"source: {Path(result.source).name}", f"status: {result.status}", f"law: {a.get('law')}",
        f"dt = {a.get('dt')} s, β = {a.get('beta')}, J = {a.get('elements')}",
        f"steps: {a.get('steps')}, impacts: {a.get('impacts')}",
        f"largest stop violation: {a.get('max_violation', float('nan')):.3g} m",
        f"κ_h = {a.get('kappa_h', float('nan')):.5g} 1/s²", f"engine CPU: {a.get('cpu_seconds', float('nan')):.3g} s",
    ]
    if result.impacts:
        lines.append(f"shocks logged: {result.shocks}")
    for name, label in (("shocks_per_second", "shocks per second"), ("power", "power to the stops"),
                        ("contact_fraction", "contact fraction")):
        if name in result.statistics:
            lines.append(f"{label}: {result.statistics[name]}")
    if result.statistics_attrs:
        lines.append(f"statistics: t ≥ {result.statistics_attrs.get('transient', 0.0):g} s, "
                     f"{result.statistics_attrs.get('batches', '?')} batches")
    ax.text(0.0, 1.0, "\n".join(lines), va="top", family="monospace", fontsize="small", transform=ax.transAxes)


def _all_figure(result: Result, transient: Optional[float], options: dict[str, Any]) -> Figure:
    """Every still kind whose data the run has on one page (the shape's place kept, empty, without snapshots)."""
    panels: list[Callable[[Axes], Any]] = [
        lambda ax: plot_tip(result, ax, **options),
        lambda ax: plot_shape(result, ax) if missing(result, "shape") is None else placeholder(
            ax, missing(result, "shape") or ""),
        lambda ax: plot_energy(result, ax),
        lambda ax: plot_phase(result, ax),
        lambda ax: plot_reaction(result, ax),
    ]
    if missing(result, "stops") is None:  # one panel per stop along the span, as kind 'stops' draws them
        panels += [lambda ax, i=int(index): plot_stop(result, i, ax) for index in np.argsort(result.stops_x)]
    if missing(result, "pdf", transient) is None:
        panels.append(lambda ax: plot_pdf(result, ax, transient=transient))
    if missing(result, "psd", transient) is None:
        panels.append(lambda ax: plot_psd(result, ax, quantity="tip_u", transient=transient))
        if np.any(result.reaction[after(result.t, transient)] != 0):
            panels.append(lambda ax: plot_psd(result, ax, quantity="reaction", transient=transient))
    if missing(result, "poincare", transient) is None:
        panels.append(lambda ax: plot_poincare(result, ax, transient=transient))
    if missing(result, "impacts") is None:
        panels += [lambda ax: plot_impulses(result, ax), lambda ax: plot_impact_velocities(result, ax)]
    panels.append(lambda ax: _info(result, ax))
    rows = math.ceil(len(panels) / 3)
    fig = Figure(figsize=(14, 4.5 * rows), layout="constrained")
    grid = np.atleast_1d(fig.subplots(rows, 3)).ravel()
    for ax, draw in zip(grid, panels):
        draw(ax)
    for ax in grid[len(panels):]:
        ax.set_axis_off()
    return fig


def figure(result: Result, kind: str = "tip", *, transient: Optional[float] = None, **options: Any) -> Figure:
    """A figure of one kind (see :data:`FIGURE_KINDS`); ``'all'`` puts every kind the run has data for on one page.

    ``transient`` (s) applies to 'pdf', 'psd' and 'poincare' (and to them in 'all'): only what
    comes after it is drawn ('pdf' draws the engine's histogram when the transient is the
    engine's or not given, otherwise a histogram of the records). Other ``options`` go to the
    kind's ``plot_*`` function (to :func:`plot_tip` for 'all').
    """
    if kind not in KINDS:
        raise ValueError(f"unknown plot kind {kind!r}; allowed: {', '.join(KINDS)}")
    transient = check_transient(transient)
    if kind == "animation":
        raise ValueError("'animation' is not a still figure: save(result, 'OUT.gif', kind='animation') writes it")
    if kind == "all":
        return _all_figure(result, transient, options)
    reason = missing(result, kind, transient)
    if reason is not None:
        raise ValueError(reason)
    if kind == "stops":
        return _stops_figure(result)
    if kind == "impacts":
        fig = Figure(figsize=(12, 4.5), layout="constrained")
        left, right = fig.subplots(1, 2)
        plot_impulses(result, left)
        plot_impact_velocities(result, right)
        fig.suptitle(_title(result), fontsize="medium")
        return fig
    if kind == "psd":
        fig = Figure(figsize=(8, 8), layout="constrained")
        top, bottom = fig.subplots(2, 1, sharex=True)
        plot_psd(result, top, quantity="tip_u", transient=transient, **options)
        plot_psd(result, bottom, quantity="reaction", transient=transient, **options)
        top.set_xlabel("")
        fig.suptitle(_title(result), fontsize="medium")
        return fig
    fig = Figure(figsize=(7, 6) if kind in ("pdf", "poincare") else (8, 4.5), layout="constrained")
    if kind in TRANSIENT_KINDS:
        options = {**options, "transient": transient}
    _PLOTS[kind](result, fig.add_subplot(), **options)
    return fig


def names_folder(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` names a folder: an existing one, or a name ending with a separator."""
    raw = os.fspath(path)
    return raw.endswith(("/", os.sep)) or os.path.isdir(raw)


def check_transient(transient: Optional[float]) -> Optional[float]:
    """``transient`` (s) as the command line's ``--transient`` takes it: None, or a finite time >= 0
    (the one check of both; ValueError out of range, TypeError for what is not a number)."""
    return None if transient is None else bounded(transient, TRANSIENT, strict=False, name="transient")


def save(result: Result, path: str | os.PathLike[str], kind: str = "tip", dpi: int = 120, **options: Any) -> Path:
    """Draw a figure of one kind and write it; gives the path of the file written.

    The format follows the file's extension; a name without one gets matplotlib's default
    format's (``savefig.format``, .png), and the path given back has it. A folder is refused
    (IsADirectoryError), and so is a name where the image would destroy data or go through a
    link (:func:`beamstops.output_files.check`: only an image or an empty file is written over).
    The image is written to a temporary file beside it and renamed into place once complete: a
    failed write (:class:`~beamstops.output_files.WriteError`, ``cannot write FILE: REASON``)
    leaves the file as it was. ``kind='animation'`` writes the beam moving between its stops to a
    .gif (or .mp4 with ffmpeg; a name without extension gets .gif); its options are ``frames`` (at
    most this many, default 200) and ``fps``.
    """
    if not isinstance(result, Result):
        raise TypeError(f"result: a beamstops.Result (from beamstops.run or beamstops.load), not {type(result).__name__}")
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path: the image file to write (a str or a path), not {type(path).__name__}")
    if os.fspath(path) == "":
        raise ValueError("path '': an empty name; name the image file to write")
    if names_folder(path):
        raise IsADirectoryError(f"{os.fspath(path)}: is a folder; name the image file to write, e.g. "
                                f"{Path(path) / ('animation.gif' if kind == 'animation' else kind + '.png')}")
    if isinstance(dpi, bool) or not isinstance(dpi, (int, float)) or not 0 < dpi <= MAX_DPI:
        raise ValueError(f"dpi {dpi!r}: allowed: 0 < dpi <= {MAX_DPI} (dots per inch)")
    path = Path(path)
    if kind == "animation":
        from .animation import animate

        if not path.suffix:  # the animation's own default format, as without -o
            path = path.with_name(f"{path.name}.gif")
        return animate(result, path, dpi=dpi, **options)
    if not path.suffix:  # what matplotlib would do, named here so that the caller knows the file
        path = path.with_name(f"{path.name}.{rcParams['savefig.format']}")
    check(path, IMAGE)
    fig = figure(result, kind, **options)
    with rc_context({"agg.path.chunksize": 20000}):
        return save_figure(fig, path, dpi)

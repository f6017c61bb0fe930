"""Plots of the impact dynamics: the engine's shock log and statistics, spectra, Poincaré sections.

Each ``plot_*`` function draws on a given Axes (or a new figure's) and returns it; one whose
data is absent raises ValueError saying what is missing. What is drawn comes from the engine
(/impacts, /statistics, the records); the only computing here is for display
(:mod:`beamstops.transforms`: histograms of the logged shocks, Welch spectra, stroboscopic
sampling of the records).

- :func:`plot_impulses`, :func:`plot_impact_velocities`: histograms over the logged shocks,
  one per stop (per side when the log has a single stop);
- :func:`plot_pdf`: probability density of the tip displacement, the engine's histogram with
  its 95 % intervals, else a display histogram of the records;
- :func:`plot_psd`: power spectral density (Welch) of the tip displacement or the reaction;
- :func:`plot_poincare`: the stroboscopic section (u(L, kT), v(L, kT)), T = 2π/ω.
"""

from __future__ import annotations

import math
from typing import Optional

import numpy as np
from matplotlib.axes import Axes
from matplotlib.ticker import MaxNLocator

from .plotbase import STOP, need_impacts, need_records, new_axes, stop_label, tip_stops
from .result import Result
from .transforms import after, sampling_rate, stroboscopic, welch

__all__ = ["plot_impulses", "plot_impact_velocities", "plot_pdf", "plot_psd", "plot_poincare", "engine_pdf",
           "poincare_period", "PSD_QUANTITIES", "MIN_SPECTRUM_RECORDS"]

#: Series :func:`plot_psd` draws: Result attribute → (axis label, unit of the PSD).
PSD_QUANTITIES: dict[str, tuple[str, str]] = {
    "tip_u": ("tip displacement u(L, t)", "m²/Hz"),
    "reaction": ("contact reaction at the tip", "N²/Hz"),
}
#: Fewest records after the transient for a spectrum.
MIN_SPECTRUM_RECORDS = 32


def _groups(result: Result, keep: np.ndarray) -> list[tuple[str, np.ndarray]]:
    """The shocks (a mask) split per stop, or per side when the log holds a single stop."""
    stop = result.impacts["stop"]
    stops = np.unique(stop[keep]).astype(int)
    if stops.size <= 1:
        side = result.impacts["side"]
        label = stop_label(result, int(stops[0])) + ", " if stops.size and result.stops_x.size else ""
        return [(f"{label}{name} stop", keep & (side == s)) for s, name in ((1.0, "lower"), (-1.0, "upper"))]
    return [(stop_label(result, int(k)), keep & (stop == k)) for k in stops]


def _histograms(ax: Axes, result: Result, values: np.ndarray, keep: np.ndarray, xlabel: str) -> None:
    keep = keep & np.isfinite(values)
    if not keep.any():
        ax.text(0.5, 0.5, "no finite values", ha="center", va="center", transform=ax.transAxes)
        return
    edges = np.histogram_bin_edges(values[keep], bins="auto")
    if edges.size > 61:
        edges = np.histogram_bin_edges(values[keep], bins=60)
    for label, mask in _groups(result, keep):
        if mask.any():
            ax.hist(values[mask], bins=edges.tolist(), histtype="step", linewidth=1.0, label=f"{label} ({mask.sum()})")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("shocks")
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))  # counts: no tick at 0.25 of a shock
    ax.legend(fontsize="small", loc="best")
    ax.grid(True, linewidth=0.3, alpha=0.5)


def plot_impulses(result: Result, ax: Optional[Axes] = None) -> Axes:
    """Histogram of |impulse| of the logged shocks (truncated shocks, whose impulse is partial, left out)."""
    need_impacts(result)
    ax = new_axes(ax)
    truncated = result.impacts.get("truncated", np.zeros(result.shocks)) != 0
    _histograms(ax, result, np.abs(result.impacts["impulse"]), ~truncated, "|impulse| per shock (N s)")
    left_out = f", {truncated.sum()} truncated left out" if truncated.any() else ""
    ax.set_title(f"impulse: {result.shocks} shocks{left_out}", fontsize="medium")
    return ax


def plot_impact_velocities(result: Result, ax: Optional[Axes] = None) -> Axes:
    """Histogram of the impact velocity |velocity_in| of the logged shocks."""
    need_impacts(result)
    ax = new_axes(ax)
    _histograms(ax, result, np.abs(result.impacts["velocity_in"]), np.ones(result.shocks, dtype=bool),
                "impact velocity |v_in| (m/s)")
    ax.set_title(f"impact velocity: {result.shocks} shocks", fontsize="medium")
    return ax


def engine_pdf(result: Result, transient: Optional[float] = None) -> bool:
    """Whether :func:`plot_pdf` draws the engine's histogram: it is there, and ``transient`` is
    None or the engine's own."""
    stats = result.statistics
    if "tip_histogram" not in stats or "tip_histogram_edges" not in stats:
        return False
    if transient is None:
        return True
    return math.isclose(transient, float(result.statistics_attrs.get("transient", 0.0)), rel_tol=1e-9,
                        abs_tol=1e-12)


def plot_pdf(result: Result, ax: Optional[Axes] = None, *, transient: Optional[float] = None) -> Axes:
    """Probability density of the tip displacement, with the stops.

    From the engine's ``tip_histogram`` (fractions of samples per bin over its window, bars: its
    95 % half-widths over batches) when the file has it and ``transient`` is None or the engine's;
    otherwise a display histogram of the records /tip/u with t ≥ transient.
    """
    ax = new_axes(ax)
    if engine_pdf(result, transient):
        edges = result.statistics["tip_histogram_edges"].value
        histogram = result.statistics["tip_histogram"]
        width = np.diff(edges)
        density = histogram.value / width
        error = np.where(np.isfinite(histogram.half_width), histogram.half_width, 0.0) / width
        ax.stairs(density, edges, color="k", linewidth=0.8, label="engine's histogram")
        ax.errorbar(0.5 * (edges[:-1] + edges[1:]), density, yerr=error, fmt="none", ecolor="tab:blue",
                    elinewidth=0.8, capsize=1.5, label="95 % interval over batches")
        a = result.statistics_attrs
        window = f"t ≥ {a.get('transient', 0.0):.4g} s"
        source = f"engine, {window}, {a.get('batches', '?')} batches"
    else:
        need_records(result)
        keep = after(result.t, transient)
        u = result.tip_u[keep]
        if u.size == 0:
            raise ValueError(f"no records after the transient: t ≥ {transient} s, the records end at "
                             f"t = {result.t[-1]:.4g} s")
        bins = int(min(100, max(10, math.sqrt(u.size))))
        density, edges = np.histogram(u, bins=bins, density=True)
        ax.stairs(density, edges, color="k", linewidth=0.8, label="histogram of the records")
        source = f"records /tip/u, t ≥ {transient or 0.0:.4g} s, {u.size} samples"
    for g in tip_stops(result):
        if g is not None:
            ax.axvline(g, **STOP)
    ax.set_xlabel("u(L) (m)")
    ax.set_ylabel("probability density (1/m)")
    ax.set_title(f"tip displacement PDF ({source})", fontsize="medium")
    ax.legend(fontsize="small", loc="best")
    ax.grid(True, linewidth=0.3, alpha=0.5)
    return ax


def plot_psd(result: Result, ax: Optional[Axes] = None, *, quantity: str = "tip_u",
             transient: Optional[float] = None, segment: Optional[int] = None) -> Axes:
    """Power spectral density of a recorded series (``quantity`` in :data:`PSD_QUANTITIES`) by Welch's
    method, on log axes, with the forcing frequency ω/2π marked."""
    if quantity not in PSD_QUANTITIES:
        raise ValueError(f"no spectrum of {quantity!r}; allowed: {', '.join(PSD_QUANTITIES)}")
    need_records(result)
    ax = new_axes(ax)
    keep = after(result.t, transient)
    t, x = result.t[keep], np.asarray(getattr(result, quantity))[keep]
    if t.size < MIN_SPECTRUM_RECORDS:
        raise ValueError(f"too few records for a spectrum: {t.size} after t = {transient or 0.0:g} s "
                         f"(at least {MIN_SPECTRUM_RECORDS})")
    frequency, psd = welch(x, sampling_rate(t), segment)
    name, unit = PSD_QUANTITIES[quantity]
    shown = (frequency > 0) & (psd > 0)
    if shown.any():
        ax.loglog(frequency[shown], psd[shown], color="k", linewidth=0.7, label=name)
    else:
        ax.text(0.5, 0.5, f"{name} is constant: no spectrum to draw", ha="center", va="center",
                transform=ax.transAxes)
    omega = float(result.attrs.get("omega", 0.0))
    if omega > 0 and shown.any():
        ax.axvline(omega / (2 * math.pi), color="tab:blue", linewidth=0.8, linestyle=":",
                   label=f"forcing ω/2π = {omega / (2 * math.pi):.3g} Hz")
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel(f"PSD ({unit})")
    ax.set_title(f"{name}", fontsize="medium")
    ax.text(0.01, 0.01, f"Welch, Δf = {frequency[1]:.3g} Hz, t ≥ {transient or 0.0:.4g} s", transform=ax.transAxes,
            fontsize="x-small", va="bottom")
    if shown.any():
        ax.legend(fontsize="small", loc="best")
    ax.grid(True, which="both", linewidth=0.3, alpha=0.5)
    return ax


def poincare_period(result: Result) -> float:
    """T = 2π/ω of the run (ValueError without forcing)."""
    omega = float(result.attrs.get("omega", 0.0))
    if not omega > 0:
        raise ValueError(f"no forcing period: omega = {omega:g} (the support does not vibrate), no Poincaré section")
    return 2 * math.pi / omega


def plot_poincare(result: Result, ax: Optional[Axes] = None, *, transient: Optional[float] = None) -> Axes:
    """Stroboscopic (Poincaré) section of the tip: (u(L, kT), v(L, kT)), T = 2π/ω, kT ≥ transient;
    each point is the record nearest kT, coloured by k."""
    need_records(result)
    period = poincare_period(result)
    k, index, offset = stroboscopic(result.t, period, transient)
    if k.size == 0:
        raise ValueError(f"no stroboscopic sample: no kT (T = {period:.4g} s) from t = {transient or 0.0:g} s to "
                         f"the last record at t = {result.t[-1]:.4g} s")
    ax = new_axes(ax)
    points = ax.scatter(result.tip_u[index], result.tip_v[index], c=k, s=8, cmap="viridis", linewidths=0)
    ax.figure.colorbar(points, ax=ax, label="period k")
    for g in tip_stops(result):
        if g is not None:
            ax.axvline(g, **STOP)
    ax.set_xlabel("u(L, kT) (m)")
    ax.set_ylabel("v(L, kT) (m/s)")
    ax.set_title(f"Poincaré section at t = kT, T = 2π/ω = {period:.4g} s", fontsize="medium")
    ax.text(0.01, 0.01, f"k = {k[0]} … {k[-1]} ({k.size} points), records within {offset:.2g} s of kT",
            transform=ax.transAxes, fontsize="x-small", va="bottom")
    ax.grid(True, linewidth=0.3, alpha=0.5)
    return ax

"""The chart of the contact-laws study (:mod:`beamstops.studies.contact_laws`): energy and its
ledger over time, violation and contact phases against Δt, tip errors against Δt."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..output_files import save_figure
from ..result import Result
from .common import Table

if TYPE_CHECKING:
    from .contact_laws import Plan

__all__ = ["draw"]


def _column(table: Table, label: str, name: str) -> tuple[np.ndarray, np.ndarray]:
    rows = [r for r in table.rows if r[0] == label]
    i = table.columns.index(name)
    return np.array([float(r[1]) for r in rows]), np.array([float(r[i]) for r in rows])  # type: ignore[arg-type]


def draw(runs: dict[str, Result], convergence: Table, plan: "Plan", path: Path) -> Path:
    """Six panels: E(t); the ledger (work, stops, damping); max violation, contact phases and the
    tip errors on both windows against Δt."""
    from matplotlib.figure import Figure

    from .contact_laws import TARGET, WINDOWS

    fig = Figure(figsize=(15, 8.5), layout="constrained")
    ax = fig.subplots(2, 3).ravel()
    colours = {label: f"C{i}" if i < 5 else "0.45" for i, label in enumerate(runs)}
    for label, r in runs.items():
        c = colours[label]
        ax[0].plot(r.t, r.energy, color=c, linewidth=0.7, label=label)
        ax[1].plot(r.t, r.work, color=c, linewidth=0.8, linestyle="--")
        ax[1].plot(r.t, r.dissipated, color=c, linewidth=1.0, label=label)
        if r.damped.size and np.any(r.damped != 0):
            ax[1].plot(r.t, r.damped, color=c, linewidth=1.0, linestyle=":")
    ax[0].set_title(f"energy E(t), Δt = {plan.energy_dt:g} s")
    ax[0].set_ylabel("E (J)")
    ax[1].set_title("ledger: support work (dashed), stops (solid), damping (dotted)")
    ax[1].set_ylabel("J since t = 0")
    for a in ax[:2]:
        a.set_xlabel("t (s)")
    labels = list(dict.fromkeys(str(r[0]) for r in convergence.rows))
    t_end = max(w[1] for w in WINDOWS)
    for label in labels:
        c = colours.get(label, "k")
        dt, violation = _column(convergence, label, "max violation (m)")
        ax[2].loglog(dt, np.maximum(violation, 1e-16), "o-", color=c, markersize=3, label=label)
        dt, phases = _column(convergence, label, f"contact phases t≤{t_end:g}")
        ax[3].semilogx(dt, phases, "o-", color=c, markersize=3, label=label)
        for k, (start, end) in enumerate(WINDOWS):
            dt, err = _column(convergence, label, f"max err [{start:g},{end:g}] (m)")
            ax[4 + k].loglog(dt, err, "o-", color=c, markersize=3, label=label)
    ax[2].set_title("largest violation of the stops (0 drawn at 1e-16)")
    ax[2].set_ylabel("max violation (m)")
    ax[3].set_title(f"chatter: contact phases for t ≤ {t_end:g} s (engine's contact_phases)")
    ax[3].set_ylabel("contact phases")
    for k, (start, end) in enumerate(WINDOWS):
        a = ax[4 + k]
        a.set_title(f"tip error on [{start:g}, {end:g}] s against Δt = {plan.dt_ref:g} s")
        a.set_ylabel("max |u − u_ref| (m)")
        dts = np.array(plan.dts)
        lo, hi = a.get_ylim()
        anchor = np.sqrt(lo * hi)
        a.loglog(dts, anchor * (dts / dts[0]) ** TARGET, "k:", linewidth=0.8, label=f"slope {TARGET:g}")
        a.axvspan(min(plan.span), max(plan.span), color="0.9", zorder=0)
    for a in ax[2:]:
        a.set_xlabel("Δt (s)")
    for k, a in enumerate(ax):
        a.grid(True, which="both", alpha=0.3)
        a.legend(fontsize=7, loc="upper left" if k < 2 else "best")
    return save_figure(fig, path, dpi=110)

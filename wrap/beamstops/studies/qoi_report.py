"""Tables and chart panels of the statistical studies: runs of one QoI against a reference's
interval, and the cost to reach a requested half-width (shared by ``converge --qoi`` and
``work-precision --qoi``). Every number in them is an engine statistic or CPU time, or the
comparisons and projections of :mod:`beamstops.studies.qoi`."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, Optional

from .common import Table
from .qoi import Estimate, HalfWidth, Measured, cost_for, statistic_name, window_for

__all__ = ["row_columns", "rows", "table", "yes_no", "errorbar_panel", "unit_of"]


def yes_no(flag: bool) -> str:
    return "yes" if flag else "no"


def unit_of(runs: Sequence[Measured], qoi: str) -> str:
    """The unit of a QoI as the engine gives it (blank for dimensionless)."""
    for m in runs:
        unit = m.estimate(qoi).unit
        if unit:
            return "" if unit == "1" else unit
    return ""


def row_columns(first: Sequence[str], unit: str) -> list[str]:
    """Columns of a table of runs against a reference (after the table's own ``first`` columns)."""
    u = f" ({unit})" if unit else ""
    return list(first) + ["window (s)", "CPU (s)", f"value{u}", f"half-width{u}", f"abs(v − v_ref){u}",
                          f"h + h_ref{u}", "within the reference's interval", f"h*{u}", "T* (s)", "cost* (s)"]


def _row(first: Sequence[Any], m: Measured, est: Estimate, ref: Estimate, target: float, cpu: float,
         is_reference: bool) -> list[Any]:
    t_star = window_for(est.half_width, m.window, target)
    scale = cpu / m.cpu_seconds if m.cpu_seconds > 0 else math.nan
    return list(first) + [m.window, cpu, est.value, est.half_width,
                          math.nan if is_reference else abs(est.value - ref.value),
                          math.nan if is_reference else est.half_width + ref.half_width,
                          "reference" if is_reference else yes_no(est.agrees(ref)),
                          target, t_star, cost_for(m, t_star) * scale]


def rows(labelled: Sequence[tuple[Sequence[Any], Measured]], reference: tuple[Sequence[Any], Measured], qoi: str,
         half_width: HalfWidth) -> list[list[Any]]:
    """One row per run, then the reference's row, then (members > 1) the reference's ensemble row.

    The ensemble row's CPU is members × the engine's cpu_seconds of member 1 (the engine times
    member 1's loop; members 2..K run after it, in lockstep when they can share one loop, each
    then cheaper than member 1 alone: the row's CPU is an upper bound of the ensemble's); its T* uses
    the members' half-width with the window, i.e. more members or a longer window alike.
    """
    ref_first, ref_run = reference
    ref = ref_run.estimate(qoi)
    target = half_width.target(ref)
    out = [_row(first, m, m.estimate(qoi), ref, target, m.cpu_seconds, False) for first, m in labelled]
    out.append(_row(ref_first, ref_run, ref, ref, target, ref_run.cpu_seconds, True))
    across = ref_run.across_members(qoi)
    if across is not None:
        first = list(ref_first)
        first[0] = f"{first[0]} (across {ref_run.members} members)"
        row = _row(first, ref_run, across, ref, target, ref_run.members * ref_run.cpu_seconds, False)
        row[len(first) + 6] = f"{yes_no(across.agrees(ref))} (ensemble)"
        out.append(row)
    return out


def table(title: str, first: Sequence[str], labelled: Sequence[tuple[Sequence[Any], Measured]],
          reference: tuple[Sequence[Any], Measured], qoi: str, half_width: HalfWidth, note: str = "") -> Table:
    unit = unit_of([m for _, m in labelled] + [reference[1]], qoi)
    return Table(title, row_columns(first, unit), rows(labelled, reference, qoi, half_width), note)


def errorbar_panel(ax: Any, x: Sequence[float], runs: Sequence[Measured], reference: Measured, qoi: str, *,
                   reference_x: Optional[float] = None, xlabel: str, title: str, log_x: bool = True) -> None:
    """Value ± half-width of each run against x, the reference's interval as a band (and its
    ensemble's interval as a second bar when it has members)."""
    ref = reference.estimate(qoi)
    unit = unit_of(list(runs) + [reference], qoi)
    if math.isfinite(ref.value):
        ax.axhspan(ref.value - ref.half_width, ref.value + ref.half_width, color="tab:orange", alpha=0.25,
                   label=f"reference {ref.value:.4g} ± {ref.half_width:.2g}")
        ax.axhline(ref.value, color="tab:orange", lw=1)
    values = [m.estimate(qoi) for m in runs]
    agree = [v.agrees(ref) for v in values]
    for flag, colour, label in ((True, "tab:blue", "within the reference's interval"),
                                (False, "tab:red", "outside it")):
        pick = [i for i, a in enumerate(agree) if a == flag]
        if pick:
            ax.errorbar([x[i] for i in pick], [values[i].value for i in pick],
                        yerr=[values[i].half_width if math.isfinite(values[i].half_width) else 0 for i in pick],
                        fmt="o", color=colour, capsize=3, label=label)
    if reference_x is not None:
        ax.errorbar([reference_x], [ref.value], yerr=[ref.half_width if math.isfinite(ref.half_width) else 0],
                    fmt="s", color="tab:orange", capsize=3, label="reference (batch means)")
        across = reference.across_members(qoi)
        if across is not None and math.isfinite(across.value):
            ax.errorbar([reference_x * (0.85 if log_x else 1)], [across.value],
                        yerr=[across.half_width if math.isfinite(across.half_width) else 0], fmt="D",
                        color="tab:green", capsize=3, label=f"reference across {reference.members} members")
    if log_x:
        ax.set_xscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(f"{statistic_name(qoi)}" + (f" ({unit})" if unit else ""))
    ax.set_title(title, fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)

"""Work-precision: error against the engine's CPU time, one curve per method.

Methods: the Signorini scheme with β = 0, 1/4, 1/2 (centred load rule), the same with the
paper's load rule, and normal compliance (β = 1/4) with 1/ε from 1e6 to 1e10 per unit mass.
Each is run at a sequence of Δt; its error is the max (and L²) of the tip displacement
against one fine reference run of the Signorini scheme (β = 1/2, centred) over windows
[0, w]: by default before the first impact (w = 0.08 s; the first impact is at 0.0878 s) and
the first contact period (w = 0.2 s, where the paper sees runs agree by eye); the cost
is the engine's ``cpu_seconds`` (the time loop's CPU time). Read the chart horizontally:
at a given error, the leftmost curve is the fastest method.

With ``--qoi NAME ...`` (statistics of the engine: stop_power, impulse_rate, shock_rate,
contact_fraction, tip_rms, ...) the chart is the statistical one of
:mod:`beamstops.studies.qoi_workprecision` (CPU against the 95 % half-width after a transient, one
curve per contact law, the cost to reach ``--half-width``); ``--qoi tip`` (the default) is the
pointwise study above, and both can be asked for at once.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import numpy as np

from ..scene import Scene
from ..arguments import number, whole
from .cli import StudyCommand
from ..output_files import save_figure
from .common import Table, progress, run_tip, tip_error
from .outputs import StudyFolder

__all__ = ["Method", "methods", "study", "draw", "qoi_options", "split_qois", "main", "register"]


@dataclass(frozen=True)
class Method:
    """A method: its label, the scene changes that select it and its time steps."""

    label: str
    changes: dict[str, object]
    dts: tuple[float, ...]


#: The record grid of the runs of :func:`study` (s).
GRID = 4e-5


def methods(quick: bool = False) -> list[Method]:
    """The methods of the chart, each with Δt = grid/2^k (β = 0 below its stability limit)."""
    k = 3 if quick else 7
    coarse = tuple(GRID / 2**i for i in range(k))
    explicit = tuple(1e-5 / 2**i for i in range(k - 2 if not quick else 2))
    out = [Method("Signorini β=0", {"beta": 0.0}, explicit),
           Method("Signorini β=1/4", {"beta": 0.25}, coarse),
           Method("Signorini β=1/2", {"beta": 0.5}, coarse),
           Method("Signorini β=1/4, paper's load", {"beta": 0.25, "load_rule": "paper"}, coarse),
           Method("Signorini β=1/2, paper's load", {"beta": 0.5, "load_rule": "paper"}, coarse)]
    for stiffness in ((1e6, 1e8, 1e10) if quick else (1e6, 1e7, 1e8, 1e9, 1e10)):
        out.append(Method(f"compliance 1/ε={stiffness:.0e}", {"beta": 0.25, "law": "compliance",
                                                             "stiffness_per_mass": stiffness}, coarse))
    return out


#: The files the study writes into its folder.
FILES = ("work_precision.md", "work_precision.csv", "work_precision.png")


def study(folder: Optional[Path] = None, *, quick: bool = False, windows: Sequence[float] = (0.08, 0.2),
          quiet: bool = False) -> Table:
    """Run every method at every Δt, write work_precision.{md,csv,png}; return the table.

    Errors on each window [0, w]; the default windows are before the first impact (t < 0.0878 s)
    and the first contact period (t ≤ 0.2 s).
    """
    out = StudyFolder.prepare(folder, "work_precision", FILES)
    grid = GRID
    if quick:
        windows = tuple(min(w, 0.05) for w in windows[:1])
    base = Scene(t_end=max(windows))
    finest = min(min(m.dts) for m in methods(quick))
    ref = run_tip(base.replace(beta=0.5, dt=finest / 8), grid)
    runs = [(m, dt) for m in methods(quick) for dt in m.dts]
    rows: list[list[object]] = []
    for m, dt in progress(runs, "work-precision", quiet=quiet):
        result = run_tip(base.replace(dt=dt, **m.changes), grid)  # type: ignore[arg-type]
        row: list[object] = [m.label, dt, result.attrs["cpu_seconds"]]
        for w in windows:
            e = tip_error(result, ref, w)
            row += [e.max, e.l2]
        rows.append(row + [result.attrs["max_violation"], result.status])
    columns = ["method", "Δt (s)", "CPU (s)"]
    for w in windows:
        columns += [f"max err [0,{w:g}] (m)", f"L2 err [0,{w:g}] (m s^1/2)"]
    table = Table("Work-precision", columns + ["max violation (m)", "status"], rows)
    table.note = (f"paper's scene (J = {base.elements}), T = {base.t_end:g} s; reference: Signorini β = 1/2, centred "
                  f"load, Δt = {finest / 8:g} s; CPU: the engine's time-loop CPU time of each run.")
    table.write(out, "work_precision")
    draw(table, out.path("work_precision.png"), windows)
    return table


def draw(table: Table, path: Path, windows: Sequence[float]) -> Path:
    """Error against CPU time, log-log, one curve per method, one panel per window."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7 * len(windows), 5.5), layout="constrained")
    labels = list(dict.fromkeys(table.column("method")))
    styles = ["o-", "s-", "^-", "v--", "D--", "x:", "+:", "*:", "p:", "h:"]
    for k, w in enumerate(windows):
        ax = fig.add_subplot(1, len(windows), k + 1)
        column = table.columns.index(f"max err [0,{w:g}] (m)")
        for i, label in enumerate(labels):
            rows = [r for r in table.rows if r[0] == label]
            cpu = np.array([max(float(r[2]), 1e-6) for r in rows])  # type: ignore[arg-type]
            err = np.array([float(r[column]) for r in rows])  # type: ignore[arg-type]
            keep = np.isfinite(err) & (err > 0)
            ax.loglog(cpu[keep], err[keep], styles[i % len(styles)], label=label, markersize=4)
        ax.set_xlabel("engine CPU time of the run (s)")
        ax.set_ylabel("max |u(L,t) − u_ref(L,t)| (m)")
        ax.set_title(f"tip error on [0, {w:g}] s — lower left is better", fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, ncol=2)
    return save_figure(fig, path, dpi=120)


def qoi_options(parser: argparse.ArgumentParser) -> None:
    """``--qoi`` and the statistical runs' options (shared with ``converge``)."""
    from .qoi import POINTWISE, QOIS, HalfWidth, statistic_name

    def name(text: str) -> str:
        if text != POINTWISE:
            try:
                statistic_name(text)
            except ValueError as exc:
                raise argparse.ArgumentTypeError(str(exc)) from None
        return text

    def half_width(text: str) -> str:
        try:
            HalfWidth.parse(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
        return text

    parser.add_argument("--qoi", nargs="+", type=name, default=[POINTWISE], metavar="NAME",
                        help=f"quantities of interest: {POINTWISE!r} (default: the tip against a reference over "
                             f"[0, W], today's study) or statistics of the engine after a transient: "
                             f"{', '.join(QOIS)} (or an engine statistic's own name)")
    parser.add_argument("--half-width", type=half_width, default="2%", metavar="H",
                        help="requested 95 %% half-width h* of each QoI: a percentage of the reference's value "
                             "(default 2%%) or a number in the QoI's unit")
    parser.add_argument("--transient", type=number("a time in s", strict=False),
                        help="start of the statistics' window (s; default 2, quick 0.5)")
    parser.add_argument("--stat-window", type=number("a time in s"), metavar="T",
                        help="window of the statistics after the transient (s; default 20, quick 2)")
    parser.add_argument("--reference-window", type=number("a time in s"), metavar="T",
                        help="window of the references (s; default 40, quick 4)")
    parser.add_argument("--members", type=whole("members"),
                        help="members of the reference's ensemble (default 4, quick 3)")


def split_qois(names: Sequence[str]) -> tuple[bool, list[str]]:
    """(whether the pointwise study runs, the statistical QoIs), names checked."""
    from .qoi import POINTWISE, statistic_name

    statistical = [n for n in dict.fromkeys(names) if n != POINTWISE]
    for name in statistical:
        statistic_name(name)
    return POINTWISE in names, statistical


def _options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--window", type=number("a time in s"), nargs="+", metavar="W",
                        help="compare on [0, W] s for each W (default 0.08 0.2: before the first impact, "
                             "the first contact period; --quick: one W <= 0.05, default 0.05)")
    qoi_options(parser)


#: The windows of ``--window`` when it is not given.
WINDOWS = (0.08, 0.2)


def _check(args: argparse.Namespace) -> Optional[str]:
    from .options import check_statistical, check_windows

    return check_windows(args) or check_statistical("work-precision", args)


def _run(folder: Path, args: argparse.Namespace) -> Path:
    from . import qoi_workprecision
    from .qoi import HalfWidth

    pointwise, statistical = split_qois(args.qoi)
    printed = folder / "work_precision.png"
    if statistical:  # every file of both checked before either runs
        qoi_workprecision.outputs(folder, statistical)
    if pointwise:
        StudyFolder.prepare(folder, "work_precision", FILES)
    if statistical:
        qoi_workprecision.study(folder, qois=statistical, quick=args.quick, half_width=HalfWidth.parse(args.half_width),
                                transient=args.transient, window=args.stat_window,
                                reference_window=args.reference_window, members=args.members, quiet=args.quiet)
        printed = folder / "work_precision_statistics.md"
    if pointwise:
        study(folder, quick=args.quick, windows=tuple(args.window or WINDOWS), quiet=args.quiet)
        printed = folder / "work_precision.png"
    return printed


#: ``work-precision [-o DIR] [--quick] [--window T] [--qoi NAME ...] [--half-width H]``; ``main`` is scripts/study_workprecision.py.
COMMAND = StudyCommand("work_precision", _options, _run, name="work-precision",
                       help="error against CPU time for every method (PNG, md, CSV)",
                       description="Work-precision chart: tip error against the engine's CPU time.",
                       prog="study_workprecision", script_description=__doc__.splitlines()[0], check=_check)
register = COMMAND.register
main = COMMAND.main

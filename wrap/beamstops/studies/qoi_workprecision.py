"""Work-precision under impacts (``work-precision --qoi NAME ...``): for each contact law (Signorini
e = 0 and e = 1, mass redistribution, normal compliance), runs at a ladder of Δt after a transient,
each QoI's value ± batch-means half-width against a fine reference of the same law, the engine's
CPU time, and the window and CPU time each run would need to reach a requested half-width h*.

Files (per QoI): ``work_precision_<qoi>.{md,csv,png}`` (CPU against the half-width and against
|v − v_ref| + h, the projected cost* against Δt), ``work_precision_<qoi>_dt.png`` (value ± h against
Δt per law with the reference's band); ``statistics_runs.csv`` (every run, every scalar statistic)
and ``work_precision_statistics.md`` (settings, headline per QoI and law, the tables).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import numpy as np

from ..scene import Scene
from ..output_files import save_figure
from .common import Table, csv_text, progress
from .outputs import StudyFolder
from .qoi import HalfWidth, Law, Measured, laws, measure, statistic_name
from .qoi_report import errorbar_panel, table

__all__ = ["Settings", "LawRuns", "settings", "run_laws", "headline", "study"]


@dataclass(frozen=True)
class Settings:
    """Windows and ensemble of the statistical runs."""

    transient: float
    window: float
    reference_window: float
    batches: int = 20
    members: int = 4
    """Members of the first law's reference run (its ensemble interval beside its batch interval)."""
    perturbation: float = 1e-6

    def describe(self) -> str:
        return (f"transient {self.transient:g} s, window {self.window:g} s (references: {self.reference_window:g} s), "
                f"{self.batches} batch means; one reference also across {self.members} members "
                f"(initial displacements perturbed by {self.perturbation:g} m)")


def settings(quick: bool, transient: Optional[float] = None, window: Optional[float] = None,
             reference_window: Optional[float] = None, members: Optional[int] = None) -> tuple[Settings, list[Law]]:
    """The study's windows and laws: full (≈ a few minutes on 2 cores) or ``quick`` (seconds)."""
    if quick:
        s = Settings(0.5, 2.0, 4.0, batches=10, members=3)
        chosen = laws((4e-5, 2e-5), 1e-5)
    else:
        s = Settings(2.0, 20.0, 40.0)
        chosen = laws(tuple(4e-5 / 2**k for k in range(5)), 1.25e-6, redistributed_finest=1e-5,
                      redistributed_window=20.0)
    s = Settings(transient if transient is not None else s.transient, window if window is not None else s.window,
                 reference_window if reference_window is not None else s.reference_window, s.batches,
                 members if members is not None else s.members, s.perturbation)
    return s, chosen


@dataclass(frozen=True)
class LawRuns:
    """A law's runs along its Δt ladder and its reference."""

    law: Law
    runs: list[Measured]
    reference: Measured


def run_laws(base: Scene, chosen: Sequence[Law], s: Settings, quiet: bool = False) -> list[LawRuns]:
    """Every law at every Δt of its ladder, and its reference (the first law's with members)."""
    todo = [(i, dt) for i, law in enumerate(chosen) for dt in law.dts] + [(i, None) for i in range(len(chosen))]
    runs: dict[int, list[Measured]] = {i: [] for i in range(len(chosen))}
    refs: dict[int, Measured] = {}
    for i, dt in progress(todo, "work-precision (statistics)", quiet=quiet):
        law = chosen[i]
        scene = base.replace(dt=dt if dt is not None else law.dt_reference, **law.changes)  # type: ignore[arg-type]
        if dt is not None:
            runs[i].append(measure(scene, s.transient, s.window, batches=s.batches))
        else:
            window = law.reference_window if law.reference_window is not None else s.reference_window
            refs[i] = measure(scene, s.transient, window, batches=s.batches, members=s.members if i == 0 else 1,
                              perturbation=s.perturbation)
    return [LawRuns(law, runs[i], refs[i]) for i, law in enumerate(chosen)]


def qoi_table(results: Sequence[LawRuns], qoi: str, half_width: HalfWidth) -> Table:
    """Every law's runs and reference for one QoI."""
    all_rows: list[list[object]] = []
    tables = [table("", ["law", "Δt (s)"], [([r.law.label, m.scene.dt], m) for m in r.runs],
                    ([r.law.label, r.reference.scene.dt], r.reference), qoi, half_width) for r in results]
    for t in tables:
        all_rows += t.rows
    return Table(f"Work-precision of {qoi} ({statistic_name(qoi)}), h* = {half_width}", tables[0].columns, all_rows)


def _cell(x: float, digits: int = 3) -> str:
    return f"{x:.{digits}g}" if math.isfinite(x) else "–"


def headline(results: Sequence[LawRuns], qoi: str, half_width: HalfWidth, checked: Optional[Measured] = None) -> str:
    """Per law: the reference (and its ensemble), and the cheapest run that agrees with the reference
    together with the window and CPU time it would need for h*."""
    t = qoi_table(results, qoi, half_width)
    col = {name: i for i, name in enumerate(t.columns)}
    value, half = t.columns[4], t.columns[5]
    target = next(i for i, name in enumerate(t.columns) if name.startswith("h*"))
    lines = [f"### {qoi} ({statistic_name(qoi)}): h* = {half_width}", ""]
    for r in results:
        ref = r.reference.estimate(qoi)
        text = (f"- **{r.law.label}**: reference (Δt = {r.reference.scene.dt:g} s, {r.reference.window:g} s) "
                f"{ref}")
        across = r.reference.across_members(qoi)
        if across is not None:
            text += f"; across {r.reference.members} members {across}"
        mine = [row for row in t.rows if row[0] == r.law.label and row[col["within the reference's interval"]] == "yes"]
        costs = [(float(row[col["cost* (s)"]]), row) for row in mine if math.isfinite(float(row[col["cost* (s)"]]))]
        if costs:
            cost, row = min(costs, key=lambda c: c[0])
            text += (f". Cheapest run within the reference's interval: Δt = {float(row[1]):g} s "
                     f"({_cell(float(row[col[value]]), 4)} ± {_cell(float(row[col[half]]), 2)} in "
                     f"{float(row[2]):g} s, CPU {_cell(float(row[3]))} s); for h* = "
                     f"{_cell(float(row[target]), 2)} it needs T* ≈ {_cell(float(row[col['T* (s)']]))} s, "
                     f"cost* ≈ {_cell(cost)} s CPU")
        elif not math.isfinite(half_width.target(ref)):
            text += ". No relative half-width: the reference's interval contains 0"
        else:
            text += ". No run within the reference's interval"
        if r.law.note and statistic_name(qoi) in ("shocks_per_second", "contact_fraction", "rebounds_per_shock",
                                                  "shock_duration_mean"):
            text += f" (note: {r.law.note})"
        if checked is not None and r is results[0]:
            est = checked.estimate(qoi)
            text += (f". Check of the projection: a run of {checked.window:g} s at Δt = {checked.scene.dt:g} s gave "
                     f"{est} (h/h* = {est.half_width / half_width.target(ref):.2f}, CPU {checked.cpu_seconds:.3g} s), "
                     f"{'within' if est.agrees(ref) else 'outside'} the reference's interval")
        lines.append(text + ".")
    return "\n".join(lines) + "\n"


def check(result: LawRuns, qoi: str, half_width: HalfWidth, s: Settings, cpu_cap: float) -> Optional[Measured]:
    """Test the projection: run the law's cheapest run within the reference's interval again with
    the window T* it was projected to need for h* (None when none qualifies or cost* > ``cpu_cap``)."""
    t = qoi_table([result], qoi, half_width)
    col = {name: i for i, name in enumerate(t.columns)}
    picks = [(float(row[col["cost* (s)"]]), float(row[col["T* (s)"]]), m)
             for row, m in zip(t.rows, result.runs) if row[col["within the reference's interval"]] == "yes"]
    picks = [p for p in picks if math.isfinite(p[0]) and p[0] <= cpu_cap]
    if not picks:
        return None
    _, t_star, m = min(picks, key=lambda p: p[0])
    return measure(m.scene, s.transient, float(math.ceil(t_star)), batches=s.batches)


def draw_work_precision(results: Sequence[LawRuns], qoi: str, half_width: HalfWidth, path: Path) -> Path:
    """CPU time against the half-width and against |v − v_ref| + h, and cost* against Δt; one curve per law."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(18, 5.5), layout="constrained")
    axes = [fig.add_subplot(1, 3, k + 1) for k in range(3)]
    styles = ["o-", "s-", "^-", "D-", "v-", "x-"]
    first_bad = {ax: next((i for i, r in enumerate(results)
                           if any(not m.estimate(qoi).agrees(r.reference.estimate(qoi)) for m in r.runs)), -1)
                 for ax in axes}
    for i, r in enumerate(results):
        ref = r.reference.estimate(qoi)
        est = [m.estimate(qoi) for m in r.runs]
        cpu = np.array([max(m.cpu_seconds, 1e-6) for m in r.runs])
        h = np.array([e.half_width for e in est])
        dist = np.array([e.distance(ref) for e in est])
        t = qoi_table([r], qoi, half_width)
        cost = np.array([float(row[t.columns.index("cost* (s)")]) for row in t.rows[:len(r.runs)]])
        dts = np.array([m.scene.dt for m in r.runs])
        outside = np.array([not e.agrees(ref) for e in est])
        for ax, x, y in ((axes[0], cpu, h), (axes[1], cpu, dist), (axes[2], dts, cost)):
            keep = np.isfinite(y) & (y > 0)
            if keep.any():
                ax.loglog(x[keep], y[keep], styles[i % len(styles)], label=r.law.label, markersize=5)
            bad = keep & outside
            if bad.any():
                ax.loglog(x[bad], y[bad], "kx", markersize=9,
                          label="outside the reference's interval" if i == first_bad[ax] else None)
    unit = next((m.estimate(qoi).unit for r in results for m in r.runs if m.estimate(qoi).unit), "")
    unit = "" if unit == "1" else f" ({unit})"
    name = statistic_name(qoi)
    axes[0].set_ylabel(f"95 % half-width of {name}{unit}")
    axes[0].set_title(f"{name}: batch-means half-width against CPU — lower left is better", fontsize=9)
    axes[1].set_ylabel(f"|v − v_ref| + h{unit}")
    axes[1].set_title(f"{name}: distance to the law's reference against CPU", fontsize=9)
    axes[2].set_ylabel(f"projected CPU time to reach h* = {half_width} (s)")
    axes[2].set_xlabel("Δt (s)")
    axes[2].set_title("cost* = cpu (transient + T*)/(transient + T), T* = T (h/h*)²", fontsize=9)
    for ax in axes[:2]:
        ax.set_xlabel("engine CPU time of the run (s)")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    return save_figure(fig, path, dpi=110)


def draw_convergence(results: Sequence[LawRuns], qoi: str, path: Path) -> Path:
    """Value ± half-width against Δt, one panel per law, with the reference's band."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(5 * len(results), 4.5), layout="constrained")
    for i, r in enumerate(results):
        ax = fig.add_subplot(1, len(results), i + 1)
        errorbar_panel(ax, [m.scene.dt for m in r.runs], r.runs, r.reference, qoi, reference_x=r.reference.scene.dt,
                       xlabel="Δt (s)", title=f"{r.law.label}: {statistic_name(qoi)} against Δt")
    return save_figure(fig, path, dpi=110)


def runs_csv(results: Sequence[LawRuns]) -> str:
    """Every run with every scalar statistic: value and half-width (the reference's ensemble too), as CSV."""
    names = sorted({n for r in results for m in r.runs + [r.reference] for n in m.statistics})
    rows = []
    for r in results:
        for role, m in [("run", m) for m in r.runs] + [("reference", r.reference)]:
            for kind, table_ in (("", m.statistics), (" (ensemble)", m.ensemble)):
                if not table_:
                    continue
                values = [x for n in names for x in ((table_[n].value, table_[n].half_width)
                                                     if n in table_ else (math.nan, math.nan))]
                rows.append([r.law.label, role + kind, m.scene.dt, m.transient, m.window, m.members, m.cpu_seconds,
                             m.status] + values)
    return csv_text(["law", "role", "dt", "transient", "window", "members", "cpu_seconds", "status"]
                    + [f"{n}{suffix}" for n in names for suffix in ("", "_half_width")], rows)


def outputs(folder: Optional[Path], qois: Sequence[str]) -> StudyFolder:
    """The study's folder (default out/work_precision_statistics), its files for ``qois`` checked before
    anything runs."""
    for q in qois:
        statistic_name(q)  # refuse unknown names before anything is written
    names = [f"work_precision_{q}{end}" for q in qois for end in (".md", ".csv", ".png", "_dt.png")]
    return StudyFolder.prepare(folder, "work_precision_statistics",
                               names + ["statistics_runs.csv", "work_precision_statistics.md"])


def study(folder: Optional[Path] = None, *, qois: Sequence[str] = ("stop_power",), quick: bool = False,
          half_width: HalfWidth = HalfWidth(0.02, True), transient: Optional[float] = None,
          window: Optional[float] = None, reference_window: Optional[float] = None, members: Optional[int] = None,
          check_cpu: Optional[float] = None, quiet: bool = False) -> dict[str, Table]:
    """Run the laws once and write the tables and charts of every QoI; return {qoi: table}.

    The first QoI's projection is checked on the first law: its cheapest run within the reference's
    interval is run again with the window T* (when its cost* ≤ ``check_cpu`` s, default 30, quick 3);
    the run is a row "(check at T*)" of that QoI's table.
    """
    out = outputs(folder, qois)
    s, chosen = settings(quick, transient, window, reference_window, members)
    base = Scene(beta=0.5)
    results = run_laws(base, chosen, s, quiet)
    checked = check(results[0], qois[0], half_width, s, check_cpu if check_cpu is not None else (3.0 if quick else 30.0))
    out.csv("statistics_runs.csv", runs_csv(results))
    tables: dict[str, Table] = {}
    heads, texts = [], []
    notes = "; ".join(f"{law.label}: {law.note}" for law in chosen if law.note)
    for q in qois:
        t = qoi_table(results, q, half_width)
        if checked is not None and q == qois[0]:
            ref = results[0].reference
            extra = table("", ["law", "Δt (s)"], [([f"{results[0].law.label} (check at T*)", checked.scene.dt], checked)],
                          ([ref.scene.dt], ref), q, half_width)
            t.rows.insert(len(results[0].runs) + 1 + (ref.members > 1), extra.rows[0])
        t.note = (f"paper's scene (J = {base.elements}, β = {base.beta:g}, centred load), {s.describe()}. "
                  "Each law against its own reference (its finest Δt, longer window); within: |v − v_ref| ≤ h + h_ref; "
                  "T* = T (h/h*)², cost* = CPU (transient + T*)/(transient + T); CPU: the engine's cpu_seconds "
                  "(an ensemble row: members × member 1's).")
        t.write(out, f"work_precision_{q}")
        draw_work_precision(results, q, half_width, out.path(f"work_precision_{q}.png"))
        draw_convergence(results, q, out.path(f"work_precision_{q}_dt.png"))
        heads.append(headline(results, q, half_width, checked if q == qois[0] else None))
        texts.append(t.markdown())
        tables[q] = t
    total = sum(m.cpu_seconds * m.members for r in results for m in r.runs + [r.reference])
    total += checked.cpu_seconds if checked is not None else 0.0
    summary = [f"# Work-precision under impacts ({', '.join(qois)})", "",
               f"Paper's scene (J = {base.elements}, β = {base.beta:g}), {s.describe()}. Laws: "
               + ", ".join(law.label for law in chosen) + f". Engine CPU of all runs: {total:.3g} s.", ""]
    if notes:
        summary += [f"Note — {notes}.", ""]
    summary += ["## Headlines", ""] + heads + ["## Tables", ""] + texts
    out.markdown("work_precision_statistics.md", "\n".join(summary))
    return tables

"""Convergence tables: error against a much finer reference run, in Δt at fixed J and in h
at a fixed fine Δt, with the observed orders between successive rows.

Errors (all from engine runs, compared here):

- tip displacement, max and L² in time over [0, window] on the common record grid;
- the energy norm of the whole beam at chosen times, relative to the reference's:
  ‖(e, ė)‖_E / ‖(u_ref, u̇_ref)‖_E with ‖(e, ė)‖²_E = ėᵀMė + eᵀSe (twice the energy of the
  error field), from the engine's full states (values, slopes, centred velocities). In h
  the coarse field is written exactly on the reference mesh (:func:`common.prolong`).

``python -m beamstops converge`` and ``scripts/convergence.py`` write the tables
(markdown and CSV) of :func:`study` into out/convergence. With ``--qoi NAME ...`` they run the
convergence of statistics after a transient instead (:mod:`beamstops.studies.qoi_convergence`:
value ± 95 % half-width against Δt and J with a fine reference's interval); ``--qoi tip`` (the
default) keeps these pointwise tables.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import numpy as np

from ..result import Result
from ..scene import Scene
from .cli import StudyCommand
from .common import States, Table, energy_norm, observed_orders, progress, prolong, run_three_level, run_tip, \
    states, tip_error
from .outputs import StudyFolder

__all__ = ["dt_table", "h_table", "study", "main", "register"]


def _window_label(w: float) -> str:
    return f"[0,{w:g}]"


def _energy_errors(run_states: "object", ref_states: "object", coarse: int, fine: int, length: float) -> list[float]:
    errors = []
    for k in range(run_states.steps.size):  # type: ignore[attr-defined]
        u = prolong(run_states.u[:, k], coarse, fine, length)  # type: ignore[attr-defined]
        v = prolong(run_states.v[:, k], coarse, fine, length)  # type: ignore[attr-defined]
        ur, vr = ref_states.u[:, k], ref_states.v[:, k]  # type: ignore[attr-defined]
        norm = energy_norm(ur, vr, ref_states.mass, ref_states.stiffness)  # type: ignore[attr-defined]
        err = energy_norm(u - ur, v - vr, ref_states.mass, ref_states.stiffness)  # type: ignore[attr-defined]
        errors.append(err / norm if norm > 0 and math.isfinite(err) else math.inf)
    return errors


def _columns(first: list[str], windows: Sequence[float], times: Sequence[float]) -> list[str]:
    cols = list(first)
    for w in windows:
        label = _window_label(w)
        cols += [f"max err {label} (m)", f"order max {label}", f"L2 err {label} (m s^1/2)", f"order L2 {label}"]
    for t in times:
        cols += [f"energy err t={t:g} (rel)", f"order energy t={t:g}"]
    return cols


@dataclass(frozen=True)
class _Reference:
    """The reference run of a table: its scene, its tip record and its states at the table's times."""

    scene: Scene
    tip: Result
    states: Optional[States]
    windows: Sequence[float]
    times: Sequence[float]

    @classmethod
    def of(cls, base: Scene, windows: Sequence[float], times: Sequence[float], grid: float,
           **change: object) -> tuple[Scene, "_Reference"]:
        """The base scene run up to the last window or time, and its reference: that scene with
        ``change``, its tip recorded on ``grid``."""
        base = base.replace(t_end=max(list(windows) + list(times)))
        scene = base.replace(**change)
        return base, cls(scene, run_tip(scene, grid), states(scene, times) if times else None, windows, times)

    def errors(self, scene: Scene, result: Result) -> list[float]:
        """A run's max and L2 tip errors on each window, then its energy errors at each time
        (on the reference's mesh)."""
        errs: list[float] = []
        for w in self.windows:
            e = tip_error(result, self.tip, w)
            errs += [e.max, e.l2]
        if self.states is not None:
            errs += _energy_errors(states(scene, self.times), self.states, scene.elements, self.scene.elements,
                                   scene.length)
        return errs


def _fill(rows: list[list[object]], sizes: Sequence[float], per_row: list[list[float]]) -> None:
    """Append each error series and its observed orders to the rows."""
    series = list(zip(*per_row)) if per_row else []
    for values in series:
        orders = observed_orders(sizes, list(values))
        for row, value, order in zip(rows, values, orders):
            row += [value, order]


def dt_table(base: Scene, dts: Sequence[float], dt_ref: float, windows: Sequence[float], times: Sequence[float],
             *, grid: Optional[float] = None, three_level: bool = False, title: str = "", quiet: bool = False) -> Table:
    """Errors in Δt at the base scene's J against a run of step ``dt_ref`` (same scene otherwise).

    ``three_level``: also run each Δt in the paper's three-level form (scenes without stops)
    and give its max tip error over [0, t_end] and its distance to the increment form.
    """
    grid = grid or max(dts)
    base, reference = _Reference.of(base, windows, times, grid, dt=dt_ref)
    rows: list[list[object]] = []
    errors: list[list[float]] = []
    extra: list[list[float]] = []
    for dt in progress(dts, "converge dt", quiet=quiet):
        scene = base.replace(dt=dt)
        result = run_tip(scene, grid)
        row: list[object] = [dt, int(result.attrs["steps"]), result.attrs["cpu_seconds"]]
        errors.append(reference.errors(scene, result))
        if three_level:
            t3, u3, cpu3 = run_three_level(scene.replace(record_every=round(grid / dt)))
            n = min(u3.size, reference.tip.tip_u.size)
            extra.append([float(np.abs(u3[:n] - reference.tip.tip_u[:n]).max()),
                          float(np.abs(u3[:n] - result.tip_u[:n]).max()), cpu3])
        rows.append(row)
    table = Table(title or f"Δt convergence, J = {base.elements}", _columns(["Δt (s)", "steps", "CPU (s)"], windows,
                                                                           times), rows)
    _fill(rows, dts, errors)
    if three_level:
        table.columns += ["three-level max err (m)", "order three-level", "|three-level − increment| (m)",
                          "three-level CPU (s)"]
        orders = observed_orders(dts, [x[0] for x in extra])
        for row, x, order in zip(rows, extra, orders):
            row += [x[0], order, x[1], x[2]]
    table.note = (f"{_scene_text(base)}; reference Δt = {dt_ref:g} s; errors on the record grid {grid:g} s; "
                  "energy err: ‖(e, ė)‖_E / ‖(u_ref, u̇_ref)‖_E at the given time.")
    return table


def h_table(base: Scene, elements: Sequence[int], reference_elements: int, windows: Sequence[float],
            times: Sequence[float], *, grid: Optional[float] = None, title: str = "", quiet: bool = False) -> Table:
    """Errors in h = L/J at the base scene's (fine) Δt against a run on ``reference_elements``."""
    grid = grid or base.dt
    base, reference = _Reference.of(base, windows, times, grid, elements=reference_elements)
    rows: list[list[object]] = []
    errors: list[list[float]] = []
    for j in progress(elements, "converge h", quiet=quiet):
        scene = base.replace(elements=j)
        result = run_tip(scene, grid)
        rows.append([j, base.length / j, int(result.attrs["steps"]), result.attrs["cpu_seconds"]])
        errors.append(reference.errors(scene, result))
    table = Table(title or f"h convergence, Δt = {base.dt:g} s", _columns(["J", "h (m)", "steps", "CPU (s)"],
                                                                          windows, times), rows)
    _fill(rows, [base.length / j for j in elements], errors)
    table.note = (f"{_scene_text(base)}; reference J = {reference_elements}; errors on the record grid {grid:g} s; "
                  "energy err: ‖(e, ė)‖_E / ‖(u_ref, u̇_ref)‖_E on the reference mesh (coarse field prolonged exactly).")
    return table


def _scene_text(scene: Scene) -> str:
    law = scene.law if scene.law != "compliance" else f"compliance 1/ε = {scene.stiffness_per_mass:g} 1/s²"
    return (f"paper's scene, law {law}, β = {scene.beta:g}, load rule {scene.load_rule}, start {scene.start}, "
            f"J = {scene.elements}, Δt = {scene.dt:g} s, T = {scene.t_end:g} s")


#: The tables the study writes into its folder (each as .md and .csv), and convergence.md gathering them.
TABLES = ("dt_none_centered", "dt_none_paper", "dt_none_centered_J19", "dt_none_paper_J19", "roundoff_three_level",
          "h_none", "dt_signorini", "h_signorini")


def outputs(folder: Optional[Path] = None) -> StudyFolder:
    """The study's folder (default out/convergence), its files checked before anything runs."""
    return StudyFolder.prepare(folder, "convergence",
                               [f"{stem}.{ext}" for stem in TABLES for ext in ("md", "csv")] + ["convergence.md"])


def study(folder: Optional[Path] = None, *, quick: bool = False, three_level: bool = True,
          quiet: bool = False) -> dict[str, Table]:
    """The convergence tables of issue 6, written to ``folder`` (default out/convergence)."""
    out = outputs(folder)
    base = Scene(beta=0.25)
    if quick:
        free_dts, free_t, free_times = [4e-5 / 2**k for k in range(4)], 0.1, (0.05, 0.1)
        stop_dts, stop_windows, stop_times = [4e-5 / 2**k for k in range(4)], (0.1,), (0.1,)
        h_j, h_ref, h_dt, roff_dts = (2, 4, 8), 16, 4e-6, [4e-6 / 2**k for k in range(3)]
        roff_t = 0.02
        fine_dts, fine_t = [4e-6 / 2**k for k in range(3)], 0.02
    else:
        free_dts, free_t, free_times = [4e-5 / 2**k for k in range(6)], 1.0, (0.5, 1.0)
        stop_dts, stop_windows, stop_times = [4e-5 / 2**k for k in range(6)], (0.08, 0.2, 2.0), (0.08, 0.2, 1.0, 2.0)
        h_j, h_ref, h_dt, roff_dts = (2, 4, 8, 16), 64, 1e-6, [4e-6 / 2**k for k in range(5)]
        roff_t = 0.2
        fine_dts, fine_t = [8e-6 / 2**k for k in range(6)], 0.2
    free = base.replace(law="none")
    small = free.replace(elements=4 if not quick else 2)
    tables: dict[str, Table] = {}
    todo = [
        ("dt_none_centered", lambda: dt_table(small, free_dts, free_dts[-1] / 8, (free_t,), free_times, quiet=quiet,
                                              title=f"Δt convergence without stops, centred load rule, "
                                                    f"J = {small.elements}")),
        ("dt_none_paper", lambda: dt_table(small.replace(load_rule="paper"), free_dts, free_dts[-1] / 8, (free_t,),
                                           free_times, quiet=quiet,
                                           title=f"Δt convergence without stops, the paper's load rule, "
                                                 f"J = {small.elements}")),
        ("dt_none_centered_J19", lambda: dt_table(free, fine_dts, fine_dts[-1] / 8, (fine_t,), (fine_t / 2, fine_t),
                                                  quiet=quiet, title="Δt convergence without stops, centred load "
                                                                     "rule, J = 19 (the paper's mesh)")),
        ("dt_none_paper_J19", lambda: dt_table(free.replace(load_rule="paper"), fine_dts, fine_dts[-1] / 8,
                                               (fine_t,), (fine_t / 2, fine_t), quiet=quiet,
                                               title="Δt convergence without stops, the paper's load rule, J = 19")),
        ("roundoff_three_level", lambda: dt_table(free.replace(elements=4, beta=0.5), roff_dts, roff_dts[-1] / 4, (roff_t,), (),
                                                  three_level=three_level, quiet=quiet,
                                                  title="Increment form against the three-level form (no stops, "
                                                        "J = 4, β = 1/2)")),
        ("h_none", lambda: h_table(free.replace(dt=h_dt), h_j, h_ref, (free_t,), free_times, grid=4e-5, quiet=quiet,
                                   title="h convergence without stops")),
        ("dt_signorini", lambda: dt_table(base.replace(beta=0.5), stop_dts, stop_dts[-1] / 8, stop_windows,
                                          stop_times, quiet=quiet,
                                          title="Δt convergence with stops (Signorini scheme, β = 1/2)")),
        ("h_signorini", lambda: h_table(base.replace(beta=0.5, dt=h_dt), h_j, h_ref, stop_windows, stop_times,
                                        grid=4e-5, quiet=quiet, title="h convergence with stops (Signorini, β = 1/2)")),
    ]
    assert [stem for stem, _ in todo] == list(TABLES)
    for stem, make in progress(todo, "convergence tables", quiet=quiet):
        table = make()
        table.write(out, stem)
        tables[stem] = table
    out.markdown("convergence.md", "\n".join(t.markdown() for t in tables.values()))
    return tables


def _options(parser: argparse.ArgumentParser) -> None:
    from .workprecision import qoi_options

    parser.add_argument("--no-three-level", action="store_true",
                        help="skip the three-level form in the round-off comparison")
    qoi_options(parser)


def _check(args: argparse.Namespace) -> Optional[str]:
    from .options import check_statistical

    return check_statistical("converge", args)


def _run(folder: Path, args: argparse.Namespace) -> Path:
    from . import qoi_convergence
    from .qoi import HalfWidth
    from .workprecision import split_qois

    pointwise, statistical = split_qois(args.qoi)
    printed = folder / "convergence.md"
    if statistical:  # every file of both checked before either runs
        qoi_convergence.outputs(folder, statistical)
    if pointwise:
        outputs(folder)
    if statistical:
        qoi_convergence.study(folder, qois=statistical, quick=args.quick, half_width=HalfWidth.parse(args.half_width),
                              transient=args.transient, window=args.stat_window, reference_window=args.reference_window,
                              members=args.members, quiet=args.quiet)
        printed = folder / "qoi_convergence.md"
    if pointwise:
        study(folder, quick=args.quick, three_level=not args.no_three_level, quiet=args.quiet)
        printed = folder / "convergence.md"
    return printed


#: ``converge [-o DIR] [--quick] [--no-three-level] [--qoi NAME ...] [--half-width H]``; ``main`` is scripts/convergence.py.
COMMAND = StudyCommand("convergence", _options, _run, name="converge",
                       help="convergence tables in Δt and h (markdown and CSV)",
                       description="Convergence tables in Δt and h against finer reference runs.",
                       prog="convergence", script_description="Convergence tables in Δt and h.", check=_check)
register = COMMAND.register
main = COMMAND.main

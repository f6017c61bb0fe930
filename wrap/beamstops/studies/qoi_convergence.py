"""Convergence of statistical QoIs in Δt and in J (``converge --qoi NAME ...``): the paper's scene
(Signorini, β = 1/2, e = 0) run after a transient at a ladder of Δt (J = 19) and of J (fixed Δt),
each QoI's value ± batch-means half-width against a fine reference (smaller Δt, or larger J, and a
longer window; the Δt reference also across perturbed members), "within the reference's interval"
when |v − v_ref| ≤ h + h_ref.

Files (per QoI): ``qoi_convergence_<qoi>_dt.{md,csv}``, ``qoi_convergence_<qoi>_J.{md,csv}``,
``qoi_convergence_<qoi>.png`` (value ± h against Δt and against J with the reference's band);
``qoi_convergence.md`` gathers the tables.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

from ..scene import Scene
from ..output_files import save_figure
from .common import Table, progress
from .outputs import StudyFolder
from .qoi import HalfWidth, Measured, measure, statistic_name
from .qoi_report import errorbar_panel, table
from .qoi_workprecision import Settings, settings

__all__ = ["Ladders", "ladders", "Runs", "run_ladders", "study"]


@dataclass(frozen=True)
class Ladders:
    """The Δt ladder (at the base J) and its reference Δt; the J ladder (at ``dt_of_j``) and its reference J."""

    dts: tuple[float, ...]
    dt_reference: float
    elements: tuple[int, ...]
    elements_reference: int
    dt_of_j: float
    modes: tuple[int, ...] = ()
    """Reduced models (&mesh modes) at the base J and ``dt_of_j``, against the full model there."""


def ladders(quick: bool) -> Ladders:
    if quick:
        return Ladders((4e-5, 2e-5), 1e-5, (5, 10), 19, 2e-5, (4, 8))
    return Ladders(tuple(4e-5 / 2**k for k in range(5)), 1.25e-6, (5, 10, 19), 38, 5e-6, (2, 4, 8, 16))


@dataclass(frozen=True)
class Runs:
    """The runs of both ladders and their references."""

    base: Scene
    by_dt: list[Measured]
    dt_reference: Measured
    by_j: list[Measured]
    j_reference: Measured
    by_r: list[Measured]
    r_reference: Measured


def run_ladders(base: Scene, lad: Ladders, s: Settings, quiet: bool = False) -> Runs:
    """Every Δt and J of the ladders and both references (the Δt reference with ``s.members`` members)."""
    todo: list[tuple[str, object]] = ([("dt", dt) for dt in lad.dts] + [("dt_ref", lad.dt_reference)]
                                      + [("J", j) for j in lad.elements] + [("J_ref", lad.elements_reference)]
                                      + [("r", r) for r in lad.modes] + [("r_ref", 0)])
    out: dict[str, list[Measured]] = {"dt": [], "dt_ref": [], "J": [], "J_ref": [], "r": [], "r_ref": []}
    for kind, x in progress(todo, "converge (statistics)", quiet=quiet):
        if kind.startswith("dt"):
            scene = base.replace(dt=x)
        elif kind.startswith("r"):
            scene = base.replace(dt=lad.dt_of_j, modes=x)
        else:
            scene = base.replace(dt=lad.dt_of_j, elements=x)
        reference = kind.endswith("_ref")
        out[kind].append(measure(scene, s.transient, s.reference_window if reference else s.window, batches=s.batches,
                                 members=s.members if kind == "dt_ref" else 1, perturbation=s.perturbation))
    return Runs(base, out["dt"], out["dt_ref"][0], out["J"], out["J_ref"][0], out["r"], out["r_ref"][0])


def tables(runs: Runs, qoi: str, half_width: HalfWidth, s: Settings) -> tuple[Table, Table, Table]:
    """The Δt table, the J table and the table of reduced models (modes r) of one QoI."""
    b = runs.base
    scene = f"paper's scene (Signorini, e = {b.restitution:g}, β = {b.beta:g}, centred load), {s.describe()}"
    by_dt = table(f"{qoi} ({statistic_name(qoi)}) against Δt, J = {b.elements}, h* = {half_width}", ["Δt (s)"],
                  [([m.scene.dt], m) for m in runs.by_dt], ([runs.dt_reference.scene.dt], runs.dt_reference), qoi,
                  half_width,
                  note=f"{scene}. Reference: Δt = {runs.dt_reference.scene.dt:g} s. Within: |v − v_ref| ≤ h + h_ref; "
                       "T* = T (h/h*)², cost* = CPU (transient + T*)/(transient + T) (engine cpu_seconds; the "
                       "ensemble row: members × member 1's).")
    dt_j = runs.j_reference.scene.dt
    by_j = table(f"{qoi} ({statistic_name(qoi)}) against J, Δt = {dt_j:g} s, h* = {half_width}", ["J"],
                 [([m.scene.elements], m) for m in runs.by_j], ([runs.j_reference.scene.elements], runs.j_reference),
                 qoi, half_width, note=f"{scene}. Reference: J = {runs.j_reference.scene.elements}.")
    by_r = table(f"{qoi} ({statistic_name(qoi)}) against the modes r of a reduced model, J = {b.elements}, "
                 f"Δt = {dt_j:g} s, h* = {half_width}", ["modes r"],
                 [([m.scene.modes], m) for m in runs.by_r], (["full"], runs.r_reference), qoi, half_width,
                 note=f"{scene}. Reference: the full finite-element model (modes = 0) at the same J and Δt; "
                      "CPU: the reduced models' own (engine cpu_seconds).")
    return by_dt, by_j, by_r


def draw(runs: Runs, qoi: str, path: Path) -> Path:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(16, 4.5), layout="constrained")
    errorbar_panel(fig.add_subplot(1, 3, 1), [m.scene.dt for m in runs.by_dt], runs.by_dt, runs.dt_reference, qoi,
                   reference_x=runs.dt_reference.scene.dt, xlabel="Δt (s)",
                   title=f"{statistic_name(qoi)} against Δt (J = {runs.base.elements})")
    errorbar_panel(fig.add_subplot(1, 3, 2), [m.scene.elements for m in runs.by_j], runs.by_j, runs.j_reference, qoi,
                   reference_x=runs.j_reference.scene.elements, xlabel="J (elements)",
                   title=f"{statistic_name(qoi)} against J (Δt = {runs.j_reference.scene.dt:g} s)")
    if runs.by_r:
        full = 2 * runs.base.elements - 1  # where the full model stands on the axis of modes
        errorbar_panel(fig.add_subplot(1, 3, 3), [m.scene.modes for m in runs.by_r], runs.by_r, runs.r_reference,
                       qoi, reference_x=full, xlabel="modes r (reduced model; rightmost: the full model)",
                       title=f"{statistic_name(qoi)} against modes r (J = {runs.base.elements})")
    return save_figure(fig, path, dpi=110)


def outputs(folder: Optional[Path], qois: Sequence[str]) -> StudyFolder:
    """The study's folder (default out/convergence), its files for ``qois`` checked before anything runs."""
    for q in qois:
        statistic_name(q)  # refuse unknown names before anything is written
    names = [f"qoi_convergence_{q}_{axis}.{ext}" for q in qois for axis in ("dt", "J", "modes") for ext in ("md", "csv")]
    names += [f"qoi_convergence_{q}.png" for q in qois] + ["qoi_convergence.md"]
    return StudyFolder.prepare(folder, "qoi_convergence", names)


def study(folder: Optional[Path] = None, *, qois: Sequence[str] = ("stop_power",), quick: bool = False,
          half_width: HalfWidth = HalfWidth(0.02, True), transient: Optional[float] = None,
          window: Optional[float] = None, reference_window: Optional[float] = None, members: Optional[int] = None,
          quiet: bool = False) -> dict[str, tuple[Table, Table, Table]]:
    """Run both ladders once; write the tables and the chart of every QoI."""
    files = outputs(folder, qois)
    s, _ = settings(quick, transient, window, reference_window, members)
    runs = run_ladders(Scene(beta=0.5), ladders(quick), s, quiet)
    out: dict[str, tuple[Table, Table, Table]] = {}
    text = []
    for q in qois:
        by_dt, by_j, by_r = tables(runs, q, half_width, s)
        by_dt.write(files, f"qoi_convergence_{q}_dt")
        by_j.write(files, f"qoi_convergence_{q}_J")
        by_r.write(files, f"qoi_convergence_{q}_modes")
        draw(runs, q, files.path(f"qoi_convergence_{q}.png"))
        text += [by_dt.markdown(), by_j.markdown(), by_r.markdown()]
        out[q] = (by_dt, by_j, by_r)
    files.markdown("qoi_convergence.md", "# Convergence of statistics in Δt, J and modes r\n\n" + "\n".join(text))
    return out

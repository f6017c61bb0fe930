"""Stability maps: run each point of a (β, Δt) or (J, Δt) grid with the stops, classify it
stable or unstable from energy growth, and draw it with the theoretical limits.

Classification of a run (all quantities from the engine's records): unstable when the
engine marked it 'diverged' (its kinetic energy passed 1e8 times the energy supplied), when
a record is not finite, or when its energy measures grow: ``growth`` = max over the run of
max(|E|, |work|, |dissipated|) divided by the same for a stable reference run (β = 1/2,
Δt = 1e-5 s, same scene), or by the run's own discrete energy at its start when that is larger,
exceeds ``threshold`` (default 10). The start matters at coarse Δt and β > 0: the beam starts at
rest on a moving clamp (v0 = −2h, SPEC 1), a velocity field with a steep first element, and
E^{1/2} holds ½ β Δt² v0ᵀ S v0 — 9.6 J against 0.16 J at Δt = 1e-5 s for J = 54, β = 1/4,
Δt = 1e-3 s — which is a constant level, not a growth (β = 1/4 is unconditionally stable).
The discrete energy E alone
would not do: for β < 1/4 beyond the linear limit E is indefinite and can stay bounded
while the beam blows up; the work of the load and the energy taken by the stops follow u.

Theoretical curves (from :func:`beamstops.stability`): the linear Newmark limit
2/sqrt((1-4β)κ_h) for β < 1/4, the paper's condition (3.1) with the exact κ_h and with
its bound κ̃ (α → 0).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Optional

import numpy as np

from ..engine import run, stability
from ..result import IncompleteRunError, Result
from ..scene import Scene
from ..arguments import number
from .cli import StudyCommand
from ..output_files import save_figure
from .common import Table, progress
from .outputs import StudyFolder

__all__ = ["classify", "energy_scale", "beta_map", "mesh_map", "answer", "study", "main", "register"]


def _peak(result: Result) -> float:
    values = [np.abs(a) for a in (result.energy, result.work, result.dissipated) if a.size]
    if not values:
        return math.inf
    stacked = np.concatenate(values)
    return float(stacked.max()) if np.all(np.isfinite(stacked)) else math.inf


def energy_scale(scene: Scene) -> float:
    """max(|E|, |work|, |dissipated|) over a stable run of the scene (β = 1/2, Δt = 1e-5 s)."""
    reference = scene.replace(beta=0.5, dt=1e-5, allow_unstable=False,
                              record_every=max(1, round(scene.t_end / 1e-5 / 20000)))
    return _peak(run(reference))


def _start(result: Result) -> float:
    """|E| of the run's first record (its discrete energy at the start; 0 when there is none)."""
    if not result.energy.size or not math.isfinite(float(result.energy[0])):
        return 0.0
    return abs(float(result.energy[0]))


def classify(result: Result, scale: float, threshold: float = 10.0) -> tuple[str, float]:
    """('stable' | 'unstable', growth) of a run: growth = its peak energy measure over the larger of
    the scene's energy scale and the run's own starting energy (growth in time, not a start whose
    discrete energy depends on Δt)."""
    growth = _peak(result) / max(scale, _start(result))
    if result.status != "complete" or not math.isfinite(growth) or growth > threshold:
        return "unstable", growth
    return "stable", growth


def _run_point(scene: Scene, scale: float, threshold: float) -> tuple[str, float, float, str]:
    steps = max(1, round(scene.t_end / scene.dt))
    scene = scene.replace(allow_unstable=True, record_every=max(1, steps // 20000))
    try:
        result = run(scene, allow_incomplete=True)
    except IncompleteRunError as exc:  # pragma: no cover - allow_incomplete returns instead
        assert exc.result is not None
        result = exc.result
    verdict, growth = classify(result, scale, threshold)
    return verdict, growth, float(result.attrs["cpu_seconds"]), result.status


def _map(base: Scene, key: str, values: Sequence[float], dts: Sequence[float], threshold: float, title: str,
         quiet: bool) -> Table:
    rows: list[list[object]] = []
    scales: dict[object, float] = {}
    points = [(v, dt) for v in values for dt in dts]
    for value, dt in progress(points, f"stability map ({key})", quiet=quiet):
        scene = base.replace(**{key: value, "dt": dt})
        scale_key = value if key == "elements" else None
        if scale_key not in scales:
            scales[scale_key] = energy_scale(scene)
        limits = stability(scene)
        verdict, growth, cpu, status = _run_point(scene, scales[scale_key], threshold)
        rows.append([scene.beta, scene.elements, dt, verdict, growth, status, cpu, limits.kappa_h,
                     limits.dt_limit_newmark, limits.dt_limit_paper, limits.dt_limit_paper_bound])
    table = Table(title, ["β", "J", "Δt (s)", "class", "growth", "status", "CPU (s)", "κ_h (1/s²)",
                          "Newmark limit (s)", "(3.1) exact κ_h (s)", "(3.1) bound κ̃ (s)"], rows)
    table.note = (f"paper's scene, law {base.law}, T = {base.t_end:g} s; unstable: diverged, or energy measures "
                  f"grow beyond {threshold:g}× those of a stable run (β = 1/2, Δt = 1e-5 s) or the run's own "
                  "starting energy, whichever is larger.")
    return table


def beta_map(base: Scene, betas: Sequence[float], dts: Sequence[float], threshold: float = 10.0,
             quiet: bool = False) -> Table:
    """Classify every (β, Δt) of the base scene."""
    return _map(base, "beta", betas, dts, threshold, f"Stability map in (β, Δt), J = {base.elements}", quiet)


def mesh_map(base: Scene, elements: Sequence[int], dts: Sequence[float], threshold: float = 10.0,
             quiet: bool = False) -> Table:
    """Classify every (J, Δt) of the base scene (at its β)."""
    return _map(base, "elements", elements, dts, threshold, f"Stability map in (J, Δt), β = {base.beta:g}", quiet)


def answer(table: Table) -> str:
    """From a (β, Δt) map: does the projected scheme with 1/4 ≤ β < 1/2 stay stable beyond (3.1)?"""
    beyond = [r for r in table.rows if 0.25 <= float(r[0]) < 0.5 and float(r[2]) > float(r[9])]  # type: ignore
    unstable = [r for r in beyond if r[3] == "unstable"]
    below_newmark = [r for r in table.rows if float(r[0]) < 0.25 and float(r[2]) < float(r[8])]  # type: ignore
    bad_below = [r for r in below_newmark if r[3] == "unstable"]
    above_newmark = [r for r in table.rows if float(r[0]) < 0.25 and float(r[2]) > float(r[8])]  # type: ignore
    bad_above = [r for r in above_newmark if r[3] == "unstable"]
    largest = max((float(r[2]) / float(r[9]) for r in beyond if r[3] == "stable"), default=math.nan)  # type: ignore
    text = [f"- 1/4 ≤ β < 1/2, Δt beyond (3.1) with the exact κ_h: {len(beyond)} runs, {len(unstable)} unstable"
            + (f"; stable up to {largest:.3g}× the (3.1) limit." if beyond and not unstable else "."),
            f"- β < 1/4 below the linear Newmark limit: {len(below_newmark)} runs, {len(bad_below)} unstable.",
            f"- β < 1/4 beyond the linear Newmark limit: {len(above_newmark)} runs, {len(bad_above)} unstable."]
    return "\n".join(text) + "\n"


def draw(beta_table: Optional[Table], mesh_tables: Sequence[Table], path: Path, base: Scene) -> Path:
    """The maps with their theoretical curves, one panel per table."""
    from matplotlib.figure import Figure

    tables = ([beta_table] if beta_table else []) + list(mesh_tables)
    fig = Figure(figsize=(6 * len(tables), 5), layout="constrained")
    for i, table in enumerate(tables):
        ax = fig.add_subplot(1, len(tables), i + 1)
        by_beta = table is beta_table
        x = np.array([float(r[0] if by_beta else r[1]) for r in table.rows])  # type: ignore[arg-type]
        dt = np.array([float(r[2]) for r in table.rows])  # type: ignore[arg-type]
        unstable = np.array([r[3] == "unstable" for r in table.rows])
        ax.scatter(x[~unstable], dt[~unstable], marker="o", facecolors="none", edgecolors="tab:green", label="stable")
        ax.scatter(x[unstable], dt[unstable], marker="x", color="tab:red", label="unstable")
        if by_beta:
            grid = np.linspace(0.0, 0.5, 201)
            scene = base.replace(dt=1e-6)
            limits = [stability(scene.replace(beta=float(b))) for b in grid]
        else:
            beta = float(table.rows[0][0])  # type: ignore[arg-type]
            grid = np.unique(np.geomspace(x.min(), x.max(), 60).round().astype(int))
            scene = base.replace(beta=beta, dt=1e-6)
            limits = [stability(scene.replace(elements=int(j))) for j in grid]
        newmark = np.array([s.dt_limit_newmark for s in limits])
        exact = np.array([s.dt_limit_paper for s in limits])
        bound = np.array([s.dt_limit_paper_bound for s in limits])
        ax.plot(grid, np.where(np.isfinite(newmark), newmark, np.nan), "k-", label="linear Newmark 2/√((1−4β)κ_h)")
        ax.plot(grid, np.where(np.isfinite(exact), exact, np.nan), "b--", label="paper (3.1), exact κ_h")
        ax.plot(grid, np.where(np.isfinite(bound), bound, np.nan), "b:", label="paper (3.1), bound κ̃")
        ax.set_yscale("log")
        if not by_beta:
            ax.set_xscale("log")
        ax.set_xlabel("β" if by_beta else "J (elements)")
        ax.set_ylabel("Δt (s)")
        ax.set_title(table.title, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="lower left" if by_beta else "upper right")
    return save_figure(fig, path, dpi=120)


#: The files the study writes into its folder.
FILES = tuple(f"stability_{stem}.{ext}" for stem in ("beta", "mesh_beta0", "mesh_beta025") for ext in ("md", "csv")) \
    + ("stability.md", "stability_map.png")


def study(folder: Optional[Path] = None, *, quick: bool = False, threshold: float = 10.0,
          quiet: bool = False) -> dict[str, Table]:
    """The (β, Δt) map and the (J, Δt) maps at β = 0 and β = 1/4; PNG, md, CSV in ``folder``."""
    out = StudyFolder.prepare(folder, "stability_map", FILES)
    if quick:
        base, betas, dts = Scene(t_end=0.05, elements=8), (0.0, 0.2, 0.25, 0.5), list(np.geomspace(1e-6, 1e-3, 4))
        meshes, mesh_dts, mesh_t = (2, 8), list(np.geomspace(1e-6, 1e-3, 4)), 0.05
    else:
        base = Scene(t_end=2.0)
        betas = (0.0, 0.05, 0.1, 0.15, 0.2, 0.22, 0.24, 0.25, 0.3, 0.35, 0.4, 0.45, 0.49, 0.5)
        dts = list(np.geomspace(1e-6, 1e-3, 16))
        meshes, mesh_dts, mesh_t = (2, 4, 8, 12, 19, 27, 38, 54), list(np.geomspace(1e-7, 1e-3, 17)), 0.2
    tables = {"beta": beta_map(base, betas, dts, threshold, quiet)}
    for beta, stem in ((0.0, "mesh_beta0"), (0.25, "mesh_beta025")):
        tables[stem] = mesh_map(base.replace(beta=beta, t_end=mesh_t), meshes, mesh_dts, threshold, quiet)
    text = []
    for stem, table in tables.items():
        table.write(out, f"stability_{stem}")
        text.append(table.markdown())
    summary = "### Answer from the (β, Δt) map\n\n" + answer(tables["beta"])
    out.markdown("stability.md", summary + "\n" + "\n".join(text))
    draw(tables["beta"], [tables["mesh_beta0"], tables["mesh_beta025"]], out.path("stability_map.png"), base)
    return tables


def _options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--threshold", type=number("a factor of energy growth"), default=10.0, help="energy growth that means unstable (default 10)")


def _run(folder: Path, args: argparse.Namespace) -> Path:
    study(folder, quick=args.quick, threshold=args.threshold, quiet=args.quiet)
    return folder / "stability_map.png"


#: ``stability-map [-o DIR] [--quick] [--threshold X]``; ``main`` is scripts/study_stability.py.
COMMAND = StudyCommand("stability_map", _options, _run, name="stability-map",
                       help="stable/unstable maps in (β, Δt) and (J, Δt) (PNG, md, CSV)",
                       description="Classify runs over (β, Δt) and (J, Δt) from energy growth.",
                       prog="study_stability", script_description="Stability maps in (β, Δt) and (J, Δt).")
register = COMMAND.register
main = COMMAND.main

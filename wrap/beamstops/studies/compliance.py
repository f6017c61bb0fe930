"""Normal compliance: the spurious high-frequency content during contact (the paper's
Fig. 5) as numbers, against Δt and the stiffness 1/ε, and the penetration against 1/ε.

Measures of a run (from the engine's records, ``record_every = 1``):

- ``reversals``: sign changes of the tip velocity while the tip is in contact (records whose
  reaction is nonzero, and the record before), per contact episode; velocities below 1e-9
  of the run's largest count as zero. A clean impact reverses once; the spurious
  oscillations of the paper's Fig. 5 reverse many times.
- ``hf``: the fraction of the tip velocity's spectral energy above a cut-off frequency
  (default 5 kHz, above the beam's 14th mode), over the whole run.
- ``penetration``: the engine's ``max_violation`` (m): max(u_tip − g2, g1 − u_tip, 0).

The Signorini scheme (β = 1/4 and 1/2) is run at the same Δt as a baseline.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Optional

import numpy as np

from ..engine import run
from ..result import Result
from ..scene import Scene
from ..arguments import number
from .cli import StudyCommand
from ..output_files import save_figure
from .common import Table, progress
from .outputs import StudyFolder

__all__ = ["reversals", "hf_fraction", "study", "main", "register"]


def reversals(result: Result) -> tuple[float, int]:
    """(sign changes of the tip velocity in contact per contact episode, episodes)."""
    contact = result.reaction != 0
    if not contact.any():
        return math.nan, 0
    edges = np.diff(np.concatenate([[0], contact.astype(np.int8), [0]]))
    starts, ends = np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]
    changes = 0
    # Velocities below this are zero: a tip resting on a Signorini stop records round-off (~1e-12 m/s).
    tiny = 1e-9 * float(np.abs(result.tip_v).max())
    for a, b in zip(starts, ends):
        v = result.tip_v[max(a - 1, 0):b + 1]  # the record before contact: the approach velocity
        s = np.sign(v[np.abs(v) > tiny])
        changes += int(np.count_nonzero(s[1:] != s[:-1]))
    return changes / starts.size, int(starts.size)


def hf_fraction(result: Result, cutoff: float) -> float:
    """Fraction of the tip velocity's spectral energy above ``cutoff`` Hz (uniform records)."""
    v = result.tip_v
    if v.size < 4 or not np.all(np.isfinite(v)):
        return math.nan
    spectrum = np.abs(np.fft.rfft(v - v.mean())) ** 2
    freq = np.fft.rfftfreq(v.size, d=float(result.t[1] - result.t[0]))
    total = float(spectrum.sum())
    return float(spectrum[freq > cutoff].sum()) / total if total > 0 else math.nan


#: The files the study writes into its folder.
FILES = ("compliance.md", "compliance.csv", "compliance.png")


def study(folder: Optional[Path] = None, *, quick: bool = False, cutoff: float = 5000.0,
          quiet: bool = False) -> Table:
    """Run compliance over (1/ε, Δt) and the Signorini baseline; write compliance.{md,csv,png}."""
    out = StudyFolder.prepare(folder, "compliance", FILES)
    if quick:
        base, stiffnesses, dts = Scene(t_end=0.12, beta=0.25), (1e6, 1e8, 1e10), (5e-6, 2e-6)
    else:
        base, stiffnesses, dts = Scene(t_end=0.5, beta=0.25), (1e6, 1e7, 1e8, 1e9, 1e10), (5e-6, 2e-6, 1e-6, 5e-7)
    cases: list[tuple[str, dict[str, object]]] = [
        (f"compliance 1/ε={k:.0e}", {"law": "compliance", "stiffness_per_mass": k}) for k in stiffnesses]
    cases += [("Signorini β=1/4", {}), ("Signorini β=1/2", {"beta": 0.5})]
    points = [(label, changes, dt) for label, changes in cases for dt in dts]
    rows: list[list[object]] = []
    for label, changes, dt in progress(points, "compliance", quiet=quiet):
        result = run(base.replace(dt=dt, record_every=1, **changes))  # type: ignore[arg-type]
        per_episode, episodes = reversals(result)
        rows.append([label, float(changes.get("stiffness_per_mass", math.inf)), dt, per_episode, episodes,
                     hf_fraction(result, cutoff), result.attrs["max_violation"], result.attrs["impacts"],
                     result.attrs["cpu_seconds"]])
    table = Table(f"Normal compliance against the Signorini scheme, T = {base.t_end:g} s",
                  ["method", "1/ε (1/s²)", "Δt (s)", "reversals per contact", "contacts",
                   f"HF fraction > {cutoff:g} Hz", "penetration (m)", "impacts", "CPU (s)"], rows)
    table.note = (f"paper's scene, β = {base.beta:g} (compliance), J = {base.elements}; reversals: sign changes of "
                  "the tip velocity during contact per contact episode (1 for a clean impact); HF fraction: share of "
                  "the tip velocity's spectral energy above the cut-off; penetration: the engine's max_violation.")
    table.write(out, "compliance")
    draw(table, out.path("compliance.png"))
    return table


def draw(table: Table, path: Path) -> Path:
    """Reversals and HF fraction against Δt, penetration against 1/ε."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(15, 4.5), layout="constrained")
    axes = [fig.add_subplot(1, 3, i + 1) for i in range(3)]
    labels = list(dict.fromkeys(table.column("method")))
    for label in labels:
        rows = [r for r in table.rows if r[0] == label]
        dt = [float(r[2]) for r in rows]  # type: ignore[arg-type]
        style = "o-" if label.startswith("compliance") else "k--"
        axes[0].semilogx(dt, [float(r[3]) for r in rows], style, label=label, markersize=4)  # type: ignore
        axes[1].loglog(dt, [max(float(r[5]), 1e-16) for r in rows], style, label=label, markersize=4)  # type: ignore
    axes[0].set_xlabel("Δt (s)")
    axes[0].set_ylabel("tip-velocity reversals per contact")
    axes[0].set_title("spurious oscillations in contact")
    axes[1].set_xlabel("Δt (s)")
    axes[1].set_ylabel(f"spectral energy fraction {table.columns[5][12:]}")
    axes[1].set_title("high-frequency content of the tip velocity")
    for dt in sorted({float(r[2]) for r in table.rows}):  # type: ignore[arg-type]
        rows = [r for r in table.rows if float(r[2]) == dt and str(r[0]).startswith("compliance")]  # type: ignore
        k = np.array([float(r[1]) for r in rows])  # type: ignore[arg-type]
        pen = np.array([float(r[6]) for r in rows])  # type: ignore[arg-type]
        axes[2].loglog(k, pen, "o-", label=f"Δt = {dt:g} s", markersize=4)
    ks = np.array(sorted({float(r[1]) for r in table.rows if math.isfinite(float(r[1]))}))  # type: ignore
    if ks.size:
        pens = [float(r[6]) for r in table.rows if float(r[1]) == ks[0]]  # type: ignore[arg-type]
        axes[2].loglog(ks, max(pens) * (ks / ks[0]) ** -0.5, "k:", label="slope −1/2")
    axes[2].set_xlabel("1/ε per unit mass (1/s²)")
    axes[2].set_ylabel("largest penetration (m)")
    axes[2].set_title("penetration of the stops")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    return save_figure(fig, path, dpi=120)


def _options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--cutoff", type=number("a frequency in Hz"), default=5000.0, help="cut-off frequency in Hz (default 5000)")


def _run(folder: Path, args: argparse.Namespace) -> Path:
    study(folder, quick=args.quick, cutoff=args.cutoff, quiet=args.quiet)
    return folder / "compliance.png"


#: ``compliance [-o DIR] [--quick] [--cutoff HZ]``; ``main`` is scripts/study_compliance.py.
COMMAND = StudyCommand("compliance", _options, _run, name="compliance",
                       help="normal compliance: spurious oscillations and penetration",
                       description="Normal compliance against the Signorini scheme (PNG, md, CSV).",
                       prog="study_compliance", script_description="Normal compliance study.")
register = COMMAND.register
main = COMMAND.main

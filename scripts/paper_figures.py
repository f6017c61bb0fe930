#!/usr/bin/env python3
"""Reproduce the numerical results of Dumont & Paoli, "Vibrations of a beam between stops".

Runs input/paper_fig2.nml ... paper_fig8.nml with the engine (``beamstops.run``, in
memory), and writes into the output directory (default out/paper):

- ``figN.png``: the tip displacement of figure N drawn on the paper's axis ranges and
  ticks, with the stops, to be set next to the paper's figure;
- ``agreement.png``: the runs of each family overlaid on the first contact period;
- ``report.md``: for each figure the paper's CPU time, ours (the engine's own
  ``cpu_seconds``, time loop only) and their ratio; the largest violation of the stops
  (0 for the Signorini scheme; the normal-compliance runs against the paper's
  2.25e-4 m); the agreement between time steps up to t = 0.2 s, as the paper observes;
  the paper's stability bound. The report is generated: never edit it by hand.

The paper's numbers (CPU times, violation, stability bound, axis ranges) are typed in
from SPEC.md §2 and the paper's figures; everything else comes from the runs.

Usage: python scripts/paper_figures.py [--t-end T] [--out DIR] [--input DIR] [--figures 2 5 ...]
``--t-end`` shortens the horizon (CI); the CPU comparison then uses the cost per step.
"""

from __future__ import annotations

import argparse
import datetime
import platform
import shlex
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Optional, Sequence

import numpy as np
from matplotlib import rc_context
from matplotlib.figure import Figure
from tqdm import tqdm

import beamstops
from beamstops import plots
from beamstops.output_files import save_figure
from beamstops.studies.outputs import StudyFolder

ROOT = Path(__file__).resolve().parents[1]

#: The paper's horizon T (s) and the end of its first contact period (s).
PAPER_T_END = 2.0
FIRST_CONTACT_PERIOD = 0.2
#: The paper's largest stop violation, normal compliance at dt = 5e-7 s (SPEC §2).
PAPER_VIOLATION = 2.25e-4
PAPER_VIOLATION_FIGURE = 7
#: The paper's stability bound for J = 19, beta = 1/4: dt <= 2 sqrt(2/kappa_tilde) (SPEC §2).
PAPER_DT_BOUND = 3.3469e-6


@dataclass(frozen=True)
class PaperFigure:
    """What the paper shows for one figure (SPEC §2 table; axes as printed in the paper)."""

    number: int
    cpu_seconds: float
    """CPU time of the paper's run (s; Scilab on a 1.1 GHz Mac G4), SPEC §2."""
    heading: str
    """The label printed in the paper's plot."""
    xlim: tuple[float, float]
    ylim: tuple[float, float]
    yticks: tuple[float, ...]
    xticks: Optional[tuple[float, ...]] = None


_TICKS_01 = tuple(np.round(np.arange(-0.10, 0.1001, 0.02), 2))
_TICKS_1002 = (-0.1002, -0.0668, -0.0334, 0.0, 0.0334, 0.0668, 0.1002)
PAPER: dict[int, PaperFigure] = {
    2: PaperFigure(2, 18.24, "fem−Newmark scheme", (0.0, 2.0), (-0.10, 0.10), _TICKS_01),
    3: PaperFigure(3, 173.71, "fem−Newmark scheme", (0.0, 2.0), (-0.10, 0.10), _TICKS_01),
    4: PaperFigure(4, 870.45, "fem−Newmark scheme", (0.0, 2.0), (-0.10, 0.10), _TICKS_01),
    5: PaperFigure(5, 241.17, "Normal Compliance − Newmark scheme", (0.0, 1.550), (-0.1048, 0.1085),
                   (-0.1048, -0.0693, -0.0337, 0.0018, 0.0374, 0.0729, 0.1085),
                   (0.000, 0.194, 0.387, 0.581, 0.775, 0.969, 1.162, 1.356, 1.550)),
    6: PaperFigure(6, 1187.9, "Normal Compliance − Newmark scheme", (0.0, 2.0), (-0.1002, 0.1002), _TICKS_1002),
    7: PaperFigure(7, 2426.4, "Normal Compliance − Newmark scheme", (0.0, 2.0), (-0.1002, 0.1002), _TICKS_1002),
    # The text extraction of the paper keeps no tick labels for Figure 8: the ranges of Figures 2-4.
    8: PaperFigure(8, 859.38, "fem−trapezoidal scheme", (0.0, 2.0), (-0.10, 0.10), _TICKS_01),
}

#: Families compared at common record times: (title, figures, reference figure).
FAMILIES: list[tuple[str, tuple[int, ...], int]] = [
    ("Signorini scheme, β = 1/2 (Figures 2, 3, 4)", (2, 3, 4), 4),
    ("normal compliance, β = 1/4 (Figures 5, 6, 7)", (5, 6, 7), 7),
    ("Signorini scheme at Δt = 1e-6 s, β = 1/4 against β = 1/2 (Figures 8, 4)", (8, 4), 4),
]


@dataclass
class Run:
    """What the report keeps of one run (the tip history and the attributes)."""

    figure: int
    scene: beamstops.Scene
    t: np.ndarray
    tip_u: np.ndarray
    attrs: dict


def parse_args(argv: Optional[Sequence[str]]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--t-end", type=float, default=None,
                        help="shorten every run to this horizon (s); default: the namelists' (the paper's 2 s)")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "paper", help="output directory (default out/paper)")
    parser.add_argument("--input", type=Path, default=ROOT / "input", help="directory of paper_figN.nml (default input)")
    parser.add_argument("--figures", type=int, nargs="+", default=sorted(PAPER), choices=sorted(PAPER),
                        metavar="N", help="figures to run (default: 2 to 8)")
    return parser.parse_args(argv)


def scene_of(figure: int, input_dir: Path, t_end: Optional[float]) -> beamstops.Scene:
    scene = beamstops.Scene.from_namelist(input_dir / f"paper_fig{figure}.nml")
    if t_end is not None:
        scene = scene.replace(t_end=min(t_end, scene.t_end))
    return scene


def run_all(scenes: dict[int, beamstops.Scene]) -> dict[int, Run]:
    """Run every scene, with a progress bar across runs (weighted by their steps)."""
    steps = {n: max(1, round(s.t_end / s.dt)) for n, s in scenes.items()}
    runs: dict[int, Run] = {}
    with tqdm(total=sum(steps.values()), unit="step", unit_scale=True, desc="paper figures",
              dynamic_ncols=True) as bar:
        for n, scene in scenes.items():
            bar.set_postfix_str(f"figure {n}: dt = {scene.dt:g} s, {steps[n]} steps")
            result = beamstops.run(scene)
            runs[n] = Run(n, scene, result.t, result.tip_u, dict(result.attrs))
            bar.update(steps[n])
    return runs


def draw_figure(run: Run, path: Path) -> None:
    """The tip displacement on the paper's axis ranges and ticks, with the stops."""
    paper = PAPER[run.figure]
    fig = Figure(figsize=(7.5, 4.2), layout="constrained")
    ax = fig.add_subplot()
    result = beamstops.Result(t=run.t, tip_u=run.tip_u, tip_v=np.empty(0), reaction=np.empty(0),
                              energy=np.empty(0), work=np.empty(0), dissipated=np.empty(0),
                              snapshot_t=np.empty(0), snapshot_x=np.empty(0), snapshot_u=np.empty((0, 0)),
                              attrs=run.attrs)
    a = run.attrs
    horizon = "" if a["t_end"] >= PAPER_T_END else f", run to t = {a['t_end']:g} s"
    plots.plot_tip(result, ax, xlim=paper.xlim, ylim=paper.ylim,
                   title=f"Figure {run.figure}: {paper.heading} (Δt = {a['dt']:g} s, β = {a['beta']:g}{horizon})")
    ax.set_yticks(paper.yticks)
    if paper.xticks is not None:
        ax.set_xticks(paper.xticks)
    with rc_context({"agg.path.chunksize": 20000}):
        save_figure(fig, path, dpi=120)


def common(a: Run, b: Run) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times both runs recorded (on the coarser record grid) and the tip values there."""
    spacing = max(a.attrs["dt"] * a.attrs["record_every"], b.attrs["dt"] * b.attrs["record_every"])

    def keyed(run: Run) -> tuple[np.ndarray, np.ndarray]:
        k = np.rint(run.t / spacing)
        on_grid = np.abs(run.t / spacing - k) < 1e-6
        return k[on_grid].astype(np.int64), run.tip_u[on_grid]

    ka, ua = keyed(a)
    kb, ub = keyed(b)
    k, ia, ib = np.intersect1d(ka, kb, assume_unique=True, return_indices=True)
    return k * spacing, ua[ia], ub[ib]


def agreement(a: Run, b: Run, split: float) -> dict[str, float]:
    t, ua, ub = common(a, b)
    gap = np.abs(ua - ub)
    early, late = t <= split + 1e-12, t > split + 1e-12
    over = np.nonzero(gap > 1e-3)[0]
    return {
        "early": float(gap[early].max()) if early.any() else float("nan"),
        "late": float(gap[late].max()) if late.any() else float("nan"),
        "first_mm": float(t[over[0]]) if over.size else float("nan"),
        "points": int(t.size),
    }


def draw_agreement(runs: dict[int, Run], path: Path, until: float) -> None:
    families = [(title, [n for n in members if n in runs]) for title, members, _ in FAMILIES[:2]]
    families = [(title, members) for title, members in families if members]
    if not families:
        return
    fig = Figure(figsize=(8, 3.2 * len(families)), layout="constrained")
    axes = fig.subplots(len(families), 1, squeeze=False)[:, 0]
    for ax, (title, members) in zip(axes, families):
        for n in members:
            run = runs[n]
            keep = run.t <= until
            ax.plot(run.t[keep], run.tip_u[keep], linewidth=0.8, label=f"Figure {n}: Δt = {run.attrs['dt']:g} s")
        first = runs[members[0]]
        for g in (first.attrs["lower"], first.attrs["upper"]):
            ax.axhline(g, color="tab:red", linewidth=0.8, linestyle="--")
        ax.axvline(FIRST_CONTACT_PERIOD, color="0.5", linewidth=0.8, linestyle=":")
        ax.set_xlim(0, until)
        ax.set_title(title, fontsize="medium")
        ax.set_xlabel("t (s)")
        ax.set_ylabel("u(L, t) (m)")
        ax.legend(fontsize="small")
    save_figure(fig, path, dpi=120)


def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def fmt(x: float, spec: str = ".3g") -> str:
    return "—" if x is None or (isinstance(x, float) and np.isnan(x)) else format(x, spec)


def report(runs: dict[int, Run], args: argparse.Namespace, argv: Sequence[str]) -> str:
    shortened = any(r.attrs["t_end"] < PAPER_T_END for r in runs.values())
    horizon = min(r.attrs["t_end"] for r in runs.values())
    split = min(FIRST_CONTACT_PERIOD, horizon)
    lines = [
        "# Dumont & Paoli, \"Vibrations of a beam between stops\": the numerical results reproduced",
        "",
        "<!-- Generated by scripts/paper_figures.py; do not edit by hand: run the script again. -->",
        "",
        f"Generated {datetime.datetime.now().isoformat(timespec='seconds')} by "
        f"`{shlex.join(['python', 'scripts/paper_figures.py', *argv])}` with beamstops {beamstops.version()} "
        f"(engine in memory, `beamstops.run`) on {cpu_model()}, Python {platform.python_version()}.",
        "The paper's numbers (CPU times, stop violation, stability bound) are those of SPEC.md §2; "
        "everything else comes from the runs.",
        "",
    ]
    if shortened:
        lines += [f"**Shortened horizon: the runs stop at t = {horizon:g} s, not the paper's {PAPER_T_END:g} s.** "
                  "CPU times are compared per time step.", ""]

    lines += ["## CPU time and stop violation", "",
              "Ours is the engine's own `cpu_seconds` (the time loop); the paper's ran in Scilab on a 1.1 GHz "
              "Mac G4. Ratio = paper / ours" + (", per time step." if shortened else "."), "",
              "| figure | law | β | Δt (s) | steps | paper CPU (s) | our CPU (s) | ratio | impacts "
              "| largest stop violation (m) | paper |",
              "|---|---|---|---|---|---|---|---|---|---|---|"]
    for n, run in runs.items():
        a = run.attrs
        paper = PAPER[n]
        paper_steps = round(PAPER_T_END / a["dt"])
        ours = a["cpu_seconds"]
        ratio = (paper.cpu_seconds / paper_steps) / (ours / a["steps"]) if ours > 0 else float("nan")
        if a["law"] == "signorini":
            paper_violation = "0 (never violated)"
        elif n == PAPER_VIOLATION_FIGURE:
            paper_violation = f"{PAPER_VIOLATION:.3g}"
        else:
            paper_violation = "—"
        lines.append(f"| {n} | {a['law']} | {a['beta']:g} | {a['dt']:g} | {a['steps']} | {paper.cpu_seconds:g} | "
                     f"{ours:.3g} | {fmt(ratio, '.0f')} | {a['impacts']} | {a['max_violation']:.3g} | "
                     f"{paper_violation} |")
    lines.append("")
    signorini = [r for r in runs.values() if r.attrs["law"] == "signorini"]
    if signorini:
        worst = max(r.attrs["max_violation"] for r in signorini)
        lines.append(f"- Signorini scheme: largest violation over Figures "
                     f"{', '.join(str(r.figure) for r in signorini)} = {worst:g} m "
                     f"({'never violated, as in the paper' if worst == 0 else 'VIOLATED'}).")
    if PAPER_VIOLATION_FIGURE in runs:
        v = runs[PAPER_VIOLATION_FIGURE].attrs["max_violation"]
        lines.append(f"- Normal compliance at Δt = {runs[PAPER_VIOLATION_FIGURE].attrs['dt']:g} s: largest "
                     f"violation {v:.3g} m against the paper's {PAPER_VIOLATION:.3g} m "
                     f"(ratio {v / PAPER_VIOLATION:.2f})" + (" — over the shortened horizon only." if shortened
                                                               else "."))
    lines.append("")

    lines += [f"## Agreement between time steps (up to t = {split:g} s and after)", "",
              "The paper: the trajectories for different Δt are almost the same up to the end of the first "
              "contact period (t ≤ 0.2 s) and differ in detail afterwards (sensitivity to data). "
              "Largest |Δu(L, t)| at the record times both runs share, against the family's reference run:", "",
              "| family | figure | against | max \\|Δu\\| for t ≤ %g s (m) | max \\|Δu\\| after (m) "
              "| first t with \\|Δu\\| > 1 mm (s) |" % split,
              "|---|---|---|---|---|---|"]
    for title, members, reference in FAMILIES:
        if reference not in runs:
            continue
        for n in members:
            if n == reference or n not in runs:
                continue
            g = agreement(runs[n], runs[reference], split)
            lines.append(f"| {title} | {n} (Δt = {runs[n].attrs['dt']:g}) | {reference} "
                         f"(Δt = {runs[reference].attrs['dt']:g}) | {fmt(g['early'])} | {fmt(g['late'])} | "
                         f"{fmt(g['first_mm'], '.4f')} |")
    lines.append("")

    quarter = [r for r in runs.values() if r.attrs["beta"] == 0.25]
    if quarter:
        a = quarter[0].attrs
        lines += ["## Stability bound", "",
                  f"For J = {a['elements']} and β = 1/4 the paper's condition (3.1) with its bound κ̃ gives "
                  f"Δt ≤ {PAPER_DT_BOUND:.5g} s; the engine: κ̃ = {a['kappa_bound']:.5g} 1/s², "
                  f"Δt ≤ {a['dt_limit_paper_bound']:.5g} s. With the exact κ_h = {a['kappa_h']:.5g} 1/s², "
                  f"(3.1) allows Δt < {a['dt_limit_paper']:.5g} s.", ""]

    lines += ["## Figures", ""]
    for n, run in runs.items():
        lines.append(f"- Figure {n} ({PAPER[n].heading}, Δt = {run.attrs['dt']:g} s, β = {run.attrs['beta']:g}): "
                     f"[fig{n}.png](fig{n}.png), drawn on the paper's axis ranges "
                     f"t ∈ [{PAPER[n].xlim[0]:g}, {PAPER[n].xlim[1]:g}] s, "
                     f"u ∈ [{PAPER[n].ylim[0]:g}, {PAPER[n].ylim[1]:g}] m.")
    lines += ["- [agreement.png](agreement.png): each family overlaid on the first contact period.", ""]
    return "\n".join(lines)


def main(argv: Optional[Sequence[str]] = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    args = parse_args(argv)
    try:
        scenes = {n: scene_of(n, args.input, args.t_end) for n in sorted(set(args.figures))}
        out = StudyFolder.prepare(args.out, "paper_figures",  # every file checked before anything runs
                                  [f"fig{n}.png" for n in scenes] + ["agreement.png", "report.md"])
        runs = run_all(scenes)
    except (OSError, ValueError) as exc:
        print(f"paper_figures: error: {exc}", file=sys.stderr)
        return 1
    try:
        for n, run in runs.items():
            draw_figure(run, out.path(f"fig{n}.png"))
        draw_agreement(runs, out.path("agreement.png"), until=min(0.3, max(r.attrs["t_end"] for r in runs.values())))
        out.markdown("report.md", report(runs, args, argv))
    except OSError as exc:
        print(f"paper_figures: error: {exc}", file=sys.stderr)
        return 1
    print(args.out / "report.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())

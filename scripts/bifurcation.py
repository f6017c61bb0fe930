#!/usr/bin/env python3
"""Bifurcation diagram: the tip's stroboscopic displacement against the forcing frequency ω.

Runs the sweep input/sweeps/bifurcation.toml (``python -m beamstops sweep``'s machinery,
resumable: a second call only draws) and draws from its summary table:

- top: u(L, kT), T = 2π/ω, for every k after the transient (one dot per sample), with
  the stops; a point whose samples repeat with a period p (``strobe_period``) is drawn
  in the colour of its p (1, 2, 3, ≥ 4), the others in black;
- bottom: the energy the stops take per forcing period over the whole run (and the
  Rayleigh damping's, when the sweep has a ``damped`` reduction), and the number of
  shocks (the engine's ``impacts``) per period.

Beside the image, a markdown table (same name, ``.md``): how many values of ω settle on a
period-p motion at the stroboscope (from ``strobe_period``), and the windows of ω where they do.

Usage::

    python scripts/bifurcation.py                      # 300 points, out/bifurcation/bifurcation.png
    python scripts/bifurcation.py --spec input/sweeps/bifurcation_damped.toml   # ζ = 1.5 %, out/bifurcation_damped/
    python scripts/bifurcation.py --quick              # 12 short points (a test), out/bifurcation-quick/
    python scripts/bifurcation.py -j 8 -o DIR --png FILE
    mpiexec -n 9 python -m mpi4py.futures scripts/bifurcation.py   # on MPI ranks

Every number comes from the engine's HDF5 outputs (the program's runs); this script only
samples and draws them.
"""

from __future__ import annotations

import argparse
import math
import shlex
import sys
from pathlib import Path
from typing import Any, Optional, Sequence

import numpy as np
from matplotlib import rc_context
from matplotlib.figure import Figure

from beamstops import sweep
from beamstops.output_files import save_figure
from beamstops.studies.outputs import StudyFolder

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "input" / "sweeps" / "bifurcation.toml"
#: --quick: a dozen short runs, for tests and a first look (a different hash, so another folder).
QUICK = ("axes.omega.num=12", "periods.t_end=16", "reductions.strobe.transient_periods=8",
         "reductions.u_max.after_periods=8")


#: Colours of the period classes: (label, test on strobe_period, colour).
CLASSES = (("no period ≤ max_period", lambda p: p == 0, "k"), ("period 1", lambda p: p == 1, "tab:blue"),
           ("period 2", lambda p: p == 2, "tab:orange"), ("period 3", lambda p: p == 3, "tab:green"),
           ("period ≥ 4", lambda p: p >= 4, "tab:purple"))


def periods_table(rows: list[dict[str, Any]]) -> str:
    """Markdown: values of ω per stroboscopic period p (0: none found), and the windows of ω (runs of
    successive values of ω with the same p > 0), from the sweep's ``strobe_period`` column."""
    done = sorted((r for r in rows if r.get("status") == "complete" and r.get("strobe")), key=lambda r: r["omega"])
    total = len(done)
    counts: dict[int, int] = {}
    for r in done:
        counts[int(r["strobe_period"])] = counts.get(int(r["strobe_period"]), 0) + 1
    lines = ["| stroboscopic period p | values of ω | fraction |", "|---|---|---|"]
    for p in sorted(counts, key=lambda p: (p == 0, p)):
        lines.append(f"| {p if p else 'none ≤ max_period'} | {counts[p]} | {counts[p] / total:.1%} |")
    periodic = total - counts.get(0, 0)
    lines += ["", f"Periodic (any p): {periodic} of {total} values of ω ({periodic / max(total, 1):.1%}).", "",
              "| window of ω (rad/s) | p | values of ω |", "|---|---|---|"]
    start, windows = 0, 0
    for i in range(1, total + 1):
        if i == total or done[i]["strobe_period"] != done[start]["strobe_period"]:
            p = int(done[start]["strobe_period"])
            if p and i - start >= 2:
                lines.append(f"| {done[start]['omega']:.4g} – {done[i - 1]['omega']:.4g} | {p} | {i - start} |")
                windows += 1
            start = i
    if not windows:
        lines.append("| none | – | 0 |")
    lines.append("")
    lines.append("Windows of at least two successive values of ω; period p: the smallest p ≤ max_period with "
                 "|u(L, (k+p)T) − u(L, kT)| ≤ tolerance for every sample after the transient.")
    return "\n".join(lines) + "\n"


def draw(rows: list[dict[str, Any]], path: Path, title: str = "", stops: Sequence[float] = ()) -> Path:
    """The diagram of a sweep's summary rows (an axis omega, a strobe reduction named 'strobe')."""
    done = [r for r in rows if r.get("status") == "complete" and r.get("strobe")]
    bad = [r for r in rows if r.get("status") not in ("complete", "pending")]
    with rc_context({"font.size": 9}):
        fig = Figure(figsize=(8.0, 6.4), constrained_layout=True)
        top, bottom = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1.3]})
        for label, test, colour in CLASSES:
            chosen = [r for r in done if test(int(r.get("strobe_period") or 0))]
            x = np.concatenate([np.full(len(r["strobe"]), r["omega"]) for r in chosen]) if chosen else np.empty(0)
            y = np.concatenate([np.asarray(r["strobe"], dtype=float) for r in chosen]) if chosen else np.empty(0)
            if x.size:
                top.scatter(x, y, s=1.5 if colour == "k" else 3, linewidths=0, color=colour,
                            label=f"{label} ({len(chosen)} values of ω)")
        if bad:
            top.scatter([r["omega"] for r in bad], np.zeros(len(bad)), marker="x", color="tab:red", s=12,
                        label=f"failed or diverged ({len(bad)})")
        for g in stops:
            top.axhline(g, color="tab:red", linewidth=0.8, linestyle="--")
        top.set_ylabel("tip displacement u(L, kT) (m)")
        top.set_title(title or "Stroboscopic tip displacement, T = 2π/ω")
        if len(top.get_legend_handles_labels()[0]):
            top.legend(loc="upper right", fontsize=7, markerscale=4)
        omega = np.array([r["omega"] for r in done])
        if omega.size:
            periods = np.array([r["t_end"] * r["omega"] / (2 * math.pi) for r in done])
            energy = np.array([(r.get("dissipated") or 0.0) for r in done]) / periods
            impacts = np.array([(r.get("impacts") or 0) for r in done]) / periods
            bottom.plot(omega, energy, color="k", linewidth=0.8, label="energy taken by the stops per period (J)")
            if any(r.get("damped") is not None for r in done):
                damped = np.array([(r.get("damped") or 0.0) for r in done]) / periods
                bottom.plot(omega, damped, color="tab:green", linewidth=0.8, label="energy taken by damping per period (J)")
            bottom.set_ylabel("J per period")
            twin = bottom.twinx()
            twin.plot(omega, impacts, color="tab:orange", linewidth=0.8, label="shocks per period")
            twin.set_ylabel("shocks per period", color="tab:orange")
            bottom.legend(loc="upper left", fontsize=7)
        bottom.set_xlabel("forcing frequency ω (rad/s)")
        save_figure(fig, path, dpi=150)
    return path


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--spec", type=Path, default=SPEC, help=f"sweep specification (default: {SPEC.relative_to(ROOT)})")
    parser.add_argument("-o", "--output", type=Path, help="sweep folder (default: out/SPEC's name, "
                                                          "out/SPEC's name-quick with --quick)")
    parser.add_argument("--png", type=Path, help="image (default: OUTPUT/bifurcation.png)")
    parser.add_argument("--quick", action="store_true", help="12 short points (tests)")
    parser.add_argument("-j", "--jobs", type=int, help="local worker processes (default: every core)")
    parser.add_argument("--executor", choices=sweep.EXECUTORS, default="auto")
    parser.add_argument("--set", action="append", default=[], metavar="TABLE.KEY=VALUE",
                        help="change the specification (see python -m beamstops sweep --help)")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress")
    args = parser.parse_args(argv)

    overrides = (list(QUICK) if args.quick else []) + list(args.set)
    out = args.output or ROOT / "out" / (args.spec.stem + ("-quick" if args.quick else ""))
    png = args.png or out / "bifurcation.png"
    try:
        spec = sweep.load_spec(args.spec, overrides=overrides)
        # the chart and its table checked before the sweep runs (beamstops.studies.outputs)
        files = StudyFolder.prepare(png.parent, "bifurcation", [png.name, png.with_suffix(".md").name])
        outcome = sweep.run_sweep(spec, out, executor=args.executor, jobs=args.jobs,
                                  stream=None if args.quiet else sys.stderr)
        rows = sweep.read_summary(out)
    except (OSError, ValueError) as exc:
        print(f"bifurcation: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
    scene = spec.points[0].scene
    ratios = dict.fromkeys(scene.ratio)  # one value when both modes have the same ratio
    damping = f", damping ζ = {', '.join(f'{z:g}' for z in ratios)}" if ratios else ""
    title = (f"Stroboscopic tip displacement u(L, kT), T = 2π/ω\n{len(rows)} values of ω, "
             f"k ≥ {spec.reductions['strobe']['transient_periods']} of {spec.periods['t_end']:g} periods{damping}")
    draw(rows, png, title=title, stops=(scene.lower, scene.upper))
    command = "python scripts/bifurcation.py" + (" --quick" if args.quick else "") + (
        f" --spec {shlex.quote(str(args.spec.relative_to(ROOT) if args.spec.is_relative_to(ROOT) else args.spec))}"
        if args.spec.resolve() != SPEC else "") + "".join(f" --set {shlex.quote(s)}" for s in args.set)
    files.markdown(png.with_suffix(".md").name, f"# {title.replace(chr(10), ': ')}\n\n![bifurcation diagram]({png.name})"
                   f"\n\n{periods_table(rows)}\nRegenerate: `{command}`\n")
    print(f"{png}  ({outcome.complete}/{outcome.total} points complete; regenerate: {command})")
    return 0


if __name__ == "__main__":
    sys.exit(main())

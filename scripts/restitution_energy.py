"""The energy the stops take with an elastic restitution (e = 1) against Δt: the README's figures.

The README's "The energy ledger" quotes, for the paper's Figure 2 scene (input/paper_fig2.nml)
with ``&stops restitution = 1.0``, the stops' figure of the summary line (the root attribute
``dissipated``, J) and the support's work at three time steps. They come from

    python scripts/restitution_energy.py

(Δt = 1e-4, 1e-5 and 1e-6 s over the scene's 2 s; about a second of CPU). ``--quick`` runs the
same scenes over 0.2 s, for tests. Every number is the engine's (:func:`beamstops.run`, the same
loop and bits as ``beamstops run``); prints a markdown table and the README's sentence.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Optional, Sequence

import beamstops

DTS = (1e-4, 1e-5, 1e-6)
SCENE = Path(__file__).resolve().parents[1] / "input" / "paper_fig2.nml"


def ledger(scene: beamstops.Scene, dt: float) -> tuple[float, float]:
    """The stops' energy and the support's work (J) at the end of the scene run with ``dt``, e = 1."""
    result = beamstops.run(scene.replace(restitution=1.0, dt=dt, record_every=1000))
    return float(result.attrs["dissipated"]), float(result.attrs["work"])


def signed(value: float) -> str:
    """Three significant digits, a negative value with the minus sign (−) the README writes."""
    return f"{value:.3g}".replace("-", "\u2212", 1) if value < 0 else f"{value:.3g}"


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="restitution_energy", description=__doc__.splitlines()[0])
    parser.add_argument("--scene", type=Path, default=SCENE, help="namelist of the scene (default: %(default)s)")
    parser.add_argument("--quick", action="store_true", help="0.2 s instead of the scene's t_end (seconds)")
    args = parser.parse_args(argv)
    try:
        scene = beamstops.Scene.from_namelist(args.scene)
    except (OSError, ValueError) as exc:
        print(f"restitution_energy: error: {exc}", file=sys.stderr)
        return 1
    if args.quick:
        scene = scene.replace(t_end=0.2)
    rows = [(dt, *ledger(scene, dt)) for dt in DTS]
    print(f"{args.scene.name}, &stops restitution = 1.0, t_end = {scene.t_end:g} s\n")
    print("| Δt (s) | stops (J) | support work (J) |\n|---|---|---|")
    for dt, stops, work in rows:
        print(f"| {dt:g} | {stops:.3g} | {work:.3g} |")
    said = ", ".join(f"{signed(stops)} J at Δt = {dt:g} s" for dt, stops, _ in rows)
    works = ", ".join(signed(work) for _, _, work in rows[:-1]) + f" and {signed(rows[-1][2])} J"
    print(f"\n{said}, against a support work of {works}.")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Cost per step of stops along the span against their number m (issue 8).

For J = 19 and J = 1000 elements and m = 1, 2, 4, 8, 16 stops spread along the beam (the
tip always among them), the time loop's CPU time per step (the engine's ``cpu_seconds``
over ``steps``, the best of a few runs) in three regimes:

- ``free``: gaps never reached (the trial check only, O(m) beyond a free step);
- ``contact``: the paper's scene with gaps of 5 mm at every stop: the QP on most steps,
  several stops active at once;
- the tip-only path (the rank-one projection) and no stops at all, for reference.

Prints a table of microseconds per step, the fraction of steps with a stop acting and the
most stops acting at once (with --out, also as a markdown file).

    python scripts/bench_stops.py [--repeat 3] [--steps 20000] [--out docs/stops/bench_stops.md]
"""

from __future__ import annotations

import argparse
import os
import platform
from pathlib import Path

import numpy as np

import beamstops
from beamstops import Scene


def spread(elements: int, m: int) -> tuple[int, ...]:
    """m distinct nodes spread over 1..J, the last one the tip."""
    nodes = np.unique(np.round(np.linspace(elements, 0, m, endpoint=False)[::-1]).astype(int))
    return tuple(int(n) for n in nodes)


def measure(scene: Scene, repeat: int) -> tuple[float, beamstops.Result]:
    best, result = float("inf"), None
    for _ in range(repeat):
        result = beamstops.run(scene)
        best = min(best, result.attrs["cpu_seconds"] / result.attrs["steps"])
    assert result is not None
    return 1e6 * best, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=3, help="runs per point, the fastest kept (default 3)")
    parser.add_argument("--steps", type=int, default=20000, help="time steps per run at J = 1000 (default 20000)")
    parser.add_argument("--out", type=Path, help="also write the table as markdown to this file")
    args = parser.parse_args()
    rows: list[tuple[str, ...]] = []

    def row(*cells: str) -> None:
        rows.append(cells)
        print(f"{cells[0]:>5} {cells[1]:>8} {cells[2]:>9} {cells[3]:>9} {cells[4]:>19} {cells[5]:>13}")

    print(f"beamstops {beamstops.version()}: microseconds per step (best of {args.repeat})")
    print(f"{'J':>5} {'stops':>8} {'free':>9} {'contact':>9} {'steps with contact':>19} {'most at once':>13}")
    for elements in (19, 1000):
        steps = args.steps * (20 if elements == 19 else 1)
        dt = 2e-5
        base = Scene(elements=elements, dt=dt, t_end=steps * dt, beta=0.25, record_every=steps)
        none, _ = measure(base.replace(law="none"), args.repeat)
        tip_free, _ = measure(base.replace(lower=-10.0, upper=10.0), args.repeat)
        tip, _ = measure(base.replace(lower=-0.005, upper=0.005), args.repeat)
        row(str(elements), "none", f"{none:.3f}", "", "", "")
        row(str(elements), "tip", f"{tip_free:.3f}", f"{tip:.3f}", "", "")
        for m in (1, 2, 4, 8, 16):
            nodes = spread(elements, m)
            free, _ = measure(base.replace(nodes=nodes, lower=-10.0, upper=10.0), args.repeat)
            scene = base.replace(nodes=nodes, lower=-0.005, upper=0.005)
            contact, _ = measure(scene, args.repeat)
            # the same run with every record, to count the stops acting (timed apart: records cost)
            result = beamstops.run(scene.replace(record_every=1))
            acting = np.count_nonzero(result.stops_reaction, axis=1)
            row(str(elements), f"m = {len(nodes)}", f"{free:.3f}", f"{contact:.3f}", f"{np.mean(acting > 0):.1%}",
                str(int(acting.max())))
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        lines = [f"Stops along the span: time loop's CPU time per step (µs, best of {args.repeat}), "
                 f"beamstops {beamstops.version()}, {platform.processor() or platform.machine()}, "
                 f"{os.cpu_count()} CPUs; `python scripts/bench_stops.py`.", "",
                 "'free': gaps never reached (the check of the m trial values only); 'contact': gaps of 5 mm "
                 "at every stop of the paper's beam (the QP on most steps). 'tip' is the tip-only path "
                 "(rank-one projection), 'none' no stops.", "",
                 "| J | stops | free | contact | steps with contact | most stops acting at once |",
                 "|---:|---:|---:|---:|---:|---:|"]
        lines += ["| " + " | ".join(cells) + " |" for cells in rows]
        args.out.write_text("\n".join(lines) + "\n")
        print(args.out)


if __name__ == "__main__":
    main()

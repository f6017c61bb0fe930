#!/usr/bin/env python3
"""A sweep over ω at one fixed Δt: wall time one point per process against lockstep batches.

    python scripts/bench_sweep.py                # 300 points, damped and undamped beam (a few minutes)
    python scripts/bench_sweep.py --quick        # 40 points, shorter runs, one repeat
    python scripts/bench_sweep.py --program build/bench/beamstops --jobs 2 --out sweep.md

The paper's scene (J = 19, β = 1/2, Signorini tip stops ±0.1 m, a = 0.2 m), Δt = 1e-5 s,
t_end = 0.5 s (50,000 steps), the tip recorded every 10 steps, ω evenly spaced from 5 to
60 rad/s; the damped beam adds &damping ratio = 0.015 at modes 1 and 2. Each sweep runs
twice on the same cores (``-j``, default every core), into fresh folders: with
``[sweep] lockstep = 1`` (one ``beamstops run`` per point: today's sweeps) and with
``lockstep = K`` (default 8: batches of K points, the engine runs those that share A in
lockstep). Reported: the wall time of each (the whole sweep: processes, HDF5 files,
reductions, summary), their ratio, the engine's CPU seconds summed over the points, how many
points the engine ran in lockstep, and whether the two summaries agree (every column but the
timings). scripts/bench.py runs this as one of its sections.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

SPEC = """
[sweep]
description = "bench: omega sweep at one dt ({label})"
lockstep = {lockstep}
[scene]
elements = 19
beta = 0.5
dt = 1e-5
t_end = {t_end}
record_every = 10
{damping}
[axes]
omega = {{ start = 5, stop = 60, num = {points} }}
[reductions.u_max]
kind = "max"
quantity = "tip_u"
"""

TIMING = ("cpu_seconds", "wall_seconds")


def run_one(program: str, folder: Path, points: int, t_end: float, damped: bool, lockstep: int,
            jobs: int | None) -> dict[str, Any]:
    """One sweep into a fresh folder: its wall time, engine CPU, points in lockstep, rows."""
    from beamstops.sweep import parse_spec, read_summary, run_sweep
    import tomllib

    text = SPEC.format(label="damped" if damped else "undamped", lockstep=lockstep, t_end=t_end, points=points,
                       damping="ratio = 0.015" if damped else "")
    spec = parse_spec(tomllib.loads(text), f"bench_sweep ({'damped' if damped else 'undamped'})", text=text)
    out = folder / f"{'damped' if damped else 'free'}-{lockstep}"
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    outcome = run_sweep(spec, out, executor="local", jobs=jobs, program=program, stream=None)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)  # the pool's workers and their programs, waited for
    processes = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    rows = read_summary(out)
    shutil.rmtree(out, ignore_errors=True)
    return {"wall": wall, "processes": processes, "cpu": sum(r.get("cpu_seconds") or 0.0 for r in rows), "lockstep": outcome.lockstep,
            "complete": outcome.complete, "points": outcome.total,
            "rows": [{k: v for k, v in r.items() if k not in TIMING} for r in rows]}


def section(program: str, quick: bool = False, *, jobs: int | None = None, batch: int = 8,
            scenes: tuple[str, ...] = ("damped", "undamped"), points: int | None = None,
            repeats: int | None = None) -> list[str]:
    """The markdown of the benchmark (a heading, a sentence, a table)."""
    import statistics

    points = points or (40 if quick else 300)
    repeats = repeats or (1 if quick else 3)
    t_end = 0.2 if quick else 0.5
    workers = jobs or os.cpu_count() or 1
    lines = [f"### A sweep over ω at one Δt (scripts/bench_sweep.py{' --quick' if quick else ''})\n",
             f"{points} values of ω from 5 to 60 rad/s, the paper's scene (J = 19, β = 1/2), Δt = 1e-5 s, "
             f"t_end = {t_end:g} s ({round(t_end / 1e-5):,} steps), tip recorded every 10 steps; "
             f"{workers} worker process{'es' if workers > 1 else ''}. Wall time of the whole sweep "
             f"(`python -m beamstops sweep`), one `beamstops run` per point (`lockstep = 1`) against batches "
             f"of {batch} (`lockstep = {batch}`: the engine runs the points that share A in lockstep); "
             f"medians of {repeats} repeat{'s' if repeats > 1 else ''}, the two runs alternating; load average "
             f"before: {os.getloadavg()[0]:.1f}.\n",
             "| beam | wall, one per point (s) | wall, batches (s) | speed-up | engine CPU, one per point (s) "
             "| engine CPU, batches (s) | CPU of all processes, one per point (s) | CPU of all processes, "
             "batches (s) | points in lockstep | same summary |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as tmp:
        for label in scenes:
            damped = label == "damped"
            runs: dict[int, list[dict[str, Any]]] = {1: [], batch: []}
            for _ in range(repeats):
                for lockstep in (1, batch):
                    runs[lockstep].append(run_one(program, Path(tmp), points, t_end, damped, lockstep, jobs))
            alone, batched = runs[1][-1], runs[batch][-1]
            wall = {k: statistics.median(r["wall"] for r in v) for k, v in runs.items()}
            cpu = {k: statistics.median(r["cpu"] for r in v) for k, v in runs.items()}
            total = {k: statistics.median(r["processes"] for r in v) for k, v in runs.items()}
            same = "yes" if all(r["rows"] == alone["rows"] for r in runs[1] + runs[batch]) else "**NO**"
            lines.append(f"| {label} | {wall[1]:.2f} | {wall[batch]:.2f} | {wall[1] / wall[batch]:.2f}× | "
                         f"{cpu[1]:.2f} | {cpu[batch]:.2f} | {total[1]:.2f} | {total[batch]:.2f} | {batched['lockstep']} of {batched['points']} | {same} |")
    lines.append("\nEngine CPU: the sum of the points' `cpu_seconds` (a lockstep member's is its share of "
                 "its group's loop). CPU of all processes: user + system time of the sweep's workers and their "
                 "`beamstops` programs (start-up, HDF5 files, reductions; less sensitive to a loaded machine "
                 "than the wall time). Points in lockstep: the engine's own count (`beamstops run` with several "
                 "scenes says how it grouped them).")
    return lines


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="40 points of 0.2 s (seconds of measuring)")
    parser.add_argument("--program", help="the beamstops program (default: the one sweeps find)")
    parser.add_argument("--jobs", "-j", type=int, help="worker processes (default: every core)")
    parser.add_argument("--batch", type=int, default=8, help="points per batch, [sweep] lockstep (default 8)")
    parser.add_argument("--points", type=int, help="values of omega (default 300, quick 40)")
    parser.add_argument("--scene", choices=("damped", "undamped", "both"), default="both")
    parser.add_argument("--repeats", type=int, help="repeats of each sweep (default 3, quick 1)")
    parser.add_argument("--out", type=Path, help="also write the markdown here")
    args = parser.parse_args()
    from beamstops.sweep.runner import find_program

    program = find_program(args.program)
    scenes = ("damped", "undamped") if args.scene == "both" else (args.scene,)
    text = "\n".join(section(program, args.quick, jobs=args.jobs, batch=args.batch, scenes=scenes,
                             points=args.points, repeats=args.repeats)) + "\n"
    print(text)
    if args.out:
        args.out.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())

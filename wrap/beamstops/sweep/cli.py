"""``python -m beamstops sweep SPEC -o DIR``: run a parameter sweep (see :mod:`beamstops.sweep`)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..arguments import number, whole

EPILOG = """\
examples:
  python -m beamstops sweep input/sweeps/bifurcation.toml -o out/bifurcation          # every core
  python -m beamstops sweep SPEC -o DIR -j 4 --set axes.omega.num=20                  # 4 processes, fewer points
  mpiexec -n 9 python -m mpi4py.futures -m beamstops sweep SPEC -o DIR                # 8 MPI workers
Running the same command again resumes: finished points are skipped. A folder holds one
specification only. Summary: DIR/summary.csv (and summary.json); outputs: DIR/points/.
exit status: 0 every point complete; 3 some point failed (timed out, crashed, its output could
not be written) or diverged (the summary says which; running the same command again retries the
failed ones); 1 a bad specification (--set values included; a point whose scene the engine
refuses: a value out of range, a time step beyond the stability limit), no -o, a folder that cannot be used (another
specification's, not a sweep's, or locked by a running sweep), no program, or MPI that cannot
start its workers; 2 a bad command-line option (unknown, or a value
out of range: -j, --timeout, --interval, --executor), refused before anything is written;
130 interrupted.
"""

#: Exit status of a sweep in which some point failed (refused, timed out) or diverged, as for
#: `beamstops run A.nml B.nml ...` with a scene that did not complete.
INCOMPLETE = 3


def _sweep(args: argparse.Namespace) -> int:
    from .runner import run_sweep
    from .spec import load_spec

    spec = load_spec(args.spec, overrides=args.set or ())
    if args.dry_run:
        return _dry_run(spec, args)
    if args.output is None:
        raise ValueError("sweep: name the output folder with -o DIR")
    stream = None if args.quiet else sys.stderr
    try:
        outcome = run_sweep(spec, args.output, executor=args.executor, jobs=args.jobs, program=args.program,
                            timeout=args.timeout, stream=stream, interval=args.interval)
    except KeyboardInterrupt:
        return 130
    if outcome.complete == outcome.total:
        return 0
    print(f"beamstops: error: sweep: {outcome.total - outcome.complete} of {outcome.total} points did not "
          f"complete ({outcome.failed} failed, {outcome.diverged} diverged); their messages are in "
          f"{outcome.summary}; running the same command again retries the failed ones", file=sys.stderr)
    return INCOMPLETE


def _dry_run(spec, args: argparse.Namespace) -> int:  # type: ignore[no-untyped-def]
    points = spec.points
    shape = " × ".join(f"{'+'.join(g)} {len(spec.axes[g[0]])}" for g in spec.zip_groups)
    steps = sum(round(p.scene.t_end / p.scene.dt) for p in points)
    print(f"{spec.path}: {len(points)} points ({shape}), hash {spec.hash[:12]}, {steps:.3g} steps in all")
    for point in points[:5] + ([None] if len(points) > 6 else []) + (points[-1:] if len(points) > 5 else []):
        if point is None:
            print("  ...")
            continue
        params = ", ".join(f"{k}={v!r}" for k, v in point.params.items())
        print(f"  {point.name}: {params}  (dt={point.scene.dt!r}, t_end={point.scene.t_end!r}, "
              f"record_every={point.scene.record_every})")
    return 0


def register_sweep(subparsers: argparse._SubParsersAction) -> None:
    """``sweep SPEC -o DIR``: run every point of a sweep specification, resumably."""
    from .runner import EXECUTORS

    parser = subparsers.add_parser(
        "sweep", help="run a parameter sweep (TOML specification) on local cores or MPI ranks",
        description="Run every point of a sweep specification (TOML): each point is a `beamstops run` "
                    "writing its own HDF5 file; one summary table gathers them.",
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("spec", type=Path, help="sweep specification (TOML; see input/sweeps/)")
    parser.add_argument("-o", "--output", type=Path, help="the sweep's folder (created; reused to resume)")
    parser.add_argument("-j", "--jobs", type=whole("worker processes"), help="local worker processes, >= 1 (default: every core)")
    parser.add_argument("--executor", choices=EXECUTORS, default="auto",
                        help="auto (default): MPI under `python -m mpi4py.futures`, else local processes")
    parser.add_argument("--set", action="append", metavar="TABLE.KEY=VALUE",
                        help="change the specification, e.g. --set axes.omega.num=20 (a TOML value; repeatable; "
                             "changes the hash, so use another folder)")
    parser.add_argument("--timeout", type=number("a number of seconds"),
                        help="wall-time limit of one point, s > 0, any length (default: [sweep] timeout)")
    parser.add_argument("--program", help="the beamstops program to run (default: the one installed with "
                                          "this package)")
    parser.add_argument("--dry-run", action="store_true", help="check the specification, list points, run nothing")
    parser.add_argument("--interval", type=number("a number of seconds"), default=10.0,
                        help="seconds between progress lines when not on a terminal, > 0 (default: 10)")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress and no notes")
    parser.set_defaults(handler=_sweep)

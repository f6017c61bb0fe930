"""``python -m beamstops plan SCENE.nml --qoi Q --tol T``: the cheapest model for a tolerance (see
:mod:`beamstops.plan`). Prints the candidates' table and the check, writes the chosen scene when the plan
meets the tolerance (exit status 0), else says why on stderr and exits 3."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .plan import LAWS, QUANTITIES, Quantity, parse_tolerance, plan

#: Exit status when the plan does not meet the tolerance (no model qualified, or the check failed).
NOT_MET = 3

EPILOG = """\
exit status: 0 the chosen model's estimated error is within the tolerance and its check against a
finer run passed: the chosen scene is written; 3 the plan does not meet the tolerance (no model
qualified, or the check FAILED): the table and the summary are printed, one last line on stderr
says why, and no scene is written; 1 bad input (--until beyond the scene's t_end among them).
"""


def _handler(args: argparse.Namespace) -> int:
    from .scene import Scene

    quantity = Quantity(args.qoi, until=args.until)  # a bad quantity or tolerance is refused before the scene is read
    parse_tolerance(args.tol)
    scene = Scene.from_namelist(args.scene)
    if quantity.deterministic and not args.until <= scene.t_end:
        raise ValueError(f"--until {args.until!r}: beyond the scene's t_end = {scene.t_end!r} s ({args.scene}); "
                         f"allowed: 0 < --until ≤ {scene.t_end!r} s (or a longer &time t_end in the scene)")
    out = args.output or args.scene.with_name(f"{args.scene.stem}_plan.nml")
    if out.resolve() == args.scene.resolve():
        raise ValueError(f"{out}: the output would overwrite the scene read")
    _check_output(out)
    laws = [law.strip() for law in args.laws.split(",") if law.strip()] if args.laws else None
    result = plan(scene, Quantity(args.qoi, until=args.until, stop=args.stop), args.tol, until=args.until, budget=args.budget, laws=laws, safety=args.safety,
                  coarser=args.coarser, finer=args.finer, exhaustive=args.all, max_window=args.max_window,
                  quiet=args.quiet)
    print(result.table())
    print(result.summary())
    shortfall = result.shortfall()
    if shortfall is not None or result.scene is None:
        print(f"beamstops: error: plan: {shortfall}; {out} not written", file=sys.stderr)
        return NOT_MET
    result.scene.to_namelist(out)
    print(f"chosen scene written to {out}")
    return 0


def register_plan(subparsers: argparse._SubParsersAction) -> None:
    """``plan SCENE.nml --qoi Q --tol T [--until S] [--budget S] [-o OUT.nml] [--laws L,...]``."""
    parser = subparsers.add_parser(
        "plan", help="the cheapest model (law, mesh, dt) whose estimated error on a quantity is under a tolerance",
        description="Search the contact law (--laws), the mesh J and the time step for the cheapest model whose "
                    "estimated error on the quantity is under the tolerance; print the candidates, write the "
                    "chosen scene and check it against a finer run (next J, dt/2).",
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", type=Path, help="namelist file of the scene")
    parser.add_argument("--qoi", required=True, metavar="QUANTITY",
                        help=f"{', '.join(QUANTITIES)}; tip: the tip trajectory on [0, --until] (max error); or a statistic of the engine "
                             "after the scene's transient, with its 95 %% interval")
    parser.add_argument("--tol", required=True,
                        help="tolerance: absolute in the quantity's unit (m, W, N, 1/s, 1), or relative (2%%)")
    parser.add_argument("--until", type=float,
                        help="tip: end of the window [0, UNTIL] (s), 0 < UNTIL ≤ the scene's t_end")
    parser.add_argument("--stop", type=int, default=0,
                        help="statistics per stop: which entry (0: the tip's stops, or the first stop along the span)")
    parser.add_argument("--budget", type=float, metavar="SECONDS",
                        help="engine CPU seconds for the search; stop refining when exceeded")
    parser.add_argument("--laws", help=f"comma-separated contact models the search may use, among "
                                       f"{', '.join(LAWS)} (default: the scene's own)")
    parser.add_argument("--safety", type=float,
                        help="factor on the error estimates (default 2 for tip, 1 for statistics)")
    parser.add_argument("--max-window", type=float, metavar="SECONDS",
                        help="statistics: longest window after the transient the search may use (s)")
    parser.add_argument("--coarser", type=int, default=2,
                        help="Δt ladder: from the scene's Δt × 2^COARSER (default 2) ...")
    parser.add_argument("--finer", type=int, default=3, help="... down to Δt / 2^FINER (default 3, at least 2)")
    parser.add_argument("--all", action="store_true",
                        help="estimate every candidate (within the budget), not only up to the first that qualifies")
    parser.add_argument("-o", "--output", type=Path,
                        help="chosen scene (default SCENE_plan.nml), written only when the plan meets the tolerance")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.set_defaults(handler=_handler)


def _check_output(out: Path) -> None:
    """Refuse, before planning, an output that exists and is not a scene plan (or Scene.to_namelist)
    wrote: a folder, an HDF5 output, a namelist written by hand."""
    if not out.exists() and not out.is_symlink():
        return
    if out.is_dir():
        raise ValueError(f"{out}: is a folder; -o takes the file the chosen scene is written to")
    from .scene import NAMELIST_HEADER

    try:
        with open(out, encoding="utf-8") as handle:
            first = handle.readline().rstrip("\n")
    except (OSError, UnicodeDecodeError):
        first = ""
    if first != NAMELIST_HEADER:
        raise ValueError(f"{out}: exists and was not written by beamstops (plan writes over its own scenes "
                         f"only); remove it or choose another -o")

"""``python -m beamstops plan SCENE.nml --qoi Q --tol T``: the cheapest model for a tolerance (see
:mod:`beamstops.plan`). Prints the candidates' table and the check, writes the chosen scene when the plan
meets the tolerance (exit status 0), else says why on stderr and exits 3."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import Callable

from .arguments import OptionError, number, output_name, whole
from .output_files import check, names_no_file, write_text
from .plan import LAWS, MAX_RUNGS, QUANTITIES, Quantity, check_max_window, parse_tolerance, plan
from .plan_types import ALIASES, ALIASES_TEXT, TOLERANCE, parse_laws, window_range
from .scene import NAMELIST_FILE

#: Exit status when the plan does not meet the tolerance (no model qualified, or the check failed).
NOT_MET = 3

#: The chosen scene: plan writes over a scene beamstops wrote (Scene.to_namelist's first line), or an empty file.
SCENE = NAMELIST_FILE
#: How to proceed when -o names a file plan will not write over.
ADVICE = "remove it or choose another -o"

EPILOG = """\
exit status: 0 the chosen model's estimated error is within the tolerance and its check against a
finer run passed: the chosen scene is written; 3 the plan does not meet the tolerance (no model
qualified, or the check FAILED): the table and the summary are printed, one last line on stderr
says why, and no scene is written; 2 a bad option; 1 bad input (the scene, --until outside one
step of the scene ... its t_end, an output that cannot be written).
"""


def _output(args: argparse.Namespace) -> Path:
    """Where the chosen scene goes, checked before the search (it could otherwise end in an error
    after it): -o, or SCENE_plan.nml beside a scene file; refused as output_files.check refuses."""
    if args.output is not None:
        out = Path(args.output)
    elif names_no_file(args.scene):
        raise ValueError(f"{args.scene}: a namelist read from a pipe, a device or an open descriptor (/dev/stdin, "
                         f"/dev/fd/N, <(...)) gives no output name; allowed: name the output, -o OUT.nml")
    else:
        out = args.scene.with_name(f"{args.scene.stem}_plan.nml")
    try:
        same = out.resolve() == args.scene.resolve() or os.path.samefile(out, args.scene)
    except OSError:
        same = False
    if same:
        raise ValueError(f"{out}: the output would overwrite the scene read; {ADVICE}")
    return check(out, SCENE, ADVICE)


def _handler(args: argparse.Namespace) -> int:
    from .scene import Scene

    if args.qoi == "tip" and args.until is None:
        raise OptionError("argument --until: --qoi tip needs the end of its window [0, UNTIL] (s), e.g. --until 0.08")
    if args.qoi != "tip" and args.until is not None:
        raise OptionError(f"argument --until: the window [0, UNTIL] is --qoi tip's only; --qoi {args.qoi} is taken "
                          f"after the scene's &statistics transient to its t_end: leave --until out")
    scene = Scene.from_namelist(args.scene)
    if args.until is not None:
        window_range(args.until, scene.t_end, scene.dt, name="--until")
    if args.max_window is not None and args.qoi != "tip":
        try:  # a window the engine refuses (shorter than a step): the option's own error, before any run
            check_max_window(scene, args.max_window, "")
        except ValueError as exc:
            raise OptionError(f"argument --max-window: {exc}") from None
    out = _output(args)
    result = plan(scene, Quantity(args.qoi, until=args.until, stop=args.stop), args.tol, budget=args.budget,
                  laws=args.laws, safety=args.safety, coarser=args.coarser, finer=args.finer, exhaustive=args.all,
                  max_window=args.max_window, quiet=args.quiet)
    print(result.table())
    print(result.summary())
    shortfall = result.shortfall()
    if shortfall is not None or result.scene is None:
        print(f"beamstops: error: plan: {shortfall}; {out} not written", file=sys.stderr)
        return NOT_MET
    write_text(out, SCENE, result.scene.namelist_file_text(), ADVICE)
    print(f"chosen scene written to {out}")
    return 0


def _checked(parse: Callable[[str], object], keep: bool = False) -> Callable[[str], object]:
    """An argparse type from a parser of plan's own (its ValueError or TypeError: the option's
    message); ``keep``: the text itself is the value."""

    def convert(text: str) -> object:
        try:
            value = parse(text)
        except (TypeError, ValueError) as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
        return text if keep else value

    return convert


def _quantity(text: str) -> str:
    text = ALIASES.get(text, text)  # the studies' stop_power and shock_rate
    if text not in QUANTITIES:
        raise ValueError(f"{text!r}: allowed: one of {', '.join(QUANTITIES)} ({ALIASES_TEXT}, the studies' names)")
    return text


def _tolerance(text: str) -> tuple[float, bool]:
    try:
        return parse_tolerance(text)
    except ValueError:
        raise ValueError(f"{text!r}: allowed: {TOLERANCE}") from None


def _laws(text: str) -> list[str]:
    try:
        return parse_laws(text)
    except ValueError:
        raise ValueError(f"{text!r}: allowed: one or more of {', '.join(LAWS)}, separated by commas") from None


def register_plan(subparsers: argparse._SubParsersAction) -> None:
    """``plan SCENE.nml --qoi Q --tol T [--until S] [--budget S] [-o OUT.nml] [--laws L,...]``."""
    parser = subparsers.add_parser(
        "plan", help="the cheapest model (law, mesh, dt) whose estimated error on a quantity is under a tolerance",
        description="Search the contact law (--laws), the mesh J and the time step for the cheapest model whose "
                    "estimated error on the quantity is under the tolerance; print the candidates, write the "
                    "chosen scene and check it against a finer run (next J, dt/2).",
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", type=Path, help="namelist file of the scene")
    parser.add_argument("--qoi", required=True, metavar="QUANTITY", type=_checked(_quantity),
                        help=f"{', '.join(QUANTITIES)}; tip: the tip trajectory on [0, --until] (max error); or a statistic of the engine "
                             "after the scene's transient, with its 95 %% interval (the studies' stop_power and "
                             "shock_rate are power and shocks_per_second)")
    parser.add_argument("--tol", required=True, type=_checked(_tolerance, keep=True),
                        help="tolerance: absolute in the quantity's unit (m, W, N, 1/s, 1), or relative (2%%); "
                             "finite, > 0")
    parser.add_argument("--until", type=number("a time in s"),
                        help="tip only: end of the window [0, UNTIL] (s), one step of the scene ≤ UNTIL ≤ its t_end")
    parser.add_argument("--stop", type=whole("the per-stop statistic's entry (0: the tip's stops, or the first stop "
                                             "along the span)", 0), default=0,
                        help="statistics per stop: which entry (0: the tip's stops, or the first stop along the span)")
    parser.add_argument("--budget", type=number("engine CPU seconds"), metavar="SECONDS",
                        help="engine CPU seconds for the search (> 0); stop refining when exceeded")
    parser.add_argument("--laws", type=_checked(_laws),
                        help=f"comma-separated contact models the search may use, among "
                             f"{', '.join(LAWS)} (default: the scene's own)")
    parser.add_argument("--safety", type=number("a factor on the error estimates"),
                        help="factor on the error estimates, > 0 (default 2 for tip, 1 for statistics)")
    parser.add_argument("--max-window", type=number("a window after the transient in s"), metavar="SECONDS",
                        help="statistics: longest window after the transient the search may use (s)")
    parser.add_argument("--coarser", type=whole("powers of 2 of the scene's Δt", 0, MAX_RUNGS), default=2,
                        help=f"Δt ladder: from the scene's Δt × 2^COARSER (default 2, at most {MAX_RUNGS}) ...")
    parser.add_argument("--finer", type=whole("powers of 2 of the scene's Δt", 2, MAX_RUNGS), default=3,
                        help=f"... down to Δt / 2^FINER (default 3, 2 ... {MAX_RUNGS})")
    parser.add_argument("--all", action="store_true",
                        help="estimate every candidate (within the budget), not only up to the first that qualifies")
    parser.add_argument("-o", "--output", type=output_name("a file name for the chosen scene"),
                        help="chosen scene (default SCENE_plan.nml; required for a scene read from a pipe), written "
                             "only when the plan meets the tolerance, over nothing but a scene beamstops wrote")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.set_defaults(handler=_handler)

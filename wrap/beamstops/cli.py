"""``python -m beamstops``: subcommands over the package.

Each subcommand is a function ``register(subparsers)`` that adds its parser and sets
``handler`` (a function of the parsed arguments returning an exit status). To add one,
write such a function (here or in a module of its own) and list it in :data:`COMMANDS`, and
add its name and one-line help to the table of the program (``python_commands`` in
src/main.f90), which hands these subcommands to this module: ``beamstops plot ...`` runs
``main(["plot", ...], prog="beamstops")`` in the Python beside the program
(tests/python/test_cli.py checks that the two tables agree).
Errors a user can fix end in one line ``beamstops: error: ...`` and exit status 1; a command that
ran but did not reach its goal (a sweep with points that failed or diverged, a plan that does not
meet its tolerance) says so in such a line and exits 3.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Callable, Optional, Sequence

from .arguments import MAX_DPI, OneLineParser, OptionError, number, output_name, whole


def _plot(args: argparse.Namespace) -> int:
    from . import plots
    from .result import IncompleteRunError, load

    suffix = ".gif" if args.kind == "animation" else ".png"
    default = f"{Path(args.file).stem}_{args.kind}{suffix}"
    if args.output is not None and plots.names_folder(args.output):
        raise ValueError(f"-o {args.output}: is a folder; name the image file to write, e.g. "
                         f"-o {Path(args.output) / default}")
    try:
        result = load(args.file, allow_incomplete=args.allow_incomplete)
    except IncompleteRunError as exc:  # its message names the Python keyword; here it is the option
        raise ValueError(f"{exc.reason}; plot what it holds with --allow-incomplete") from None
    out = args.output or Path(args.file).with_name(default)
    if args.kind == "animation":
        options = {"frames": args.frames, "fps": args.fps}
    else:
        options = {"transient": args.transient} if args.transient is not None else {}
    try:
        written = plots.save(result, out, kind=args.kind, dpi=args.dpi, **options)
    except ValueError as exc:  # what the file lacks for this kind ("no snapshots: ..."): name the file
        message = str(exc)
        named = message.startswith(str(args.file)) or str(out) in message  # the image's own refusals name it
        raise ValueError(message if named else f"{args.file}: {message}") from None
    print(written)
    return 0


def register_plot(subparsers: argparse._SubParsersAction) -> None:
    """``plot OUT.h5 [-o PNG] [--kind KIND]``: draw a run written by ``beamstops run``."""
    from .plot_kinds import KINDS, TRANSIENT

    parser = subparsers.add_parser("plot", help="plot the HDF5 output of `beamstops run`",
                                   description="Plot the HDF5 output of `beamstops run` (no display needed).")
    parser.add_argument("file", type=Path, help="HDF5 file written by `beamstops run`")
    parser.add_argument("-o", "--output", type=output_name("an image file name"),
                        help="image file to write, not a folder; its extension gives the format (none: .png is added, "
                             ".gif for animation); "
                             "the name written is printed (default: FILE_KIND.png next to FILE; "
                             "FILE_animation.gif for animation)")
    parser.add_argument("--kind", choices=KINDS, default="tip",
                        help="tip: tip displacement; shape or spacetime: the beam's ũ(x, t) from snapshots; energy; "
                             "phase: tip phase portrait; reaction; stops: the stops along the span (one panel each); "
                             "impacts: histograms of impulse and impact velocity per stop (the shock log); "
                             "pdf: tip-displacement PDF (the engine's histogram, 95 %% intervals); psd: Welch spectra "
                             "of the tip displacement and the reaction; poincare: (u, v) of the tip at t = kT, "
                             "T = 2π/ω; animation: the beam between its stops (.gif, or .mp4 with ffmpeg); all: "
                             "every still kind the run has data for (default: tip)")
    parser.add_argument("--transient", type=number(TRANSIENT, strict=False), metavar="SECONDS",
                        help="pdf, psd, poincare: draw only t ≥ SECONDS (pdf: the engine's histogram covers its own "
                             "transient; another one draws a histogram of the records)")
    parser.add_argument("--frames", type=whole("frames"), default=200,
                        help="animation: at most this many frames, spread over the snapshots (default: 200)")
    parser.add_argument("--fps", type=whole("frames per second"), default=20, help="animation: frames per second (default: 20)")
    parser.add_argument("--dpi", type=whole("dots per inch", 1, MAX_DPI), default=120, help="resolution of raster images, 1 ... 2400 (default: 120)")
    parser.add_argument("--allow-incomplete", action="store_true",
                        help="plot a run that diverged or was interrupted")
    parser.set_defaults(handler=_plot)


#: Subcommand registrars, in the order `--help` lists them.
COMMANDS: list[Callable[[argparse._SubParsersAction], None]] = [register_plot]

# Parameter sweeps (issue 7): `sweep SPEC -o DIR`.
from .sweep.cli import register_sweep  # noqa: E402

COMMANDS.append(register_sweep)

from .studies.cli import STUDIES  # noqa: E402  (issue 6: converge, work-precision, stability-map, compliance)

COMMANDS += STUDIES

from .plan_cli import register_plan  # noqa: E402  (issue 14 item 3: plan)

COMMANDS.append(register_plan)


def build_parser(prog: str = "python -m beamstops") -> argparse.ArgumentParser:
    from . import version

    parser = OneLineParser(prog=prog, description="beamstops: a beam on a vibrating support between rigid stops.")
    parser.add_argument("-V", "--version", action="version", version=f"beamstops {version()}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for register in COMMANDS:
        register(subparsers)
    return parser


def _subcommands(parser: argparse.ArgumentParser) -> argparse._SubParsersAction:
    return next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))


def commands() -> dict[str, str]:
    """The subcommands and their one-line help, in the order ``--help`` lists them."""
    return {choice.dest: choice.help or "" for choice in _subcommands(build_parser())._choices_actions}


def quiet_font_lookup() -> None:
    """Keep matplotlib's font lookup from flooding stderr: with a font cache that lacks a family
    mathtext asks for (cmr10, STIXGeneral, DejaVu Sans Display on log axes), every lookup logs a
    warning ``findfont: Font family [...] not found. Falling back to DejaVu Sans.``; the fallback
    draws the same text, so the command line logs only the font manager's errors."""
    import logging

    logging.getLogger("matplotlib.font_manager").setLevel(logging.ERROR)


def _described(exc: Exception) -> str:
    """An error in one line: an OSError as 'FILE: what went wrong' (its str() reads '[Errno 2] No
    such file or directory: 'FILE''), anything else as its message."""
    text = str(exc)
    if isinstance(exc, OSError) and exc.strerror and text.startswith("[Errno"):  # not one that words itself
        files = " and ".join(str(f) for f in (exc.filename, exc.filename2) if f is not None)
        return f"{files}: {exc.strerror}" if files else exc.strerror
    return text


def main(argv: Optional[Sequence[str]] = None, prog: str = "python -m beamstops") -> int:
    """Run a subcommand; ``prog`` names the command in messages (``beamstops`` when the
    program hands a subcommand on)."""
    parser = build_parser(prog)
    args, extra = parser.parse_known_args(argv)
    if extra:  # the subcommand's parser says so, in its name ("beamstops sweep: error: ...")
        _subcommands(parser).choices[args.command].error(f"unrecognized arguments: {' '.join(extra)}")
    quiet_font_lookup()
    try:
        return int(args.handler(args))
    except OptionError as exc:  # options that do not go together: as a bad option value
        _subcommands(parser).choices[args.command].error(str(exc))
        return 2  # not reached: error() exits with status 2
    except (OSError, ValueError) as exc:
        print(f"beamstops: error: {_described(exc)}", file=sys.stderr)
        return 1

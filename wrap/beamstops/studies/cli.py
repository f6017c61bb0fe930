"""Subcommands of the studies for ``python -m beamstops`` (appended to cli.COMMANDS):
``converge``, ``work-precision``, ``stability-map``, ``compliance``, ``contact-laws``; and :class:`StudyCommand`,
the command line every study shares (its subcommand and the ``main`` of its script)."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Optional

from ..arguments import OneLineParser, output_name
from .outputs import study_folder


@dataclass(frozen=True)
class StudyCommand:
    """The command line of a study: ``-o DIR`` (default out/<stem>), ``--quick``, the study's own
    ``options``, ``--quiet``. ``run(folder, args)`` runs the study into ``folder`` and returns
    the file the command prints. It is the subcommand ``name`` of ``python -m beamstops``
    (``help``, ``description``) and the script ``prog`` (``script_description``)."""

    stem: str
    options: Callable[[argparse.ArgumentParser], None]
    run: Callable[[Path, argparse.Namespace], Path]
    name: str
    help: str
    description: str
    prog: str
    script_description: str
    check: Optional[Callable[[argparse.Namespace], Optional[str]]] = None
    """After parsing: the message refusing an option (``argument --X: ...``), or None; a refusal is
    argparse's one line, exit status 2, before anything runs (the engine's limits on the scenes the
    study makes of the options, :mod:`beamstops.studies.options`)."""

    def arguments(self, parser: argparse.ArgumentParser) -> None:
        parser.add_argument("-o", "--output", type=output_name("a folder name (. for the current folder)"),
                            help=f"output folder (default out/{self.stem}); a file there is written over only when "
                                 f"it is this study's own earlier output (or an image where it writes a chart)")
        parser.add_argument("--quick", action="store_true", help="small sizes (seconds), for tests and CI")
        self.options(parser)
        parser.add_argument("--quiet", action="store_true", help="no progress bars")

    def handler(self, args: argparse.Namespace) -> int:
        print(self.run(study_folder(args.output, self.stem), args))
        return 0

    def checked(self, parser: argparse.ArgumentParser, args: argparse.Namespace) -> int:
        """:meth:`handler` once :attr:`check` accepts the options (else ``parser.error``: exit status 2)."""
        if self.check is not None:
            message = self.check(args)
            if message is not None:
                parser.error(message)
        return self.handler(args)

    def register(self, subparsers: argparse._SubParsersAction) -> None:
        """Add the study's subcommand to ``python -m beamstops``."""
        parser = subparsers.add_parser(self.name, help=self.help, description=self.description)
        self.arguments(parser)
        parser.set_defaults(handler=lambda args: self.checked(parser, args))

    def main(self, argv: Optional[Sequence[str]] = None) -> int:
        """The study's script: parse ``argv`` (default sys.argv[1:]), run, print the file."""
        parser = OneLineParser(prog=self.prog, description=self.script_description)
        self.arguments(parser)
        return self.checked(parser, parser.parse_args(argv))


def register_converge(subparsers: argparse._SubParsersAction) -> None:
    from .convergence import register

    register(subparsers)


def register_work_precision(subparsers: argparse._SubParsersAction) -> None:
    from .workprecision import register

    register(subparsers)


def register_stability_map(subparsers: argparse._SubParsersAction) -> None:
    from .stability_map import register

    register(subparsers)


def register_compliance(subparsers: argparse._SubParsersAction) -> None:
    from .compliance import register

    register(subparsers)


def register_contact_laws(subparsers: argparse._SubParsersAction) -> None:
    from .contact_laws import register

    register(subparsers)


#: The studies' registrars, in the order `--help` lists them.
STUDIES: list[Callable[[argparse._SubParsersAction], None]] = [register_converge, register_work_precision,
                                                               register_stability_map, register_compliance,
                                                               register_contact_laws]

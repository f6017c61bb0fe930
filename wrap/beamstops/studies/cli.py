"""Subcommands of the studies for ``python -m beamstops`` (appended to cli.COMMANDS):
``converge``, ``work-precision``, ``stability-map``, ``compliance``."""

from __future__ import annotations

import argparse
from typing import Callable


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


#: The studies' registrars, in the order `--help` lists them.
STUDIES: list[Callable[[argparse._SubParsersAction], None]] = [register_converge, register_work_precision,
                                                               register_stability_map, register_compliance]

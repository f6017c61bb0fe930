"""Argparse pieces shared by the command lines (``beamstops plot``, the studies, ``sweep``): a
parser whose errors are one line, a finite number above a bound, a whole number within bounds.
argparse's message names the option; these name the range (``'-1': allowed: a time in s >= 0``)."""

from __future__ import annotations

import argparse
import math
from typing import Callable, NoReturn, Optional

#: The largest resolution of a raster image (dots per inch), for ``--dpi`` and ``plots.save``: a
#: page-sized figure stays within what the Agg renderer allocates (--dpi 100000 ended in a
#: MemoryError traceback).
MAX_DPI = 2400


class OneLineParser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line on stderr, ``PROG: error: MESSAGE``, exit status 2,
    as the program's own (argparse's prints its usage block first); subcommands' parsers are of
    the same class (``add_subparsers`` makes them so)."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} ({self.prog} --help: the options)\n")


def number(what: str, low: float = 0.0, strict: bool = True) -> Callable[[str], float]:
    """A finite number > low (``strict``) or >= low; ``what`` names it in the message."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and (value > low if strict else value >= low)):
            raise argparse.ArgumentTypeError(f"{text!r}: allowed: {what} {'>' if strict else '>='} {low:g}")
        return value

    return parse


def whole(what: str, low: int = 1, high: Optional[int] = None) -> Callable[[str], int]:
    """A whole number >= low (and <= high when given); ``what`` names it in the message."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = low - 1
        if value < low or (high is not None and value > high):
            allowed = f"{low} ... {high}" if high is not None else f">= {low}"
            raise argparse.ArgumentTypeError(f"{text!r}: allowed: a whole number of {what}"
                                             f"{', ' if high is not None else ' '}{allowed}")
        return value

    return parse

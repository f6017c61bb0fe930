"""Argparse pieces shared by the command lines (``beamstops plot``, the studies, ``sweep``): a
parser whose errors are one line, a finite number above a bound, a whole number within bounds.
argparse's message names the option; these name the range (``'-1': allowed: a time in s >= 0``)."""

from __future__ import annotations

import argparse
import math
import numbers
from typing import Callable, NoReturn, Optional

#: The largest resolution of a raster image (dots per inch), for ``--dpi`` and ``plots.save``: a
#: page-sized figure stays within what the Agg renderer allocates (--dpi 100000 ended in a
#: MemoryError traceback).
MAX_DPI = 2400


class OptionError(ValueError):
    """Options that do not go together (``--until`` without ``--qoi tip``): the subcommand's parser
    reports it as it reports a bad option value, one line and exit status 2 (cli.main)."""


class OneLineParser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line on stderr, ``PROG: error: MESSAGE``, exit status 2,
    as the program's own (argparse's prints its usage block first); subcommands' parsers are of
    the same class (``add_subparsers`` makes them so)."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} ({self.prog} --help: the options)\n")


def allowed(what: str, low: float = 0.0, strict: bool = True) -> str:
    """The range of :func:`bounded`, in words: ``a time in s >= 0``."""
    return f"{what} {'>' if strict else '>='} {low:g}"


def bounded(value: object, what: str, low: float = 0.0, strict: bool = True, name: str = "") -> float:
    """``value`` as a finite number > low (``strict``) or >= low: the check an option and its Python
    keyword share. ValueError ``NAME VALUE: allowed: WHAT > LOW`` out of range (NaN, infinity
    included), TypeError for what is not a real number (a bool, a text, None)."""
    prefix = f"{name} " if name else ""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{prefix}{value!r}: allowed: {allowed(what, low, strict)} (a real number)")
    number_ = float(value)
    if not (math.isfinite(number_) and (number_ > low if strict else number_ >= low)):
        raise ValueError(f"{prefix}{value!r}: allowed: {allowed(what, low, strict)}")
    return number_


def number(what: str, low: float = 0.0, strict: bool = True) -> Callable[[str], float]:
    """A finite number > low (``strict``) or >= low; ``what`` names it in the message."""

    def parse(text: str) -> float:
        try:
            return bounded(float(text), what, low, strict)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r}: allowed: {allowed(what, low, strict)}") from None

    return parse


def output_name(what: str) -> Callable[[str], str]:
    """A file or folder name that is not empty (``-o ''`` is refused as ``beamstops run`` refuses it:
    an empty name is no name; ``.`` names the current folder)."""

    def parse(text: str) -> str:
        if text == "":
            raise argparse.ArgumentTypeError(f"'': allowed: {what} (an empty name names nothing)")
        return text

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

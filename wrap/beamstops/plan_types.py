"""The plan's types: the quantity, the tolerance, a model of the search, the candidates, the check
and the plan itself with its table and summary (see :mod:`beamstops.plan`)."""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Optional, Union

from .arguments import bounded
from .scene import Scene

__all__ = ["QUANTITIES", "ALIASES", "ALIASES_TEXT", "STATISTICAL", "LAWS", "Quantity", "Model", "Candidate", "Check",
           "Plan", "parse_tolerance", "parse_laws", "window_range", "TOLERANCE"]

#: Statistical quantities: the engine's statistic of that name (entry ``stop``).
STATISTICAL: tuple[str, ...] = ("power", "impulse_rate", "shocks_per_second", "contact_fraction", "tip_rms")
#: Every quantity ``plan`` accepts.
QUANTITIES: tuple[str, ...] = ("tip",) + STATISTICAL
#: The studies' names of the same statistics (``--qoi stop_power`` of converge and work-precision), accepted
#: for them: the quantity then carries the engine's name.
ALIASES: dict[str, str] = {"stop_power": "power", "shock_rate": "shocks_per_second"}
#: The aliases as messages name them: ``stop_power = power, shock_rate = shocks_per_second``.
ALIASES_TEXT = ", ".join(f"{alias} = {name}" for alias, name in ALIASES.items())
#: Contact models the search may use: scene changes of each.
LAWS: dict[str, dict[str, str]] = {
    "signorini": {"law": "signorini", "mass": "consistent"},
    "redistributed": {"law": "signorini", "mass": "redistributed"},
    "compliance": {"law": "compliance", "mass": "consistent"},
    "none": {"law": "none", "mass": "consistent"},
}


#: The tolerance's range, in the messages of ``--tol`` and ``tol`` alike.
TOLERANCE = ("a finite number > 0 (absolute, in the quantity's unit: m, W, N, 1/s, 1), or a finite percentage > 0 "
             "such as 2%")


def parse_tolerance(text: Union[str, float]) -> tuple[float, bool]:
    """``'2%'`` → (0.02, True) (relative); ``'0.01'`` or 0.01 → (0.01, False) (absolute). Must be finite
    and > 0: ValueError out of range, TypeError for what is neither a number nor a text (a bool, None)."""
    if isinstance(text, bool) or not isinstance(text, (str, numbers.Real)):
        raise TypeError(f"tolerance {text!r}: allowed: {TOLERANCE} (a real number or a text)")
    relative = isinstance(text, str) and text.strip().endswith("%")
    body = text.strip()[:-1] if relative and isinstance(text, str) else text
    try:
        value = float(body)
    except ValueError:
        value = math.nan
    if not (value > 0 and math.isfinite(value)):
        raise ValueError(f"tolerance {text!r}: allowed: {TOLERANCE}")
    return (value / 100.0 if relative else value), relative


def parse_laws(laws: Union[str, Sequence[str]]) -> list[str]:
    """The contact models a plan may use: one name, names separated by commas, or a sequence of
    names; each of :data:`LAWS`, at least one (ValueError; TypeError for what is not text)."""
    items = laws.split(",") if isinstance(laws, str) else laws
    if not isinstance(items, Sequence) or not all(isinstance(law, str) for law in items):
        raise TypeError(f"laws {laws!r}: allowed: a law or a sequence of laws among {', '.join(LAWS)}")
    names = [law.strip() for law in items if law.strip()]
    unknown = [law for law in names if law not in LAWS]
    if unknown or not names:
        what = f"unknown law(s) {', '.join(map(repr, unknown))}" if unknown else f"laws {laws!r}: no law given"
        raise ValueError(f"{what}; allowed: one or more of {', '.join(LAWS)} (separated by commas)")
    return list(dict.fromkeys(names))


def window_range(until: float, t_end: float, dt: float, name: str = "until") -> None:
    """Refuse a window [0, until] of the tip beyond the scene's ``t_end`` (the chosen scene runs to
    it) or shorter than one of its steps ``dt`` (nothing to compare but the start)."""
    if not dt <= until <= t_end:
        where = "beyond the scene's t_end" if until > t_end else "shorter than one step of the scene"
        raise ValueError(f"{name} {until!r} s: {where} (dt = {dt!r} s, t_end = {t_end!r} s); allowed: "
                         f"{dt!r} <= {name} <= {t_end!r} s (one step of the scene to its t_end; a longer "
                         f"window needs a longer &time t_end)")


@dataclass(frozen=True)
class Quantity:
    """What the plan must get right: the tip trajectory on [0, until] or a statistic of the engine."""

    name: str
    until: Optional[float] = None
    """``tip``: end of the window [0, until] (s)."""
    stop: int = 0
    """Statistical: which entry of a per-stop statistic (0: the tip's stops, or the first stop)."""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise TypeError(f"quantity {self.name!r}: allowed: one of {', '.join(QUANTITIES)} (a text)")
        if self.name in ALIASES:
            object.__setattr__(self, "name", ALIASES[self.name])
        if self.name not in QUANTITIES:
            raise ValueError(f"unknown quantity {self.name!r}; choose one of {', '.join(QUANTITIES)} ({ALIASES_TEXT})")
        if self.deterministic and self.until is None:
            raise ValueError("quantity 'tip' needs a window end until > 0 (s), e.g. --until 0.08")
        if not self.deterministic and self.until is not None:
            raise ValueError(f"until {self.until!r}: the window [0, until] is the tip's (quantity 'tip') only; "
                             f"a statistic such as {self.name!r} is taken after the scene's &statistics transient "
                             f"to its t_end: leave until out")
        if self.until is not None:
            bounded(self.until, "a time in s", name="until")
        if isinstance(self.stop, bool) or not isinstance(self.stop, int) or self.stop < 0:
            raise ValueError(f"stop {self.stop!r}: allowed: an entry 0, 1, ... of the per-stop statistic "
                             "(0: the tip's stops, or the first stop along the span)")

    @property
    def deterministic(self) -> bool:
        return self.name == "tip"

    def label(self) -> str:
        return f"max |u_tip| error on [0, {self.until:g}] s" if self.deterministic else self.name


@dataclass(frozen=True, order=True)
class Model:
    """A point of the search: contact model, mesh (J, reduced modes: 0 = full) and Δt."""

    law: str
    elements: int
    modes: int
    dt: float

    def describe(self) -> str:
        return f"{self.law} J={self.elements}" + (f" r={self.modes}" if self.modes else "") + f" dt={self.dt:g}"


@dataclass(frozen=True)
class Candidate:
    """One row of the plan's table."""

    model: Model
    value: float
    """QoI value: max |u_tip| on the window (tip), or the statistic's value."""
    half_width: float
    """95 % half-width of the statistic (nan for the tip)."""
    error: float
    """Estimated error (inf when it could not be estimated)."""
    parts: dict[str, float]
    """The estimate's terms: 'dt', 'mesh', 'law' (tip); 'difference', 'half_width' (statistics)."""
    cpu_per_second: float
    """The engine's CPU seconds per simulated second."""
    verdict: str
    """'qualifies', 'too coarse', 'no estimate' or 'refused: ...'."""

    @property
    def qualifies(self) -> bool:
        return self.verdict == "qualifies"


@dataclass(frozen=True)
class Check:
    """The choice against a finer run (next mesh, Δt/2, the scene's law)."""

    finer: Model
    value: float
    half_width: float
    finer_value: float
    finer_half_width: float
    difference: float
    """Measured: max |u − u'| on the window (tip) or |v − v'| (statistics)."""
    tolerance: float
    overlap: Optional[bool]
    """Statistics: whether the two 95 % intervals overlap."""

    @property
    def passed(self) -> bool:
        return self.difference <= self.tolerance


@dataclass
class Plan:
    """The search's outcome: candidates in the order run, the choice, its scene and its check."""

    quantity: Quantity
    tolerance: float
    """Absolute tolerance (the QoI's unit)."""
    relative: Optional[float]
    """The relative tolerance asked for (0.02 for 2 %), or None."""
    unit: str
    candidates: list[Candidate] = field(default_factory=list)
    choice: Optional[Candidate] = None
    scene: Optional[Scene] = None
    check: Optional[Check] = None
    window: Optional[float] = None
    """Statistics: the window after the transient used by every candidate (s)."""
    pilot_window: Optional[float] = None
    pilot_half_width: Optional[float] = None
    cpu_seconds: float = 0.0
    """The engine's CPU time of every run of the search and the check."""
    runs: int = 0
    stopped: Optional[str] = None
    """Why the search stopped before finding a qualifying candidate (budget), or None."""
    notes: list[str] = field(default_factory=list)

    @property
    def met(self) -> bool:
        """Whether the plan meets its tolerance: the choice's estimated error is within it and its
        check against a finer run (when the engine could run one) measured a difference within it."""
        return self.shortfall() is None

    def shortfall(self) -> Optional[str]:
        """Why the plan does not meet its tolerance, in one sentence, or None when it does."""
        tol = f"{_g(self.tolerance)} {self.unit}".rstrip()
        if self.choice is None:
            return f"no candidate could be estimated{f' ({self.stopped})' if self.stopped else ''}"
        c = self.choice
        if not c.qualifies:
            why = f"; {self.stopped}" if self.stopped else ""
            return (f"no model met the tolerance {tol} (the best estimate found: {c.model.describe()}, estimated "
                    f"error {_g(c.error)} {self.unit}{why})")
        if self.check is not None and not self.check.passed:
            return (f"the choice {c.model.describe()} qualified by its estimate, but its check against "
                    f"{self.check.finer.describe()} measured {_g(self.check.difference)} {self.unit} > tolerance {tol}")
        return None

    def table(self) -> str:
        """The candidates as a markdown table."""
        unit = f" ({self.unit})" if self.unit else ""
        lines = [f"| law | J | {'modes | ' if any(c.model.modes for c in self.candidates) else ''}Δt (s) | "
                 f"value{unit} | ± 95 %{unit} | error estimate{unit} | CPU s per simulated s | verdict |",
                 "|---|---|" + ("---|" if any(c.model.modes for c in self.candidates) else "") + "---|---|---|---|---|---|"]
        with_modes = any(c.model.modes for c in self.candidates)
        for c in self.candidates:
            mark = " **chosen**" if c is self.choice else ""
            modes = (f"{c.model.modes or 'all'} | " if with_modes else "")
            lines.append(f"| {c.model.law} | {c.model.elements} | {modes}{c.model.dt:.4g} | {_g(c.value)} | "
                         f"{_g(c.half_width)} | {_g(c.error)} | {_g(c.cpu_per_second)} | {c.verdict}{mark} |")
        return "\n".join(lines) + "\n"

    def summary(self) -> str:
        """What the plan found, in a few lines of text."""
        tol = f"{self.tolerance:.4g} {self.unit}".rstrip()
        if self.relative is not None:
            tol += f" ({100 * self.relative:g} % of the scene's value)"
        out = [f"quantity: {self.quantity.label()}; tolerance {tol}"]
        if self.window is not None:
            out.append(f"window after the transient: {self.window:.4g} s (the scene's {self.pilot_window:.4g} s gave "
                       f"± {self.pilot_half_width:.3g}; half-widths scale as 1/sqrt(window))")
        out.append(f"search: {self.runs} runs, {self.cpu_seconds:.3g} s of engine CPU")
        if self.stopped:
            out.append(f"stopped: {self.stopped}")
        if self.choice is None:
            out.append("no candidate could be estimated")
        else:
            c = self.choice
            state = "qualifies" if c.qualifies else "does NOT qualify (best estimate found)"
            out.append(f"choice: {c.model.describe()}: value {_g(c.value)}, estimated error {_g(c.error)} "
                       f"{self.unit}, {_g(c.cpu_per_second)} CPU s per simulated s; {state}")
        out += [f"note: {note}" for note in self.notes]
        if self.check is not None:
            k = self.check
            overlap = "" if k.overlap is None else f"; intervals {'overlap' if k.overlap else 'do NOT overlap'}"
            out.append(f"check against {k.finer.describe()}: measured difference {_g(k.difference)} {self.unit} "
                       f"{'≤' if k.passed else '>'} tolerance {_g(k.tolerance)}: {'PASS' if k.passed else 'FAIL'}"
                       f"{overlap}")
        return "\n".join(out)


def _g(x: float) -> str:
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else ("inf" if x == math.inf else f"{x:.3g}")

"""The studies' options checked at parse time against the scenes the study runs with them.

``converge`` and ``work-precision`` turn ``--transient``, ``--stat-window``, ``--reference-window``,
``--members`` (the statistical runs) and ``--window`` (the pointwise work-precision) into scenes'
t_end, transient and ensemble members. A value the engine would refuse in those scenes ended the
study, after its first runs, in the engine's message about a scene (``scene: &time t_end =
1.000000002e+09 is out of range``, ``&statistics transient = 0.5 ...``), which did not name the
option. Here those scenes are made (the engine's reader, and its output-size check) before
anything runs, with the values given; when the engine refuses one, the option is refused in
argparse's one line (exit status 2) with the range of values whose scenes the engine accepts —
found by asking the engine again (bisection), not by restating its rules — and its message.

Only the options given are checked (the defaults are the studies' own); each with the others at
their values, the windows before the transient, so that a transient too long for the windows given
is the one named.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable, Iterator
from typing import Optional

from ..engine import sizes
from ..scene import Scene

__all__ = ["check_statistical", "check_windows", "QUICK_WINDOW"]

#: The longest window of ``work-precision --quick`` (its study cuts a longer one to this).
QUICK_WINDOW = 0.05
#: Bounds of the bisections (s; members): far beyond any value the engine accepts, finite.
_TINY, _HUGE, _MANY = 1e-300, 1e300, 10**12


def _refusal(scenes: Iterator[Callable[[], Scene]]) -> Optional[str]:
    """The engine's message about the first scene it refuses (reader or output size), None when it
    accepts every one."""
    for make in scenes:
        try:
            sizes(make())
        except ValueError as exc:
            return str(exc)
    return None


def _bisect(accepts: Callable[[float], bool], good: float, bad: float, integer: bool = False) -> float:
    """The value nearest ``bad`` that is accepted, between ``good`` (accepted) and ``bad`` (refused):
    geometric steps for reals (their bounds span hundreds of decades), to 1e-6 relative."""
    for _ in range(200):
        if integer:
            if abs(bad - good) <= 1:
                break
            middle: float = (good + bad) // 2
        else:
            if abs(bad - good) <= 1e-6 * abs(good):
                break
            middle = math.sqrt(good * bad) if good > 0 and bad > 0 else (good + bad) / 2
        if accepts(middle):
            good = middle
        else:
            bad = middle
    return good


def _shown(value: float, up: bool, accepts: Callable[[float], bool]) -> float:
    """A bound shown with 4 significant digits: the nearest such number when it is accepted, else the
    next one toward the inside of the range (``up``: a lower bound)."""
    if value == 0 or not math.isfinite(value):
        return value
    nearest = float(f"{value:.4g}")
    if accepts(nearest):
        return nearest
    step = 10.0 ** (math.floor(math.log10(abs(value))) - 3)
    return float(f"{(math.ceil(value / step) if up else math.floor(value / step)) * step:.4g}")


def _range(accepts: Callable[[float], bool], good: float, integer: bool = False, low: float = _TINY
           ) -> tuple[float, float]:
    """The accepted values around ``good`` (accepted): the lowest above ``low`` and the highest."""
    top = _MANY if integer else _HUGE
    lowest = low if accepts(low) else _bisect(accepts, good, low, integer)
    highest = top if accepts(top) else _bisect(accepts, good, top, integer)
    if integer:
        return lowest, highest
    return _shown(lowest, True, accepts), _shown(highest, False, accepts)


def _refuse(option: str, value: float, what: str, span: tuple[float, float], message: str) -> str:
    low, high = span
    shown = f"{value:g}" if not isinstance(value, int) else str(value)
    return f"argument {option}: {shown}: allowed: {what}, {low:g} ... {high:g} (the engine: {message})"


# ---------------------------------------------------------------------- statistical runs


def _statistical_runs(command: str, quick: bool, transient: float, window: float, reference_window: float,
                      members: int) -> Iterator[Callable[[], Scene]]:
    """The scenes the statistical study of ``command`` runs (before it runs them), as run_ladders
    (converge) and run_laws (work-precision) make them."""
    from .qoi import configure
    from .qoi_convergence import ladders
    from .qoi_workprecision import settings

    s, chosen = settings(quick, transient, window, reference_window, members)
    base = Scene(beta=0.5)

    def make(scene: Callable[[], Scene], window: float, members: int = 1) -> Callable[[], Scene]:
        return lambda: configure(scene(), s.transient, window, batches=s.batches, members=members,
                                 perturbation=s.perturbation)

    if command == "converge":
        lad = ladders(quick)
        yield make(lambda: base.replace(dt=lad.dt_reference), s.reference_window, s.members)
        for dt in lad.dts:
            yield make(lambda dt=dt: base.replace(dt=dt), s.window)
        yield make(lambda: base.replace(dt=lad.dt_of_j, elements=lad.elements_reference), s.reference_window)
        for j in lad.elements:
            yield make(lambda j=j: base.replace(dt=lad.dt_of_j, elements=j), s.window)
        yield make(lambda: base.replace(dt=lad.dt_of_j, modes=0), s.reference_window)
        for r in lad.modes:
            yield make(lambda r=r: base.replace(dt=lad.dt_of_j, modes=r), s.window)
        return
    for i, law in enumerate(chosen):
        reference = law.reference_window if law.reference_window is not None else s.reference_window
        yield make(lambda law=law: base.replace(dt=law.dt_reference, **law.changes), reference,  # type: ignore[misc]
                   s.members if i == 0 else 1)
        for dt in law.dts:
            yield make(lambda law=law, dt=dt: base.replace(dt=dt, **law.changes), s.window)  # type: ignore[misc]


def check_statistical(command: str, args: argparse.Namespace) -> Optional[str]:
    """The message refusing ``--members``, ``--stat-window``, ``--reference-window`` or
    ``--transient`` (argparse's ``argument --X: ...``), or None when the engine accepts every
    scene of the statistical study with the values given."""
    from .qoi_workprecision import settings

    given = {name: getattr(args, name, None) for name in ("members", "window", "reference_window", "transient")}
    given["window"] = getattr(args, "stat_window", None)
    if all(value is None for value in given.values()):
        return None
    defaults, _ = settings(args.quick)
    values = {"members": defaults.members, "window": defaults.window, "reference_window": defaults.reference_window,
              "transient": defaults.transient}
    options = {"members": ("--members", "a whole number of members"), "window": ("--stat-window", "a time in s"),
               "reference_window": ("--reference-window", "a time in s"), "transient": ("--transient", "a time in s")}

    def refusal(changes: dict[str, float]) -> Optional[str]:
        v = {**values, **changes}
        return _refusal(_statistical_runs(command, args.quick, v["transient"], v["window"], v["reference_window"],
                                          int(v["members"])))

    # each option given, with the others at the values already checked: the windows before the transient
    for name in ("members", "window", "reference_window", "transient"):
        value = given[name]
        if value is None:
            continue
        message = refusal({name: value})
        if message is not None:
            integer = name == "members"
            span = _range(lambda x: refusal({name: int(x) if integer else x}) is None, values[name], integer,
                          low=1 if integer else 0.0 if name == "transient" else _TINY)
            option, what = options[name]
            return _refuse(option, value, what, span, message)
        values[name] = value
    return None


# ---------------------------------------------------------------------- the pointwise work-precision


def _pointwise_runs(quick: bool, window: float) -> Iterator[Callable[[], Scene]]:
    """The scenes of the pointwise work-precision over [0, window], as its study makes them."""
    from .common import every
    from .workprecision import GRID, methods

    def base() -> Scene:  # the study's base scene, which the engine may refuse too
        return Scene(t_end=window)

    finest = min(min(m.dts) for m in methods(quick))
    yield base
    yield lambda: base().replace(beta=0.5, dt=finest / 8, record_every=every(GRID, finest / 8))
    for m in methods(quick):
        for dt in m.dts:
            yield lambda m=m, dt=dt: base().replace(dt=dt, record_every=every(GRID, dt), **m.changes)  # type: ignore[misc]


def check_windows(args: argparse.Namespace) -> Optional[str]:
    """The message refusing ``--window`` (argparse's ``argument --window: ...``), or None: with
    ``--quick`` one window of at most QUICK_WINDOW s (the quick study cut 0.2 0.1 to 0.05 unsaid);
    every window within the range whose runs the engine accepts."""
    windows = getattr(args, "window", None)
    if windows is None:
        return None
    shown = " ".join(f"{w:g}" for w in windows)
    if args.quick and (len(windows) > 1 or windows[0] > QUICK_WINDOW):
        return (f"argument --window: {shown}: allowed: with --quick, one window W <= {QUICK_WINDOW:g} s (the quick "
                "study compares on one short window; several, or longer ones, without --quick)")
    for w in sorted(set(windows), reverse=True):
        message = _refusal(_pointwise_runs(args.quick, w))
        if message is not None:
            span = _range(lambda x: _refusal(_pointwise_runs(args.quick, x)) is None, QUICK_WINDOW if args.quick else 0.2)
            if args.quick:
                span = (span[0], min(span[1], QUICK_WINDOW))
            return _refuse("--window", w, "a time in s for each window [0, W]", span, message)
    return None

"""Sweep specifications: a TOML file naming a base scene, the axes and the reductions.

A specification (``input/sweeps/*.toml``)::

    [sweep]                       # optional
    base = "../quickstart.nml"    # base scene: a namelist, relative to this file (default: the paper's scene)
    mode = "product"              # "product" (default: every combination) or "zip" (axes side by side)
    zip = [["omega", "amplitude"]]  # product mode only: groups of axes that vary together
    max_points = 10000            # refuse larger sweeps (default 10000, at most 100000)
    timeout = 600                 # wall-time limit of one point (s > 0, any length; default none)
    lockstep = 8                  # points per `beamstops run` process (default 8; 1: one process per point)
    description = "free text"

    [scene]                       # fixed changes to the base scene: namelist keys, flat
    elements = 10
    dt = 2e-5

    [axes]                        # at least one; each a list or a range, in the order written
    omega = { start = 5, stop = 60, num = 300 }          # inclusive, evenly spaced
    amplitude = [0.1, 0.2]                               # a list
    dt = { start = 1e-5, stop = 1e-4, num = 4, spacing = "log" }
    elements = { start = 4, stop = 32, step = 4 }        # start, start+step, ... up to stop inclusive

    [periods]                     # optional: lengths in forcing periods T = 2π/ω (needs ω > 0)
    t_end = 100                   # t_end = 100 T at every point
    records_per_period = 16       # lock the time grid to the forcing (see below; not with a dt axis)
    # shared_grid = true          # or: one dt and one t_end for every point (see below)

    [reductions.strobe]           # user-chosen reductions, each a column of the summary
    kind = "strobe"               # tip displacement at t = k T (+ phase T), k >= transient_periods
    transient_periods = 50

    [reductions.u_max]
    kind = "max"                  # max, min, mean, rms, peak_to_peak, final
    quantity = "tip_u"            # tip_u, tip_v, reaction, energy, work, dissipated, damped
    after_periods = 50            # or after = 1.5 (s): only the records from then on
    # a reduction's columns (a strobe's NAME, NAME_offset, NAME_period) are its own: a name that is
    # a column of the summary or of another reduction is refused

Axis and scene keys are the namelist keys of :class:`beamstops.Scene` (fields and the
routes ``stiffness`` and the four material keys); ``file`` is the sweep's to set.

**Time grid locked to the forcing.** With ``records_per_period = r``, each point's time
step becomes dt' = T/(r·m) with m = ⌈T/(r·dt)⌉ (the largest such step not above the
scene's dt) and ``record_every = m``: the records fall every T/r exactly, so the
stroboscopic times k·T are record times (to round-off). Without it, dt and
``record_every`` are kept and a strobe takes the record nearest to each k·T; the summary
then says how far off it was (``<name>_offset``, s).

**One time grid for every point** (``shared_grid = true``, not with ``records_per_period``):
every point keeps the scene's dt and runs the same t_end, the longest of the points' t_end
periods (t_end · 2π/ω at the lowest ω), so each point covers at least t_end periods. Points
that differ only in the forcing (ω, amplitude) or the tip stops then share A = M + dt²βS and
the number of steps: the engine runs them in lockstep (the common ω sweep at one fixed Δt).

**Lockstep batches** (``[sweep] lockstep = K``, default 8): the runner hands the points to
the engine K at a time, as one ``beamstops run p1.nml ... pK.nml``; the engine runs those that
share A in lockstep and the others alone (its rule, not the sweep's), each into its own file,
identical to the point run alone. ``lockstep = 1`` runs one process per point.

Any mistake ends in :class:`SpecError`, a ValueError whose message starts with the
file's name: unknown tables or keys, unknown scene keys, empty axes, zip axes of
different lengths, values of the wrong type, non-finite numbers, too many points, and a
point whose scene the engine refuses — its reader (a value out of range) or the check of
``beamstops run`` (a time step beyond the stability limit of the model the point steps),
with the engine's message.
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import json
import math
import numbers
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from decimal import Decimal
from pathlib import Path
from typing import Any, Optional, Sequence

import numpy as np

from ..scene import GROUPS, Scene

__all__ = ["Spec", "Point", "SpecError", "load_spec", "parse_spec", "QUANTITIES", "REDUCTION_KINDS",
           "DEFAULT_MAX_POINTS", "DEFAULT_LOCKSTEP", "SCENE_KEYS"]

#: Version of the specification's resolved form (part of its hash).
FORMAT = 1
#: Largest sweep accepted unless [sweep] max_points says otherwise.
DEFAULT_MAX_POINTS = 10_000
#: [sweep] max_points cannot go beyond this: every point's scene is read and checked by the engine
#: before anything runs (about 0.8 ms a point, and some 4.5 KB of memory: a --dry-run of 100,000
#: points took 80 s of CPU and 0.45 GB; 10,000,000, accepted before, took over 2 min and 4.4 GB for
#: a tenth of its points).
HARD_MAX_POINTS = 100_000
#: Keys a sweep may set: every namelist key but the output file, which the sweep names, and the
#: positions of stops along the span (lists). ``modes`` is a key of &damping and of &mesh: a sweep's
#: ``modes`` is the Scene field, &mesh's (the damping modes, a pair, go in the base namelist), so
#: &damping's is left out and the list names each key once.
SCENE_KEYS: tuple[str, ...] = tuple(key for group, keys in GROUPS.items() for key in keys
                                    if key not in ("file", "nodes", "x") and (group, key) != ("damping", "modes"))
_INT_KEYS = {f.name for f in dataclasses.fields(Scene) if f.type in ("int", int)}
_KIND = {f.name: {"float": "real", "int": "integer", "bool": "boolean"}.get(str(f.type), "text")
         for f in dataclasses.fields(Scene)}
_KIND.update({key: "real" for key in ("stiffness", "youngs_modulus", "density", "outer_diameter", "wall_thickness")})
# Stops along the span (issue 8): the Scene holds lower and upper as tuples then; a sweep sets one
# value, for every stop. Their positions (nodes, x) are lists: give them in the base namelist.
_KIND.update({"lower": "real", "upper": "real"})
# Rayleigh damping (issue 12): a sweep sets one damping ratio, the same at both modes (the Scene
# holds a tuple); two different ratios go in the base namelist.
_KIND.update({"ratio": "real"})

_TABLES = ("sweep", "scene", "axes", "periods", "reductions")
_SWEEP_KEYS = ("base", "mode", "zip", "max_points", "timeout", "description", "lockstep")
_PERIOD_KEYS = ("t_end", "records_per_period", "shared_grid")
#: Points per `beamstops run` process unless [sweep] lockstep says otherwise.
DEFAULT_LOCKSTEP = 8
_RANGE_KEYS = ("start", "stop", "num", "step", "spacing")
_MODES = ("product", "zip")

#: Result arrays a reduction may read (names of :class:`beamstops.Result`).
QUANTITIES = ("tip_u", "tip_v", "reaction", "energy", "work", "dissipated", "damped")
_WINDOW = {"quantity": "tip_u", "after": None, "after_periods": None}
#: Reduction kinds and their keys with defaults.
REDUCTION_KINDS: dict[str, dict[str, Any]] = {
    "strobe": {"quantity": "tip_u", "transient_periods": 0, "phase": 0.0, "tolerance": 1e-6, "max_period": 16},
    "max": dict(_WINDOW), "min": dict(_WINDOW), "mean": dict(_WINDOW), "rms": dict(_WINDOW),
    "peak_to_peak": dict(_WINDOW), "final": {"quantity": "tip_u"},
}
#: Columns every summary has; reductions and axes may not take these names.
BUILTIN_COLUMNS = ("point", "status", "message", "cpu_seconds", "wall_seconds", "steps", "impacts",
                   "max_violation", "dissipated", "dt", "t_end", "record_every", "file")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


class SpecError(ValueError):
    """A specification that cannot be run; the message starts with the file's name."""


@dataclass(frozen=True)
class Point:
    """One run of a sweep: its axis values and the full scene the program runs."""

    index: int
    params: dict[str, Any]
    scene: Scene

    @property
    def name(self) -> str:
        return f"{self.index:05d}"

    def cost(self) -> float:
        """A guess of the run's cost, proportional to steps × elements."""
        return max(1.0, self.scene.t_end / self.scene.dt) * max(1, self.scene.elements)


@dataclass(frozen=True)
class Spec:
    """A parsed, checked sweep specification with every point resolved."""

    path: str
    """The file (or the name given to :func:`parse_spec`), the prefix of every message."""
    text: str
    """The file's text, copied into the sweep's folder."""
    data: dict[str, Any]
    """The TOML tables as read, after ``--set`` overrides."""
    base: Optional[str]
    axes: dict[str, list[Any]]
    mode: str
    zip_groups: list[list[str]]
    periods: Optional[dict[str, Any]]
    reductions: dict[str, dict[str, Any]]
    max_points: int
    timeout: Optional[float]
    description: str
    points: list[Point] = field(repr=False)
    hash: str = ""
    overrides: tuple[str, ...] = ()
    lockstep: int = DEFAULT_LOCKSTEP
    """Points per `beamstops run` process (the engine runs those that share A in lockstep)."""

    def resolved(self) -> dict[str, Any]:
        """What the hash covers: every point's scene and axis values, and the reductions."""
        return _resolved(self.points, self.reductions)


# ---------------------------------------------------------------------- reading


def load_spec(path: str | os.PathLike[str], overrides: Sequence[str] = ()) -> Spec:
    """Read and check a specification file; ``overrides`` are ``table.key=value`` (TOML values)."""
    import tomllib

    name = os.fspath(path)
    try:
        text = Path(name).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SpecError(f"{name}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SpecError(f"{name}: cannot read: {exc}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"{name}: not valid TOML: {exc}") from None
    return parse_spec(data, name, base_dir=Path(name).resolve().parent, text=text, overrides=overrides)


def parse_spec(data: Mapping[str, Any], path: str = "spec", *, base_dir: Optional[Path] = None, text: str = "",
               overrides: Sequence[str] = ()) -> Spec:
    """Check the tables of a specification (as TOML gives them) and resolve its points."""
    try:
        return _parse(data, path, base_dir or Path.cwd(), text, tuple(overrides))
    except SpecError:
        raise
    except (TypeError, ValueError, OverflowError, KeyError, AttributeError) as exc:  # a value of an odd type
        raise SpecError(f"{path}: {exc}") from None


def _parse(data: Mapping[str, Any], path: str, base_dir: Path, text: str, overrides: tuple[str, ...]) -> Spec:
    def fail(message: str) -> SpecError:
        return SpecError(f"{path}: {message}")

    if not isinstance(data, Mapping):
        raise fail("a specification is a TOML table")
    data = copy.deepcopy(dict(data))
    for item in overrides:
        _override(data, item, fail)
    _only(data, _TABLES, "top level", fail, tables=True)
    for table in _TABLES:
        if table in data and not isinstance(data[table], Mapping):
            raise fail(f"{table} must be a table ([{table}]), not {_show(data[table])}")

    sweep = dict(data.get("sweep", {}))
    _only(sweep, _SWEEP_KEYS, "[sweep]", fail)
    mode = sweep.get("mode", "product")
    if mode not in _MODES:
        raise fail(f"[sweep] mode = {_show(mode)}; allowed: 'product' or 'zip'")
    max_points = sweep.get("max_points", DEFAULT_MAX_POINTS)
    if not _is_int(max_points) or not 1 <= max_points <= HARD_MAX_POINTS:
        raise fail(f"[sweep] max_points = {_show(max_points)}; allowed: an integer 1 ... {HARD_MAX_POINTS}")
    timeout = sweep.get("timeout")
    if timeout is not None and not (_is_real(timeout) and math.isfinite(timeout) and timeout > 0):
        raise fail(f"[sweep] timeout = {_show(timeout)}; allowed: a number of seconds > 0")
    lockstep = sweep.get("lockstep", DEFAULT_LOCKSTEP)
    if not _is_int(lockstep) or not 1 <= lockstep <= 1024:
        raise fail(f"[sweep] lockstep = {_show(lockstep)}; allowed: an integer 1 ... 1024 (points per process; "
                   "1: one process per point)")
    description = sweep.get("description", "")
    if not isinstance(description, str):
        raise fail(f"[sweep] description must be a string, not {_show(description)}")

    base = sweep.get("base")
    if base is not None and not isinstance(base, str):
        raise fail(f"[sweep] base must be the path of a namelist file, not {_show(base)}")
    base_path = None
    if base is None:
        base_scene = Scene()
    else:
        base_path = str((base_dir / base).resolve()) if not os.path.isabs(base) else base
        try:
            base_scene = Scene.from_namelist(base_path)
        except (OSError, ValueError) as exc:
            raise fail(f"[sweep] base = {base!r}: {exc}") from None

    fixed = dict(data.get("scene", {}))
    for key, value in fixed.items():
        _scene_key(key, "[scene]", fail)
        _scalar(value, f"[scene] {key}", fail, key)
        if key in _INT_KEYS:
            fixed[key] = int(value)

    raw_axes = data.get("axes", {})
    if not raw_axes:
        raise fail("no axes: give at least one in [axes], e.g. omega = { start = 5, stop = 60, num = 100 }")
    for key in raw_axes:
        _scene_key(key, "[axes]", fail)
        if key in fixed:
            raise fail(f"{key} is both in [scene] and in [axes]; keep one")
    # The number of values of every axis before making any (a range may be huge).
    sizes = {key: _axis_size(key, value, fail) for key, value in raw_axes.items()}

    groups = _groups(sweep.get("zip"), mode, list(raw_axes), fail)
    total = 1
    for group in groups:
        lengths = {key: sizes[key] for key in group}
        if len(set(lengths.values())) > 1:
            raise fail("zip axes of different lengths: "
                       + ", ".join(f"{key} has {_many(n)} value{'s' if n != 1 else ''}" for key, n in lengths.items()))
        total *= lengths[group[0]]
        if total > max_points:
            break
    if total > max_points:
        shape = " × ".join(_many(sizes[g[0]]) for g in groups)
        raise fail(f"the axes make {_count(groups, sizes)} points ({shape}), more than max_points = {max_points}; "
                   "set [sweep] max_points if you mean it")
    axes = {key: _axis_values(key, value, fail) for key, value in raw_axes.items()}

    periods = _periods(data.get("periods"), fixed, axes, fail)
    if periods is not None and periods["shared_grid"]:
        omegas = [float(params.get("omega", fixed.get("omega", base_scene.omega)))
                  for params in _combinations(axes, groups)]
        if not min(omegas) > 0:
            raise fail("[periods] needs omega > 0; the sweep has omega = "
                       f"{min(omegas)!r}")
        periods["shared_t_end"] = periods["t_end"] * 2 * math.pi / min(omegas)
    reductions = _reductions(data.get("reductions", {}), list(axes), fail)

    points = []
    for index, params in enumerate(_combinations(axes, groups)):
        points.append(Point(index, params, _scene(base_scene, fixed, params, periods, index, fail)))
    needs_omega = periods is not None or any(
        spec["kind"] == "strobe" or spec.get("after_periods") is not None for spec in reductions.values())
    if needs_omega:
        for point in points:
            if not point.scene.omega > 0:
                what = "[periods]" if periods is not None else "a reduction in forcing periods"
                raise fail(f"{what} needs omega > 0; point {point.index} ({_params(point.params)}) "
                           f"has omega = {point.scene.omega!r}")
    _check_runs(points, fail)
    digest = _digest(points, reductions)
    return Spec(path=path, text=text, data=data, base=base_path, axes=axes, mode=mode, zip_groups=groups,
                periods=periods, reductions=reductions, max_points=int(max_points),
                timeout=float(timeout) if timeout is not None else None, description=description,
                points=points, hash=digest, overrides=overrides, lockstep=int(lockstep))


# ---------------------------------------------------------------------- pieces


def _override(data: dict[str, Any], item: str, fail: Any) -> None:
    """Apply ``table.key[.subkey]=TOML value`` to the tables."""
    import tomllib

    if "=" not in item:
        raise fail(f"--set {item!r}: expected TABLE.KEY=VALUE, e.g. axes.omega.num=20")
    where, value_text = item.split("=", 1)
    keys = [k.strip() for k in where.strip().split(".")]
    if len(keys) < 2 or not all(keys):
        raise fail(f"--set {item!r}: expected TABLE.KEY=VALUE, e.g. periods.t_end=20")
    try:
        value = tomllib.loads(f"value = {value_text.strip()}")["value"]
    except tomllib.TOMLDecodeError:
        value = value_text.strip()  # a bare word: a string
    table: Any = data
    for key in keys[:-1]:
        table = table.setdefault(key, {})
        if not isinstance(table, dict):
            raise fail(f"--set {item!r}: {key} is not a table")
    table[keys[-1]] = value


def _only(table: Mapping[str, Any], allowed: Sequence[str], where: str, fail: Any, tables: bool = False) -> None:
    unknown = [key for key in table if key not in allowed]
    if unknown:
        shown = ", ".join(f"[{k}]" if tables else k for k in allowed)
        raise fail(f"unknown {'table' if tables else 'key'} {unknown[0]!r} in {where}; allowed: {shown}")


def _show(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _is_int(value: Any) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def _is_real(value: Any) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _scene_key(key: str, where: str, fail: Any) -> None:
    if key == "file":
        raise fail(f"{where} file: the sweep names each point's output; remove it")
    if key not in SCENE_KEYS:
        raise fail(f"unknown scene key {key!r} in {where}; allowed: {', '.join(SCENE_KEYS)}")


def _scalar(value: Any, what: str, fail: Any, key: Optional[str] = None) -> None:
    """A value of the scene: a finite number, a string or a boolean, of the type its key holds."""
    if not (isinstance(value, (bool, str)) or _is_real(value)):
        raise fail(f"{what} = {_show(value)}: expected a number, a string or a boolean")
    if _is_real(value) and not math.isfinite(value):
        raise fail(f"{what} = {value!r}: not a finite number")
    kind = _KIND.get(key or "", "")
    if kind == "real" and not _is_real(value):
        raise fail(f"{what} = {_show(value)}: not a number")
    if kind == "integer" and not (_is_real(value) and float(value).is_integer()):
        raise fail(f"{what} = {_show(value)}: not an integer")
    if kind == "text" and not isinstance(value, str):
        raise fail(f"{what} = {_show(value)}: expected a string")
    if kind == "boolean" and not isinstance(value, bool):
        raise fail(f"{what} = {_show(value)}: expected true or false")


def _axis_size(key: str, value: Any, fail: Any) -> int:
    """The number of values of an axis (a list or a range table), without making them."""
    if isinstance(value, list):
        if not value:
            raise fail(f"axis {key} is empty; give at least one value")
        return len(value)
    if not isinstance(value, Mapping):
        raise fail(f"axis {key} = {_show(value)}: an axis is a list [a, b, ...] or a range "
                   "{ start = a, stop = b, num = n } or { start, stop, step }; put a fixed value in [scene]")
    _only(value, _RANGE_KEYS, f"axis {key}", fail)
    for end in ("start", "stop"):
        if end not in value:
            raise fail(f"axis {key}: a range needs start and stop (and num or step)")
        if not _is_real(value[end]) or not math.isfinite(value[end]):
            raise fail(f"axis {key}: {end} = {_show(value[end])}: not a finite number")
    start, stop = value["start"], value["stop"]
    if ("num" in value) == ("step" in value):
        raise fail(f"axis {key}: a range needs exactly one of num and step")
    spacing = value.get("spacing", "linear")
    if spacing not in ("linear", "log"):
        raise fail(f"axis {key}: spacing = {_show(spacing)}; allowed: 'linear' or 'log'")
    if "num" in value:
        num = value["num"]
        if not _is_int(num) or num < 1:
            raise fail(f"axis {key}: num = {_show(num)}; allowed: an integer >= 1")
        if spacing == "log" and not (start > 0 and stop > 0):
            raise fail(f"axis {key}: a log range needs start > 0 and stop > 0")
        return int(num)
    if spacing != "linear":
        raise fail(f"axis {key}: spacing = 'log' goes with num, not step")
    step = value["step"]
    if not _is_real(step) or not math.isfinite(step) or step == 0:
        raise fail(f"axis {key}: step = {_show(step)}; allowed: a finite non-zero number")
    span = (stop - start) / step
    if span < 0:
        raise fail(f"axis {key}: step = {step!r} goes away from stop = {stop!r}")
    if not math.isfinite(span):
        raise fail(f"axis {key}: step = {step!r} is too small for the range {start!r} ... {stop!r}")
    return int(math.floor(span + 1e-9)) + 1


def _axis_values(key: str, value: Any, fail: Any) -> list[Any]:
    if isinstance(value, list):
        for item in value:
            _scalar(item, f"axis {key} value", fail, key)
        values = list(value)
    else:
        start, stop = value["start"], value["stop"]
        if "num" in value:
            num = int(value["num"])
            if value.get("spacing", "linear") == "log":
                array = np.geomspace(start, stop, num)
            else:
                array = np.linspace(start, stop, num)
            values = [float(v) for v in array]
            if num >= 1:
                values[0] = start  # exact ends
            if num >= 2:
                values[-1] = stop
        else:
            step = value["step"]
            count = int(math.floor((stop - start) / step + 1e-9)) + 1
            if all(_is_int(v) for v in (start, stop, step)):
                values = [int(start + k * step) for k in range(count)]
            else:  # in decimal, so that 0.1, 0.2, 0.3 are the numbers written so
                first, stride = Decimal(repr(float(start))), Decimal(repr(float(step)))
                values = [float(first + k * stride) for k in range(count)]
    if key in _INT_KEYS:
        out = []
        for item in values:
            if _is_real(item) and float(item).is_integer():
                out.append(int(item))
            else:
                raise fail(f"axis {key}: the range gives {_show(item)}, not an integer")
        values = out
    return values


def _groups(zips: Any, mode: str, names: list[str], fail: Any) -> list[list[str]]:
    """The dimensions of the sweep: groups of axes that vary together."""
    if mode == "zip":
        if zips is not None:
            raise fail("[sweep] zip groups go with mode = 'product' (mode = 'zip' zips every axis)")
        return [names]
    if zips is None:
        return [[name] for name in names]
    if not isinstance(zips, list) or not all(isinstance(g, list) for g in zips):
        raise fail("[sweep] zip must be a list of lists of axis names, e.g. zip = [['omega', 'amplitude']]")
    seen: set[str] = set()
    for group in zips:
        if len(group) < 2:
            raise fail(f"[sweep] zip group {_show(group)}: a group needs two axes or more")
        for name in group:
            if not isinstance(name, str) or name not in names:
                raise fail(f"[sweep] zip names {_show(name)}, which is not an axis; axes: {', '.join(names)}")
            if name in seen:
                raise fail(f"[sweep] zip names {name} twice")
            seen.add(name)
    first = {group[0]: group for group in zips}
    out: list[list[str]] = []
    for name in names:  # each dimension where its first axis is written
        if name not in seen:
            out.append([name])
        elif name in first:
            out.append(list(first[name]))
    return out


#: Counts up to this many digits are written out; larger ones as ``about 1e+300``.
_DIGITS = 12


def _many(count: int) -> str:
    """A number of points or values as written, or compactly when it is huge (a step of 1e-300 gave
    a count of 301 digits)."""
    return str(count) if count < 10**_DIGITS else _about(math.log10(count))


def _about(log10: float) -> str:
    exponent = math.floor(log10)
    mantissa = round(10 ** (log10 - exponent), 1)
    if mantissa >= 10:
        mantissa, exponent = mantissa / 10, exponent + 1
    return f"about {mantissa:g}e+{exponent}"


def _count(groups: list[list[str]], sizes: dict[str, int]) -> str:
    """The number of points of the axes, as :func:`_many` writes it (from the sum of the logarithms
    when it is huge: the product of a few such axes has thousands of digits)."""
    log10 = sum(math.log10(sizes[group[0]]) for group in groups)
    if log10 >= _DIGITS:
        return _about(log10)
    total = 1
    for group in groups:
        total *= sizes[group[0]]
    return _many(total)


def _combinations(axes: dict[str, list[Any]], groups: list[list[str]]) -> list[dict[str, Any]]:
    """Every point's axis values: the product of the groups (first group outermost), zipped inside."""
    import itertools

    dims = [[{key: axes[key][i] for key in group} for i in range(len(axes[group[0]]))] for group in groups]
    out = []
    for combo in itertools.product(*dims):
        params: dict[str, Any] = {}
        for part in combo:
            params.update(part)
        out.append({key: params[key] for key in axes})  # axes in the order written
    return out


def _periods(table: Any, fixed: dict[str, Any], axes: dict[str, list[Any]], fail: Any) -> Optional[dict[str, Any]]:
    if table is None:
        return None
    _only(table, _PERIOD_KEYS, "[periods]", fail)
    if "t_end" not in table:
        raise fail("[periods] needs t_end, the run's length in forcing periods")
    t_end = table["t_end"]
    if not _is_real(t_end) or not (math.isfinite(t_end) and t_end > 0):
        raise fail(f"[periods] t_end = {_show(t_end)}; allowed: a number of periods > 0")
    if "t_end" in fixed or "t_end" in axes:
        raise fail("[periods] sets t_end; remove t_end from [scene] and [axes]")
    records = table.get("records_per_period")
    if records is not None:
        if not _is_int(records) or not 1 <= records <= 1_000_000:
            raise fail(f"[periods] records_per_period = {_show(records)}; allowed: an integer 1 ... 1000000")
        if "record_every" in fixed or "record_every" in axes:
            raise fail("[periods] records_per_period sets record_every; remove record_every from [scene] and [axes]")
        if "dt" in axes:  # the summary's dt column would be the axis value, not the step the point ran
            raise fail("[periods] records_per_period sets each point's dt (T/(r m), the largest such step not "
                       "above the scene's dt); an axis of dt would not be the step run: give dt in [scene], or "
                       "sweep dt without records_per_period")
    shared = table.get("shared_grid", False)
    if not isinstance(shared, bool):
        raise fail(f"[periods] shared_grid = {_show(shared)}; allowed: true or false")
    if shared and records is not None:
        raise fail("[periods] shared_grid = true keeps one dt for every point; records_per_period changes dt "
                   "with omega: give one of the two")
    return {"t_end": float(t_end), "records_per_period": int(records) if records is not None else None,
            "shared_grid": shared}


def _reductions(table: Any, axes: list[str], fail: Any) -> dict[str, dict[str, Any]]:
    from .reductions import columns

    out: dict[str, dict[str, Any]] = {}
    owner: dict[str, str] = {}  # every reduction's columns (a strobe's NAME_offset, NAME_period): whose
    for name, body in table.items():
        if not _NAME.match(name):
            raise fail(f"reduction name {name!r}: use letters, digits and _")
        if name in BUILTIN_COLUMNS or name in axes or name in SCENE_KEYS:
            raise fail(f"reduction name {name!r} is taken by a column of the summary; choose another")
        if not isinstance(body, Mapping):
            raise fail(f"[reductions.{name}] must be a table with a kind")
        kind = body.get("kind")
        if kind not in REDUCTION_KINDS:
            raise fail(f"[reductions.{name}] kind = {_show(kind)}; allowed: {', '.join(REDUCTION_KINDS)}")
        defaults = REDUCTION_KINDS[kind]
        _only(body, ("kind",) + tuple(defaults), f"[reductions.{name}]", fail)
        spec: dict[str, Any] = {"kind": kind}
        for key, default in defaults.items():
            value = body.get(key, default)
            where = f"[reductions.{name}] {key} = {_show(value)}"
            if key == "quantity":
                if value not in QUANTITIES:
                    raise fail(f"{where}; allowed: {', '.join(QUANTITIES)}")
            elif key in ("transient_periods", "max_period"):
                if not _is_int(value) or value < (1 if key == "max_period" else 0):
                    raise fail(f"{where}; allowed: an integer >= {1 if key == 'max_period' else 0}")
                value = int(value)
            elif value is not None:
                if not _is_real(value) or not math.isfinite(value) or value < 0:
                    raise fail(f"{where}; allowed: a finite number >= 0")
                value = float(value)
            spec[key] = value
        if kind == "strobe" and not spec["phase"] < 1:
            raise fail(f"[reductions.{name}] phase = {spec['phase']!r}; allowed: 0 <= phase < 1 (a fraction of T)")
        if spec.get("after") is not None and spec.get("after_periods") is not None:
            raise fail(f"[reductions.{name}]: give after (s) or after_periods, not both")
        filled = columns(name, spec)
        fills = f"a {kind} fills the columns {', '.join(filled)}" if len(filled) > 1 else ""
        for column in filled:
            if column != name and (column in BUILTIN_COLUMNS or column in axes or column in SCENE_KEYS):
                raise fail(f"[reductions.{name}]: {fills}, and {column} is taken by a column of the summary; "
                           "choose another name")
            if column in owner:
                other = owner[column]
                theirs = columns(other, out[other])
                if column == name:  # this name is a column another reduction fills
                    raise fail(f"reduction name {name!r} is taken by a column of [reductions.{other}] (a "
                               f"{out[other]['kind']} fills the columns {', '.join(theirs)}); choose another name")
                raise fail(f"[reductions.{name}]: {fills}, and {column} is [reductions.{other}]; choose another "
                           "name")
        owner.update((column, name) for column in filled)
        out[name] = spec
    return out


def _scene(base: Scene, fixed: dict[str, Any], params: dict[str, Any], periods: Optional[dict[str, Any]],
           index: int, fail: Any) -> Scene:
    try:
        scene = base.replace(**{**fixed, **params}, file=None)
    except (TypeError, ValueError) as exc:
        where = f"point {index} ({_params(params)})" if params else "[scene]"
        raise fail(f"{where}: {exc}") from None
    if periods is None or not scene.omega > 0:
        return scene
    period = 2 * math.pi / scene.omega
    if periods["shared_grid"]:
        return dataclasses.replace(scene, t_end=periods["shared_t_end"])
    changes: dict[str, Any] = {"t_end": periods["t_end"] * period}
    records = periods["records_per_period"]
    if records is not None:
        every = max(1, math.ceil(period / (records * scene.dt) * (1 - 1e-12)))
        changes["dt"] = period / (records * every)
        changes["record_every"] = every
    return dataclasses.replace(scene, **changes)


def _check_runs(points: list[Point], fail: Any) -> None:
    """Refuse a point the engine would refuse to run, with its message: the check of ``beamstops
    run`` and ``beamstops info`` (engine.validate: the stability limit of the model the point
    steps), asked once for each distinct scene of the sweep."""
    from ..engine import validate

    asked: set[str] = set()
    for point in points:
        text = point.scene.to_text()
        if text in asked:
            continue
        asked.add(text)
        try:
            validate(point.scene)
        except ValueError as exc:
            raise fail(f"point {point.index} ({_params(point.params)}): {exc}") from None


def _params(params: dict[str, Any]) -> str:
    return ", ".join(f"{k}={v!r}" for k, v in params.items())


def _digest(points: list[Point], reductions: dict[str, dict[str, Any]]) -> str:
    """sha256 of ``json.dumps(_resolved(points, reductions), sort_keys=True, allow_nan=False)``, the same
    text written point by point (the whole text of 100,000 points is some 200 MB)."""
    digest = hashlib.sha256()
    encode = json.JSONEncoder(sort_keys=True, allow_nan=False).encode
    digest.update(f'{{"format": {encode(FORMAT)}, "points": ['.encode())
    for i, point in enumerate(points):
        digest.update(((", " if i else "") + encode({"params": point.params, "scene": point.scene.to_dict()})).encode())
    digest.update(f'], "reductions": {encode(reductions)}}}'.encode())
    return digest.hexdigest()


def _resolved(points: list[Point], reductions: dict[str, dict[str, Any]]) -> dict[str, Any]:
    return {"format": FORMAT,
            "points": [{"params": p.params, "scene": p.scene.to_dict()} for p in points],
            "reductions": reductions}

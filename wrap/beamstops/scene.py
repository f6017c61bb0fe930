"""The scene: every input of a run, a frozen view of the engine's canonical namelist text.

The engine reads every input once (``src/beamstops/namelist.f90``): a :class:`Scene` is
built by writing its keys as namelist text, handing that text to the engine, and taking
back the engine's *canonical* text — every key, defaults filled in, values that read back
exactly — whose values become the fields. So a scene that exists is a scene the program
would run, a bad value raises :class:`ValueError` with the engine's own message (naming
group, key and allowed range), and ``Scene -> text -> Scene`` is the identity.

Fields are named exactly like the namelist keys; defaults are the paper's scene (Figure 2).
Three inputs of the namelist are routes to fields, accepted by :meth:`Scene.from_keys` and
:meth:`Scene.replace` and resolved by the engine:

- ``youngs_modulus``, ``density``, ``outer_diameter``, ``wall_thickness`` give ``k2`` and
  ``mass_per_length``;
- ``stiffness`` (N/m) gives ``stiffness_per_mass`` (1/s²);
- ``x`` (abscissae of stops along the span) gives ``nodes``.

With stops along the span (``nodes``), ``lower`` and ``upper`` are tuples, one value per stop
(one value given is used for all); without, they are the tip stops (single values).
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable, Literal, Optional, Union

from .output_files import text_kind, write_text

__all__ = ["Scene", "GROUPS", "ROUTES", "namelist_value"]

Law = Literal["signorini", "compliance", "none"]
LoadRule = Literal["centered", "paper"]
Start = Literal["taylor", "euler"]
PathLike = Union[str, "os.PathLike[str]"]


def _engine_keys() -> dict[str, tuple[str, ...]]:
    from . import engine

    return engine.keys()


#: Namelist groups and the keys each accepts (fields and routes), as the engine's reader lists them.
GROUPS: dict[str, tuple[str, ...]] = _engine_keys()
#: Fields whose name is not their key: &damping modes (&mesh has its own `modes`).
_KEY_OF: dict[str, tuple[str, str]] = {"damping_modes": ("damping", "modes")}
_FIELD_OF = {group_key: field for field, group_key in _KEY_OF.items()}
_GROUP_OF = {key: group for group, keys in GROUPS.items() for key in keys if (group, key) not in _FIELD_OF}
_GROUP_OF.update({field: group for field, (group, _) in _KEY_OF.items()})
#: Routes to fields, and the fields each one gives (a route in :meth:`Scene.replace` replaces them).
ROUTES: dict[str, tuple[str, ...]] = {
    "youngs_modulus": ("k2", "mass_per_length"), "density": ("k2", "mass_per_length"),
    "outer_diameter": ("k2", "mass_per_length"), "wall_thickness": ("k2", "mass_per_length"),
    "stiffness": ("stiffness_per_mass",), "x": ("nodes",),
    "ratio": ("mass_coefficient", "stiffness_coefficient"), "mass_coefficient": ("ratio",),
    "stiffness_coefficient": ("ratio",),
}


@dataclass(frozen=True)
class Scene:
    """Every input of a run; fields are the namelist keys, defaults the paper's scene (Fig. 2)."""

    # &beam
    length: float = 1.501
    """Length L of the beam (m)."""
    k2: float = 282.84
    """k² = EI/(ρS) (m⁴/s²)."""
    mass_per_length: float = 0.11938
    """Mass per unit length ρS (kg/m); scales reactions and energies."""
    # &support
    amplitude: float = 0.2
    """Amplitude a of the support motion φ(t) = a sin(ωt) (m)."""
    omega: float = 10.0
    """Angular frequency ω of the support (rad/s)."""
    # &stops
    lower: Union[float, tuple[float, ...]] = -0.1
    """Lower stop g1 < 0 (m): the tip's, or one per stop along the span (a tuple, with ``nodes``)."""
    upper: Union[float, tuple[float, ...]] = 0.1
    """Upper stop g2 > 0 (m): the tip's, or one per stop along the span (a tuple, with ``nodes``)."""
    nodes: tuple[int, ...] = ()
    """Nodes (1..J, J the tip) of the stops along the span; () for the tip stops alone."""
    law: Law = "signorini"
    """Contact law: 'signorini' (the paper's scheme), 'compliance' (a spring) or 'none'."""
    stiffness_per_mass: float = 0.0
    """Normal-compliance stiffness per unit mass 1/ε (1/s²); used with law='compliance' only."""
    restitution: float = 0.0
    """Restitution coefficient e in [0, 1] (Paoli–Schatzman, law 'signorini'); 0 is the paper's scheme."""
    mass: Literal["consistent", "redistributed"] = "consistent"
    """'redistributed': the constrained displacement unknowns carry no mass (needs beta > 0)."""
    # &damping
    mass_coefficient: float = 0.0
    """Rayleigh damping C = a M + b S: a (1/s)."""
    stiffness_coefficient: float = 0.0
    """Rayleigh damping: b (s)."""
    ratio: tuple[float, ...] = ()
    """Damping ratios ζ at the two ``damping_modes`` (one value: both); () for the coefficients' form."""
    damping_modes: tuple[int, ...] = (1, 2)
    """&damping modes: the two cantilever modes (1-based) of the ratio form."""
    # &mesh
    elements: int = 19
    """Number of elements J."""
    modes: int = 0
    """Fixed-interface modes r of a reduced (Craig–Bampton) model; 0: the full finite-element model."""
    # &time
    dt: float = 5e-5
    """Time step (s)."""
    t_end: float = 2.0
    """Final time (s)."""
    beta: float = 0.5
    """Newmark β in [0, 1/2]."""
    load_rule: LoadRule = "centered"
    """'centered' (second order) or 'paper' (the paper's rule, first order)."""
    start: Start = "taylor"
    """'taylor' (second-order start) or 'euler' (the paper's)."""
    allow_unstable: bool = False
    """Run even beyond the linear stability limit of β < 1/4."""
    # &output
    file: Optional[str] = None
    """HDF5 file the program writes (None: the namelist's base name with .h5); unused in memory. Given
    as a str or an os.PathLike (held as a str); another type is a TypeError."""
    record_every: int = 1
    """Record the tip and the energy every this many steps."""
    snapshot_every: int = 0
    """Record the beam's shape every this many steps (0: never)."""
    checkpoint_every: int = 0
    """Save a checkpoint every this many steps, for ``beamstops run --restart`` (0: never)."""
    max_output_gb: float = 4.0
    """Refuse a run whose recorded data would exceed this many gigabytes (1e9 bytes)."""
    # &statistics
    enabled: bool = True
    """Keep the shock log (/impacts) and the statistics (/statistics)."""
    transient: float = 0.0
    """Start of the statistics' window (s)."""
    batches: int = 20
    """Batches of the batch-means 95 % intervals (>= 2)."""
    bins: int = 40
    """Bins of the tip-displacement histogram."""
    rest_time: float = 0.01
    """Contact phases closer than this are one shock (s)."""
    histogram_lower: Optional[float] = None
    """Lower end of the tip histogram (m; None, the default: the tip's lower stop, as the engine's
    reader fills it in; a scene always holds the number)."""
    histogram_upper: Optional[float] = None
    """Upper end of the tip histogram (m; None, the default: the tip's upper stop)."""
    # &ensemble
    members: int = 1
    """Members of the ensemble (1: the scene alone)."""
    perturbation: float = 0.0
    """Size of the members' random initial perturbation (m)."""
    seed: int = 1
    """Seed of the perturbation's random numbers."""

    def __post_init__(self) -> None:
        values = {field.name: getattr(self, field.name) for field in dataclasses.fields(self)}
        for field in dataclasses.fields(self):
            value = values[field.name]
            if field.default is None or isinstance(field.default, tuple):
                continue  # None or () mean "not given" only where they are the default
            if value is None or (isinstance(value, (list, tuple)) and len(value) == 0):
                raise TypeError(f"scene key {field.name} cannot hold {value!r} (a number, a text, a logical or "
                                f"a list of them; leave the key out for its default)")
        _adopt(self, _canonical(_namelist(values), "scene"))

    # ------------------------------------------------------------------ construction

    @classmethod
    def from_text(cls, text: str, source: str = "scene") -> Scene:
        """The scene of namelist text, read by the engine; ValueError with its message otherwise
        (TypeError when ``text`` is not a str: a file is read by :meth:`from_namelist`)."""
        if not isinstance(text, str):
            raise TypeError(f"Scene.from_text: text must be a str of namelist text, not {type(text).__name__}"
                            f"{' (decode it first)' if isinstance(text, (bytes, bytearray)) else ''}; "
                            "a file is read by Scene.from_namelist(path)")
        return cls._of_canonical(_canonical(text, source))

    @classmethod
    def from_keys(cls, values: Mapping[str, Any], source: str = "scene") -> Scene:
        """A scene from namelist keys (fields and routes, flat), starting from the defaults."""
        return cls().replace(_source=source, **dict(values))

    @classmethod
    def from_namelist(cls, path: PathLike) -> Scene:
        """Read a scene from a namelist file exactly as the ``beamstops`` program reads it.

        Missing groups and keys keep the paper's values, and ``file`` defaults to the file's
        base name with ``.h5``. A file the program refuses raises :class:`ValueError` with the
        program's message (:class:`FileNotFoundError` when there is no such file).
        """
        from . import engine

        return cls._of_canonical(engine.read_file(path))

    @classmethod
    def _of_canonical(cls, text: str) -> Scene:
        """The scene of the engine's canonical text, as it is: no second reading by the engine
        (the canonical text reads back as itself)."""
        scene = object.__new__(cls)
        _adopt(scene, text)
        return scene

    def replace(self, _source: str = "scene", **changes: Any) -> Scene:
        """A copy with some keys changed: any field, or a route (the material, ``stiffness``, ``x``).

        A route replaces the fields it gives (the material replaces ``k2`` and
        ``mass_per_length``, ``stiffness`` replaces ``stiffness_per_mass``, ``x`` replaces
        ``nodes``, the damping ``ratio`` replaces the Rayleigh coefficients and they replace it);
        the engine resolves it with the scene's (new) other keys. A route given as nothing (``ratio=()``,
        ``x=None``) replaces nothing.
        """
        _refuse_unknown(changes)
        values = self.to_dict()
        for route in set(changes) & set(ROUTES):
            if _not_given(changes[route]):
                continue  # `ratio=()`, `x=None`: no route taken, the fields it would give are kept
            for derived in ROUTES[route]:
                values.pop(derived, None)
        if set(changes) & _STOP_KEYS:
            # A histogram range that is the old stops' default follows the new stops; one set
            # apart from them is carried over like any other key.
            stops_default = Scene._of_canonical(_canonical(_namelist(
                {key: value for key, value in values.items() if key not in _HISTOGRAM_KEYS}), _source))
            for key in _HISTOGRAM_KEYS:
                if _same(values[key], getattr(stops_default, key)):
                    values[key] = None
        values.update(changes)
        # The keys not in `changes` are carried over: the engine drops those that would do nothing
        # under the new keys (its rule), where it refuses such a key given anew.
        carried = ["{}:{}".format(*_group_key(key)) for key in values if key not in changes]
        return Scene._of_canonical(_canonical(_namelist(values), _source, carried))

    # ------------------------------------------------------------------ output

    def to_text(self) -> str:
        """The scene as namelist text: the engine's canonical text (what :func:`beamstops.run` passes)."""
        return str(self.__dict__["_canonical"])

    def groups(self) -> dict[str, dict[str, Any]]:
        """The scene as namelist groups of values (what :meth:`to_namelist` writes)."""
        out: dict[str, dict[str, Any]] = {group: {} for group in GROUPS}
        for group, key, _ in _items(self.to_text()):
            out[group][key] = getattr(self, _FIELD_OF.get((group, key), key))
        return out

    def to_namelist(self, path: PathLike) -> None:
        """Write the scene as a namelist file the program reads (reals read back exactly): whole (a
        temporary file renamed into place), over an empty file or a scene written so before only
        (never through a symbolic link, over a run's output, a hand-written namelist or a FIFO:
        :func:`beamstops.output_files.check`, the rule of every file beamstops writes)."""
        write_text(path, NAMELIST_FILE, self.namelist_file_text())

    def namelist_file_text(self) -> str:
        """What :meth:`to_namelist` writes: its first line :data:`NAMELIST_HEADER`, then :meth:`to_text`."""
        return NAMELIST_HEADER + "\n" + self.to_text()

    def to_dict(self) -> dict[str, Any]:
        """The fields as a flat dictionary (their values are immutable: numbers, texts, tuples; a
        shallow copy, where dataclasses.asdict's deep one cost a sweep of 100,000 points 30 s)."""
        return {name: getattr(self, name) for name in _FIELD_NAMES}

    # ------------------------------------------------------------------ engine

    def validate(self, source: str = "scene") -> None:
        """Check the scene with the engine again, messages starting with ``source``."""
        _canonical(self.to_text(), source)

    def differences(self, other: Scene) -> str:
        """Keys whose values differ (bit for bit for reals), as text; '' when none."""
        out = []
        for field in dataclasses.fields(self):
            a, b = getattr(self, field.name), getattr(other, field.name)
            if isinstance(a, tuple) and isinstance(b, tuple):
                same = len(a) == len(b) and all(_same(p, q) for p, q in zip(a, b))
            else:
                same = _same(a, b)
            if not same:
                out.append(f"{field.name}: {a!r} != {b!r}")
        return "; ".join(out)


#: The fields of a Scene, in order (to_dict).
_FIELD_NAMES: tuple[str, ...] = tuple(field.name for field in dataclasses.fields(Scene))
_FIELDS_INIT = Scene.__init__


def _scene_init(self: Scene, *args: Any, **keys: Any) -> None:
    """The dataclass's constructor, but a key that is no field is what :meth:`Scene.replace` makes
    of it: a route (``youngs_modulus=``, ``stiffness=``, ``x=``...) is resolved by the engine from the
    defaults, and an unknown key is refused with the keys allowed (Python's own message named only
    the key)."""
    others = set(keys) - set(_FIELD_NAMES)
    if not others:
        _FIELDS_INIT(self, *args, **keys)
        return
    _refuse_unknown(others)
    if args:
        raise TypeError(f"Scene takes keys by name only with a route ({', '.join(sorted(others))})")
    _adopt(self, Scene().replace(**keys).to_text())


Scene.__init__ = _scene_init  # type: ignore[method-assign]


def _refuse_unknown(keys: Iterable[str]) -> None:
    """TypeError naming the keys that are neither a field nor a route, and the keys allowed."""
    unknown = sorted(set(keys) - set(_GROUP_OF))
    if unknown:
        raise TypeError(f"unknown scene key(s) {', '.join(unknown)}; allowed: {', '.join(_GROUP_OF)}")


# ---------------------------------------------------------------------- text

#: The first line of a namelist file Scene.to_namelist writes.
NAMELIST_HEADER = "! beamstops scene (written by beamstops.Scene.to_namelist)"
#: A namelist file :meth:`Scene.to_namelist` wrote, for :mod:`beamstops.output_files`: ``plan -o`` (and a
#: study) writes a scene over nothing else.
NAMELIST_FILE = text_kind("a scene", NAMELIST_HEADER, f"a scene beamstops wrote (first line {NAMELIST_HEADER!r})")

def namelist_value(value: Any, key: str = "value") -> str:
    """A Python value as a namelist value: reals that read back exactly, lists by commas (nested lists
    flattened, as they always were), quoted texts; a numpy scalar or 0-d array as its one value."""
    if getattr(value, "ndim", None) == 0 and hasattr(value, "item"):
        value = value.item()
    if isinstance(value, bool):
        return ".true." if value else ".false."
    if isinstance(value, str):
        if any(ord(c) < 32 or ord(c) == 127 for c in value):
            raise ValueError(f"scene key {key} = {value!r} holds a control character (a line break, a tab, ...); "
                             f"allowed: printable text")
        return "'" + value.replace("'", "''") + "'"
    if isinstance(value, numbers.Integral):
        return _decimal(int(value))
    if isinstance(value, numbers.Real):
        try:
            return repr(float(value))
        except OverflowError:  # a Fraction beyond the doubles: infinite, as the reader takes 10**400
            return repr(math.inf if value > 0 else -math.inf)
    if _is_list(value):
        return ", ".join(namelist_value(v, key) for v in value)
    raise TypeError(f"scene key {key} cannot hold {value!r} (a number, a text, a logical or a list of them)")


def _decimal(number: int) -> str:
    """str(number), also beyond Python's limit on the digits of an int made text (4300): the
    engine's reader, not Python, refuses such a number with the key's range."""
    try:
        return str(number)
    except ValueError:
        sign, rest, parts = "-" if number < 0 else "", abs(number), []
        while rest:
            rest, part = divmod(rest, 10**1000)
            parts.append(part)
        return sign + str(parts[-1]) + "".join(f"{part:01000d}" for part in reversed(parts[:-1]))


def _path(value: Any) -> Optional[str]:
    """``file``: a str or an os.PathLike (of a str), or None (the default name); any other type is a
    TypeError (a number was taken for a file name, ``file = 123``)."""
    if value is None or isinstance(value, str):
        return value
    name = os.fspath(value) if isinstance(value, os.PathLike) else None
    if not isinstance(name, str):
        raise TypeError(f"scene key file = {value!r}: allowed: a str or an os.PathLike (the HDF5 output's path), "
                        "or None for the namelist's name with .h5")
    return name


#: The tip histogram's range, whose default (None) is the tip's stops, and the keys that give them.
_HISTOGRAM_KEYS = ("histogram_lower", "histogram_upper")
_STOP_KEYS = frozenset({"lower", "upper", "nodes", "x", "length", "elements"})


def _namelist(values: Mapping[str, Any]) -> str:
    """Namelist text of flat keys, each in its group; None, empty lists and the fields' defaults
    are left out (the engine's reader fills in every default)."""
    defaults = {field.name: field.default for field in dataclasses.fields(Scene)}
    groups: dict[str, list[str]] = {}
    for key, value in values.items():
        if key == "file":
            value = _path(value)
        if value is None or (isinstance(value, (tuple, list)) and len(value) == 0):
            continue
        if key in defaults and _is_default(value, defaults[key]):
            continue
        group, name = _group_key(key)
        if _is_list(value):
            # A list is written with its section, `key(1:n) = ...`: the engine reads it into the
            # first n elements of a list key and refuses it for a key of one value (`dt(1:1) = 1e-05`
            # is malformed), where `dt = 1e-05` would have taken [1e-5] for 1e-5.
            name = f"{name}(1:{_count(value)})"
        groups.setdefault(group, []).append(f"  {name} = {namelist_value(value, key)}")
    return "".join(f"&{group}\n" + "\n".join(lines) + "\n/\n" for group, lines in groups.items()) or "&time /\n"


def _not_given(value: Any) -> bool:
    """None or an empty list: a key left out of the text (its default, or nothing)."""
    return value is None or (_is_list(value) and _count(value) == 0)


def _is_default(value: Any, default: Any) -> bool:
    """Whether a value is a field's default in another dress, and so left out of the text as the
    default itself is: a list or an array for a tuple (``damping_modes=[1, 2]``), a numpy scalar, an
    int for a real (``stiffness_per_mass=0``). A logical stands for a logical only, a number for a
    number only (``True`` is not 1), and -0.0 is not 0.0."""
    if getattr(value, "ndim", None) == 0 and hasattr(value, "item"):
        value = value.item()
    if isinstance(default, tuple):
        if not _is_list(value):
            return False
        items = list(value)  # each item unwrapped from numpy by the call on it
        return len(items) == len(default) and all(_is_default(v, d) for v, d in zip(items, default))
    if isinstance(default, bool) or isinstance(value, bool):
        return isinstance(default, bool) and isinstance(value, bool) and value == default
    if isinstance(default, numbers.Real) and not isinstance(default, numbers.Integral):
        return (isinstance(value, numbers.Real) and value == default
                and math.copysign(1.0, float(value)) == math.copysign(1.0, default))
    if isinstance(default, numbers.Integral):
        return isinstance(value, numbers.Integral) and value == default
    return type(value) is type(default) and bool(value == default)


def _is_list(value: Any) -> bool:
    """Whether namelist_value writes the value as a list (a list, a tuple or an array)."""
    return isinstance(value, (list, tuple)) or (hasattr(value, "ndim") and getattr(value, "ndim", 0) > 0)


def _count(value: Any) -> int:
    """Number of values namelist_value writes for a value (nested lists flattened)."""
    return sum(_count(v) for v in value) if _is_list(value) else 1


def _group_key(field: str) -> tuple[str, str]:
    """The namelist group and key of a field or route (``damping_modes`` is ``&damping modes``)."""
    return _KEY_OF.get(field, (_GROUP_OF[field], field))


def _canonical(text: str, source: str, carried: Iterable[str] = ()) -> str:
    from . import engine

    return engine.canonical(text, source, carried)


_LINE = re.compile(r"^  (\w+) = (.*)$")


def _items(text: str) -> list[tuple[str, str, str]]:
    """(group, key, value text) of the engine's canonical text (one `key = value` a line)."""
    out, group = [], ""
    for line in text.splitlines():
        if line.startswith("&"):
            group = line[1:].strip()
        elif (match := _LINE.match(line)) is not None:
            out.append((group, match.group(1), match.group(2)))
    return out


def parse_value(text: str) -> Any:
    """A value of the engine's canonical text or attribute lines: a quoted text, a logical, an
    integer, a real, or a list of them (separated by commas)."""
    text = text.strip()
    if text.startswith("'"):
        return text[1:-1].replace("''", "'")
    if text in (".true.", ".false."):
        return text == ".true."
    if "," in text:
        return tuple(parse_value(part) for part in text.split(","))
    if re.fullmatch(r"[+-]?\d+", text):
        return int(text)
    return float(text)


def _fields_of(text: str) -> dict[str, Any]:
    """Field values of canonical text; with stops along the span lower and upper are tuples."""
    values = {_FIELD_OF.get((group, key), key): parse_value(value) for group, key, value in _items(text)}
    for key in ("ratio", "damping_modes"):
        if key in values and not isinstance(values[key], tuple):
            values[key] = (values[key],)
    if "nodes" in values:
        for key in ("nodes", "lower", "upper"):
            if not isinstance(values[key], tuple):
                values[key] = (values[key],)
    return values


def _adopt(scene: Scene, canonical: str) -> None:
    """Set a scene's fields to the values of the engine's canonical text."""
    values = _fields_of(canonical)
    for field in dataclasses.fields(scene):
        default = field.default if field.name not in ("nodes", "ratio") else ()
        object.__setattr__(scene, field.name, values.get(field.name, default))
    object.__setattr__(scene, "_canonical", canonical)


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        return (a == b and math.copysign(1.0, a) == math.copysign(1.0, b)) or (math.isnan(a) and math.isnan(b))
    return bool(a == b)

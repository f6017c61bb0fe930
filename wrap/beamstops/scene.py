"""The scene: every input of a run, as the namelist file of the ``beamstops`` program holds it.

A :class:`Scene` is plain, immutable data whose fields are named exactly like the
namelist keys. Its defaults are the paper's scene (Figure 2). Values are checked by
the engine (``validate_scene``, through the extension), which is the one place that
knows the allowed ranges: :meth:`Scene.validate`, :func:`beamstops.run` and
:func:`beamstops.stability` raise :class:`ValueError` with the engine's message.

Two inputs of the namelist are not fields but routes to them, accepted by
:meth:`Scene.from_namelist`, :meth:`Scene.from_keys` and :meth:`Scene.replace`:

- ``youngs_modulus``, ``density``, ``outer_diameter``, ``wall_thickness`` (all four
  together) give ``k2`` and ``mass_per_length`` by the engine's own formulas;
- ``stiffness`` (N/m) gives ``stiffness_per_mass = stiffness / mass_per_length`` (1/s²);
- ``x`` (abscissae of stops along the span, each at a node to 1e-9 length) gives ``nodes``,
  with the (new) ``length`` and ``elements``.

Stops along the span (issue 8): with ``nodes`` (node indices 1..J) the scene has a stop at
each, and ``lower`` and ``upper`` are tuples, one value per stop (one value given is used
for all); without, ``lower`` and ``upper`` are the tip stops (single values), as before.
"""

from __future__ import annotations

import dataclasses
import io
import math
import numbers
import operator
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, Optional, Union

import f90nml

__all__ = ["Scene", "GROUPS", "LAWS", "LOAD_RULES", "STARTS", "MATERIAL_KEYS"]

Law = Literal["signorini", "compliance", "none"]
LoadRule = Literal["centered", "paper"]
Start = Literal["taylor", "euler"]
PathLike = Union[str, "os.PathLike[str]"]

#: Contact laws and their codes in the engine (beamstops_scene: law_none, law_signorini, law_compliance).
LAWS: dict[str, int] = {"signorini": 1, "compliance": 2, "none": 0}
#: Load rules: 'centered' (second order) or 'paper' (the paper's, first order).
LOAD_RULES = ("centered", "paper")
#: Starts: 'taylor' (second order) or 'euler' (the paper's u1 = u0 + dt v0).
STARTS = ("taylor", "euler")
#: The material route to k2 and mass_per_length (all four or none).
MATERIAL_KEYS = ("youngs_modulus", "density", "outer_diameter", "wall_thickness")

#: Namelist groups and the keys each accepts (fields and routes), as the program reads them.
GROUPS: dict[str, tuple[str, ...]] = {
    "beam": ("length", "k2", "mass_per_length") + MATERIAL_KEYS,
    "support": ("amplitude", "omega"),
    "stops": ("lower", "upper", "nodes", "x", "law", "stiffness", "stiffness_per_mass"),
    "mesh": ("elements",),
    "time": ("dt", "t_end", "beta", "load_rule", "start", "allow_unstable"),
    "output": ("file", "record_every", "snapshot_every", "max_output_gb"),
}
_GROUP_OF = {key: group for group, keys in GROUPS.items() for key in keys}
_ROUTES = MATERIAL_KEYS + ("stiffness", "x")


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
    # &mesh
    elements: int = 19
    """Number of elements J."""
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
    """HDF5 file the program writes (None: the namelist's base name with .h5); unused in memory."""
    record_every: int = 1
    """Record the tip and the energy every this many steps."""
    snapshot_every: int = 0
    """Record the beam's shape every this many steps (0: never)."""
    max_output_gb: float = 4.0
    """Refuse a run whose recorded data would exceed this many gigabytes (1e9 bytes)."""

    def __post_init__(self) -> None:
        for field in dataclasses.fields(self):
            value = getattr(self, field.name)
            object.__setattr__(self, field.name, _coerce(field.name, value))
        for key in ("lower", "upper"):
            object.__setattr__(self, key, _per_stop(key, getattr(self, key), len(self.nodes)))
        _check_name("stops", "law", self.law, tuple(LAWS))
        _check_name("time", "load_rule", self.load_rule, LOAD_RULES)
        _check_name("time", "start", self.start, STARTS)

    # ------------------------------------------------------------------ construction

    @classmethod
    def from_keys(cls, values: Mapping[str, Any], source: str = "scene") -> Scene:
        """A scene from namelist keys (fields and routes, flat), starting from the defaults."""
        return cls().replace(_source=source, **dict(values))

    @classmethod
    def from_namelist(cls, path: PathLike) -> Scene:
        """Read a scene from a namelist file with f90nml, as the ``beamstops`` program reads it.

        Missing groups and keys keep the paper's values, and ``file`` defaults to the
        file's base name with ``.h5``. The engine reads the same file too and has the last
        word: a file it refuses raises :class:`ValueError` with the program's message, and
        the scene returned holds exactly the values the program would run.
        """
        from . import engine

        path = os.fspath(path)
        source = path
        if not Path(path).is_file():
            raise FileNotFoundError(f"{path}: cannot open: no such file")
        engine_scene = engine.read_namelist(path)  # ValueError with the program's message
        text = Path(path).read_text(encoding="utf-8", errors="replace")
        # A line holding only '&end' (or '$end') closes a group for the program; f90nml would
        # take it for a group named 'end' and stop reading. Text outside groups is ignored.
        text = re.sub(r"(?im)^[ \t]*[&$]end[ \t]*(!.*)?$", "/", text)
        try:
            nml = f90nml.reads(text)
        except Exception as exc:  # f90nml raises several types on syntax it does not know
            raise ValueError(f"{path}: f90nml cannot read this namelist: {exc}") from None
        values = _keys_of(nml, source)
        values.setdefault("file", _default_output(path))
        if values.get("law", cls.law) != "compliance":
            # the program reads a stiffness only with law='compliance'
            values.pop("stiffness", None)
            values.pop("stiffness_per_mass", None)
        scene = cls.from_keys(values, source=source)
        scene.validate(source)
        differences = scene.differences(engine_scene)
        if differences:
            raise ValueError(f"{path}: f90nml and the engine read different values ({differences}); "
                             "please report this file")
        return scene

    def replace(self, _source: str = "scene", **changes: Any) -> Scene:
        """A copy with some keys changed: any field, the material route or ``stiffness`` (N/m).

        The material keys go together (all four) and exclude ``k2`` and ``mass_per_length``;
        ``stiffness`` is converted with the (new) ``mass_per_length``; ``x`` gives ``nodes`` with
        the (new) ``length`` and ``elements``.
        """
        unknown = sorted(set(changes) - set(_GROUP_OF))
        if unknown:
            raise TypeError(f"unknown scene key(s) {', '.join(unknown)}; allowed: {', '.join(_GROUP_OF)}")
        fields = {key: value for key, value in changes.items() if key not in _ROUTES}
        material = {key: changes[key] for key in MATERIAL_KEYS if key in changes}
        if material:
            fields.update(_material(material, fields, _source))
        if "stiffness" in changes:
            stiffness = changes["stiffness"]
            if "stiffness_per_mass" in fields:
                raise ValueError(f"{_source}: &stops gives both stiffness (N/m) and stiffness_per_mass (1/s^2); "
                                 "allowed: exactly one of them")
            stiffness = _coerce("stiffness", stiffness)
            if not stiffness > 0:
                raise ValueError(f"{_source}: &stops stiffness = {stiffness!r} is out of range; "
                                 "allowed: stiffness > 0 (N/m)")
            mass = _coerce("mass_per_length", fields.get("mass_per_length", self.mass_per_length))
            fields["stiffness_per_mass"] = stiffness / mass
        if "x" in changes:
            if "nodes" in fields:
                raise ValueError(f"{_source}: &stops gives both nodes and x; allowed: one of them (node indices "
                                 "1..elements, or abscissae x = i*length/elements)")
            length = _coerce("length", fields.get("length", self.length))
            elements = _coerce("elements", fields.get("elements", self.elements))
            fields["nodes"] = _nodes_of(_coerce("x", changes["x"]), length, elements, _source)
        return dataclasses.replace(self, **fields)

    # ------------------------------------------------------------------ output

    def groups(self) -> dict[str, dict[str, Any]]:
        """The scene as namelist groups (what :meth:`to_namelist` writes)."""
        out: dict[str, dict[str, Any]] = {group: {} for group in GROUPS}
        for field in dataclasses.fields(self):
            value = getattr(self, field.name)
            if field.name == "file" and value is None:
                continue
            if field.name == "stiffness_per_mass" and self.law != "compliance":
                continue  # the program reads it only with law='compliance'
            if field.name == "nodes" and not value:
                continue  # the tip-only form
            if isinstance(value, tuple):
                value = list(value)
            out[_GROUP_OF[field.name]][field.name] = value
        return out

    def to_namelist(self, path: PathLike) -> None:
        """Write the scene as a namelist file the program reads (f90nml; reals round-trip exactly)."""
        nml = f90nml.Namelist([(group, f90nml.Namelist(list(keys.items()))) for group, keys in self.groups().items()])
        text = io.StringIO()
        nml.write(text)
        Path(path).write_text("! beamstops scene (written by beamstops.Scene.to_namelist)\n" + text.getvalue(),
                              encoding="utf-8")

    def to_dict(self) -> dict[str, Any]:
        """The fields as a flat dictionary."""
        return dataclasses.asdict(self)

    # ------------------------------------------------------------------ engine

    def validate(self, source: str = "scene") -> None:
        """Check every value with the engine; :class:`ValueError` names group, key and allowed range."""
        from . import engine

        engine.validate(self, source)

    def differences(self, other: Scene) -> str:
        """Keys whose values differ (bit for bit for reals), as text; '' when none."""
        out = []
        for field in dataclasses.fields(self):
            a, b = getattr(self, field.name), getattr(other, field.name)
            if isinstance(a, tuple) and isinstance(b, tuple):
                same = len(a) == len(b) and all(_same_float(p, q) if isinstance(p, float) else p == q
                                                 for p, q in zip(a, b))
            else:
                same = (a == b) if not isinstance(a, float) else _same_float(a, b)
            if not same:
                out.append(f"{field.name}: {a!r} != {b!r}")
        return "; ".join(out)


# ---------------------------------------------------------------------- helpers

_FLOATS = {"length", "k2", "mass_per_length", "amplitude", "omega", "stiffness_per_mass", "dt",
           "t_end", "beta", "max_output_gb", "stiffness"} | set(MATERIAL_KEYS)
_FLOAT_OR_LIST = {"lower", "upper"}
_LISTS = {"nodes": "an integer", "x": "a real number"}
_INTS = {"elements", "record_every", "snapshot_every"}
_BOOLS = {"allow_unstable"}
_TEXTS = {"law", "load_rule", "start", "file"}


def _coerce(key: str, value: Any) -> Any:
    """A value of the type its key holds; TypeError names the key otherwise."""
    if key in _FLOAT_OR_LIST:
        if isinstance(value, (list, tuple)) or (hasattr(value, "ndim") and getattr(value, "ndim", 0) > 0):
            return tuple(_coerce(key + "[]", v) for v in value)
        return _coerce(key + "[]", value)
    if key in ("lower[]", "upper[]", "x[]"):
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise TypeError(f"scene key {key[:-2]} must hold real numbers, not {value!r}")
        return float(value)
    if key in _LISTS:
        if not isinstance(value, (list, tuple)) and not (hasattr(value, "ndim") and getattr(value, "ndim", 0) > 0):
            value = (value,)  # one stop
        if key == "x":
            return tuple(_coerce("x[]", v) for v in value)
        out = []
        for v in value:
            if isinstance(v, bool):
                raise TypeError(f"scene key nodes must hold integers, not {v!r}")
            try:
                out.append(operator.index(v))
            except TypeError:
                raise TypeError(f"scene key nodes must hold integers, not {v!r}") from None
        return tuple(out)
    if key in _FLOATS:
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise TypeError(f"scene key {key} must be a real number, not {value!r}")
        return float(value)
    if key in _INTS:
        if isinstance(value, bool):
            raise TypeError(f"scene key {key} must be an integer, not {value!r}")
        try:
            return operator.index(value)
        except TypeError:
            raise TypeError(f"scene key {key} must be an integer, not {value!r}") from None
    if key in _BOOLS:
        if not isinstance(value, (bool,)) and type(value).__name__ != "bool_":
            raise TypeError(f"scene key {key} must be True or False, not {value!r}")
        return bool(value)
    if key in _TEXTS:
        if key == "file" and value is None:
            return None
        if isinstance(value, os.PathLike) and key == "file":
            value = os.fspath(value)
        if not isinstance(value, str):
            raise TypeError(f"scene key {key} must be a string, not {value!r}")
        return value
    raise TypeError(f"unknown scene key {key}")


def _per_stop(key: str, value: Union[float, tuple[float, ...]], m: int) -> Union[float, tuple[float, ...]]:
    """lower or upper for m stops along the span: a tuple of m values (one value given: for all);
    without stops along the span (m = 0), the tip's single value."""
    values = value if isinstance(value, tuple) else (value,)
    if m == 0:
        if len(values) != 1:
            raise ValueError(f"scene: &stops {key} has {len(values)} values but no stops along the span are given "
                             "(nodes or x); allowed: one value (the tip stop), or nodes or x with one value per stop")
        return values[0]
    if len(values) == 1:
        return values * m
    if len(values) != m:
        raise ValueError(f"scene: &stops {key} has {len(values)} values for {m} stops; allowed: one value "
                         f"(the same for every stop) or {m}")
    return values


def _nodes_of(x: tuple[float, ...], length: float, elements: int, source: str) -> tuple[int, ...]:
    """Node indices of abscissae x, each at a node to 1e-9 length (the engine's namelist rule)."""
    nodes = []
    h = length / elements
    for i, xi in enumerate(x, start=1):
        if not (xi > 0 and xi <= length * (1 + 1e-9)):
            raise ValueError(f"{source}: &stops x({i}) = {xi!r} is out of range; allowed: 0 < x <= length = "
                             f"{length!r} (x = 0 is the clamp)")
        node = max(1, min(elements, round(xi / h)))
        if abs(xi - length * node / elements) > 1e-9 * length:
            below = min(elements - 1, int(xi / h))
            raise ValueError(f"{source}: &stops x({i}) = {xi!r} is not at a node; allowed: x = i*length/elements "
                             f"to 1e-9*length (length = {length!r}, elements = {elements}); the nearest nodes are "
                             f"{below} (x = {length * below / elements!r}) and {below + 1} "
                             f"(x = {length * (below + 1) / elements!r})")
        nodes.append(node)
    return tuple(nodes)


def _check_name(group: str, key: str, value: str, allowed: tuple[str, ...]) -> None:
    if value not in allowed:
        names = ", ".join(f"'{name}'" for name in allowed[:-1]) + f" or '{allowed[-1]}'"
        raise ValueError(f"scene: &{group} {key} = '{value}' is out of range; allowed: {names}")


def _same_float(a: float, b: float) -> bool:
    return a == b and math.copysign(1.0, a) == math.copysign(1.0, b) or (math.isnan(a) and math.isnan(b))


def _material(material: dict[str, Any], fields: dict[str, Any], source: str) -> dict[str, float]:
    """k2 and mass_per_length from the tube's material and geometry, by the engine's formulas."""
    from . import engine

    for key in MATERIAL_KEYS:
        if key not in material:
            raise ValueError(f"{source}: &beam {key} is missing; allowed: give all of "
                             f"{', '.join(MATERIAL_KEYS)}, or none of them (then k2)")
    values = {key: _coerce(key, material[key]) for key in MATERIAL_KEYS}
    for key, value in values.items():
        if not (value > 0 and math.isfinite(value)):
            raise ValueError(f"{source}: &beam {key} = {value!r} is out of range; allowed: {key} > 0")
    if "k2" in fields or "mass_per_length" in fields:
        raise ValueError(f"{source}: &beam gives k2 or mass_per_length together with the material; allowed: "
                         f"either k2 (and mass_per_length) or {', '.join(MATERIAL_KEYS)}")
    if not values["wall_thickness"] <= values["outer_diameter"] / 2:
        raise ValueError(f"{source}: &beam wall_thickness = {values['wall_thickness']!r} is out of range; allowed: "
                         f"0 < wall_thickness <= outer_diameter/2 = {values['outer_diameter'] / 2!r}")
    k2, mass_per_length = engine.tube(**values)
    return {"k2": k2, "mass_per_length": mass_per_length}


def _keys_of(nml: f90nml.Namelist, source: str) -> dict[str, Any]:
    """Flat keys of a parsed namelist, with the program's null values (``key =``) dropped."""
    values: dict[str, Any] = {}
    for group, body in nml.items():
        if group == "end":  # an old-style '&end' terminator
            continue
        if group not in GROUPS:
            raise ValueError(f"{source}: unknown group &{group}; allowed groups: "
                             + ", ".join(f"&{g}" for g in GROUPS))
        for key, value in body.items():
            if key not in GROUPS[group]:
                raise ValueError(f"{source}: &{group}: unknown key {key}; keys of &{group}: "
                                 + ", ".join(GROUPS[group]))
            if isinstance(value, list):
                # 'key = x,' or 'key = x,,' (nulls after one value); 'key = x;' (gfortran's separator)
                value = [v for v in value if not (isinstance(v, str) and v == ";")] or [None]
            if isinstance(value, list) and key in ("nodes", "x", "lower", "upper"):
                while value and value[-1] is None:
                    value.pop()
                if any(v is None for v in value):
                    raise ValueError(f"{source}: &{group}: malformed value for {key}: {value!r}")
                value = value if len(value) != 1 else value[0]
                if isinstance(value, list) and not value:
                    continue
            elif isinstance(value, list):
                if any(v is not None for v in value[1:]):
                    raise ValueError(f"{source}: &{group}: malformed value for {key}: {value!r}")
                value = value[0]
            if value is None:
                continue
            if key in ("law", "load_rule", "start") and not isinstance(value, str):
                value = str(value)
            if key == "law":
                value = value.strip()  # the program compares trim(adjustl(law))
            elif key in ("load_rule", "start", "file"):
                value = value.rstrip()  # the program compares trim(...)
            values[key] = value
    return values


def _default_output(path: str) -> str:
    """The program's default output: the input's base name with '.h5' in place of its extension."""
    name = path[path.rfind("/") + 1:]
    dot = name.rfind(".")
    if dot > 0:
        name = name[:dot]
    return name + ".h5"

"""The engine, through the f2py extension ``beamstops._engine``.

Every routine of the extension (wrap/beamstops_wrap.f90) takes a scene as namelist text —
the exact text of :meth:`Scene.to_text` — and a source for its messages; the engine's one
reader reads and validates it, builds the model and runs the same time loop as the
``beamstops`` program, recording into memory instead of an HDF5 file. An engine error
(status /= 0) becomes a :class:`ValueError` carrying the engine's message.
"""

from __future__ import annotations

import os
import re
import signal
import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Iterable, Optional

import numpy as np

from . import _engine
from .engine_call import engine_call
from .result import IncompleteRunError, Result

if TYPE_CHECKING:
    from .scene import PathLike, Scene

__all__ = ["run", "stability", "sizes", "canonical", "validate", "read_file", "read_namelist", "keys", "version", "Stability"]


def _text(value: Any) -> str:
    """f2py returns fixed-length character outputs as bytes, blank-padded (character inputs
    are passed as bytes too, file-system encoded, so that any path goes through)."""
    if isinstance(value, (bytes, np.bytes_)):
        value = bytes(value).decode("utf-8", errors="replace")
    return str(value).rstrip(" \x00")


def _source(source: Any) -> bytes:
    """The name a message starts with, for the engine (a TypeError when it is not a str)."""
    if not isinstance(source, str):
        raise TypeError(f"source = {source!r}: allowed: a str, the name the messages start with (e.g. 'scene')")
    return os.fsencode(source)


def flag(name: str, value: Any, where: str = "run") -> bool:
    """A keyword that is True or False (a numpy bool too); a TypeError naming it otherwise ('no',
    1 or None were taken for what they are as a condition)."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{where}: {name} = {value!r}; allowed: True or False")
    return bool(value)


def _check(status: int, message: Any) -> None:
    if status != 0:
        raise ValueError(_text(message))


def interruptible() -> int:
    """1 in the main thread: the engine's loop then catches Ctrl-C (SIGINT) and SIGTERM and stops
    within a block (a few ms) instead of at its end; the caller raises the signal again
    (:func:`raise_stop_signal`). Other threads leave the signals alone (0)."""
    return int(threading.current_thread() is threading.main_thread())


def raise_stop_signal() -> None:
    """Raise again the signal that stopped the engine's last interruptible loop, for Python's own
    handler (KeyboardInterrupt for Ctrl-C, the process's end for SIGTERM's default)."""
    signum = int(engine_call(_engine.bs_stop_signal))
    if signum:
        signal.raise_signal(signum)


def _scene_text(scene: Scene) -> bytes:
    from .scene import Scene

    if not isinstance(scene, Scene):
        raise TypeError(f"expected a beamstops.Scene, not {type(scene).__name__}")
    return scene.to_text().encode("utf-8")


def version() -> str:
    """The engine's version."""
    return _text(engine_call(_engine.bs_version))


def keys() -> dict[str, tuple[str, ...]]:
    """The namelist groups and the keys the engine's reader accepts in each."""
    out: dict[str, tuple[str, ...]] = {}
    for line in _text(engine_call(_engine.bs_keys)).splitlines():
        group, _, names = line.partition(":")
        out[group.strip()] = tuple(name.strip() for name in names.split(",") if name.strip())
    return out


def canonical(text: str, source: str = "scene", carried: Iterable[str] = ()) -> str:
    """The engine's canonical text of namelist text (every key, defaults filled in).

    ``carried``: keys (``"group:key"``) the text carries over from a scene being changed rather
    than gives anew; the engine drops such a key where it would do nothing (a spring without the
    compliance law, ``&damping modes`` without ``ratio``) instead of refusing it."""
    words = " ".join(carried) or " "
    # f2py hands the engine a text up to its first NUL (what follows was dropped unsaid): a NUL
    # goes as another control character, which the engine refuses as binary as it refuses NUL
    if not isinstance(text, str):
        raise TypeError(f"canonical: text must be a str of namelist text, not {type(text).__name__}")
    result, status, message = engine_call(_engine.bs_scene, text.replace("\x00", "\x01").encode("utf-8"),
                                          _source(source),
                                          words.encode("utf-8"))
    _check(status, message)
    return _text(result)


def validate(scene: Scene, source: str = "scene") -> None:
    """Whether the program would run the scene (ValueError with the engine's message when not): the
    engine's reader and the check of ``beamstops run`` (the time step against the stability limit
    of the model the run steps), messages starting with ``source``."""
    refusal = stability(scene, source).refusal
    if refusal is not None:
        raise ValueError(refusal)


def read_file(path: PathLike) -> str:
    """The canonical text of the scene of a namelist file, read as the program reads it."""
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(f"path = {path!r}: allowed: a str or an os.PathLike naming a namelist file")
    result, status, message = engine_call(_engine.bs_read_file, os.fsencode(os.fspath(path)))
    if status != 0 and not os.path.exists(path):
        raise FileNotFoundError(_text(message))
    _check(status, message)
    return _text(result)


def read_namelist(path: PathLike) -> Scene:
    """The scene the program itself reads from a file (same as :meth:`Scene.from_namelist`)."""
    from .scene import Scene

    return Scene.from_namelist(path)


def sizes(scene: Scene) -> tuple[int, int, int, int]:
    """Records and snapshots of a complete run, nodes J+1 per snapshot, stops along the span."""
    records, snapshots, nodes, stops, status, message = engine_call(_engine.bs_sizes, _scene_text(scene), b"scene")
    _check(status, message)
    return int(records), int(snapshots), int(nodes), int(stops)


@dataclass(frozen=True)
class Stability:
    """Spectrum and time-step limits of a scene (SPEC §6), all from the engine's model."""

    kappa_h: float
    """Largest generalized eigenvalue κ_h of (S, M) (1/s²)."""
    kappa_bound: float
    """The paper's upper bound κ̃ (5.2) (1/s²)."""
    kappa_contact: float
    """Largest eigenvalue with the compliance spring at the tip (= κ_h for other laws) (1/s²)."""
    kappa_method: str
    """How κ_h was computed: 'dsbgv' (exact) or 'inverse iteration'."""
    dt_limit_newmark: float
    """Linear Newmark limit 2/sqrt((1-4β)κ) for β < 1/4, +inf otherwise (s)."""
    dt_limit_paper: float
    """Paper's condition (3.1) with the exact κ_h, 2/sqrt((1-2β)κ_h); +inf for β = 1/2 (s)."""
    dt_limit_paper_bound: float
    """Paper's condition (3.1) with its bound κ̃ (s); 3.3469e-6 s for the paper's scene at β = 1/4."""
    kappa_run: float
    """Largest eigenvalue of the model the run steps (the reduced one with ``modes`` > 0; with the
    compliance spring); 0 for a reduced model with β ≥ 1/4, where it is not computed (1/s²)."""
    dt_limit_run: float
    """Linear Newmark limit of the model the run steps, the one the engine applies (s)."""
    run_model: str
    """Which model the run steps: 'full model' or 'reduced model of r modes'."""
    dt: float
    """The scene's time step (s)."""
    refusal: Optional[str]
    """Why the engine would refuse to run the scene (dt beyond the linear limit of the model the
    run steps: the check of ``beamstops run`` and ``beamstops info``), or None."""

    @property
    def runnable(self) -> bool:
        """Whether :func:`run` accepts the scene's time step."""
        return self.refusal is None


def stability(scene: Scene, source: str = "scene") -> Stability:
    """κ_h, the paper's κ̃ and the time-step limits of a scene (builds the model, does not run);
    messages start with ``source``."""
    (kappa_h, kappa_bound, kappa_contact, dt_newmark, dt_paper, dt_paper_bound, method, kappa_run, dt_run,
     run_model, refused, refusal, status, message) = engine_call(_engine.bs_stability, _scene_text(scene),
                                                                 _source(source))
    _check(status, message)
    return Stability(kappa_h=float(kappa_h), kappa_bound=float(kappa_bound), kappa_contact=float(kappa_contact),
                     kappa_method=_text(method), dt_limit_newmark=float(dt_newmark),
                     dt_limit_paper=float(dt_paper), dt_limit_paper_bound=float(dt_paper_bound),
                     kappa_run=float(kappa_run), dt_limit_run=float(dt_run), run_model=_text(run_model),
                     dt=scene.dt, refusal=_text(refusal) if refused else None)


# `name = value` at the start of a line; a quoted value may span lines (the scene's text).
_ATTRIBUTE = re.compile(r"^(\w+) = ('(?:[^']|'')*'|[^\n]*)$", re.M)


def attributes_of(lines: str) -> dict[str, Any]:
    """The engine's attribute lines `name = value` as a dictionary (the output file's root attributes)."""
    from .scene import parse_value

    return {match.group(1): parse_value(match.group(2)) for match in _ATTRIBUTE.finditer(lines)}


def _observations(scene: Scene, fields: list[str], shocks: np.ndarray, value: np.ndarray, half: np.ndarray, entries: np.ndarray,
                  labels: str) -> dict[str, Any]:
    """The engine's shock log and statistics as Result fields (the layout of /impacts and /statistics)."""
    from .observations import Statistic

    if not scene.enabled:
        return {}
    impacts = {name: np.ascontiguousarray(shocks[i]) for i, name in enumerate(fields)}
    tables: dict[str, dict[str, Statistic]] = {"statistics": {}, "ensemble": {}}
    for k, line in enumerate(labels.splitlines()):
        name, unit, axis, table = line.split()
        n = int(entries[k])
        tables[table][name] = Statistic(value=value[:n, k].copy(), half_width=half[:n, k].copy(), unit=unit,
                                        axis=axis)
    settings = {"transient": scene.transient, "batches": scene.batches, "bins": scene.bins,
                "rest_time": scene.rest_time}
    return {"impacts": impacts, "statistics": tables["statistics"], "statistics_attrs": settings,
            "ensemble": tables["ensemble"]}


#: Most rows of the shock log :func:`run` makes room for at first (each row a few values; a run
#: with more shocks runs again with room for every one).
MAX_SHOCK_CAPACITY = 100_000_000


def run(scene: Scene, *, allow_incomplete: bool = False, shock_capacity: int = 4096) -> Result:
    """Run a scene in memory and return its :class:`Result` (no file is written).

    Same engine loop as ``beamstops run``: for the same scene, every array and every
    attribute but ``cpu_seconds`` equals the program's HDF5 output bit for bit.
    A run that does not complete (it diverged) raises :class:`IncompleteRunError`
    (a ValueError holding the partial result) unless ``allow_incomplete``. ``shock_capacity``: rows
    of the shock log to make room for (a run with more shocks runs again, with room for every one).
    """
    allow_incomplete = flag("allow_incomplete", allow_incomplete)
    if (isinstance(shock_capacity, bool) or not isinstance(shock_capacity, (int, np.integer))
            or not 1 <= shock_capacity <= MAX_SHOCK_CAPACITY):
        raise ValueError(f"run: shock_capacity = {shock_capacity!r} is out of range; allowed: a whole number, "
                         f"1 <= shock_capacity <= {MAX_SHOCK_CAPACITY} (rows of the shock log to make room for; a "
                         "run with more shocks runs again, with room for every one)")
    text = _scene_text(scene)
    records, snapshots, nodes, stops = sizes(scene)
    width = max(stops, 1, scene.bins + 1)
    capacity = int(shock_capacity)
    stoppable = interruptible()
    while True:
        (t, tip_u, tip_v, reaction, energy, work, dissipated, damped, snapshot_t, snapshot_x, snapshot_u, stops_x,
         stops_u, stops_reaction, filled, snaps, shocks, shock_count, shock_labels, stat_value, stat_half, stat_entries,
         stat_labels, attribute_text, status, message) = engine_call(
            _engine.bs_run, text, b"scene", records, snapshots, nodes, stops, capacity, width, stoppable)
        _check(status, message)
        attrs = attributes_of(_text(attribute_text))
        if attrs.get("status") == "interrupted":
            raise_stop_signal()
            break  # a handler that returned: the records so far (status 'interrupted')
        if int(shock_count) <= capacity:
            break
        capacity = int(shock_count)  # the same deterministic run again, with room for every shock
    filled, snaps = int(filled), int(snaps)
    cut: Callable[[np.ndarray], np.ndarray] = (lambda a: a) if filled == records else (lambda a: a[:filled].copy())
    result = Result(
        t=cut(t), tip_u=cut(tip_u), tip_v=cut(tip_v), reaction=cut(reaction), energy=cut(energy),
        work=cut(work), dissipated=cut(dissipated), damped=cut(damped),
        snapshot_t=snapshot_t[:snaps] if snaps == snapshots else snapshot_t[:snaps].copy(),
        snapshot_x=snapshot_x,
        snapshot_u=np.ascontiguousarray(snapshot_u.T[:snaps]),
        stops_x=stops_x,
        stops_node=np.array(scene.nodes, dtype=np.float64),
        stops_lower=np.array(scene.lower if scene.nodes else (), dtype=np.float64),
        stops_upper=np.array(scene.upper if scene.nodes else (), dtype=np.float64),
        stops_u=np.ascontiguousarray(stops_u.T[:filled]), stops_reaction=np.ascontiguousarray(stops_reaction.T[:filled]),
        attrs=attrs, source="memory", **_observations(scene, _text(shock_labels).split(), shocks[:, :int(shock_count)], stat_value, stat_half,
                                                     stat_entries, _text(stat_labels)))
    if attrs.get("status") != "complete" and not allow_incomplete:
        raise IncompleteRunError(f"scene: run {attrs.get('status')}: {attrs.get('message', '')}", result)
    return result

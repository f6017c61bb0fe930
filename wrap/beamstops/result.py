"""The result of a run: the arrays of the program's HDF5 layout and the run's attributes.

=================  =====================  =========================================
Result             HDF5 (program output)  meaning
=================  =====================  =========================================
t                  /tip/t (= /energy/t)   record times (s)
tip_u              /tip/u                 tip displacement u(L, t) (m)
tip_v              /tip/v                 tip velocity (m/s)
reaction           /tip/reaction          contact reaction (N)
energy             /energy/E              discrete energy E^{n+1/2} (J)
work               /energy/work           work of the load (J)
dissipated         /energy/dissipated     energy taken by the stops (J)
damped             /energy/damped         energy taken by the Rayleigh damping (J)
snapshot_t         /snapshots/t           snapshot times (s)
snapshot_x         /snapshots/x           node abscissae x_0..x_J (m)
snapshot_u         /snapshots/u           physical displacement ũ(x, t), (snapshots, J+1) (m)
stops_x            /stops/x               abscissae of the stops along the span (m)
stops_node         /stops/node            their node indices 1..J (float64, whole numbers)
stops_lower        /stops/lower           their lower stops (m)
stops_upper        /stops/upper           their upper stops (m)
stops_u            /stops/u               physical displacement ũ at each stop, (records, m) (m)
stops_reaction     /stops/reaction        reaction of each stop, (records, m) (N)
impacts            /impacts/NAME          the engine's shock log: {NAME: one value per shock}
statistics         /statistics/NAME       the engine's statistics: {NAME: Statistic}
statistics_attrs   /statistics attributes transient (s), batches, bins, rest_time (s)
ensemble           /ensemble/NAME         &ensemble members > 1: {NAME: Statistic} across the members
attrs              root attributes        scene, κ_h, limits, status, steps, cpu_seconds, …
=================  =====================  =========================================

Without stops along the span (the tip-only form) the ``stops_*`` arrays are empty
(``stops_u`` and ``stops_reaction`` of shape (records, 0)). Without a shock log or
statistics (a file written before the engine kept them) ``impacts``, ``statistics`` and
``statistics_attrs`` are empty dicts. Their columns, names and units are in
:mod:`beamstops.observations` (definitions: docs/statistics.md); :meth:`Result.impacts_frame`
and :meth:`Result.statistics_frame` give them as pandas DataFrames when pandas is installed.

:func:`load` reads a file written by ``beamstops run``; :func:`beamstops.run` gives the
same object from memory.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np

from .observations import Statistic, _plain, impacts_frame, read_impacts, read_statistics, statistics_frame

__all__ = ["Result", "Statistic", "IncompleteRunError", "load", "ARRAYS"]

#: Result arrays and the HDF5 datasets they come from.
ARRAYS: dict[str, str] = {
    "t": "tip/t",
    "tip_u": "tip/u",
    "tip_v": "tip/v",
    "reaction": "tip/reaction",
    "energy": "energy/E",
    "work": "energy/work",
    "dissipated": "energy/dissipated",
    "damped": "energy/damped",
    "snapshot_t": "snapshots/t",
    "snapshot_x": "snapshots/x",
    "snapshot_u": "snapshots/u",
    "stops_x": "stops/x",
    "stops_node": "stops/node",
    "stops_lower": "stops/lower",
    "stops_upper": "stops/upper",
    "stops_u": "stops/u",
    "stops_reaction": "stops/reaction",
}


class IncompleteRunError(ValueError):
    """A run that did not complete (diverged, failed or interrupted); ``result`` holds what was recorded.

    ``reason`` is what is wrong (the message without its advice, which names the Python keyword
    ``allow_incomplete``: a command line names its own option instead)."""

    def __init__(self, message: str, result: Optional[Result] = None, reason: Optional[str] = None) -> None:
        super().__init__(message)
        self.result = result
        self.reason = reason if reason is not None else message


@dataclass(eq=False)
class Result:
    """Arrays and attributes of one run (the table of :mod:`beamstops.result`: each field, its HDF5 dataset, units)."""

    t: np.ndarray
    tip_u: np.ndarray
    tip_v: np.ndarray
    reaction: np.ndarray
    energy: np.ndarray
    work: np.ndarray
    dissipated: np.ndarray
    snapshot_t: np.ndarray
    snapshot_x: np.ndarray
    snapshot_u: np.ndarray
    damped: np.ndarray = field(default_factory=lambda: np.empty(0))
    stops_x: np.ndarray = field(default_factory=lambda: np.empty(0))
    stops_node: np.ndarray = field(default_factory=lambda: np.empty(0))
    stops_lower: np.ndarray = field(default_factory=lambda: np.empty(0))
    stops_upper: np.ndarray = field(default_factory=lambda: np.empty(0))
    stops_u: np.ndarray = field(default_factory=lambda: np.empty((0, 0)))
    stops_reaction: np.ndarray = field(default_factory=lambda: np.empty((0, 0)))
    impacts: dict[str, np.ndarray] = field(default_factory=dict)
    """The shock log, one 1-d array per column of /impacts ({} when none was recorded)."""
    statistics: dict[str, Statistic] = field(default_factory=dict)
    """The engine's statistics by name ({} when none were computed)."""
    statistics_attrs: dict[str, Any] = field(default_factory=dict)
    """Attributes of the statistics: transient (s), batches, bins, rest_time (s)."""
    ensemble: dict[str, Statistic] = field(default_factory=dict)
    """With &ensemble members > 1: each statistic across the members, mean and t s/sqrt(K) (/ensemble)."""
    attrs: dict[str, Any] = field(default_factory=dict)
    source: str = "memory"
    """'memory' for :func:`beamstops.run`, the file name for :func:`load`."""

    @property
    def status(self) -> str:
        """'complete', 'diverged', 'failed', 'interrupted' (stopped by SIGINT or SIGTERM, a
        checkpoint saved) or 'running' (a program still running, or killed)."""
        return str(self.attrs.get("status", "unknown"))

    @property
    def snapshots(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(snapshot_t, snapshot_x, snapshot_u)."""
        return self.snapshot_t, self.snapshot_x, self.snapshot_u

    @property
    def shocks(self) -> int:
        """Number of rows of the shock log (0 when none was recorded)."""
        return int(next(iter(self.impacts.values())).size) if self.impacts else 0

    def impacts_frame(self) -> Any:
        """The shock log as a pandas DataFrame, one row per shock (ImportError without pandas)."""
        return impacts_frame(self.impacts)

    def statistics_frame(self) -> Any:
        """The statistics as a pandas DataFrame indexed by (name, index) (ImportError without pandas)."""
        return statistics_frame(self.statistics)

    def scene(self) -> Any:
        """The :class:`beamstops.Scene` of the run, from its ``scene`` attribute (the engine's canonical text)."""
        from .scene import Scene

        if "scene" not in self.attrs:
            raise ValueError(f"{self.source}: no scene attribute (written by a beamstops older than 0.2)")
        return Scene.from_text(str(self.attrs["scene"]), self.source)

    def __repr__(self) -> str:
        a = self.attrs
        return (f"Result({self.source!r}, status={self.status!r}, law={a.get('law')!r}, dt={a.get('dt')!r}, "
                f"records={self.t.size}, snapshots={self.snapshot_t.size}, shocks={self.shocks}, "
                f"steps={a.get('steps')!r}, "
                f"cpu_seconds={a.get('cpu_seconds')!r})")


def _read(path: str) -> tuple[dict[str, Any], dict[str, np.ndarray], dict[str, np.ndarray], dict[str, Statistic],
                              dict[str, Any], dict[str, Statistic]]:
    """The attributes, arrays, shock log, statistics (with their settings) and ensemble table of
    a file written by ``beamstops run``."""
    import h5py

    with h5py.File(path, "r") as f:
        attrs = {name: _plain(value) for name, value in f.attrs.items()}
        if "status" not in attrs:
            raise ValueError(f"{path}: not a beamstops output (no status attribute)")
        arrays: dict[str, np.ndarray] = {}
        for name, dataset in ARRAYS.items():
            if dataset in f:
                try:
                    arrays[name] = np.asarray(f[dataset][()], dtype=np.float64)
                except (TypeError, ValueError, AttributeError):
                    raise ValueError(f"{path}: /{dataset}: not numbers (it holds {_holds(f[dataset])}); not the "
                                     f"output of `beamstops run`, or damaged") from None
        impacts = read_impacts(f, path)
        statistics, statistics_attrs = read_statistics(f, path)
        ensemble, _ = read_statistics(f, path, "ensemble")
    return attrs, arrays, impacts, statistics, statistics_attrs, ensemble


def _holds(item: Any) -> str:
    """What an HDF5 item holds, in words: a dataset's type and shape, or a group."""
    dtype = getattr(item, "dtype", None)
    return f"{dtype} of shape {item.shape}" if dtype is not None else "a group, not a dataset"


#: The series every output with records holds (``damped`` and the snapshots' abscissae came later).
REQUIRED = ("t", "tip_u", "tip_v", "reaction", "energy", "work", "dissipated")


def _check_layout(path: str, arrays: dict[str, np.ndarray], attrs: dict[str, Any]) -> None:
    """Refuse a file whose series are missing (a run that recorded writes them all) or do not fit
    together (a series per record, the snapshots' shape), naming the file and the dataset: the
    plots would fail later in matplotlib's words, without the file's name."""
    def fail(name: str, what: str) -> None:
        raise ValueError(f"{path}: /{ARRAYS[name]}: {what}; not the output of `beamstops run`, or damaged")

    records = arrays["t"].shape[0] if "t" in arrays and arrays["t"].ndim == 1 else None
    for name in REQUIRED if records else ():
        if name not in arrays:
            fail(name, f"missing, where /tip/t has {records} records")
    for name in RECORD_SERIES:
        if name in arrays:
            value, ndim = arrays[name], (2 if name.startswith("stops_") else 1)
            if value.ndim != ndim:
                fail(name, f"{value.ndim} dimension(s) of shape {value.shape}, where a series has {ndim}")
            if records is not None and value.shape[0] != records:
                fail(name, f"{value.shape[0]} records where /tip/t has {records}")
    x, u, t = arrays.get("snapshot_x"), arrays.get("snapshot_u"), arrays.get("snapshot_t")
    elements = attrs.get("elements")
    if x is not None:
        if x.ndim != 1 or (x.size and isinstance(elements, (int, np.integer)) and x.size != int(elements) + 1):
            fail("snapshot_x", f"shape {x.shape}, where the run's {elements} elements have {elements} + 1 nodes")
        if u is not None and (u.ndim != 2 or u.shape[1] != x.size):
            fail("snapshot_u", f"shape {u.shape}, where /snapshots/x has {x.size} nodes")
    if u is not None and t is not None and (t.ndim != 1 or u.shape[0] != t.shape[0]):
        fail("snapshot_u", f"{u.shape[0]} snapshots where /snapshots/t has shape {t.shape}")


def _raise_eoa(path: str) -> bool:
    """Raise the end of allocation the file's superblock records to the file's size (the
    engine's ``raise_hdf5_eoa``, as ``h5clear --increment=0``): everything a killed run wrote is
    in the file, and its indexes may point past the allocation its last flush recorded. True
    when it was raised."""
    from . import _engine
    from .engine_call import engine_call

    return bool(engine_call(_engine.bs_raise_hdf5_eoa, path.encode()))


RECORD_SERIES = ("t", "tip_u", "tip_v", "reaction", "energy", "work", "dissipated", "damped", "stops_u", "stops_reaction")
"""The arrays with one entry a record."""


def _common_records(arrays: dict[str, np.ndarray]) -> None:
    """The records every series holds, in place: an output that did not complete may hold one
    series a record or a buffer longer than another (the writer hands its buffers over when any
    of them is full, the values at the stops coming a step ahead of the tip's row, and a run
    that stopped between two hand-overs, or was killed during one, wrote some of them)."""
    lengths = [arrays[name].shape[0] for name in RECORD_SERIES if name in arrays]
    if lengths:
        common = min(lengths)
        for name in RECORD_SERIES:
            if name in arrays:
                arrays[name] = arrays[name][:common]


def load(path: str | os.PathLike[str], allow_incomplete: bool = False) -> Result:
    """Read the HDF5 output of ``beamstops run``.

    A file whose ``status`` is not 'complete' (a run that diverged, failed or is still
    being written) raises :class:`IncompleteRunError` (a ValueError, holding what the
    file has) unless ``allow_incomplete``. A file HDF5 refuses with "addr overflow" (a run
    killed while HDF5 flushed it) has the end of allocation its superblock records raised to its
    size, in place, and is read again (what ``h5clear --increment=0`` does; nothing else of the
    file changes). The series of a file that is not complete are cut to the records they all hold.
    """
    from .engine import flag

    allow_incomplete = flag("allow_incomplete", allow_incomplete, "load")
    path = os.fspath(path)
    if os.path.isdir(path):
        raise IsADirectoryError(f"{path}: is a folder, not the HDF5 output of `beamstops run`; name the file")
    if not os.path.isfile(path):
        raise FileNotFoundError(f"{path}: no such file")
    try:
        attrs, arrays, impacts, statistics, statistics_attrs, ensemble = _read(path)
    except (OSError, RuntimeError) as exc:
        # a run killed while HDF5 flushed its file: indexes past the allocation the file records
        if "addr overflow" not in str(exc) or not _raise_eoa(path):
            raise OSError(f"{path}: cannot read as HDF5 ({exc})") from None
        attrs, arrays, impacts, statistics, statistics_attrs, ensemble = _read(path)
    nodes = arrays["snapshot_x"].size if "snapshot_x" in arrays else 0
    arrays.setdefault("snapshot_t", np.empty(0))
    arrays.setdefault("snapshot_x", np.empty(0))
    arrays.setdefault("snapshot_u", np.empty((0, nodes)))
    if attrs.get("status") != "complete":
        _common_records(arrays)
        shown = min(arrays["snapshot_t"].shape[0], arrays["snapshot_u"].shape[0])  # the snapshots both hold
        arrays["snapshot_t"], arrays["snapshot_u"] = arrays["snapshot_t"][:shown], arrays["snapshot_u"][:shown]
    _check_layout(path, arrays, attrs)
    records = arrays["t"].size if "t" in arrays else 0
    arrays.setdefault("stops_u", np.empty((records, 0)))
    arrays.setdefault("stops_reaction", np.empty((records, 0)))
    for name in ARRAYS:
        arrays.setdefault(name, np.empty(0))
    result = Result(**arrays, impacts=impacts, statistics=statistics, statistics_attrs=statistics_attrs, ensemble=ensemble,
                    attrs=attrs, source=path)
    if result.status != "complete" and not allow_incomplete:
        reason = f"{path}: run {result.status}: {attrs.get('message', 'not complete')}"
        raise IncompleteRunError(f"{reason}; pass allow_incomplete=True to read what it holds", result, reason)
    return result

"""The engine's shock log and statistics as Python reads them (definitions: docs/statistics.md).

=================  ====================  ==================================================
Result             HDF5 (program output)  meaning
=================  ====================  ==================================================
impacts            /impacts/NAME          one row per shock, NAME in :data:`IMPACT_FIELDS`
statistics         /statistics/NAME       :class:`Statistic` per NAME (value, 95 % half-width)
statistics_attrs   /statistics attributes ``transient`` (s), ``batches``, ``bins``, ``rest_time`` (s)
=================  ====================  ==================================================

Nothing here computes a statistic: the engine does. This module reads the groups, checks
their shapes, and formats them (``str(statistic)``, pandas frames when pandas is installed).
An absent group reads as an empty dict (files written before the engine logged shocks).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    import h5py
    import pandas

__all__ = ["Statistic", "IMPACT_FIELDS", "IMPACT_UNITS", "STATISTIC_NAMES", "AXES", "read_impacts",
           "read_statistics", "impacts_frame", "statistics_frame"]

#: Columns of the shock log and their units (the ``units`` attribute of each /impacts dataset).
IMPACT_UNITS: dict[str, str] = {
    "t_start": "s", "t_end": "s", "stop": "1", "side": "1", "velocity_in": "m/s", "velocity_out": "m/s",
    "impulse": "N s", "peak_reaction": "N", "energy_taken": "J", "contact_time": "s", "rebounds": "1",
    "contact_steps": "1", "truncated": "1",
}
IMPACT_FIELDS: tuple[str, ...] = tuple(IMPACT_UNITS)
#: Shock-log columns that hold whole numbers (integers in :func:`impacts_frame`).
_INTEGER_FIELDS = ("stop", "side", "rebounds", "contact_steps")

#: Statistics the engine writes under /statistics (docs/statistics.md).
STATISTIC_NAMES: tuple[str, ...] = (
    "window", "shocks", "contact_phases", "shocks_per_second", "rebounds_per_shock", "force_mean", "force_rms",
    "force_max", "force_mean_contact", "force_rms_contact", "shock_duration_mean", "shock_duration_min",
    "shock_duration_max", "contact_fraction", "impulse_rate", "power", "tip_mean", "tip_rms", "tip_min", "tip_max",
    "tip_histogram", "tip_histogram_edges",
)
#: What the entries of a statistic run over: one per stop, one for the tip or the run, per bin, per bin edge.
AXES: tuple[str, ...] = ("stop", "tip", "run", "bin", "edge")


def _text(value: Any) -> str:
    if isinstance(value, (bytes, np.bytes_)):
        return bytes(value).decode("utf-8", errors="replace").rstrip(" \x00")
    if isinstance(value, np.ndarray):
        value = value[()] if value.shape == () else value.ravel()[0]
        return _text(value)
    return str(value)


def _plain(value: Any) -> Any:
    if isinstance(value, (bytes, np.bytes_, str)):
        return _text(value)
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value[()]
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    return value


def _number(value: float, half_width: float) -> str:
    """value ± half-width, the value rounded where the half-width's second significant digit falls."""
    if not math.isfinite(value):
        return str(value)
    if not math.isfinite(half_width) or half_width <= 0:
        return f"{value:.4g}"
    digits = 1 - math.floor(math.log10(half_width))  # decimals keeping 2 significant digits of the half-width
    scale = max(abs(value), half_width)
    if digits > 6 or scale >= 1e6:  # a shared power of ten: (5.60 ± 0.31)e-06
        exponent = math.floor(math.log10(scale))
        mantissa_digits = max(digits + exponent, 0)
        v, h = value / 10.0**exponent, half_width / 10.0**exponent
        return f"({v:.{mantissa_digits}f} ± {h:.{mantissa_digits}f})e{exponent:+03d}"
    decimals = max(digits, 0)
    return f"{round(value, digits):.{decimals}f} ± {round(half_width, digits):.{decimals}f}"


@dataclass(frozen=True, eq=False)
class Statistic:
    """One statistic of the engine: its value(s) and 95 % half-width(s) (NaN where not defined).

    ``axis`` says what the entries run over: 'stop' (one per stop), 'tip' or 'run' (one),
    'bin' (the tip histogram's bins) or 'edge' (its bins + 1 edges). ``str()`` gives
    ``0.560 ± 0.031 W`` (the value rounded to the half-width's second significant digit).
    """

    value: np.ndarray
    half_width: np.ndarray
    unit: str
    axis: str

    @classmethod
    def from_table(cls, table: Any, unit: str = "", axis: str = "", name: str = "statistic") -> Statistic:
        """From the (count, 2) table of the HDF5 layout: column 0 the value, column 1 the half-width."""
        array = np.asarray(table, dtype=np.float64)
        if array.ndim == 1 and array.size == 2:
            array = array.reshape(1, 2)
        if array.ndim != 2 or array.shape[1] != 2:
            raise ValueError(f"{name}: expected a (count, 2) table of value and half-width, got shape {array.shape}")
        return cls(value=array[:, 0].copy(), half_width=array[:, 1].copy(), unit=unit, axis=axis)

    def __len__(self) -> int:
        return int(self.value.size)

    def __float__(self) -> float:
        if self.value.size != 1:
            raise TypeError(f"a statistic of {self.value.size} entries (axis {self.axis!r}) is not one number")
        return float(self.value[0])

    def __str__(self) -> str:
        unit = "" if self.unit in ("", "1") else f" {self.unit}"
        entries = [_number(float(v), float(h)) for v, h in zip(self.value, self.half_width)]
        if len(entries) == 1:
            return entries[0] + unit
        return "[" + ", ".join(entries) + "]" + unit

    def __repr__(self) -> str:
        return f"Statistic({self}, axis={self.axis!r})"


def read_impacts(file: h5py.File, source: str = "") -> dict[str, np.ndarray]:
    """The /impacts group as 1-d float64 arrays of one length (empty dict when the group is absent)."""
    if "impacts" not in file:
        return {}
    group = file["impacts"]
    impacts = {name: np.asarray(group[name][()], dtype=np.float64).reshape(-1) for name in group
               if hasattr(group[name], "shape")}
    lengths = {name: array.size for name, array in impacts.items()}
    if len(set(lengths.values())) > 1:
        raise ValueError(f"{source}: /impacts columns differ in length: "
                         + ", ".join(f"{n} {k}" for n, k in lengths.items()))
    return impacts


def read_statistics(file: h5py.File, source: str = "", group_name: str = "statistics"
                    ) -> tuple[dict[str, Statistic], dict[str, Any]]:
    """The /statistics group (or /ensemble): {name: Statistic} and the group's attributes ({} and {} when absent)."""
    if group_name not in file:
        return {}, {}
    group = file[group_name]
    statistics: dict[str, Statistic] = {}
    for name in group:
        dataset = group[name]
        if not hasattr(dataset, "shape"):
            continue
        statistics[name] = Statistic.from_table(
            dataset[()], unit=_text(dataset.attrs.get("units", "")), axis=_text(dataset.attrs.get("axis", "")),
            name=f"{source}: /{group_name}/{name}")
    attrs = {name: _plain(value) for name, value in group.attrs.items()}
    return statistics, attrs


def _pandas(what: str) -> Any:
    try:
        import pandas
    except ImportError:
        raise ImportError(f"{what} needs pandas, which is not installed (pip install pandas); "
                          "the same data is in the Result as numpy arrays") from None
    return pandas


def impacts_frame(impacts: Mapping[str, np.ndarray]) -> pandas.DataFrame:
    """The shock log as a DataFrame, one row per shock (whole-number columns as integers, truncated as bool)."""
    pandas = _pandas("Result.impacts_frame()")
    columns: dict[str, np.ndarray] = {}
    for name, array in impacts.items():
        if name in _INTEGER_FIELDS and np.all(np.isfinite(array)):
            columns[name] = array.astype(np.int64)
        elif name == "truncated" and np.all(np.isfinite(array)):
            columns[name] = array != 0
        else:
            columns[name] = array
    order = [n for n in IMPACT_FIELDS if n in columns] + [n for n in columns if n not in IMPACT_FIELDS]
    return pandas.DataFrame({name: columns[name] for name in order}, columns=order)


def statistics_frame(statistics: Mapping[str, Statistic]) -> pandas.DataFrame:
    """The statistics as a long DataFrame indexed by (name, index): value, half_width, unit, axis.

    ``index`` is the 0-based entry along the statistic's axis (the stop, the bin, the edge; 0 for one value).
    """
    pandas = _pandas("Result.statistics_frame()")
    rows: list[tuple[str, int, float, float, str, str]] = []
    for name, stat in statistics.items():
        for i, (v, h) in enumerate(zip(stat.value, stat.half_width)):
            rows.append((name, i, float(v), float(h), stat.unit, stat.axis))
    frame = pandas.DataFrame(rows, columns=["name", "index", "value", "half_width", "unit", "axis"])
    return frame.set_index(["name", "index"])

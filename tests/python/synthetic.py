"""Synthetic /impacts and /statistics groups in the engine's HDF5 layout, for the Python tests.

The values are made up (plausible shapes and units, not physics): they test the reading side
and the plots against the layout, independently of the engine writing it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import h5py
import numpy as np

from beamstops.observations import IMPACT_UNITS

#: (unit, axis) of every statistic of docs/statistics.md.
STATISTICS: dict[str, tuple[str, str]] = {
    "window": ("s", "run"), "shocks": ("1", "stop"), "contact_phases": ("1", "stop"),
    "shocks_per_second": ("1/s", "stop"), "rebounds_per_shock": ("1", "stop"), "force_mean": ("N", "stop"),
    "force_rms": ("N", "stop"), "force_max": ("N", "stop"), "force_mean_contact": ("N", "stop"),
    "force_rms_contact": ("N", "stop"), "shock_duration_mean": ("s", "stop"), "shock_duration_min": ("s", "stop"),
    "shock_duration_max": ("s", "stop"), "contact_fraction": ("1", "stop"), "impulse_rate": ("N", "stop"),
    "power": ("W", "stop"), "tip_mean": ("m", "tip"), "tip_rms": ("m", "tip"), "tip_min": ("m", "tip"),
    "tip_max": ("m", "tip"), "tip_histogram": ("1", "bin"), "tip_histogram_edges": ("m", "edge"),
}
#: Statistics without a confidence interval (NaN half-width).
NO_INTERVAL = {"shocks", "contact_phases", "force_max", "shock_duration_min", "shock_duration_max", "tip_min",
               "tip_max"}


def impacts(rows: int, stops: int = 1, seed: int = 0, t_end: float = 1.0) -> dict[str, np.ndarray]:
    """A made-up shock log of ``rows`` shocks spread over ``stops`` stops and both sides."""
    rng = np.random.default_rng(seed)
    t_start = np.sort(rng.uniform(0, t_end * 0.95, rows))
    steps = rng.integers(1, 40, rows).astype(np.float64)
    side = rng.choice([-1.0, 1.0], rows)
    velocity_in = -side * rng.uniform(0.05, 2.0, rows)
    impulse = side * rng.uniform(1e-4, 5e-3, rows)
    out = {
        "t_start": t_start, "t_end": t_start + steps * 5e-5, "stop": rng.integers(1, stops + 1, rows).astype(float),
        "side": side, "velocity_in": velocity_in, "velocity_out": -0.5 * velocity_in, "impulse": impulse,
        "peak_reaction": side * rng.uniform(1, 50, rows), "energy_taken": rng.uniform(0, 1e-3, rows),
        "contact_time": steps * 5e-5, "rebounds": rng.integers(0, 3, rows).astype(float), "contact_steps": steps,
        "truncated": np.zeros(rows),
    }
    if rows:
        out["truncated"][-1] = 1.0
        out["velocity_out"][-1] = np.nan
    return out


def statistics(stops: int = 1, bins: int = 20, lower: float = -0.1, upper: float = 0.1, seed: int = 0
               ) -> dict[str, np.ndarray]:
    """Made-up (count, 2) tables of every statistic: value and 95 % half-width."""
    rng = np.random.default_rng(seed)
    counts = {"stop": stops, "tip": 1, "run": 1, "bin": bins, "edge": bins + 1}
    tables: dict[str, np.ndarray] = {}
    for name, (_, axis) in STATISTICS.items():
        value = rng.uniform(0.1, 1.0, counts[axis])
        half = np.full(counts[axis], np.nan) if name in NO_INTERVAL else 0.05 * value
        tables[name] = np.column_stack([value, half])
    centres = np.linspace(lower, upper, bins)
    fraction = np.exp(-(centres / (0.4 * (upper - lower))) ** 2)
    fraction /= fraction.sum()
    tables["tip_histogram"] = np.column_stack([fraction, 0.1 * fraction])
    edges = lower + np.arange(bins + 1) * (upper - lower) / bins
    edges[-1] = upper
    tables["tip_histogram_edges"] = np.column_stack([edges, np.zeros(bins + 1)])
    tables["power"][:, 0] = 0.56
    tables["power"][:, 1] = 0.031
    return tables


def write(path: Path, impacts_rows: dict[str, np.ndarray] | None = None,
          statistics_tables: dict[str, np.ndarray] | None = None, statistics_attrs: dict[str, Any] | None = None
          ) -> Path:
    """Add (or replace) /impacts and /statistics groups of an HDF5 file (created when missing) in the engine's layout."""
    with h5py.File(path, "a") as f:
        if "status" not in f.attrs:
            f.attrs["status"] = "complete"
        if impacts_rows is not None:
            if "impacts" in f:  # the engine's own log, replaced by the synthetic one
                del f["impacts"]
            group = f.create_group("impacts")
            for name, column in impacts_rows.items():
                dataset = group.create_dataset(name, data=np.asarray(column, dtype=np.float64))
                dataset.attrs["units"] = IMPACT_UNITS.get(name, "1")
        if statistics_tables is not None:
            if "statistics" in f:
                del f["statistics"]
            group = f.create_group("statistics")
            for key, value in (statistics_attrs or {"transient": 0.0, "batches": 8, "bins": 20,
                                                    "rest_time": 1e-3}).items():
                group.attrs[key] = value
            for name, table in statistics_tables.items():
                unit, axis = STATISTICS.get(name, ("1", "run"))
                dataset = group.create_dataset(name, data=np.asarray(table, dtype=np.float64))
                dataset.attrs["units"] = unit
                dataset.attrs["axis"] = axis
    return path

"""Reductions: numbers of a run for the summary table, read from the program's HDF5 output.

They only sample and reduce what the engine recorded (``/tip/*``, ``/energy/*``); the
physics is the engine's. Each reduction named ``NAME`` in the specification gives:

- ``strobe``: ``NAME``, the quantity at the stroboscopic times t_k = (k + phase)·T,
  T = 2π/ω, for k = transient_periods, transient_periods + 1, ... up to the end of the
  run; each sample is the record nearest to t_k, and ``NAME_offset`` is the largest
  |t_record − t_k| (s): round-off when the time grid is locked to the forcing
  ([periods] records_per_period), up to half a record interval otherwise.
  ``NAME_period`` is the smallest p ≤ max_period with |x_{k+p} − x_k| ≤ tolerance for
  every sample (a period-p motion at the forcing's stroboscope), 0 when there is none.
- ``max``, ``min``, ``mean``, ``rms``, ``peak_to_peak``: over the records with t ≥ after
  (s) or t ≥ after_periods·T; ``final``: the last record.
"""

from __future__ import annotations

import math
from typing import Any, Optional

import numpy as np

__all__ = ["reduce", "strobe", "columns"]


def columns(name: str, spec: dict[str, Any]) -> list[str]:
    """The summary columns a reduction fills."""
    if spec["kind"] == "strobe":
        return [name, f"{name}_offset", f"{name}_period"]
    return [name]


def strobe(t: np.ndarray, x: np.ndarray, omega: float, transient_periods: int = 0, phase: float = 0.0
           ) -> tuple[np.ndarray, np.ndarray, float]:
    """Samples of x at t_k = (k + phase)·2π/ω, k ≥ transient_periods: (t_k, x at the nearest records, offset)."""
    if t.size == 0 or not omega > 0:
        return np.empty(0), np.empty(0), math.nan
    period = 2 * math.pi / omega
    last = t[-1]
    # the targets up to the last record (a hair of round-off allowed at the end)
    count = int(math.floor((last / period - phase) * (1 + 1e-12) + 1e-9)) - transient_periods + 1
    if count <= 0:
        return np.empty(0), np.empty(0), math.nan
    targets = (np.arange(transient_periods, transient_periods + count) + phase) * period
    right = np.clip(np.searchsorted(t, targets), 1, t.size - 1) if t.size > 1 else np.zeros(count, dtype=int)
    if t.size > 1:
        left = right - 1
        nearest = np.where(np.abs(t[left] - targets) <= np.abs(t[right] - targets), left, right)
    else:
        nearest = right
    offset = float(np.max(np.abs(t[nearest] - targets)))
    return targets, x[nearest], offset


def _period(samples: np.ndarray, tolerance: float, max_period: int) -> int:
    for p in range(1, max_period + 1):
        if samples.size < 2 * p:
            break
        if float(np.max(np.abs(samples[p:] - samples[:-p]))) <= tolerance:
            return p
    return 0


def _number(value: float) -> Optional[float]:
    value = float(value)
    return value if math.isfinite(value) else None


def reduce(result: Any, reductions: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """Every reduction of a :class:`beamstops.Result` (NaN and missing values become None)."""
    out: dict[str, Any] = {}
    omega = float(result.attrs.get("omega", 0.0))
    t = np.asarray(result.t)
    for name, spec in reductions.items():
        x = np.asarray(getattr(result, spec["quantity"]))
        if spec["kind"] == "strobe":
            _, samples, offset = strobe(t, x, omega, spec["transient_periods"], spec["phase"])
            out[name] = [_number(v) for v in samples]
            out[f"{name}_offset"] = _number(offset)
            out[f"{name}_period"] = _period(samples, spec["tolerance"], spec["max_period"]) if samples.size else 0
            continue
        if spec["kind"] == "final":
            out[name] = _number(x[-1]) if x.size else None
            continue
        start = 0.0
        if spec.get("after") is not None:
            start = spec["after"]
        elif spec.get("after_periods") is not None:
            start = spec["after_periods"] * 2 * math.pi / omega
        window = x[t >= start * (1 - 1e-12)] if x.size else x
        if window.size == 0:
            out[name] = None
            continue
        value = {"max": np.max, "min": np.min, "mean": np.mean,
                 "rms": lambda a: np.sqrt(np.mean(a * a)), "peak_to_peak": np.ptp}[spec["kind"]](window)
        out[name] = _number(value)
    return out

"""Display-only transforms of recorded series for the plots (numpy arrays in and out).

None of these is a result of the simulation: the statistics and shocks come from the engine
(:mod:`beamstops.observations`). These only resample or re-express records for drawing:

- :func:`welch`: power spectral density by Welch's method (Hann window, 50 % overlap,
  one-sided, density scaling: the same conventions as ``scipy.signal.welch``'s defaults);
- :func:`stroboscopic`: indices of the records nearest the times kT (a Poincaré section);
- :func:`frame_indices`: at most N evenly spread indices (animation frames);
- :func:`after`: the records from a transient on.
"""

from __future__ import annotations

import math
from typing import Optional

import numpy as np

__all__ = ["welch", "sampling_rate", "stroboscopic", "frame_indices", "after"]


def after(t: np.ndarray, transient: Optional[float]) -> np.ndarray:
    """Boolean mask of the times t ≥ transient (all of them when transient is None or ≤ 0)."""
    t = np.asarray(t)
    if transient is None or transient <= 0:
        return np.ones(t.shape, dtype=bool)
    return t >= transient * (1 - 1e-12)


def sampling_rate(t: np.ndarray, tolerance: float = 1e-6) -> float:
    """1 / Δt of uniformly spaced times; ValueError when they are not uniform (to ``tolerance`` relative)."""
    t = np.asarray(t, dtype=np.float64)
    if t.size < 2:
        raise ValueError("a spectrum needs at least two records")
    step = np.diff(t)
    mean = (t[-1] - t[0]) / (t.size - 1)
    if not mean > 0 or np.max(np.abs(step - mean)) > tolerance * mean + 1e-12 * abs(t[-1]):
        raise ValueError("records are not evenly spaced in time: no spectrum")
    return 1.0 / mean


def welch(x: np.ndarray, fs: float, segment: Optional[int] = None) -> tuple[np.ndarray, np.ndarray]:
    """One-sided power spectral density of x sampled at fs (Hz): (frequencies in Hz, PSD in x²/Hz).

    Segments of ``segment`` samples (default: the largest power of two giving at least 8
    segments, at least 16 samples, at most the whole series) overlapping by half, each with its
    mean removed and a Hann window (periodic, as ``scipy.signal.get_window('hann', n)``); their
    periodograms averaged. The spectrum integrates to the variance of x.
    """
    x = np.asarray(x, dtype=np.float64)
    n = x.size
    if n < 2:
        raise ValueError("a spectrum needs at least two samples")
    if segment is None:
        segment = 1 << max(4, int(math.floor(math.log2(max(n / 4.5, 1)))))
    segment = int(min(segment, n))
    if segment < 2:
        raise ValueError("segment must hold at least two samples")
    hop = segment - segment // 2
    starts = np.arange(0, n - segment + 1, hop)
    window = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(segment) / segment)
    frames = x[starts[:, None] + np.arange(segment)[None, :]]
    frames = frames - frames.mean(axis=1, keepdims=True)
    spectrum = np.abs(np.fft.rfft(frames * window, axis=1)) ** 2
    psd = spectrum.mean(axis=0) / (fs * np.sum(window**2))
    if segment % 2 == 0:
        psd[1:-1] *= 2
    else:
        psd[1:] *= 2
    return np.fft.rfftfreq(segment, 1.0 / fs), psd


def stroboscopic(t: np.ndarray, period: float, transient: Optional[float] = None
                 ) -> tuple[np.ndarray, np.ndarray, float]:
    """Records nearest the times kT, k = 0, 1, ..., kT ≥ transient and kT within the records.

    Gives (k, record indices, largest |t_record − kT|).
    """
    t = np.asarray(t, dtype=np.float64)
    if t.size == 0 or not period > 0:
        return np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64), math.nan
    first = max(0, math.ceil((transient or 0.0) / period * (1 - 1e-12) - 1e-9))
    last = math.floor(t[-1] / period * (1 + 1e-12) + 1e-9)
    first = max(first, math.ceil(t[0] / period * (1 - 1e-12) - 1e-9))
    if last < first:
        return np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64), math.nan
    k = np.arange(first, last + 1, dtype=np.int64)
    targets = k * period
    if t.size == 1:
        nearest = np.zeros(k.size, dtype=np.int64)
    else:
        right = np.clip(np.searchsorted(t, targets), 1, t.size - 1)
        left = right - 1
        nearest = np.where(np.abs(t[left] - targets) <= np.abs(t[right] - targets), left, right)
    return k, nearest.astype(np.int64), float(np.max(np.abs(t[nearest] - targets)))


def frame_indices(count: int, frames: int = 200) -> np.ndarray:
    """At most ``frames`` indices in 0..count-1, evenly spread, first and last included."""
    if count <= 0:
        return np.empty(0, dtype=np.int64)
    if frames < 1:
        raise ValueError(f"frames = {frames}: at least 1")
    if count <= frames:
        return np.arange(count, dtype=np.int64)
    if frames == 1:
        return np.zeros(1, dtype=np.int64)
    return np.unique(np.rint(np.linspace(0, count - 1, frames)).astype(np.int64))

"""What the studies share: engine calls they need beyond :func:`beamstops.run`, error norms
between runs, observed orders, tables (markdown and CSV) and progress bars.

Every number about a run comes from the engine (tip records, states, matrices, CPU time);
this module only compares runs. Time grids: every study records its runs on one common
grid (``record_every = grid/dt``), so that errors are differences of samples at the same
instants, never interpolations.
"""

from __future__ import annotations

import csv
import io
import math
import sys
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional, TypeVar

import numpy as np

from .. import _engine
from ..engine_call import engine_call
from ..engine import _check, _scene_text, _text, interruptible, raise_stop_signal, run, sizes
from ..result import IncompleteRunError, Result
from ..scene import Scene
from .outputs import StudyFolder

__all__ = ["Table", "States", "TipError", "progress", "run_tip", "run_three_level", "states", "every",
           "tip_error", "energy_norm", "prolong", "observed_orders", "csv_cell", "csv_text"]

T = TypeVar("T")


def progress(items: Iterable[T], desc: str, total: Optional[int] = None, quiet: bool = False) -> Iterator[T]:
    """A tqdm progress bar on stderr (none when ``quiet`` or without tqdm)."""
    if quiet:
        yield from items
        return
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover - tqdm is a dependency
        yield from items
        return
    yield from tqdm(items, desc=desc, total=total, file=sys.stderr, leave=False, dynamic_ncols=True)


def every(grid: float, dt: float) -> int:
    """Steps between records so that a run of step ``dt`` records on the common ``grid``."""
    m = round(grid / dt)
    if m < 1 or abs(m * dt - grid) > 1e-9 * grid:
        raise ValueError(f"dt = {dt!r} does not divide the record grid {grid!r}: use dt = grid/m, m integer")
    return int(m)


def run_tip(scene: Scene, grid: float) -> Result:
    """Run a scene recording on the common grid; a run that did not complete is returned as is."""
    try:
        return run(scene.replace(record_every=every(grid, scene.dt)), allow_incomplete=True)
    except IncompleteRunError as exc:  # pragma: no cover - allow_incomplete returns instead
        assert exc.result is not None
        return exc.result


def _check_stopped(status: int, message: Any) -> None:
    """An engine call's outcome: status 2, a stop signal ended its loop (Ctrl-C in the main thread):
    the signal is raised again (KeyboardInterrupt); a handler that returns leaves a RuntimeError,
    the call having no result to give. Otherwise as :func:`beamstops.engine._check`."""
    if status == 2:
        raise_stop_signal()
        raise RuntimeError(_text(message))
    _check(status, message)


def run_three_level(scene: Scene) -> tuple[np.ndarray, np.ndarray, float]:
    """The scene (law 'none') in the paper's three-level form (engine module beamstops_three_level):
    record times, tip displacement every ``record_every`` steps, and the loop's CPU time (s)."""
    records = sizes(scene)[0]
    t, tip_u, cpu, status, message = engine_call(_engine.bs_run_three_level, _scene_text(scene), b"scene", records,
                                                 interruptible())
    _check_stopped(status, message)
    return np.asarray(t), np.asarray(tip_u), float(cpu)


@dataclass(frozen=True)
class States:
    """Full states of the engine's loop at chosen steps, and the matrices of the mesh."""

    steps: np.ndarray
    """Steps n (the times are n dt)."""
    u: np.ndarray
    """u^n, homogeneous unknown (values and slopes at nodes 1..J), shape (2J, len(steps))."""
    v: np.ndarray
    """(u^{n+1} - u^{n-1})/(2 dt), same shape."""
    mass: np.ndarray
    """M, per unit mass, LAPACK upper band storage (4, 2J)."""
    stiffness: np.ndarray
    """S, per unit mass, band storage (4, 2J)."""
    cpu_seconds: float


def states(scene: Scene, times: Sequence[float]) -> States:
    """The engine's full state at the steps nearest ``times`` (wrapper ``bs_states``)."""
    steps = np.array([round(t / scene.dt) for t in times], dtype=np.int64)
    u, v, mass, stiffness, cpu, status, message = engine_call(_engine.bs_states, _scene_text(scene), b"scene", steps,
                                                              2 * scene.elements, interruptible())
    _check_stopped(status, message)
    return States(steps=steps, u=np.asarray(u), v=np.asarray(v), mass=np.asarray(mass),
                  stiffness=np.asarray(stiffness), cpu_seconds=float(cpu))


def _band_dot(ab: np.ndarray, x: np.ndarray) -> float:
    """x.A x for A symmetric in upper band storage ab[kd + i - j, j] = A[i, j]."""
    kd = ab.shape[0] - 1
    total = float(np.dot(ab[kd] * x, x))
    for d in range(1, kd + 1):
        total += 2.0 * float(np.dot(ab[kd - d, d:] * x[d:], x[:-d]))
    return total


def energy_norm(u: np.ndarray, v: np.ndarray, mass: np.ndarray, stiffness: np.ndarray) -> float:
    """sqrt(v.M v + u.S u): the energy norm (per unit mass, twice the energy) of a Hermite field."""
    return math.sqrt(max(_band_dot(mass, v) + _band_dot(stiffness, u), 0.0))


def prolong(x: np.ndarray, coarse: int, fine: int, length: float) -> np.ndarray:
    """Hermite field on ``coarse`` elements written exactly on ``fine`` elements (fine = m coarse).

    ``x`` holds (values, slopes) at nodes 1..J, node 0 clamped (0, 0); the result holds the
    same piecewise cubic's values and slopes at the fine nodes: the coarse field is in the
    fine space, so the energy norm of a difference is computed on the fine mesh exactly.
    """
    m, rest = divmod(fine, coarse)
    if rest:
        raise ValueError(f"cannot prolong {coarse} elements to {fine}: not a multiple")
    h = length / coarse
    value = np.concatenate([[0.0], x[0::2]])
    slope = np.concatenate([[0.0], x[1::2]])
    out = np.empty(2 * fine)
    for k in range(1, fine + 1):
        e, s = divmod(k, m)
        if s == 0:  # a coarse node
            e, xi = e - 1, 1.0
        else:
            xi = s / m
        a, b, c, d = value[e], h * slope[e], value[e + 1], h * slope[e + 1]
        h00, h10, h01, h11 = 2 * xi**3 - 3 * xi**2 + 1, xi**3 - 2 * xi**2 + xi, -2 * xi**3 + 3 * xi**2, xi**3 - xi**2
        d00, d10, d01, d11 = 6 * xi**2 - 6 * xi, 3 * xi**2 - 4 * xi + 1, -6 * xi**2 + 6 * xi, 3 * xi**2 - 2 * xi
        out[2 * k - 2] = h00 * a + h10 * b + h01 * c + h11 * d
        out[2 * k - 1] = (d00 * a + d10 * b + d01 * c + d11 * d) / h
    return out


@dataclass(frozen=True)
class TipError:
    """Error of the tip displacement against a reference on [0, window]."""

    max: float
    """max |u - u_ref| over the record grid (m)."""
    l2: float
    """sqrt(∫ (u - u_ref)² dt), trapezoid on the record grid (m s^½)."""


def tip_error(result: Result, reference: Result, window: float, start: float = 0.0) -> TipError:
    """Tip errors of a run against a reference recorded on the same grid, over [start, window]."""
    n = min(result.t.size, reference.t.size)
    t = result.t[:n]
    if not np.allclose(t, reference.t[:n], rtol=0, atol=1e-9 * max(1.0, float(t[-1]))):
        raise ValueError("runs not recorded on the same grid")
    keep = (t <= window * (1 + 1e-12)) & (t >= start * (1 - 1e-12))
    e = result.tip_u[:n][keep] - reference.tip_u[:n][keep]
    if e.size == 0 or not np.all(np.isfinite(e)):
        return TipError(math.inf, math.inf)
    return TipError(float(np.abs(e).max()), float(math.sqrt(np.trapezoid(e**2, t[keep])) if e.size > 1 else 0.0))


def observed_orders(steps: Sequence[float], errors: Sequence[float]) -> list[float]:
    """log(e_{i-1}/e_i)/log(h_{i-1}/h_i) between successive rows (nan for the first row)."""
    out = [math.nan]
    for i in range(1, len(steps)):
        a, b = errors[i - 1], errors[i]
        if a > 0 and b > 0 and math.isfinite(a) and math.isfinite(b):
            out.append(math.log(a / b) / math.log(steps[i - 1] / steps[i]))
        else:
            out.append(math.nan)
    return out


@dataclass
class Table:
    """Rows of a result table, written as markdown and CSV."""

    title: str
    columns: list[str]
    rows: list[list[Any]]
    note: str = ""

    def column(self, name: str) -> list[Any]:
        i = self.columns.index(name)
        return [row[i] for row in self.rows]

    def markdown(self) -> str:
        def cell(name: str, x: Any) -> str:
            if isinstance(x, float):
                if math.isnan(x):
                    return "–"
                return f"{x:.2f}" if name.startswith("order") else f"{x:.3g}"
            return str(x)

        lines = [f"### {self.title}", ""]
        if self.note:
            lines += [self.note, ""]
        lines.append("| " + " | ".join(self.columns) + " |")
        lines.append("|" + "---|" * len(self.columns))
        for row in self.rows:
            lines.append("| " + " | ".join(cell(name, x) for name, x in zip(self.columns, row)) + " |")
        return "\n".join(lines) + "\n"

    def write(self, out: StudyFolder, stem: str) -> tuple[Path, Path]:
        """``stem``.md and ``stem``.csv in the study's folder."""
        return out.markdown(f"{stem}.md", self.markdown()), out.csv(f"{stem}.csv", self.csv())

    def csv(self) -> str:
        """The rows as CSV text (reals written so that they read back exactly)."""
        return csv_text(self.columns, self.rows)


def csv_cell(x: Any) -> Any:
    """A cell of a CSV table: a real (numpy's too) as its shortest exact text, ``1e-06`` (numpy 2's
    repr of its scalars, ``np.float64(1e-06)``, is no number for a reader), anything else as is."""
    return repr(float(x)) if isinstance(x, (float, np.floating)) else x


def csv_text(columns: Sequence[str], rows: Iterable[Sequence[Any]]) -> str:
    """A CSV table: a line of column names, then one line per row (:func:`csv_cell`)."""
    text = io.StringIO()
    writer = csv.writer(text)
    writer.writerow(columns)
    for row in rows:
        writer.writerow([csv_cell(x) for x in row])
    return text.getvalue()

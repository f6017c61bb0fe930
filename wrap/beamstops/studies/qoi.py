"""Statistical quantities of interest (issue 13 item 4): what the convergence and work-precision
studies chart once trajectories no longer converge (after the first impacts).

A QoI is one of the engine's statistics (docs/statistics.md), read from a run whose window is
[transient, transient + window]: its value and 95 % batch-means half-width come from
``Result.statistics``, its value across perturbed members from ``Result.ensemble`` (members > 1),
its cost from the engine's ``cpu_seconds``. This module only names, runs and compares:

- agreement with a reference: |v − v_ref| ≤ h + h_ref (the two intervals overlap);
- the window that would reach a requested half-width h*: batch-means half-widths fall as
  1/sqrt(window), so T* = T (h/h*)²; its CPU time cost* = cpu (transient + T*)/(transient + T)
  (the run's CPU per simulated second, the transient paid once).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Optional

from ..engine import run
from ..observations import Statistic
from ..result import IncompleteRunError, Result
from ..scene import Scene

__all__ = ["QOIS", "POINTWISE", "statistic_name", "Estimate", "Law", "Measured", "laws", "measure", "configure",
           "HalfWidth", "window_for", "cost_for"]

#: Study names of the QoIs and the engine's statistics they read (engine names are accepted too).
QOIS: dict[str, str] = {
    "stop_power": "power",
    "impulse_rate": "impulse_rate",
    "shock_rate": "shocks_per_second",
    "contact_fraction": "contact_fraction",
    "tip_rms": "tip_rms",
    "tip_mean": "tip_mean",
    "force_mean": "force_mean",
    "force_rms": "force_rms",
    "rebounds_per_shock": "rebounds_per_shock",
    "shock_duration": "shock_duration_mean",
}
#: The QoI name that keeps today's pointwise study (tip displacement against a reference).
POINTWISE = "tip"
_ENGINE_NAMES = frozenset(QOIS.values()) | {"force_mean_contact", "force_rms_contact"}


def statistic_name(qoi: str) -> str:
    """The engine's statistic behind a QoI name (a study name or the engine's own name)."""
    if qoi in QOIS:
        return QOIS[qoi]
    if qoi in _ENGINE_NAMES:
        return qoi
    raise ValueError(f"unknown quantity of interest {qoi!r}; allowed: {', '.join(QOIS)} "
                     f"(or the engine's names {', '.join(sorted(_ENGINE_NAMES - set(QOIS)))}), or {POINTWISE!r}")


@dataclass(frozen=True)
class Estimate:
    """A statistic of one run (or across members): value ± 95 % half-width, in ``unit``."""

    value: float
    half_width: float
    unit: str

    def agrees(self, reference: Estimate) -> bool:
        """Whether the two 95 % intervals overlap: |v − v_ref| ≤ h + h_ref (False when either is not finite)."""
        gap, room = abs(self.value - reference.value), self.half_width + reference.half_width
        return bool(math.isfinite(gap) and math.isfinite(room) and gap <= room)

    def distance(self, reference: Estimate) -> float:
        """|v − v_ref| + h: how far the run can be from the reference's value at 95 %."""
        return abs(self.value - reference.value) + self.half_width

    def __str__(self) -> str:
        unit = "" if self.unit in ("", "1") else f" {self.unit}"
        return f"{self.value:.4g} ± {self.half_width:.2g}{unit}"


@dataclass(frozen=True)
class Law:
    """A contact law of the charts: its label, the scene changes that select it and its time steps."""

    label: str
    changes: dict[str, object]
    dts: tuple[float, ...]
    dt_reference: float
    reference_window: Optional[float] = None
    """Window of its reference run (None: the study's reference window)."""
    note: str = ""


def laws(dts: Sequence[float], dt_reference: float, stiffness_per_mass: float = 1e8,
         redistributed_finest: Optional[float] = None, redistributed_window: Optional[float] = None) -> list[Law]:
    """The laws of the charts on one Δt ladder: Signorini e = 0 (the paper's), e = 1, mass
    redistribution (e = 0), normal compliance 1/ε per unit mass, and the reduced (Craig–Bampton)
    model with r = 8 modes of Signorini e = 0, so that reduced and full models share the CPU axis.

    ``redistributed_finest``: the finest Δt of the mass-redistribution ladder, the next finer one
    its reference (its shock log holds a row every step or two: see the law's note).
    """
    ladder = tuple(dts)
    redistributed, redistributed_ref = ladder, dt_reference
    if redistributed_finest is not None:
        redistributed = tuple(dt for dt in ladder if dt >= redistributed_finest * (1 - 1e-12))
        redistributed_ref = redistributed[-1] / 2
    return [
        Law("Signorini e=0", {"restitution": 0.0}, ladder, dt_reference),
        Law("Signorini e=1", {"restitution": 1.0}, ladder, dt_reference),
        Law("mass redistribution", {"mass": "redistributed"}, redistributed, redistributed_ref, redistributed_window),
        Law(f"compliance 1/ε={stiffness_per_mass:.0e}", {"law": "compliance", "stiffness_per_mass": stiffness_per_mass},
            ladder, dt_reference),
        Law("reduced r=8 (Signorini e=0)", {"restitution": 0.0, "modes": 8}, ladder, dt_reference),
    ]


@dataclass(frozen=True)
class Measured:
    """One engine run of the statistical studies: what it was and every statistic it gave."""

    scene: Scene
    transient: float
    window: float
    cpu_seconds: float
    status: str
    statistics: dict[str, Estimate]
    ensemble: dict[str, Estimate] = field(default_factory=dict)
    members: int = 1

    def estimate(self, qoi: str) -> Estimate:
        """The run's batch-means estimate of a QoI (NaN ± NaN when the run has none)."""
        return self.statistics.get(statistic_name(qoi), Estimate(math.nan, math.nan, ""))

    def across_members(self, qoi: str) -> Optional[Estimate]:
        """The ensemble's estimate of a QoI (mean ± t s/√K over the members), None for one member."""
        return self.ensemble.get(statistic_name(qoi))


def _scalars(table: Mapping[str, Statistic]) -> dict[str, Estimate]:
    """The one-entry statistics (one stop, the tip or the run) as estimates; histograms are left out."""
    return {name: Estimate(float(stat.value[0]), float(stat.half_width[0]), stat.unit)
            for name, stat in table.items() if stat.value.size == 1}


def configure(scene: Scene, transient: float, window: float, *, batches: int = 20, members: int = 1,
              perturbation: float = 1e-6, record_grid: float = 0.01) -> Scene:
    """The scene :func:`measure` runs (the engine's reader refuses what it would not run)."""
    changes: dict[str, object] = dict(t_end=transient + window, transient=transient, batches=batches, enabled=True,
                                      record_every=max(1, round(record_grid / scene.dt)), snapshot_every=0,
                                      members=members)
    if members > 1:
        changes.update(perturbation=perturbation)
    return scene.replace(**changes)


def measure(scene: Scene, transient: float, window: float, *, batches: int = 20, members: int = 1,
            perturbation: float = 1e-6, record_grid: float = 0.01) -> Measured:
    """Run ``scene`` for transient + window seconds, statistics on [transient, end] in ``batches``
    batch means (and across ``members`` perturbed members when > 1); records only every
    ``record_grid`` seconds (the engine's statistics see every step)."""
    if scene.nodes:
        raise ValueError("the statistical studies chart the tip stops: a scene with stops along the span has one "
                         "statistic per stop")
    configured = configure(scene, transient, window, batches=batches, members=members, perturbation=perturbation,
                           record_grid=record_grid)
    try:
        result: Result = run(configured, allow_incomplete=True)
    except IncompleteRunError as exc:  # pragma: no cover - allow_incomplete returns instead
        assert exc.result is not None
        result = exc.result
    return Measured(scene=configured, transient=transient, window=window,
                    cpu_seconds=float(result.attrs.get("cpu_seconds", math.nan)), status=result.status,
                    statistics=_scalars(result.statistics), ensemble=_scalars(result.ensemble), members=members)


@dataclass(frozen=True)
class HalfWidth:
    """A requested half-width h*: absolute (in the QoI's unit) or a fraction of the reference's value."""

    amount: float
    relative: bool

    @classmethod
    def parse(cls, text: str) -> HalfWidth:
        """'2%' (of the reference's |value|) or '0.01' (absolute, the QoI's unit)."""
        text = text.strip()
        relative = text.endswith("%")
        try:
            amount = float(text[:-1] if relative else text)
        except ValueError:
            raise ValueError(f"--half-width {text!r}: expected a number or a percentage such as 2%") from None
        if not amount > 0 or not math.isfinite(amount):
            raise ValueError(f"--half-width {text!r}: must be > 0")
        return cls(amount / 100 if relative else amount, relative)

    def target(self, reference: Estimate) -> float:
        """h* for a QoI whose reference is ``reference`` (NaN when relative and the reference's
        interval contains 0: no relative precision is defined)."""
        if not self.relative:
            return self.amount
        if not (abs(reference.value) > reference.half_width):
            return math.nan
        return self.amount * abs(reference.value)

    def __str__(self) -> str:
        return f"±{100 * self.amount:g} %" if self.relative else f"±{self.amount:g}"


def window_for(half_width: float, window: float, target: float) -> float:
    """T* = T (h/h*)²: the window whose batch-means half-width would be ``target``."""
    if not (half_width > 0 and target > 0):
        return math.nan
    return window * (half_width / target) ** 2


def cost_for(measured: Measured, target_window: float) -> float:
    """CPU time of a run of ``target_window`` after the same transient: cpu (transient + T*)/(transient + T)."""
    if not math.isfinite(target_window):
        return math.nan
    return measured.cpu_seconds * (measured.transient + target_window) / (measured.transient + measured.window)

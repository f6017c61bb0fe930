"""How the plan makes its runs: the mesh and Δt ladders, the scene of a model, the runs (once each,
within a budget) and the distances and Richardson estimates between them (see :mod:`beamstops.plan`)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from .engine import run, stability
from .plan_types import LAWS, Model, Quantity
from .result import IncompleteRunError, Result
from .scene import GROUPS, Scene

_P_BOUNDS = (1.0, 4.0)
RECORDS = 2000  # records kept by a statistical run (the statistics use every step)
__all__ = ["Rung", "Ladder", "Run", "Runner", "mesh_ladder", "dt_ladder", "scene_of", "distance",
           "richardson", "ratio", "reduced_available"]

STEP_WORK = 8.0  # elements' worth of fixed work per step, for the cost prediction


def reduced_available() -> bool:
    """Whether the engine has the reduced (modal) model's key ``modes`` in ``&mesh``."""
    return "modes" in GROUPS.get("mesh", ()) and "modes" in {f.name for f in dataclasses.fields(Scene)}


Rung = tuple[int, int]
"""A mesh: (elements J, reduced modes r; 0 = the full model)."""


@dataclass
class Ladder:
    """Meshes and the next finer mesh of each: J/4 → J/2 → J → 2J (full models), and with the reduced
    model r = 4 → 8 → … → the full model at the scene's J."""

    rungs: list[Rung]
    finer: dict[Rung, Rung]

    def chain(self, rung: Rung, length: int) -> list[Rung]:
        """``rung`` and up to ``length - 1`` finer rungs after it."""
        out = [rung]
        while len(out) < length and out[-1] in self.finer:
            out.append(self.finer[out[-1]])
        return out

    def refinable(self) -> list[Rung]:
        """Rungs with a finer one (the candidates)."""
        return [rung for rung in self.rungs if rung in self.finer]

    def extend(self) -> None:
        """One finer full model: 2J after the finest."""
        top = max(rung[0] for rung in self.rungs)
        self.finer[(top, 0)] = (2 * top, 0)
        self.rungs.append((2 * top, 0))


def mesh_ladder(scene: Scene, reduced: bool = True) -> Ladder:
    """The meshes of the search around ``scene``'s J; with ``reduced`` (and an engine that has them)
    the reduced models at that J too (not for an ensemble scene: the engine runs none reduced)."""
    j = scene.elements
    full: list[Rung] = []
    for factor in (0.25, 0.5, 1.0, 2.0):
        n = max(1, round(j * factor))
        if scene.nodes and any((node * n) % j for node in scene.nodes):
            continue  # the stops along the span would not be nodes
        if (n, 0) not in full:
            full.append((n, 0))
    finer = {a: b for a, b in zip(full, full[1:])}
    rungs = list(full)
    if reduced and reduced_available():
        modes = [(j, r) for r in (4, 8, 16, 32, 64) if r < 2 * j - max(len(scene.nodes), 1)]
        chain = modes + [(j, 0)]
        finer.update({a: b for a, b in zip(chain, chain[1:])})
        rungs = modes + rungs
    return Ladder(rungs, finer)


def dt_ladder(scene: Scene, coarser: int, finer: int) -> list[float]:
    return [scene.dt * 2.0**k for k in range(coarser, -finer - 1, -1)]


def scene_of(base: Scene, model: Model, record_every: int) -> Scene:
    changes: dict[str, Any] = dict(LAWS[model.law])
    if base.nodes and model.elements != base.elements:
        changes["nodes"] = tuple(node * model.elements // base.elements for node in base.nodes)
    if reduced_available():
        changes["modes"] = model.modes
    return base.replace(elements=model.elements, dt=model.dt, record_every=record_every, **changes)


@dataclass(frozen=True)
class Run:
    value: float
    half_width: float
    tip: Optional[np.ndarray]
    cpu: float
    simulated: float
    unit: str


class Runner:
    """Runs models once each (cached), keeps the CPU spent, refuses runs beyond the budget."""

    def __init__(self, base: Scene, quantity: Quantity, grid: Optional[float], budget: Optional[float]) -> None:
        self.base, self.quantity, self.grid, self.budget = base, quantity, grid, budget
        self.cache: dict[Model, Run] = {}
        self.refused: dict[Model, str] = {}
        self.cpu = 0.0
        self.rate: Optional[float] = None  # CPU s per (element-step), from the runs so far
        self.shock_rate = 0.0  # shocks per simulated second, the most seen (room in the shock log)

    def scene(self, model: Model) -> Scene:
        if self.quantity.deterministic:
            assert self.grid is not None
            every = max(1, round(self.grid / model.dt))
        else:
            every = max(1, math.ceil(self.base.t_end / model.dt / RECORDS))
        return scene_of(self.base, model, every)

    def predicted(self, model: Model) -> float:
        steps = self.base.t_end / model.dt
        return (self.rate or 0.0) * steps * (model.elements + STEP_WORK)

    def affordable(self, models: Iterable[Model]) -> bool:
        if self.budget is None:
            return True
        todo = {m for m in models if m not in self.cache and m not in self.refused}
        return self.cpu + sum(self.predicted(m) for m in todo) <= self.budget

    def get(self, model: Model) -> Optional[Run]:
        """The model's run, or None when the engine refuses its Δt (recorded in ``refused``)."""
        if model in self.cache:
            return self.cache[model]
        if model in self.refused:
            return None
        try:
            scene = self.scene(model)
            limits = stability(scene)
        except ValueError as exc:
            self.refused[model] = str(exc)
            return None
        if not limits.runnable:
            self.refused[model] = f"Δt beyond the stability limit {limits.dt_limit_newmark:.3g} s"
            return None
        steps = max(1, round(scene.t_end / scene.dt))
        try:
            result = run(scene, shock_capacity=4096 + int(2 * self.shock_rate * scene.t_end))
        except IncompleteRunError as exc:
            self.refused[model] = f"run {exc.result.status if exc.result else 'failed'}"
            return None
        entry = self._entry(result, scene)
        self.shock_rate = max(self.shock_rate, result.shocks / scene.t_end)
        self.cache[model] = entry
        self.cpu += entry.cpu
        work = steps * (model.elements + STEP_WORK)
        self.rate = entry.cpu / work if self.rate is None else max(self.rate, 0.5 * self.rate + 0.5 * entry.cpu / work)
        return entry

    def _entry(self, result: Result, scene: Scene) -> Run:
        cpu = float(result.attrs["cpu_seconds"])
        if self.quantity.deterministic:
            assert self.quantity.until is not None
            keep = result.t <= self.quantity.until * (1 + 1e-12)
            tip = np.asarray(result.tip_u[keep], dtype=np.float64)
            return Run(float(np.abs(tip).max()) if tip.size else math.nan, math.nan, tip, cpu, scene.t_end, "m")
        statistic = result.statistics.get(self.quantity.name)
        if statistic is None:
            raise ValueError(f"the engine gave no statistic {self.quantity.name!r} (is &statistics enabled?)")
        if self.quantity.stop >= len(statistic):
            raise ValueError(f"stop {self.quantity.stop} (--stop): statistic {self.quantity.name!r} has "
                             f"{len(statistic)} entries, one per stop of the scene; allowed: 0 <= stop <= "
                             f"{len(statistic) - 1}")
        return Run(float(statistic.value[self.quantity.stop]), float(statistic.half_width[self.quantity.stop]),
                    None, cpu, scene.t_end, statistic.unit)


def distance(a: Run, b: Run) -> float:
    if a.tip is not None and b.tip is not None:
        n = min(a.tip.size, b.tip.size)
        d = np.abs(a.tip[:n] - b.tip[:n])
        return float(d.max()) if n and np.all(np.isfinite(d)) else math.inf
    return abs(a.value - b.value)


def richardson(runs: Sequence[Optional[Run]], ratios: Sequence[float], nominal: float, safety: float) -> float:
    """The candidate's error, safety · |q_0 − q_1| · r^p / (r^p − 1), from rungs q_0 (the candidate),
    q_1, q_2 (finer, finer still; r = q_0's refinement ratio to q_1); p observed from the three,
    bounded; the nominal order without a third rung.

    With q_h = q + C h^p, |q_0 − q_1| = |C| h_0^p (1 − r^−p), so |q_0 − q| = |q_0 − q_1| r^p/(r^p − 1);
    |q_0 − q_1|/(r^p − 1) alone would be the error of the finer rung q_1, r^p times too small."""
    if runs[0] is None or runs[1] is None:
        return math.inf
    d1 = distance(runs[0], runs[1])
    if d1 == 0.0 or not math.isfinite(d1):
        return d1
    p = nominal
    if len(runs) > 2 and runs[2] is not None:
        d2 = distance(runs[1], runs[2])
        if d2 > 0 and math.isfinite(d2):
            p = math.log(d1 / d2) / math.log(ratios[1] if len(ratios) > 1 else ratios[0])
    p = min(max(p, _P_BOUNDS[0]), _P_BOUNDS[1])
    gain = ratios[0] ** p
    return safety * d1 * gain / (gain - 1.0)


def ratio(coarse: Rung, fine: Rung) -> float:
    """Refinement ratio of two rungs of the mesh ladder (elements, or modes; all modes = 2J)."""
    (j0, r0), (j1, r1) = coarse, fine
    if j0 != j1:
        return j1 / j0
    return (r1 or 2 * j1) / (r0 or 2 * j0)

"""Which model do I need? The cheapest model whose estimated error on a quantity is under a tolerance.

``plan(scene, qoi, tol)`` searches the contact law (among those allowed), the mesh (the number of
elements J on a ladder J/4, J/2, J, 2J around the scene's; the reduced model's ``modes`` when the
engine has that key) and the time step (the scene's Δt times 4, 2, 1, 1/2, 1/4, 1/8, refused ones
skipped) for the cheapest candidate, by CPU per simulated second, whose estimated error is ≤ tol,
then checks the choice against a finer run.

Quantities (:data:`QUANTITIES`):

- ``tip`` (deterministic): the tip trajectory on [0, until], distance max |u_tip − u'_tip| over a
  common record grid. A candidate's error is a Richardson estimate in Δt plus one in the mesh,
  each ``safety · |q_h − q_fine| / (r^p − 1)`` with r the refinement ratio and p the order
  observed from three rungs (bounded to [1, 4]; the nominal order when a third rung is missing),
  plus, for a law other than the scene's, the measured distance to the scene's law at the same
  mesh and Δt.
- ``power``, ``impulse_rate``, ``shocks_per_second``, ``contact_fraction``, ``tip_rms``
  (statistical, the engine's batch-means statistics after the scene's ``transient``): a
  candidate's error is ``safety · (|v − v_finer| + h)``, h its 95 % half-width and v_finer the
  value of the finer run (next mesh, Δt/2, the scene's law). The window is first scaled so that
  the half-width is about half the tolerance, W = W_scene · (h_scene / h*)² (batch means), and
  reported.

Every run, CPU time, statistic and interval comes from the engine (:func:`beamstops.run`);
this module only chooses scenes, differences and sorts. The search is deterministic (no
random numbers; the engine's runs are reproducible bit for bit).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any, Optional, Union

import numpy as np

from .engine import run, stability
from .result import IncompleteRunError, Result
from .scene import GROUPS, Scene
from .studies.common import progress

__all__ = ["QUANTITIES", "STATISTICAL", "LAWS", "Quantity", "Model", "Candidate", "Check", "Plan", "plan",
           "parse_tolerance", "reduced_available"]

#: Statistical quantities: the engine's statistic of that name (entry ``stop``).
STATISTICAL: tuple[str, ...] = ("power", "impulse_rate", "shocks_per_second", "contact_fraction", "tip_rms")
#: Every quantity ``plan`` accepts.
QUANTITIES: tuple[str, ...] = ("tip",) + STATISTICAL
#: Contact models the search may use: scene changes of each.
LAWS: dict[str, dict[str, str]] = {
    "signorini": {"law": "signorini", "mass": "consistent"},
    "redistributed": {"law": "signorini", "mass": "redistributed"},
    "compliance": {"law": "compliance", "mass": "consistent"},
    "none": {"law": "none", "mass": "consistent"},
}
_P_BOUNDS = (1.0, 4.0)
_RECORDS = 2000  # records kept by a statistical run (the statistics use every step)
_STEP_WORK = 8.0  # elements' worth of fixed work per step, for the cost prediction


def reduced_available() -> bool:
    """Whether the engine has the reduced (modal) model's key ``modes`` in ``&mesh``."""
    return "modes" in GROUPS.get("mesh", ()) and "modes" in {f.name for f in dataclasses.fields(Scene)}


def parse_tolerance(text: Union[str, float]) -> tuple[float, bool]:
    """``'2%'`` → (0.02, True) (relative); ``'0.01'`` or 0.01 → (0.01, False) (absolute). Must be > 0."""
    relative = isinstance(text, str) and text.strip().endswith("%")
    body = text.strip()[:-1] if relative and isinstance(text, str) else text
    try:
        value = float(body)
    except ValueError:
        raise ValueError(f"tolerance {text!r}: a number > 0, or a percentage such as 2%") from None
    if not (value > 0 and math.isfinite(value)):
        raise ValueError(f"tolerance {text!r}: must be > 0")
    return (value / 100.0 if relative else value), relative


@dataclass(frozen=True)
class Quantity:
    """What the plan must get right: the tip trajectory on [0, until] or a statistic of the engine."""

    name: str
    until: Optional[float] = None
    """``tip``: end of the window [0, until] (s)."""
    stop: int = 0
    """Statistical: which entry of a per-stop statistic (0: the tip's stops, or the first stop)."""

    def __post_init__(self) -> None:
        if self.name not in QUANTITIES:
            raise ValueError(f"unknown quantity {self.name!r}; choose one of {', '.join(QUANTITIES)}")
        if self.deterministic and not (self.until is not None and self.until > 0):
            raise ValueError("quantity 'tip' needs a window end until > 0 (s), e.g. --until 0.08")

    @property
    def deterministic(self) -> bool:
        return self.name == "tip"

    def label(self) -> str:
        return f"max |u_tip| error on [0, {self.until:g}] s" if self.deterministic else self.name


@dataclass(frozen=True, order=True)
class Model:
    """A point of the search: contact model, mesh (J, reduced modes: 0 = full) and Δt."""

    law: str
    elements: int
    modes: int
    dt: float

    def describe(self) -> str:
        return f"{self.law} J={self.elements}" + (f" r={self.modes}" if self.modes else "") + f" dt={self.dt:g}"


@dataclass(frozen=True)
class Candidate:
    """One row of the plan's table."""

    model: Model
    value: float
    """QoI value: max |u_tip| on the window (tip), or the statistic's value."""
    half_width: float
    """95 % half-width of the statistic (nan for the tip)."""
    error: float
    """Estimated error (inf when it could not be estimated)."""
    parts: dict[str, float]
    """The estimate's terms: 'dt', 'mesh', 'law' (tip); 'difference', 'half_width' (statistics)."""
    cpu_per_second: float
    """The engine's CPU seconds per simulated second."""
    verdict: str
    """'qualifies', 'too coarse', 'no estimate' or 'refused: ...'."""

    @property
    def qualifies(self) -> bool:
        return self.verdict == "qualifies"


@dataclass(frozen=True)
class Check:
    """The choice against a finer run (next mesh, Δt/2, the scene's law)."""

    finer: Model
    value: float
    half_width: float
    finer_value: float
    finer_half_width: float
    difference: float
    """Measured: max |u − u'| on the window (tip) or |v − v'| (statistics)."""
    tolerance: float
    overlap: Optional[bool]
    """Statistics: whether the two 95 % intervals overlap."""

    @property
    def passed(self) -> bool:
        return self.difference <= self.tolerance


@dataclass
class Plan:
    """The search's outcome: candidates in the order run, the choice, its scene and its check."""

    quantity: Quantity
    tolerance: float
    """Absolute tolerance (the QoI's unit)."""
    relative: Optional[float]
    """The relative tolerance asked for (0.02 for 2 %), or None."""
    unit: str
    candidates: list[Candidate] = field(default_factory=list)
    choice: Optional[Candidate] = None
    scene: Optional[Scene] = None
    check: Optional[Check] = None
    window: Optional[float] = None
    """Statistics: the window after the transient used by every candidate (s)."""
    pilot_window: Optional[float] = None
    pilot_half_width: Optional[float] = None
    cpu_seconds: float = 0.0
    """The engine's CPU time of every run of the search and the check."""
    runs: int = 0
    stopped: Optional[str] = None
    """Why the search stopped before finding a qualifying candidate (budget), or None."""
    notes: list[str] = field(default_factory=list)

    def table(self) -> str:
        """The candidates as a markdown table."""
        unit = f" ({self.unit})" if self.unit else ""
        lines = [f"| law | J | {'modes | ' if any(c.model.modes for c in self.candidates) else ''}Δt (s) | "
                 f"value{unit} | ± 95 %{unit} | error estimate{unit} | CPU s per simulated s | verdict |",
                 "|---|---|" + ("---|" if any(c.model.modes for c in self.candidates) else "") + "---|---|---|---|---|---|"]
        with_modes = any(c.model.modes for c in self.candidates)
        for c in self.candidates:
            mark = " **chosen**" if c is self.choice else ""
            modes = (f"{c.model.modes or 'all'} | " if with_modes else "")
            lines.append(f"| {c.model.law} | {c.model.elements} | {modes}{c.model.dt:.4g} | {_g(c.value)} | "
                         f"{_g(c.half_width)} | {_g(c.error)} | {_g(c.cpu_per_second)} | {c.verdict}{mark} |")
        return "\n".join(lines) + "\n"

    def summary(self) -> str:
        """What the plan found, in a few lines of text."""
        tol = f"{self.tolerance:.4g} {self.unit}".rstrip()
        if self.relative is not None:
            tol += f" ({100 * self.relative:g} % of the scene's value)"
        out = [f"quantity: {self.quantity.label()}; tolerance {tol}"]
        if self.window is not None:
            out.append(f"window after the transient: {self.window:.4g} s (the scene's {self.pilot_window:.4g} s gave "
                       f"± {self.pilot_half_width:.3g}; half-widths scale as 1/sqrt(window))")
        out.append(f"search: {self.runs} runs, {self.cpu_seconds:.3g} s of engine CPU")
        if self.stopped:
            out.append(f"stopped: {self.stopped}")
        if self.choice is None:
            out.append("no candidate could be estimated")
        else:
            c = self.choice
            state = "qualifies" if c.qualifies else "does NOT qualify (best estimate found)"
            out.append(f"choice: {c.model.describe()}: value {_g(c.value)}, estimated error {_g(c.error)} "
                       f"{self.unit}, {_g(c.cpu_per_second)} CPU s per simulated s; {state}")
        out += [f"note: {note}" for note in self.notes]
        if self.check is not None:
            k = self.check
            overlap = "" if k.overlap is None else f"; intervals {'overlap' if k.overlap else 'do NOT overlap'}"
            out.append(f"check against {k.finer.describe()}: measured difference {_g(k.difference)} {self.unit} "
                       f"{'≤' if k.passed else '>'} tolerance {_g(k.tolerance)}: {'PASS' if k.passed else 'FAIL'}"
                       f"{overlap}")
        return "\n".join(out)


def _g(x: float) -> str:
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else ("inf" if x == math.inf else f"{x:.3g}")


# ----------------------------------------------------------------------------------- ladders

Rung = tuple[int, int]
"""A mesh: (elements J, reduced modes r; 0 = the full model)."""


@dataclass
class _Ladder:
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


def _mesh_ladder(scene: Scene) -> _Ladder:
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
    if reduced_available():
        modes = [(j, r) for r in (4, 8, 16, 32, 64) if r < 2 * j - max(len(scene.nodes), 1)]
        chain = modes + [(j, 0)]
        finer.update({a: b for a, b in zip(chain, chain[1:])})
        rungs = modes + rungs
    return _Ladder(rungs, finer)


def _dt_ladder(scene: Scene, coarser: int, finer: int) -> list[float]:
    return [scene.dt * 2.0**k for k in range(coarser, -finer - 1, -1)]


def _scene_of(base: Scene, model: Model, record_every: int) -> Scene:
    changes: dict[str, Any] = dict(LAWS[model.law])
    if base.nodes and model.elements != base.elements:
        changes["nodes"] = tuple(node * model.elements // base.elements for node in base.nodes)
    if reduced_available():
        changes["modes"] = model.modes
    return base.replace(elements=model.elements, dt=model.dt, record_every=record_every, **changes)


# ----------------------------------------------------------------------------------- runs

@dataclass(frozen=True)
class _Run:
    value: float
    half_width: float
    tip: Optional[np.ndarray]
    cpu: float
    simulated: float
    unit: str


class _Runner:
    """Runs models once each (cached), keeps the CPU spent, refuses runs beyond the budget."""

    def __init__(self, base: Scene, quantity: Quantity, grid: Optional[float], budget: Optional[float]) -> None:
        self.base, self.quantity, self.grid, self.budget = base, quantity, grid, budget
        self.cache: dict[Model, _Run] = {}
        self.refused: dict[Model, str] = {}
        self.cpu = 0.0
        self.rate: Optional[float] = None  # CPU s per (element-step), from the runs so far
        self.shock_rate = 0.0  # shocks per simulated second, the most seen (room in the shock log)

    def scene(self, model: Model) -> Scene:
        if self.quantity.deterministic:
            assert self.grid is not None
            every = max(1, round(self.grid / model.dt))
        else:
            every = max(1, math.ceil(self.base.t_end / model.dt / _RECORDS))
        return _scene_of(self.base, model, every)

    def predicted(self, model: Model) -> float:
        steps = self.base.t_end / model.dt
        return (self.rate or 0.0) * steps * (model.elements + _STEP_WORK)

    def affordable(self, models: Iterable[Model]) -> bool:
        if self.budget is None:
            return True
        todo = {m for m in models if m not in self.cache and m not in self.refused}
        return self.cpu + sum(self.predicted(m) for m in todo) <= self.budget

    def get(self, model: Model) -> Optional[_Run]:
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
        work = steps * (model.elements + _STEP_WORK)
        self.rate = entry.cpu / work if self.rate is None else max(self.rate, 0.5 * self.rate + 0.5 * entry.cpu / work)
        return entry

    def _entry(self, result: Result, scene: Scene) -> _Run:
        cpu = float(result.attrs["cpu_seconds"])
        if self.quantity.deterministic:
            assert self.quantity.until is not None
            keep = result.t <= self.quantity.until * (1 + 1e-12)
            tip = np.asarray(result.tip_u[keep], dtype=np.float64)
            return _Run(float(np.abs(tip).max()) if tip.size else math.nan, math.nan, tip, cpu, scene.t_end, "m")
        statistic = result.statistics.get(self.quantity.name)
        if statistic is None:
            raise ValueError(f"the engine gave no statistic {self.quantity.name!r} (is &statistics enabled?)")
        if self.quantity.stop >= len(statistic):
            raise ValueError(f"statistic {self.quantity.name!r} has {len(statistic)} entries; no stop "
                             f"{self.quantity.stop}")
        return _Run(float(statistic.value[self.quantity.stop]), float(statistic.half_width[self.quantity.stop]),
                    None, cpu, scene.t_end, statistic.unit)


def _distance(a: _Run, b: _Run) -> float:
    if a.tip is not None and b.tip is not None:
        n = min(a.tip.size, b.tip.size)
        d = np.abs(a.tip[:n] - b.tip[:n])
        return float(d.max()) if n and np.all(np.isfinite(d)) else math.inf
    return abs(a.value - b.value)


def _richardson(runs: Sequence[Optional[_Run]], ratios: Sequence[float], nominal: float, safety: float) -> float:
    """safety |q_0 − q_1| / (r^p − 1) from rungs q_0 (candidate), q_1, q_2 (finer, finer still);
    p observed from the three, bounded; the nominal order without a third rung."""
    if runs[0] is None or runs[1] is None:
        return math.inf
    d1 = _distance(runs[0], runs[1])
    if d1 == 0.0 or not math.isfinite(d1):
        return d1
    p = nominal
    if len(runs) > 2 and runs[2] is not None:
        d2 = _distance(runs[1], runs[2])
        if d2 > 0 and math.isfinite(d2):
            p = math.log(d1 / d2) / math.log(ratios[1] if len(ratios) > 1 else ratios[0])
    p = min(max(p, _P_BOUNDS[0]), _P_BOUNDS[1])
    return safety * d1 / (ratios[0] ** p - 1.0)


# ----------------------------------------------------------------------------------- search

def plan(scene: Scene, qoi: Union[str, Quantity], tol: Union[str, float], *, until: Optional[float] = None,
         budget: Optional[float] = None, laws: Optional[Sequence[str]] = None, safety: Optional[float] = None,
         coarser: int = 2, finer: int = 3, extend: int = 2, exhaustive: bool = False, max_window: Optional[float] = None,
         quiet: bool = False) -> Plan:
    """The cheapest model of ``scene`` whose estimated error on ``qoi`` is ≤ ``tol``, and its check.

    ``qoi``: 'tip' (with ``until``, s) or a statistic of :data:`STATISTICAL`; ``tol``: absolute in the
    quantity's unit, or a percentage string ('2%') of the scene's own value. ``laws``: contact models
    the search may use (keys of :data:`LAWS`; default the scene's own). ``budget``: engine CPU seconds
    for the search (stops refining once the next runs would exceed it). ``safety``: factor on the
    estimates (default 2 for the tip, 1 for statistics, whose difference already carries both runs'
    noise). ``coarser``/``finer``: Δt ladder from dt·2^coarser down to dt/2^finer. ``exhaustive``:
    estimate every candidate (within the budget) instead of stopping at the first, in order of
    predicted cost, that qualifies. ``extend``: when nothing qualifies, add up to this many finer rungs
    (Δt/2 and 2J each) and go on. Raises ValueError on bad input.
    """
    quantity = qoi if isinstance(qoi, Quantity) else Quantity(qoi, until=until)
    fraction, relative = parse_tolerance(tol)
    if budget is not None and not budget > 0:
        raise ValueError(f"budget {budget!r}: CPU seconds > 0")
    if coarser < 0 or finer < 2 or extend < 0:
        raise ValueError("the Δt ladder needs coarser >= 0, finer >= 2 and extend >= 0")
    reference_law = "redistributed" if (scene.law == "signorini" and scene.mass == "redistributed") else scene.law
    chosen_laws = list(dict.fromkeys(laws)) if laws else [reference_law]
    unknown = [law for law in chosen_laws if law not in LAWS]
    if unknown:
        raise ValueError(f"unknown law(s) {', '.join(unknown)}; choose among {', '.join(LAWS)}")
    if "compliance" in chosen_laws and not scene.stiffness_per_mass > 0:
        raise ValueError("law 'compliance' needs a stiffness in the scene (&stops stiffness or stiffness_per_mass)")
    if reference_law not in chosen_laws:
        chosen_laws.append(reference_law)  # the finer runs use the scene's law
    factor = safety if safety is not None else (2.0 if quantity.deterministic else 1.0)
    if not factor > 0:
        raise ValueError(f"safety {safety!r}: > 0")

    base = scene.replace(snapshot_every=0, checkpoint_every=0, members=1)
    dts = _dt_ladder(base, coarser, finer)
    grid = None
    if quantity.deterministic:
        assert quantity.until is not None
        grid = max(dts)
        base = base.replace(t_end=max(quantity.until, grid), enabled=False)
    elif not base.enabled:
        base = base.replace(enabled=True)
    if not quantity.deterministic and not base.t_end > base.transient:
        raise ValueError(f"the scene's window after its transient is empty (t_end {base.t_end} ≤ transient "
                         f"{base.transient})")
    meshes = _mesh_ladder(base)
    runner = pilot_runner = _Runner(base, quantity, grid, budget)
    own = Model(reference_law, base.elements, int(getattr(base, "modes")) if reduced_available() else 0, base.dt)
    pilot = runner.get(own)
    if pilot is None:
        raise ValueError(f"the scene itself cannot run: {runner.refused.get(own, 'refused')}")
    unit = pilot.unit
    tolerance = fraction * abs(pilot.value) if relative else fraction
    if relative and not tolerance > 0:
        raise ValueError(f"a relative tolerance of a quantity whose value is {pilot.value}: give it absolute")
    out = Plan(quantity=quantity, tolerance=tolerance, relative=fraction if relative else None, unit=unit)

    if not quantity.deterministic:  # scale the window to a half-width of about half the tolerance
        window = base.t_end - base.transient
        out.pilot_window, out.pilot_half_width = window, pilot.half_width
        target = 0.5 * tolerance
        needed = window * (pilot.half_width / target) ** 2 if math.isfinite(pilot.half_width) else window
        needed = max(needed, 0.25 * window)
        if max_window is not None:
            needed = min(needed, max_window)
        needed = float(f"{needed:.3g}")
        out.window = needed
        if needed != window:
            t_end = base.transient + needed
            base = base.replace(t_end=t_end, record_every=max(1, math.ceil(t_end / min(dts) / _RECORDS)))
            pilot_runner, runner = runner, _Runner(base, quantity, grid, budget)
            runner.cpu, runner.rate, runner.shock_rate = pilot_runner.cpu, pilot_runner.rate, pilot_runner.shock_rate
    done: set[Model] = set()
    for round_ in range(extend + 1):
        if round_:  # nothing qualified: one rung finer in Δt and in the mesh
            dts.append(dts[-1] / 2)
            meshes.extend()
        models = [Model(law, j, r, dt) for law in chosen_laws for (j, r) in meshes.refinable() for dt in dts[:-1]]
        models = sorted((m for m in models if m not in done), key=_cost)
        for model in progress(models, f"plan (round {round_ + 1})", total=len(models), quiet=quiet):
            needs = _needs(model, meshes, dts, reference_law, quantity)
            if not runner.affordable(needs):
                runs = len(runner.cache) + (runner is not pilot_runner)
                out.stopped = (f"budget of {budget:g} CPU s reached after {runs} runs "
                               f"({runner.cpu:.3g} s); finer candidates were not estimated")
                break
            done.add(model)
            candidate = _estimate(model, runner, meshes, dts, reference_law, quantity, factor, tolerance)
            if candidate is None:
                continue
            out.candidates.append(candidate)
            if candidate.qualifies and not exhaustive:
                break
        if out.stopped or any(c.qualifies for c in out.candidates):
            break
        if not quantity.deterministic and out.candidates and \
                min(c.half_width for c in out.candidates) > 0.5 * tolerance:
            out.notes.append("no candidate qualifies and the half-widths exceed half the tolerance: a longer window "
                             "(max_window), not a finer model, is what is missing")
            break
    qualified = [c for c in out.candidates if c.qualifies]
    if qualified:
        out.choice = min(qualified, key=lambda c: c.cpu_per_second)
    elif out.candidates:
        out.choice = min(out.candidates, key=lambda c: c.error)
    if out.choice is not None:
        steps = (scene.t_end if quantity.deterministic else base.t_end) / out.choice.model.dt
        every = max(scene.record_every, math.ceil(steps / 1e6))
        if every != scene.record_every:
            out.notes.append(f"the chosen scene records every {every} steps (at most a million records)")
        keep: dict[str, Any] = {"file": scene.file, "record_every": every, "checkpoint_every": scene.checkpoint_every,
                "members": scene.members, "enabled": scene.enabled,
                "t_end": scene.t_end if quantity.deterministic else base.t_end}
        chosen = runner.scene(out.choice.model)
        try:
            out.scene = chosen.replace(snapshot_every=scene.snapshot_every, **keep)
        except ValueError as exc:  # the scene's snapshots would not fit at the chosen Δt
            out.scene = chosen.replace(snapshot_every=0, **keep)
            out.notes.append(f"the chosen scene has no snapshots ({exc})")
        out.check = _check(out.choice, runner, meshes, reference_law, tolerance)
    if out.choice is not None and out.choice.qualifies and out.choice.model.dt == dts[0]:
        out.notes.append("the choice is on the coarsest Δt rung: a coarser Δt may qualify too (coarser=, --coarser)")
    if out.choice is not None and out.choice.qualifies and (out.choice.model.elements, out.choice.model.modes) == meshes.rungs[0]:
        out.notes.append("the choice is on the coarsest mesh rung")
    refused = {**pilot_runner.refused, **runner.refused}
    if refused:
        first = next(iter(refused.items()))
        out.notes.append(f"{len(refused)} model(s) refused by the engine and skipped (e.g. {first[0].describe()}: "
                         f"{first[1]})")
    out.cpu_seconds, out.runs = runner.cpu, len(runner.cache) + (runner is not pilot_runner)
    return out


def _cost(model: Model) -> float:
    """Predicted cost per simulated second, up to a factor: (unknowns' work + fixed work) / Δt."""
    return ((model.modes or model.elements) + _STEP_WORK) / model.dt


def _needs(model: Model, meshes: _Ladder, dts: Sequence[float], reference_law: str,
           quantity: Quantity) -> list[Model]:
    """The runs the estimate of ``model`` uses."""
    rungs, k = meshes.chain((model.elements, model.modes), 3), dts.index(model.dt)
    if not quantity.deterministic:
        j, r = rungs[1]
        return [model, Model(reference_law, j, r, dts[k + 1])]
    out = [model] + [Model(model.law, model.elements, model.modes, dt) for dt in dts[k + 1:k + 3]]
    out += [Model(model.law, j, r, model.dt) for (j, r) in rungs[1:]]
    if model.law != reference_law:
        out.append(Model(reference_law, model.elements, model.modes, model.dt))
    return out


def _estimate(model: Model, runner: _Runner, meshes: _Ladder, dts: Sequence[float],
              reference_law: str, quantity: Quantity, safety: float, tolerance: float) -> Optional[Candidate]:
    own = runner.get(model)
    if own is None:
        return None  # refused by the engine (stability): not a candidate
    cpu_rate = own.cpu / own.simulated
    rungs, k = meshes.chain((model.elements, model.modes), 3), dts.index(model.dt)
    if quantity.deterministic:
        in_dt = [runner.get(Model(model.law, model.elements, model.modes, dt)) for dt in dts[k:k + 3]]
        in_mesh = [runner.get(Model(model.law, j, r, model.dt)) for (j, r) in rungs]
        nominal_dt = 1.0 if runner.base.load_rule == "paper" else 2.0
        e_dt = _richardson(in_dt, [2.0, 2.0], nominal_dt, safety)
        ratios = [_ratio(rungs[n], rungs[n + 1]) for n in range(len(rungs) - 1)]
        e_mesh = _richardson(in_mesh, ratios, 2.0, safety)
        parts = {"dt": e_dt, "mesh": e_mesh}
        if model.law != reference_law:
            ref = runner.get(Model(reference_law, model.elements, model.modes, model.dt))
            parts["law"] = _distance(own, ref) if ref is not None else math.inf
        error = sum(parts.values())
        half = math.nan
    else:
        j, r = rungs[1]
        finer = runner.get(Model(reference_law, j, r, dts[k + 1]))
        difference = abs(own.value - finer.value) if finer is not None else math.inf
        parts = {"difference": difference, "half_width": own.half_width}
        error = safety * (difference + own.half_width) if math.isfinite(own.half_width) else math.inf
        half = own.half_width
    if not math.isfinite(error):
        verdict = "no estimate"
    else:
        verdict = "qualifies" if error <= tolerance else "too coarse"
    return Candidate(model=model, value=own.value, half_width=half, error=error, parts=parts,
                     cpu_per_second=cpu_rate, verdict=verdict)


def _ratio(coarse: Rung, fine: Rung) -> float:
    """Refinement ratio of two rungs of the mesh ladder (elements, or modes; all modes = 2J)."""
    (j0, r0), (j1, r1) = coarse, fine
    if j0 != j1:
        return j1 / j0
    return (r1 or 2 * j1) / (r0 or 2 * j0)


def _check(choice: Candidate, runner: _Runner, meshes: _Ladder, reference_law: str,
           tolerance: float) -> Optional[Check]:
    model = choice.model
    rung = (model.elements, model.modes)
    j, r = meshes.finer.get(rung, (2 * model.elements, 0))
    finer = Model(reference_law, j, r, model.dt / 2)
    a, b = runner.get(model), runner.get(finer)
    if a is None or b is None:
        return None
    difference = _distance(a, b)
    overlap = None if runner.quantity.deterministic else bool(difference <= a.half_width + b.half_width)
    return Check(finer=finer, value=a.value, half_width=a.half_width, finer_value=b.value,
                 finer_half_width=b.half_width, difference=difference, tolerance=tolerance, overlap=overlap)

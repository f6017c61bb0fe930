"""Which model do I need? The cheapest model whose estimated error on a quantity is under a tolerance.

``plan(scene, qoi, tol)`` searches the contact law (among those allowed), the mesh (the number of
elements J on a ladder J/4, J/2, J, 2J around the scene's; the reduced model's ``modes`` when the
engine has that key) and the time step (the scene's Δt times 4, 2, 1, 1/2, 1/4, 1/8, refused ones
skipped) for the cheapest candidate, by CPU per simulated second, whose estimated error is ≤ tol,
then checks the choice against a finer run.

Quantities (:data:`QUANTITIES`):

- ``tip`` (deterministic): the tip trajectory on [0, until], distance max |u_tip − u'_tip| over a
  common record grid. A candidate's error is a Richardson estimate in Δt plus one in the mesh,
  each ``safety · |q_h − q_fine| · r^p / (r^p − 1)`` (the candidate's own error, not the finer
  run's) with r the refinement ratio and p the order observed from three rungs (bounded to [1, 4]; the nominal order when a third rung is missing),
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

import math
import os
import sys
from collections.abc import Sequence
from typing import Any, Optional, Union

from .arguments import bounded

from .plan_runs import RECORDS, STEP_WORK, Ladder, Runner, distance, dt_ladder, mesh_ladder, ratio, reduced_available, \
    richardson
from .plan_types import LAWS, QUANTITIES, STATISTICAL, Candidate, Check, Model, Plan, Quantity, parse_laws, \
    parse_tolerance, window_range
from .scene import Scene
from .studies.common import progress

__all__ = ["QUANTITIES", "STATISTICAL", "LAWS", "Quantity", "Model", "Candidate", "Check", "Plan", "plan",
           "parse_tolerance", "reduced_available", "window_scene", "check_max_window"]

#: Most rungs of the Δt ladder either way: Δt·2^20 or Δt/2^20 (a million times the scene's steps).
MAX_RUNGS = 20


# ----------------------------------------------------------------------------------- search

def plan(scene: Union[Scene, str, "os.PathLike[str]"], qoi: Union[str, Quantity], tol: Union[str, float], *,
         until: Optional[float] = None, budget: Optional[float] = None, laws: Optional[Union[str, Sequence[str]]] = None,
         safety: Optional[float] = None, coarser: int = 2, finer: int = 3, extend: int = 2, exhaustive: bool = False,
         max_window: Optional[float] = None, quiet: bool = False) -> Plan:
    """The cheapest model of ``scene`` whose estimated error on ``qoi`` is ≤ ``tol``, and its check.

    ``scene``: a :class:`Scene` or the path of a namelist file. ``qoi``: 'tip' (with ``until``, s:
    one step of the scene ≤ until ≤ its t_end) or a statistic of :data:`STATISTICAL` (no
    ``until``); ``tol``: absolute in the quantity's unit, or a percentage string ('2%') of the
    scene's own value. ``laws``: contact models the search may use (keys of :data:`LAWS`: one name,
    names separated by commas, or a sequence; default the scene's own). ``budget``: engine CPU seconds
    for the search (stops refining once the next runs would exceed it). ``safety``: factor on the
    estimates (default 2 for the tip, 1 for statistics, whose difference already carries both runs'
    noise). ``coarser``/``finer``: Δt ladder from dt·2^coarser down to dt/2^finer (rungs beyond the
    tip's window or the scene's t_end left out). ``exhaustive``: estimate every candidate (within the
    budget) instead of stopping at the first, in order of predicted cost, that qualifies.
    ``extend``: when nothing qualifies, add up to this many finer rungs (Δt/2 and 2J each) and go
    on. Raises ValueError on bad input and TypeError on arguments of the wrong type.
    :attr:`Plan.met` says whether the outcome meets the tolerance, :meth:`Plan.shortfall` why not.
    """
    if isinstance(scene, (str, os.PathLike)):
        scene = Scene.from_namelist(scene)
    elif not isinstance(scene, Scene):
        raise TypeError(f"scene: a beamstops.Scene or the path of a namelist file, not {type(scene).__name__}")
    if isinstance(qoi, Quantity):
        if until is not None and until != qoi.until:
            raise ValueError(f"until {until!r} differs from the quantity's until {qoi.until!r}: give one")
        quantity = qoi
    else:
        quantity = Quantity(qoi, until=until)
    if quantity.deterministic:
        assert quantity.until is not None
        window_range(quantity.until, scene.t_end, scene.dt)
    fraction, relative = parse_tolerance(tol)
    if budget is not None:
        bounded(budget, "engine CPU seconds", name="budget")
    for name, value, low in (("coarser", coarser, 0), ("finer", finer, 2), ("extend", extend, 0)):
        if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= MAX_RUNGS:
            raise ValueError(f"{name} {value!r}: allowed: a whole number {low} ... {MAX_RUNGS} (powers of 2 of the "
                             f"scene's Δt: the Δt ladder runs from dt·2^coarser to dt/2^finer)")
    if max_window is not None:
        bounded(max_window, "a window after the transient in s", name="max_window")
        if not quantity.deterministic:
            check_max_window(scene, max_window, "max_window")
    reference_law = "redistributed" if (scene.law == "signorini" and scene.mass == "redistributed") else scene.law
    chosen_laws = parse_laws(laws) if laws is not None else [reference_law]
    if "compliance" in chosen_laws and not scene.stiffness_per_mass > 0:
        raise ValueError("law 'compliance' needs a stiffness in the scene (&stops stiffness or stiffness_per_mass)")
    if reference_law not in chosen_laws:
        chosen_laws.append(reference_law)  # the finer runs use the scene's law
    if safety is not None:
        bounded(safety, "a factor on the error estimates", name="safety")
    factor = safety if safety is not None else (2.0 if quantity.deterministic else 1.0)

    base = scene.replace(snapshot_every=0, checkpoint_every=0, members=1)
    ladder = dt_ladder(base, coarser, finer)
    # a rung longer than the tip's window, or than the run, has no step in it: left out, as the engine
    # would refuse the second (dt <= t_end); the scene's own dt is never one of them
    dts = [dt for dt in ladder if dt <= (quantity.until if quantity.until is not None else base.t_end)]
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
    meshes = mesh_ladder(base, reduced=scene.members == 1)  # no reduced model runs an ensemble
    runner = pilot_runner = Runner(base, quantity, grid, budget)
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
            try:
                base = window_scene(base, needed, min(dts))
            except ValueError as exc:  # the engine's words on a scene the user never wrote: say where it came from
                raise ValueError(f"the window after the transient that the tolerance {tolerance:g} {unit} needs, "
                                 f"{needed:g} s (the scene's {window:g} s times (its half-width "
                                 f"{pilot.half_width:.3g} / half the tolerance)^2"
                                 f"{', at most max_window' if max_window is not None else ''}), makes a scene the "
                                 f"engine refuses ({exc}); allowed: a larger tolerance, or a window the engine "
                                 "accepts by max_window (--max-window)") from None
            if not quiet and needed > window:  # a long search says so before it starts, not after hours
                per_run = pilot.cpu / pilot.simulated * base.t_end
                print(f"plan: the tolerance {tolerance:g} {unit} needs a window of {needed:g} s after the transient "
                      f"(the scene's {window:g} s gave a half-width of {pilot.half_width:.3g} {unit}); the scene's "
                      f"own model runs it in about {per_run:.3g} CPU s, and each candidate takes a few such runs"
                      f"{'' if budget is not None else ' (bound the search with --budget or --max-window)'}",
                      file=sys.stderr, flush=True)
            dts = [dt for dt in ladder if dt <= base.t_end]  # a longer window may take coarser rungs back
            pilot_runner, runner = runner, Runner(base, quantity, grid, budget)
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
    if out.choice is not None and out.choice.qualifies and out.choice.model.dt == dts[0] == ladder[0]:
        out.notes.append("the choice is on the coarsest Δt rung: a coarser Δt may qualify too "
                         f"(coarser={coarser + 1} from Python, --coarser {coarser + 1} on the command line)")
    if out.choice is not None and out.choice.qualifies and (out.choice.model.elements, out.choice.model.modes) == meshes.rungs[0]:
        out.notes.append("the choice is on the coarsest mesh rung")
    refused = {**pilot_runner.refused, **runner.refused}
    if refused:
        first = next(iter(refused.items()))
        out.notes.append(f"{len(refused)} model(s) refused by the engine and skipped (e.g. {first[0].describe()}: "
                         f"{first[1]})")
    out.cpu_seconds, out.runs = runner.cpu, len(runner.cache) + (runner is not pilot_runner)
    return out


def window_scene(base: Scene, window: float, finest_dt: Optional[float] = None) -> Scene:
    """``base`` run over ``window`` s after its transient (at most RECORDS records a run, steps of
    ``finest_dt``, by default its own dt); the engine's ValueError when it refuses that scene."""
    t_end = base.transient + window
    every = max(1, math.ceil(t_end / (finest_dt if finest_dt is not None else base.dt) / RECORDS))
    return base.replace(t_end=t_end, record_every=every)


def check_max_window(scene: Scene, max_window: float, name: str) -> None:
    """A ValueError naming ``name`` (none when empty) when the engine refuses the statistical scene
    run ``max_window`` s after its transient (a window shorter than one step, or one beyond the
    engine's t_end): checked before any run, by :func:`plan` and by the command line."""
    try:
        window_scene(scene.replace(snapshot_every=0, checkpoint_every=0, members=1, enabled=True), max_window)
    except ValueError as exc:
        raise ValueError(f"{name + ' ' if name else ''}{max_window!r} s: the scene run {max_window!r} s after its "
                         f"transient ({scene.transient!r} s) is refused by the engine ({exc}); allowed: a window of "
                         f"at least one step of the scene (dt = {scene.dt!r} s) that ends within the engine's "
                         "t_end") from None


def _cost(model: Model) -> float:
    """Predicted cost per simulated second, up to a factor: (unknowns' work + fixed work) / Δt."""
    return ((model.modes or model.elements) + STEP_WORK) / model.dt


def _needs(model: Model, meshes: Ladder, dts: Sequence[float], reference_law: str,
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


def _estimate(model: Model, runner: Runner, meshes: Ladder, dts: Sequence[float],
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
        e_dt = richardson(in_dt, [2.0, 2.0], nominal_dt, safety)
        ratios = [ratio(rungs[n], rungs[n + 1]) for n in range(len(rungs) - 1)]
        e_mesh = richardson(in_mesh, ratios, 2.0, safety)
        parts = {"dt": e_dt, "mesh": e_mesh}
        if model.law != reference_law:
            ref = runner.get(Model(reference_law, model.elements, model.modes, model.dt))
            parts["law"] = distance(own, ref) if ref is not None else math.inf
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


def _check(choice: Candidate, runner: Runner, meshes: Ladder, reference_law: str,
           tolerance: float) -> Optional[Check]:
    model = choice.model
    rung = (model.elements, model.modes)
    j, r = meshes.finer.get(rung, (2 * model.elements, 0))
    finer = Model(reference_law, j, r, model.dt / 2)
    a, b = runner.get(model), runner.get(finer)
    if a is None or b is None:
        return None
    difference = distance(a, b)
    overlap = None if runner.quantity.deterministic else bool(difference <= a.half_width + b.half_width)
    return Check(finer=finer, value=a.value, half_width=a.half_width, finer_value=b.value,
                 finer_half_width=b.half_width, difference=difference, tolerance=tolerance, overlap=overlap)

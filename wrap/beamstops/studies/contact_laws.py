"""Contact laws compared on the paper's scene (SPEC §9, §10, §12): the paper's projection
(e = 0), Paoli–Schatzman restitution (e = 0.5, 1), mass redistribution (a massless tip) and
normal compliance, on the energy they keep and take, the violation, the chatter, and the
pointwise convergence in Δt of the tip through the first contact period.

Every number comes from engine runs (J = 19, β = 1/4, centred load, Taylor start):

- energy (one run per law over ``t_end``, plus the paper's law with Rayleigh damping, whose
  ledger has a damping term): E(t) and the ledger /energy/work, /energy/dissipated (the stops),
  /energy/damped, and the run's ``energy_residual``, ``max_violation`` and ``impacts``;
- chatter: the engine's count of entries into contact (``contact_phases``, every step), and
  from its shock log (``result.impacts``: contact phases closer than ``rest_time`` merged) the
  shocks and the contact phases per shock (1 + mean ``rebounds``);
- convergence: the tip on a common record grid against a reference at ``dt_ref`` of the same
  law, largest error over [0, 0.2] s and over [0.08, 0.125] s, with observed orders
  (:func:`common.observed_orders`) and the order over a span of Δt (``span``, SPEC §10's
  6.25e-7 → 7.8125e-8 s); a law "converges" on a window when that order is ≥ ``TARGET``.

``python -m beamstops contact-laws`` and ``scripts/study_contact_laws.py`` write
contact_laws.{png,md} and contact_laws_{energy,convergence,headline}.csv.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

import numpy as np

from ..engine import run
from ..result import Result
from ..scene import Scene
from .cli import StudyCommand
from .common import Table, observed_orders, progress, run_tip, tip_error
from .outputs import StudyFolder

__all__ = ["LAWS", "Plan", "PLANS", "chatter", "shock_log", "inconsistent", "energy_table", "energy_sentence", "convergence_table", "headline",
           "study", "main", "register"]

#: The contact laws compared: label and the scene keys that make it.
LAWS: tuple[tuple[str, dict[str, Any]], ...] = (
    ("e = 0 (paper)", {}),
    ("e = 0.5", {"restitution": 0.5}),
    ("e = 1", {"restitution": 1.0}),
    ("mass redistributed", {"mass": "redistributed"}),
    ("compliance 1/ε = 1e8", {"law": "compliance", "stiffness_per_mass": 1e8}),
)
#: A case of the energy runs only: the paper's law with Rayleigh damping (the ledger's third term).
DAMPED: tuple[str, dict[str, Any]] = ("e = 0, ζ = 1.5 %", {"ratio": (0.015,)})
#: SPEC §10's target: order of the tip error over the span of Δt on the window [0.08, 0.125] s.
TARGET = 1.2
#: Windows of the tip error (s): the first contact period, and its impacts alone.
WINDOWS: tuple[tuple[float, float], ...] = ((0.0, 0.2), (0.08, 0.125))


@dataclass(frozen=True)
class Plan:
    """Sizes of a study: the energy runs, the Δt ladder and its reference, the span of the headline."""

    energy_t_end: float
    energy_dt: float
    energy_record_every: int
    dts: tuple[float, ...]
    dt_ref: float
    span: tuple[float, float]
    grid: float = 1e-5


#: Full study (SPEC §10's ladder: Δt = 1e-5/2^k down to 7.8125e-8, reference 3.90625e-8) and --quick.
PLANS: dict[str, Plan] = {
    "full": Plan(2.0, 1e-6, 10, tuple(1e-5 / 2**k for k in range(2, 8)), 1e-5 / 2**8, (6.25e-7, 7.8125e-8)),
    "quick": Plan(0.5, 2.5e-6, 4, tuple(1e-5 / 2**k for k in range(0, 4)), 1e-5 / 2**4, (5e-6, 1.25e-6)),
}


def base_scene() -> Scene:
    """The paper's scene (input/paper_fig8.nml's beam, stops and β = 1/4), centred load, Taylor start."""
    return Scene(beta=0.25, elements=19)


def shock_log(result: Result) -> tuple[int, float]:
    """(shocks, contact phases per shock = 1 + mean rebounds) of the engine's shock log; (0, NaN)
    without one."""
    rebounds = result.impacts.get("rebounds") if result.impacts else None
    if rebounds is None or np.asarray(rebounds).size == 0:
        return 0, math.nan
    return int(np.asarray(rebounds).size), 1.0 + float(np.mean(rebounds))


def chatter(result: Result) -> tuple[int, float, float]:
    """(contact phases, shocks, contact phases per shock): the engine's ``contact_phases`` (its
    ``impacts`` in runs written before the shock log), and its shock log — NaN without one, or
    when the log holds more shocks than there were contact phases (a shock is one contact phase
    or more: such a log counted something else, see :func:`inconsistent`)."""
    phases = int(result.attrs.get("contact_phases", result.attrs["impacts"]))
    shocks, per_shock = shock_log(result)
    if not shocks or shocks > phases:
        return phases, math.nan, math.nan
    return phases, float(shocks), per_shock


def inconsistent(result: Result) -> Optional[str]:
    """Why the run's shock log is not used (more shocks than contact phases), or None."""
    phases = int(result.attrs.get("contact_phases", result.attrs["impacts"]))
    shocks, _ = shock_log(result)
    if shocks <= phases:
        return None
    reaction = np.abs(result.reaction[result.reaction != 0])
    smallest = f"; its smallest nonzero recorded reaction is {float(reaction.min()):.2g} N" if reaction.size else ""
    return f"the shock log holds {shocks} shocks for {phases} contact phases{smallest}"


def energy_runs(base: Scene, plan: Plan, quiet: bool = False) -> dict[str, Result]:
    """One run per law (and the damped case) over ``plan.energy_t_end`` at ``plan.energy_dt``."""
    scene = base.replace(t_end=plan.energy_t_end, dt=plan.energy_dt, record_every=plan.energy_record_every)
    cases = list(LAWS) + [DAMPED]
    return {label: run(scene.replace(**keys)) for label, keys in progress(cases, "contact laws: energy", quiet=quiet)}


def energy_table(runs: dict[str, Result], plan: Plan) -> Table:
    """The energy ledger, violation and chatter of the energy runs."""
    rows: list[list[object]] = []
    for label, r in runs.items():
        phases, shocks, per_shock = chatter(r)
        a = r.attrs
        rows.append([label, plan.energy_dt, float(r.t[-1]), float(r.energy[-1]), float(np.mean(r.energy)),
                     float(a["work"]), float(a["dissipated"]), float(a["damped"]), float(a["energy_residual"]),
                     float(a["max_violation"]), phases, shocks, per_shock, float(a["cpu_seconds"])])
    table = Table(f"Energy ledger over {plan.energy_t_end:g} s, Δt = {plan.energy_dt:g} s",
                  ["law", "Δt (s)", "T (s)", "E(T) (J)", "mean E (J)", "support work (J)", "stops (J)",
                   "damping (J)", "energy residual (J)", "max violation (m)", "contact phases", "shocks",
                   "phases per shock", "CPU (s)"], rows)
    unused = [f"{label}: {why}" for label, r in runs.items() if (why := inconsistent(r)) is not None]
    table.note = ("E − E(0) = work − stops − damping; energy residual: the engine's round-off of that balance. "
                  "Contact phases: the engine's `contact_phases` (entries into contact, every step); shocks and "
                  "phases per shock (1 + mean rebounds): the engine's shock log (contact phases closer than "
                  "its rest_time are one shock; – when the run has none).")
    if unused:
        table.note += (" Shock log not used (a shock is one contact phase or more) for " + "; ".join(unused) +
                       " — it counts steps whose reaction is round-off as contact.")
    return table


def convergence_table(base: Scene, plan: Plan, quiet: bool = False) -> Table:
    """Tip errors in Δt per law against its own reference run (common record grid ``plan.grid``)."""
    t_end = max(w[1] for w in WINDOWS)
    scene0 = base.replace(t_end=t_end)
    rows: list[list[object]] = []
    points = [(label, keys, dt) for label, keys in LAWS for dt in (plan.dt_ref,) + plan.dts]
    reference: Optional[Result] = None
    errors: dict[str, list[list[float]]] = {}
    for label, keys, dt in progress(points, "contact laws: Δt", quiet=quiet):
        result = run_tip(scene0.replace(dt=dt, **keys), plan.grid)
        if dt == plan.dt_ref:
            reference = result
            continue
        assert reference is not None
        errs = [tip_error(result, reference, end, start).max for start, end in WINDOWS]
        errors.setdefault(label, []).append(errs)
        phases, shocks, per_shock = chatter(result)
        rows.append([label, dt, int(result.attrs["steps"])] + [math.nan] * (2 * len(WINDOWS)) +
                    [float(result.attrs["max_violation"]), phases, per_shock, float(result.attrs["dissipated"]),
                     float(result.attrs["cpu_seconds"])])
    for label, per_dt in errors.items():
        mine = [row for row in rows if row[0] == label]
        for w in range(len(WINDOWS)):
            values = [e[w] for e in per_dt]
            for row, value, order in zip(mine, values, observed_orders(plan.dts, values)):
                row[3 + 2 * w], row[4 + 2 * w] = value, order
    columns = ["law", "Δt (s)", "steps"]
    for start, end in WINDOWS:
        columns += [f"max err [{start:g},{end:g}] (m)", f"order [{start:g},{end:g}]"]
    columns += ["max violation (m)", f"contact phases t≤{t_end:g}", "phases per shock", f"stops (J) t≤{t_end:g}",
                "CPU (s)"]
    table = Table(f"Pointwise convergence in Δt of the tip, t ≤ {t_end:g} s", columns, rows)
    table.note = (f"Paper's scene, J = {base.elements}, β = {base.beta:g}, load '{base.load_rule}', start "
                  f"'{base.start}'; each law against its own reference run at Δt = {plan.dt_ref:g} s; errors on the "
                  f"record grid {plan.grid:g} s; orders between successive rows.")
    return table


def _span_order(table: Table, label: str, column: str, span: tuple[float, float]) -> tuple[float, float, float]:
    """(error at span[0], error at span[1], order between them) of a law in the convergence table."""
    values = {float(r[1]): float(r[table.columns.index(column)]) for r in table.rows if r[0] == label}  # type: ignore
    a, b = values.get(span[0], math.nan), values.get(span[1], math.nan)
    return a, b, observed_orders(list(span), [a, b])[1]


def headline(table: Table, plan: Plan) -> tuple[Table, str]:
    """Per law, the errors at the span's ends and the order between them, on each window; and the
    sentence that answers whether any law converges where the paper's does not."""
    rows: list[list[object]] = []
    verdict: dict[str, list[bool]] = {}
    for label, _ in LAWS:
        row: list[object] = [label]
        for start, end in WINDOWS:
            a, b, order = _span_order(table, label, f"max err [{start:g},{end:g}] (m)", plan.span)
            ok = math.isfinite(order) and order >= TARGET
            verdict.setdefault(label, []).append(ok)
            row += [a, b, order, "yes" if ok else "no"]
        rows.append(row)
    columns = ["law"]
    for start, end in WINDOWS:
        w = f"[{start:g},{end:g}]"
        columns += [f"err {w} Δt={plan.span[0]:g}", f"err {w} Δt={plan.span[1]:g}", f"order {w}",
                    f"converges {w}"]
    summary = Table(f"Headline: order of the tip error between Δt = {plan.span[0]:g} and {plan.span[1]:g} s",
                    columns, rows)
    summary.note = f"'converges': observed order over the span ≥ {TARGET:g} (SPEC §10's target)."
    return summary, _sentence(summary, verdict, plan)


def _sentence(summary: Table, verdict: dict[str, list[bool]], plan: Plan) -> str:
    window = WINDOWS[1]
    w = f"[{window[0]:g}, {window[1]:g}] s"
    paper = LAWS[0][0]
    rows = {str(r[0]): r for r in summary.rows}

    def numbers(label: str) -> str:
        r = rows[label]
        return f"{float(r[5]):.2g} → {float(r[6]):.2g} m, order {float(r[7]):.2f}"  # type: ignore[arg-type]

    winners = [label for label, ok in verdict.items() if ok[1] and label != paper]
    lines = [f"**Answer (measured):** on {w}, between Δt = {plan.span[0]:g} and {plan.span[1]:g} s, "
             f"the paper's projection, {paper}, gives {numbers(paper)}: it "
             + ("converges" if verdict[paper][1] else "does not converge") + f" (target order ≥ {TARGET:g})."]
    if winners and not verdict[paper][1]:
        lines.append("Laws that converge where the paper's does not: "
                     + "; ".join(f"{label} ({numbers(label)})" for label in winners) + ".")
    elif winners:
        lines.append("Laws that converge as the paper's does: "
                     + "; ".join(f"{label} ({numbers(label)})" for label in winners) + ".")
    else:
        lines.append("No other law reaches that order either: "
                     + "; ".join(f"{label} ({numbers(label)})" for label in verdict if label != paper) + ".")
    whole = [label for label, ok in verdict.items() if ok[0]]
    lines.append(f"Over the whole first contact period [{WINDOWS[0][0]:g}, {WINDOWS[0][1]:g}] s: "
                 + (("order ≥ " + f"{TARGET:g} for " + ", ".join(whole)) if whole else "no law reaches that order")
                 + ".")
    return " ".join(lines)


def energy_sentence(energy: Table) -> str:
    """What the energy runs measured, law by law: the stops' share of the support's work, the
    contact phases and the largest violation."""
    col = {name: energy.columns.index(name) for name in energy.columns}
    parts = []
    for r in energy.rows:
        work, stops, damped = (float(r[col[k]]) for k in ("support work (J)", "stops (J)", "damping (J)"))  # type: ignore
        shocks, per_shock = float(r[col["shocks"]]), float(r[col["phases per shock"]])  # type: ignore[arg-type]
        phases = f"{r[col['contact phases']]} contact phases"
        if math.isfinite(per_shock):
            phases += f" in {shocks:.0f} shocks ({per_shock:.3g} per shock)"
        part = (f"{r[0]}: stops {stops:.3g} J of the support's {work:.3g} J ({100 * stops / work:.2g} %), "
                f"{phases}, violation {float(r[col['max violation (m)']]):.2g} m")  # type: ignore
        if damped:
            part += f", damping {damped:.3g} J"
        parts.append(part)
    t, dt = energy.rows[0][col["T (s)"]], energy.rows[0][col["Δt (s)"]]
    return f"**Energy over {float(t):g} s at Δt = {float(dt):g} s (measured):** " + "; ".join(parts) + "."  # type: ignore


#: The files the study writes into its folder.
FILES = tuple(f"contact_laws_{name}.csv" for name in ("energy", "convergence", "headline")) \
    + ("contact_laws.png", "contact_laws.md")


def study(folder: Optional[Path] = None, *, quick: bool = False, quiet: bool = False) -> dict[str, Table]:
    """Run the study; write contact_laws.{png,md} and the tables' CSV into ``folder``."""
    from .contact_laws_draw import draw

    out = StudyFolder.prepare(folder, "contact_laws", FILES)
    plan = PLANS["quick" if quick else "full"]
    base = base_scene()
    runs = energy_runs(base, plan, quiet)
    energy = energy_table(runs, plan)
    convergence = convergence_table(base, plan, quiet)
    summary, sentence = headline(convergence, plan)
    tables = {"energy": energy, "convergence": convergence, "headline": summary}
    for name, table in tables.items():
        out.csv(f"contact_laws_{name}.csv", table.csv())
    draw(runs, convergence, plan, out.path("contact_laws.png"))
    text = [f"# Contact laws on the paper's scene{' (quick)' if quick else ''}", "", sentence, "",
            energy_sentence(energy), "",
            "![contact laws](contact_laws.png)", "", summary.markdown(), energy.markdown(), convergence.markdown()]
    out.markdown("contact_laws.md", "\n".join(text))
    return tables


def _options(parser: argparse.ArgumentParser) -> None:
    del parser  # no options of its own


def _run(folder: Path, args: argparse.Namespace) -> Path:
    study(folder, quick=args.quick, quiet=args.quiet)
    return folder / "contact_laws.png"


#: ``contact-laws [-o DIR] [--quick]``; ``main`` is scripts/study_contact_laws.py.
COMMAND = StudyCommand("contact_laws", _options, _run, name="contact-laws",
                       help="contact laws: energy, violation, chatter, convergence in dt",
                       description="Contact laws compared on the paper's scene (PNG, md, CSV).",
                       prog="study_contact_laws", script_description="Contact-laws study.")
register = COMMAND.register
main = COMMAND.main


def orders(table: Table, label: str, column: str) -> Sequence[float]:
    """The observed orders of a law in a column of the convergence table (for tests)."""
    i = table.columns.index(column)
    return [float(r[i]) for r in table.rows if r[0] == label]  # type: ignore[arg-type]

"""The plan's error estimates, checked on synthetic runs whose exact error is known (no engine run):
a Richardson estimate is the candidate's own error, not the finer rung's."""

from __future__ import annotations

import math

import numpy as np
import pytest

from beamstops.plan_runs import Run, richardson


def _tip(values: np.ndarray) -> Run:
    return Run(value=float(np.abs(values).max()), half_width=math.nan, tip=values, cpu=1.0, simulated=1.0, unit="m")


@pytest.mark.parametrize("p", [1.0, 1.5, 2.0, 3.0])
@pytest.mark.parametrize("r", [2.0, 1.9])
def test_richardson_is_the_error_of_the_candidate(p: float, r: float) -> None:
    # q_h = q + C h^p on a grid of times: the candidate's error is C h0^p, whatever p and r
    t = np.linspace(0.0, 1.0, 51)
    exact, shape = np.sin(3 * t), np.cos(7 * t) * t
    h0 = 0.1
    runs = [_tip(exact + shape * (h0 / r**k) ** p) for k in range(3)]
    truth = float(np.abs(shape * h0**p).max())
    assert richardson(runs, [r, r], nominal=2.0, safety=1.0) == pytest.approx(truth, rel=1e-9)
    # the safety factor multiplies it
    assert richardson(runs, [r, r], nominal=2.0, safety=2.0) == pytest.approx(2 * truth, rel=1e-9)


def test_richardson_with_two_rungs_uses_the_nominal_order() -> None:
    t = np.linspace(0.0, 1.0, 11)
    runs = [_tip(1 + t * 0.04), _tip(1 + t * 0.01), None]  # p = 2, r = 2: error 0.04 at t = 1
    assert richardson(runs, [2.0], nominal=2.0, safety=1.0) == pytest.approx(0.04)
    assert richardson(runs[:2], [2.0], nominal=2.0, safety=1.0) == pytest.approx(0.04)


def test_a_statistics_check_restates_the_estimates_difference() -> None:
    # README: for a statistic the check's finer run is the estimate's own (next mesh, Δt/2, the scene's
    # law), so its measured difference is the estimate's |v − v_finer| term
    import beamstops
    from beamstops.plan import plan

    scene = beamstops.Scene(elements=4, t_end=1.5, transient=0.5, dt=1e-4, beta=0.5)
    p = plan(scene, "impulse_rate", 0.5, quiet=True)
    assert p.choice is not None and p.check is not None
    assert p.check.difference == p.choice.parts["difference"]
    assert p.check.difference <= p.choice.error

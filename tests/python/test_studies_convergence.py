"""Convergence study (issue 6): observed orders, the three-level round-off, the engine's states."""

from __future__ import annotations

import math

import numpy as np
import pytest

import beamstops
from beamstops import Scene
from beamstops.studies import common, convergence

FREE = Scene(law="none", beta=0.25, elements=2, t_end=0.2)
DTS = [4e-5 / 2**k for k in range(4)]


@pytest.mark.parametrize("rule, low, high", [("centered", 1.9, 2.1), ("paper", 0.95, 1.2)])
def test_orders_without_stops(rule: str, low: float, high: float) -> None:
    table = convergence.dt_table(FREE.replace(load_rule=rule), DTS, DTS[-1] / 8, (0.2,), (), quiet=True)
    for name in ("order max [0,0.2]", "order L2 [0,0.2]"):
        orders = table.column(name)
        assert math.isnan(orders[0])
        assert all(low < order < high for order in orders[1:]), (name, orders)


def test_three_level_round_off_floor() -> None:
    """SPEC 4: J = 4, T = 0.2 s, dt = 2.5e-7 (β = 1/2): the two forms differ by ~1.3e-6 m, more than
    the discretization error of dt = 4e-6 at t = T."""
    scene = Scene(law="none", elements=4, t_end=0.2, dt=2.5e-7, record_every=16)
    t, tip_u, cpu = common.run_three_level(scene)
    increment = beamstops.run(scene)
    np.testing.assert_array_equal(t, increment.t)
    gap = float(np.abs(tip_u - increment.tip_u).max())
    assert 3e-7 < gap < 1e-5
    coarse = beamstops.run(scene.replace(dt=4e-6, record_every=1))
    assert abs(coarse.tip_u[-1] - increment.tip_u[-1]) < gap  # at t = T
    # With 16 times fewer steps the two forms are much closer (the drift grows with the steps).
    t3, u3, _ = common.run_three_level(scene.replace(dt=4e-6, record_every=1))
    assert float(np.abs(u3 - coarse.tip_u).max()) < gap / 100


def test_three_level_refuses_stops() -> None:
    with pytest.raises(ValueError, match="without stops"):
        common.run_three_level(Scene(t_end=0.01, dt=1e-4))


def test_states_match_the_records() -> None:
    scene = Scene(t_end=0.1, dt=1e-5, elements=5)
    result = beamstops.run(scene)
    steps = [0, 1, 2, 5000, 9000, 10000]
    states = common.states(scene, [n * scene.dt for n in steps])
    tip = 2 * scene.elements - 2
    np.testing.assert_allclose(states.u[tip], result.tip_u[steps], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(states.v[tip], result.tip_v[steps], rtol=1e-12, atol=1e-12)


def test_states_in_blocks_equal_one_call() -> None:
    """In the main thread the engine advances the states in blocks, looking for a stop signal
    after each (Ctrl-C); in another thread in one call: the same bits."""
    import threading

    scene = Scene(t_end=0.05, dt=1e-6, elements=5)
    times = [0.0, 1e-6, 0.02, 0.05]
    blocks = common.states(scene, times)
    found: list[common.States] = []
    worker = threading.Thread(target=lambda: found.append(common.states(scene, times)))
    worker.start()
    worker.join()
    np.testing.assert_array_equal(blocks.u.view(np.uint64), found[0].u.view(np.uint64))
    np.testing.assert_array_equal(blocks.v.view(np.uint64), found[0].v.view(np.uint64))


def test_prolongation_is_exact_in_the_energy_norm() -> None:
    coarse, fine = common.states(Scene(elements=3, t_end=0.001, dt=1e-4), [0.0]), \
        common.states(Scene(elements=12, t_end=0.001, dt=1e-4), [0.0])
    x = np.random.default_rng(1).normal(size=6)
    y = np.random.default_rng(2).normal(size=6)
    a = common.energy_norm(x, y, coarse.mass, coarse.stiffness)
    b = common.energy_norm(common.prolong(x, 3, 12, 1.501), common.prolong(y, 3, 12, 1.501), fine.mass,
                           fine.stiffness)
    assert b == pytest.approx(a, rel=1e-10)


def test_observed_orders() -> None:
    orders = common.observed_orders([1.0, 0.5, 0.25], [4.0, 1.0, 0.25])
    assert math.isnan(orders[0]) and orders[1:] == pytest.approx([2.0, 2.0])
    assert math.isnan(common.observed_orders([1.0, 0.5], [1.0, 0.0])[1])


def test_grid_must_divide() -> None:
    with pytest.raises(ValueError, match="does not divide"):
        common.every(4e-5, 3e-5)

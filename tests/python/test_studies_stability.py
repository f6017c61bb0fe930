"""Stability map (issue 6): classification of small cases against the known limits."""

from __future__ import annotations

import beamstops
from beamstops import Scene
from beamstops.studies import stability_map

BASE = Scene(elements=8, t_end=0.05)


def _verdict(scene: Scene) -> str:
    scale = stability_map.energy_scale(scene)
    return stability_map._run_point(scene, scale, 10.0)[0]


def test_explicit_scheme_around_its_linear_limit() -> None:
    scene = BASE.replace(beta=0.0)
    limit = beamstops.stability(scene).dt_limit_newmark
    assert beamstops.stability(scene.replace(dt=1.5 * limit)).refusal is not None
    assert _verdict(scene.replace(dt=0.5 * limit)) == "stable"
    assert _verdict(scene.replace(dt=1.5 * limit)) == "unstable"


def test_projected_scheme_beyond_the_paper_condition() -> None:
    scene = BASE.replace(beta=0.25)
    limit = beamstops.stability(scene).dt_limit_paper
    assert _verdict(scene.replace(dt=10 * limit)) == "stable"


def test_map_and_answer() -> None:
    table = stability_map.beta_map(BASE, (0.0, 0.25), (1e-5, 2e-4), quiet=True)
    verdicts = {(row[0], row[2]): row[3] for row in table.rows}
    assert verdicts == {(0.0, 1e-5): "stable", (0.0, 2e-4): "unstable", (0.25, 1e-5): "stable",
                        (0.25, 2e-4): "stable"}
    text = stability_map.answer(table)
    assert "1 runs, 0 unstable" in text and "beyond the linear Newmark limit: 1 runs, 1 unstable" in text


def test_a_large_starting_energy_is_no_growth() -> None:
    # β ≥ 1/4 is unconditionally stable: at a coarse Δt on a fine mesh the discrete energy starts high
    # (½ β Δt² v0ᵀ S v0 of the start v0 = −2h), stays there, and is no instability
    scene = Scene(elements=54, t_end=0.2, beta=0.25, dt=1e-3)
    result = beamstops.run(scene.replace(allow_unstable=True, record_every=1))
    scale = stability_map.energy_scale(scene)
    assert abs(result.energy[0]) > 10 * scale  # the start alone is above the threshold of the scale
    assert abs(result.energy).max() <= 1.1 * abs(result.energy[0])  # and the run does not grow beyond it
    verdict, growth = stability_map.classify(result, scale)
    assert verdict == "stable" and growth < 2
    # a run that grows from its start is still caught
    explicit = BASE.replace(beta=0.0)
    limit = beamstops.stability(explicit).dt_limit_newmark
    assert _verdict(explicit.replace(dt=1.2 * limit)) == "unstable"

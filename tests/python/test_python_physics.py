"""Damping, restitution and mass redistribution (issue 12) through the one reader and the
program: keys, canonical text, the energy ledger of the records, and bad inputs."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

import beamstops
from beamstops import Scene


SHORT = Scene(t_end=0.3, dt=1e-5, beta=0.25)


def test_keys_read_back_exactly_and_reach_the_output() -> None:
    scene = SHORT.replace(ratio=0.02, restitution=0.5)
    assert scene.ratio == (0.02, 0.02) and scene.damping_modes == (1, 2) and scene.restitution == 0.5
    assert Scene.from_text(scene.to_text()) == scene
    assert "&damping\n  ratio = 0.02, 0.02\n  modes = 1, 2\n/" in scene.to_text()
    coefficients = SHORT.replace(mass_coefficient=0.5, stiffness_coefficient=1e-5)
    assert "mass_coefficient = 0.5" in coefficients.to_text() and coefficients.ratio == ()
    redistributed = SHORT.replace(mass="redistributed")
    assert Scene.from_text(redistributed.to_text()).mass == "redistributed"


def test_ratio_form_gives_the_requested_damping_at_both_modes() -> None:
    # zeta(omega) = a/(2 omega) + b omega/2 with the engine's a and b, at the FE frequencies of modes 1 and 3
    result = beamstops.run(SHORT.replace(law="none", ratio=(0.01, 0.03), damping_modes=(1, 3), t_end=0.01))
    a, b = result.attrs["damping_a"], result.attrs["damping_b"]
    omegas = [26.2458, 460.5477]  # SPEC §3, the cantilever's (J = 19 agrees to 2e-5)
    zetas = [a / (2 * w) + b * w / 2 for w in omegas]
    assert zetas == pytest.approx([0.01, 0.03], rel=1e-4)


@pytest.mark.parametrize("changes", [
    dict(law="none", ratio=0.02),
    dict(ratio=0.02),
    dict(restitution=0.7),
    dict(mass="redistributed"),
    dict(mass_coefficient=2.0, restitution=1.0),
])
def test_energy_ledger_closes_with_every_loss_apart(changes: dict) -> None:
    result = beamstops.run(SHORT.replace(**changes))
    e, w, d, c = result.energy, result.work, result.dissipated, result.damped
    defect = (e - e[0]) - (w - d - c)
    scale = max(np.abs(e).max(), np.abs(w).max())
    assert np.abs(defect).max() < 1e-9 * scale, np.abs(defect).max() / scale
    assert np.all(np.diff(c) >= -1e-15 * scale)  # the damping only takes energy
    assert result.attrs["damped"] == pytest.approx(c[-1], rel=1e-12, abs=1e-15)
    assert abs(result.attrs["energy_residual"]) < 1e-9 * scale
    if "ratio" in changes or "mass_coefficient" in changes:
        assert c[-1] > 0
    else:
        assert np.all(c == 0)


def test_damping_takes_energy_that_the_undamped_beam_keeps() -> None:
    free = beamstops.run(SHORT.replace(law="none", t_end=1.0))
    damped = beamstops.run(SHORT.replace(law="none", t_end=1.0, ratio=0.05))
    assert damped.damped[-1] > 0 and np.abs(damped.tip_u).max() < np.abs(free.tip_u).max()


def test_the_papers_stops_only_take_energy_and_elastic_ones_converge_to_taking_none() -> None:
    # SPEC 6: with the paper's projection the stops' energy D^n >= 0 at every step; with e = 1
    # (Paoli-Schatzman) the impact law conserves energy only as dt -> 0, so what the stops book
    # over the same scene shrinks with dt (the README's "The energy ledger")
    paper = Scene(t_end=0.5, dt=1e-5, beta=0.5)
    projected = beamstops.run(paper)
    d = projected.dissipated
    assert d[-1] > 0 and np.diff(d).min() >= -1e-14 * d[-1]
    elastic = [abs(beamstops.run(paper.replace(dt=dt, restitution=1.0)).dissipated[-1]) for dt in (1e-4, 1e-5)]
    assert elastic[1] < 0.5 * elastic[0] and elastic[1] < d[-1], (elastic, d[-1])


def test_restitution_violation_is_reported_and_shrinks_with_dt() -> None:
    violations = [beamstops.run(Scene(t_end=0.2, dt=dt, beta=0.25, restitution=1.0)).attrs["max_violation"]
                  for dt in (2e-5, 5e-6)]
    assert violations[0] > 0 and violations[1] < violations[0]
    assert beamstops.run(Scene(t_end=0.2, dt=5e-6, beta=0.25)).attrs["max_violation"] == 0


BAD = [
    ("&stops restitution = 1.5 /", "&stops restitution = 1.5 is out of range; allowed: 0 <= restitution <= 1"),
    ("&stops restitution = -0.1 /", "&stops restitution = -0.1 is out of range"),
    ("&damping ratio = 0.02, mass_coefficient = 1 /", "&damping gives ratio together with mass_coefficient"),
    ("&damping mass_coefficient = -1 /", "&damping mass_coefficient = -1 is out of range; allowed: 0 <= mass_coefficient <= "),
    ("&damping stiffness_coefficient = -1e-4 /", "&damping stiffness_coefficient = -0.0001 is out of range"),
    ("&stops mass = 'redistributed' /\n&time beta = 0, dt = 1e-6 /", "&stops mass = 'redistributed' needs beta > 0"),
    ("&stops law = 'compliance', stiffness = 1e7, restitution = 0.5 /",
     "&stops restitution = 0.5 is out of range for law = 'compliance'"),
    ("&stops mass = 'lumped' /", "&stops mass = 'lumped' is out of range; allowed: 'consistent' or 'redistributed'"),
    ("&damping ratio = 1.2 /", "&damping ratio = 1.2 is out of range; allowed: 0 <= ratio < 1"),
    ("&damping ratio = 0.1, modes = 2, 2 /", "&damping modes = 2, 2 is out of range"),
]


@pytest.mark.parametrize(("text", "needle"), BAD, ids=[b[0][:40] for b in BAD])
def test_bad_physics_inputs_end_in_one_message(text: str, needle: str, tmp_path: Path, program: str) -> None:
    path = tmp_path / "bad.nml"
    path.write_text(text + "\n")
    done = subprocess.run([program, "run", str(path)], capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 1 and done.stderr.count("\n") == 1, done.stderr
    assert f"{path}: {needle}" in done.stderr
    with pytest.raises(ValueError) as caught:
        Scene.from_namelist(path)
    assert needle in str(caught.value)
    assert not (tmp_path / "bad.h5").exists()


def test_a_model_refusal_names_the_file(tmp_path, program) -> None:  # type: ignore[no-untyped-def]
    """The model's refusals (here the ratio pair that gives b < 0) name the file, as the
    reader's do; they named the group and key only."""
    import subprocess

    scene = tmp_path / "pair.nml"
    scene.write_text("&time dt = 1e-5, t_end = 0.01 /\n&damping ratio = 0.02, 0 /\n")
    done = subprocess.run([program, "run", str(scene), "-o", str(tmp_path / "out.h5")], capture_output=True,
                          text=True)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 1 and len(lines) == 1
    assert lines[0].startswith(f"beamstops: error: {scene}: &damping ratio = 0.02, 0 "), lines
    assert not (tmp_path / "out.h5").exists()


@pytest.mark.parametrize("key", ["mass_coefficient", "stiffness_coefficient"])
def test_the_ledger_closes_at_the_damping_bounds(key: str) -> None:
    """The README's 'Why these bounds': at a coefficient's upper bound (read from the engine's own
    refusal of a larger one) the paper's scene still balances its energy ledger to a small part of
    the damping term; far beyond it (a = 1e14 1/s) it missed by the whole term."""
    scene = Scene(t_end=0.5, dt=1e-4)
    with pytest.raises(ValueError, match=rf"allowed: 0 <= {key} <= ") as refused:
        beamstops.run(scene.replace(**{key: 1e300}))
    bound = float(str(refused.value).split(f"<= {key} <= ")[1].split()[0])
    result = beamstops.run(scene.replace(**{key: bound}))
    e, w, d, c = result.energy, result.work, result.dissipated, result.damped
    assert c[-1] > 0.5 * (w[-1] - d[-1])  # the damping takes most of the support's work
    assert np.abs((e - e[0]) - (w - d - c)).max() < 1e-6 * c[-1]
    assert abs(result.attrs["energy_residual"]) < 1e-6 * c[-1]


@pytest.mark.parametrize(("stops", "kappa"), [("", "kappa_h"), ("&stops law = 'compliance', stiffness_per_mass = 1e12 /\n",
                                                                  "kappa")])
def test_the_explicit_limit_names_the_eigenvalue_it_takes(stops: str, kappa: str, tmp_path: Path,
                                                            program: str) -> None:
    """Under normal compliance the limit takes the largest eigenvalue with the stops' spring, which
    the message called kappa_h (the paper's bound of S alone, 7000 times smaller here)."""
    path = tmp_path / "fast.nml"
    path.write_text(stops + "&time beta = 0, dt = 1e-4 /\n")
    done = subprocess.run([program, "run", str(path)], capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 1 and done.stderr.count("\n") == 1, done.stderr
    assert f"the linear stability limit 2/sqrt((1-4 beta) {kappa}) for beta = 0 ({kappa} = " in done.stderr
    limits = beamstops.stability(Scene.from_namelist(path))
    value = float(done.stderr.split(f"({kappa} = ")[1].split()[0])
    assert value == pytest.approx(4 / limits.dt_limit_newmark ** 2, rel=1e-5)  # the limit's own eigenvalue

"""Relations the engine must satisfy whatever the right numbers are (found by a metamorphic audit):
a lockstep group of the program gives each member the bits of the same scene run alone also where
the Newmark products by beta round (beta other than 0, 1/4, 1/2), and a scene's histogram range
is the one asked for, through Python as through a namelist file."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

import beamstops
from beamstops import Scene

SERIES = ("t", "tip_u", "tip_v", "reaction", "energy", "work", "dissipated", "damped")


def same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


@pytest.mark.parametrize("law", ["signorini", "compliance"])
def test_lockstep_members_equal_their_runs_alone_at_beta_0_3(tmp_path: Path, program: str, law: str) -> None:
    """Four scenes sharing A (beta = 0.3, members differing in omega and amplitude) run in lockstep by
    `beamstops run A B C D`; each member's records and summary equal the scene run alone bit for
    bit. Before the Newmark sums were formed out of line (src/beamstops/newmark.c) gfortran fused
    them differently in the two loops: the work parted at the 45th step, the tip later."""
    spring = {"stiffness_per_mass": 1e8} if law == "compliance" else {}
    base = Scene(law=law, **spring, elements=5, beta=0.3, dt=1e-4, t_end=0.2, lower=-0.02, upper=0.02)
    scenes = [base, base.replace(omega=30.0), base.replace(amplitude=-0.1), base.replace(omega=60.0, amplitude=0.05)]
    paths = []
    for k, scene in enumerate(scenes):
        path = tmp_path / f"m{k}.nml"
        scene.replace(file=str(tmp_path / f"m{k}.h5")).to_namelist(path)
        paths.append(str(path))
    done = subprocess.run([program, "run", *paths], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    for k, scene in enumerate(scenes):
        member = beamstops.load(tmp_path / f"m{k}.h5")
        alone = beamstops.run(scene)
        assert alone.attrs["impacts"] > 0
        for name in SERIES:
            assert same_bits(getattr(member, name), getattr(alone, name)), (k, name)
        for key in ("impacts", "contact_phases", "max_violation", "work", "dissipated", "energy_residual"):
            assert member.attrs[key] == alone.attrs[key], (k, key)


def test_a_histogram_range_equal_to_the_fields_old_default_is_kept(tmp_path: Path) -> None:
    """`histogram_lower = -0.1, histogram_upper = 0.1` with stops at +-0.05: the range asked for, from
    a file, from Scene(...) and after replace() of another key (Python had dropped a value equal to
    its field's old default, 0.1, and the engine then took the stops' +-0.05)."""
    path = tmp_path / "scene.nml"
    path.write_text("&stops lower = -0.05, upper = 0.05 /\n&statistics histogram_lower = -0.1, histogram_upper = 0.1 /\n")
    wanted = (-0.1, 0.1)
    read = Scene.from_namelist(path)
    given = Scene(lower=-0.05, upper=0.05, histogram_lower=-0.1, histogram_upper=0.1)
    for scene in (read, given, read.replace(t_end=1.0), given.replace(dt=1e-5), Scene.from_text(read.to_text())):
        assert (scene.histogram_lower, scene.histogram_upper) == wanted
    # a range left to its default follows the stops, also when they change
    assert (Scene(lower=-0.05, upper=0.05).histogram_lower, Scene().replace(upper=0.02).histogram_upper) == (-0.05, 0.02)
    assert Scene(lower=-0.05, upper=0.05).replace(lower=-0.02).histogram_lower == -0.02
    # a range set apart from the stops is carried over when they change
    assert read.replace(lower=-0.02).histogram_lower == -0.1
    short = read.replace(t_end=0.05, dt=1e-4)
    edges = beamstops.run(short).statistics["tip_histogram_edges"].value
    assert (edges[0], edges[-1]) == wanted

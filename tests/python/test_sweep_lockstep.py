"""Several scenes in one `beamstops run`, and sweeps in lockstep batches: every output is the
one its scene gives alone, bit for bit; bad inputs are refused before anything runs; a batch
that fails leaves its points to run alone."""

from __future__ import annotations

import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

import h5py
import numpy as np
import pytest

from beamstops.sweep import load_spec, read_summary, run_sweep
from beamstops.sweep.runner import batches, prepare_folder

#: Root attributes that differ from one run of the same scene to the next.
TIMING_ATTRS = ("cpu_seconds",)


def contents(path: Path) -> tuple[dict[str, bytes], dict[str, bytes]]:
    """Every dataset (its bytes, shape and type) and every root attribute but the timings."""
    datasets: dict[str, bytes] = {}
    with h5py.File(path, "r") as f:
        def visit(name: str, item: Any) -> None:
            if isinstance(item, h5py.Dataset):
                value = np.asarray(item[()])
                datasets[name] = repr((value.shape, value.dtype.str)).encode() + value.tobytes()
                for key, attr in item.attrs.items():
                    datasets[f"{name}@{key}"] = np.asarray(attr).tobytes()

        f.visititems(visit)
        attrs = {k: np.asarray(v).tobytes() for k, v in f.attrs.items() if k not in TIMING_ATTRS}
    return datasets, attrs


SCENES = {
    # a and b share A (J, dt, beta, steps) and differ in the forcing and the stops; c has
    # another dt; d is an &ensemble of 3 members sharing a's A.
    "a": "&mesh elements = 10 /\n&time dt = 5e-5, t_end = 0.4 /\n&support omega = 12 /\n",
    "b": "&mesh elements = 10 /\n&time dt = 5e-5, t_end = 0.4 /\n&support omega = 31, amplitude = 0.25 /\n"
         "&stops lower = -0.06 /\n&output record_every = 3, snapshot_every = 50 /\n",
    "c": "&mesh elements = 10 /\n&time dt = 4e-5, t_end = 0.4 /\n&support omega = 20 /\n",
    "d": "&mesh elements = 10 /\n&time dt = 5e-5, t_end = 0.4 /\n&support omega = 17 /\n"
         "&ensemble members = 3, perturbation = 1e-5 /\n",
    "e": "&mesh elements = 10 /\n&time dt = 5e-5, t_end = 0.4, load_rule = 'paper' /\n&support omega = 25 /\n"
         "&stops upper = 0.08, restitution = 0.5 /\n",
}


def write_scenes(folder: Path, names: str) -> list[str]:
    folder.mkdir(parents=True, exist_ok=True)
    for name in names:
        (folder / f"{name}.nml").write_text(SCENES[name])
    return [f"{name}.nml" for name in names]


def test_several_scenes_write_the_files_each_writes_alone(tmp_path: Path, program: str) -> None:
    files = write_scenes(tmp_path / "together", "abcde")
    done = subprocess.run([program, "run", *files], cwd=tmp_path / "together", capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    # the engine's partition: a, b, d, e share A (one lockstep group), c runs alone
    assert "5 scenes: 4 in 1 lockstep group(s), 1 alone" in done.stderr
    # one summary line per scene, naming its output
    assert [line.split(":")[0] for line in done.stdout.splitlines() if "steps," in line] == \
        ["a.h5", "b.h5", "d.h5", "e.h5", "c.h5"]
    # fewer than four that share A gain nothing from lockstep: they run one after the other
    few = subprocess.run([program, "run", *files[:3]], cwd=tmp_path / "together", capture_output=True, text=True)
    assert few.returncode == 0, few.stderr
    assert "3 scenes: 0 in 0 lockstep group(s), 3 alone" in few.stderr
    alone = tmp_path / "alone"
    for name in "abcde":
        write_scenes(alone, name)
        single = subprocess.run([program, "run", f"{name}.nml"], cwd=alone, capture_output=True, text=True)
        assert single.returncode == 0, single.stderr
        together, by_itself = contents(tmp_path / "together" / f"{name}.h5"), contents(alone / f"{name}.h5")
        assert together[0].keys() == by_itself[0].keys() and together[1].keys() == by_itself[1].keys()
        for what in (0, 1):
            differ = [k for k in by_itself[what] if together[what][k] != by_itself[what][k]]
            assert not differ, f"{name}: {differ} differ from the scene run alone"
        assert not (tmp_path / "together" / f"{name}.h5.partial").exists()


def test_bad_command_lines_and_a_bad_file_among_several_run_nothing(tmp_path: Path, program: str) -> None:
    files = write_scenes(tmp_path, "ab")
    done = subprocess.run([program, "run", *files, "-o", "out.h5"], cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 2 and "'-o' names the output of one scene" in done.stderr
    (tmp_path / "bad.nml").write_text("&time dt = -1 /\n")
    done = subprocess.run([program, "run", files[0], "bad.nml", files[1]], cwd=tmp_path, capture_output=True,
                          text=True)
    assert done.returncode == 1
    assert "bad.nml" in done.stderr and "dt" in done.stderr and "none of the 3 scenes was run" in done.stderr
    assert not list(tmp_path.glob("*.h5*"))
    # two scenes that would write one file
    (tmp_path / "twin.nml").write_text(SCENES["c"] + "&output file = 'a.h5' /\n")
    done = subprocess.run([program, "run", files[0], "twin.nml"], cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 4 and "a.h5: is the output of both a.nml and twin.nml" in done.stderr
    assert not list(tmp_path.glob("*.h5*"))
    done = subprocess.run([program, "info", *files], cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 2 and "unexpected argument 'b.nml'" in done.stderr


def test_scenes_whose_files_meet_under_other_spellings_run_nothing(tmp_path: Path, program: str) -> None:
    """One output spelt two ways (`b.h5`, `./b.h5`, `sub/../b.h5`), or the output of one scene
    at the partial output of another (`a.h5.partial`): refused before anything runs. They ran,
    and the second run failed to create its partial file, or overwrote the first one's output."""
    files = write_scenes(tmp_path, "ab")
    (tmp_path / "sub").mkdir()
    for spelling in ("./b.h5", "sub/../b.h5"):
        (tmp_path / "twin.nml").write_text(SCENES["a"] + f"&output file = '{spelling}' /\n")
        done = subprocess.run([program, "run", *files, "twin.nml"], cwd=tmp_path, capture_output=True, text=True)
        assert done.returncode == 4, done.stderr
        assert f"{spelling}: is the output of both b.nml and twin.nml" in done.stderr
        assert "none of the 3 scenes was run" in done.stderr
        assert not list(tmp_path.glob("*.h5*"))
    (tmp_path / "twin.nml").write_text(SCENES["c"] + "&output file = 'a.h5.partial' /\n")
    for order in (["twin.nml", files[0]], [files[0], "twin.nml"]):
        done = subprocess.run([program, "run", *order], cwd=tmp_path, capture_output=True, text=True)
        assert done.returncode == 4, done.stderr
        assert "a.h5.partial: is the" in done.stderr and "partial output of a.nml" in done.stderr
        assert not list(tmp_path.glob("*.h5*"))


SWEEP = """
[sweep]
lockstep = {lockstep}
[scene]
elements = 6
dt = 1e-4
[axes]
omega = {{ start = 6, stop = 30, num = 7 }}
amplitude = [0.15, 0.25]
[periods]
t_end = 5
shared_grid = true
[reductions.strobe]
kind = "strobe"
transient_periods = 1
[reductions.u_max]
kind = "max"
after_periods = 1
"""


def test_a_sweep_in_lockstep_batches_gives_the_results_of_one_point_at_a_time(
        tmp_path: Path, write_spec: Callable[..., Path], program: str,
        without_timing: Callable[[list[dict[str, Any]]], list[dict[str, Any]]]) -> None:
    batched = load_spec(write_spec(SWEEP.format(lockstep=8), "batched.toml"))
    alone = load_spec(write_spec(SWEEP.format(lockstep=1), "alone.toml"))
    assert batched.hash == alone.hash  # the same points: lockstep is how they run, not what
    # shared_grid: one dt and one t_end (5 periods of the lowest omega) for every point
    assert {p.scene.dt for p in batched.points} == {1e-4}
    assert {p.scene.t_end for p in batched.points} == {5 * 2 * np.pi / 6}
    assert [len(b) for b in batches([{"index": i} for i in range(14)], 8, 2)] == [7, 7]
    log = tmp_path / "log.txt"
    with log.open("w") as stream:
        one = run_sweep(batched, tmp_path / "batched", jobs=2, stream=stream, program=program)
    text = log.read_text()
    assert "in 2 batches of up to 7 (lockstep = 8)" in text and "14 ran in lockstep" in text
    other = run_sweep(alone, tmp_path / "alone", jobs=2, stream=None, program=program)
    assert one.complete == other.complete == 14
    assert without_timing(read_summary(tmp_path / "batched")) == without_timing(read_summary(tmp_path / "alone"))
    csv_a = [line.split(",") for line in (tmp_path / "batched" / "summary.csv").read_text().splitlines()]
    csv_b = [line.split(",") for line in (tmp_path / "alone" / "summary.csv").read_text().splitlines()]
    timing = [csv_a[0].index(name) for name in ("cpu_seconds", "wall_seconds")]
    assert [[c for i, c in enumerate(r) if i not in timing] for r in csv_a] == \
        [[c for i, c in enumerate(r) if i not in timing] for r in csv_b]
    for point in batched.points:
        a = contents(tmp_path / "batched" / "points" / f"{point.name}.h5")
        b = contents(tmp_path / "alone" / "points" / f"{point.name}.h5")
        assert a == b, f"point {point.index} differs"


DIVERGING = """
[sweep]
lockstep = {lockstep}
[scene]
elements = 6
dt = 2e-4
beta = 0.0
allow_unstable = true
t_end = 0.2
[axes]
amplitude = [0.0, 0.1, 0.0, 0.2]
[reductions.u]
kind = "final"
"""


def test_a_diverged_point_has_one_row_in_lockstep_or_alone(
        tmp_path: Path, write_spec: Callable[..., Path], program: str,
        without_timing: Callable[[list[dict[str, Any]]], list[dict[str, Any]]]) -> None:
    # explicit steps beyond their limit: the forced points diverge, the unforced ones stay at rest; in a
    # lockstep group of 4 and one at a time, each diverged row carries the engine's message (the file's
    # `message`), not a line of stderr naming the folder it ran in
    rows = {}
    for lockstep in (8, 1):
        spec = load_spec(write_spec(DIVERGING.format(lockstep=lockstep), f"l{lockstep}.toml"))
        outcome = run_sweep(spec, tmp_path / f"l{lockstep}", jobs=1, stream=None, program=program)
        assert (outcome.complete, outcome.diverged, outcome.lockstep) == (2, 2, 4 if lockstep == 8 else 0)
        rows[lockstep] = read_summary(tmp_path / f"l{lockstep}")
        for row in rows[lockstep]:
            with h5py.File(tmp_path / f"l{lockstep}" / row["file"], "r") as f:
                message = f.attrs["message"].decode() if row["status"] == "diverged" else ""
            assert row["message"] == message
    assert [r["status"] for r in rows[1]] == ["complete", "diverged", "complete", "diverged"]
    assert without_timing(rows[8]) == without_timing(rows[1])


def test_a_batch_refused_as_a_whole_runs_its_points_alone(tmp_path: Path, write_spec: Callable[..., Path],
                                                          program: str) -> None:
    # a folder is where point 1 would write its partial output: the program refuses the batch's
    # `beamstops run` as a whole (it checks every output first); the others then run alone.
    spec = load_spec(write_spec("""
[sweep]
lockstep = 4
[scene]
elements = 6
dt = 2e-4
t_end = 0.1
[axes]
beta = [0.5, 0.3, 0.25, 0.5]
"""))
    prepare_folder(spec, tmp_path / "out", program)
    (tmp_path / "out" / "points" / "00001.h5.partial").mkdir()
    outcome = run_sweep(spec, tmp_path / "out", jobs=1, stream=None, program=program)
    rows = read_summary(tmp_path / "out")
    assert [r["status"] for r in rows] == ["complete", "failed", "complete", "complete"]
    assert "00001.h5.partial" in rows[1]["message"] and "a folder" in rows[1]["message"]
    assert (outcome.complete, outcome.failed) == (3, 1)


@pytest.mark.parametrize("value", [0, 2000, 1.5, "8"])
def test_lockstep_key_is_checked(write_spec: Callable[..., Path], value: Any) -> None:
    text = SWEEP.format(lockstep=repr(value) if not isinstance(value, str) else f'"{value}"')
    with pytest.raises(ValueError, match="lockstep"):
        load_spec(write_spec(text))


def test_shared_grid_and_records_per_period_are_exclusive(write_spec: Callable[..., Path]) -> None:
    with pytest.raises(ValueError, match="shared_grid"):
        load_spec(write_spec(SWEEP.format(lockstep=8).replace("shared_grid = true",
                                                              "shared_grid = true\nrecords_per_period = 8")))


def test_a_batch_over_its_time_limit_leaves_its_points_to_run_alone(tmp_path: Path, write_spec: Callable[..., Path],
                                                                    program: str) -> None:
    # one batch of three points on one worker; the long point holds the batch beyond its limit
    # (3 x 0.5 s); then every point without a finished output runs alone with its own limit
    spec = load_spec(write_spec("""
[sweep]
timeout = 0.5
lockstep = 4
[scene]
elements = 4
dt = 1e-6
record_every = 100000
[axes]
t_end = [0.01, 0.02, 1000.0]
"""))
    outcome = run_sweep(spec, tmp_path / "out", jobs=1, stream=None, program=program)
    rows = read_summary(tmp_path / "out")
    assert [r["status"] for r in rows] == ["complete", "complete", "failed"]
    assert rows[2]["message"].startswith("timed out after 0.5 s")
    assert (outcome.complete, outcome.failed) == (2, 1)

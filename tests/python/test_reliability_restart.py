"""Checkpoints: a run killed with SIGKILL at random moments and resumed with --restart
gives the uninterrupted run's output bit for bit; an interrupted run leaves its records in
OUT.h5.partial (which says so) and never touches OUT.h5."""

from __future__ import annotations

import os
import random
import shutil
import signal
import subprocess
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

import beamstops

PROGRAM = os.environ.get("BEAMSTOPS_PROGRAM") or shutil.which("beamstops")
pytestmark = pytest.mark.skipif(PROGRAM is None, reason="the beamstops program is not on PATH")

SCENE = """&time dt=1e-6, t_end={t_end} /
&output file='{file}', record_every=1, snapshot_every=997, checkpoint_every=40000 /
"""


def stat_or_none(path: Path) -> os.stat_result | None:
    """The file's stat, or None when it does not exist (any more: a run that ends renames its
    partial file and removes its checkpoint between two looks)."""
    try:
        return path.stat()
    except FileNotFoundError:
        return None


def write_scene(folder: Path, name: str, t_end: float = 1.0) -> Path:
    path = folder / f"{name}.nml"
    path.write_text(SCENE.format(t_end=t_end, file=f"{name}.h5"))
    return path


def run(*args: str | Path, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([PROGRAM, *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=300)


def datasets(path: Path) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    with h5py.File(path) as f:
        f.visititems(lambda name, obj: out.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
        out.update({f"@{k}": v for k, v in f.attrs.items() if k != "cpu_seconds"})
    return out


def assert_identical(a: Path, b: Path) -> None:
    x, y = datasets(a), datasets(b)
    assert sorted(x) == sorted(y)
    for name in x:
        if name.startswith("@"):
            assert np.array_equal(x[name], y[name]), name
        else:
            assert x[name].shape == y[name].shape, name
            assert np.array_equal(x[name].view(np.uint64), y[name].view(np.uint64)), name


def kill_after_first_checkpoint(scene: Path, checkpoint: Path) -> None:
    """Run `scene` and kill it (SIGKILL) as soon as its first checkpoint exists."""
    process = subprocess.Popen([PROGRAM, "run", str(scene)], cwd=scene.parent, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    while process.poll() is None and not checkpoint.exists():
        time.sleep(0.001)
    process.send_signal(signal.SIGKILL)
    process.wait()
    if not checkpoint.exists():
        pytest.skip("the run ended before its first checkpoint")


def test_killed_runs_resume_bit_for_bit(tmp_path: Path) -> None:
    reference = write_scene(tmp_path, "reference")
    assert run("run", reference, cwd=tmp_path).returncode == 0
    scene = write_scene(tmp_path, "killed")
    seed = int(time.time())
    rng = random.Random(seed)
    kills = 0
    args: list[str | Path] = ["run", scene]
    for _ in range(6):
        process = subprocess.Popen([PROGRAM, *map(str, args)], cwd=tmp_path, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
        time.sleep(rng.uniform(0.02, 0.3))
        if process.poll() is None:
            process.send_signal(signal.SIGKILL)
            kills += 1
        process.wait()
        args = ["run", scene, "--restart"]
    done = run(*args, cwd=tmp_path)
    assert done.returncode == 0, f"seed {seed}: {done.stderr}"
    assert kills > 0, "the run was never killed: make it longer"
    assert not (tmp_path / "killed.h5.checkpoint").exists()
    assert not (tmp_path / "killed.h5.partial").exists()
    assert_identical(tmp_path / "killed.h5", tmp_path / "reference.h5")


REDUCED = """&mesh modes=8 /
&damping ratio=0.02 /
&stops restitution=0.5 /
&statistics enabled=.true., transient=0.2 /
"""


def test_killed_reduced_runs_resume_bit_for_bit(tmp_path: Path) -> None:
    """A reduced run (modes = 8, damped, with restitution and statistics) killed after each of
    its first checkpoints and resumed gives the uninterrupted run's output bit for bit."""
    reference = write_scene(tmp_path, "reference")
    reference.write_text(reference.read_text() + REDUCED)
    assert run("run", reference, cwd=tmp_path).returncode == 0
    scene = write_scene(tmp_path, "killed")
    scene.write_text(scene.read_text() + REDUCED)
    checkpoint = tmp_path / "killed.h5.checkpoint"
    args: list[str | Path] = ["run", scene]
    kills = 0
    for _ in range(3):
        process = subprocess.Popen([PROGRAM, *map(str, args)], cwd=tmp_path, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
        before = stat_or_none(checkpoint)
        seen = before.st_mtime_ns if before else 0
        deadline = time.time() + 60
        while process.poll() is None and time.time() < deadline:
            now = stat_or_none(checkpoint)
            if now is not None and now.st_mtime_ns != seen:
                break
            time.sleep(0.005)
        if process.poll() is None:
            process.send_signal(signal.SIGKILL)
            kills += 1
        process.wait()
        args = ["run", scene, "--restart"]
    done = run(*args, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert kills > 0, "the run was never killed: make it longer"
    assert not checkpoint.exists() and not (tmp_path / "killed.h5.partial").exists()
    assert_identical(tmp_path / "killed.h5", tmp_path / "reference.h5")


def test_interrupted_file_says_so_and_keeps_its_records(tmp_path: Path) -> None:
    scene = write_scene(tmp_path, "cut", t_end=4.0)
    process = subprocess.Popen([PROGRAM, "run", str(scene)], cwd=tmp_path, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    checkpoint = tmp_path / "cut.h5.checkpoint"
    deadline = time.time() + 60
    while not checkpoint.exists() and time.time() < deadline:
        time.sleep(0.01)
    time.sleep(0.05)
    process.send_signal(signal.SIGKILL)
    process.wait()
    assert checkpoint.exists()
    assert not (tmp_path / "cut.h5").exists()
    with pytest.raises(beamstops.IncompleteRunError):
        beamstops.load(tmp_path / "cut.h5.partial")
    partial = beamstops.load(tmp_path / "cut.h5.partial", allow_incomplete=True)
    assert partial.status == "running"
    # every record up to the checkpoint is there, on the time grid
    assert partial.t.size >= 40000
    np.testing.assert_allclose(partial.t[:40001], np.arange(40001) * 1e-6, rtol=0, atol=1e-12)


def test_restart_refuses_a_changed_scene(tmp_path: Path) -> None:
    scene = write_scene(tmp_path, "changed", t_end=4.0)
    process = subprocess.Popen([PROGRAM, "run", str(scene)], cwd=tmp_path, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    deadline = time.time() + 60
    while not (tmp_path / "changed.h5.checkpoint").exists() and time.time() < deadline:
        time.sleep(0.01)
    process.send_signal(signal.SIGKILL)
    process.wait()
    scene.write_text(scene.read_text().replace("dt=1e-6", "dt=2e-6"))
    done = run("run", scene, "--restart", cwd=tmp_path)
    assert done.returncode == 1
    assert "another scene" in done.stderr and done.stderr.count("\n") == 1
    # the keys changed are named, with both values
    assert "&time dt = 1e-06 in the checkpoint, 2e-06 here" in done.stderr, done.stderr


def test_restart_without_checkpoint_starts_over(tmp_path: Path) -> None:
    scene = write_scene(tmp_path, "fresh", t_end=0.05)
    done = run("run", scene, "--restart", cwd=tmp_path)
    assert done.returncode == 0
    assert "starting from t = 0" in done.stderr
    assert beamstops.load(tmp_path / "fresh.h5").attrs["steps"] == 50000


def test_killed_rerun_leaves_the_complete_output_untouched(tmp_path: Path) -> None:
    """A complete output survives a re-run killed in the middle, bit for bit and file for file;
    --restart then finishes the re-run and replaces it."""
    scene = write_scene(tmp_path, "kept", t_end=0.3)
    assert run("run", scene, cwd=tmp_path).returncode == 0
    output = tmp_path / "kept.h5"
    before = output.read_bytes()
    inode = output.stat().st_ino
    scene.write_text(SCENE.format(t_end=1.0, file="kept.h5"))
    process = subprocess.Popen([PROGRAM, "run", str(scene)], cwd=tmp_path, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    checkpoint = tmp_path / "kept.h5.checkpoint"
    deadline = time.time() + 60
    while not checkpoint.exists() and time.time() < deadline:
        time.sleep(0.01)
    process.send_signal(signal.SIGKILL)
    assert process.wait() == -signal.SIGKILL, "the re-run ended before it was killed"
    assert checkpoint.exists() and (tmp_path / "kept.h5.partial").exists()
    assert output.read_bytes() == before and output.stat().st_ino == inode
    assert beamstops.load(output).attrs["steps"] == 300000
    done = run("run", scene, "--restart", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert beamstops.load(output).attrs["steps"] == 1000000
    assert not (tmp_path / "kept.h5.partial").exists() and not checkpoint.exists()


def test_restart_without_partial_output_starts_over(tmp_path: Path) -> None:
    scene = write_scene(tmp_path, "lost", t_end=4.0)
    process = subprocess.Popen([PROGRAM, "run", str(scene)], cwd=tmp_path, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    deadline = time.time() + 60
    while not (tmp_path / "lost.h5.checkpoint").exists() and time.time() < deadline:
        time.sleep(0.01)
    process.send_signal(signal.SIGKILL)
    process.wait()
    (tmp_path / "lost.h5.partial").unlink()
    scene.write_text(SCENE.format(t_end=0.05, file="lost.h5"))
    done = run("run", scene, "--restart", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "lost.h5.partial" in done.stderr and "starting from t = 0" in done.stderr
    assert beamstops.load(tmp_path / "lost.h5").attrs["steps"] == 50000


def test_a_resume_after_a_failed_attempt_keeps_no_stale_message(tmp_path: Path) -> None:
    # An attempt that failed after a checkpoint (here: its end written by hand, as `finish`
    # writes a failed run's) leaves status 'failed' and its message in OUT.h5.partial; the
    # resumed run that completes must be the uninterrupted run, without that message.
    reference = write_scene(tmp_path, "reference", t_end=0.2)
    assert run("run", reference, cwd=tmp_path).returncode == 0
    scene = write_scene(tmp_path, "killed", t_end=0.2)
    kill_after_first_checkpoint(scene, tmp_path / "killed.h5.checkpoint")
    with h5py.File(tmp_path / "killed.h5.partial", "r+") as f:
        f.attrs["status"] = "failed"
        f.attrs["message"] = "killed.h5: cannot write to killed.h5.partial"
    done = run("run", scene, "--restart", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert_identical(tmp_path / "killed.h5", tmp_path / "reference.h5")


def test_a_resume_after_an_attempt_killed_in_its_end(tmp_path: Path) -> None:
    # An attempt killed while it wrote its end (after its observations, before the rename)
    # leaves /impacts and /statistics in OUT.h5.partial beside the checkpoint; the resumed run
    # writes its own end and must be the uninterrupted run (found by the killed-runs test).
    stats = "&statistics enabled=.true., transient=0.05 /\n"
    reference = write_scene(tmp_path, "reference", t_end=0.2)
    reference.write_text(reference.read_text() + stats)
    assert run("run", reference, cwd=tmp_path).returncode == 0
    scene = write_scene(tmp_path, "killed", t_end=0.2)
    scene.write_text(scene.read_text() + stats)
    kill_after_first_checkpoint(scene, tmp_path / "killed.h5.checkpoint")
    with h5py.File(tmp_path / "reference.h5") as done, h5py.File(tmp_path / "killed.h5.partial", "r+") as f:
        assert "impacts" in done and "statistics" in done
        for group in ("impacts", "statistics"):
            done.copy(group, f)
        f.attrs["status"] = "complete"
    done = run("run", scene, "--restart", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert_identical(tmp_path / "killed.h5", tmp_path / "reference.h5")


def test_checkpoints_leave_the_records_unchanged(tmp_path: Path) -> None:
    # A block that ends at a checkpoint completes its last record with the sums of the forward
    # pass's record (energy_dots), not with other dot products: the run with checkpoints is the run without.
    plain = tmp_path / "plain.nml"
    plain.write_text(SCENE.format(t_end=0.2, file="plain.h5").replace(", checkpoint_every=40000", ""))
    assert run("run", plain, cwd=tmp_path).returncode == 0
    checked = write_scene(tmp_path, "checked", t_end=0.2)
    assert run("run", checked, cwd=tmp_path).returncode == 0
    x, y = datasets(tmp_path / "plain.h5"), datasets(tmp_path / "checked.h5")
    names = sorted(name for name in x if not name.startswith("@"))
    assert names == sorted(name for name in y if not name.startswith("@")) and "energy/E" in names
    for name in names:
        assert np.array_equal(x[name].view(np.uint64), y[name].view(np.uint64)), name


def test_an_unreadable_partial_output_is_refused_and_a_plain_run_starts_over(tmp_path: Path) -> None:
    # A partial file HDF5 cannot open (here: cut short by hand, as a kill during HDF5's own
    # flush might leave it): --restart says so in one line and how to go on, and does that.
    scene = write_scene(tmp_path, "cut", t_end=0.2)
    kill_after_first_checkpoint(scene, tmp_path / "cut.h5.checkpoint")
    partial = tmp_path / "cut.h5.partial"
    with partial.open("r+b") as f:
        f.truncate(2000)
    done = run("run", scene, "--restart", cwd=tmp_path)
    assert done.returncode == 4
    assert done.stderr.count("\n") == 1 and "cut.h5.partial" in done.stderr and "without --restart" in done.stderr
    again = run("run", scene, cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    assert beamstops.load(tmp_path / "cut.h5").attrs["steps"] == 200000


def test_a_partial_output_older_than_its_checkpoint_is_refused(tmp_path: Path) -> None:
    """A partial file with fewer records than its checkpoint counts (restored from a copy, or
    left by a power cut) is refused by --restart, untouched: it had been extended with zeros and
    called complete."""
    scene = write_scene(tmp_path, "old", t_end=4.0)
    partial, checkpoint = tmp_path / "old.h5.partial", tmp_path / "old.h5.checkpoint"
    kill_after_first_checkpoint(scene, checkpoint)
    early = tmp_path / "early.partial"
    shutil.copy2(partial, early)
    with h5py.File(early) as f:
        early_records = f["tip/t"].shape[0]
    # the resumed run moves on past its next checkpoint, which then counts more records
    first = checkpoint.stat().st_mtime_ns
    process = subprocess.Popen([PROGRAM, "run", str(scene), "--restart"], cwd=tmp_path, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    deadline = time.time() + 60
    while process.poll() is None and (stat_or_none(checkpoint) is None or checkpoint.stat().st_mtime_ns == first) \
            and time.time() < deadline:
        time.sleep(0.001)
    process.send_signal(signal.SIGKILL)
    process.wait()
    if not checkpoint.exists() or checkpoint.stat().st_mtime_ns == first:
        pytest.skip("the resumed run ended before its next checkpoint")
    shutil.copy2(early, partial)
    before = partial.read_bytes()
    done = run("run", scene, "--restart", cwd=tmp_path)
    assert done.returncode == 4 and done.stdout == ""
    assert done.stderr.count("\n") == 1, done.stderr
    assert f"holds {early_records} rows of /tip/t, fewer than the " in done.stderr
    assert "run without --restart to start over" in done.stderr
    assert partial.read_bytes() == before and not (tmp_path / "old.h5").exists()


@pytest.mark.parametrize("index, value, needle", [
    (0, 1e9, "its step 1e+09 is not a step of the run"),
    (0, -5.0, "its step -5 is not a step of the run"),
    (0, float("nan"), "a value is not finite"),
    (14, 0.0, "it counts 0 records where the run has written"),
    (14, -3.0, "it counts -3 records where the run has written"),
    (15, 7.0, "it counts 7 snapshots where the run has written"),
])
def test_a_damaged_checkpoint_is_refused(tmp_path: Path, index: int, value: float, needle: str) -> None:
    """The checkpoint's loop values were trusted: a step of 1e9 ran far past t_end into a file
    marked complete, a step of NaN ran until killed, records = -3 made HDF5 spin in the writer
    (SIGTERM ignored). Each is refused (exit 1, one line), both files untouched."""
    scene = write_scene(tmp_path, "d", t_end=4.0)
    partial, checkpoint = tmp_path / "d.h5.partial", tmp_path / "d.h5.checkpoint"
    kill_after_first_checkpoint(scene, checkpoint)
    with h5py.File(checkpoint, "r+") as f:
        scalars = f["scalars"][()]
        scalars[index] = value
        f["scalars"][...] = scalars
    before = partial.read_bytes(), checkpoint.read_bytes()
    done = run("run", scene, "--restart", cwd=tmp_path)
    assert done.returncode == 1 and done.stdout == "" and done.stderr.count("\n") == 1, done.stderr
    assert "d.h5.checkpoint: the checkpoint is damaged: " + needle in done.stderr
    assert (partial.read_bytes(), checkpoint.read_bytes()) == before and not (tmp_path / "d.h5").exists()


def test_a_partial_file_of_another_scene_is_refused(tmp_path: Path) -> None:
    """The complete output of another scene copied to OUT.h5.partial, beside this scene's
    checkpoint, was extended and marked complete: its first rows and attributes the other
    scene's. It is refused, naming the keys that differ; both files untouched."""
    scene = write_scene(tmp_path, "p", t_end=4.0)
    partial, checkpoint = tmp_path / "p.h5.partial", tmp_path / "p.h5.checkpoint"
    kill_after_first_checkpoint(scene, checkpoint)
    other = tmp_path / "other.nml"
    other.write_text("&support omega = 12 /\n&time dt=1e-6, t_end=0.2 /\n&output file='other.h5', "
                     "record_every=1, snapshot_every=997, checkpoint_every=40000 /\n")
    assert run("run", other, cwd=tmp_path).returncode == 0
    shutil.copy2(tmp_path / "other.h5", partial)
    before = partial.read_bytes(), checkpoint.read_bytes()
    done = run("run", scene, "--restart", cwd=tmp_path)
    assert done.returncode == 1 and done.stderr.count("\n") == 1, done.stderr
    assert "p.h5.partial, the output of the interrupted run, belongs to another scene: " in done.stderr
    assert "&support omega = 12.0 in the partial file, 10.0 here" in done.stderr
    assert (partial.read_bytes(), checkpoint.read_bytes()) == before and not (tmp_path / "p.h5").exists()


def test_several_files_with_restart_are_all_checked_before_any_runs(tmp_path: Path) -> None:
    """`run A B C --restart` ran A and the scenes after a refused checkpoint of B: every scene's
    checkpoint and partial file are now checked first, and none runs (README)."""
    scene = write_scene(tmp_path, "b", t_end=4.0)
    kill_after_first_checkpoint(scene, tmp_path / "b.h5.checkpoint")
    scene.write_text(SCENE.format(t_end=3.0, file="b.h5"))  # another t_end: not this checkpoint's scene
    for name in ("a", "c"):
        write_scene(tmp_path, name, t_end=0.01)
    done = run("run", "a.nml", "b.nml", "c.nml", "--restart", cwd=tmp_path)
    assert done.returncode == 1, done.stderr
    assert "b.h5.checkpoint: the checkpoint belongs to another scene" in done.stderr
    assert "none of the 3 scenes was run" in done.stderr
    assert not (tmp_path / "a.h5").exists() and not (tmp_path / "c.h5").exists()


def test_an_interrupted_run_counts_its_shocks_not_its_contact_phases(tmp_path: Path) -> None:
    """A run stopped by SIGTERM wrote its contact phases as `impacts` (the README: `impacts`
    counts shocks): the partial file's `impacts` is now the shocks closed so far, those of the
    resumed run's shock log that had ended by then (closed a rest time and two steps later)."""
    scene = tmp_path / "s.nml"
    scene.write_text("&time dt=5e-5, t_end=400 /\n&output file='s.h5', record_every=100 /\n")
    process = subprocess.Popen([PROGRAM, "run", str(scene)], cwd=tmp_path, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    partial = tmp_path / "s.h5.partial"
    while process.poll() is None and not partial.exists():
        time.sleep(0.01)
    time.sleep(0.4)
    process.send_signal(signal.SIGTERM)
    assert process.wait() != 0
    with h5py.File(partial) as f:
        impacts, phases, stopped = int(f.attrs["impacts"]), int(f.attrs["contact_phases"]), float(f.attrs["t_final"])
    assert 0 < impacts < phases
    done = run("run", scene, "--restart", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    final = beamstops.load(tmp_path / "s.h5")
    t_start, t_end = final.impacts["t_start"], final.impacts["t_end"]
    rest = final.scene().rest_time
    assert np.count_nonzero(t_end + rest + 3 * 5e-5 < stopped) <= impacts <= np.count_nonzero(t_start < stopped)

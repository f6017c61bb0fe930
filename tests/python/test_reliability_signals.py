"""A run stopped by SIGTERM or SIGINT stops politely: records flushed, a checkpoint saved, its
partial file closed with status 'interrupted', one line on stderr, exit status 128 + the signal,
and `--restart` continues it to the uninterrupted run's output bit for bit."""

from __future__ import annotations

import signal
import subprocess
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

import beamstops
from test_reliability_restart import PROGRAM, REDUCED, assert_identical, run, stat_or_none

pytestmark = pytest.mark.skipif(PROGRAM is None, reason="the beamstops program is not on PATH")

PLAIN = """&time dt=1e-6, t_end=1.0 /
&output file='{file}', record_every=1, snapshot_every=997 /
"""


def write(folder: Path, name: str, extra: str = "") -> Path:
    path = folder / f"{name}.nml"
    path.write_text(PLAIN.format(file=f"{name}.h5") + extra)
    return path


def stop_while_running(scenes: list[Path], signum: int) -> subprocess.CompletedProcess[str]:
    """`beamstops run` of `scenes`, sent `signum` once the first one's time loop has written
    records (its partial file past 2 MB: the first buffers of 16,384 rows); how it ended. Skips the
    test when the first scene ended before the signal."""
    first = scenes[0]
    partial = first.with_suffix(".h5.partial")
    process = subprocess.Popen([PROGRAM, "run", *map(str, scenes)], cwd=first.parent, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 60
    while process.poll() is None and time.time() < deadline:
        now = stat_or_none(partial)
        if now is not None and now.st_size >= 2_000_000:
            break
        time.sleep(0.001)
    if process.poll() is None:
        process.send_signal(signum)
    out, err = process.communicate(timeout=120)
    if first.with_suffix(".h5").exists():
        pytest.skip("the first scene ended before the signal")
    return subprocess.CompletedProcess(process.args, process.returncode, out, err)


@pytest.mark.parametrize(("signum", "extra"), [(signal.SIGTERM, ""), (signal.SIGINT, REDUCED)],
                         ids=["SIGTERM, full model, no checkpoint_every", "SIGINT, reduced model"])
def test_a_signal_stops_the_run_politely_and_restart_continues_bit_for_bit(tmp_path: Path, signum: int,
                                                                           extra: str) -> None:
    reference = write(tmp_path, "reference", extra)
    assert run("run", reference, cwd=tmp_path).returncode == 0
    scene = write(tmp_path, "stopped", extra)
    done = stop_while_running([scene], signum)
    assert done.returncode == 128 + signum, done.stderr
    name = signal.Signals(signum).name
    assert done.stderr.count("\n") == 1, done.stderr
    assert f"run interrupted: stopped by {name} at t = " in done.stderr
    assert "stopped.nml --restart continues it" in done.stderr
    assert not (tmp_path / "stopped.h5").exists()
    assert (tmp_path / "stopped.h5.checkpoint").exists()
    with pytest.raises(beamstops.IncompleteRunError, match="run interrupted"):
        beamstops.load(tmp_path / "stopped.h5.partial")
    partial = beamstops.load(tmp_path / "stopped.h5.partial", allow_incomplete=True)
    assert partial.status == "interrupted"
    # every record the loop made is in the file: one a step up to where it stopped
    assert partial.t.size == int(partial.attrs["steps"]) + 1 > 0
    resumed = run("run", scene, "--restart", cwd=tmp_path)
    assert resumed.returncode == 0, resumed.stderr
    assert not (tmp_path / "stopped.h5.checkpoint").exists()
    assert not (tmp_path / "stopped.h5.partial").exists()
    assert_identical(tmp_path / "stopped.h5", tmp_path / "reference.h5")


def test_a_signal_stops_several_scenes_after_the_one_it_stopped(tmp_path: Path) -> None:
    """`beamstops run A.nml B.nml C.nml` (each alone: different meshes): SIGTERM during A stops A
    politely and starts neither B nor C."""
    scenes = [write(tmp_path, name, f"&mesh elements={elements} /\n") for name, elements in
              (("a", 19), ("b", 18), ("c", 17))]
    partial = tmp_path / "a.h5.partial"
    done = stop_while_running(scenes, signal.SIGTERM)
    err = done.stderr
    assert done.returncode == 128 + signal.SIGTERM, err
    assert "a.h5: run interrupted: stopped by SIGTERM" in err
    assert err.rstrip("\n").splitlines()[-1] == "beamstops: 2 of the 3 scenes were not started", err
    assert beamstops.load(partial, allow_incomplete=True).status == "interrupted"
    assert not any((tmp_path / name).exists() for name in ("b.h5", "b.h5.partial", "c.h5", "c.h5.partial"))


def test_a_signal_stops_a_lockstep_group_with_every_member_flushed(tmp_path: Path) -> None:
    """Four scenes sharing A (ω varied) run in lockstep; SIGTERM stops the group between two
    blocks: every member's partial file says 'interrupted' and holds the records of the steps done,
    the same bits as the scene run alone; no checkpoint (the message says to run it again)."""
    scenes = [write(tmp_path, f"m{k}", f"&support omega={omega} /\n") for k, omega in enumerate((8, 9, 10, 11))]
    partial = tmp_path / "m0.h5.partial"
    done = stop_while_running(scenes, signal.SIGTERM)
    err = done.stderr
    assert done.returncode == 128 + signal.SIGTERM, err
    assert "4 in 1 lockstep group(s)" in err
    for k in range(4):
        assert f"m{k}.h5: run interrupted: stopped by SIGTERM" in err
        assert f"beamstops run {scenes[k]} runs it again" in err
        assert not (tmp_path / f"m{k}.h5.checkpoint").exists()
    member = beamstops.load(partial, allow_incomplete=True)
    assert member.status == "interrupted"
    assert member.t.size == int(member.attrs["steps"]) + 1 > 0
    assert run("run", scenes[0], cwd=tmp_path).returncode == 0
    alone = beamstops.load(tmp_path / "m0.h5")
    for name in ("t", "tip_u", "tip_v", "reaction", "energy", "work", "dissipated"):
        kept = getattr(member, name)
        assert np.array_equal(kept.view(np.uint64), getattr(alone, name)[:kept.size].view(np.uint64)), name


def lower_eoa(path: Path, eoa: int) -> None:
    """Write `eoa` as the end of allocation of the file's superblock (version 0: at byte 40), as a
    kill between HDF5's writes of the chunk indexes and of the superblock leaves it."""
    with path.open("r+b") as f:
        head = f.read(48)
        assert head[:8] == b"\x89HDF\r\n\x1a\n" and head[8] == 0 and head[13] == 8
        f.seek(40)
        f.write(eoa.to_bytes(8, "little"))


def test_a_superblock_behind_its_indexes_is_mended_on_load_and_restart(tmp_path: Path) -> None:
    """A partial file whose superblock records less allocation than its chunk indexes point to
    (what a SIGKILL inside HDF5's flush leaves; HDF5 refuses it: 'addr overflow') is read by
    `load` and resumed by `--restart`, bit for bit, once the end of allocation is raised to the
    file's size."""
    reference = write(tmp_path, "reference")
    assert run("run", reference, cwd=tmp_path).returncode == 0
    scene = write(tmp_path, "stopped")
    done = stop_while_running([scene], signal.SIGTERM)
    assert done.returncode == 128 + signal.SIGTERM, done.stderr
    partial = tmp_path / "stopped.h5.partial"
    intact = beamstops.load(partial, allow_incomplete=True)
    size = partial.stat().st_size
    lower_eoa(partial, size // 2)
    with pytest.raises(OSError, match="addr overflow"):
        with h5py.File(partial, "r") as f:
            f["tip/t"][()]
    mended = beamstops.load(partial, allow_incomplete=True)
    assert np.array_equal(mended.t.view(np.uint64), intact.t.view(np.uint64))
    assert np.array_equal(mended.energy.view(np.uint64), intact.energy.view(np.uint64))
    lower_eoa(partial, size // 2)
    resumed = run("run", scene, "--restart", cwd=tmp_path)
    assert resumed.returncode == 0, resumed.stderr
    assert_identical(tmp_path / "stopped.h5", tmp_path / "reference.h5")


def test_a_signal_while_an_ensembles_members_run_stops_them_politely(tmp_path: Path) -> None:
    """SIGTERM after member 1 of an &ensemble, while members 2..K ran, killed the program silently
    (exit 143, its partial file left 'running', no line); it now stops them between two blocks:
    one line, the partial file 'interrupted' with member 1 whole, and running the scene again gives
    the uninterrupted output."""
    text = ("&time dt=1e-5, t_end=2.0 /\n&output file='{file}', record_every=10 /\n"
            "&ensemble members=200, perturbation=1e-6 /\n")
    reference, scene = tmp_path / "reference.nml", tmp_path / "ensemble.nml"
    reference.write_text(text.format(file="reference.h5"))
    scene.write_text(text.format(file="ensemble.h5"))
    assert run("run", reference, cwd=tmp_path).returncode == 0
    process = subprocess.Popen([PROGRAM, "run", str(scene)], cwd=tmp_path, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    time.sleep(0.35)  # member 1 (200,000 steps) takes some 30 ms, the 199 others about a second
    process.send_signal(signal.SIGTERM)
    out, err = process.communicate(timeout=120)
    if process.returncode == 0:
        pytest.skip("the ensemble ended before the signal")
    if "while the ensemble's members" not in err:
        pytest.skip("the signal came before member 1 ended")
    assert process.returncode == 128 + signal.SIGTERM, err
    assert err.count("\n") == 1 and "ensemble.h5: run interrupted: stopped by SIGTERM while the ensemble's " \
                                   "members 2..200 ran (member 1 complete" in err, err
    assert f"beamstops run {scene} runs it again" in err
    partial = beamstops.load(tmp_path / "ensemble.h5.partial", allow_incomplete=True)
    full = beamstops.load(tmp_path / "reference.h5")
    assert partial.status == "interrupted" and not partial.ensemble
    assert np.array_equal(partial.tip_u.view(np.uint64), full.tip_u.view(np.uint64))  # member 1 whole
    assert run("run", scene, cwd=tmp_path).returncode == 0
    assert_identical(tmp_path / "ensemble.h5", tmp_path / "reference.h5")

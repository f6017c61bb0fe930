"""The disk space the HDF5 recorder reserves ahead of its writes
(src/beamstops/recorder/disk_space.c) is released when the file is closed: a finished output,
and the partial output of an interrupted run, hold no blocks past their end. A killed run's
partial output holds at most one reservation past its end, released when it is resumed. A run
that finds no room for its next records (here the file-size limit, `ulimit -f`; a full disk takes
the same path) stops with its partial output readable: the records written so far, status
'failed', and `--restart` continues it bit for bit once there is room."""

from __future__ import annotations

import resource
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

import beamstops
from test_reliability_restart import PROGRAM, assert_identical, stat_or_none

pytestmark = pytest.mark.skipif(PROGRAM is None, reason="the beamstops program is not on PATH")

SCENE = """&time dt=1e-6, t_end={t_end} /
&output file='out.h5', record_every=1, snapshot_every=500, checkpoint_every={checkpoint} /
"""

# what a file of this size may hold beyond its 4 KiB blocks: the file system's own (an extent
# block); a reservation left behind is at least 1 MiB
SLACK = 64 * 1024


def excess(path: Path) -> int:
    """Bytes allocated to the file beyond its size rounded up to 4 KiB blocks."""
    s = path.stat()
    return s.st_blocks * 512 - -(-s.st_size // 4096) * 4096


def write_scene(folder: Path, t_end: float, checkpoint: int = 0) -> Path:
    path = folder / "scene.nml"
    path.write_text(SCENE.format(t_end=t_end, checkpoint=checkpoint))
    return path


def test_a_finished_output_holds_no_blocks_past_its_end(tmp_path: Path) -> None:
    scene = write_scene(tmp_path, t_end=0.05)
    done = subprocess.run([PROGRAM, "run", str(scene)], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    out = tmp_path / "out.h5"
    assert out.stat().st_size > 3_000_000
    assert excess(out) < SLACK, f"{excess(out)} bytes allocated past the end of {out.stat().st_size}"


def test_an_interrupted_output_holds_no_blocks_past_its_end(tmp_path: Path) -> None:
    scene = write_scene(tmp_path, t_end=4.0)
    process = subprocess.Popen([PROGRAM, "run", str(scene)], cwd=tmp_path, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    partial = tmp_path / "out.h5.partial"
    deadline = time.time() + 60
    while process.poll() is None and time.time() < deadline:
        now = stat_or_none(partial)  # None: not created yet (or, the run over, renamed: it fails below)
        if now is not None and now.st_size >= 5_000_000:
            break
        time.sleep(0.005)
    process.send_signal(signal.SIGINT)
    assert process.wait(timeout=60) != 0
    assert partial.stat().st_size >= 5_000_000
    assert excess(partial) < SLACK, f"{excess(partial)} bytes allocated past the end of {partial.stat().st_size}"


def test_a_killed_run_resumed_releases_its_reservation(tmp_path: Path) -> None:
    scene = write_scene(tmp_path, t_end=0.6, checkpoint=100000)
    checkpoint = tmp_path / "out.h5.checkpoint"
    process = subprocess.Popen([PROGRAM, "run", str(scene)], cwd=tmp_path, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    deadline = time.time() + 60
    while process.poll() is None and time.time() < deadline and not checkpoint.exists():
        time.sleep(0.001)
    process.send_signal(signal.SIGKILL)
    process.wait()
    if not checkpoint.exists():
        pytest.skip("the run ended before its first checkpoint")
    partial = tmp_path / "out.h5.partial"
    # at most one reservation: four of the writer's orders (16,384 records of 72 bytes each)
    assert excess(partial) <= 4 * 16384 * 72 + 2**20 + SLACK
    done = subprocess.run([PROGRAM, "run", str(scene), "--restart"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert excess(tmp_path / "out.h5") < SLACK


def test_no_room_under_the_file_size_limit_leaves_a_readable_output_that_resumes(tmp_path: Path) -> None:
    reference = tmp_path / "reference"
    reference.mkdir()
    scene = write_scene(reference, t_end=0.5, checkpoint=100000)
    done = subprocess.run([PROGRAM, "run", str(scene)], cwd=reference, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    limit = 20_000_000

    def limited() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, resource.RLIM_INFINITY))

    scene = write_scene(tmp_path, t_end=0.5, checkpoint=100000)
    done = subprocess.run([PROGRAM, "run", str(scene)], cwd=tmp_path, capture_output=True, text=True, timeout=120,
                          preexec_fn=limited)
    assert done.returncode == 4, done.stderr
    assert done.stderr.count("\n") == 1 and "file-size limit" in done.stderr, done.stderr
    assert not (tmp_path / "out.h5").exists()
    partial = tmp_path / "out.h5.partial"
    assert partial.stat().st_size <= limit
    kept = beamstops.load(partial, allow_incomplete=True)
    assert kept.status == "failed"
    assert 100000 < kept.t.size < 500001
    np.testing.assert_array_equal(kept.t, np.arange(kept.t.size) * 1e-6)
    whole = beamstops.load(reference / "out.h5")
    np.testing.assert_array_equal(kept.energy, whole.energy[:kept.t.size])
    done = subprocess.run([PROGRAM, "run", str(scene), "--restart"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert_identical(tmp_path / "out.h5", reference / "out.h5")


TUBE = """&beam length=1.5 /
&stops law='signorini', x=0.5, 1.0, 1.5, lower=-0.002, -0.002, -0.004, upper=0.002, 0.002, 0.004 /
&support amplitude=0.002, omega=40.0 /
&mesh elements=30 /
&time dt=2e-5, t_end=10.0, beta=0.25 /
&output file='out.h5', record_every=1, snapshot_every=3 /
"""


@pytest.mark.parametrize("limit", [4_000_000, 6_000_000, 12_000_000])
def test_no_room_with_stops_along_the_span_and_snapshots(tmp_path: Path, limit: int) -> None:
    """Stops along the span and snapshots (more series, each order larger): the partial output is
    readable whatever the limit, and its series hold the same records."""
    scene = tmp_path / "scene.nml"
    scene.write_text(TUBE)

    def limited() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, resource.RLIM_INFINITY))

    done = subprocess.run([PROGRAM, "run", str(scene)], cwd=tmp_path, capture_output=True, text=True, timeout=120,
                          preexec_fn=limited)
    assert done.returncode == 4, done.stderr
    kept = beamstops.load(tmp_path / "out.h5.partial", allow_incomplete=True)
    assert kept.status == "failed"
    assert kept.t.size == kept.stops_u.shape[0] == kept.stops_reaction.shape[0] == kept.energy.size
    np.testing.assert_array_equal(kept.t, np.arange(kept.t.size) * 2e-5)
    assert kept.snapshot_t.size > 0 or kept.t.size == 0

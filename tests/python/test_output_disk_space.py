"""The disk space the HDF5 recorder reserves ahead of its writes
(src/beamstops/recorder/disk_space.c) is released when the file is closed: a finished output,
and the partial output of an interrupted run, hold no blocks past their end. A killed run's
partial output holds at most one reservation past its end, released when it is resumed."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import time
from pathlib import Path

import pytest

PROGRAM = os.environ.get("BEAMSTOPS_PROGRAM") or shutil.which("beamstops")
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
        try:
            if partial.stat().st_size >= 5_000_000:
                break
        except FileNotFoundError:  # not created yet (or, the run over, renamed: then it failed below)
            pass
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

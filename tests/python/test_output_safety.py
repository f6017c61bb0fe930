"""The files a run writes beside its output (OUT.h5.partial, OUT.h5.checkpoint and its temporary
file OUT.h5.checkpoint.tmp, the hidden name an earlier output is moved aside to) never destroy
what is there: another run's live file, the input, what a symbolic link leads to, a foreign HDF5
file, a FIFO (which would block the run). Each is refused before anything is written, in one line,
exit status 4."""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from test_cli import PROGRAM, SHORT, beamstops, complete_output, one_error_line, write

pytestmark = pytest.mark.skipif(PROGRAM is None, reason="the beamstops program is not on PATH")

#: A run of several seconds (30,000,000 steps), checkpointed.
LONG = "&time dt=1e-6, t_end=30 /\n&output record_every=100, checkpoint_every=1000000 /\n"


def wait_for(path: Path, process: subprocess.Popen[str], size: int = 1) -> bool:
    """Whether `path` reached `size` bytes while `process` still runs."""
    deadline = time.time() + 60
    while process.poll() is None and time.time() < deadline:
        if path.exists() and path.stat().st_size >= size:
            return True
        time.sleep(0.005)
    return False


@pytest.mark.parametrize("locking", [None, "FALSE"], ids=["HDF5 locks", "HDF5_USE_FILE_LOCKING=FALSE"])
def test_a_second_run_to_a_live_output_is_refused_before_it_touches_anything(locking: str | None,
                                                                             tmp_path: Path) -> None:
    env = dict(os.environ)
    if locking is not None:
        env["HDF5_USE_FILE_LOCKING"] = locking
    scene = write(tmp_path, LONG, name="s.nml")
    partial, checkpoint = tmp_path / "s.h5.partial", tmp_path / "s.h5.checkpoint"
    first = subprocess.Popen([PROGRAM, "run", scene.name], cwd=tmp_path, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=env)
    try:
        if not (wait_for(partial, first, 1 << 20) and wait_for(checkpoint, first)):
            pytest.skip("the first run ended before the second started")
        for args in (["run", scene.name], ["run", scene.name, "--restart"]):
            second = subprocess.run([PROGRAM, *args], cwd=tmp_path, capture_output=True, text=True, timeout=60,
                                    env=env)
            assert second.returncode == 4, second.stderr
            assert one_error_line(second) == (
                "beamstops: error: s.h5 (&output file of s.nml, by default the input's name with .h5): s.h5.partial "
                "is being written by another run (a process holds a lock on it: another beamstops run, or a program "
                "reading it); allowed: wait for it to end, or choose another output (-o OUT.h5, or &output file)")
            assert checkpoint.exists()  # the first run's checkpoint is left to it
        if first.poll() is not None:
            pytest.skip("the first run ended while the second ran")
        out, err = first.communicate(timeout=120)
    finally:
        if first.poll() is None:
            first.kill()
            first.wait()
    assert first.returncode == 0, err
    with h5py.File(tmp_path / "s.h5") as f:  # the first run's file, whole
        assert f.attrs["status"] == b"complete"
        t = f["tip/t"][:]
        assert t.shape == (300001,) and t[0] == 0 and np.all(np.diff(t) > 0)


def test_a_partial_file_another_process_holds_is_refused_untouched(tmp_path: Path) -> None:
    """HDF5 holds a lock on every file it has open (here h5py, reading the partial file of an
    interrupted run): the run does not open it for writing, which would empty it."""
    partial = tmp_path / "out.h5.partial"
    earlier, _ = complete_output(tmp_path, "earlier.h5")
    earlier.rename(partial)
    before = partial.read_bytes()
    scene = write(tmp_path, SHORT)
    with h5py.File(partial, "r"):
        done = beamstops("run", scene, "-o", "out.h5", cwd=tmp_path)
    assert done.returncode == 4
    assert "out.h5.partial is being written by another run" in one_error_line(done)
    assert partial.read_bytes() == before and not (tmp_path / "out.h5").exists()


def victim(tmp_path: Path) -> tuple[Path, bytes]:
    """A file of the user's that a link may lead to."""
    path = tmp_path / "victim.txt"
    path.write_text("the user's own file\n")
    return path, path.read_bytes()


@pytest.mark.parametrize("suffix", [".partial", ".checkpoint", ".checkpoint.tmp"])
@pytest.mark.parametrize("kind", ["input", "symbolic link", "FIFO", "text"])
def test_what_is_at_a_file_the_run_writes_is_refused_untouched(suffix: str, kind: str, tmp_path: Path) -> None:
    """The input itself, a symbolic link (to the user's file), a FIFO (opening it would block) or a
    foreign file at OUT.h5.partial, OUT.h5.checkpoint or OUT.h5.checkpoint.tmp (where a checkpoint
    is written, with checkpoint_every or on SIGINT): refused in one line, nothing written."""
    target, before = victim(tmp_path)
    there = tmp_path / f"out.h5{suffix}"
    scene = SHORT + "&output checkpoint_every=1000 /\n"
    if kind == "input":
        there.write_text(scene)
        name = there.name
    else:
        name = write(tmp_path, scene).name
        if kind == "symbolic link":
            there.symlink_to(target.name)
        elif kind == "FIFO":
            os.mkfifo(there)
        else:
            there.write_text("not HDF5\n")
    done = subprocess.run([PROGRAM, "run", name, "-o", "out.h5"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=30)
    assert done.returncode == 4, done.stderr
    line = one_error_line(done)
    assert line.startswith(f"beamstops: error: out.h5 (-o): out.h5{suffix}, where the run "), line
    why = {"input": f"is the input file out.h5{suffix}", "symbolic link": "is a symbolic link",
           "FIFO": "is a FIFO (named pipe), not a regular file", "text": "not "}[kind]
    assert why in line, line
    assert target.read_bytes() == before
    if kind == "input":
        assert there.read_text() == scene
    assert not (tmp_path / "out.h5").exists()
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith("out.h5")) == [there.name]


def test_a_link_put_at_the_checkpoints_temporary_file_during_the_run_is_not_written_through(
        tmp_path: Path) -> None:
    """SIGTERM saves a checkpoint through OUT.h5.checkpoint.tmp: a link put there after the run
    started is refused then too."""
    target, before = victim(tmp_path)
    scene = write(tmp_path, "&time dt=1e-6, t_end=30 /\n&output record_every=100 /\n")
    process = subprocess.Popen([PROGRAM, "run", scene.name, "-o", "out.h5"], cwd=tmp_path, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    try:
        if not wait_for(tmp_path / "out.h5.partial", process, 1 << 20):
            pytest.skip("the run ended before the link was made")
        (tmp_path / "out.h5.checkpoint.tmp").symlink_to(target.name)
        process.send_signal(signal.SIGTERM)
        _, err = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert process.returncode == 4, err
    assert "out.h5.checkpoint.tmp" in err and "symbolic link" in err and err.count("\n") == 1, err
    assert target.read_bytes() == before
    assert not (tmp_path / "out.h5").exists() and not (tmp_path / "out.h5.checkpoint").exists()


def test_a_link_at_the_partial_file_to_another_output_is_refused(tmp_path: Path) -> None:
    other, before = complete_output(tmp_path, "other.h5")
    (tmp_path / "out.h5.partial").symlink_to(other.name)
    done = beamstops("run", write(tmp_path, SHORT), "-o", "out.h5", cwd=tmp_path)
    assert done.returncode == 4
    assert "out.h5.partial, where the run writes until it is done, is a symbolic link" in one_error_line(done)
    assert other.read_bytes() == before and not (tmp_path / "out.h5").exists()


def lookalike(path: Path) -> bytes:
    """An HDF5 file with the root attributes version and status, that beamstops did not write."""
    with h5py.File(path, "w") as f:
        f["data"] = np.arange(3.0)
        f.attrs["version"] = "2.1"
        f.attrs["status"] = "complete"
    return path.read_bytes()


@pytest.mark.parametrize("name", ["out.h5", "out.h5.partial"])
def test_an_hdf5_file_with_version_and_status_that_beamstops_did_not_write_is_refused(name: str,
                                                                                      tmp_path: Path) -> None:
    before = lookalike(tmp_path / name)
    done = beamstops("run", write(tmp_path, SHORT), "-o", "out.h5", cwd=tmp_path)
    assert done.returncode == 4
    line = one_error_line(done)
    assert "without the root attributes version, status and scene and the dataset /tip/t" in line, line
    assert (tmp_path / name).read_bytes() == before


def test_every_kind_of_beamstops_file_is_taken_as_its_own(tmp_path: Path) -> None:
    """A complete, a diverged, a failed and an interrupted output (the last two as partial files)
    are replaced by a re-run, as before the signature was strengthened."""
    scene = write(tmp_path, SHORT)
    diverged = write(tmp_path, "&time dt=2e-5, beta=0, t_end=0.5, allow_unstable=.true. /\n"
                               "&output record_every=100 /\n", name="diverged.nml")
    assert beamstops("run", diverged, "-o", "d.h5", cwd=tmp_path).returncode == 3
    assert beamstops("run", scene, "-o", "d.h5", cwd=tmp_path).returncode == 0
    for status in (b"failed", b"interrupted", b"running"):
        complete_output(tmp_path, "p.h5")
        with h5py.File(tmp_path / "p.h5", "a") as f:
            f.attrs["status"] = status
        (tmp_path / "p.h5").rename(tmp_path / "out.h5.partial")
        done = beamstops("run", scene, "-o", "out.h5", cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        assert beamstops("run", scene, "-o", "out.h5", cwd=tmp_path).returncode == 0


def test_a_file_at_the_hidden_name_of_the_replaced_output_is_kept(tmp_path: Path) -> None:
    """The earlier output is moved aside to .OUT.h5.replaced-PID before it is removed; a file of
    that name (the shell's PID is the program's after exec) is not overwritten."""
    complete_output(tmp_path, "out.h5")
    scene = write(tmp_path, SHORT)
    done = subprocess.run(["sh", "-c", 'echo mine > ".out.h5.replaced-$$"; exec "$0" run scene.nml -o out.h5',
                           PROGRAM], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    hidden = [p for p in tmp_path.glob(".out.h5.replaced-*") if "-" not in p.name.rsplit("replaced-", 1)[1]]
    assert len(hidden) == 1 and hidden[0].read_text() == "mine\n"
    deadline = time.time() + 30  # the earlier output, moved aside under another name, is removed
    while len(list(tmp_path.glob(".out.h5.replaced-*"))) > 1 and time.time() < deadline:
        time.sleep(0.01)
    assert list(tmp_path.glob(".out.h5.replaced-*")) == hidden
    with h5py.File(tmp_path / "out.h5") as f:
        assert f.attrs["status"] == b"complete"


@pytest.mark.parametrize("kind", ["FIFO", "link to a FIFO", "device"])
def test_an_output_that_is_not_a_regular_file_is_refused_without_opening_it(kind: str, tmp_path: Path) -> None:
    scene = write(tmp_path, SHORT)
    out = {"FIFO": "ff", "link to a FIFO": "link.h5", "device": "/dev/null"}[kind]
    if kind != "device":
        os.mkfifo(tmp_path / "ff")
    if kind == "link to a FIFO":
        (tmp_path / "link.h5").symlink_to("ff")
    done = beamstops("run", scene, "-o", out, cwd=tmp_path)
    assert done.returncode == 4
    why = {"FIFO": "is a FIFO (named pipe), not a regular file", "link to a FIFO": "is a symbolic link to a FIFO",
           "device": "is a device, not a regular file"}[kind]
    assert one_error_line(done).startswith(f"beamstops: error: {out} (-o): {why}")

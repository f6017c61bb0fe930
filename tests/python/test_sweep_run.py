"""Running sweeps on local processes: outputs, summary, failures, resuming, one spec per folder."""

from __future__ import annotations

import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import h5py
import numpy as np
import pytest

import beamstops
from beamstops.sweep import load_spec, read_summary, run_sweep
from beamstops.sweep.runner import prepare_folder

ROOT = Path(__file__).resolve().parents[2]

SMALL = """
[scene]
elements = 4
dt = 1e-4
[axes]
omega = [8.0, 20.0]
amplitude = [0.1, 0.2]
[periods]
t_end = 6
records_per_period = 8
[reductions.strobe]
kind = "strobe"
transient_periods = 2
[reductions.v_rms]
kind = "rms"
quantity = "tip_v"
after_periods = 2
"""


def mtimes(folder: Path) -> dict[str, int]:
    return {p.name: p.stat().st_mtime_ns for p in sorted((folder / "points").glob("*.h5"))}


def test_every_point_writes_its_file_and_the_summary_gathers_them(tmp_path: Path,
                                                                  write_spec: Callable[..., Path]) -> None:
    spec = load_spec(write_spec(SMALL))
    outcome = run_sweep(spec, tmp_path / "out", jobs=2, stream=None)
    assert (outcome.total, outcome.complete, outcome.failed, outcome.ran) == (4, 4, 0, 4)
    rows = read_summary(tmp_path / "out")
    assert [(r["omega"], r["amplitude"]) for r in rows] == [(8.0, 0.1), (8.0, 0.2), (20.0, 0.1), (20.0, 0.2)]
    for row, point in zip(rows, spec.points):
        result = beamstops.load(tmp_path / "out" / row["file"])  # the program's own complete output
        assert result.status == "complete" and result.attrs["omega"] == row["omega"]
        assert row["steps"] == result.attrs["steps"] and row["impacts"] == result.attrs["impacts"]
        assert row["cpu_seconds"] == result.attrs["cpu_seconds"] and row["wall_seconds"] > 0
        assert row["max_violation"] == 0.0 and row["dissipated"] == result.dissipated[-1]
        assert row["dt"] == point.scene.dt and row["record_every"] == point.scene.record_every
        # the strobe: u(L, kT) for k = 2..6 are records k*8 of a grid locked to the forcing
        assert row["strobe"] == result.tip_u[[8 * k for k in range(2, 7)]].tolist()
        assert row["strobe_offset"] < 1e-12
        period = 2 * math.pi / row["omega"]
        v = result.tip_v[result.t >= 2 * period * (1 - 1e-12)]
        assert row["v_rms"] == pytest.approx(float(np.sqrt(np.mean(v * v))), rel=1e-15)
    # the namelist each point ran, and the specification with its hash
    assert beamstops.Scene.from_namelist(tmp_path / "out" / "points" / "00003.nml").omega == 20.0
    manifest = json.loads((tmp_path / "out" / "sweep.json").read_text())
    assert manifest["spec_hash"] == spec.hash and (tmp_path / "out" / "spec.toml").read_text() == SMALL
    header = (tmp_path / "out" / "summary.csv").read_text().splitlines()[0].split(",")
    assert header[:8] == ["point", "omega", "amplitude", "status", "cpu_seconds", "wall_seconds", "steps", "impacts"]
    assert {"max_violation", "dissipated", "strobe", "strobe_offset", "strobe_period", "v_rms", "message"} <= set(header)


def test_a_failed_point_is_recorded_and_the_sweep_goes_on(tmp_path: Path, write_spec: Callable[..., Path],
                                                          program: str) -> None:
    spec = load_spec(write_spec("""
[scene]
elements = 4
t_end = 0.05
beta = 0.0
[axes]
dt = [1e-4, 2e-5, 5e-5]
"""))
    # a folder is where point 1 would write its partial output: the program refuses to run it
    prepare_folder(spec, tmp_path / "out", program)
    (tmp_path / "out" / "points" / "00001.h5.partial").mkdir()
    outcome = run_sweep(spec, tmp_path / "out", jobs=2, stream=None, program=program)
    assert (outcome.complete, outcome.failed) == (2, 1)
    rows = read_summary(tmp_path / "out")
    assert [r["status"] for r in rows] == ["complete", "failed", "complete"]
    assert "00001.h5.partial" in rows[1]["message"] and "a folder" in rows[1]["message"]  # the program's line
    assert (tmp_path / "out" / "points" / "00001.h5.partial").is_dir()
    # a failed point runs again on the next call; finished ones do not
    again = run_sweep(spec, tmp_path / "out", jobs=2, stream=None, program=program)
    assert (again.ran, again.skipped, again.failed) == (1, 2, 1)


def test_a_diverged_run_is_finished_and_kept(tmp_path: Path, write_spec: Callable[..., Path]) -> None:
    spec = load_spec(write_spec("""
[scene]
elements = 4
t_end = 0.5
beta = 0.0
allow_unstable = true
[axes]
dt = [1e-4, 1e-3]
[reductions.u_final]
kind = "final"
"""))
    outcome = run_sweep(spec, tmp_path / "out", jobs=2, stream=None)
    assert (outcome.complete, outcome.diverged, outcome.failed) == (1, 1, 0)
    row = read_summary(tmp_path / "out")[1]
    result = beamstops.load(tmp_path / "out" / row["file"], allow_incomplete=True)
    assert row["status"] == result.status == "diverged" and "blew up" in row["message"]
    assert row["message"] == result.attrs["message"]  # the engine's message, not its stderr line naming the file
    # every column in every row of summary.json, in the order of summary.csv; a diverged point has no reductions
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    header = (tmp_path / "out" / "summary.csv").read_text().splitlines()[0].split(",")
    assert summary["columns"] == header and all(list(r) == header for r in summary["points"])
    complete = beamstops.load(tmp_path / "out" / "points" / "00000.h5")
    assert row["u_final"] is None and read_summary(tmp_path / "out")[0]["u_final"] == complete.tip_u[-1]
    # the engine went to its end: resuming does not run it again
    assert run_sweep(spec, tmp_path / "out", stream=None).ran == 0


def test_a_point_over_its_time_limit_fails_alone(tmp_path: Path, write_spec: Callable[..., Path]) -> None:
    spec = load_spec(write_spec("""
[sweep]
timeout = 0.5
[scene]
elements = 4
dt = 1e-6
record_every = 100000
[axes]
t_end = [0.01, 1000.0]
"""))
    start = time.perf_counter()
    outcome = run_sweep(spec, tmp_path / "out", jobs=2, stream=None)
    assert time.perf_counter() - start < 20
    rows = read_summary(tmp_path / "out")
    assert [r["status"] for r in rows] == ["complete", "failed"] and outcome.failed == 1
    assert rows[1]["message"].startswith("timed out after 0.5 s")


def test_resume_skips_finished_points_and_reruns_interrupted_ones(tmp_path: Path, write_spec: Callable[..., Path],
                                                                  without_timing: Callable[..., Any]) -> None:
    spec = load_spec(write_spec(SMALL))
    out = tmp_path / "out"
    run_sweep(spec, out, jobs=2, stream=None)
    first = read_summary(out)
    before = mtimes(out)
    points = out / "points"
    # point 1: interrupted while running (the program marks its file 'running' until the end)
    with h5py.File(points / "00001.h5", "r+") as f:
        f.attrs["status"] = np.bytes_(b"running")
    # point 2: the run finished but its record was not written; point 3: never started
    (points / "00002.json").unlink()
    (points / "00003.h5").unlink()
    (points / "00003.json").unlink()
    time.sleep(0.01)
    outcome = run_sweep(spec, out, jobs=2, stream=None)
    assert (outcome.ran, outcome.skipped, outcome.complete) == (3, 1, 4)
    after = mtimes(out)
    assert after["00000.h5"] == before["00000.h5"]  # skipped
    assert after["00001.h5"] != before["00001.h5"]  # run again
    assert after["00002.h5"] == before["00002.h5"]  # only reduced again from its complete file
    assert without_timing(read_summary(out)) == without_timing(first)


def stop_sweep(spec_path: Path, out: Path, pattern: str, settle: float) -> tuple[list[str], str]:
    """Start ``beamstops sweep`` of `spec_path` into `out` on one worker, in a session of its own;
    once a file matching `pattern` is in out/points and `settle` seconds more have passed, send
    SIGTERM to the whole session (a batch system's time limit: the whole job). The command and
    the sweep's stderr; the sweep must say it was interrupted (exit 130)."""
    command = [sys.executable, "-m", "beamstops", "sweep", str(spec_path), "-o", str(out), "-j", "1", "--interval", "0.1"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               start_new_session=True)
    deadline = time.monotonic() + 60
    while process.poll() is None and not list((out / "points").glob(pattern)) and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(settle)
    os.killpg(process.pid, signal.SIGTERM)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    return command, err


def test_resume_after_a_real_interruption_gives_the_uninterrupted_results(tmp_path: Path,
                                                                          write_spec: Callable[..., Path],
                                                                          without_timing: Callable[..., Any]) -> None:
    # batches of 2 points (lockstep) on one worker: the kill comes while a later batch runs
    text = """
[sweep]
lockstep = 2
[scene]
elements = 10
dt = 2e-5
t_end = 80.0
record_every = 10
[axes]
amplitude = { start = 0.10, stop = 0.15, step = 0.01 }
"""
    spec_path = write_spec(text)
    out = tmp_path / "out"
    # the sweep takes the point's result after its worker wrote the file (slow when loaded)
    command, err = stop_sweep(spec_path, out, "*.json", 0.5)
    assert "interrupted" in err and "Traceback" not in err
    statuses = [r["status"] for r in read_summary(out)]
    assert "complete" in statuses and "pending" in statuses, statuses
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "done before" in done.stderr
    resumed = read_summary(out)
    assert all(r["status"] == "complete" for r in resumed), resumed
    clean = run_sweep(load_spec(spec_path), tmp_path / "clean", jobs=2, stream=None)
    assert clean.complete == len(resumed)
    assert without_timing(read_summary(tmp_path / "clean")) == without_timing(resumed)


def test_a_point_stopped_by_a_signal_continues_from_its_checkpoint(tmp_path: Path,
                                                                   write_spec: Callable[..., Path],
                                                                   without_timing: Callable[..., Any]) -> None:
    """SIGTERM to the whole sweep (a batch system's time limit) while a point runs: the point's
    program stops politely (checkpoint saved, its partial file 'interrupted'); the resumed sweep
    continues that point from the checkpoint (--restart) instead of starting it over. Seen by a
    mark put into the partial file's first record: a run started over would not keep it."""
    spec_path = write_spec("[sweep]\nlockstep = 1\n[scene]\ndt = 1e-6\nt_end = 3.0\nrecord_every = 100\n"
                           "[axes]\namplitude = { start = 0.10, stop = 0.12, num = 2 }\n")
    out = tmp_path / "out"
    command, _ = stop_sweep(spec_path, out, "*.h5.partial", 0.2)  # 0.2 s: into the point's time loop
    partials = list((out / "points").glob("*.h5.partial"))
    if not partials:
        pytest.skip("the point ended before the signal")
    partial = partials[0]
    assert Path(f"{str(partial)[:-len('.partial')]}.checkpoint").is_file()
    assert beamstops.load(partial, allow_incomplete=True).status == "interrupted"
    with h5py.File(partial, "r+") as f:
        f["tip/u"][0] = 42.0
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    final = Path(str(partial)[:-len(".partial")])
    assert beamstops.load(final).tip_u[0] == 42.0  # continued, not started over
    assert not partial.exists()
    clean = run_sweep(load_spec(spec_path), tmp_path / "clean", jobs=1, stream=None)
    assert clean.complete == 2
    assert without_timing(read_summary(tmp_path / "clean")) == without_timing(read_summary(out))


def test_a_folder_holds_one_specification(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                          write_spec: Callable[..., Path]) -> None:
    from beamstops import cli

    spec_path = write_spec(SMALL)
    out = tmp_path / "out"
    assert cli.main(["sweep", str(spec_path), "-o", str(out), "-j", "2", "-q"]) == 0
    other = write_spec(SMALL.replace("t_end = 6", "t_end = 7"), "other.toml")
    assert cli.main(["sweep", str(other), "-o", str(out), "-q"]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"beamstops: error: {out}: holds the results of another specification") and "hash" in err
    # the same spec with a --set is another spec too
    assert cli.main(["sweep", str(spec_path), "-o", str(out), "-q", "--set", "scene.elements=5"]) == 1
    err = capsys.readouterr().err
    assert f"({os.path.abspath(spec_path)} without --set, hash " in err, err
    assert f"; {spec_path} with --set scene.elements=5 has hash " in err, err
    assert "(--set values are part of the specification)" in err, err
    # a folder that is not a sweep's is not used
    (tmp_path / "busy").mkdir()
    (tmp_path / "busy" / "notes.txt").write_text("mine")
    assert cli.main(["sweep", str(spec_path), "-o", str(tmp_path / "busy"), "-q"]) == 1
    assert "not a sweep folder" in capsys.readouterr().err
    # the same spec resumes (nothing left to run)
    assert cli.main(["sweep", str(spec_path), "-o", str(out)]) == 0
    assert "4 complete" in capsys.readouterr().err


def test_progress_lines_in_a_log(tmp_path: Path, write_spec: Callable[..., Path]) -> None:
    import io

    spec = load_spec(write_spec(SMALL))
    log = io.StringIO()
    run_sweep(spec, tmp_path / "out", jobs=2, stream=log, interval=0.0)
    lines = log.getvalue().splitlines()
    assert lines[0].startswith("sweep: 4 points in") and "to run on 2 local processes" in lines[0]
    assert any("4/4 points done, 0 failed" in line and "left" in line for line in lines)
    assert "\r" not in log.getvalue()
    assert lines[-1].startswith("sweep: 4 points: 4 complete, 0 diverged, 0 failed")


def test_bifurcation_script_quick(tmp_path: Path) -> None:
    png = tmp_path / "bif.png"
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "bifurcation.py"), "--quick", "-o",
                           str(tmp_path / "bif"), "--png", str(png), "-j", "2", "-q"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20000
    assert "python scripts/bifurcation.py --quick" in done.stdout
    rows = read_summary(tmp_path / "bif")
    assert len(rows) == 12 and all(r["status"] == "complete" and len(r["strobe"]) == 9 for r in rows)


def test_resuming_with_another_build_of_the_engine_says_so(tmp_path: Path, program: str,
                                                           write_spec: Callable[..., Path]) -> None:
    import io
    import shutil

    spec = load_spec(write_spec(SMALL))
    run_sweep(spec, tmp_path / "out", jobs=2, stream=None)
    (tmp_path / "out" / "points" / "00000.h5").unlink()
    rebuilt = tmp_path / "beamstops"
    shutil.copy2(program, rebuilt)
    with open(rebuilt, "ab") as f:
        f.write(b"\0")  # another file, the same program
    log = io.StringIO()
    outcome = run_sweep(spec, tmp_path / "out", jobs=1, stream=log, program=str(rebuilt))
    assert outcome.ran == 1 and outcome.complete == 4
    assert "another build of the engine" in log.getvalue()


def test_progress_bar_on_a_terminal_is_tqdm(tmp_path: Path, write_spec: Callable[..., Path]) -> None:
    import io

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    terminal = Terminal()
    run_sweep(load_spec(write_spec(SMALL)), tmp_path / "out", jobs=2, stream=terminal)
    text = terminal.getvalue()
    assert "\r" in text and "100%|" in text and "4/4 points done, 0 failed" in text
    assert text.splitlines()[-1].startswith("sweep: 4 points: 4 complete")


# ---------------------------------------------------------------- one sweep per folder (issue 15)


LONG = """
[sweep]
lockstep = 1   # one process per point: long enough for the other sweeps to try
[scene]
elements = 10
dt = 2e-5
t_end = 20.0
record_every = 100
[axes]
amplitude = { start = 0.10, stop = 0.15, step = 0.01 }
"""


def test_a_second_sweep_into_a_running_sweeps_folder_is_refused(tmp_path: Path, write_spec: Callable[..., Path],
                                                                 without_timing: Callable[..., Any]) -> None:
    import socket

    spec_path = write_spec(LONG)
    out = tmp_path / "out"
    command = [sys.executable, "-m", "beamstops", "sweep", str(spec_path), "-o", str(out), "-j", "1", "-q"]
    first = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lock = out / ".lock"
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and first.poll() is None:
        if lock.is_file() and lock.read_text().startswith("pid"):
            break
        time.sleep(0.01)
    assert lock.read_text().split() == ["pid", str(first.pid), "host", socket.gethostname()]
    others = [subprocess.Popen(c, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
              for c in (command, command[:-1])]  # a second sweep, and a resume (not quiet)
    second, resume = (subprocess.CompletedProcess(p.args, p.wait(timeout=60), *p.communicate()) for p in others)
    assert first.poll() is None, "the first sweep ended before the others tried: make it longer"
    _, err = first.communicate(timeout=300)
    assert first.returncode == 0, err
    for refused in (second, resume):
        assert refused.returncode == 1, refused.stderr
        line = refused.stderr.strip().splitlines()[-1]
        assert line.startswith(f"beamstops: error: {out}: another sweep is running into this folder")
        assert f"pid {first.pid} host {socket.gethostname()}" in line
    # the refused sweeps changed nothing: the results are a lone sweep's
    assert lock.read_text() == ""
    rows = read_summary(out)
    assert all(r["status"] == "complete" for r in rows)
    clean = run_sweep(load_spec(spec_path), tmp_path / "clean", jobs=2, stream=None)
    assert clean.complete == len(rows)
    assert without_timing(read_summary(tmp_path / "clean")) == without_timing(rows)


def test_a_sweep_refuses_a_folder_locked_in_this_process(tmp_path: Path, write_spec: Callable[..., Path]) -> None:
    from beamstops.sweep.runner import FolderLock

    spec = load_spec(write_spec(SMALL))
    out = tmp_path / "out"
    with FolderLock(out):
        with pytest.raises(ValueError, match=f"pid {os.getpid()} host "):
            run_sweep(spec, out, jobs=1, stream=None)
        assert not (out / "points").exists()
    assert run_sweep(spec, out, jobs=2, stream=None).complete == 4


def test_the_lock_of_a_dead_sweep_is_taken_over(tmp_path: Path, write_spec: Callable[..., Path]) -> None:
    import io

    spec = load_spec(write_spec(SMALL))
    out = tmp_path / "out"
    run_sweep(spec, out, jobs=2, stream=None)
    (out / "points" / "00001.h5").unlink()
    # a sweep killed with SIGKILL: its lock file still names it, but the kernel dropped its lock
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    (out / ".lock").write_text(f"pid {dead.pid} host elsewhere\n")
    log = io.StringIO()
    outcome = run_sweep(spec, out, jobs=1, stream=log)
    assert (outcome.ran, outcome.complete) == (1, 4)
    assert f"took over the lock of a sweep that is no longer running (pid {dead.pid} host elsewhere)" in log.getvalue()


def children(pid: int) -> list[int]:
    """The processes whose parent is `pid` (/proc)."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            found.append(int(stat.parent.name))
    return found


def test_a_sweep_killed_with_sigkill_takes_its_workers_with_it(tmp_path: Path,
                                                                write_spec: Callable[..., Path]) -> None:
    """SIGKILL to the sweep's own process (an out-of-memory killer, `kill -9`): its workers get
    SIGTERM from the kernel and end (they went on idle for good, holding the folder's lock they
    inherited, and every resume was refused), and a resume then runs."""
    text = """
[scene]
elements = 10
dt = 2e-5
t_end = 4000.0
record_every = 100000
[axes]
amplitude = { start = 0.10, stop = 0.13, step = 0.01 }
"""
    spec_path = write_spec(text)
    out = tmp_path / "out"
    command = [sys.executable, "-m", "beamstops", "sweep", str(spec_path), "-o", str(out), "-j", "2"]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while not list((out / "points").glob("*.nml")) and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(0.5)
    workers = children(process.pid)
    assert workers, "the sweep has no worker processes"
    process.send_signal(signal.SIGKILL)
    process.wait()
    deadline = time.monotonic() + 60
    while any(Path(f"/proc/{pid}").exists() for pid in workers) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not any(Path(f"/proc/{pid}").exists() for pid in workers), "workers outlived their sweep"
    from beamstops.sweep.runner import FolderLock

    with FolderLock(out):  # taken: no worker holds it any more
        pass


def test_without_flock_the_pid_in_the_lock_file_decides(tmp_path: Path, write_spec: Callable[..., Path],
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    import errno
    import fcntl
    import socket

    from beamstops.sweep.runner import FolderLock

    def no_locks(fd: int, operation: int) -> None:
        raise OSError(errno.ENOLCK, "No locks available")

    monkeypatch.setattr(fcntl, "flock", no_locks)
    out = tmp_path / "out"
    out.mkdir()
    (out / ".lock").write_text(f"pid {os.getpid()} host {socket.gethostname()}\n")  # alive: this process
    with pytest.raises(ValueError, match=f"pid {os.getpid()} host"):
        FolderLock(out).acquire()
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    (out / ".lock").write_text(f"pid {dead.pid} host {socket.gethostname()}\n")
    with FolderLock(out) as lock:
        assert lock.unlocked and lock.stale == f"pid {dead.pid} host {socket.gethostname()}"
        assert (out / ".lock").read_text().split()[1] == str(os.getpid())


UNSTABLE = """
[scene]
t_end = 0.01
beta = 0
dt = 1e-3
[axes]
omega = [5, 10]
"""
STABLE = UNSTABLE.replace("beta = 0", "elements = 4").replace("1e-3", "1e-4")
#: Points that do not complete: 1e9 steps each, over their time limit.
SLOW = "[sweep]\ntimeout = 0.3\n" + STABLE.replace("t_end = 0.01", "t_end = 1e5\nrecord_every = 1000000")


def sweep_command(*args: str | Path, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "beamstops", "sweep", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=300)


def test_a_sweep_with_failed_points_exits_3_and_says_so(tmp_path: Path, write_spec: Callable[..., Path]) -> None:
    spec = write_spec(SLOW)
    done = sweep_command(spec, "-o", tmp_path / "out", "-j", "2", cwd=tmp_path)
    assert done.returncode == 3, done.stderr
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith("beamstops: error: sweep: 2 of 2 points did not complete (2 failed, 0 diverged)")
    assert [r["status"] for r in read_summary(tmp_path / "out")] == ["failed", "failed"]
    # quiet: no progress, but the failure is still said, and the status is the same on a resume
    again = sweep_command(spec, "-o", tmp_path / "out", "-q", cwd=tmp_path)
    assert again.returncode == 3 and again.stderr.strip().startswith("beamstops: error: sweep: 2 of 2 points")
    assert len(again.stderr.strip().splitlines()) == 1
    # the status is documented
    assert "3 some point failed" in sweep_command("--help", cwd=tmp_path).stdout


def test_a_sweep_with_a_diverged_point_exits_3(tmp_path: Path, write_spec: Callable[..., Path]) -> None:
    spec = write_spec("[scene]\nelements = 4\nt_end = 0.5\nbeta = 0.0\nallow_unstable = true\n"
                      "[axes]\ndt = [1e-4, 1e-3]\n")  # the second diverges
    done = sweep_command(spec, "-o", tmp_path / "out", "-j", "2", "-q", cwd=tmp_path)
    assert done.returncode == 3, done.stderr
    assert "1 of 2 points did not complete (0 failed, 1 diverged)" in done.stderr


def test_a_sweep_whose_points_all_complete_exits_0(tmp_path: Path, write_spec: Callable[..., Path]) -> None:
    done = sweep_command(write_spec(STABLE), "-o", tmp_path / "out", "-j", "2", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "2 complete, 0 diverged, 0 failed" in done.stderr and "error" not in done.stderr


@pytest.mark.parametrize("option, value", [("--timeout", "-1"), ("--timeout", "0"), ("--timeout", "nan"),
                                           ("--interval", "-5"), ("--interval", "0")])
def test_non_positive_timeout_and_interval_are_refused(option: str, value: str, tmp_path: Path,
                                                       write_spec: Callable[..., Path]) -> None:
    done = sweep_command(write_spec(STABLE), "-o", tmp_path / "out", option, value, cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr == (f"python -m beamstops sweep: error: argument {option}: '{value}': allowed: a number of "
                           "seconds > 0 (python -m beamstops sweep --help: the options)\n")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("value", ["0", "-1", "two"])
def test_fewer_than_one_worker_is_refused_before_the_folder_is_made(value: str, tmp_path: Path,
                                                                    write_spec: Callable[..., Path]) -> None:
    """-j 0 was refused only after the folder, its summary (every point 'pending') and its
    specification were written."""
    done = sweep_command(write_spec(STABLE), "-o", tmp_path / "out", "-j", value, cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr.splitlines() == [f"python -m beamstops sweep: error: argument -j/--jobs: '{value}': allowed: "
                                        "a whole number of worker processes >= 1 (python -m beamstops sweep --help: "
                                        "the options)"]
    assert not (tmp_path / "out").exists()
    with pytest.raises(ValueError, match="-j 0: the number of workers must be >= 1"):
        run_sweep(load_spec(write_spec(STABLE)), tmp_path / "api", jobs=0)
    assert not (tmp_path / "api").exists()


@pytest.mark.parametrize(("args", "message"), [
    (["-j", "0"], "argument -j/--jobs: '0': allowed: a whole number of worker processes >= 1"),
    (["--timeout", "-1"], "argument --timeout: '-1': allowed: a number of seconds > 0"),
    (["--interval", "inf"], "argument --interval: 'inf': allowed: a number of seconds > 0"),
    (["--executor", "cloud"], "argument --executor: invalid choice: 'cloud' (choose from 'auto', 'local', 'mpi')"),
    (["--jobs"], "argument -j/--jobs: expected one argument"),
    (["--fast"], "unrecognized arguments: --fast"),
])
def test_a_bad_command_line_value_is_one_line_from_the_program(args: list[str], message: str, tmp_path: Path,
                                                              write_spec: Callable[..., Path], program: str) -> None:
    """`beamstops sweep` (the program hands the command to Python): one line naming the option and what
    it allows, exit status 2, nothing written (argparse printed its usage block first: six lines)."""
    done = subprocess.run([program, "sweep", str(write_spec(STABLE)), "-o", str(tmp_path / "out"), *args],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert done.stderr == f"beamstops sweep: error: {message} (beamstops sweep --help: the options)\n"
    assert done.stdout == "" and not (tmp_path / "out").exists()


def test_a_point_the_engine_refuses_refuses_the_specification_before_anything_is_written(
        tmp_path: Path, write_spec: Callable[..., Path], program: str) -> None:
    """beta = 0 beyond its stability limit, found by the engine's own check of `beamstops run` (as
    elements = 0 is found by its reader): exit status 1, the engine's message, no folder."""
    done = subprocess.run([program, "sweep", str(write_spec(UNSTABLE)), "-o", str(tmp_path / "out")],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 1
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(
        f"beamstops: error: {tmp_path / 'spec.toml'}: point 0 (omega=5): scene: &time dt = 0.001 is out of range; "
        "allowed: dt < "), done.stderr
    # the full model's limit (SPEC 3: 1.2395e-5 s at beta = 0), rounded down as shown
    shown = re.search(r"allowed: dt < (\S+) s, the linear stability limit", lines[0])
    assert shown is not None and 1.2394e-5 < float(shown.group(1)) <= 1.2395060e-5, lines[0]
    assert not (tmp_path / "out").exists()
    # the limit is that of the model the point runs: a reduced model's (&mesh modes = 4) is 1.3e-3 s
    reduced = UNSTABLE.replace("beta = 0", "beta = 0\nmodes = 4")
    spec = load_spec(write_spec(reduced, "reduced.toml"))
    assert len(spec.points) == 2
    with pytest.raises(ValueError) as refused:
        load_spec(write_spec(reduced.replace("dt = 1e-3", "dt = 1e-2"), "too_long.toml"))
    assert "point 0 (omega=5): scene: &time dt = 0.01 is out of range; allowed: dt < 0.00129667 s" in str(refused.value)
    assert "of the reduced model with modes = 4" in str(refused.value)
    # beamstops.stability says which limit the engine applies, and of which model
    limits = beamstops.stability(spec.points[0].scene)
    assert limits.runnable and limits.run_model == "reduced model of 4 modes"
    assert limits.dt_limit_run == pytest.approx(1.296673e-3, rel=1e-6) and limits.dt_limit_newmark < 2e-5


@pytest.mark.parametrize("how", ["option", "spec"])
def test_a_time_limit_of_any_length_works(how: str, tmp_path: Path, write_spec: Callable[..., Path]) -> None:
    """A limit beyond what one wait takes (2**31 ms over the points of a batch; 1e300 s beyond
    Python's clock) made every point fail with `OverflowError: timeout is too large`: a 30-day
    limit, or 1e300 s, is waited in pieces and the points complete."""
    if how == "option":
        done = sweep_command(write_spec(STABLE), "-o", tmp_path / "out", "-j", "1", "--timeout", str(30 * 86400),
                             cwd=tmp_path)
    else:
        done = sweep_command(write_spec("[sweep]\ntimeout = 1e300\n" + STABLE), "-o", tmp_path / "out", "-j", "1",
                             cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert [r["status"] for r in read_summary(tmp_path / "out")] == ["complete", "complete"]


def test_a_long_time_limit_is_waited_in_pieces(monkeypatch: pytest.MonkeyPatch) -> None:
    """The wait for a point's program is cut into pieces no longer than one wait can take; the
    limit still stops a program that runs beyond it."""
    from beamstops.sweep import worker

    monkeypatch.setattr(worker, "_WAIT_PIECE", 0.05)
    sleeper = [sys.executable, "-c", "import time; time.sleep(0.4); print('done')"]
    done = worker._run(sleeper, timeout=1e300)
    assert done.returncode == 0 and done.stdout == "done\n"
    with pytest.raises(subprocess.TimeoutExpired):
        worker._run([sys.executable, "-c", "import time; time.sleep(60)"], timeout=0.2)


@pytest.mark.parametrize("content", [
    '{"format": 1, "spec_hash": 5}', "[1, 2]", '"text"', "{}", "[" * 100000, "\xff\xfe",
    "SPEC_HASH_BUT_OVERRIDES_OF_NUMBERS", "SPEC_HASH_OF_ANOTHER_FORMAT"])
def test_a_tampered_manifest_is_unreadable_in_one_line(content: str, tmp_path: Path, write_spec: Callable[..., Path],
                                                       program: str) -> None:
    """A sweep.json of another structure (`"spec_hash": 5` ended in a traceback, `TypeError: 'int'
    object is not subscriptable`): the folder's one line, exit status 1, the points left alone."""
    spec_path = write_spec(STABLE)
    out = tmp_path / "out"
    prepare_folder(load_spec(spec_path), out, program)
    good = json.loads((out / "sweep.json").read_text())
    if content == "SPEC_HASH_BUT_OVERRIDES_OF_NUMBERS":
        content = json.dumps({**good, "overrides": [5]})
    elif content == "SPEC_HASH_OF_ANOTHER_FORMAT":
        content = json.dumps({**good, "format": 99})
    (out / "sweep.json").write_bytes(content.encode("latin-1") if content == "\xff\xfe" else content.encode())
    (out / "points" / "mine.txt").write_text("kept")
    done = sweep_command(spec_path, "-o", out, cwd=tmp_path)
    assert done.returncode == 1
    assert done.stderr == f"beamstops: error: {out}: sweep.json is unreadable; this is not a sweep folder to resume\n"
    assert (out / "points" / "mine.txt").read_text() == "kept" and not (out / "points" / "00000.h5").exists()


def test_a_tampered_point_record_is_made_again(tmp_path: Path, write_spec: Callable[..., Path]) -> None:
    """A point's record of another structure (reductions that are not an object, a text for a
    number) is not taken for the point's: the finished output is reduced again, no traceback."""
    spec = load_spec(write_spec(STABLE + "[reductions.u]\nkind = 'max'\n"))
    run_sweep(spec, tmp_path / "out", jobs=1, stream=None)
    record = tmp_path / "out" / "points" / "00000.json"
    first = json.loads(record.read_text())
    record.write_text(json.dumps({**first, "reductions": 5, "cpu_seconds": "fast"}))
    again = run_sweep(spec, tmp_path / "out", jobs=1, stream=None)
    assert (again.ran, again.skipped, again.complete) == (1, 1, 2)
    row = read_summary(tmp_path / "out")[0]
    assert row["u"] == first["reductions"]["u"] and row["cpu_seconds"] == first["cpu_seconds"]


@pytest.mark.parametrize("folder", ["/proc/beamstops-no-such-folder", "/dev/null/sweep"])
def test_an_output_folder_that_cannot_be_made_is_one_clear_line(folder: str, write_spec: Callable[..., Path],
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    """`sweep -o /proc/xx` ended in Python's '[Errno 2] No such file or directory: '/proc/xx''."""
    from beamstops import cli

    assert cli.main(["sweep", str(write_spec(SMALL)), "-o", folder, "-q"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"beamstops: error: {folder}: the sweep's output folder cannot be "
                                               "created or written ("), err
    assert "[Errno" not in err[0] and "allowed: -o a folder" in err[0]


def test_an_os_error_reads_as_its_file_and_what_went_wrong() -> None:
    from beamstops.cli import _described

    assert _described(FileNotFoundError(2, "No such file or directory", "/a/b")) == "/a/b: No such file or directory"
    assert _described(OSError(18, "Invalid cross-device link", "/a", None, "/b")) == "/a and /b: Invalid cross-device link"
    assert _described(ValueError("x.nml: bad")) == "x.nml: bad"
    from beamstops.output_files import WriteError

    failed = WriteError(27, "File too large", "old.png")  # an OSError that words itself
    assert _described(failed) == str(failed) and str(failed).startswith("cannot write old.png")


def test_a_point_whose_worker_died_keeps_its_time_grid_in_the_summary(tmp_path: Path,
                                                                       write_spec: Callable[..., Path]) -> None:
    # a worker that dies leaves its points a record of status and message only; their rows still give the
    # time grid each point runs (its scene's), as a pending or complete point's row does
    from beamstops.sweep.runner import write_summary

    spec = load_spec(write_spec(SMALL))
    (tmp_path / "out").mkdir()
    died = {0: {"point": 0, "params": spec.points[0].params, "status": "failed",
                "message": "worker failed: BrokenProcessPool: ...", "reductions": {}}}
    write_summary(spec, tmp_path / "out", died)
    rows = read_summary(tmp_path / "out")
    for row, point in zip(rows, spec.points):
        assert (row["dt"], row["t_end"], row["record_every"]) == \
            (point.scene.dt, point.scene.t_end, point.scene.record_every)
        assert row["file"] == f"points/{point.name}.h5"
    assert [r["status"] for r in rows] == ["failed", "pending", "pending", "pending"]

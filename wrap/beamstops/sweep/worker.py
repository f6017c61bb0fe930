"""Points of a sweep, as an executor's tasks: write their namelists, run the program, reduce.

A point runs as ``beamstops run NAME.nml -o NAME.h5`` in a child process, so a crash
or a hang (``timeout``) fails that point only. A batch of points runs as one
``beamstops run P1.nml P2.nml ...`` (each namelist names its own output): the engine runs
those that share A in lockstep, each into its own file as if alone; every point of the batch
that did not end with a finished file (the batch crashed, hung, or was refused as a whole)
runs again alone, so a batch never fails a point that would succeed alone. The program writes ``NAME.h5.partial`` and
renames it onto ``NAME.h5`` only when the run went to its end (complete or diverged), so an
existing ``NAME.h5`` is always a finished run. Its record (parameters, status, message,
the run's figures and the reductions) is written next to its HDF5 file as ``NAME.json``
(atomically) and returned. Tasks and records are plain data, so that any
``concurrent.futures`` executor carries them: local processes or MPI ranks.

A worker stopped by SIGTERM (the sweep stopped, a batch system's time limit) sends SIGTERM to
its program, which stops between two blocks of its loop with a checkpoint saved
(``NAME.h5.checkpoint``; not for members of a lockstep group), and SIGKILL after 30 s. When the
sweep resumes, a point with a checkpoint continues from it (``--restart``), bit for bit, instead
of starting over.
"""

from __future__ import annotations

import json
import math
import os
import re
import signal
import subprocess
import time
from pathlib import Path
from typing import Any, Optional

__all__ = ["run_point", "run_batch", "read_status", "FINISHED"]

#: HDF5 statuses of a run that has gone to its end (rerunning it gives the same file).
FINISHED = ("complete", "diverged")


def read_status(path: Path) -> Optional[str]:
    """The ``status`` attribute of a program's HDF5 output; None when there is no readable file."""
    if not path.is_file():
        return None
    try:
        import h5py

        with h5py.File(path, "r") as f:
            value = f.attrs.get("status")
    except Exception:  # a truncated file of an interrupted run, or not HDF5 at all
        return None
    if isinstance(value, bytes):
        value = value.decode("utf-8", "replace")
    return str(value).rstrip(" \x00") if value is not None else None


def _message(stderr: str, stdout: str, code: int) -> str:
    lines = [line.strip() for line in (stderr or "").splitlines() if line.strip()]
    if not lines:
        lines = [line.strip() for line in (stdout or "").splitlines() if line.strip()]
    text = lines[-1] if lines else ""
    if code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = f"signal {-code}"
        return f"the program was killed by {name}" + (f": {text}" if text else "")
    return text or f"the program exited with status {code}"


def _write_json(path: Path, record: dict[str, Any]) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(record, indent=1, allow_nan=False) + "\n", encoding="utf-8")
    os.replace(tmp, path)


def _clean(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


_ARMED = False
_PROGRAM: Optional[subprocess.Popen[str]] = None  # the program this worker is running, if any


#: Seconds a worker stopped by SIGTERM gives its program to stop politely before SIGKILL.
_GRACE = 30.0


def _on_term(signum: int, frame: Any) -> None:
    # Stop the running program, then this worker. The program is sent SIGTERM: it stops between
    # two blocks of its loop with its records flushed and a checkpoint saved (a point running
    # alone then continues from there on resume, bit for bit); SIGKILL after _GRACE seconds.
    # Nothing is raised: the handler runs between any two bytecodes, inside a weakref callback or
    # the pool's machinery too, where an exception surfaces as an "Exception ignored" traceback
    # and the worker goes on; nothing of ours needs cleaning (a point's record is written
    # atomically, and an unfinished point runs again on resume).
    program = _PROGRAM
    if program is not None and program.returncode is None:
        try:
            os.kill(program.pid, signal.SIGTERM)
            deadline = time.monotonic() + _GRACE
            while os.waitpid(program.pid, os.WNOHANG) == (0, 0):
                if time.monotonic() > deadline:
                    os.kill(program.pid, signal.SIGKILL)
                    break
                time.sleep(0.005)
        except OSError:  # ended (and reaped) already
            pass
    os._exit(128 + signum)


#: Longest single wait for the program (s). The wait polls with its time limit in milliseconds as
#: a C int (at most 2**31 - 1 ms, 24.8 days; a batch waits its points' limits together), and a
#: limit such as 1e300 s is beyond what Python's clock converts: a longer limit is waited in
#: pieces of this length, so any time limit works (one longer than the run is no limit).
_WAIT_PIECE = 86400.0


def _communicate(process: subprocess.Popen[str], timeout: Optional[float]) -> tuple[str, str]:
    """process.communicate(timeout=timeout) for any timeout > 0 (None: no limit), waited in pieces
    of at most _WAIT_PIECE s (communicate may be called again after TimeoutExpired without losing
    output); TimeoutExpired once ``timeout`` s have passed."""
    if timeout is None:
        return process.communicate()
    deadline = time.monotonic() + timeout
    while True:
        left = deadline - time.monotonic()
        try:
            return process.communicate(timeout=max(0.0, min(left, _WAIT_PIECE)))
        except subprocess.TimeoutExpired:
            if left <= _WAIT_PIECE:
                raise


def _run(command: list[str], *, timeout: Optional[float],
         cwd: Optional[str] = None) -> subprocess.CompletedProcess[str]:
    """subprocess.run(command, capture_output=True, text=True, stdin=DEVNULL, timeout=...), the
    running program known to _on_term; any timeout > 0 works (a 30-day limit, 1e300 s)."""
    global _PROGRAM
    with subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL,
                          text=True, cwd=cwd) as process:
        _PROGRAM = process
        try:
            stdout, stderr = _communicate(process, timeout)
        except subprocess.TimeoutExpired:
            process.kill()
            process.communicate()
            raise
        finally:
            _PROGRAM = None
    return subprocess.CompletedProcess(command, process.returncode, stdout, stderr)


def arm() -> None:
    """Make SIGTERM stop this worker and its running program (the sweep stops its workers so),
    and the sweep's own death send it (the local pool's initializer, and every point's start)."""
    global _ARMED
    if _ARMED:
        return
    import multiprocessing
    import threading

    # only in a worker process of a local pool (never in the caller's own process)
    parent = multiprocessing.parent_process()
    if parent is not None and threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _on_term)
        _die_with(parent.pid)
    _ARMED = True


def _die_with(parent: Optional[int]) -> None:
    """SIGTERM to this worker when the sweep's process dies (Linux's PR_SET_PDEATHSIG): a sweep
    killed with SIGKILL cannot stop its workers, which went on idle, holding the folder's lock
    (inherited when they were forked) so that no resume could start."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(1, int(signal.SIGTERM), 0, 0, 0) != 0:  # 1: PR_SET_PDEATHSIG
            return
    except (OSError, AttributeError):
        return  # not Linux: the workers end with their pool
    if parent is not None and os.getppid() != parent:  # the sweep died before the request
        os.kill(os.getpid(), signal.SIGTERM)


def run_point(task: dict[str, Any]) -> dict[str, Any]:
    """Run (or, with ``task['reduce_only']``, only reduce) one point; never raises an Exception."""
    arm()
    folder = Path(task["folder"])
    name = task["name"]
    nml, h5, record_path = folder / f"{name}.nml", folder / f"{name}.h5", folder / f"{name}.json"
    record = _base_record(task, folder, h5)
    start = time.perf_counter()
    try:
        if not task.get("reduce_only"):
            _run_program(task, nml, h5, record)
        else:
            record["wall_seconds"] = task.get("wall_seconds")
        if record["status"] != "failed" or task.get("reduce_only"):
            _read(task, h5, record)
    except Exception as exc:  # anything else: this point fails, the sweep goes on
        record["status"] = "failed"
        record["message"] = f"{type(exc).__name__}: {exc}"
    if record["wall_seconds"] is None and not task.get("reduce_only"):
        record["wall_seconds"] = time.perf_counter() - start
    try:
        _write_json(record_path, record)
    except OSError as exc:
        record["status"] = "failed"
        record["message"] = f"cannot write {record_path}: {exc}"
    return record


def _run_program(task: dict[str, Any], nml: Path, h5: Path, record: dict[str, Any]) -> None:
    from ..scene import Scene

    for stale in (h5, nml.with_suffix(".json")):
        if stale.exists():
            stale.unlink()
    Scene(**task["scene"]).to_namelist(nml)
    command = [task["program"], "run", str(nml), "-o", str(h5)]
    # a point a signal stopped (its checkpoint saved) continues from it, bit for bit
    resume = _resumable(h5)
    start = time.perf_counter()
    try:
        done = _run(command + ["--restart"] if resume else command, timeout=task.get("timeout"))
        if resume and done.returncode in (1, 4):  # a checkpoint of another scene, a partial file HDF5 refuses
            done = _run(command, timeout=task.get("timeout"))
    except subprocess.TimeoutExpired:
        record["wall_seconds"] = time.perf_counter() - start
        record["message"] = f"timed out after {task['timeout']:g} s (the run was stopped)"
        return
    except OSError as exc:
        record["message"] = f"cannot run {task['program']}: {exc}"
        return
    record["wall_seconds"] = time.perf_counter() - start
    if done.returncode == 0:
        record["status"] = "complete"
    elif done.returncode == 3 and h5.is_file():  # diverged: the program renamed its file into place
        record["status"] = "diverged"
        record["message"] = _message(done.stderr, done.stdout, done.returncode)
    else:
        record["message"] = _message(done.stderr, done.stdout, done.returncode)


def _resumable(h5: Path) -> bool:
    """Whether the point writing `h5` was stopped with a checkpoint saved (the program's
    OUT.h5.partial and OUT.h5.checkpoint): `beamstops run --restart` continues it."""
    return Path(f"{h5}.partial").is_file() and Path(f"{h5}.checkpoint").is_file()


def _base_record(task: dict[str, Any], folder: Path, h5: Path) -> dict[str, Any]:
    return {
        "point": task["index"], "params": task["params"], "spec_hash": task["spec_hash"],
        "status": "failed", "message": "", "cpu_seconds": None, "wall_seconds": None, "steps": None,
        "impacts": None, "max_violation": None, "dissipated": None,
        "dt": task["scene"]["dt"], "t_end": task["scene"]["t_end"], "record_every": task["scene"]["record_every"],
        "file": f"{folder.name}/{h5.name}", "reductions": {},
    }


#: The program's line on stderr that says how it grouped the scenes of a batch.
_GROUPS = re.compile(r"^beamstops: (\d+) scenes: (\d+) in (\d+) lockstep group")


def run_batch(tasks: list[dict[str, Any]]) -> dict[str, Any]:
    """Run points together as one ``beamstops run P1.nml P2.nml ...`` (the engine runs those
    that share A in lockstep), then reduce each; the points that did not end with a finished
    output run again one at a time (run_point). Returns ``{"records": [...], "lockstep": n}``
    with n the points the engine ran in lockstep groups. Never raises an Exception."""
    arm()
    if len(tasks) == 1:
        return {"records": [run_point(tasks[0])], "lockstep": 0}
    lockstep = 0
    records: list[dict[str, Any]] = []
    again: list[dict[str, Any]] = []
    start = time.perf_counter()
    try:
        from ..scene import Scene

        paths = []
        for task in tasks:
            folder = Path(task["folder"])
            nml, h5 = folder / f"{task['name']}.nml", folder / f"{task['name']}.h5"
            for stale in (h5, nml.with_suffix(".json")):
                if stale.exists():
                    stale.unlink()
            # the namelist names its output beside it: `beamstops run NNNNN.nml` in the points folder
            Scene(**{**task["scene"], "file": h5.name}).to_namelist(nml)
            paths.append(nml.name)
        timeout = tasks[0].get("timeout")
        # points a signal stopped (their checkpoints saved) continue from them, alone, bit for bit
        resume = any(_resumable(Path(task["folder"]) / f"{task['name']}.h5") for task in tasks)
        try:
            done = _run([tasks[0]["program"], "run", *paths, *(["--restart"] if resume else [])],
                        cwd=tasks[0]["folder"],
                        timeout=timeout * len(tasks) if timeout else None)
            for line in done.stderr.splitlines():
                match = _GROUPS.match(line)
                if match:
                    lockstep = int(match.group(2))
        except subprocess.TimeoutExpired:
            pass  # the points not finished run again alone, each with its own time limit
        wall = (time.perf_counter() - start) / len(tasks)
        for task in tasks:
            folder = Path(task["folder"])
            h5 = folder / f"{task['name']}.h5"
            if read_status(h5) not in FINISHED:
                again.append(task)
                continue
            record = _base_record(task, folder, h5)
            record["wall_seconds"] = wall
            try:
                _read(task, h5, record)
            except Exception as exc:
                record["status"] = "failed"
                record["message"] = f"{type(exc).__name__}: {exc}"
            try:
                _write_json(folder / f"{task['name']}.json", record)
            except OSError as exc:
                record["status"] = "failed"
                record["message"] = f"cannot write {task['name']}.json: {exc}"
            records.append(record)
    except Exception:  # anything else (e.g. the program cannot start): every point not done runs alone
        done_points = {r["point"] for r in records}
        again = [t for t in tasks if t["index"] not in done_points]
    for task in again:
        records.append(run_point(task))
    return {"records": records, "lockstep": lockstep}


#: The record series a point's reductions may read (the names of beamstops.Result).
_SERIES = ("t", "tip_u", "tip_v", "reaction", "energy", "work", "dissipated", "damped")
#: The root attributes they read.
_ATTRS = ("status", "message", "cpu_seconds", "max_violation", "steps", "impacts", "omega")


def _load_series(h5: Path) -> Any:
    """What a point's record and reductions read of the program's output: the root attributes they
    use and the record series, as :func:`beamstops.load` gives them (without the shock log,
    statistics, snapshots and the other attributes, which the summary does not use and which cost
    most of a full load)."""
    from types import SimpleNamespace

    import h5py
    import numpy as np

    from ..result import ARRAYS, _plain

    with h5py.File(h5, "r") as f:
        attrs = {name: _plain(f.attrs[name]) for name in _ATTRS if name in f.attrs}
        series = {name: np.asarray(f[ARRAYS[name]][()], dtype=np.float64) if ARRAYS[name] in f else np.empty(0)
                  for name in _SERIES}
    if "status" not in attrs:
        raise ValueError(f"{h5}: not a beamstops output (no status attribute)")
    return SimpleNamespace(attrs=attrs, **series)


def _read(task: dict[str, Any], h5: Path, record: dict[str, Any]) -> None:
    from .reductions import reduce

    result = _load_series(h5)
    attrs = result.attrs
    status = str(attrs.get("status"))
    if status not in FINISHED:
        record["status"] = "failed"
        record["message"] = record["message"] or f"the output says status {status!r}"
        return
    record["status"] = status
    if status != "complete":
        # the engine's own message, as the file holds it: the same whether the point ran alone (whose
        # stderr line also names the file's path) or in a batch
        record["message"] = str(attrs.get("message", "")) or record["message"]
    for key in ("cpu_seconds", "max_violation"):
        if key in attrs:
            record[key] = _clean(float(attrs[key]))
    for key in ("steps", "impacts"):
        if key in attrs:
            record[key] = int(attrs[key])
    if result.dissipated.size:
        record["dissipated"] = _clean(float(result.dissipated[-1]))
    if status == "complete":
        record["reductions"] = reduce(result, task["reductions"])

"""Running a sweep: its folder, the executor, resuming, progress and the summary table.

The folder of a sweep (``-o DIR``)::

    DIR/sweep.json       the manifest: the specification's hash, file, overrides, axes, reductions
    DIR/spec.toml        the specification's text, as given
    DIR/points/NNNNN.nml the point's scene (Scene.to_namelist), run as `beamstops run NNNNN.nml -o NNNNN.h5`,
                         or with others of its batch as `beamstops run NNNNN.nml MMMMM.nml ...` (in
                         DIR/points: then the namelist names its output, file = NNNNN.h5)
    DIR/points/NNNNN.h5  the program's own output
    DIR/points/NNNNN.json the point's record: parameters, status, message, figures, reductions
    DIR/summary.csv      one row per point (also summary.json, with full lists)
    DIR/.lock            held (flock) by the sweep running into DIR; holds its pid and host

Resuming: a point whose HDF5 says 'complete' (or 'diverged': the run went to its end)
and whose record belongs to this specification is skipped; every other point (no
output, an interrupted 'running' file, a failure) runs again. A folder holding another
specification's results (another hash) is refused, so results never mix.

One sweep at a time per folder: a sweep holds an exclusive lock (``fcntl.flock``) on
``DIR/.lock`` while it runs, with its process id and host written in it; a second sweep (or
a resume) into the same folder is refused with the first one's pid and host. The kernel
drops the lock when its process dies, so the lock of a dead sweep is taken over (with a note).
"""

from __future__ import annotations

import csv
import datetime
import errno
import io
import json
import math
import os
import re
import shutil
import signal
import socket
import sys
import sysconfig
import time
from concurrent.futures import Executor, Future, ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional, TextIO

from ..output_files import file_sha256
from .reductions import columns as reduction_columns
from .spec import Spec
from .worker import FINISHED, arm, read_status, run_batch

__all__ = ["run_sweep", "read_summary", "find_program", "make_executor", "Outcome", "FolderLock", "MANIFEST",
           "LOCK", "EXECUTORS"]

MANIFEST = "sweep.json"
#: The lock file of a sweep's folder.
LOCK = ".lock"
#: Executors of ``--executor``: auto (MPI under ``python -m mpi4py.futures``, else local), local, mpi.
EXECUTORS = ("auto", "local", "mpi")
_MANIFEST_FORMAT = 1


@dataclass
class Outcome:
    """What a sweep did."""

    folder: Path
    total: int
    complete: int
    diverged: int
    failed: int
    ran: int
    """Points run (or reduced again) by this call."""
    skipped: int
    """Points finished by an earlier call."""
    wall_seconds: float
    executor: str
    lockstep: int = 0
    """Points the engine ran in lockstep groups in this call (batches of ``[sweep] lockstep``)."""

    @property
    def summary(self) -> Path:
        return self.folder / "summary.csv"


# ---------------------------------------------------------------------- program and executor


def find_program(explicit: Optional[str] = None) -> str:
    """The `beamstops` program: --program, $BEAMSTOPS_PROGRAM, next to this Python's scripts, or on PATH."""
    candidates = [explicit] if explicit else []
    if not explicit:
        if os.environ.get("BEAMSTOPS_PROGRAM"):
            candidates.append(os.environ["BEAMSTOPS_PROGRAM"])
        candidates.append(str(Path(sysconfig.get_path("scripts")) / "beamstops"))
        candidates.append(shutil.which("beamstops") or "")
    for candidate in candidates:
        if candidate and os.path.isfile(candidate) and os.access(candidate, os.X_OK):
            return os.path.abspath(candidate)
    if explicit:
        raise ValueError(f"--program {explicit}: no such executable")
    raise ValueError("cannot find the beamstops program: install the package (pip install .) "
                     "or name it with --program")


def _under_mpi_futures() -> bool:
    """Whether this process is rank 0 of ``python -m mpi4py.futures`` (workers wait on the other ranks)."""
    core = sys.modules.get("mpi4py.futures._core")
    return core is not None and getattr(core, "SharedPool", None) is not None


def _mpi_world_size_from_env() -> int:
    for key in ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS"):
        try:
            return int(os.environ[key])
        except (KeyError, ValueError):
            continue
    return 1


def _check_not_plain_mpi() -> None:
    if not _under_mpi_futures() and _mpi_world_size_from_env() > 1:
        raise ValueError("started as one of several MPI ranks: every rank would run the whole sweep; run "
                         "`mpiexec -n N python -m mpi4py.futures -m beamstops sweep ...` (rank 0 runs the "
                         "sweep, the other ranks are its workers)")


def make_executor(kind: str = "auto", jobs: Optional[int] = None) -> tuple[Executor, str, int]:
    """A concurrent.futures executor, its description and its number of workers.

    ``local``: a ProcessPoolExecutor of ``jobs`` processes (default: every core).
    ``mpi``: mpi4py's MPIPoolExecutor; under ``mpiexec -n N python -m mpi4py.futures -m
    beamstops sweep ...`` its workers are the ranks 1 … N−1 (rank 0 runs this code).
    ``auto``: mpi under ``python -m mpi4py.futures``, local otherwise.
    """
    under = _under_mpi_futures()
    if kind == "auto":
        kind = "mpi" if under else "local"
    _check_not_plain_mpi()
    if jobs is not None and jobs < 1:
        raise ValueError(f"-j {jobs}: the number of workers must be >= 1")
    if kind == "local":
        workers = jobs or os.cpu_count() or 1
        return (ProcessPoolExecutor(max_workers=workers, initializer=arm),
                f"{workers} local process{'es' if workers > 1 else ''}", workers)
    if kind == "mpi":
        try:
            from mpi4py import MPI
            from mpi4py.futures import MPIPoolExecutor
        except ImportError as exc:
            raise ValueError(f"--executor mpi needs mpi4py ({exc}); install it with `pip install mpi4py` "
                             "over an MPI library (Debian: openmpi-bin libopenmpi-dev)") from None
        if under:
            workers = max(1, MPI.COMM_WORLD.Get_size() - 1)
            where = (f"{workers} MPI worker rank{'s' if workers > 1 else ''}" if MPI.COMM_WORLD.Get_size() > 1
                     else "MPI with one rank (tasks run on rank 0)")
            return MPIPoolExecutor(), where, workers
        workers = jobs or os.cpu_count() or 1
        return _spawned(MPIPoolExecutor, workers), f"{workers} spawned MPI workers", workers
    raise ValueError(f"--executor {kind}: allowed: {', '.join(EXECUTORS)}")


#: Seconds the spawned MPI workers of ``--executor mpi`` (outside mpiexec) have to answer a first task.
SPAWN_TIMEOUT = 60.0

_MPIEXEC = "mpiexec -n N python -m mpi4py.futures -m beamstops sweep ..."


def _spawned(factory: Any, workers: int) -> Executor:
    """An MPIPoolExecutor of ``workers`` spawned workers that answered a first task.

    Outside mpiexec the pool spawns its workers (MPI_Comm_spawn) in a thread of its own; when
    MPI cannot spawn them (Open MPI: "not enough slots"), that thread dies with MPI_ERR_SPAWN and
    every task waits forever. So a first task is sent before any point: the thread's failure (or
    no answer within :data:`SPAWN_TIMEOUT` s) is a ValueError naming the documented way instead.
    """
    import threading

    failures: list[BaseException] = []
    previous = threading.excepthook

    def catch(args: Any) -> None:  # the pool's thread: keep its traceback off stderr, report it below
        if args.thread is not threading.main_thread() and args.exc_value is not None:
            failures.append(args.exc_value)
        else:
            previous(args)

    threading.excepthook = catch
    pool = factory(max_workers=workers)
    try:
        probe = pool.submit(int, 0)
        deadline = time.monotonic() + SPAWN_TIMEOUT
        while not failures and not probe.done() and time.monotonic() < deadline:
            time.sleep(0.05)
    finally:
        threading.excepthook = previous
    error = probe.exception() if probe.done() and not probe.cancelled() else None
    if probe.done() and not probe.cancelled() and error is None and not failures:
        return pool
    try:
        pool.shutdown(wait=False, cancel_futures=True)
    except Exception:
        pass
    failure = failures[0] if failures else error
    why = (" ".join(f"{type(failure).__name__}: {failure}".split()) if failure is not None
           else f"no worker answered within {SPAWN_TIMEOUT:g} s")
    raise ValueError(f"--executor mpi: MPI could not start {workers} worker{'s' if workers > 1 else ''} from this "
                     f"process ({why}); run the sweep under MPI instead: `{_MPIEXEC}` (rank 0 runs the sweep, "
                     "the other N-1 ranks are its workers), or use --executor local")


# ---------------------------------------------------------------------- folder


def _manifest(spec: Spec, program: str) -> dict[str, Any]:
    from .. import version

    # the program's sha256: a rebuilt engine may differ at round-off, which impacts amplify
    return {"format": _MANIFEST_FORMAT, "spec_hash": spec.hash, "spec_file": os.path.abspath(spec.path),
            "program": program, "program_sha256": file_sha256(program),
            "overrides": list(spec.overrides), "points": len(spec.points), "mode": spec.mode,
            "axes": spec.axes, "zip": spec.zip_groups, "periods": spec.periods, "reductions": spec.reductions,
            "base": spec.base, "description": spec.description, "engine_version": version(),
            "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}


def check_folder(out: Path) -> None:
    """Refuse a folder that is not a sweep's (a file, or a folder holding other things)."""
    if (out / MANIFEST).is_file():
        return
    if out.exists() and (not out.is_dir() or any(p.name != LOCK for p in out.iterdir())):
        raise ValueError(f"{out}: exists and is not a sweep folder (no {MANIFEST}); use another -o")


class FolderLock:
    """The exclusive lock of a sweep's folder: ``flock`` on ``DIR/.lock``, which holds the
    holder's pid and host. :meth:`acquire` raises ValueError naming the holder when another
    process holds it; a lock left by a dead process (the kernel released it) is taken over,
    and :attr:`stale` then says whose it was. On a file system without ``flock`` (ENOLCK,
    EOPNOTSUPP, ENOSYS) the pid and host in the file decide: a running process of this host,
    or any process of another host, holds the folder."""

    def __init__(self, folder: Path):
        self.path = Path(folder) / LOCK
        self.fd: Optional[int] = None
        self.stale = ""
        #: The file system refused flock: the lock is the pid in the file only.
        self.unlocked = False

    def acquire(self) -> "FolderLock":
        import fcntl

        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:  # the folder cannot be made or written: say which, not '[Errno 2] ...'
            raise ValueError(f"{self.path.parent}: the sweep's output folder cannot be created or written "
                             f"({exc.strerror or exc}{': ' + str(exc.filename) if exc.filename else ''}); "
                             "allowed: -o a folder in a place you can write") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            holder = _read_holder(fd)
            if exc.errno in (errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOSYS) and not _alive_here(holder):
                self.unlocked = True  # a file system without locks: the pid written in the file decides
            else:
                os.close(fd)
                raise ValueError(f"{self.path.parent}: another sweep is running into this folder "
                                 f"({holder or 'its process id is not written yet'}); wait for it to end, or stop "
                                 "it, before running or resuming a sweep here") from None
        self.stale = _read_holder(fd)
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"pid {os.getpid()} host {socket.gethostname()}\n".encode(), 0)
        self.fd = fd
        return self

    def release(self) -> None:
        import fcntl

        if self.fd is None:
            return
        try:
            os.ftruncate(self.fd, 0)
            # explicitly: local workers forked while the lock was held share its descriptor
            fcntl.flock(self.fd, fcntl.LOCK_UN)
        except OSError:
            pass
        os.close(self.fd)
        self.fd = None

    def __enter__(self) -> "FolderLock":
        return self.acquire()

    def __exit__(self, *exc: Any) -> None:
        self.release()


def _alive_here(holder: str) -> bool:
    """Whether ``pid N host H`` names a running process of this host (unknown hosts: assumed running)."""
    words = holder.split()
    if len(words) != 4 or words[0] != "pid" or words[2] != "host":
        return False
    if words[3] != socket.gethostname():
        return True
    try:
        os.kill(int(words[1]), 0)
    except ProcessLookupError:
        return False
    except (PermissionError, ValueError):
        return True
    return True


def _read_holder(fd: int) -> str:
    """``pid N host H`` as written by the lock's holder ('' when empty)."""
    try:
        return os.pread(fd, 256, 0).decode("utf-8", "replace").strip()
    except OSError:
        return ""


def prepare_folder(spec: Spec, out: Path, program: str) -> tuple[Path, Optional[str]]:
    """Create or reopen the sweep's folder; a note when the engine changed since the last call."""
    out = Path(out)
    manifest = out / MANIFEST
    note = None
    if manifest.is_file():
        old = _read_manifest(manifest)
        if old is None:
            raise ValueError(f"{out}: {MANIFEST} is unreadable; this is not a sweep folder to resume")
        old_hash = old["spec_hash"]
        if old_hash != spec.hash:
            raise ValueError(f"{out}: holds the results of another specification ({old.get('spec_file')}"
                             f"{_with_sets(old.get('overrides'))}, hash {old_hash[:12]}); {spec.path}"
                             f"{_with_sets(spec.overrides)} has hash {spec.hash[:12]} (--set values are part of "
                             f"the specification). Use another -o, or remove {out} to start again")
        from .. import version

        if old.get("engine_version") != version() or old.get("program_sha256") != file_sha256(program):
            note = (f"the points done before ran with another build of the engine ({old.get('engine_version')}, "
                    f"{old.get('program')}); this is {version()}, {program}: results may differ at round-off, "
                    "which impacts amplify; use a new folder for one build throughout")
    else:
        check_folder(out)
        (out / "points").mkdir(parents=True, exist_ok=True)
        (out / "spec.toml").write_text(spec.text, encoding="utf-8")
        tmp = manifest.with_name(MANIFEST + ".tmp")
        tmp.write_text(json.dumps(_manifest(spec, program), indent=1) + "\n", encoding="utf-8")
        os.replace(tmp, manifest)
    (out / "points").mkdir(exist_ok=True)
    return out, note


#: The manifest's entries a resume reads, and their types (sweep.json as _manifest writes it).
_MANIFEST_TYPES: dict[str, type] = {"format": int, "spec_hash": str, "spec_file": str, "program": str,
                                    "program_sha256": str, "overrides": list, "engine_version": str}
_HASH = re.compile(r"^[0-9a-f]{64}$")


def _json_object(path: Path) -> Optional[dict[str, Any]]:
    """The JSON object a file holds, or None when it cannot be read, is not JSON (or nests too
    deep) or holds something else."""
    try:
        content = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    return content if isinstance(content, dict) else None


def _read_manifest(path: Path) -> Optional[dict[str, Any]]:
    """A folder's sweep.json, or None when it is not one _manifest wrote: not JSON, not an object,
    an entry a resume reads missing or of another type (``"spec_hash": 5``), another format."""
    old = _json_object(path)
    if old is None:
        return None
    for key, kind in _MANIFEST_TYPES.items():
        if not isinstance(old.get(key), kind) or isinstance(old.get(key), bool):
            return None
    if old["format"] != _MANIFEST_FORMAT or not _HASH.match(old["spec_hash"]):
        return None
    if not all(isinstance(item, str) for item in old["overrides"]):
        return None
    return old


def _with_sets(overrides: Any) -> str:
    """`` with --set A --set B`` for a specification's overrides, `` without --set`` for none."""
    if not isinstance(overrides, (list, tuple)) or not overrides:
        return " without --set"
    return " with " + " ".join(f"--set {item}" for item in overrides)


def _task(spec: Spec, point: Any, folder: Path, program: str, timeout: Optional[float]) -> dict[str, Any]:
    return {"index": point.index, "name": point.name, "params": point.params, "scene": point.scene.to_dict(),
            "folder": str(folder / "points"), "program": program, "timeout": timeout,
            "reductions": spec.reductions, "spec_hash": spec.hash}


def plan(spec: Spec, folder: Path, program: str, timeout: Optional[float]
         ) -> tuple[dict[int, dict[str, Any]], list[dict[str, Any]]]:
    """Records of the points finished before, and the tasks left (longest runs first)."""
    done: dict[int, dict[str, Any]] = {}
    tasks = []
    for point in spec.points:
        h5 = folder / "points" / f"{point.name}.h5"
        status = read_status(h5)
        task = _task(spec, point, folder, program, timeout)
        if status in FINISHED:
            record = _read_record(folder / "points" / f"{point.name}.json")
            if record and record.get("spec_hash") == spec.hash and record.get("status") == status:
                done[point.index] = record
                continue
            task["reduce_only"] = True  # the run finished but its record was not written
            if record:
                task["wall_seconds"] = record.get("wall_seconds")
        tasks.append(task)
    costs = {point.index: point.cost() for point in spec.points}
    tasks.sort(key=lambda t: (0.0 if t.get("reduce_only") else -costs[t["index"]], t["index"]))
    return done, tasks


def batches(tasks: list[dict[str, Any]], lockstep: int, workers: int) -> list[list[dict[str, Any]]]:
    """The tasks in batches of `beamstops run` processes: consecutive runs (in the order of
    ``plan``), at most ``lockstep`` per batch and no more than keep every worker busy; a point
    only to reduce again goes alone. Which points of a batch share A the engine decides."""
    runs = [t for t in tasks if not t.get("reduce_only")]
    out: list[list[dict[str, Any]]] = [[t] for t in tasks if t.get("reduce_only")]
    size = max(1, min(lockstep, math.ceil(len(runs) / max(1, workers))))
    out.extend(runs[i:i + size] for i in range(0, len(runs), size))
    return out


#: The figures of a point's record (numbers, or null for none).
_RECORD_NUMBERS = ("cpu_seconds", "wall_seconds", "steps", "impacts", "max_violation", "dissipated", "dt", "t_end",
                   "record_every")


def _read_record(path: Path) -> Optional[dict[str, Any]]:
    """A point's record (NNNNN.json), or None when it is not one the worker wrote (then the point's
    finished output is reduced again): its figures numbers or null, its message a text, its
    reductions an object."""
    record = _json_object(path)
    if record is None:
        return None
    for key in _RECORD_NUMBERS:
        value = record.get(key)
        if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))):
            return None
    if not isinstance(record.get("message", ""), str) or not isinstance(record.get("reductions", {}), dict):
        return None
    return record


# ---------------------------------------------------------------------- progress


def _clock(seconds: float) -> str:
    if not math.isfinite(seconds):
        return "?"
    seconds = int(round(seconds))
    hours, rest = divmod(seconds, 3600)
    return f"{hours}:{rest // 60:02d}:{rest % 60:02d}" if hours else f"{rest // 60}:{rest % 60:02d}"


#: The progress line: work done (each point weighted by its cost) and the points.
_BAR = "{desc}: {percentage:3.0f}%|{bar}| {elapsed} elapsed, ~{remaining} left{postfix}"


class Progress:
    """Points done, failed and the time left (from the cost of the points done): a tqdm bar on
    a terminal; on a log file (a batch job), the same text, one line every ``interval`` seconds."""

    def __init__(self, total: int, skipped: int, cost: float, stream: Optional[TextIO], interval: float = 10.0):
        self.total, self.skipped, self.cost = total, skipped, cost
        self.done = self.failed = 0
        self.done_cost = 0.0
        self.stream = stream
        self.tty = bool(stream is not None and getattr(stream, "isatty", lambda: False)())
        self.interval = interval
        self.start = time.perf_counter()
        self.last = -math.inf
        self.bar: Any = None
        if self.tty:
            from tqdm import tqdm

            self.bar = tqdm(total=cost, desc="sweep", bar_format=_BAR, file=stream, dynamic_ncols=True,
                            mininterval=0.2, postfix=self.points())

    def points(self) -> str:
        return f"{self.skipped + self.done}/{self.total} points done, {self.failed} failed"

    def line(self) -> str:
        from tqdm import tqdm

        return tqdm.format_meter(min(self.done_cost, self.cost), self.cost, time.perf_counter() - self.start,
                                 ncols=80, prefix="sweep", ascii=True, bar_format=_BAR, postfix=self.points())

    def show(self, force: bool = False) -> None:
        if self.stream is None:
            return
        if self.bar is not None:
            self.bar.set_postfix_str(self.points(), refresh=force)
            return
        now = time.perf_counter()
        if force or now - self.last >= self.interval:
            self.stream.write(self.line() + "\n")
            self.stream.flush()
            self.last = now

    def say(self, text: str) -> None:
        if self.stream is None:
            return
        if self.bar is not None:
            self.bar.write(text, file=self.stream)
            return
        self.stream.write(text + "\n")
        self.stream.flush()

    def update(self, record: dict[str, Any], cost: float) -> None:
        self.done += 1
        self.done_cost += cost
        if record.get("status") == "failed":
            self.failed += 1
        if self.bar is not None:
            self.bar.set_postfix_str(self.points(), refresh=False)
            self.bar.update(cost)
        else:
            self.show()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.set_postfix_str(self.points(), refresh=True)
            self.bar.close()
            self.bar = None
            return
        self.show(force=True)


# ---------------------------------------------------------------------- summary


def _columns(spec: Spec) -> list[str]:
    names = ["point", *spec.axes, "status", "cpu_seconds", "wall_seconds", "steps", "impacts", "max_violation",
             "dissipated"]
    for key in ("dt", "t_end", "record_every"):
        if key not in spec.axes:
            names.append(key)
    for name, reduction in spec.reductions.items():
        names.extend(reduction_columns(name, reduction))
    return names + ["message", "file"]


def _row(spec: Spec, index: int, record: Optional[dict[str, Any]]) -> dict[str, Any]:
    point = spec.points[index]
    row: dict[str, Any] = {"point": index, **point.params}
    # the point's time grid is its scene's (what it runs, whatever became of it: a failed point's too)
    for key in ("dt", "t_end", "record_every"):
        if key not in point.params:
            row[key] = getattr(point.scene, key)
    row["file"] = f"points/{point.name}.h5"
    if record is None:
        row["status"] = "pending"
        return row
    for key in ("status", "cpu_seconds", "wall_seconds", "steps", "impacts", "max_violation", "dissipated",
                "message"):
        row[key] = record.get(key)
    row.update(record.get("reductions") or {})
    return row


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, list):
        return " ".join(_cell(v) for v in value)
    return str(value)


def write_summary(spec: Spec, folder: Path, records: dict[int, dict[str, Any]]) -> Path:
    """summary.csv and summary.json of every point (status 'pending' for those not run yet)."""
    names = _columns(spec)
    # every row holds every column (None for none: a pending, failed or diverged point has no reductions)
    rows = [dict.fromkeys(names) | _row(spec, point.index, records.get(point.index)) for point in spec.points]
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow(names)
    for row in rows:
        writer.writerow([_cell(row.get(name)) for name in names])
    csv_path = folder / "summary.csv"
    _replace(csv_path, text.getvalue())
    _replace(folder / "summary.json", json.dumps({"spec_hash": spec.hash, "spec_file": os.path.abspath(spec.path),
                                                   "columns": names, "points": rows}, indent=1) + "\n")
    return csv_path


def _replace(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)


def read_summary(folder: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """The rows of a sweep's summary.json (one dict per point, lists for strobe reductions)."""
    path = Path(folder) / "summary.json"
    try:
        return list(json.loads(path.read_text(encoding="utf-8"))["points"])
    except FileNotFoundError:
        raise FileNotFoundError(f"{path}: no such file (run the sweep first)") from None
    except (ValueError, KeyError, TypeError) as exc:
        raise ValueError(f"{path}: not a sweep summary ({exc})") from None


# ---------------------------------------------------------------------- the sweep


class _Stop(KeyboardInterrupt):
    """SIGTERM (a batch system's time limit): stop like Ctrl-C, keeping what is done."""


def _on_term(signum: int, frame: Any) -> None:
    raise _Stop()


def run_sweep(spec: Spec, out: str | os.PathLike[str], *, executor: str = "auto", jobs: Optional[int] = None,
              program: Optional[str] = None, timeout: Optional[float] = None, stream: Optional[TextIO] = sys.stderr,
              interval: float = 10.0) -> Outcome:
    """Run every point of ``spec`` not finished yet in ``out``, then write the summary.

    ``stream`` gets the progress and the notes (None: silent). A KeyboardInterrupt (or
    SIGTERM) stops the sweep after writing the summary of what is done; running the same
    call again resumes it. The folder is locked while the sweep runs: another sweep into it
    is refused (ValueError) with this one's pid and host.
    """
    _check_not_plain_mpi()
    if jobs is not None and jobs < 1:  # before the folder is made: a refused sweep writes nothing
        raise ValueError(f"-j {jobs}: the number of workers must be >= 1")
    program = find_program(program)
    check_folder(Path(out))  # before the lock file is written into it
    with FolderLock(Path(out)) as lock:
        if lock.stale and stream is not None:
            stream.write(f"sweep: note: took over the lock of a sweep that is no longer running ({lock.stale})\n")
        return _run_sweep(spec, Path(out), executor=executor, jobs=jobs, program=program, timeout=timeout,
                          stream=stream, interval=interval)


def _run_sweep(spec: Spec, out: Path, *, executor: str, jobs: Optional[int], program: str,
               timeout: Optional[float], stream: Optional[TextIO], interval: float) -> Outcome:
    timeout = timeout if timeout is not None else spec.timeout
    folder, note = prepare_folder(spec, Path(out), program)
    done, tasks = plan(spec, folder, program, timeout)
    records: dict[int, dict[str, Any]] = dict(done)
    costs = {point.index: point.cost() for point in spec.points}
    write_summary(spec, folder, records)

    def say(text: str) -> None:
        if stream is not None:
            stream.write(text + "\n")
            stream.flush()

    start = time.perf_counter()
    description = "nothing to run"
    in_lockstep = 0
    if tasks:
        pool, description, workers = make_executor(executor, jobs)
        work = batches(tasks, spec.lockstep, workers)
        grouped = (f" in {len(work)} batches of up to {max(len(b) for b in work)} (lockstep = {spec.lockstep})"
                   if len(work) < len(tasks) else "")
        say(f"sweep: {len(spec.points)} points in {folder} (spec {spec.hash[:12]}): {len(done)} done before, "
            f"{len(tasks)} to run on {description}{grouped}")
        if note:
            say(f"sweep: note: {note}")
        progress = Progress(len(spec.points), len(done), sum(costs[t["index"]] for t in tasks), stream, interval)
        progress.show(force=True)
        previous = None
        try:
            previous = signal.signal(signal.SIGTERM, _on_term)
        except ValueError:  # not the main thread
            pass
        futures: dict[Future[dict[str, Any]], list[dict[str, Any]]] = {}
        last_summary = time.perf_counter()
        try:
            for batch in work:
                futures[pool.submit(run_batch, batch)] = batch
            for future in as_completed(futures):
                batch = futures[future]
                try:
                    result = future.result()
                    got = result["records"]
                    in_lockstep += int(result.get("lockstep", 0))
                except Exception as exc:  # the worker itself died; its points fail, the sweep goes on
                    got = [{"point": task["index"], "params": task["params"], "status": "failed",
                            "message": f"worker failed: {type(exc).__name__}: {exc}", "reductions": {}}
                           for task in batch]
                for task in batch:
                    record = next((r for r in got if r.get("point") == task["index"]), None) or {
                        "point": task["index"], "params": task["params"], "status": "failed",
                        "message": "the worker returned no record", "reductions": {}}
                    records[task["index"]] = record
                    if record.get("status") == "failed":
                        progress.say(f"sweep: point {task['index']} ({_params(task['params'])}) failed: "
                                     f"{record.get('message', '')}")
                    progress.update(record, costs[task["index"]])
                if time.perf_counter() - last_summary > 60:
                    write_summary(spec, folder, records)
                    last_summary = time.perf_counter()
        except KeyboardInterrupt:
            _stop(pool, futures)
            write_summary(spec, folder, records)
            progress.close()
            say(f"sweep: interrupted with {len(records)}/{len(spec.points)} points done; run the same command "
                "again to resume")
            raise
        finally:
            if previous is not None:
                signal.signal(signal.SIGTERM, previous)
        pool.shutdown(wait=True)
        progress.close()
    write_summary(spec, folder, records)
    statuses = [r.get("status") for r in records.values()]
    outcome = Outcome(folder=folder, total=len(spec.points), complete=statuses.count("complete"),
                      diverged=statuses.count("diverged"), failed=statuses.count("failed"), ran=len(tasks),
                      skipped=len(done), wall_seconds=time.perf_counter() - start, executor=description,
                      lockstep=in_lockstep)
    cpu = sum(r.get("cpu_seconds") or 0.0 for i, r in records.items() if i not in done)
    say(f"sweep: {outcome.total} points: {outcome.complete} complete, {outcome.diverged} diverged, "
        f"{outcome.failed} failed ({outcome.ran} run now, {outcome.skipped} before; {_clock(outcome.wall_seconds)} "
        f"wall, {cpu:.1f} s engine CPU{f'; {in_lockstep} ran in lockstep' if in_lockstep else ''}); "
        f"summary: {outcome.summary}")
    return outcome


def _stop(pool: Executor, futures: dict[Future[Any], Any]) -> None:
    """Cancel what has not started and stop the local workers (each kills its running program)."""
    for future in futures:
        future.cancel()
    handles = list((getattr(pool, "_processes", None) or {}).values()) if isinstance(pool, ProcessPoolExecutor) else []
    try:
        pool.shutdown(wait=False, cancel_futures=True)
    except Exception:
        pass
    for handle in handles:
        if handle is not None and handle.is_alive():
            handle.terminate()


def _params(params: dict[str, Any]) -> str:
    return ", ".join(f"{k}={v!r}" for k, v in params.items())

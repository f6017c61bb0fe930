"""``--executor mpi`` outside mpiexec, when MPI cannot spawn its workers: one line, exit status 1.

mpi4py's MPIPoolExecutor spawns its workers in a thread of its own; when the spawn fails
(Open MPI: "not enough slots", MPI_ERR_SPAWN) that thread dies and every task waits forever.
The tests put a stand-in for mpi4py in sys.modules (no MPI needed): its pool's thread raises as
the spawn does, or never answers.
"""

from __future__ import annotations

import sys
import threading
import types
from collections.abc import Callable
from concurrent.futures import Future
from pathlib import Path
from typing import Any

import pytest

from beamstops.sweep import runner

SPEC = """
[scene]
elements = 4
dt = 1e-4
t_end = 0.01
[axes]
omega = [8.0, 20.0]
"""


class _FailingSpawn:
    """A pool whose manager thread dies as mpi4py's does when MPI_Comm_spawn fails."""

    answers = False

    def __init__(self, max_workers: int | None = None) -> None:
        self.max_workers = max_workers

    def submit(self, fn: Callable[..., Any], *args: Any) -> Future[Any]:
        if not self.answers:
            threading.Thread(target=self._spawn, daemon=True).start()
        return Future()  # never done: the tasks wait for workers that never come

    def _spawn(self) -> None:
        raise RuntimeError("MPI_ERR_SPAWN: could not spawn processes")

    def shutdown(self, wait: bool = True, cancel_futures: bool = False) -> None:
        pass


class _SilentSpawn(_FailingSpawn):
    """A pool whose workers never answer, without an error."""

    answers = True


def _fake_mpi4py(monkeypatch: pytest.MonkeyPatch, pool: type) -> None:
    package = types.ModuleType("mpi4py")
    mpi = types.ModuleType("mpi4py.MPI")
    futures = types.ModuleType("mpi4py.futures")
    futures.MPIPoolExecutor = pool  # type: ignore[attr-defined]
    package.MPI = mpi  # type: ignore[attr-defined]
    package.futures = futures  # type: ignore[attr-defined]
    for name, module in (("mpi4py", package), ("mpi4py.MPI", mpi), ("mpi4py.futures", futures)):
        monkeypatch.setitem(sys.modules, name, module)
    monkeypatch.delitem(sys.modules, "mpi4py.futures._core", raising=False)


def _in_thread(call: Callable[[], Any], seconds: float = 30.0) -> Any:
    """``call()`` in a daemon thread; fails the test (instead of hanging it) if it does not return."""
    out: dict[str, Any] = {}

    def target() -> None:
        try:
            out["value"] = call()
        except BaseException as exc:  # noqa: BLE001 (handed to the test)
            out["error"] = exc

    thread = threading.Thread(target=target, daemon=True)
    thread.start()
    thread.join(seconds)
    assert not thread.is_alive(), f"still waiting after {seconds} s: the sweep hangs"
    if "error" in out:
        raise out["error"]
    return out["value"]


def test_a_failed_spawn_is_one_line_naming_mpiexec(monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str],
                                                   write_spec: Callable[..., Path]) -> None:
    from beamstops import cli

    _fake_mpi4py(monkeypatch, _FailingSpawn)
    spec = write_spec(SPEC)
    status = _in_thread(lambda: cli.main(["sweep", str(spec), "-o", str(tmp_path / "out"), "--executor", "mpi",
                                          "-j", "2", "-q"]))
    assert status == 1
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    assert err.startswith("beamstops: error: --executor mpi: MPI could not start 2 workers"), err
    assert "MPI_ERR_SPAWN" in err and "`mpiexec -n N python -m mpi4py.futures -m beamstops sweep ...`" in err
    assert "Traceback" not in err


def test_workers_that_never_answer_time_out(monkeypatch: pytest.MonkeyPatch) -> None:
    _fake_mpi4py(monkeypatch, _SilentSpawn)
    monkeypatch.setattr(runner, "SPAWN_TIMEOUT", 0.3, raising=False)
    with pytest.raises(ValueError, match=r"no worker answered within 0\.3 s.*mpiexec -n N python -m mpi4py\.futures"):
        _in_thread(lambda: runner.make_executor("mpi", 3), seconds=10)


def test_the_help_states_the_exit_status_of_a_bad_option(capsys: pytest.CaptureFixture[str],
                                                         write_spec: Callable[..., Path], tmp_path: Path) -> None:
    from beamstops import cli

    with pytest.raises(SystemExit) as done:
        cli.main(["sweep", "--help"])
    assert done.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "2 a bad command-line option" in text and "1 a bad specification" in text
    assert "option or folder" not in text
    spec = write_spec(SPEC)
    for bad in (["-j", "0"], ["--timeout", "-1"], ["--interval", "0"], ["--executor", "threads"], ["--no-such"]):
        with pytest.raises(SystemExit) as done:
            cli.main(["sweep", str(spec), "-o", str(tmp_path / "out"), *bad])
        assert done.value.code == 2, bad
    assert not (tmp_path / "out").exists()
    assert cli.main(["sweep", str(spec), "-o", str(tmp_path / "out"), "--set", "scene.nonsense=1"]) == 1

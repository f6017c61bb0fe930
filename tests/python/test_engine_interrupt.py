"""Ctrl-C (SIGINT) during an in-memory run stops the engine's loop within a block and raises
KeyboardInterrupt at once, instead of after the whole run; SIGTERM keeps its usual effect (raised
again once the loop has stopped); a thread other than the main one leaves the signals alone. The
studies' own engine calls (the engine's states at chosen steps, the three-level form) stop the
same way."""

from __future__ import annotations

import signal
import subprocess
import sys
import time

import pytest

# A run of some 4 minutes at least (2e9 steps of the paper's scene at 0.12 us or more a step), a
# record every 1e6 steps: a run that did not stop would outlast the tests' 60 s wait.
SCRIPT = """
import sys, threading, beamstops
scene = beamstops.Scene(dt=1e-6, t_end=2000.0, record_every=1000000)
where = sys.argv[1]
if where == "states":
    from beamstops.studies import common
    print("running", flush=True)
    try:
        common.states(scene, [2000.0])
    except KeyboardInterrupt:
        print("interrupted", flush=True)
        sys.exit(7)
elif where == "three_level":
    from beamstops.studies import common
    print("running", flush=True)
    try:
        common.run_three_level(scene.replace(law="none"))
    except KeyboardInterrupt:
        print("interrupted", flush=True)
        sys.exit(7)
elif where == "thread":
    worker = threading.Thread(target=beamstops.run, args=(scene,), daemon=True)
    worker.start()
    print("running", flush=True)
    try:
        worker.join()
    except KeyboardInterrupt:
        print("main thread interrupted", flush=True)
        sys.exit(7)
else:
    print("running", flush=True)
    try:
        beamstops.run(scene)
    except KeyboardInterrupt:
        print("interrupted", flush=True)
        sys.exit(7)
"""


def finish(process: subprocess.Popen[str]) -> tuple[str, str]:
    """The process's output once it has ended (killed, and the test failed, after 60 s)."""
    try:
        return process.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        process.kill()
        process.communicate()
        pytest.fail("the run went on after the signal")


def start(where: str) -> subprocess.Popen[str]:
    process = subprocess.Popen([sys.executable, "-c", SCRIPT, where], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True)
    assert process.stdout is not None
    assert process.stdout.readline() == "running\n"
    time.sleep(0.5)  # into the time loop
    return process


@pytest.mark.parametrize("where", ["main", "thread", "states", "three_level"])
def test_ctrl_c_interrupts_an_in_memory_run_promptly(where: str) -> None:
    process = start(where)
    process.send_signal(signal.SIGINT)
    out, err = finish(process)
    assert process.returncode == 7, err
    assert out == ("main thread interrupted\n" if where == "thread" else "interrupted\n"), err


def test_sigterm_keeps_its_usual_effect() -> None:
    process = start("main")
    process.send_signal(signal.SIGTERM)
    finish(process)
    assert process.returncode == -signal.SIGTERM


@pytest.mark.parametrize("where", ["states", "three_level"])
def test_sigterm_ends_the_studies_calls(where: str) -> None:
    process = start(where)
    process.send_signal(signal.SIGTERM)
    finish(process)
    assert process.returncode == -signal.SIGTERM

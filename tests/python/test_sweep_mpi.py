"""The MPI executor (mpi4py.futures under mpiexec) gives the same results as local processes.

Runs ``mpiexec -n 3 python -m mpi4py.futures -m beamstops sweep`` (rank 0 runs the
sweep, ranks 1 and 2 are its workers) on 2 cores. Skipped, with the reason, when
mpiexec or mpi4py is missing (scripts/setup.sh installs both).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import h5py
import numpy as np
import pytest

from beamstops.sweep import load_spec, read_summary, run_sweep

MPIEXEC = shutil.which("mpiexec")


def _mpi4py() -> str | None:
    done = subprocess.run([sys.executable, "-c", "import mpi4py.futures"], capture_output=True, text=True, timeout=60)
    return None if done.returncode == 0 else done.stderr.strip().splitlines()[-1]


pytestmark = pytest.mark.skipif(MPIEXEC is None, reason="mpiexec is not installed (Debian: openmpi-bin libopenmpi-dev)")

SPEC = """
[sweep]
zip = [["lower", "upper"]]
[scene]
elements = 6
dt = 5e-5
[axes]
omega = [9.0, 26.0, 41.0]
lower = [-0.05, -0.1]
upper = [0.05, 0.1]
[periods]
t_end = 8
records_per_period = 8
[reductions.strobe]
kind = "strobe"
transient_periods = 3
[reductions.e_end]
kind = "final"
quantity = "energy"
"""


def mpiexec(ranks: int, *args: str, timeout: float = 120) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_btl_vader_single_copy_mechanism="none", OMPI_MCA_rmaps_base_oversubscribe="1")
    flags = ["--oversubscribe"] + (["--allow-run-as-root"] if hasattr(os, "geteuid") and os.geteuid() == 0 else [])
    return subprocess.run([str(MPIEXEC), *flags, "-n", str(ranks), sys.executable, *args], capture_output=True,
                          text=True, timeout=timeout, env=env, stdin=subprocess.DEVNULL)


def test_mpi_and_local_executors_give_identical_results(tmp_path: Path, write_spec: Callable[..., Path],
                                                        without_timing: Callable[..., Any]) -> None:
    missing = _mpi4py()
    if missing:
        pytest.skip(f"mpi4py is not importable: {missing}")
    spec_path = write_spec(SPEC)
    done = mpiexec(3, "-m", "mpi4py.futures", "-m", "beamstops", "sweep", str(spec_path), "-o", str(tmp_path / "mpi"))
    assert done.returncode == 0, done.stdout + done.stderr
    assert "to run on 2 MPI worker ranks" in done.stderr, done.stderr
    local = run_sweep(load_spec(spec_path), tmp_path / "local", executor="local", jobs=2, stream=None)
    assert local.complete == 6
    by_mpi, by_local = read_summary(tmp_path / "mpi"), read_summary(tmp_path / "local")
    assert all(r["status"] == "complete" for r in by_mpi)
    assert without_timing(by_mpi) == without_timing(by_local)  # every parameter, figure and reduction
    for row in by_local:  # and every recorded array, bit for bit
        with h5py.File(tmp_path / "mpi" / row["file"]) as a, h5py.File(tmp_path / "local" / row["file"]) as b:
            for name in ("tip/t", "tip/u", "tip/v", "tip/reaction", "energy/E", "energy/work", "energy/dissipated"):
                np.testing.assert_array_equal(a[name][()], b[name][()], err_msg=name)
    # resuming under MPI: nothing left to run
    again = mpiexec(2, "-m", "mpi4py.futures", "-m", "beamstops", "sweep", str(spec_path), "-o", str(tmp_path / "mpi"))
    assert again.returncode == 0 and "6 before" in again.stderr, again.stderr


def test_plain_mpiexec_without_mpi4py_futures_is_refused(tmp_path: Path, write_spec: Callable[..., Path]) -> None:
    spec_path = write_spec(SPEC)
    done = mpiexec(2, "-m", "beamstops", "sweep", str(spec_path), "-o", str(tmp_path / "out"))
    assert done.returncode != 0
    assert "beamstops: error: started as one of several MPI ranks" in done.stderr, done.stderr
    assert "Traceback" not in done.stderr

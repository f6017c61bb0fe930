"""`scripts/bench.py --quick` runs to its end and prints every section of docs/bench.md: the
benchmark behind the README's speed tables stays runnable; so does `scripts/bench_rerun.py
--quick`, behind the README's figures for a re-run. Its build is $BEAMSTOPS_BUILD, else
build/tests (scripts/test.sh) or build/bench, configured with -Dbench=true when it is not (the
microbenchmarks under bench/ then compile into it), else a build/speed-test made here. Timings
vary with the machine and are not asserted; what the bench checks for itself is: every sweep
point's summary the same in lockstep as one at a time, and every point that shares A run in
lockstep."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "scripts"))

import bench_ext  # noqa: E402

SECTIONS = [
    "## Speed (scripts/bench.py --quick)",
    "### Per step, the paper's scene",
    "### The cost of each option",
    "### The floor (J = 19)",
    "### Lockstep ensembles: member-steps per second per core",
    "### Scaling in J",
    "### Records (Figure 4 scene",
    "### The paper's CPU times beside ours",
    "### The paper's Figure 4 run at the floor",
    "### A peer on the paper's scene: Siconos",
    "### A sweep over ω at one Δt",
]


def test_bench_quick_runs_every_section(tmp_path: Path) -> None:
    if shutil.which("meson") is None or shutil.which(os.environ.get("FC", "gfortran")) is None:
        pytest.skip("meson and a Fortran compiler are needed to build the benchmarks")
    out = tmp_path / "bench.md"
    done = subprocess.run([sys.executable, str(REPO / "scripts" / "bench.py"), "--quick", "--build", str(bench_ext.existing_build("speed-test")),
                           "--out", str(out)], capture_output=True, text=True, timeout=900, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    text = out.read_text()
    for heading in SECTIONS:
        assert heading in text, heading
    assert not re.search(r"\bnan\b", text.lower()), "a figure is not a number"
    # the lockstep ratio at K = 8 and the Figure 4 ratios are printed as numbers
    assert re.search(r"K = 8 over one at a time, medians: J = 19: \*\*[0-9.]+×\*\*", text)
    assert re.search(r"whole process / engine loop with nothing recorded: \*\*[0-9.]+×\*\*", text)
    assert re.search(r"engine loop / chain floor \([0-9.]+ ns a multiply-add\): \*\*[0-9.]+×\*\*", text)
    # the ω sweep: both beams, every point in lockstep, the same summary either way
    rows = [line for line in text.splitlines() if line.startswith(("| damped |", "| undamped |"))]
    assert len(rows) == 2, rows
    for row in rows:
        cells = [cell.strip() for cell in row.strip("|").split("|")]
        lockstep, same = cells[-2], cells[-1]
        done_points, total = re.fullmatch(r"(\d+) of (\d+)", lockstep).groups()  # type: ignore[union-attr]
        assert done_points == total and int(total) > 0, row
        assert same == "yes", row


def test_bench_rerun_quick_runs() -> None:
    """`scripts/bench_rerun.py --quick` (the README's re-run figures) runs to its end and no
    earlier output is left behind by the runs into an existing one."""
    program = os.environ.get("BEAMSTOPS_PROGRAM") or shutil.which("beamstops")
    if program is None:
        pytest.skip("the beamstops program is not on PATH")
    done = subprocess.run([sys.executable, str(REPO / "scripts" / "bench_rerun.py"), "--quick", "--program", program],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    assert re.search(r"re-run - fresh: least -?[0-9.]+ ms, median -?[0-9.]+ ms \(3 runs each; earlier outputs "
                     r"left behind: 0\)", done.stdout), done.stdout

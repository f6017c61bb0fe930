"""scripts/bench_start.py runs its three commands on both programs and prints one row each (here
the installed program twice: the script's plumbing, not a timing; nothing about time is asserted)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path


def test_bench_start_table(program: str, repo_root: Path) -> None:
    done = subprocess.run([sys.executable, str(repo_root / "scripts" / "bench_start.py"), program, program,
                           "--repeats", "1"], capture_output=True, text=True, check=True)
    lines = [line for line in done.stdout.splitlines() if line.startswith("|")]
    assert lines[0].startswith("| command |") and lines[1].startswith("|---|")
    rows = lines[2:]
    labels = [row.split("|")[1].strip() for row in rows]
    assert labels == ["`--version`", "100-step run", "sweep point (50,000 steps)"]
    for row in rows:
        cells = [cell.strip() for cell in row.split("|")[2:4]]
        for cell in cells:
            least, median = (float(x) for x in cell.split(" / "))
            assert 0 < least <= median

"""scripts/stress_kills.py kills a few short runs and prints its summary line (the script's
plumbing: how many files a kill leaves unreadable is chance, nothing about it is asserted)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path


def test_stress_kills_summary(program: str, repo_root: Path) -> None:
    done = subprocess.run([sys.executable, str(repo_root / "scripts" / "stress_kills.py"), "--program", program,
                           "--kills", "3", "--t-end", "0.2", "--window", "0.01", "0.05", "--seed", "1"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    last = done.stdout.strip().splitlines()[-1]
    match = re.fullmatch(r"seed 1: 3 kills, (\d+) left a file HDF5 could not read; --restart resumed (\d+) of them "
                         r"bit for bit, refused (\d+)", last)
    assert match, last
    unreadable, resumed, refused = map(int, match.groups())
    assert resumed + refused <= unreadable <= 3

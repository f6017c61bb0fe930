"""scripts/paper_figures.py on a shortened horizon: every figure, the report, no display."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import INPUT, ROOT

FIGURES = range(2, 9)


@pytest.mark.skipif(not all((INPUT / f"paper_fig{n}.nml").is_file() for n in FIGURES),
                    reason="input/paper_fig2.nml ... paper_fig8.nml are not all there")
def test_report_script_runs_on_a_short_horizon(tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "MPLBACKEND")}
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "paper_figures.py"), "--t-end", "0.01",
                           "--out", str(tmp_path)], capture_output=True, text=True, timeout=300, env=env)
    assert done.returncode == 0, done.stderr
    assert "paper figures" in done.stderr  # the progress bar
    for n in FIGURES:
        assert (tmp_path / f"fig{n}.png").read_bytes()[:4] == b"\x89PNG"
    assert (tmp_path / "agreement.png").is_file()
    report = (tmp_path / "report.md").read_text()
    assert "do not edit by hand" in report and "Shortened horizon" in report
    rows = [line for line in report.splitlines() if line.startswith("| ") and line.split("|")[1].strip().isdigit()]
    assert [int(row.split("|")[1]) for row in rows] == list(FIGURES)
    for n, paper_cpu in [(2, "18.24"), (7, "2426.4"), (8, "859.38")]:
        assert f"| {n} |" in report and paper_cpu in report
    assert "never violated, as in the paper" in report
    assert "0.000225" in report and "3.3469e-06" in report


def test_report_script_reports_bad_input_in_one_line(tmp_path: Path) -> None:
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "paper_figures.py"), "--input", str(tmp_path),
                           "--out", str(tmp_path / "out")], capture_output=True, text=True, timeout=120)
    assert done.returncode == 1
    assert done.stderr.startswith("paper_figures: error:") and "Traceback" not in done.stderr

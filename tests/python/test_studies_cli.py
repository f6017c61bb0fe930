"""The studies' subcommands in --quick mode write their charts and tables."""

from __future__ import annotations

from pathlib import Path

import pytest

from beamstops import cli


@pytest.mark.parametrize("command, files", [
    ("converge", ["convergence.md", "dt_none_centered.csv", "roundoff_three_level.md", "h_signorini.csv"]),
    ("work-precision", ["work_precision.png", "work_precision.csv", "work_precision.md"]),
    ("stability-map", ["stability_map.png", "stability.md", "stability_beta.csv", "stability_mesh_beta0.csv"]),
    ("compliance", ["compliance.png", "compliance.csv", "compliance.md"]),
])
def test_quick_study(tmp_path: Path, command: str, files: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main([command, "--quick", "--quiet", "-o", str(tmp_path)]) == 0
    for name in files:
        assert (tmp_path / name).stat().st_size > 0, name
    assert str(tmp_path) in capsys.readouterr().out

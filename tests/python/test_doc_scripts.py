"""The scripts behind the README's measured figures run in their quick form, and the README names them:
`scripts/restitution_energy.py` (the energy the stops take with e = 1) and `scripts/plan_chart.py`
(docs/plan). Also the README's Python blocks can be pasted into a fresh interpreter, and the table
of :mod:`beamstops.result` names each array's dataset once, with one unit."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import beamstops.result
from conftest import ROOT

README = (ROOT / "README.md").read_text(encoding="utf-8")


def script(name: str, *args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, str(ROOT / "scripts" / name), *args], cwd=cwd, capture_output=True,
                          text=True, timeout=300)


def test_restitution_energy_quick_prints_the_ledger_of_each_step(tmp_path: Path) -> None:
    assert "`python scripts/restitution_energy.py`" in README
    done = script("restitution_energy.py", "--quick", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    rows = [line.split("|")[1:4] for line in done.stdout.splitlines() if re.match(r"\| \d", line)]
    assert [float(row[0]) for row in rows] == [1e-4, 1e-5, 1e-6]
    assert all(float(work) > 0 for _, _, work in rows)
    assert "against a support work of" in done.stdout and list(tmp_path.iterdir()) == []


def test_restitution_energy_refuses_a_bad_scene_in_one_line(tmp_path: Path) -> None:
    (tmp_path / "bad.nml").write_text("&time dtt = 1 /\n")
    done = script("restitution_energy.py", "--scene", "bad.nml", "--quick", cwd=tmp_path)
    assert done.returncode == 1 and done.stderr.count("\n") == 1 and "unknown key dtt" in done.stderr


def test_plan_chart_quick_writes_its_chart_table_and_scene(tmp_path: Path) -> None:
    assert "python scripts/plan_chart.py" in README
    done = script("plan_chart.py", "--quick", "--quiet", "-o", "plan", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "plan" / "plan.png").read_bytes()[:4] == b"\x89PNG"
    report = (tmp_path / "plan" / "plan.md").read_text()
    assert "--quick" in report and "| law | J |" in report
    # --quick without -o goes to out/plan_quick, never over docs/plan
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plan"]


def test_readme_python_blocks_import_what_they_use() -> None:
    for block in re.findall(r"```python\n(.*?)```", README, re.S):
        if "beamstops." in block:
            assert "import beamstops" in block, block
        for name in ("Scene", "run"):
            if re.search(rf"(?<![.\w]){name}\(", block):
                assert re.search(rf"from beamstops import .*\b{name}\b", block), (name, block)


def test_result_table_gives_each_array_its_dataset_and_one_unit() -> None:
    table = beamstops.result.__doc__
    assert table is not None
    for name, dataset in beamstops.result.ARRAYS.items():
        row = next(line for line in table.splitlines() if line.split()[:1] == [name])
        assert f"/{dataset}" in row, row
        assert not re.search(r"(\([^()]*\)) \1$", row), row  # a unit once, not "(m) (m)"
    assert re.search(r"^stops_node .*whole numbers", table, re.M)
    assert re.search(r"^ensemble +/ensemble/NAME", table, re.M)

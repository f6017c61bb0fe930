"""Contact-laws study (issue 12 item 5): the --quick study writes its chart and tables, one row
per law and Δt with finite orders; physics: mass redistribution leaves the stops almost no
energy where the paper's projection takes a share of the support's work, and e = 1 keeps more
energy in the beam than e = 0."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from beamstops import cli
from beamstops.studies import contact_laws
from beamstops.studies.common import Table


@pytest.fixture(scope="module")
def quick(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Table]]:
    folder = tmp_path_factory.mktemp("contact_laws")
    return folder, contact_laws.study(folder, quick=True, quiet=True)


def test_files_and_rows(quick: tuple[Path, dict[str, Table]]) -> None:
    folder, tables = quick
    for name in ("contact_laws.png", "contact_laws.md", "contact_laws_energy.csv", "contact_laws_convergence.csv",
                 "contact_laws_headline.csv"):
        assert (folder / name).stat().st_size > 0, name
    plan = contact_laws.PLANS["quick"]
    labels = [label for label, _ in contact_laws.LAWS]
    convergence = tables["convergence"]
    for label in labels:
        assert sum(1 for r in convergence.rows if r[0] == label) == len(plan.dts), label
        for start, end in contact_laws.WINDOWS:
            orders = contact_laws.orders(convergence, label, f"order [{start:g},{end:g}]")
            assert math.isnan(orders[0]) and all(math.isfinite(o) for o in orders[1:]), (label, orders)
    assert [r[0] for r in tables["headline"].rows] == labels
    assert [r[0] for r in tables["energy"].rows] == labels + [contact_laws.DAMPED[0]]
    per_shock = [float(r[tables["energy"].columns.index("phases per shock")]) for r in tables["energy"].rows]  # type: ignore
    assert all(math.isnan(x) or x >= 1 for x in per_shock) and any(x >= 1 for x in per_shock)
    text = (folder / "contact_laws.md").read_text(encoding="utf-8")
    assert "**Answer (measured):**" in text and "contact_laws.png" in text


def _energy(tables: dict[str, Table], label: str, column: str) -> float:
    table = tables["energy"]
    row = next(r for r in table.rows if r[0] == label)
    return float(row[table.columns.index(column)])  # type: ignore[arg-type]


def test_physics(quick: tuple[Path, dict[str, Table]]) -> None:
    _, tables = quick
    paper, elastic, massless = "e = 0 (paper)", "e = 1", "mass redistributed"
    # the stops take a share of the support's work under the projection, almost nothing without tip mass
    assert _energy(tables, paper, "stops (J)") > 0.1 * _energy(tables, paper, "support work (J)")
    assert abs(_energy(tables, massless, "stops (J)")) < 0.01 * _energy(tables, paper, "stops (J)")
    # e = 1 gives the beam back what e = 0 takes
    assert _energy(tables, elastic, "mean E (J)") > _energy(tables, paper, "mean E (J)")
    assert _energy(tables, elastic, "stops (J)") < 0.5 * _energy(tables, paper, "stops (J)")
    # the projection never violates; restitution e > 0 does, by a little; damping takes energy
    assert _energy(tables, paper, "max violation (m)") == 0
    assert 0 < _energy(tables, elastic, "max violation (m)") < 1e-3
    assert _energy(tables, contact_laws.DAMPED[0], "damping (J)") > 0
    for label, _ in contact_laws.LAWS:
        assert abs(_energy(tables, label, "energy residual (J)")) < 1e-8, label


def test_command(tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[tuple[Path, bool]] = []
    monkeypatch.setattr(contact_laws, "study", lambda folder, quick, quiet: calls.append((folder, quick)) or {})
    assert cli.main(["contact-laws", "--quick", "--quiet", "-o", str(tmp_path)]) == 0
    assert calls == [(tmp_path, True)]
    assert str(tmp_path / "contact_laws.png") in capsys.readouterr().out


ROOT = Path(__file__).resolve().parents[2]


def test_readme_quotes_the_committed_runs() -> None:
    """The README's numbers on contact laws and the damped diagram are the lines the runs wrote."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    laws = (ROOT / "docs" / "contact_laws" / "contact_laws.md").read_text(encoding="utf-8")
    for prefix in ("**Answer (measured):**", "**Energy over"):
        line = next(line for line in laws.splitlines() if line.startswith(prefix))
        assert f"> {line}" in readme, prefix
    damped = (ROOT / "docs" / "bifurcation_damped" / "bifurcation.md").read_text(encoding="utf-8")
    line = next(line for line in damped.splitlines() if line.startswith("Periodic (any p):"))
    assert line in readme.replace("\n", " ")
    # the undamped diagram: the README says no value of ω settles on a periodic motion
    undamped = (ROOT / "docs" / "bifurcation" / "bifurcation.md").read_text(encoding="utf-8")
    assert "Periodic (any p): 0 of" in undamped and "No value of ω settles on a periodic motion" in readme

"""Statistical quantities of interest (issue 13 item 4): work-precision and convergence with --qoi."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import pytest

from beamstops import Scene, cli
from beamstops.studies import qoi, qoi_workprecision

QOIS = ["stop_power", "impulse_rate", "shock_rate", "contact_fraction", "tip_rms"]


@pytest.fixture(scope="module")
def quick_tables(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, object]]:
    folder = tmp_path_factory.mktemp("wpq")
    tables = qoi_workprecision.study(folder, qois=QOIS, quick=True, quiet=True)
    return folder, tables  # type: ignore[return-value]


def test_files_and_every_law(quick_tables: tuple[Path, dict[str, object]]) -> None:
    folder, tables = quick_tables
    for name in ["work_precision_statistics.md", "statistics_runs.csv"] + [
            f"work_precision_{q}{suffix}" for q in QOIS for suffix in (".md", ".csv", ".png", "_dt.png")]:
        assert (folder / name).stat().st_size > 0, name
    labels = [law.label for law in qoi_workprecision.settings(True)[1]]
    assert len(labels) == 5 and any(label.startswith("reduced") for label in labels)
    for q in QOIS:
        with (folder / f"work_precision_{q}.csv").open(encoding="utf-8") as f:
            rows = list(csv.DictReader(f))
        assert {row["law"] for row in rows} >= set(labels), q
        assert any("across" in row["law"] for row in rows)  # the reference's ensemble row
        assert all(row["within the reference's interval"] in ("yes", "no", "reference", "yes (ensemble)",
                                                              "no (ensemble)") for row in rows)
    summary = (folder / "work_precision_statistics.md").read_text(encoding="utf-8")
    assert all(label in summary for label in labels)


def test_intervals_positive(quick_tables: tuple[Path, dict[str, object]]) -> None:
    _, tables = quick_tables
    for q in ("stop_power", "impulse_rate", "tip_rms"):
        table = tables[q]
        half = table.column(next(c for c in table.columns if c.startswith("half-width")))  # type: ignore[attr-defined]
        cpu = table.column("CPU (s)")  # type: ignore[attr-defined]
        assert all(h > 0 and math.isfinite(h) for h in half), (q, half)
        assert all(c > 0 for c in cpu)


def test_power_agrees_at_two_time_steps() -> None:
    """Physics: the stop power (Signorini, e = 0) at Δt = 4e-5 and 1e-5 agree within their intervals
    while the trajectories differ by millimetres, the fraction of time in contact does not converge;
    without stops the power is exactly zero."""
    base = Scene(beta=0.5)
    a = qoi.measure(base.replace(dt=4e-5), 0.5, 3.0, batches=10).estimate("stop_power")
    b = qoi.measure(base.replace(dt=1e-5), 0.5, 3.0, batches=10).estimate("stop_power")
    assert a.unit == "W" and a.value > 0.2 and b.value > 0.2 and 0 < a.half_width < a.value
    assert a.agrees(b), (a, b)
    # The time in contact is not a converged statistic (SPEC 12: chatter resolved differently with Δt).
    fa = qoi.measure(base.replace(dt=4e-5), 0.5, 3.0, batches=10).estimate("contact_fraction")
    fb = qoi.measure(base.replace(dt=1e-5), 0.5, 3.0, batches=10).estimate("contact_fraction")
    assert fa.value > fb.value and not fa.agrees(fb), (fa, fb)
    free = qoi.measure(base.replace(dt=4e-5, law="none"), 0.5, 1.0, batches=5).estimate("stop_power")
    assert free.value == 0


def test_ensemble_beside_batch_means() -> None:
    m = qoi.measure(Scene(beta=0.5, dt=4e-5), 0.5, 2.0, batches=10, members=3)
    batch, across = m.estimate("tip_rms"), m.across_members("tip_rms")
    assert across is not None and across.half_width > 0 and batch.half_width > 0
    assert across.agrees(batch)
    assert qoi.measure(Scene(beta=0.5, dt=4e-5), 0.5, 1.0, batches=5).across_members("tip_rms") is None


def test_agreement_and_projection() -> None:
    ref = qoi.Estimate(1.0, 0.1, "W")
    assert qoi.Estimate(1.25, 0.15, "W").agrees(ref)
    assert not qoi.Estimate(1.26, 0.15, "W").agrees(ref)
    assert not qoi.Estimate(math.nan, 0.1, "W").agrees(ref)
    assert qoi.window_for(0.1, 20.0, 0.05) == pytest.approx(80.0)
    assert math.isnan(qoi.window_for(0.0, 20.0, 0.05))
    m = qoi.Measured(Scene(), transient=2.0, window=20.0, cpu_seconds=1.1, status="complete", statistics={})
    assert qoi.cost_for(m, 80.0) == pytest.approx(1.1 * 82 / 22)
    h = qoi.HalfWidth.parse("2%")
    assert h.relative and h.target(ref) == pytest.approx(0.02)
    assert math.isnan(h.target(qoi.Estimate(0.05, 0.1, "W")))  # interval holds 0: no relative precision
    assert qoi.HalfWidth.parse("0.01").target(ref) == 0.01
    with pytest.raises(ValueError):
        qoi.HalfWidth.parse("-1%")


def test_names() -> None:
    assert qoi.statistic_name("stop_power") == "power"
    assert qoi.statistic_name("shock_rate") == "shocks_per_second"
    assert qoi.statistic_name("force_rms_contact") == "force_rms_contact"
    with pytest.raises(ValueError, match="unknown quantity"):
        qoi.statistic_name("speed")


def test_cli_converge_qoi(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["converge", "--quick", "--quiet", "--qoi", "stop_power", "tip_rms", "-o", str(tmp_path)]) == 0
    for name in ("qoi_convergence.md", "qoi_convergence_stop_power.png", "qoi_convergence_stop_power_dt.csv",
                 "qoi_convergence_tip_rms_J.md"):
        assert (tmp_path / name).stat().st_size > 0, name
    assert not (tmp_path / "dt_none_centered.csv").exists()  # no 'tip': the pointwise tables are not run
    assert "qoi_convergence.md" in capsys.readouterr().out
    text = (tmp_path / "qoi_convergence_stop_power_dt.md").read_text(encoding="utf-8")
    assert "reference" in text and "across 3 members" in text
    # the reduced models (modes r) against the full model
    with (tmp_path / "qoi_convergence_tip_rms_modes.csv").open(encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert [row["modes r"] for row in rows] == ["4", "8", "full"]


@pytest.mark.parametrize("options", [["--qoi", "speed"], ["--qoi", "stop_power", "--half-width", "-2%"]])
def test_cli_refuses_bad_options(tmp_path: Path, options: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        cli.main(["work-precision", "--quick", "--quiet", "-o", str(tmp_path / "never")] + options)
    assert exit_.value.code == 2
    assert not (tmp_path / "never").exists()
    assert "--" in capsys.readouterr().err


def test_projection_checked_by_a_run(quick_tables: tuple[Path, dict[str, object]]) -> None:
    """The window T* projected from h ∝ 1/sqrt(T) gives a half-width near h* when run."""
    _, tables = quick_tables
    table = tables["stop_power"]
    rows = [row for row in table.rows if str(row[0]).endswith("(check at T*)")]  # type: ignore[attr-defined]
    assert len(rows) == 1
    col = {name: i for i, name in enumerate(table.columns)}  # type: ignore[attr-defined]
    half = rows[0][next(i for n, i in col.items() if n.startswith("half-width"))]
    target = rows[0][next(i for n, i in col.items() if n.startswith("h*"))]
    assert rows[0][col["window (s)"]] > 20 * 2.0  # far longer than the quick window
    assert 0.5 < half / target < 2.0, (half, target)

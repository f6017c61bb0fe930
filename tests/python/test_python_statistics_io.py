"""Reading the engine's shock log (/impacts) and statistics (/statistics): Result.impacts,
Result.statistics, Statistic, the pandas frames; files written here with h5py in the layout."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

import synthetic
import beamstops
from beamstops import Statistic
from beamstops.observations import IMPACT_FIELDS, IMPACT_UNITS, STATISTIC_NAMES


@pytest.fixture
def logged(tmp_path: Path) -> Path:
    """A minimal complete output with a shock log of 25 shocks at 2 stops and every statistic."""
    path = tmp_path / "logged.h5"
    with h5py.File(path, "w") as f:
        f.attrs["status"] = "complete"
        f.create_dataset("tip/t", data=np.linspace(0, 1, 11))
        for name in ("tip/u", "tip/v", "tip/reaction", "energy/E", "energy/work", "energy/dissipated"):
            f.create_dataset(name, data=np.zeros(11))  # every series a run with records writes (load checks)
    return synthetic.write(path, synthetic.impacts(25, stops=2), synthetic.statistics(stops=2, bins=20),
                           {"transient": 0.25, "batches": 8, "bins": 20, "rest_time": 1e-3})


def test_load_round_trips_impacts_and_statistics(logged: Path) -> None:
    result = beamstops.load(logged)
    expected = synthetic.impacts(25, stops=2)
    assert set(result.impacts) == set(IMPACT_FIELDS)
    for name, column in expected.items():
        assert result.impacts[name].dtype == np.float64 and result.impacts[name].shape == (25,)
        np.testing.assert_array_equal(result.impacts[name], column)  # NaN in the same places
    assert result.shocks == 25
    tables = synthetic.statistics(stops=2, bins=20)
    assert set(result.statistics) == set(STATISTIC_NAMES)
    for name, table in tables.items():
        stat = result.statistics[name]
        np.testing.assert_array_equal(stat.value, table[:, 0])
        np.testing.assert_array_equal(stat.half_width, table[:, 1])
        assert (stat.unit, stat.axis) == synthetic.STATISTICS[name]
    assert len(result.statistics["power"]) == 2 and len(result.statistics["tip_histogram_edges"]) == 21
    assert result.statistics_attrs == {"transient": 0.25, "batches": 8, "bins": 20, "rest_time": 1e-3}
    assert "shocks=25" in repr(result)
    _check_layout(result, stops=2)


def test_fixed_length_text_attributes_as_fortran_writes_them(tmp_path: Path) -> None:
    path = tmp_path / "bytes.h5"
    with h5py.File(path, "w") as f:
        f.attrs["status"] = np.bytes_(b"complete")
        d = f.create_dataset("statistics/power", data=np.array([[0.5, 0.1]]))
        d.attrs["units"] = np.bytes_(b"W   ")
        d.attrs["axis"] = np.bytes_(b"stop")
        f["statistics"].attrs["transient"] = np.array([0.5])
    result = beamstops.load(path)
    assert result.statistics["power"].unit == "W" and result.statistics["power"].axis == "stop"
    assert result.statistics_attrs["transient"] == pytest.approx(0.5)


def test_absent_groups_read_as_empty(tmp_path: Path) -> None:
    path = tmp_path / "old.h5"
    with h5py.File(path, "w") as f:
        f.attrs["status"] = "complete"
    result = beamstops.load(path)
    assert result.impacts == {} and result.statistics == {} and result.statistics_attrs == {}
    assert result.shocks == 0


def test_result_is_constructible_without_them() -> None:
    empty = np.empty(0)
    result = beamstops.Result(t=empty, tip_u=empty, tip_v=empty, reaction=empty, energy=empty, work=empty,
                              dissipated=empty, snapshot_t=empty, snapshot_x=empty, snapshot_u=np.empty((0, 0)))
    assert result.impacts == {} and result.statistics == {} and result.shocks == 0
    other = beamstops.Result(t=empty, tip_u=empty, tip_v=empty, reaction=empty, energy=empty, work=empty,
                             dissipated=empty, snapshot_t=empty, snapshot_x=empty, snapshot_u=np.empty((0, 0)))
    result.impacts["x"] = empty
    assert other.impacts == {}  # no shared default


def test_an_empty_shock_log_is_not_an_absent_one(tmp_path: Path) -> None:
    path = synthetic.write(tmp_path / "quiet.h5", synthetic.impacts(0))
    result = beamstops.load(path)
    assert set(result.impacts) == set(IMPACT_FIELDS) and result.shocks == 0


def test_malformed_groups_are_refused_with_the_file_named(tmp_path: Path) -> None:
    path = tmp_path / "bad.h5"
    with h5py.File(path, "w") as f:
        f.attrs["status"] = "complete"
        f.create_dataset("statistics/power", data=np.ones(3))
    with pytest.raises(ValueError, match=r"bad\.h5: /statistics/power: expected a \(count, 2\) table"):
        beamstops.load(path)
    path = tmp_path / "ragged.h5"
    with h5py.File(path, "w") as f:
        f.attrs["status"] = "complete"
        f.create_dataset("impacts/t_start", data=np.ones(3))
        f.create_dataset("impacts/impulse", data=np.ones(2))
    with pytest.raises(ValueError, match="ragged.h5: /impacts columns differ in length"):
        beamstops.load(path)


@pytest.mark.parametrize("value, half, unit, text", [
    (0.56, 0.031, "W", "0.560 ± 0.031 W"),
    (12345.0, 310.0, "N", "12340 ± 310 N"),
    (2.0, 0.25, "1", "2.00 ± 0.25"),
    (1.2345e-5, 3.1e-7, "m", "(1.234 ± 0.031)e-05 m"),
    (7.0, math.nan, "1", "7"),
    (0.1234567, 0.0, "m", "0.1235 m"),
    (-0.02, 0.004, "m", "-0.0200 ± 0.0040 m"),
])
def test_statistic_string(value: float, half: float, unit: str, text: str) -> None:
    stat = Statistic(np.array([value]), np.array([half]), unit, "stop")
    assert str(stat) == text
    assert float(stat) == value


def test_statistic_of_several_entries() -> None:
    stat = Statistic.from_table([[0.56, 0.031], [1.5, 0.2]], unit="W", axis="stop")
    assert str(stat) == "[0.560 ± 0.031, 1.50 ± 0.20] W"
    assert len(stat) == 2
    with pytest.raises(TypeError, match="2 entries"):
        float(stat)
    with pytest.raises(ValueError, match=r"\(count, 2\)"):
        Statistic.from_table(np.ones((3, 3)))
    with pytest.raises(Exception):
        stat.unit = "J"  # type: ignore[misc]  # frozen


def test_frames_with_pandas(logged: Path) -> None:
    pandas = pytest.importorskip("pandas")
    result = beamstops.load(logged)
    impacts = result.impacts_frame()
    assert isinstance(impacts, pandas.DataFrame) and len(impacts) == 25
    assert list(impacts.columns) == list(IMPACT_FIELDS)
    assert impacts["stop"].dtype == np.int64 and set(impacts["stop"]) <= {1, 2}
    assert impacts["truncated"].dtype == bool and impacts["truncated"].sum() == 1
    np.testing.assert_array_equal(impacts["impulse"].to_numpy(), result.impacts["impulse"])
    stats = result.statistics_frame()
    assert stats.loc[("power", 1), "value"] == pytest.approx(0.56)
    assert stats.loc[("power", 0), "unit"] == "W"
    assert len(stats.loc["tip_histogram_edges"]) == 21


def test_frames_without_pandas_say_what_to_install(logged: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas then raises ImportError
    result = beamstops.load(logged)
    with pytest.raises(ImportError, match=r"impacts_frame\(\) needs pandas.*pip install pandas"):
        result.impacts_frame()
    with pytest.raises(ImportError, match=r"statistics_frame\(\) needs pandas"):
        result.statistics_frame()


def _check_layout(result: beamstops.Result, stops: int) -> None:
    """What the contract says of the groups, on whatever the engine wrote."""
    if result.impacts:
        assert set(result.impacts) == set(IMPACT_FIELDS)
        assert len({a.size for a in result.impacts.values()}) == 1
        if result.shocks:
            assert set(np.unique(result.impacts["stop"])) <= set(range(1, stops + 1))
            assert set(np.unique(result.impacts["side"])) <= {-1.0, 1.0}
            assert np.all(result.impacts["t_end"] > result.impacts["t_start"])
    if result.statistics:
        assert set(result.statistics) <= set(STATISTIC_NAMES)
        bins = int(result.statistics_attrs["bins"])
        counts = {"stop": stops, "tip": 1, "run": 1, "bin": bins, "edge": bins + 1}
        for name, stat in result.statistics.items():
            assert stat.axis in counts, (name, stat.axis)
            assert len(stat) == counts[stat.axis], name
        assert {"transient", "batches", "bins", "rest_time"} <= set(result.statistics_attrs)


def test_the_engine_output_follows_the_layout(program: str, tmp_path: Path) -> None:
    """Live once the engine writes /impacts and /statistics (skipped before)."""
    import subprocess

    from beamstops import Scene

    Scene(t_end=0.5, file="out.h5").to_namelist(tmp_path / "scene.nml")
    done = subprocess.run([program, "run", "scene.nml"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    result = beamstops.load(tmp_path / "out.h5")
    memory = beamstops.run(Scene(t_end=0.5))
    if not (result.impacts or result.statistics or memory.impacts or memory.statistics):
        pytest.skip("this engine writes no /impacts or /statistics yet")
    _check_layout(result, 1)
    _check_layout(memory, 1)
    for name in result.impacts:
        np.testing.assert_array_equal(result.impacts[name], memory.impacts.get(name, result.impacts[name]))
    with h5py.File(tmp_path / "out.h5") as f:
        for name in f.get("impacts", {}):
            assert f["impacts"][name].attrs["units"] in (IMPACT_UNITS[name], IMPACT_UNITS[name].encode())

"""Stops along the span (issue 8) from Python and the program: the Scene's list keys and the
x route, the program's /stops datasets against beamstops.run bit for bit, one stop at the tip
against the tip-only path, the example input, a killed run resumed, the 'stops' plot."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

import beamstops
from beamstops import Scene
from beamstops.result import ARRAYS

from conftest import INPUT

SUPPORTS = Scene(length=1.5, elements=30, amplitude=0.002, omega=40.0, beta=0.25, dt=2e-5, t_end=0.5,
                 nodes=(10, 20, 30), lower=(-0.002, -0.002, -0.004), upper=(0.002, 0.002, 0.004))


def same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype == np.float64 and a.shape == b.shape and np.array_equal(
        np.ascontiguousarray(a).view(np.uint64), np.ascontiguousarray(b).view(np.uint64))


# ---------------------------------------------------------------------- Scene


def test_scene_lists_broadcast_and_x_route() -> None:
    scene = Scene(length=1.5, elements=30).replace(x=[0.5, 1.0000000001, 1.5], lower=-0.002, upper=0.004)
    assert scene.nodes == (10, 20, 30)
    assert scene.lower == (-0.002,) * 3 and scene.upper == (0.004,) * 3
    assert Scene(nodes=7).nodes == (7,)
    assert Scene().lower == -0.1  # the tip-only form keeps single values


@pytest.mark.parametrize("changes, needles", [
    ({"x": [0.52]}, ["x(1) = 0.52", "nearest nodes are 10 (x = 0.5)", "11 (x = 0.55)"]),
    ({"nodes": (3, 5), "lower": (-0.1, -0.1, -0.1)}, ["lower has 3 values for 2 stops", "or 2, one per stop"]),
    ({"nodes": (3,), "upper": (0.1, 0.2)}, ["upper has 2 values for 1 stop; allowed: one value"]),
    ({"lower": (-0.1, -0.2)}, ["lower or upper has several values", "nodes or x"]),
    ({"nodes": (3,), "x": [0.5]}, ["both nodes and x"]),
])
def test_scene_refuses_bad_lists(changes: dict, needles: list[str]) -> None:
    with pytest.raises(ValueError) as caught:
        Scene(length=1.5, elements=30).replace(**changes)
    for needle in needles:
        assert needle in str(caught.value), str(caught.value)


@pytest.mark.parametrize("changes, needle", [
    ({"nodes": (3, 5, 3), "lower": -0.1, "upper": 0.1}, "each node once"),
    ({"nodes": (0,), "lower": -0.1, "upper": 0.1}, "node 0 is clamped"),
    ({"nodes": (3,), "lower": 0.1, "upper": 0.2}, "lower(1) = 0.1"),
    ({"nodes": (3,), "law": "compliance", "stiffness_per_mass": 1e8}, "compliance"),
])
def test_engine_refuses_bad_stops(changes: dict, needle: str) -> None:
    with pytest.raises(ValueError, match=None) as caught:
        Scene().replace(**changes).validate()
    assert needle in str(caught.value), str(caught.value)


def test_namelist_round_trip_and_engine_reader(tmp_path: Path) -> None:
    SUPPORTS.to_namelist(tmp_path / "supports.nml")
    text = (tmp_path / "supports.nml").read_text()
    assert "nodes = 10, 20, 30" in text
    again = Scene.from_namelist(tmp_path / "supports.nml")  # f90nml and the engine agree
    assert again.differences(SUPPORTS.replace(file="supports.h5")) == ""
    engine = beamstops.engine.read_namelist(tmp_path / "supports.nml")
    assert engine.nodes == (10, 20, 30) and engine.lower == SUPPORTS.lower


def test_example_input_reads_with_x() -> None:
    scene = Scene.from_namelist(INPUT / "tube_supports.nml")
    assert scene.nodes == (10, 20, 30) and scene.lower[:2] == (-0.002, -0.002)


# ---------------------------------------------------------------------- runs


def test_kkt_and_energy_at_every_record() -> None:
    result = beamstops.run(SUPPORTS)
    u, r = result.stops_u, result.stops_reaction
    lower, upper = np.array(SUPPORTS.lower), np.array(SUPPORTS.upper)
    tol = 1e-17
    assert u.shape == r.shape == (result.t.size, 3)
    assert np.all(u >= lower - tol) and np.all(u <= upper + tol)
    # a record holds u~^n and the reaction of the step that put it there
    assert np.all(np.abs(u[r < 0] - np.broadcast_to(upper, u.shape)[r < 0]) <= tol)
    assert np.all(np.abs(u[r > 0] - np.broadcast_to(lower, u.shape)[r > 0]) <= tol)
    assert np.count_nonzero(r) > 100 and result.attrs["max_violation"] == 0
    # the energy the stops take never decreases (but for round-off: 2e-18 J steps, 1e-15 of it)
    assert result.dissipated[-1] > 0
    assert np.all(np.diff(result.dissipated) >= -1e-12 * result.dissipated[-1])
    balance = (result.energy - result.energy[0]) - (result.work - result.dissipated)
    assert np.abs(balance).max() <= 1e-9 * np.abs(result.energy).max()
    assert result.scene().differences(SUPPORTS) == ""


def test_single_tip_stop_is_the_tip_path() -> None:
    tip = Scene(t_end=0.5, beta=0.25)
    a = beamstops.run(tip)
    b = beamstops.run(tip.replace(nodes=(tip.elements,), lower=tip.lower, upper=tip.upper))
    assert a.attrs["impacts"] > 0 and a.attrs["impacts"] == b.attrs["impacts"]
    for name in ("t", "tip_u", "tip_v", "reaction", "energy", "work", "dissipated", "snapshot_u"):
        assert same_bits(getattr(a, name), getattr(b, name)), name
    assert same_bits(b.stops_u[:, 0], b.tip_u) and same_bits(b.stops_reaction[:, 0], b.reaction)


def test_program_writes_stops_as_run_does(program: str, tmp_path: Path) -> None:
    scene = SUPPORTS.replace(file="out.h5", record_every=3, snapshot_every=50)
    scene.to_namelist(tmp_path / "scene.nml")
    done = subprocess.run([program, "run", "scene.nml"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    loaded = beamstops.load(tmp_path / "out.h5")
    ran = beamstops.run(Scene.from_namelist(tmp_path / "scene.nml"))
    for array in ARRAYS:
        assert same_bits(getattr(loaded, array), getattr(ran, array)), array
    with h5py.File(tmp_path / "out.h5") as f:
        assert f["stops/u"].shape == (ran.t.size, 3) and f["stops/u"].chunks is not None
        assert f["stops/reaction"].attrs["units"] == b"N"
        assert list(f["stops/node"][()]) == [10.0, 20.0, 30.0]
        units = {name: f[name].attrs["units"] for name in ("stops/x", "stops/node", "stops/lower", "stops/upper",
                                                            "snapshots/x")}
        assert units == {"stops/x": b"m", "stops/node": b"1", "stops/lower": b"m", "stops/upper": b"m",
                         "snapshots/x": b"m"}
        assert "lower" not in f.attrs and f.attrs["stops"] == 3
    cpu = [r.attrs.pop("cpu_seconds") for r in (loaded, ran)]
    assert all(c >= 0 for c in cpu) and loaded.attrs == ran.attrs
    info = subprocess.run([program, "info", "scene.nml"], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert "3 along the span" in info.stdout


def test_tip_only_output_has_no_stops(program: str, tmp_path: Path) -> None:
    Scene(t_end=0.01, file="tip.h5").to_namelist(tmp_path / "tip.nml")
    assert subprocess.run([program, "run", "tip.nml"], cwd=tmp_path, capture_output=True, timeout=60).returncode == 0
    with h5py.File(tmp_path / "tip.h5") as f:
        assert "stops" not in f and f.attrs["lower"] == -0.1
    result = beamstops.load(tmp_path / "tip.h5")
    assert result.stops_u.shape == (result.t.size, 0)


def test_killed_run_resumes_bit_for_bit(program: str, tmp_path: Path) -> None:
    text = SUPPORTS.replace(dt=1e-6, t_end=1.0, record_every=7, snapshot_every=9973).groups()
    for name in ("reference", "killed"):
        Scene(**{k: v for g in text.values() for k, v in g.items()}).replace(
            file=f"{name}.h5", checkpoint_every=100000).to_namelist(tmp_path / f"{name}.nml")
    assert subprocess.run([program, "run", "reference.nml"], cwd=tmp_path, timeout=300).returncode == 0
    process = subprocess.Popen([program, "run", "killed.nml"], cwd=tmp_path, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    checkpoint = tmp_path / "killed.h5.checkpoint"
    deadline = time.time() + 120
    while not checkpoint.exists() and time.time() < deadline and process.poll() is None:
        time.sleep(0.005)
    if process.poll() is not None:
        pytest.skip("the run ended before it could be killed")
    process.send_signal(signal.SIGKILL)
    process.wait()
    assert subprocess.run([program, "run", "killed.nml", "--restart"], cwd=tmp_path, timeout=300).returncode == 0
    with h5py.File(tmp_path / "killed.h5") as a, h5py.File(tmp_path / "reference.h5") as b:
        for name in ("stops/u", "stops/reaction", "tip/u", "energy/E", "energy/dissipated"):
            assert same_bits(a[name][()], b[name][()]), name


def test_stops_plot(tmp_path: Path) -> None:
    from beamstops import plots

    result = beamstops.run(SUPPORTS)
    path = plots.save(result, tmp_path / "stops.png", kind="stops")
    assert path.stat().st_size > 10000
    figure = plots.figure(result, "stops")
    assert len(figure.axes) == 3
    # a tip-only result has no stops along the span: the kind says so
    with pytest.raises(ValueError, match="no stops along the span"):
        plots.figure(beamstops.run(Scene(t_end=0.01)), "stops")


def test_all_has_a_panel_per_stop_along_the_span(tmp_path: Path) -> None:
    from beamstops import plots

    result = beamstops.run(SUPPORTS.replace(t_end=0.1))
    titles = [ax.get_title() for ax in plots.figure(result, "all").axes]
    for stop, node in enumerate((10, 20, 30), start=1):
        assert any(t.startswith(f"stop {stop}: node {node}, x = ") for t in titles), (stop, titles)
    # a tip-only run has none
    bare = [ax.get_title() for ax in plots.figure(beamstops.run(Scene(t_end=0.01)), "all").axes]
    assert not any(t.startswith("stop ") for t in bare)


def test_cli_plot_stops(program: str, tmp_path: Path) -> None:
    SUPPORTS.replace(file="s.h5").to_namelist(tmp_path / "s.nml")
    assert subprocess.run([program, "run", "s.nml"], cwd=tmp_path, capture_output=True, timeout=60).returncode == 0
    done = subprocess.run([sys.executable, "-m", "beamstops", "plot", "s.h5", "--kind", "stops"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "s_stops.png").is_file()


def test_the_readme_example_runs_as_written(monkeypatch: pytest.MonkeyPatch) -> None:
    readme = (INPUT.parent / "README.md").read_text(encoding="utf-8")
    section = readme.split("\n## Stops along the span\n", 1)[1].split("\n## ", 1)[0]
    blocks = section.split("```python\n")[1:]
    assert blocks, "the section has a Python example"
    monkeypatch.chdir(INPUT.parent)  # its paths are the repository's
    names: dict[str, object] = {}
    exec(blocks[0].split("```", 1)[0], names)  # noqa: S102 (the README's own example)
    assert names["scene"].nodes == names["same"].nodes == names["tube"].nodes == (10, 20, 30)
    assert names["result"].stops_u.shape[1] == 3

"""Sweep specifications: parsing, ranges, product and zip, periods, and bad specifications."""

from __future__ import annotations

import copy
import math
import random
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from beamstops import Scene, cli
from beamstops.sweep import SpecError, load_spec, parse_spec
from beamstops.sweep.reductions import strobe

ROOT = Path(__file__).resolve().parents[2]

GOOD = """
[sweep]
description = "test"
zip = [["lower", "upper"]]

[scene]
elements = 4
dt = 1e-4
t_end = 0.1

[axes]
lower = [-0.05, -0.1]
upper = [0.05, 0.1]
amplitude = { start = 0.1, stop = 0.3, step = 0.1 }

[reductions.u_max]
kind = "max"
quantity = "tip_u"
after = 0.05
"""


def test_product_with_a_zip_group_and_decimal_steps(write_spec: Callable[..., Path]) -> None:
    spec = load_spec(write_spec(GOOD))
    assert len(spec.points) == 6
    assert spec.axes["amplitude"] == [0.1, 0.2, 0.3]  # written numbers, not 0.30000000000000004
    assert [p.params for p in spec.points[:4]] == [
        {"lower": -0.05, "upper": 0.05, "amplitude": 0.1}, {"lower": -0.05, "upper": 0.05, "amplitude": 0.2},
        {"lower": -0.05, "upper": 0.05, "amplitude": 0.3}, {"lower": -0.1, "upper": 0.1, "amplitude": 0.1}]
    scene = spec.points[4].scene
    assert scene == Scene(elements=4, dt=1e-4, t_end=0.1, lower=-0.1, upper=0.1, amplitude=0.2)
    assert scene.file is None
    assert spec.reductions == {"u_max": {"kind": "max", "quantity": "tip_u", "after": 0.05, "after_periods": None}}


def test_zip_mode_linspace_log_and_integer_axes(write_spec: Callable[..., Path]) -> None:
    spec = load_spec(write_spec("""
[sweep]
mode = "zip"
[axes]
omega = { start = 5, stop = 60, num = 3 }
dt = { start = 1e-6, stop = 1e-4, num = 3, spacing = "log" }
elements = { start = 4, stop = 12, num = 3 }
"""))
    assert [p.params["omega"] for p in spec.points] == [5, 32.5, 60]
    assert [p.params["dt"] for p in spec.points] == pytest.approx([1e-6, 1e-5, 1e-4], rel=1e-12)
    assert [p.scene.elements for p in spec.points] == [4, 8, 12]
    assert all(isinstance(p.params["elements"], int) for p in spec.points)


def test_periods_lock_the_time_grid_to_the_forcing(write_spec: Callable[..., Path]) -> None:
    spec = load_spec(write_spec("""
[scene]
dt = 2e-5
[axes]
omega = [7.0, 20.0, 59.3]
[periods]
t_end = 30
records_per_period = 16
"""))
    for point in spec.points:
        s = point.scene
        period = 2 * math.pi / s.omega
        assert s.dt <= 2e-5 and s.dt > 2e-5 * 0.99
        assert s.t_end == pytest.approx(30 * period, rel=1e-15)
        # a record every T/16: record_every steps of dt make T/16 to round-off
        assert s.record_every * s.dt * 16 == pytest.approx(period, rel=1e-14)
        assert round(s.t_end / s.dt) == 30 * 16 * s.record_every


def test_the_hash_follows_what_runs_not_how_it_is_written(write_spec: Callable[..., Path]) -> None:
    a = load_spec(write_spec(GOOD, "a.toml"))
    reordered = GOOD.replace('description = "test"', 'description = "other words"  # a comment')
    b = load_spec(write_spec(reordered, "b.toml"))
    assert a.hash == b.hash
    c = load_spec(write_spec(GOOD, "c.toml"), overrides=["scene.t_end=0.2"])
    assert c.hash != a.hash and c.points[0].scene.t_end == 0.2


def test_base_namelist_relative_to_the_spec(tmp_path: Path, write_spec: Callable[..., Path]) -> None:
    (tmp_path / "nml").mkdir()
    (tmp_path / "nml" / "base.nml").write_text("&support omega=12.5 /\n&mesh elements=6 /\n")
    spec = load_spec(write_spec('[sweep]\nbase = "nml/base.nml"\n[axes]\namplitude = [0.1]\n'))
    assert spec.points[0].scene.omega == 12.5 and spec.points[0].scene.elements == 6
    (tmp_path / "nml" / "base.nml").write_text("&support omega=13.5 /\n&mesh elements=6 /\n")
    assert load_spec(tmp_path / "spec.toml").hash != spec.hash  # the base's values are in the hash


BAD: list[tuple[str, str, str]] = [
    ("toml syntax", "[axes\nomega = [1]", "not valid TOML"),
    ("unknown table", "[axis]\nomega = [1]", "unknown table 'axis'"),
    ("unknown sweep key", "[sweep]\nmodes = 'zip'\n[axes]\nomega = [1]", "unknown key 'modes' in [sweep]"),
    ("unknown scene key", "[scene]\nomegaa = 3\n[axes]\nomega = [1]", "unknown scene key 'omegaa' in [scene]"),
    ("unknown axis", "[axes]\ngap = [0.1]", "unknown scene key 'gap' in [axes]"),
    ("file", "[axes]\nfile = ['a.h5']", "names each point's output"),
    ("no axes", "[scene]\nomega = 3", "no axes"),
    ("empty axis", "[axes]\nomega = []", "axis omega is empty"),
    ("scalar axis", "[axes]\nomega = 3", "an axis is a list"),
    ("zip lengths", "[sweep]\nmode = 'zip'\n[axes]\nomega = [1, 2]\namplitude = [0.1, 0.2, 0.3]",
     "zip axes of different lengths: omega has 2 values, amplitude has 3 values"),
    ("zip group lengths", "[sweep]\nzip = [['lower', 'upper']]\n[axes]\nlower = [-0.1]\nupper = [0.1, 0.2]",
     "zip axes of different lengths"),
    ("zip unknown axis", "[sweep]\nzip = [['omega', 'dt']]\n[axes]\nomega = [1, 2]", "not an axis"),
    ("non-numeric", "[axes]\nomega = ['fast', 'slow']", "axis omega value = 'fast': not a number"),
    ("non-numeric range", "[axes]\nomega = { start = 'a', stop = 2, num = 3 }", "start = 'a': not a finite number"),
    ("nan", "[axes]\nomega = [nan]", "not a finite number"),
    ("inf in scene", "[scene]\ndt = inf\n[axes]\nomega = [1]", "not a finite number"),
    ("nested list", "[axes]\nomega = [[1, 2]]", "expected a number"),
    ("integer key", "[axes]\nelements = [4.5]", "axis elements value = 4.5: not an integer"),
    ("integer range", "[axes]\nelements = { start = 4, stop = 5, num = 3 }", "axis elements: the range gives 4.5, not an integer"),
    ("text key", "[axes]\nlaw = [1]", "axis law value = 1: expected a string"),
    ("unknown law", "[axes]\nlaw = ['rigid']", "law = 'rigid' is out of range"),
    ("bool number", "[axes]\nomega = [true]", "omega value = True: not a number"),
    ("huge product", "[axes]\nomega = { start = 1, stop = 2, num = 1000 }\namplitude = { start = 0.1, stop = 0.2, num = 1000 }",
     "the axes make 1000000 points (1000 × 1000), more than max_points = 10000"),
    ("huge step range", "[axes]\nomega = { start = 1, stop = 1e9, step = 1e-9 }", "more than max_points"),
    ("range without num", "[axes]\nomega = { start = 1, stop = 2 }", "exactly one of num and step"),
    ("range num and step", "[axes]\nomega = { start = 1, stop = 2, num = 2, step = 1 }", "exactly one of num and step"),
    ("backward step", "[axes]\nomega = { start = 1, stop = 2, step = -1 }", "goes away from stop"),
    ("log of zero", "[axes]\ndt = { start = 0, stop = 1e-4, num = 3, spacing = 'log' }", "start > 0"),
    ("num zero", "[axes]\nomega = { start = 1, stop = 2, num = 0 }", "num = 0"),
    ("range extra key", "[axes]\nomega = { start = 1, stop = 2, num = 2, end = 3 }", "unknown key 'end' in axis omega"),
    ("both", "[scene]\nomega = 1\n[axes]\nomega = [1, 2]", "both in [scene] and in [axes]"),
    ("bad mode", "[sweep]\nmode = 'cartesian'\n[axes]\nomega = [1]", "mode = 'cartesian'"),
    ("periods omega 0", "[axes]\nomega = [0.0, 1.0]\n[periods]\nt_end = 3", "needs omega > 0; point 0"),
    ("periods key", "[axes]\nomega = [1.0]\n[periods]\nt_end = 3\nrecords = 4", "unknown key 'records' in [periods]"),
    ("periods t_end", "[axes]\nomega = [1.0]\n[periods]\nt_end = -3", "[periods] t_end = -3"),
    ("periods and a dt axis", "[axes]\nomega = [1.0]\ndt = [1e-4, 2e-4]\n[periods]\nt_end = 3\nrecords_per_period = 4",
     "an axis of dt would not be the step run"),
    ("periods and t_end", "[scene]\nt_end = 1\n[axes]\nomega = [1.0]\n[periods]\nt_end = 3", "remove t_end"),
    ("reduction kind", "[axes]\nomega = [1]\n[reductions.x]\nkind = 'median'", "kind = 'median'"),
    ("reduction key", "[axes]\nomega = [1]\n[reductions.x]\nkind = 'max'\nwhen = 3", "unknown key 'when'"),
    ("reduction quantity", "[axes]\nomega = [1]\n[reductions.x]\nkind = 'max'\nquantity = 'u'", "quantity = 'u'"),
    ("reduction name", "[axes]\nomega = [1]\n[reductions.status]\nkind = 'max'", "taken by a column"),
    # a strobe's derived columns (NAME_offset, NAME_period) were a second column of that name in
    # summary.csv, and one result was lost in summary.json
    ("strobe's column", "[axes]\nomega = [1]\n[reductions.x]\nkind = 'strobe'\n[reductions.x_period]\nkind = 'max'",
     "reduction name 'x_period' is taken by a column of [reductions.x] (a strobe fills the columns x, x_offset, "
     "x_period); choose another name"),
    ("strobe after", "[axes]\nomega = [1]\n[reductions.x_offset]\nkind = 'final'\n[reductions.x]\nkind = 'strobe'",
     "[reductions.x]: a strobe fills the columns x, x_offset, x_period, and x_offset is [reductions.x_offset]; "
     "choose another name"),
    ("two strobes", "[axes]\nomega = [1]\n[reductions.a]\nkind = 'strobe'\n[reductions.a_offset]\nkind = 'strobe'",
     "reduction name 'a_offset' is taken by a column of [reductions.a]"),
    ("strobe omega 0", "[scene]\nomega = 0.0\n[axes]\namplitude = [1.0]\n[reductions.s]\nkind = 'strobe'",
     "needs omega > 0"),
    ("material incomplete", "[axes]\nyoungs_modulus = [2e11]", "density is missing"),
    ("max_points type", "[sweep]\nmax_points = 'many'\n[axes]\nomega = [1]", "max_points = 'many'"),
    ("timeout", "[sweep]\ntimeout = 0\n[axes]\nomega = [1]", "timeout = 0"),
    ("table as value", "sweep = 3\n[axes]\nomega = [1]", "sweep must be a table"),
]


@pytest.mark.parametrize("text, expected", [(t, e) for _, t, e in BAD], ids=[name for name, _, _ in BAD])
def test_bad_specifications_say_what_is_wrong(text: str, expected: str, write_spec: Callable[..., Path]) -> None:
    path = write_spec(text)
    with pytest.raises(SpecError) as info:
        load_spec(path)
    message = str(info.value)
    assert message.startswith(f"{path}: "), message
    assert expected in message, message
    assert "\n" not in message


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(SpecError, match="no such file"):
        load_spec(tmp_path / "nowhere.toml")


def test_command_line_prints_one_line_and_exits_1(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                  write_spec: Callable[..., Path]) -> None:
    path = write_spec("[axes]\nomega = []\n")
    assert cli.main(["sweep", str(path), "-o", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert err == f"beamstops: error: {path}: axis omega is empty; give at least one value\n"
    assert not (tmp_path / "out").exists()
    bad_set = write_spec(GOOD, "good.toml")
    assert cli.main(["sweep", str(bad_set), "-o", str(tmp_path / "out"), "--set", "axes.omega"]) == 1
    assert "expected TABLE.KEY=VALUE" in capsys.readouterr().err


def test_command_line_in_a_fresh_process_has_no_traceback(tmp_path: Path, write_spec: Callable[..., Path]) -> None:
    path = write_spec("[scene]\nelements = 'many'\n[axes]\nomega = [1.0]\n")
    done = subprocess.run([sys.executable, "-m", "beamstops", "sweep", str(path), "-o", str(tmp_path / "o")],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 1
    assert done.stderr.startswith(f"beamstops: error: {path}: ") and "Traceback" not in done.stderr
    assert "[scene] elements = 'many': not an integer" in done.stderr


def test_dry_run_lists_points_and_refuses_a_point_the_engine_refuses(capsys: pytest.CaptureFixture[str],
                                                                     write_spec: Callable[..., Path]) -> None:
    path = write_spec("[scene]\nt_end = 0.1\nbeta = 0.0\nelements = 4\n[axes]\ndt = [1e-4, 2e-4]\n")
    assert cli.main(["sweep", str(path), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "2 points" in out and "00001: dt=0.0002" in out
    # a point beyond the stability limit of beta = 0, which the program would refuse: the engine's check
    # refuses the specification, as its reader does a value out of range
    path = write_spec("[scene]\nt_end = 0.1\nbeta = 0.0\nelements = 4\n[axes]\ndt = [1e-4, 1e-3]\n")
    assert cli.main(["sweep", str(path), "--dry-run"]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"beamstops: error: {path}: point 1 (dt=0.001): scene: &time dt = 0.001 is out of range; "
                          "allowed: dt < ") and "stability limit" in err and len(err.splitlines()) == 1
    # a point with a value out of range: the engine's reader refuses the specification at once
    path = write_spec("[scene]\nt_end = 0.1\n[axes]\ndt = [1e-4, 0.5]\n")
    assert cli.main(["sweep", str(path), "--dry-run"]) == 1
    err = capsys.readouterr().err
    assert "point 1 (dt=0.5): scene: &time dt = 0.5 is out of range; allowed: 1e-15 <= dt <= t_end" in err


def _mutations(data: dict[str, Any], rng: random.Random) -> dict[str, Any]:
    garbage = ["abc", -1, 0, 1.5, 1e308, -1e-300, math.inf, math.nan, [], {}, [1, "a"], True, 10**12, [[]],
               {"start": 1}, {"start": 1, "stop": 2, "num": 3}, ["x"], [0.1, 0.2]]
    out = copy.deepcopy(data)
    for _ in range(rng.randint(1, 3)):
        tables = [out] + [v for v in out.values() if isinstance(v, dict)]
        tables += [v for t in list(tables) for v in t.values() if isinstance(v, dict)]
        table = rng.choice(tables)
        action = rng.random()
        if action < 0.3 and table:
            del table[rng.choice(list(table))]
        elif action < 0.8 and table:
            table[rng.choice(list(table))] = copy.deepcopy(rng.choice(garbage))
        else:
            table[rng.choice(["omega", "zip", "kind", "t_end", "x y", "num", "step", "sweep"])] = \
                copy.deepcopy(rng.choice(garbage))
    return out


def test_fuzzed_specifications_end_in_spec_errors_only(tmp_path: Path) -> None:
    """Random mutations of a valid specification parse or raise SpecError, never anything else."""
    import tomllib

    data = tomllib.loads(GOOD + "[periods]\nt_end = 2\nrecords_per_period = 4\n"
                         "[reductions.s]\nkind = 'strobe'\ntransient_periods = 1\n")
    rng = random.Random(7)
    outcomes = {"ok": 0, "error": 0}
    for _ in range(400):
        mutated = _mutations(data, rng)
        try:
            spec = parse_spec(mutated, "fuzz.toml", base_dir=tmp_path)
        except SpecError as exc:
            assert str(exc).startswith("fuzz.toml: ") and "\n" not in str(exc)
            outcomes["error"] += 1
        else:
            assert spec.points and len(spec.hash) == 64
            outcomes["ok"] += 1
    assert outcomes["ok"] >= 5 and outcomes["error"] > 100, outcomes


def test_strobe_samples_and_period_detection() -> None:
    omega = 10.0
    period = 2 * math.pi / omega
    import numpy as np

    t = np.arange(0, 40 * 64 + 1) * (period / 64)
    # period-1 (a response at the forcing frequency) and period-2 (half the frequency)
    for x, expected in ((np.sin(omega * t + 0.3), 1), (np.sin(omega * t / 2 + 0.3), 2)):
        times, samples, offset = strobe(t, x, omega, transient_periods=10)
        assert times.size == 31 and offset < 1e-12
        from beamstops.sweep.reductions import _period

        assert _period(samples, 1e-9, 16) == expected
    # a grid not locked to the forcing: the nearest record, at most half a record interval off
    t = np.arange(0, 4001) * 1e-3
    times, samples, offset = strobe(t, np.cos(omega * t), omega, transient_periods=2)
    assert 0 < offset <= 0.5e-3 + 1e-15 and samples.size == int(4.0 / period) - 1


def test_reductions_follow_the_readme_definitions() -> None:
    """reduce() against the README's words, on random records: the strobe's k from transient_periods
    while (k + phase) T is not after the last record, each the nearest record (the earlier of two as
    near); the period p <= n/2 of n samples; mean, rms = sqrt(mean x^2), peak_to_peak over t >= after."""
    from types import SimpleNamespace

    import numpy as np

    from beamstops.sweep.reductions import reduce

    rng = np.random.default_rng(3)
    for _ in range(50):
        omega = float(rng.uniform(5, 60))
        period = 2 * math.pi / omega
        step = float(rng.uniform(0.01, 0.3)) * period
        t = np.arange(int(rng.integers(1, 200))) * step
        x = rng.normal(size=t.size)
        k0, phase, after = int(rng.integers(0, 4)), float(rng.choice([0.0, 0.25, 0.5, 0.9])), float(rng.uniform(0, 3))
        result = SimpleNamespace(attrs={"omega": omega}, t=t, tip_u=x, tip_v=x)
        got = reduce(result, {"s": {"kind": "strobe", "quantity": "tip_u", "transient_periods": k0, "phase": phase,
                                    "tolerance": 1e-6, "max_period": 16},
                              "r": {"kind": "rms", "quantity": "tip_v", "after": after, "after_periods": None},
                              "m": {"kind": "mean", "quantity": "tip_v", "after": None, "after_periods": 1.0}})
        targets = [(k + phase) * period for k in range(k0, 1000) if (k + phase) * period <= t[-1]]
        nearest = [int(np.argmin(np.abs(t - target))) for target in targets]
        assert got["s"] == [float(x[i]) for i in nearest]
        assert got["s_offset"] == (max(abs(t[i] - c) for i, c in zip(nearest, targets)) if targets else None)
        window = x[t >= after]
        assert got["r"] == (pytest.approx(math.sqrt(float(np.mean(window**2))), rel=1e-14) if window.size else None)
        assert got["m"] == pytest.approx(float(np.mean(x[t >= period]))) if (t >= period).any() else got["m"] is None
    # a period p needs n >= 2p samples: [a, b, c, a] is no period 3 (0); [a, b, a, b] is period 2
    from beamstops.sweep.reductions import _period

    assert _period(np.array([1.0, 2.0, 3.0, 1.0]), 1e-9, 16) == 0
    assert _period(np.array([1.0, 2.0, 1.0, 2.0]), 1e-9, 16) == 2


def test_damping_ratio_in_scene_and_axis_and_damped_reduction(write_spec: Callable[..., Path]) -> None:
    spec = load_spec(write_spec("""
[scene]
elements = 4
dt = 1e-4
t_end = 0.1
ratio = 0.015

[axes]
omega = [10, 20]

[reductions.damped]
kind = "final"
quantity = "damped"
"""))
    assert all(p.scene.ratio == (0.015, 0.015) for p in spec.points)
    assert spec.reductions["damped"]["quantity"] == "damped"
    spec = load_spec(write_spec("[scene]\nelements = 4\n[axes]\nratio = [0.01, 0.02]\n"))
    assert [p.scene.ratio for p in spec.points] == [(0.01, 0.01), (0.02, 0.02)]


def test_damped_bifurcation_spec_is_valid() -> None:
    spec = load_spec(ROOT / "input" / "sweeps" / "bifurcation_damped.toml")
    assert spec.points[0].scene.ratio and "damped" in spec.reductions


def test_the_allowed_scene_keys_are_listed_once_each(write_spec: Callable[..., Path]) -> None:
    path = write_spec("[scene]\nomegaa = 3\n[axes]\nomega = [1]")
    with pytest.raises(SpecError) as info:
        load_spec(path)
    allowed = str(info.value).split("allowed: ", 1)[1].split(", ")
    assert "modes" in allowed and "omega" in allowed
    assert len(allowed) == len(set(allowed)), sorted(k for k in allowed if allowed.count(k) > 1)
    # a sweep's `modes` is the reduced model's (&mesh); the damping modes keep the base scene's
    points = load_spec(write_spec("[axes]\nmodes = [0, 4]\n", "modes.toml")).points
    assert [p.scene.modes for p in points] == [0, 4]
    assert {p.scene.damping_modes for p in points} == {Scene().damping_modes}


@pytest.mark.parametrize("axes, count, shape", [
    ("omega = { start = 1, stop = 2, step = 1e-300 }", "about 1e+300", "about 1e+300"),
    ("omega = { start = 1, stop = 2, step = 1e-300 }\namplitude = { start = 0, stop = 0.1, step = 1e-300 }\n"
     "dt = { start = 1e-5, stop = 2e-5, step = 1e-307 }", "about 1e+901", "about 1e+300 × about 1e+299 × about 1e+302"),
    ("omega = { start = 1, stop = 2, step = 1e-12 }", "about 1e+12", "about 1e+12"),
    ("omega = { start = 1, stop = 2, num = 100000 }\namplitude = [0.1, 0.2]", "200000", "100000 × 2"),
])
def test_a_huge_number_of_points_is_written_compactly(axes: str, count: str, shape: str,
                                                      write_spec: Callable[..., Path]) -> None:
    """A step of 1e-300 printed a count of 301 digits, twice (a line of 721 characters)."""
    path = write_spec(f"[axes]\n{axes}\n")
    with pytest.raises(SpecError) as info:
        load_spec(path)
    assert str(info.value) == (f"{path}: the axes make {count} points ({shape}), more than max_points = 10000; "
                               "set [sweep] max_points if you mean it")


def test_zip_axes_of_huge_lengths_are_written_compactly(write_spec: Callable[..., Path]) -> None:
    path = write_spec("[sweep]\nmode = 'zip'\n[axes]\nomega = { start = 1, stop = 2, step = 1e-300 }\n"
                      "amplitude = [0.1, 0.2]\n")
    with pytest.raises(SpecError) as info:
        load_spec(path)
    assert str(info.value) == (f"{path}: zip axes of different lengths: omega has about 1e+300 values, amplitude has "
                               "2 values")


def test_max_points_is_at_most_what_the_engine_checks_in_reasonable_time(write_spec: Callable[..., Path]) -> None:
    """max_points up to 10,000,000 was accepted, but every point's scene is read and checked by the
    engine before anything runs (a --dry-run of 10M points ran for minutes and 4.4 GB and had not
    ended): the largest sweep accepted is 100,000 points."""
    path = write_spec("[sweep]\nmax_points = 100001\n[axes]\nomega = [1.0]\n")
    with pytest.raises(SpecError) as info:
        load_spec(path)
    assert str(info.value) == f"{path}: [sweep] max_points = 100001; allowed: an integer 1 ... 100000"
    assert len(load_spec(write_spec("[sweep]\nmax_points = 100000\n[axes]\nomega = [1.0]\n")).points) == 1


def test_the_hash_is_the_resolved_specification_s_text_written_point_by_point(write_spec: Callable[..., Path]) -> None:
    """The hash is computed point by point (the text of 100,000 points is some 200 MB), and is the one
    of the whole text, so that folders written before resume."""
    import hashlib
    import json

    spec = load_spec(write_spec(GOOD))
    text = json.dumps(spec.resolved(), sort_keys=True, allow_nan=False)
    assert spec.hash == hashlib.sha256(text.encode()).hexdigest()
    scene = spec.points[0].scene
    assert scene.to_dict() == __import__("dataclasses").asdict(scene)

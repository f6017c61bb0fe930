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
    """Run twice into one folder: the second run writes over the first's outputs (and only over them:
    tests/python/test_output_files.py)."""
    for _ in range(2):
        assert cli.main([command, "--quick", "--quiet", "-o", str(tmp_path)]) == 0
        for name in files:
            assert (tmp_path / name).stat().st_size > 0, name
        assert str(tmp_path) in capsys.readouterr().out


@pytest.mark.parametrize("command, option, value, allowed", [
    ("converge", "--transient", "-1", "a time in s >= 0"),
    ("converge", "--transient", "nan", "a time in s >= 0"),
    ("converge", "--stat-window", "0", "a time in s > 0"),
    ("converge", "--reference-window", "-4", "a time in s > 0"),
    ("converge", "--members", "0", "a whole number of members >= 1"),
    ("work-precision", "--members", "-3", "a whole number of members >= 1"),
    ("work-precision", "--window", "-1", "a time in s > 0"),
    ("compliance", "--cutoff", "-5", "a frequency in Hz > 0"),
    ("compliance", "--cutoff", "nan", "a frequency in Hz > 0"),
    ("stability-map", "--threshold", "-1", "a factor of energy growth > 0"),
])
def test_bad_study_options_are_refused_before_anything_runs(tmp_path: Path, command: str, option: str, value: str,
                                                            allowed: str, capsys: pytest.CaptureFixture[str]) -> None:
    """They ran: compliance and stability-map with the nonsense (exit 0), converge and
    work-precision into the engine's message about a scene's &time t_end or &statistics
    transient (the option unnamed), the output folder made."""
    args = [command, "--quick", "--quiet", "-o", str(tmp_path / "out")]
    if command in ("converge", "work-precision") and option not in ("--window",):
        args += ["--qoi", "stop_power"]
    with pytest.raises(SystemExit) as exit_:
        cli.main(args + [f"{option}={value}"])
    assert exit_.value.code == 2
    assert f"argument {option}: '{value}': allowed: {allowed}" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_output_that_is_a_file_is_refused_and_kept(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """-o naming an existing file: one line that says -o takes a folder (it read '[Errno 17] File
    exists'), exit 1, the file untouched."""
    target = tmp_path / "notes.txt"
    target.write_text("keep me")
    assert cli.main(["stability-map", "--quick", "--quiet", "-o", str(target)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "is not a folder" in err[0] and str(target) in err[0]
    assert target.read_text() == "keep me"


@pytest.mark.parametrize("command, options, line", [
    ("converge", ["--quick", "--qoi", "stop_power", "--members", "100000"],
     "argument --members: 100000: allowed: a whole number of members, 1 ... 10000 (the engine: scene: &ensemble "
     "members = 100000 is out of range; allowed: 1 <= members <= 10000)"),
    ("converge", ["--transient", "1e9"], "argument --transient: 1e+09: allowed: a time in s, 0 ... "),
    ("converge", ["--quick", "--stat-window", "1e-9"],
     "argument --stat-window: 1e-09: allowed: a time in s, 2e-05 ... "),
    ("work-precision", ["--quick", "--qoi", "stop_power", "--reference-window", "1e12"],
     "argument --reference-window: 1e+12: allowed: a time in s, 5e-06 ... 555500 (the engine: scene: &time t_end"),
    ("work-precision", ["--window", "1e9"],
     "argument --window: 1e+09: allowed: a time in s for each window [0, W], 5e-05 ... "),
    ("work-precision", ["--quick", "--window", "0.2", "0.1"],
     "argument --window: 0.2 0.1: allowed: with --quick, one window W <= 0.05 s"),
])
def test_study_options_the_engine_would_refuse_are_refused_naming_the_option(
        tmp_path: Path, command: str, options: list[str], line: str, capsys: pytest.CaptureFixture[str]) -> None:
    """They went through argparse and ended the study in the engine's message about one of its
    scenes (`scene: &time t_end = 1.000000002e+09 is out of range`, `&statistics transient = 0.5`),
    exit status 1, the option unnamed; --quick --window 0.2 0.1 ran on 0.05 s unsaid. Now: argparse's
    one line naming the option and the range whose scenes the engine accepts, exit 2, nothing made."""
    with pytest.raises(SystemExit) as exit_:
        cli.main([command, "--quiet", "-o", str(tmp_path / "out"), *options])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith(f"python -m beamstops {command}: error: {line}"), err
    assert err.count("\n") == 1 and not (tmp_path / "out").exists()


def test_the_ranges_stated_for_study_options_are_accepted() -> None:
    """The bounds a refusal states are values whose scenes the engine accepts; values within pass."""
    import argparse
    import re

    from beamstops.studies import options

    def namespace(**given: object) -> argparse.Namespace:
        values = {"quick": True, "members": None, "transient": None, "stat_window": None, "reference_window": None,
                  "window": None}
        return argparse.Namespace(**{**values, **given})

    refused = options.check_statistical("converge", namespace(stat_window=1e-9))
    assert refused is not None
    low, high = map(float, re.search(r"allowed: a time in s, (\S+) \.\.\. (\S+) \(", refused).groups())
    for value in (low, high, 1.0):
        assert options.check_statistical("converge", namespace(stat_window=value)) is None, value
    assert options.check_statistical("converge", namespace(stat_window=high * 1.01)) is not None
    assert options.check_statistical("work-precision", namespace(members=1, transient=0.0)) is None
    assert options.check_windows(namespace(window=[0.05])) is None
    assert options.check_windows(namespace(window=[0.03, 0.04])) is not None  # --quick: one window

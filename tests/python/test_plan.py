"""``plan``: the cheapest model under a tolerance, checked against runs much finer than the search's."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import beamstops
from beamstops import cli
from beamstops.plan import Plan, Quantity, parse_tolerance, plan

FREE = beamstops.Scene(law="none", t_end=0.1)
PAPER_SHORT = beamstops.Scene(t_end=4.0, transient=1.0)


@pytest.fixture(scope="module")
def free_plan() -> Plan:
    return plan(FREE, "tip", 5e-4, until=0.08, quiet=True)


def test_trajectory_choice_is_within_tolerance_of_a_much_finer_run(free_plan: Plan) -> None:
    chosen = free_plan.scene
    assert chosen is not None and free_plan.choice is not None and free_plan.choice.qualifies
    # the choice is cheaper than the finest rungs of the search: the tolerance is loose enough to coarsen
    assert chosen.dt > FREE.dt / 8
    grid = chosen.dt
    mine = beamstops.run(chosen.replace(t_end=0.08))
    fine_dt = chosen.dt / 16
    reference = beamstops.run(FREE.replace(elements=4 * chosen.elements, dt=fine_dt, t_end=0.08,
                                           record_every=round(grid / fine_dt)))
    n = min(mine.t.size, reference.t.size)
    assert np.allclose(mine.t[:n], reference.t[:n], rtol=0, atol=1e-12)
    measured = float(np.abs(mine.tip_u[:n] - reference.tip_u[:n]).max())
    assert 0 < measured < 5e-4
    assert free_plan.check is not None and free_plan.check.passed
    assert free_plan.check.difference < 5e-4


def test_trajectory_estimates_are_not_below_the_measured_error(free_plan: Plan) -> None:
    # every candidate that failed was estimated above the tolerance; the cheapest among the evaluated
    # candidates that qualify is chosen, and the table lists it
    assert all(c.error > 5e-4 for c in free_plan.candidates if not c.qualifies)
    assert "**chosen**" in free_plan.table()
    assert free_plan.choice is min((c for c in free_plan.candidates if c.qualifies), key=lambda c: c.cpu_per_second)


def test_tighter_tolerance_costs_more() -> None:
    loose = plan(FREE, "tip", 2e-3, until=0.08, quiet=True)
    tight = plan(FREE, "tip", 2e-4, until=0.08, quiet=True)
    assert loose.choice is not None and tight.choice is not None
    assert tight.choice.cpu_per_second > loose.choice.cpu_per_second
    assert tight.choice.error <= 2e-4 < loose.choice.error or tight.choice.error < loose.choice.error


def test_statistic_choice_overlaps_a_finer_reference() -> None:
    result = plan(PAPER_SHORT, "power", "20%", quiet=True)
    assert result.choice is not None and result.choice.qualifies and result.scene is not None
    assert result.window is not None and result.window > 0
    assert result.scene.t_end == pytest.approx(PAPER_SHORT.transient + result.window)
    chosen = beamstops.run(result.scene.replace(record_every=100)).statistics["power"]
    # the same run as the plan's (the engine is deterministic)
    assert float(chosen.value[0]) == result.choice.value
    finer = result.scene.replace(elements=2 * result.scene.elements, dt=result.scene.dt / 4, record_every=400)
    reference = beamstops.run(finer).statistics["power"]
    v, h, vr, hr = float(chosen.value[0]), float(chosen.half_width[0]), float(reference.value[0]), float(reference.half_width[0])
    assert abs(v - vr) <= h + hr, (v, h, vr, hr)
    assert abs(v - vr) <= result.tolerance
    assert result.check is not None and result.check.overlap


def test_budget_stops_the_search_and_says_so() -> None:
    result = plan(FREE, "tip", 1e-6, until=0.08, budget=0.003, quiet=True)
    assert result.stopped is not None and "budget" in result.stopped
    assert "stopped: budget" in result.summary()
    assert result.choice is None or not result.choice.qualifies


def test_relative_tolerance_and_bad_inputs() -> None:
    assert parse_tolerance("2%") == (0.02, True)
    assert parse_tolerance(0.01) == (0.01, False)
    for bad in ("0", "-1", "0%", "abc", "nan"):
        with pytest.raises(ValueError, match="tolerance"):
            parse_tolerance(bad)
    with pytest.raises(ValueError, match="unknown quantity 'energy'"):
        plan(FREE, "energy", 1e-3)
    with pytest.raises(ValueError, match="until"):
        Quantity("tip")
    with pytest.raises(ValueError, match="unknown law"):
        plan(FREE, "tip", 1e-3, until=0.05, laws=["spring"])
    with pytest.raises(ValueError, match="compliance' needs a stiffness"):
        plan(FREE, "tip", 1e-3, until=0.05, laws=["compliance"], quiet=True)


def test_python_arguments_of_the_wrong_kind_are_refused_by_name() -> None:
    """plan(S, "power", True) ran with a tolerance of 1.0; a None tolerance, until='0.01' and a path
    for the scene gave raw TypeErrors and AttributeErrors; until with a statistic was ignored; a
    window shorter than one step qualified with nothing but the start to compare."""
    cases: list[tuple[Any, type[Exception], str]] = [
        (lambda: plan(FREE, "power", True), TypeError, "tolerance True: allowed: a finite number > 0"),
        (lambda: plan(FREE, "tip", None, until=0.01), TypeError, "tolerance None: allowed"),
        (lambda: plan(FREE, "tip", "1e400", until=0.01), ValueError, "tolerance '1e400': allowed: a finite number"),
        (lambda: plan(FREE, "tip", 1e-2, until="0.01"), TypeError, "until '0.01': allowed: a time in s > 0"),
        (lambda: plan(FREE, "tip", 1e-2, until=np.nan), ValueError, "until nan: allowed: a time in s > 0"),
        (lambda: plan(FREE, "tip", 1e-2, until=1e-9), ValueError, "until 1e-09 s: shorter than one step"),
        (lambda: plan(FREE, "power", 1e-2, until=0.05), ValueError, "until 0.05: the window .* is the tip's"),
        (lambda: plan(None, "tip", 1e-2, until=0.01), TypeError, "scene: a beamstops.Scene or the path of a namelist"),
        (lambda: plan(FREE, None, 1e-2), TypeError, "quantity None: allowed: one of tip, power"),
        (lambda: plan(FREE, "tip", 1e-2, until=0.01, laws=""), ValueError, "laws '': no law given; allowed"),
        (lambda: plan(FREE, "tip", 1e-2, until=0.01, laws="none,spring"), ValueError, "unknown law.*'spring'"),
        (lambda: plan(FREE, "tip", 1e-2, until=0.01, laws=[None]), TypeError, "laws \\[None\\]: allowed"),
        (lambda: plan(FREE, "tip", 1e-2, until=0.01, budget=np.nan), ValueError, "budget nan: allowed"),
        (lambda: plan(FREE, "tip", 1e-2, until=0.01, budget="60"), TypeError, "budget '60': allowed"),
        (lambda: plan(FREE, "tip", 1e-2, until=0.01, coarser=1.5), ValueError, "coarser 1.5: allowed: a whole"),
        (lambda: plan(FREE, "tip", 1e-2, until=0.01, finer=True), ValueError, "finer True: allowed: a whole"),
        (lambda: plan(FREE, "tip", 1e-2, until=0.01, safety=-1), ValueError, "safety -1: allowed"),
    ]
    for call, error, message in cases:
        with pytest.raises(error, match=message):
            call()


def test_python_plan_takes_a_namelist_path_and_one_law_as_a_string(tmp_path: Path) -> None:
    """plan('x.nml', ...) raised AttributeError; laws='none' was read letter by letter ("unknown
    law(s) n, o, n, e")."""
    FREE.to_namelist(tmp_path / "free.nml")
    for scene in (str(tmp_path / "free.nml"), tmp_path / "free.nml"):
        outcome = plan(scene, "tip", 5e-2, until=0.02, laws="none", quiet=True)
        assert outcome.met and outcome.scene is not None and outcome.scene.law == "none"
        assert {c.model.law for c in outcome.candidates} == {"none"}


@pytest.mark.parametrize("scene, until", [
    (beamstops.Scene(t_end=1e-4), 1e-4),  # the rung 2e-4 s: "scene: &time dt = 0.0002 is out of range"
    (beamstops.Scene(t_end=0.1, dt=0.1), 0.1),
    # "scene: &mesh modes = 4 with an ensemble (&ensemble members > 1) is not supported"
    (beamstops.Scene(t_end=0.05, members=3, perturbation=1e-6), 0.01),
], ids=["t_end_one_rung", "dt_is_t_end", "ensemble"])
def test_valid_scenes_plan(scene: beamstops.Scene, until: float) -> None:
    """The plan refused valid scenes with messages about its own candidates: a Δt rung longer than
    the window (left out now, as rungs the engine refuses for stability are skipped), a reduced
    model for an ensemble scene (which the engine runs only in full)."""
    outcome = plan(scene, "tip", 1e-2, until=until, quiet=True)
    assert outcome.met and outcome.scene is not None, outcome.summary()
    assert all(c.model.dt <= until for c in outcome.candidates)
    assert outcome.scene.members == scene.members and outcome.scene.t_end == scene.t_end
    if scene.members > 1:
        assert all(c.model.modes == 0 for c in outcome.candidates) and outcome.scene.modes == 0


def test_cli_writes_the_chosen_scene(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scene_file = tmp_path / "free.nml"
    FREE.to_namelist(scene_file)
    assert cli.main(["plan", str(scene_file), "--qoi", "tip", "--until", "0.08", "--tol", "1e-3", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert ("| law | J | Δt (s) |" in out or "| law | J | modes | Δt (s) |" in out) and "PASS" in out
    assert "**chosen**" in out
    written = beamstops.Scene.from_namelist(tmp_path / "free_plan.nml")
    expected = plan(FREE, "tip", 1e-3, until=0.08, quiet=True).scene
    assert expected is not None
    assert written.dt == expected.dt and written.elements == expected.elements and written.law == "none"
    assert written.t_end == FREE.t_end


@pytest.mark.parametrize("arguments, message", [
    (["--qoi", "tip", "--until", "0.5", "--tol", "1e-3"],
     "--until 0.5 s: beyond the scene's t_end (dt = 5e-05 s, t_end = 0.1 s); allowed: 5e-05 <= --until <= 0.1 s"),
    # a window shorter than one step "qualified" with nothing but the start to compare (exit 0)
    (["--qoi", "tip", "--until", "1e-9", "--tol", "1e-3"],
     "--until 1e-09 s: shorter than one step of the scene (dt = 5e-05 s, t_end = 0.1 s); allowed: 5e-05 <= --until"),
])
def test_cli_bad_input_is_one_line_and_exit_1(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                arguments: list[str], message: str) -> None:
    scene_file = tmp_path / "free.nml"
    FREE.to_namelist(scene_file)
    assert cli.main(["plan", str(scene_file), *arguments, "--quiet"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("beamstops: error:") and message in err[0], err
    assert not (tmp_path / "free_plan.nml").exists()


TOLERANCE = ("allowed: a finite number > 0 (absolute, in the quantity's unit: m, W, N, 1/s, 1), or a finite "
             "percentage > 0 such as 2%")


@pytest.mark.parametrize("arguments, message", [
    (["--qoi", "tip", "--until", "0.08", "--tol", "0"], f"argument --tol: '0': {TOLERANCE}"),
    (["--qoi", "tip", "--until", "0.08", "--tol", "-0.001"], "argument --tol: '-0.001': allowed"),
    (["--qoi", "power", "--tol", "1e400"], f"argument --tol: '1e400': {TOLERANCE}"),  # said "must be > 0"
    (["--qoi", "power", "--tol", "1e400%"], "argument --tol: '1e400%': allowed"),
    (["--qoi", "energy", "--tol", "1e-3"], "argument --qoi: 'energy': allowed: one of tip, power,"),
    (["--qoi", "tip", "--tol", "1e-3"], "argument --until: --qoi tip needs the end of its window"),
    # silently ignored, the window being the statistic's transient to t_end
    (["--qoi", "power", "--until", "0.05", "--tol", "0.1"], "argument --until: the window [0, UNTIL] is --qoi tip's only"),
    (["--qoi", "tip", "--until", "-1", "--tol", "0.1"], "argument --until: '-1': allowed: a time in s > 0"),
    # these exited 1 (after reading the scene) where every other option error exits 2
    (["--qoi", "power", "--tol", "0.1", "--budget", "-1"], "argument --budget: '-1': allowed: engine CPU seconds > 0"),
    (["--qoi", "power", "--tol", "0.1", "--coarser", "100"], "argument --coarser: '100': allowed: a whole number of "
                                                              "powers of 2 of the scene's Δt, 0 ... 20"),
    (["--qoi", "power", "--tol", "0.1", "--coarser", "-1"], "argument --coarser: '-1': allowed"),
    (["--qoi", "power", "--tol", "0.1", "--finer", "100"], "argument --finer: '100': allowed: a whole number of "
                                                            "powers of 2 of the scene's Δt, 2 ... 20"),
    (["--qoi", "power", "--tol", "0.1", "--max-window", "-1"], "argument --max-window: '-1': allowed: a window after "
                                                                "the transient in s > 0"),
    (["--qoi", "power", "--tol", "0.1", "--max-window", "nan"], "argument --max-window: 'nan': allowed"),
    (["--qoi", "power", "--tol", "0.1", "--safety", "0"], "argument --safety: '0': allowed"),
    (["--qoi", "power", "--tol", "0.1", "--stop", "-1"], "argument --stop: '-1': allowed: a whole number of"),
    # fell back to the scene's own law
    (["--qoi", "power", "--tol", "0.1", "--laws", ""], "argument --laws: '': allowed: one or more of signorini, "
                                                        "redistributed, compliance, none, separated by commas"),
    (["--qoi", "power", "--tol", "0.1", "--laws", "signorini,spring"], "argument --laws: 'signorini,spring': allowed"),
    (["--qoi", "power", "--tol", "0.1", "-o", ""], "argument -o/--output: '': allowed: a file name"),
])
def test_cli_bad_options_are_one_line_and_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                 arguments: list[str], message: str) -> None:
    """As every subcommand's option errors (README): argparse's `argument --X:` line, exit 2, before
    the scene is read or anything runs."""
    with pytest.raises(SystemExit) as exit_:
        cli.main(["plan", str(tmp_path / "absent.nml"), *arguments, "--quiet"], prog="beamstops")
    assert exit_.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("beamstops plan: error: ") and message in err[0], err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("kind", ["hdf5", "hand", "folder"])
def test_cli_output_is_written_only_over_its_own_scenes(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                         kind: str) -> None:
    """-o at an existing file plan did not write (an output, a namelist of one's own) or at a
    folder: refused before planning, one line, exit 1, the file kept (it was overwritten)."""
    scene_file = tmp_path / "free.nml"
    FREE.to_namelist(scene_file)
    target = tmp_path / ("run.h5" if kind == "hdf5" else "mine.nml" if kind == "hand" else "folder")
    if kind == "folder":
        target.mkdir()
    else:
        target.write_bytes(b"\x89HDF\r\n\x1a\n" if kind == "hdf5" else b"&time dt = 1e-5 /\n")
    before = None if kind == "folder" else target.read_bytes()
    arguments = ["plan", str(scene_file), "--qoi", "tip", "--until", "0.08", "--tol", "1e-3", "--quiet", "-o", str(target)]
    assert cli.main(arguments) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(target) in err[0], err
    if before is not None:
        assert target.read_bytes() == before
    # its own earlier output is written over
    own = tmp_path / "own.nml"
    FREE.to_namelist(own)
    assert cli.main([*arguments[:-1], str(own)]) == 0
    assert beamstops.Scene.from_namelist(own).law == "none"


def test_mesh_ladder_with_and_without_the_reduced_model(monkeypatch: pytest.MonkeyPatch) -> None:
    from beamstops import plan_runs as module

    monkeypatch.setattr(module, "reduced_available", lambda: False)
    ladder = module.mesh_ladder(PAPER_SHORT)
    assert ladder.rungs == [(5, 0), (10, 0), (19, 0), (38, 0)]
    assert ladder.chain((5, 0), 3) == [(5, 0), (10, 0), (19, 0)] and ladder.refinable() == [(5, 0), (10, 0), (19, 0)]
    ladder.extend()
    assert ladder.chain((19, 0), 3) == [(19, 0), (38, 0), (76, 0)]
    # stops along the span keep their nodes: no J/4 or J/2 that would move them off the nodes
    spans = module.mesh_ladder(beamstops.Scene(nodes=(10, 19), lower=-0.1, upper=0.1, elements=19))
    assert spans.rungs == [(19, 0), (38, 0)]
    # with the reduced model's key (&mesh modes, 0 = full): modes 4, 8, ... refine towards the full model
    monkeypatch.setattr(module, "reduced_available", lambda: True)
    reduced = module.mesh_ladder(PAPER_SHORT)
    assert reduced.chain((19, 4), 7) == [(19, 4), (19, 8), (19, 16), (19, 32), (19, 0), (38, 0)]
    assert module.ratio((19, 32), (19, 0)) == pytest.approx(38 / 32)


def test_other_laws_carry_their_distance_to_the_scenes_law() -> None:
    paper = beamstops.Scene(t_end=0.2)
    # before the first impact (t = 0.088 s) the law without stops is the same run as Signorini's
    before = plan(paper, "tip", 1e-3, until=0.08, laws=["none", "signorini"], quiet=True, exhaustive=True)
    nones = [c for c in before.candidates if c.model.law == "none"]
    assert nones and all(c.parts["law"] == 0.0 for c in nones)
    # through the first impacts it is not: its distance to Signorini alone exceeds the tolerance
    after = plan(paper, "tip", 1e-3, until=0.15, laws=["none", "signorini"], quiet=True, finer=2, extend=0)
    nones = [c for c in after.candidates if c.model.law == "none"]
    assert nones and all(c.parts["law"] > 1e-3 and not c.qualifies for c in nones)
    assert after.choice is None or after.choice.model.law == "signorini"


def test_a_shock_log_larger_than_its_room_runs_again_to_the_same_result() -> None:
    small = beamstops.run(PAPER_SHORT, shock_capacity=1)
    roomy = beamstops.run(PAPER_SHORT, shock_capacity=10_000)
    assert small.shocks == roomy.shocks > 1
    assert np.array_equal(small.impacts["impulse"], roomy.impacts["impulse"])
    assert np.array_equal(small.statistics["power"].value, roomy.statistics["power"].value)


def test_until_beyond_the_scenes_t_end_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(ValueError, match=r"until 0\.5 s: beyond the scene's t_end \(dt = 5e-05 s, t_end = 0\.1 s\); "
                                         r"allowed: 5e-05 <= until <= 0\.1 s"):
        plan(FREE, "tip", 1e-3, until=0.5, quiet=True)
    scene_file = tmp_path / "free.nml"
    FREE.to_namelist(scene_file)
    assert cli.main(["plan", str(scene_file), "--qoi", "tip", "--until", "0.5", "--tol", "1e-3", "--quiet"]) == 1
    assert "allowed: 5e-05 <= --until <= 0.1 s" in capsys.readouterr().err


def test_a_plan_that_does_not_meet_the_tolerance_exits_3_and_writes_nothing(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scene_file = tmp_path / "free.nml"
    FREE.to_namelist(scene_file)
    status = cli.main(["plan", str(scene_file), "--qoi", "tip", "--until", "0.05", "--tol", "1e-12", "--quiet"])
    captured = capsys.readouterr()
    assert status == 3
    assert "does NOT qualify" in captured.out  # what it found is still printed
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("beamstops: error: plan: no model met the tolerance 1e-12 m"), err
    assert err[0].endswith(f"{tmp_path / 'free_plan.nml'} not written")
    assert not (tmp_path / "free_plan.nml").exists()
    with pytest.raises(SystemExit):
        cli.main(["plan", "--help"])
    assert "3 the plan does not meet the tolerance" in capsys.readouterr().out


def test_a_plan_whose_check_fails_exits_3(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    from beamstops import plan_cli
    from beamstops.plan import Candidate, Check, Model

    model, finer = Model("none", 19, 0, 1e-4), Model("none", 38, 0, 5e-5)
    outcome = Plan(quantity=Quantity("tip", until=0.05), tolerance=1e-3, relative=None, unit="m",
                   candidates=[Candidate(model, 0.03, float("nan"), 5e-4, {}, 0.01, "qualifies")])
    outcome.choice, outcome.scene = outcome.candidates[0], FREE
    outcome.check = Check(finer, 0.03, float("nan"), 0.032, float("nan"), 2e-3, 1e-3, None)
    assert not outcome.met and "measured 0.002 m > tolerance 0.001 m" in (outcome.shortfall() or "")
    monkeypatch.setattr(plan_cli, "plan", lambda *args, **kwargs: outcome)
    scene_file = tmp_path / "free.nml"
    FREE.to_namelist(scene_file)
    assert cli.main(["plan", str(scene_file), "--qoi", "tip", "--until", "0.05", "--tol", "1e-3", "--quiet"]) == 3
    captured = capsys.readouterr()
    assert "FAIL" in captured.out and "qualified by its estimate, but its check" in captured.err
    assert not (tmp_path / "free_plan.nml").exists()
    # the same plan with a passing check is written, exit 0
    outcome.check = Check(finer, 0.03, float("nan"), 0.0302, float("nan"), 2e-4, 1e-3, None)
    assert outcome.met
    assert cli.main(["plan", str(scene_file), "--qoi", "tip", "--until", "0.05", "--tol", "1e-3", "--quiet"]) == 0
    assert (tmp_path / "free_plan.nml").exists()


def test_a_choice_on_the_coarsest_dt_rung_names_the_next_coarser_value() -> None:
    loose = plan(FREE, "tip", 5e-2, until=0.08, coarser=0, quiet=True)
    assert loose.choice is not None and loose.choice.qualifies and loose.choice.model.dt == FREE.dt
    note = next(n for n in loose.notes if "coarsest Δt rung" in n)
    assert "(coarser=1 from Python, --coarser 1 on the command line)" in note, note
    assert "coarser=," not in " ".join(loose.notes)


def test_the_readme_states_the_mesh_ladder_and_the_check_the_code_uses() -> None:
    from beamstops import plan_runs

    readme = (Path(__file__).resolve().parents[2] / "README.md").read_text(encoding="utf-8")
    section = " ".join(readme.split("\n## Which model do I need?\n", 1)[1].split("\n## ", 1)[0].split())
    assert "once the engine has that key" not in section and "(next J, Δt/2" not in section
    assert "`modes` r = 4, 8, 16, 32, 64 below 2J − max(1, number of stops along the span)" in section
    assert "the next mesh rung — the next J, or for a reduced model the next `modes` rung" in section
    assert plan_runs.reduced_available()
    ladder = plan_runs.mesh_ladder(beamstops.Scene(elements=40))
    assert [r for j, r in ladder.rungs if r] == [4, 8, 16, 32, 64]
    assert [r for j, r in plan_runs.mesh_ladder(PAPER_SHORT).rungs if r] == [4, 8, 16, 32]  # 32 < 2·19 − 1
    assert ladder.finer[(40, 64)] == (40, 0) and ladder.finer[(40, 0)] == (80, 0)  # what the check runs


def test_the_studies_names_of_a_statistic_are_read_as_the_engines() -> None:
    """`converge --qoi stop_power` and `plan --qoi stop_power` name one quantity (plan refused it, exit 2)."""
    assert Quantity("stop_power").name == "power" and Quantity("shock_rate").name == "shocks_per_second"
    with pytest.raises(ValueError, match="stop_power = power"):
        Quantity("energy")
    # the option is accepted (not exit 2): what stops the plan is the absent scene (exit 1)
    assert cli.main(["plan", "absent.nml", "--qoi", "stop_power", "--tol", "2%", "--quiet"], prog="beamstops") == 1


SHORT_STATISTICS = beamstops.Scene(t_end=0.05, dt=1e-4)


@pytest.mark.parametrize("window", ["1e-16", "1e-5"])
def test_cli_max_window_shorter_than_a_step_is_an_option_error(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                               window: str) -> None:
    """--max-window below one step of the scene ran the search into the engine's 'scene: &time t_end =
    1e-16 is out of range' (or 'dt = 0.0001 ... <= t_end'), exit 1, not naming the option."""
    scene_file = tmp_path / "short.nml"
    SHORT_STATISTICS.to_namelist(scene_file)
    with pytest.raises(SystemExit) as exit_:
        cli.main(["plan", str(scene_file), "--qoi", "tip_rms", "--tol", "1e-3", "--max-window", window, "--quiet"],
                 prog="beamstops")
    assert exit_.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("beamstops plan: error: argument --max-window: "), err
    assert "allowed: a window of at least one step of the scene (dt = 0.0001 s)" in err[0], err
    assert not (tmp_path / "short_plan.nml").exists()
    with pytest.raises(ValueError, match=r"^max_window 1e-05 s: .*refused by the engine"):
        plan(SHORT_STATISTICS, "tip_rms", 1e-3, max_window=1e-5, quiet=True)


def test_a_tolerance_whose_window_the_engine_refuses_says_so(tmp_path: Path,
                                                             capsys: pytest.CaptureFixture[str]) -> None:
    """A tolerance so tight that the scaled window makes a scene the engine refuses ended in the
    engine's 'scene: &output record_every = 273200000000000 is out of range', naming neither the
    tolerance nor the window."""
    scene_file = tmp_path / "short.nml"
    SHORT_STATISTICS.to_namelist(scene_file)
    assert cli.main(["plan", str(scene_file), "--qoi", "tip_rms", "--tol", "1e-9", "--quiet"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("beamstops: error: the window after the transient that the "
                                               "tolerance 1e-09 m needs"), err
    assert "allowed: a larger tolerance" in err[0] and "--max-window" in err[0], err
    assert not (tmp_path / "short_plan.nml").exists()


def test_a_stop_beyond_the_statistics_entries_names_the_option_and_its_range(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--stop 5 on a scene with the tip's stops only said "statistic 'power' has 1 entries; no stop 5"."""
    scene_file = tmp_path / "short.nml"
    SHORT_STATISTICS.to_namelist(scene_file)
    assert cli.main(["plan", str(scene_file), "--qoi", "power", "--tol", "1", "--stop", "5", "--quiet"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "stop 5 (--stop)" in err[0] and "allowed: 0 <= stop <= 0" in err[0], err


def test_a_scaled_window_is_announced_before_the_search(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A tight tolerance scales the window (here 4x) and the search could run for hours with no word:
    the window and the cost of one run over it are said before the first candidate runs."""
    scene_file = tmp_path / "short.nml"
    SHORT_STATISTICS.to_namelist(scene_file)
    pilot = plan(SHORT_STATISTICS, "tip_rms", 1.0, quiet=True)  # the pilot's half-width, from the engine
    assert pilot.pilot_half_width is not None and pilot.pilot_half_width > 0
    tol = pilot.pilot_half_width  # half the tolerance is half the half-width: a window 4 times the scene's
    cli.main(["plan", str(scene_file), "--qoi", "tip_rms", "--tol", f"{tol!r}", "--budget", "1",
              "-o", str(tmp_path / "p.nml")])
    err = capsys.readouterr().err
    note = next(line for line in err.splitlines() if line.startswith("plan: the tolerance"))
    window = SHORT_STATISTICS.t_end - SHORT_STATISTICS.transient
    assert f"needs a window of {float(f'{4 * window:.3g}'):g} s after the transient" in note, note
    assert "CPU s" in note and "--budget" not in note  # a budget was given: no advice to give one

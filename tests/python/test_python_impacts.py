"""Shocks and statistics (issue 13) against an independent computation from the records of the
same run, and the intervals' behaviour (disjoint halves, ensembles)."""

from __future__ import annotations

import math
import subprocess
from pathlib import Path

import numpy as np
import pytest

import beamstops
from beamstops import Scene

DT = 5e-5


def shocks_from_records(result: beamstops.Result, rest_time: float) -> list[dict[str, float]]:
    """The shock log recomputed from /tip/t, /tip/u, /tip/reaction and /energy/dissipated
    (record_every = 1), with the rest-time rule of docs/statistics.md, written independently."""
    t, u, r, dissipated = result.t, result.tip_u, result.reaction, result.dissipated
    n = t.size - 1
    e = np.zeros(n + 1)
    e[2:] = dissipated[1:-1] - dissipated[:-2]
    rest_steps = max(math.ceil(rest_time / DT - 1e-9), 2)
    phases = []  # (first, last, sign) of each maximal run of contact samples of one sign
    k = 1
    while k <= n:
        if r[k] != 0:
            sign = np.sign(r[k])
            first = k
            while k + 1 <= n and r[k + 1] != 0 and np.sign(r[k + 1]) == sign:
                k += 1
            phases.append((first, k, sign))
        k += 1
    shocks: list[list[tuple[int, int, float]]] = []
    for phase in phases:
        if shocks and shocks[-1][-1][2] == phase[2] and (phase[0] - shocks[-1][-1][1] - 1) * DT < rest_time:
            shocks[-1].append(phase)
        else:
            shocks.append([phase])
    rows = []
    for shock in shocks:
        a, b = shock[0][0], shock[-1][1]
        samples = [k for first, last, _ in shock for k in range(first, last + 1)]
        u_before = u[a - 2] if a >= 2 else u[0]
        rows.append({
            "t_start": t[a], "side": shock[0][2], "rebounds": len(shock) - 1, "contact_steps": len(samples),
            "impulse": float(np.sum(r[samples]) * DT), "energy_taken": float(np.sum(e[samples])),
            "peak_reaction": float(r[samples][np.argmax(np.abs(r[samples]))]),
            "velocity_in": (u[a] - u_before) / (2 * DT),
            "t_end": t[b + 1] if b + 1 <= n else math.nan,
            "velocity_out": (u[b + 2] - u[b]) / (2 * DT) if b + 2 <= n else math.nan,
            "complete": b + rest_steps <= n,
        })
    return rows


@pytest.fixture(scope="module")
def run() -> beamstops.Result:
    return beamstops.run(Scene(t_end=3.0, dt=DT, rest_time=0.01))


def test_shock_log_equals_an_independent_one_from_the_records(run: beamstops.Result) -> None:
    expected = shocks_from_records(run, 0.01)
    got = run.impacts
    assert len(expected) == got["t_start"].size > 10
    assert run.attrs["impacts"] == len(expected)
    for i, row in enumerate(expected):
        assert got["t_start"][i] == row["t_start"] and got["side"][i] == row["side"]
        assert got["rebounds"][i] == row["rebounds"] and got["contact_steps"][i] == row["contact_steps"]
        assert got["stop"][i] == 1
        for name in ("impulse", "energy_taken", "peak_reaction", "velocity_in"):
            assert got[name][i] == pytest.approx(row[name], rel=1e-11, abs=1e-15), (i, name)
        if row["complete"]:
            assert got["t_end"][i] == row["t_end"] and got["truncated"][i] == 0
            assert got["velocity_out"][i] == pytest.approx(row["velocity_out"], rel=1e-11, abs=1e-15), i


def test_impulses_and_energies_add_up(run: beamstops.Result) -> None:
    assert run.impacts["impulse"].sum() == pytest.approx(run.reaction.sum() * DT, rel=1e-12)
    assert run.impacts["energy_taken"].sum() == pytest.approx(run.dissipated[-1], rel=1e-9)
    # contact phases: the engine's count beside the shocks
    assert run.attrs["contact_phases"] == run.impacts["rebounds"].sum() + run.impacts["rebounds"].size


def test_program_and_memory_give_the_same_shocks(tmp_path: Path, program: str) -> None:
    scene = Scene(t_end=1.0, file="out.h5")
    scene.to_namelist(tmp_path / "s.nml")
    subprocess.run([program, "run", "s.nml"], cwd=tmp_path, check=True, capture_output=True)
    loaded, ran = beamstops.load(tmp_path / "out.h5"), beamstops.run(scene)
    for name, column in ran.impacts.items():
        assert np.array_equal(loaded.impacts[name], column, equal_nan=True), name
    for name, stat in ran.statistics.items():
        assert np.array_equal(loaded.statistics[name].value, stat.value, equal_nan=True), name


def test_no_contact_no_shocks_and_one_forced_contact_one_shock() -> None:
    free = beamstops.run(Scene(t_end=0.5, law="none"))
    assert free.impacts["t_start"].size == 0 and float(free.statistics["power"]) == 0
    # stops far away but for one excursion: the support's single push brings the tip to the upper
    # stop once within 0.2 s (the first impact of the paper's scene is at t = 0.088 s)
    one = beamstops.run(Scene(t_end=0.12, rest_time=0.02, upper=0.1, lower=-1.0))
    assert one.impacts["t_start"].size == 1 and one.impacts["side"][0] == -1


def test_disjoint_halves_agree_within_their_intervals() -> None:
    first = beamstops.run(Scene(t_end=12.0, transient=2.0, batches=10, record_every=1000))
    second = beamstops.run(Scene(t_end=22.0, transient=12.0, batches=10, record_every=1000))
    for name in ("power", "shocks_per_second", "impulse_rate", "tip_rms", "tip_mean", "contact_fraction"):
        a, b = first.statistics[name], second.statistics[name]
        assert abs(float(a) - float(b)) <= a.half_width[0] + b.half_width[0], (name, str(a), str(b))


@pytest.mark.parametrize("physics", [
    {},
    # damped, with restitution: the members run in the general lockstep loop (docs/lockstep.md)
    {"ratio": (0.01,), "restitution": 0.5},
])
def test_ensembles_identical_members_and_decorrelated_members(physics: dict[str, object]) -> None:
    scene = Scene(t_end=3.0, transient=1.0, batches=10, record_every=1000, members=3, **physics)
    same = beamstops.run(scene)
    # delta = 0: the members are identical bit for bit, so is every ensemble value to member 1's,
    # and every interval is exactly 0 (the sums about the first value: 3 x / 3 need not be x)
    for name, stat in same.ensemble.items():
        mine = np.asarray(same.statistics[name].value)
        value, half = np.asarray(stat.value), np.asarray(stat.half_width)
        assert np.array_equal(value, mine, equal_nan=True), name
        assert np.all(half[np.isfinite(mine)] == 0) or name == "tip_histogram_edges", name
    spread = beamstops.run(scene.replace(perturbation=1e-6, members=4))
    assert spread.ensemble["power"].half_width[0] > 0  # the members parted after the first impacts


@pytest.mark.parametrize(("text", "needle"), [
    ("&statistics batches = 1 /", "&statistics batches = 1 is out of range; allowed: 2 <= batches <= 1000"),
    ("&statistics transient = 5 /", "&statistics transient = 5 is out of range"),
    ("&statistics rest_time = -1 /", "&statistics rest_time = -1 is out of range"),
    ("&ensemble members = 0 /", "&ensemble members = 0 is out of range"),
    ("&statistics bins = 0 /", "&statistics bins = 0 is out of range"),
    # tables beyond memory: a failed allocation ended the program (and the Python process) with a backtrace
    ("&statistics batches = 100000000 /", "&statistics batches = 100000000 is out of range; allowed: 2 <= batches <= 1000"),
    ("&statistics bins = 2000000000 /", "&statistics bins = 2000000000 is out of range; allowed: 1 <= bins <= 1000000"),
    ("&ensemble members = 2000000000 /", "&ensemble members = 2000000000 is out of range; allowed: 1 <= members <= 10000"),
    # members whose tables together pass 16 GB (members x (8 bytes x (bins x batches + 16 x 2 elements) + 96
    # bytes x (4097 stops + 16), the README's): allocated one by one they filled the machine, or failed with a
    # backtrace; the shock log (0.4 MB a member of the paper's scene) had been left out of the count
    ("&ensemble members = 1000 /\n&statistics bins = 10000, batches = 1000 /",
     f"&ensemble members = 1000 is out of range; allowed: members <= "
     f"{int(16e9 // (8 * (10000 * 1000 + 32 * 19) + 96 * 4113))} for this scene"),
    ("&ensemble members = 10000 /\n&mesh elements = 1000000 /\n&time dt = 1e-15, t_end = 1e-14 /",
     f"&ensemble members = 10000 is out of range; allowed: members <= "
     f"{int(16e9 // (8 * (40 * 20 + 32 * 10**6) + 96 * 4113))} for this scene"),
    ("&ensemble members = 10000 /\n&stops nodes = 2, 4, 6, 8, 10, 12, 14, 16, 18, 19, lower = 10*-0.1, "
     "upper = 10*0.1 /",
     f"&ensemble members = 10000 is out of range; allowed: members <= "
     f"{int(16e9 // (8 * (40 * 20 + 32 * 19) + 96 * (4097 * 10 + 16)))} for this scene"),
])
def test_bad_statistics_inputs(text: str, needle: str, tmp_path: Path) -> None:
    path = tmp_path / "bad.nml"
    path.write_text(text + "\n")
    with pytest.raises(ValueError, match="allowed") as caught:
        Scene.from_namelist(path)
    assert needle in str(caught.value)


def test_samples_are_the_records_times() -> None:
    """The shock log and the statistics take the samples t_1 .. t_N of the records: the loop's
    last step computes u^{N+1} only to complete the record of t_N = t_end."""
    dt, transient = 1e-4, 0.1
    run = beamstops.run(Scene(elements=4, dt=dt, t_end=0.3, transient=transient, batches=4))
    assert run.t[-1] == pytest.approx(0.3, abs=1e-12)
    kept = (run.t >= transient) & (run.t > 0)
    assert float(run.statistics["window"]) == pytest.approx(kept.sum() * dt, rel=1e-12)
    assert float(run.statistics["tip_mean"]) == pytest.approx(run.tip_u[kept].mean(), rel=1e-10)
    assert float(run.statistics["tip_max"]) == run.tip_u[kept].max()
    assert float(run.statistics["tip_min"]) == run.tip_u[kept].min()


def test_batches_are_those_of_the_documented_edges() -> None:
    """tip_mean's value and 95 % half-width from the records with docs/statistics.md's batches:
    w = (t_end - transient)/B, e_j = transient + j*w (the product rounded, then the sum), a sample at
    t in batch j when e_{j-1} <= t < e_j. Here samples fall on edges: t = 0.9 on e_7 (0.9 + 1 ulp by
    that rule, 0.9 as one multiply-add), so a fused edge would move a sample to the next batch."""
    scipy_stats = pytest.importorskip("scipy.stats")
    transient, t_end, batches = 0.2, 1.0, 8
    run = beamstops.run(Scene(elements=4, dt=2e-5, t_end=t_end, transient=transient, batches=batches))
    w = (t_end - transient) / batches
    edges = np.array([transient + j * w for j in range(1, batches)])
    kept = (run.t >= transient) & (run.t > 0)
    t, u = run.t[kept], run.tip_u[kept]
    which = np.searchsorted(edges, t, side="right")
    assert np.any(np.isin(t, edges)), "some sample lies on an edge"
    means = np.array([u[which == j].mean() for j in range(batches)])
    half = scipy_stats.t.ppf(0.975, batches - 1) * means.std(ddof=1) / math.sqrt(batches)
    statistic = run.statistics["tip_mean"]
    assert float(statistic.value[0]) == pytest.approx(u.mean(), rel=1e-12)
    assert float(statistic.half_width[0]) == pytest.approx(half, rel=1e-9)


def energy_per_sample(u: np.ndarray, reaction: np.ndarray) -> np.ndarray:
    """The energy a stop took in the step that brought row k, -1/2 R_k (u_k - u_{k-2}) (J), from
    the records (record_every = 1; rows 0 and 1: 0, no contact at the start here)."""
    e = np.zeros_like(u)
    e[2:] = -0.5 * reaction[2:] * (u[2:] - u[:-2])
    return e


def test_each_stop_keeps_its_own_energy() -> None:
    """Two stops along the span in contact at once: each shock's energy and each stop's power are
    that stop's own -1/2 R (u~^{n+1} - u~^{n-1}), not a share of the step's total."""
    scene = Scene(dt=DT, t_end=1.0, nodes=(10, 19), lower=(-0.03, -0.1), upper=(0.03, 0.1), rest_time=0.005)
    run = beamstops.run(scene)
    both = (run.stops_reaction != 0).all(axis=1)
    assert both.sum() > 100
    window = float(run.statistics["window"])
    for i in range(2):
        e = energy_per_sample(run.stops_u[:, i], run.stops_reaction[:, i])
        mine = run.impacts["stop"] == i + 1
        assert run.impacts["energy_taken"][mine].sum() == pytest.approx(e.sum(), rel=1e-9)
        assert run.statistics["power"].value[i] == pytest.approx(e[run.t > 0].sum() / window, rel=1e-9)
    assert run.impacts["energy_taken"].sum() == pytest.approx(run.dissipated[-2], rel=1e-9)


def test_massless_tip_reaction_only_on_the_stops() -> None:
    """Mass redistribution: the recorded reaction is zero off the stops (SPEC 4), equals the shock
    log's contact samples, and the shocks' energies (with the two steps after each contact phase,
    where the Newmark row still holds the contact) add up to the stops' energy."""
    run = beamstops.run(Scene(mass="redistributed", beta=0.25, dt=DT, t_end=1.0))
    acting = run.reaction != 0
    assert acting.sum() > 100
    on_stop = np.minimum(np.abs(run.tip_u - 0.1), np.abs(run.tip_u + 0.1))
    assert on_stop[acting].max() < 1e-9
    assert acting.sum() == run.impacts["contact_steps"].sum()
    assert run.impacts["energy_taken"].sum() == pytest.approx(run.dissipated[-2], rel=1e-9)
    assert run.impacts["impulse"].sum() == pytest.approx(run.reaction.sum() * DT, rel=1e-12)


def test_histogram_counts_are_those_of_its_stored_edges() -> None:
    """np.histogram of the window's tip samples on /statistics/tip_histogram_edges gives the
    engine's histogram: the tip resting on the stop at 0.1 (Signorini) lies on an edge of a
    histogram over [-0.2, 0.2] in 4 bins, where the nominal edge -0.2 + 3 * 0.1 is an ulp above it
    (the bin the engine counts it in)."""
    run = beamstops.run(Scene(dt=1e-5, t_end=2.0, bins=4, histogram_lower=-0.2, histogram_upper=0.2))
    kept = run.t > 0
    u = run.tip_u[kept]
    assert np.count_nonzero(u == 0.1) > 100, "the tip rests on the upper stop"
    edges = run.statistics["tip_histogram_edges"].value
    assert edges[3] != -0.2 + 3 * (0.4 / 4), "the nominal edge is not the bins' edge here"
    counts, _ = np.histogram(u, edges)
    assert np.array_equal(counts, np.rint(run.statistics["tip_histogram"].value * u.size))


def test_summary_line_gives_each_stops_headline_statistics(tmp_path: Path, program: str) -> None:
    """With stops along the span the summary line printed stop 1's shocks per second, power and
    impulse rate alone; it gives each stop's, in the order of /stops."""
    scene = Scene(dt=1e-5, t_end=1.0, beta=0.25, nodes=(7, 13, 19), lower=(-0.03, -0.06, -0.1),
                  upper=(0.03, 0.06, 0.1), file="out.h5")
    scene.to_namelist(tmp_path / "s.nml")
    done = subprocess.run([program, "run", "s.nml"], cwd=tmp_path, check=True, capture_output=True, text=True)
    line = done.stdout.splitlines()[-1]
    power = beamstops.load(tmp_path / "out.h5").statistics["power"]
    assert power.value.size == 3
    shown = line.split("power of stops 1..3 ")[1].split(" W;")[0].split(", ")
    assert len(shown) == 3
    for text, value, half in zip(shown, power.value, power.half_width):
        v, h = (float(x) for x in text.split(" +- "))
        assert v == pytest.approx(value, rel=1e-4) and h == pytest.approx(half, rel=1e-2)

"""beamstops.run, beamstops.load and beamstops.stability: the engine from Python."""

from __future__ import annotations

import subprocess
import sys
import threading
from pathlib import Path

import h5py
import numpy as np
import pytest

import beamstops
from beamstops import IncompleteRunError, Scene
from beamstops.engine import canonical
from beamstops.result import ARRAYS

SHORT = Scene(t_end=0.3, dt=5e-5)

SCENES = {
    "signorini": SHORT.replace(snapshot_every=7, record_every=3),
    "compliance": SHORT.replace(law="compliance", stiffness_per_mass=1e8, beta=0.25, dt=5e-6, t_end=0.15,
                                load_rule="paper", start="euler", snapshot_every=500),
    "none": SHORT.replace(law="none", beta=0.1, dt=5e-6, t_end=0.1, record_every=7),
    "material": SHORT.replace(youngs_modulus=2e11, density=8e3, outer_diameter=0.01, wall_thickness=5e-4,
                              elements=8, snapshot_every=1),
    # the massless tip row (the README once had the program round it apart from the extension)
    "redistributed": SHORT.replace(mass="redistributed", record_every=2),
    # products by beta that round (the Newmark sums of src/beamstops/newmark.c)
    "beta_0.3": SHORT.replace(beta=0.3, law="compliance", stiffness_per_mass=1e8, dt=5e-6, t_end=0.1),
}


def same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype == np.float64 and a.shape == b.shape and np.array_equal(
        np.ascontiguousarray(a).view(np.uint64), np.ascontiguousarray(b).view(np.uint64))


@pytest.mark.parametrize("name", sorted(SCENES))
def test_run_and_load_agree_bit_for_bit(name: str, program: str, tmp_path: Path) -> None:
    scene = SCENES[name].replace(file="out.h5")
    scene.to_namelist(tmp_path / "scene.nml")
    done = subprocess.run([program, "run", "scene.nml"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    loaded = beamstops.load(tmp_path / "out.h5")
    ran = beamstops.run(Scene.from_namelist(tmp_path / "scene.nml"))
    for array in ARRAYS:
        assert same_bits(getattr(loaded, array), getattr(ran, array)), array
    assert ran.t.size == beamstops.engine.sizes(scene)[0] and ran.t.size > 1
    assert ran.snapshot_u.shape == (ran.snapshot_t.size, scene.elements + 1)
    with h5py.File(tmp_path / "out.h5") as f:  # the same arrays as the raw file, names included
        assert same_bits(f["energy/t"][()], ran.t) and same_bits(f["energy/E"][()], ran.energy)
    cpu = [r.attrs.pop("cpu_seconds") for r in (loaded, ran)]
    assert all(c >= 0 for c in cpu)
    assert loaded.attrs == ran.attrs
    assert ran.attrs["status"] == "complete" and ran.attrs["version"] == beamstops.version()


def test_result_arrays_hold_what_the_scheme_promises() -> None:
    result = beamstops.run(SCENES["signorini"])
    assert result.t[0] == 0 and result.t[-1] == pytest.approx(0.3)
    assert result.tip_u.max() <= 0.1 and result.tip_u.min() >= -0.1
    assert result.attrs["max_violation"] == 0 and result.attrs["impacts"] > 0
    # the physical displacement at the clamp follows the support
    np.testing.assert_allclose(result.snapshot_u[:, 0], 0.2 * np.sin(10 * result.snapshot_t), rtol=0, atol=1e-15)
    assert result.scene() == SCENES["signorini"]


def test_stability_gives_the_papers_numbers() -> None:
    limits = beamstops.stability(Scene(beta=0.25, dt=1e-6))
    # SPEC §2 and §6, J = 19
    assert limits.kappa_h == pytest.approx(2.6035e10, rel=1e-4)
    assert limits.kappa_bound == pytest.approx(7.1416e11, rel=1e-4)
    assert limits.dt_limit_paper_bound == pytest.approx(3.3469e-6, rel=1e-4)
    assert limits.dt_limit_paper == pytest.approx(1.7529e-5, rel=1e-4)
    assert limits.dt_limit_newmark == np.inf and limits.runnable
    explicit = beamstops.stability(Scene(beta=0.0, dt=2e-5))
    assert explicit.dt_limit_newmark == pytest.approx(1.2395e-5, rel=1e-4)
    assert not explicit.runnable and "allow_unstable" in explicit.refusal
    # the attributes of a run carry the same numbers
    run = beamstops.run(Scene(beta=0.25, dt=1e-6, t_end=1e-4))
    assert run.attrs["kappa_h"] == limits.kappa_h and run.attrs["dt_limit_paper_bound"] == limits.dt_limit_paper_bound


BAD = [
    ("negative dt", dict(dt=-1e-5), "scene: &time dt = -1e-05 is out of range"),
    ("nan dt", dict(dt=float("nan")), "scene: &time dt = NaN"),
    ("dt beyond t_end", dict(dt=3.0), "scene: &time dt = 3"),
    ("beta", dict(beta=0.7), "scene: &time beta = 0.7"),
    ("lower stop", dict(lower=0.05), "scene: &stops lower"),
    ("upper stop", dict(upper=-0.05), "scene: &stops upper"),
    ("no elements", dict(elements=0), "scene: &mesh elements = 0"),
    ("huge elements", dict(elements=2**40), "scene: &mesh elements = 1099511627776 is out of range; allowed: 1 <= elements <= 1000000"),
    ("huger elements", dict(elements=2**80), "scene: &mesh elements = 1208925819614629174706176 is out of range; allowed: 1 <= elements"),
    ("compliance without stiffness", dict(law="compliance"), "scene: &stops law = 'compliance' needs a spring"),
    ("record_every", dict(record_every=0), "scene: &output record_every = 0"),
    ("snapshot_every", dict(snapshot_every=-1), "scene: &output snapshot_every = -1"),
    ("output too large", dict(dt=1e-9, t_end=100.0), "max_output_gb"),
    ("infinite length", dict(length=float("inf")), "scene: &beam length = Inf"),
    ("unstable explicit", dict(beta=0.0, dt=2e-5), "stability limit"),
]


@pytest.mark.parametrize(("label", "changes", "needle"), BAD, ids=[b[0] for b in BAD])
def test_bad_scenes_raise_value_error_with_the_engines_message(label: str, changes: dict, needle: str) -> None:
    # The engine's one reader refuses a bad value as the scene is made; a time step beyond the
    # stability limit is refused when the run is prepared.
    with pytest.raises(ValueError) as caught:
        beamstops.run(SHORT.replace(**changes))
    assert needle in str(caught.value)
    assert "allowed" in str(caught.value) or "keys of &" in str(caught.value)


def python_child(lines: list[str]) -> str:
    """Run the lines as a Python program in a child process (a crash shows as a failed test, not
    a dead test run); its standard output."""
    done = subprocess.run([sys.executable, "-c", "\n".join(lines)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_bad_scenes_never_crash_the_interpreter() -> None:
    # In a child process, so that a crash would show as a failed test, not a dead test run.
    out = python_child([
        "import beamstops, math",
        "from beamstops import Scene",
        "bad = [dict(dt=-1.0), dict(dt=math.nan), dict(dt=math.inf), dict(elements=0), dict(elements=-5),",
        "       dict(elements=2**31), dict(elements=2**63 - 1), dict(record_every=-(2**62)), dict(beta=-0.1),",
        "       dict(k2=0.0), dict(mass_per_length=-1.0), dict(t_end=1e300), dict(omega=math.nan),",
        "       dict(lower=-math.inf), dict(law='compliance', stiffness_per_mass=math.inf), dict(max_output_gb=-1.0)]",
        "n = 0",
        "for changes in bad:",
        "    for call in (beamstops.run, beamstops.stability, lambda s: s.validate()):",
        "        try:",
        "            call(Scene(t_end=0.01).replace(**changes))",
        "        except ValueError:",
        "            n += 1",
        "print(n)",
    ])
    assert int(out) == 16 * 3


def test_a_diverged_run_is_an_incomplete_run_error_holding_the_partial_result() -> None:
    scene = Scene(beta=0.0, dt=2e-5, t_end=0.5, allow_unstable=True, record_every=100)
    with pytest.raises(IncompleteRunError) as caught:
        beamstops.run(scene)
    assert "diverged" in str(caught.value)
    partial = caught.value.result
    assert partial.status == "diverged" and partial.attrs["steps"] < 25000
    # the records stop at the first values that are not finite
    assert 2 < partial.t.size < partial.attrs["steps"] // 100 + 1
    assert all(np.all(np.isfinite(getattr(partial, a))) for a in ("tip_u", "tip_v", "energy", "work"))
    allowed = beamstops.run(scene, allow_incomplete=True)
    assert allowed.status == "diverged" and "blew up" in allowed.attrs["message"]


def test_load_refuses_an_incomplete_file_unless_asked(program: str, tmp_path: Path) -> None:
    scene = Scene(beta=0.0, dt=2e-5, t_end=0.5, allow_unstable=True, record_every=100, file="bad.h5")
    scene.to_namelist(tmp_path / "bad.nml")
    done = subprocess.run([program, "run", "bad.nml"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 3
    with pytest.raises(IncompleteRunError, match="diverged"):
        beamstops.load(tmp_path / "bad.h5")
    loaded = beamstops.load(tmp_path / "bad.h5", allow_incomplete=True)
    ran = beamstops.run(scene, allow_incomplete=True)
    assert loaded.status == ran.status == "diverged"
    # the same bits: both keep the records up to the first values that are not finite
    assert loaded.t.size == ran.t.size > 2 and np.all(np.isfinite(loaded.energy))
    for a in ("t", "tip_u", "tip_v", "reaction", "energy", "work", "dissipated"):
        assert same_bits(getattr(loaded, a), getattr(ran, a)), a
    with pytest.raises(FileNotFoundError):
        beamstops.load(tmp_path / "nowhere.h5")
    (tmp_path / "text.h5").write_text("not HDF5")
    with pytest.raises(OSError, match="text.h5"):
        beamstops.load(tmp_path / "text.h5")


def test_a_diverged_run_with_stops_along_the_span_keeps_its_stops_records(program: str, tmp_path: Path) -> None:
    # the program's /stops/u lost one row at each record after the first values not finite, up
    # to the block's end: the file's were empty where run() kept them
    scene = Scene(law="none", nodes=(5, 10), beta=0.0, dt=1e-4, t_end=0.05, allow_unstable=True, file="bad.h5")
    scene.to_namelist(tmp_path / "bad.nml")
    done = subprocess.run([program, "run", "bad.nml"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 3
    ran = beamstops.run(scene, allow_incomplete=True)
    with h5py.File(tmp_path / "bad.h5") as f:
        assert f["stops/u"].shape == f["stops/reaction"].shape == (f["tip/u"].size, 2)
    loaded = beamstops.load(tmp_path / "bad.h5", allow_incomplete=True)
    assert loaded.status == ran.status == "diverged" and 2 < ran.t.size < ran.attrs["steps"]
    for array in ARRAYS:
        assert same_bits(getattr(loaded, array), getattr(ran, array)), array


def test_runs_in_threads_release_the_interpreter_and_agree() -> None:
    # Engine calls from several threads are serialized (beamstops.engine_call: gfortran 12 keeps
    # string lengths in static storage); each must still give the run alone, attributes and text
    # included (before the lock, about one run in ten came back with garbled attributes), and the
    # interpreter is free meanwhile: another Python thread counts while the runs go on.
    scene = SCENES["compliance"]
    alone = beamstops.run(scene)
    results: list[beamstops.Result] = []
    texts: list[str] = []
    done = threading.Event()
    ticks = [0]

    def count() -> None:
        while not done.wait(0.001):
            ticks[0] += 1

    def work() -> None:
        for _ in range(4):
            results.append(beamstops.run(scene))
            texts.extend(canonical(scene.to_text()) for _ in range(25))

    counter = threading.Thread(target=count)
    counter.start()
    threads = [threading.Thread(target=work) for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    done.set()
    counter.join()
    assert len(results) == 16 and ticks[0] > 0
    attrs = {k: v for k, v in alone.attrs.items() if k != "cpu_seconds"}
    for r in results:
        assert same_bits(r.tip_u, alone.tip_u) and same_bits(r.energy, alone.energy)
        assert {k: v for k, v in r.attrs.items() if k != "cpu_seconds"} == attrs
    assert texts == [canonical(scene.to_text())] * 400
    # one long run alone (about half a second): the counter goes on during it
    done.clear()
    ticks[0] = 0
    counter = threading.Thread(target=count)
    counter.start()
    beamstops.run(scene.replace(t_end=3.0, record_every=1000, snapshot_every=0))
    during = ticks[0]
    done.set()
    counter.join()
    assert during >= 10, during


def test_load_of_a_folder_says_it_is_a_folder(tmp_path: Path) -> None:
    with pytest.raises(IsADirectoryError, match=r"is a folder, not the HDF5 output of `beamstops run`"):
        beamstops.load(tmp_path)
    with pytest.raises(FileNotFoundError, match="no such file"):
        beamstops.load(tmp_path / "nowhere.h5")

def test_submodules_are_reachable_from_the_package_after_a_plain_import() -> None:
    out = python_child([
        "import sys, beamstops",
        "assert 'matplotlib' not in sys.modules and 'beamstops.plots' not in sys.modules",  # imported when used
        "assert callable(beamstops.plots.save) and callable(beamstops.plan.plan)",  # as the README writes them
        "assert callable(beamstops.sweep.run_sweep) and 'plots' in dir(beamstops)",
        "try:",
        "    beamstops.nothing",
        "except AttributeError as exc:",
        "    print(exc)",
    ])
    assert out.strip() == "module 'beamstops' has no attribute 'nothing'"


@pytest.mark.parametrize("value", ["no", "False", 0, 1, None, np.array([True]), 0.0])
def test_allow_incomplete_is_true_or_false(value: object, tmp_path: Path) -> None:
    """run(scene, allow_incomplete='no') was taken as true (any object is a condition); a bool (or
    a numpy bool) is required, anything else a TypeError naming the keyword."""
    scene = Scene(beta=0.0, dt=2e-5, t_end=0.5, allow_unstable=True, record_every=100)
    with pytest.raises(TypeError, match=r"^run: allow_incomplete = .*; allowed: True or False$"):
        beamstops.run(scene, allow_incomplete=value)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=r"^load: allow_incomplete = .*; allowed: True or False$"):
        beamstops.load(tmp_path / "nowhere.h5", allow_incomplete=value)  # type: ignore[arg-type]
    assert beamstops.run(scene, allow_incomplete=np.bool_(True)).status == "diverged"
    with pytest.raises(IncompleteRunError):
        beamstops.run(scene, allow_incomplete=np.bool_(False))

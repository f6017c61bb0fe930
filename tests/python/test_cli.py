"""The `beamstops` program: runs, `info`, exit statuses and messages on bad input."""

from __future__ import annotations

import os
import shutil
import subprocess
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

PROGRAM = os.environ.get("BEAMSTOPS_PROGRAM") or shutil.which("beamstops")
INPUT = Path(__file__).resolve().parents[2] / "input"

pytestmark = pytest.mark.skipif(PROGRAM is None, reason="the beamstops program is not on PATH")


def beamstops(*args: str | Path, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([PROGRAM, *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=120)


def write(tmp_path: Path, text: str, name: str = "scene.nml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


SHORT = "&time dt=5e-5, t_end=0.3 /\n"


def test_run_writes_complete_file_with_contract_layout(tmp_path: Path) -> None:
    scene = write(tmp_path, SHORT + "&output file='short.h5', snapshot_every=100 /\n")
    done = beamstops("run", scene, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "6000 steps" in done.stdout and "status complete" in done.stdout
    with h5py.File(tmp_path / "short.h5") as f:
        assert f.attrs["status"] == b"complete"
        assert f.attrs["steps"] == 6000
        for name in ["tip/t", "tip/u", "tip/v", "tip/reaction", "energy/t", "energy/E", "energy/work",
                     "energy/dissipated"]:
            assert f[name].shape == (6001,), name
        assert f["snapshots/u"].shape == (61, 20)
        assert f["snapshots/x"][-1] == pytest.approx(1.501)
        # the physical displacement at the clamp is the support's motion
        t = f["snapshots/t"][:]
        np.testing.assert_allclose(f["snapshots/u"][:, 0], 0.2 * np.sin(10 * t), rtol=0, atol=1e-15)
        # the tip never leaves [lower, upper] with the Signorini scheme
        u = f["tip/u"][:]
        assert u.max() <= 0.1 and u.min() >= -0.1
        assert f.attrs["max_violation"] == 0.0
        for key in ["kappa_h", "kappa_bound", "cpu_seconds", "impacts", "dt", "beta", "law", "version"]:
            assert key in f.attrs, key


def test_output_option_overrides_the_namelist(tmp_path: Path) -> None:
    scene = write(tmp_path, SHORT)
    done = beamstops("run", scene, "-o", tmp_path / "other.h5", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "other.h5").exists() and not (tmp_path / "scene.h5").exists()


def test_info_prints_limits_without_running(tmp_path: Path) -> None:
    scene = write(tmp_path, "&time dt=1e-6, beta=0.25 /\n")
    done = beamstops("info", scene, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "kappa_h" in done.stdout and "2000000" in done.stdout
    assert not list(tmp_path.glob("*.h5"))
    # every group's keys as read, the reduced model, the records and the statistics included
    scene = write(tmp_path, "&mesh modes=5 /\n&output record_every=10 /\n&statistics transient=0.05, bins=7 /\n"
                            "&ensemble members=1, seed=9 /\n")
    lines = beamstops("info", scene, cwd=tmp_path).stdout.splitlines()
    shown = {line[:29].strip(" &"): line[29:].split() for line in lines}
    assert shown["modes"][0] == "5" and shown["record_every"][0] == "10" and shown["bins"][0] == "7"
    assert float(shown["damping mass_coefficient"][0]) == 0 and float(shown["stiffness_coefficient"][0]) == 0
    assert float(shown["transient"][0]) == 0.05 and shown["seed"][0] == "9" and "reduced" in " ".join(shown["unknowns n"])


@pytest.mark.parametrize("name", sorted(p.name for p in INPUT.glob("*.nml")))
def test_shipped_inputs_are_valid(name: str, tmp_path: Path) -> None:
    done = beamstops("info", INPUT / name, cwd=tmp_path)
    assert done.returncode == 0, done.stderr


BAD = [
    ("missing file", None, ["nowhere.nml", "cannot open"]),
    ("unknown group", "&beams length=1 /\n", ["&beams", "unknown group"]),
    ("unknown key", "&time dtt=1e-5 /\n", ["&time", "dtt"]),
    ("malformed value", "&time dt=abc /\n", ["&time", "dt=abc"]),
    ("key without a value", "&time dt= , beta=0.25 /\n", ["&time dt has no value", "allowed: dt = a real number"]),
    ("key without a value at the end", "&stops upper= /\n", ["&stops upper has no value"]),
    ("repeated group", "&time dt=1e-5 /\n&time dt=2e-5 /\n", ["&time", "twice"]),
    ("negative dt", "&time dt=-1e-5 /\n", ["&time", "dt", "allowed"]),
    ("nan dt", "&time dt=nan /\n", ["&time", "dt", "allowed"]),
    ("beta too large", "&time beta=0.7 /\n", ["&time", "beta", "0.5"]),
    ("lower stop positive", "&stops lower=0.05 /\n", ["&stops", "lower", "allowed"]),
    ("upper stop negative", "&stops upper=-0.05 /\n", ["&stops", "upper", "allowed"]),
    ("no elements", "&mesh elements=0 /\n", ["&mesh", "elements", "allowed"]),
    ("unknown law", "&stops law='glue' /\n", ["&stops", "law", "signorini"]),
    ("compliance without stiffness", "&stops law='compliance' /\n", ["&stops", "stiffness"]),
    ("unknown load rule", "&time load_rule='midpoint' /\n", ["&time", "load_rule", "centered"]),
    ("record_every zero", "&output record_every=0 /\n", ["&output", "record_every", ">= 1"]),
    ("half a material", "&beam youngs_modulus=2e11 /\n", ["&beam", "density"]),
    ("unstable explicit", "&time dt=2e-5, beta=0 /\n", ["&time", "dt", "stability limit", "allow_unstable"]),
    ("binary garbage", "&time dt=1e-5 /\n\x00\x01\x02\n", ["binary"]),
    # infinite or huge damping ran and diverged at t = 0 (replacing an earlier output)
    ("infinite mass damping", "&damping mass_coefficient=inf /\n",
     ["&damping mass_coefficient = Inf is out of range", "allowed: 0 <= mass_coefficient <= 1.69e+08 1/s"]),
    ("huge stiffness damping", "&damping stiffness_coefficient=1e100 /\n",
     ["&damping stiffness_coefficient = 1e+100 is out of range", "allowed: 0 <= stiffness_coefficient <= 7.62 s"]),
    ("infinite rest time", "&statistics rest_time=inf /\n", ["&statistics rest_time = Inf", "<= 1e+09 s"]),
    # dt^2 underflowed: the run diverged at t = 0
    ("tiny time step", "&time dt=1e-170, t_end=1e-170 /\n",
     ["&time t_end = 1e-170 is out of range", "allowed: 1e-15 <= t_end <= 1e+09 s"]),
    ("subnormal time step", "&time dt=1e-310, t_end=1e-3 /\n",
     ["&time dt = 1e-310 is out of range", "allowed: 1e-15 <= dt <= t_end = 0.001 s"]),
    ("two springs", "&stops law='compliance', stiffness=1e5, stiffness_per_mass=1e6 /\n",
     ["&stops stiffness and stiffness_per_mass are both given"]),
]


@pytest.mark.parametrize(("label", "text", "needles"), BAD, ids=[b[0] for b in BAD])
def test_bad_input_gives_one_clear_message(label: str, text: str | None, needles: list[str],
                                           tmp_path: Path) -> None:
    scene = tmp_path / "nowhere.nml" if text is None else write(tmp_path, text)
    done = beamstops("run", scene, cwd=tmp_path)
    assert done.returncode == 1
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("beamstops: error: ") and scene.name in lines[0]
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    assert "Traceback" not in done.stderr and "Backtrace" not in done.stderr
    assert not list(tmp_path.glob("*.h5"))


def test_usage_errors_exit_2(tmp_path: Path) -> None:
    assert beamstops(cwd=tmp_path).returncode == 2
    assert beamstops("fly", "x.nml", cwd=tmp_path).returncode == 2
    assert beamstops("run", cwd=tmp_path).returncode == 2
    assert beamstops("--help", cwd=tmp_path).returncode == 0


def test_unstable_run_is_marked_diverged_not_complete(tmp_path: Path) -> None:
    scene = write(tmp_path, "&time dt=2e-5, beta=0, t_end=0.5, allow_unstable=.true. /\n"
                            "&output file='bad.h5', record_every=1, snapshot_every=10 /\n")
    done = beamstops("run", scene, cwd=tmp_path)
    assert done.returncode == 3
    assert "diverged" in done.stderr and "not finite" in done.stderr
    with h5py.File(tmp_path / "bad.h5") as f:
        assert f.attrs["status"] == b"diverged"
        assert f.attrs["steps"] < 25000
        # the records stop at the first values that are not finite: no series holds a NaN, the
        # series have one length, and the last record comes before the time the message names
        series = [f[name][:] for name in ("tip/t", "tip/u", "tip/v", "tip/reaction", "energy/E",
                                          "energy/work", "energy/dissipated", "snapshots/u")]
        assert all(np.all(np.isfinite(a)) for a in series)
        assert len({a.shape[0] for a in series[:7]}) == 1
        blew_up_at = float(f.attrs["message"].decode().split("at t = ")[1].split(" s")[0])
        assert f["tip/t"][-1] < blew_up_at <= f.attrs["t_final"]
        assert f["snapshots/t"][-1] < blew_up_at


def test_unwritable_output_exits_4(tmp_path: Path) -> None:
    scene = write(tmp_path, SHORT)
    done = beamstops("run", scene, "-o", tmp_path / "no" / "such" / "dir.h5", cwd=tmp_path)
    assert done.returncode == 4
    # the output, where its name came from, and the system's reason (not a guess)
    assert one_error_line(done) == (f"beamstops: error: {tmp_path}/no/such/dir.h5 (-o): cannot create "
                                    f"{tmp_path}/no/such/dir.h5.partial, where the run writes until it is done: "
                                    "No such file or directory")


# ---------------------------------------------------------------- no input can destroy data (issue 11)


def one_error_line(done: subprocess.CompletedProcess[str]) -> str:
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("beamstops: error: "), lines[0]
    assert "Traceback" not in done.stderr and "Backtrace" not in done.stderr
    return lines[0]


def complete_output(tmp_path: Path, name: str = "kept.h5") -> tuple[Path, bytes]:
    """A complete output of a short run, and its bytes."""
    scene = write(tmp_path, SHORT, name="previous.nml")
    done = beamstops("run", scene, "-o", name, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    return tmp_path / name, (tmp_path / name).read_bytes()


@pytest.mark.parametrize("spelling", ["same name", "./ spelling", "hard link", "symbolic link"])
def test_output_that_is_the_input_is_refused(spelling: str, tmp_path: Path) -> None:
    scene = write(tmp_path, SHORT)
    text = scene.read_bytes()
    out = {"same name": "scene.nml", "./ spelling": "./scene.nml", "hard link": "link.h5",
           "symbolic link": "symlink.h5"}[spelling]
    if spelling == "hard link":
        os.link(scene, tmp_path / out)
    elif spelling == "symbolic link":
        os.symlink(scene, tmp_path / out)
    done = beamstops("run", "scene.nml", "-o", out, cwd=tmp_path)
    assert done.returncode == 4
    line = one_error_line(done)
    assert line.startswith(f"beamstops: error: {out} (-o): ") and "input" in line
    assert scene.read_bytes() == text
    assert not list(tmp_path.glob("*.partial"))


def test_namelist_output_key_naming_the_input_is_refused(tmp_path: Path) -> None:
    scene = write(tmp_path, SHORT + "&output file='scene.nml' /\n")
    text = scene.read_bytes()
    done = beamstops("run", scene, cwd=tmp_path)
    assert done.returncode == 4
    assert "input" in one_error_line(done)
    assert scene.read_bytes() == text


def foreign_files(tmp_path: Path) -> dict[str, tuple[Path, str]]:
    text = tmp_path / "notes.h5"
    text.write_text("my notes, not HDF5\n")
    plain = tmp_path / "plain.h5"
    with h5py.File(plain, "w") as f:
        f["data"] = np.arange(3.0)
        f.attrs["version"] = "mine"  # a version but no status: still not a beamstops output
    folder = tmp_path / "folder.h5"
    folder.mkdir()
    return {"text": (text, "not an HDF5 file"), "hdf5": (plain, "without the root attributes"),
            "folder": (folder, "folder")}


@pytest.mark.parametrize("kind", ["text", "hdf5", "folder"])
def test_existing_file_that_is_not_an_output_is_refused(kind: str, tmp_path: Path) -> None:
    scene = write(tmp_path, SHORT)
    target, why = foreign_files(tmp_path)[kind]
    before = target.read_bytes() if target.is_file() else None
    done = beamstops("run", scene, "-o", target.name, cwd=tmp_path)
    assert done.returncode == 4
    line = one_error_line(done)
    assert line.startswith(f"beamstops: error: {target.name} (-o): ") and why in line
    if before is not None:
        assert target.read_bytes() == before
    assert not list(tmp_path.glob("*.partial")) and not list(tmp_path.glob("*.checkpoint"))


@pytest.mark.parametrize("suffix", [".partial", ".checkpoint"])
def test_foreign_file_at_the_partial_or_checkpoint_name_is_refused(suffix: str, tmp_path: Path) -> None:
    scene = write(tmp_path, SHORT)
    mine = tmp_path / f"out.h5{suffix}"
    mine.write_text("not HDF5\n")
    done = beamstops("run", scene, "-o", "out.h5", cwd=tmp_path)
    assert done.returncode == 4
    assert one_error_line(done).startswith(f"beamstops: error: out.h5 (-o): out.h5{suffix}, where the run ")
    assert mine.read_text() == "not HDF5\n" and not (tmp_path / "out.h5").exists()


def test_an_earlier_output_is_replaced_only_when_the_run_is_complete(tmp_path: Path) -> None:
    output, _ = complete_output(tmp_path)
    scene = write(tmp_path, "&time dt=5e-5, t_end=0.5 /\n")
    done = beamstops("run", scene, "-o", output.name, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    with h5py.File(output) as f:
        assert f.attrs["status"] == b"complete" and f.attrs["steps"] == 10000
    assert not list(tmp_path.glob("*.partial"))
    # the earlier output was moved aside and is removed by a process of its own
    deadline = time.time() + 30
    while list(tmp_path.glob(".*.replaced-*")) and time.time() < deadline:
        time.sleep(0.01)
    assert not list(tmp_path.glob(".*.replaced-*"))


def limit_file_size(size: int):  # type: ignore[no-untyped-def]
    import resource

    def apply() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (size, size))

    return apply


def test_write_beyond_the_file_size_limit_fails_cleanly(tmp_path: Path) -> None:
    output, before = complete_output(tmp_path)
    # about 13 MB of records against a 1 MB limit: the write fails with EFBIG, not SIGXFSZ
    scene = write(tmp_path, "&time dt=1e-5, t_end=2 /\n")
    done = subprocess.run([PROGRAM, "run", "scene.nml", "-o", output.name], cwd=tmp_path, capture_output=True,
                          text=True, timeout=120, preexec_fn=limit_file_size(1 << 20))
    assert done.returncode == 4, (done.returncode, done.stderr)
    line = one_error_line(done)
    assert line.startswith(f"beamstops: error: {output.name}: ") and "file-size limit" in line
    assert "kept.h5.partial" in line
    assert output.read_bytes() == before  # the complete output of the earlier run is untouched
    partial = tmp_path / "kept.h5.partial"
    assert partial.exists() and partial.stat().st_size <= 1 << 20
    try:  # the partial file is never presented as complete (a failed write may leave it unreadable)
        with h5py.File(partial) as f:
            assert f.attrs["status"] != b"complete"
    except OSError:
        pass
    # once the limit is lifted, the same command runs (the broken partial file is its own)
    done = beamstops("run", scene, "-o", output.name, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    with h5py.File(output) as f:
        assert f.attrs["status"] == b"complete" and f.attrs["steps"] == 200000


def test_unwritable_folder_exits_4_and_writes_nothing(tmp_path: Path) -> None:
    """A folder the program may not write into; root writes anywhere, so as root the program
    runs as the user nobody."""
    import tempfile

    base = Path(tempfile.mkdtemp(prefix="beamstops-ro-"))
    try:
        base.chmod(0o755)
        scene = base / "scene.nml"
        scene.write_text(SHORT)
        scene.chmod(0o644)
        locked = base / "locked"
        locked.mkdir()
        locked.chmod(0o555)
        preexec = None
        if os.geteuid() == 0:
            def preexec() -> None:
                os.setgid(65534)
                os.setuid(65534)
        done = subprocess.run([PROGRAM, "run", "scene.nml", "-o", "locked/out.h5"], cwd=base, capture_output=True,
                              text=True, timeout=120, preexec_fn=preexec)
        assert done.returncode == 4, done.stderr
        line = one_error_line(done)
        assert line == ("beamstops: error: locked/out.h5 (-o): cannot create locked/out.h5.partial, where the run "
                        "writes until it is done: Permission denied")
        assert list(locked.iterdir()) == []
    finally:
        shutil.rmtree(base, ignore_errors=True)


def test_diverged_run_replaces_the_output_and_says_so(tmp_path: Path) -> None:
    output, _ = complete_output(tmp_path, "bad.h5")
    scene = write(tmp_path, "&time dt=2e-5, beta=0, t_end=0.5, allow_unstable=.true. /\n"
                            "&output record_every=100 /\n")
    done = beamstops("run", scene, "-o", output.name, cwd=tmp_path)
    assert done.returncode == 3
    assert "diverged" in one_error_line(done)
    with h5py.File(output) as f:
        assert f.attrs["status"] == b"diverged" and f.attrs["beta"] == 0
    assert not list(tmp_path.glob("*.partial")) and not list(tmp_path.glob("*.checkpoint"))


@pytest.mark.parametrize("kind", ["file", "symbolic link", "hard link"])
def test_a_finished_run_replaces_the_name_of_an_earlier_output_only(kind: str, tmp_path: Path) -> None:
    """The finished file takes the output's name: an earlier output there is replaced; a link there is
    replaced as a name, and what it led to (another output, another name of it) is left as it was."""
    earlier, before = complete_output(tmp_path, "earlier.h5")
    out = tmp_path / "out.h5"
    if kind == "file":
        out = earlier
    elif kind == "symbolic link":
        out.symlink_to(earlier.name)
    else:
        os.link(earlier, out)
    scene = write(tmp_path, "&time dt=5e-5, t_end=0.2 /\n")
    done = beamstops("run", scene, "-o", out.name, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert not out.is_symlink()
    with h5py.File(out) as f:
        assert f.attrs["status"] == b"complete" and f.attrs["steps"] == 4000
    if kind != "file":
        assert earlier.read_bytes() == before
    assert not list(tmp_path.glob("*.partial"))


# ---------------------------------------------------------------- one entry point: the Python subcommands


def listed_commands(help_text: str) -> dict[str, str]:
    """Command names of `beamstops --help` (two-space indented lines) and their descriptions."""
    out = {}
    for line in help_text.split("exit statuses")[0].splitlines():
        if line.startswith("  ") and not line.startswith("   "):
            name, _, description = line.strip().partition(" ")
            out[name] = description.strip()
    return out


def test_help_lists_every_command_with_a_description(tmp_path: Path) -> None:
    from beamstops.cli import commands

    done = beamstops("--help", cwd=tmp_path)
    assert done.returncode == 0 and done.stderr == ""
    listed = listed_commands(done.stdout)
    python = commands()
    assert {"plot", "sweep", "converge", "work-precision", "stability-map", "compliance"} <= set(python)
    for name in ["run", "info", *python]:
        assert name in listed, (name, done.stdout)
    for name in python:
        assert listed[name], name
    # the program hands on exactly the Python subcommands: none missing, none extra
    assert set(listed) - {"run", "info", "--version"} == set(python)


@pytest.mark.parametrize("args", [["run", "--help"], ["info", "--help"], ["run", "-h"], ["run", "scene.nml", "--help"]])
def test_help_after_an_engine_command_is_the_help(args: list[str], tmp_path: Path) -> None:
    """`beamstops run --help` shows the help (it had been refused as an unexpected argument, exit 2)."""
    write(tmp_path, SHORT)
    done = beamstops(*args, cwd=tmp_path)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    assert done.stdout == beamstops("--help", cwd=tmp_path).stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.nml"]  # nothing run


def test_python_subcommands_run_from_the_program(tmp_path: Path) -> None:
    scene = write(tmp_path, SHORT)
    assert beamstops("run", scene, "-o", "short.h5", cwd=tmp_path).returncode == 0
    done = beamstops("plot", "short.h5", "--kind", "energy", "-o", "energy.png", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "energy.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the exit status is Python's: 1 for a user error, 2 for argparse's usage error
    done = beamstops("plot", "missing.h5", cwd=tmp_path)
    assert done.returncode == 1 and done.stderr.startswith("beamstops: error: missing.h5")
    done = beamstops("plot", cwd=tmp_path)
    assert done.returncode == 2 and done.stderr == ("beamstops plot: error: the following arguments are required: "
                                                    "file (beamstops plot --help: the options)\n")
    for name in ["sweep", "converge", "work-precision", "stability-map", "compliance"]:
        done = beamstops(name, "--help", cwd=tmp_path)
        assert done.returncode == 0 and f"usage: beamstops {name}" in done.stdout, (name, done.stderr)


def test_a_python_subcommand_replaces_the_program(tmp_path: Path) -> None:
    """execv, not a child process: the process becomes Python, so signals reach it directly."""
    import signal
    import time

    process = subprocess.Popen([PROGRAM, "converge", "-o", str(tmp_path / "c"), "--quiet"], cwd=tmp_path,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    cmdline = Path(f"/proc/{process.pid}/cmdline")
    deadline = time.time() + 30
    seen = b""
    while time.time() < deadline and process.poll() is None:
        seen = cmdline.read_bytes() if cmdline.exists() else b""
        if b"beamstops.cli" in seen:
            break
        time.sleep(0.01)
    try:
        assert b"beamstops.cli" in seen and b"converge" in seen, seen
        assert not [p for p in Path("/proc").glob("[0-9]*") if _parent(p) == process.pid]
    finally:
        process.send_signal(signal.SIGTERM)
        returncode = process.wait(timeout=30)
    assert returncode == -signal.SIGTERM


def _parent(proc: Path) -> int:
    try:
        return int((proc / "stat").read_text().rsplit(")", 1)[1].split()[1])
    except (OSError, IndexError, ValueError):
        return -1


def test_without_python_a_python_subcommand_says_so(tmp_path: Path) -> None:
    lone = tmp_path / "bin" / "beamstops"
    lone.parent.mkdir()
    shutil.copy2(PROGRAM, lone)  # no python beside it, and none on PATH
    done = subprocess.run([str(lone), "plot", "x.h5"], cwd=tmp_path, capture_output=True, text=True, timeout=60,
                          env={"PATH": str(tmp_path / "bin")})
    assert done.returncode == 2
    line = one_error_line(done)
    assert "'plot'" in line and "Python" in line
    # the engine's own commands need no Python
    scene = write(tmp_path, SHORT)
    assert subprocess.run([str(lone), "info", str(scene)], capture_output=True, env={"PATH": ""}).returncode == 0


def test_without_the_package_a_python_subcommand_says_so(tmp_path: Path) -> None:
    import sys

    base = getattr(sys, "_base_executable", sys.executable)
    probe = subprocess.run([base, "-c", "import beamstops"], capture_output=True)
    if probe.returncode == 0:
        pytest.skip(f"{base} imports beamstops: no Python without the package here")
    lone = tmp_path / "bin" / "beamstops"
    lone.parent.mkdir()
    shutil.copy2(PROGRAM, lone)
    (tmp_path / "bin" / "python").symlink_to(base)  # a Python beside the program, without the package
    done = subprocess.run([str(lone), "sweep", "spec.toml"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 2
    line = one_error_line(done)
    assert "'sweep'" in line and "beamstops Python package" in line and "pip install" in line


def test_an_empty_partial_file_left_by_a_kill_is_replaced(tmp_path: Path) -> None:
    """A run killed right after creating OUT.h5.partial leaves it empty: the next run takes it."""
    scene = write(tmp_path, SHORT)
    (tmp_path / "out.h5.partial").write_bytes(b"")
    done = beamstops("run", scene, "-o", "out.h5", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert not (tmp_path / "out.h5.partial").exists()
    with h5py.File(tmp_path / "out.h5") as f:
        assert f.attrs["status"] == b"complete"



def _threads_while_running(process: subprocess.Popen[bytes], partial: Path) -> int | None:
    """The number of threads of the running program (/proc/PID/task) once its run is under way
    (its partial output file exists: the start, the BLAS's included, is behind it); None when it
    ended first."""
    import time

    while process.poll() is None:
        if partial.exists():
            time.sleep(0.05)
            try:
                return len(list(Path(f"/proc/{process.pid}/task").iterdir()))
            except OSError:
                return None
        time.sleep(0.002)
    return None


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs /proc")
@pytest.mark.parametrize("chosen", [None, "2"])
def test_run_stops_a_threaded_openblas_pool_unless_told(chosen: str | None, tmp_path: Path) -> None:
    """A threaded OpenBLAS spins its pool of threads for about 0.1 s of CPU at every start; `run`
    puts OpenBLAS on one thread and stops the pool unless the user set OPENBLAS_NUM_THREADS (or
    OMP_NUM_THREADS): during the run the program then has two threads, its own and the HDF5
    writer's. With the user's choice the run goes on as before. Skipped when the BLAS is not
    OpenBLAS."""
    ldd = shutil.which("ldd")
    if ldd is None or "openblas" not in subprocess.run([ldd, PROGRAM], capture_output=True, text=True).stdout:
        pytest.skip("the program's BLAS is not OpenBLAS")
    scene = write(tmp_path, "&time dt=1e-6, t_end=2 /\n&output file='long.h5', record_every=1000 /\n")
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")}
    if chosen is not None:
        env["OPENBLAS_NUM_THREADS"] = chosen
    process = subprocess.Popen([PROGRAM, "run", str(scene)], cwd=tmp_path, env=env, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    try:
        threads = _threads_while_running(process, tmp_path / "long.h5.partial")
        assert process.wait(timeout=120) == 0
    finally:
        if process.poll() is None:
            process.kill()
    if chosen is None:
        assert threads == 2
    with h5py.File(tmp_path / "long.h5") as f:
        assert f.attrs["status"] == b"complete"


def _cpu_list(text: str) -> set[int]:
    """The CPUs of a list such as '0-3,6' (/proc/PID/status's Cpus_allowed_list)."""
    cpus: set[int] = set()
    for part in text.strip().split(","):
        low, _, high = part.partition("-")
        cpus.update(range(int(low), int(high or low) + 1))
    return cpus


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs /proc")
@pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="needs two CPUs (with one, no writer thread)")
def test_the_writer_thread_keeps_off_the_time_loops_cpu(tmp_path: Path) -> None:
    """The HDF5 writer thread may run on any CPU the process may use but the one the time loop
    is on (the kernel had woken it there, where it preempted the loop while the other CPU idled):
    while the run goes on, its allowed CPUs are the process's without the loop's."""
    import time

    scene = write(tmp_path, "&time dt=1e-6, t_end=4 /\n&output file='long.h5', record_every=1 /\n")
    process = subprocess.Popen([PROGRAM, "run", str(scene)], cwd=tmp_path, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    samples: list[tuple[set[int], set[int], int]] = []
    try:
        while process.poll() is None and len(samples) < 20:
            time.sleep(0.02)
            if not (tmp_path / "long.h5.partial").exists():
                continue
            try:
                tasks = {int(t.name): t for t in Path(f"/proc/{process.pid}/task").iterdir()}
                if len(tasks) != 2:
                    continue
                loop, writer = tasks[process.pid], next(t for tid, t in tasks.items() if tid != process.pid)
                allowed = {t: _cpu_list(next(line.split(":", 1)[1] for line in (t / "status").read_text().splitlines()
                                             if line.startswith("Cpus_allowed_list"))) for t in (loop, writer)}
                loop_cpu = int((loop / "stat").read_text().rsplit(")", 1)[1].split()[36])
            except (OSError, StopIteration, KeyError):
                continue
            samples.append((allowed[loop], allowed[writer], loop_cpu))
        assert process.wait(timeout=120) == 0
    finally:
        if process.poll() is None:
            process.kill()
    assert len(samples) >= 5, "the run ended before it could be watched"
    # the writer is kept off one CPU of the process's, never more (all of them only after the loop
    # had to wait for it: a machine so busy that the writer fell behind), and (the loop moving
    # seldom) off the loop's own most of the time
    assert all(writer <= loop and len(loop - writer) <= 1 for loop, writer, _ in samples), samples
    assert sum(cpu not in writer for _, writer, cpu in samples) >= len(samples) // 2, samples


def test_an_empty_or_repeated_output_name_is_refused_before_the_run(tmp_path: Path) -> None:
    scene = write(tmp_path, SHORT)
    for args in (["-o", ""], ["-o", "  "], ["-o", "a.h5", "-o", "b.h5"]):
        done = beamstops("run", scene, *args, cwd=tmp_path)
        lines = done.stderr.strip().splitlines()
        assert done.returncode == 2 and len(lines) == 1 and "'-o'" in lines[0], (args, done.stderr)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.nml"]


def test_the_transient_must_come_before_the_last_step_the_run_reaches(tmp_path: Path) -> None:
    # t_end = 0.0104 s in steps of 1 ms: the run ends at 0.010 s, before a transient of 0.0102 s
    scene = write(tmp_path, "&time dt=1e-3, t_end=0.0104 /\n&statistics transient=0.0102 /\n")
    done = beamstops("run", scene, cwd=tmp_path)
    line = one_error_line(done)
    assert done.returncode == 1 and "&statistics transient" in line and "< 0.01 s" in line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.nml"]


def test_contact_phases_count_every_phase_of_every_shock(tmp_path: Path) -> None:
    # a gap of 2e-12 m: the tip goes from one stop straight to the other, phase after phase
    for stops in ("&stops lower=-1e-12, upper=1e-12 /\n", "&stops nodes=5,10,19, lower=-0.01, upper=0.01 /\n"):
        scene = write(tmp_path, "&time dt=5e-5, t_end=0.2 /\n" + stops + "&output file='p.h5' /\n")
        done = beamstops("run", scene, cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        with h5py.File(tmp_path / "p.h5") as f:
            shocks = f["impacts/rebounds"].shape[0]
            phases = int(np.sum(f["impacts/rebounds"][:])) + shocks  # rebounds = phases - 1 per shock
            assert f.attrs["impacts"] == shocks > 0
            assert f.attrs["contact_phases"] == phases >= shocks, stops
        (tmp_path / "p.h5").unlink()


def test_a_key_given_twice_in_a_group_is_refused(tmp_path: Path) -> None:
    scene = write(tmp_path, "&time dt=1e-5, t_end=0.001, DT = 2e-5 /\n")
    line = one_error_line(beamstops("run", scene, cwd=tmp_path))
    assert "&time dt is given twice" in line
    # the elements of an array, each once, are not a repetition
    scene = write(tmp_path, "&damping ratio(1)=0.01, ratio(2)=0.02 /\n&time dt=5e-5, t_end=0.001 /\n")
    assert beamstops("run", scene, cwd=tmp_path).returncode == 0


def test_a_byte_order_mark_at_the_start_of_a_namelist_is_ignored(tmp_path: Path) -> None:
    scene = tmp_path / "bom.nml"
    scene.write_bytes(b"\xef\xbb\xbf&time dt=5e-5, t_end=0.001 /\n&output file='bom.h5' /\n")
    done = beamstops("run", scene, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    with h5py.File(tmp_path / "bom.h5") as f:
        assert f.attrs["status"] == b"complete" and f.attrs["steps"] == 20


def test_too_many_stops_along_the_span_are_refused_naming_the_limit(tmp_path: Path) -> None:
    scene = write(tmp_path, "&stops nodes=" + ",".join(["19"] * 1001) + ", lower=-0.01, upper=0.01 /\n")
    line = one_error_line(beamstops("run", scene, cwd=tmp_path))
    assert "&stops nodes" in line and "at most 1000 stops" in line


def test_bad_damping_leaves_an_earlier_output_and_info_refuses_it(tmp_path: Path) -> None:
    kept, before = complete_output(tmp_path, "in.h5")
    for value in ("inf", "1e150", "1e300"):
        scene = write(tmp_path, SHORT + f"&damping mass_coefficient={value} /\n", name="in.nml")
        line = one_error_line(done := beamstops("run", scene, cwd=tmp_path))
        assert done.returncode == 1 and "&damping mass_coefficient" in line and "is out of range" in line
        assert kept.read_bytes() == before
        done = beamstops("info", scene, cwd=tmp_path)
        assert done.returncode == 1 and "&damping mass_coefficient" in one_error_line(done)


def test_a_namelist_from_a_pipe_is_read_whole_and_needs_an_output_name(tmp_path: Path) -> None:
    text = "&time dt=5e-5, t_end=0.001 /\n"

    def piped(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([PROGRAM, *args], cwd=tmp_path, input=text, capture_output=True, text=True,
                              timeout=120)

    # a pipe reports size 0: it was read as an empty text, 'no namelist group'
    done = piped("info", "/dev/stdin")
    assert done.returncode == 0, done.stderr
    done = piped("run", "/dev/stdin", "-o", "piped.h5")
    assert done.returncode == 0, done.stderr
    with h5py.File(tmp_path / "piped.h5") as f:
        assert f.attrs["status"] == b"complete" and f.attrs["steps"] == 20
    # /dev/stdin or /dev/fd/63 (bash's <(...)) names no output: -o or &output file is needed
    done = piped("run", "/dev/stdin")
    assert done.returncode == 4
    line = one_error_line(done)
    assert "/dev/stdin: a namelist read from a pipe" in line and "-o OUT.h5 or &output file" in line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["piped.h5"]
    text += "&output file='named.h5' /\n"
    assert piped("run", "/dev/stdin").returncode == 0 and (tmp_path / "named.h5").exists()


def test_a_pipe_beyond_64_mb_and_a_file_beyond_4_gib_are_refused_with_their_size(tmp_path: Path) -> None:
    done = subprocess.run([PROGRAM, "info", "/dev/stdin"], cwd=tmp_path, input=b" " * (64 * 2**20 + 1),
                          capture_output=True, timeout=120)
    assert done.returncode == 1
    assert "/dev/stdin: more than 64 MB read" in done.stderr.decode()
    big = tmp_path / "big.nml"
    with big.open("wb") as f:  # sparse: 5 GiB said 1073741824 bytes (an int32 size), 3 GiB 'no namelist group'
        f.truncate(5 * 2**30)
    line = one_error_line(beamstops("info", big, cwd=tmp_path))
    assert "big.nml: 5368709120 bytes; allowed: a namelist file of at most 64 MB" in line
# ---------------------------------------------------------------- info and run: one check (audit P6)


def test_info_applies_the_check_of_run_with_the_limit_of_the_reduced_model(tmp_path: Path) -> None:
    # beta = 0 with &mesh modes = 4: the run steps the reduced model, whose limit is 1.30e-3 s (the
    # full model's, 1.24e-5 s, does not apply); info refuses what run refuses, with its message
    unstable = write(tmp_path, "&time dt=1e-2, t_end=0.05, beta=0 /\n&mesh modes=4 /\n", "unstable.nml")
    info, run = beamstops("info", unstable.name, cwd=tmp_path), beamstops("run", unstable.name, cwd=tmp_path)
    assert info.returncode == run.returncode == 1 and info.stdout == ""
    line = one_error_line(info)
    assert line == one_error_line(run)
    assert line.startswith("beamstops: error: unstable.nml: &time dt = 0.01 is out of range; allowed: dt < 0.00129667 s")
    assert "of the reduced model with modes = 4" in line
    # within the reduced model's limit, beyond the full model's: both accept, info shows the limit that applies
    stable = write(tmp_path, "&time dt=1e-3, t_end=0.05, beta=0 /\n&mesh modes=4 /\n", "stable.nml")
    info = beamstops("info", stable, cwd=tmp_path)
    assert info.returncode == 0, info.stderr
    shown = {line[:29].strip(): line[29:] for line in info.stdout.splitlines()}
    limit = shown["dt limit Newmark"].split()
    assert float(limit[0]) == pytest.approx(1.296673e-3, rel=1e-6) and "of the reduced model of 4 modes" in shown[
        "dt limit Newmark"]
    assert float(shown["kappa of the run"].split()[0]) == pytest.approx(2.379027e6, rel=1e-6)
    assert beamstops("run", stable, cwd=tmp_path).returncode == 0
    # the full model: its own limit, named as such
    full = write(tmp_path, "&time dt=1e-6, t_end=0.001, beta=0 /\n", "full.nml")
    shown = {line[:29].strip(): line[29:] for line in beamstops("info", full, cwd=tmp_path).stdout.splitlines()}
    assert float(shown["dt limit Newmark"].split()[0]) == pytest.approx(1.239506e-5, rel=1e-6)
    assert "of the full model" in shown["dt limit Newmark"] and "kappa of the run" not in shown


def test_several_scenes_refuse_a_reduced_scene_beyond_its_limit_before_any_runs(tmp_path: Path) -> None:
    good = write(tmp_path, SHORT, "good.nml")
    bad = write(tmp_path, "&time dt=1e-2, t_end=0.05, beta=0 /\n&mesh modes=4 /\n", "bad.nml")
    done = beamstops("run", good, bad, cwd=tmp_path)
    assert done.returncode == 1
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 2 and "bad.nml: &time dt = 0.01 is out of range" in lines[0], done.stderr
    assert lines[1] == "beamstops: none of the 2 scenes was run"
    assert not list(tmp_path.glob("*.h5*"))


# ---------------------------------------------------------------- output paths: origin and the system's reason (audit P10)


def test_a_name_too_long_is_refused_with_the_systems_reason(tmp_path: Path) -> None:
    scene = write(tmp_path, SHORT)
    name = "a" * 300 + ".h5"
    line = one_error_line(done := beamstops("run", scene, "-o", name, cwd=tmp_path))
    assert done.returncode == 4
    assert line == (f"beamstops: error: {name} (-o): cannot create {name}.partial, where the run writes until it is "
                    "done: File name too long")
    # the partial file fits the limit of 255 bytes, the checkpoint's temporary file does not: refused before the
    # run when checkpoints are asked for, not at the first checkpoint
    name = "b" * 243 + ".h5"
    scene = write(tmp_path, SHORT + "&output checkpoint_every=1000 /\n")
    line = one_error_line(done := beamstops("run", scene, "-o", name, cwd=tmp_path))
    assert done.returncode == 4 and line.endswith(
        f"cannot create {name}.checkpoint.tmp, where the run saves its checkpoints (&output checkpoint_every): "
        "File name too long")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.nml"]


def test_an_output_name_ending_in_a_slash_is_refused_naming_the_namelist(tmp_path: Path) -> None:
    scene = write(tmp_path, SHORT + "&output file='out.h5/' /\n").name
    done = beamstops("run", scene, cwd=tmp_path)
    assert done.returncode == 4
    assert one_error_line(done) == ("beamstops: error: out.h5/ (&output file of scene.nml): ends with /, the name of "
                                    "a folder, not of a file; allowed: the name of the HDF5 file to write, e.g. out.h5")
    (tmp_path / "out.h5").mkdir()  # an existing folder too
    assert one_error_line(beamstops("run", scene, cwd=tmp_path)).startswith(
        "beamstops: error: out.h5/ (&output file of scene.nml): ends with /")
    # a name from -o; and the default, the input's name with .h5, says so
    line = one_error_line(beamstops("run", scene, "-o", "x/", cwd=tmp_path))
    assert line.startswith("beamstops: error: x/ (-o): ends with /") and line.endswith("e.g. x")
    (tmp_path / "scene.h5").write_text("notes\n")
    line = one_error_line(beamstops("run", write(tmp_path, SHORT).name, cwd=tmp_path))
    assert line.startswith("beamstops: error: scene.h5 (&output file of scene.nml, by default the input's name "
                           "with .h5): exists and is not a beamstops output")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.h5", "scene.h5", "scene.nml"]


def test_several_scenes_refuse_an_output_the_system_refuses_before_any_runs(tmp_path: Path) -> None:
    write(tmp_path, SHORT, "good.nml")
    write(tmp_path, SHORT + "&output file='missing/bad.h5' /\n", "bad.nml")
    done = beamstops("run", "good.nml", "bad.nml", cwd=tmp_path)
    assert done.returncode == 4
    assert done.stderr.splitlines() == [
        "beamstops: error: missing/bad.h5 (&output file of bad.nml): cannot create missing/bad.h5.partial, where the "
        "run writes until it is done: No such file or directory", "beamstops: none of the 2 scenes was run"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.nml", "good.nml"]


def test_standard_output_is_refused_as_an_output(tmp_path: Path) -> None:
    scene = write(tmp_path, SHORT)
    done = beamstops("run", scene, "-o", "-", cwd=tmp_path)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1 and lines[0].startswith(
        "beamstops: '-o -': beamstops cannot write its output to standard output"), done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.nml"]
    # a file named - is still possible, spelt as a path
    assert beamstops("run", scene, "-o", "./-", cwd=tmp_path).returncode == 0 and (tmp_path / "-").is_file()


# ---------------------------------------------------------------- repeated or unexpected arguments


@pytest.mark.parametrize(("args", "needle"), [
    (["run", "scene.nml", "--restart", "--restart"], "'--restart' is given twice; allowed: once"),
    (["--version", "junk"], "unexpected argument 'junk' after '--version', which takes none"),
    (["-V", "junk"], "unexpected argument 'junk' after '-V', which takes none"),
    (["--help", "run"], "unexpected argument 'run' after '--help', which takes none"),
])
def test_repeated_or_unexpected_arguments_are_refused(args: list[str], needle: str, tmp_path: Path) -> None:
    write(tmp_path, SHORT)
    done = beamstops(*args, cwd=tmp_path)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1 and needle in lines[0], done.stderr
    assert done.stdout == "" and sorted(p.name for p in tmp_path.iterdir()) == ["scene.nml"]


# ---------------------------------------------------------------- numbers of any exponent


def test_numbers_with_three_digit_exponents_are_printed_with_their_e(tmp_path: Path) -> None:
    import re

    # a support amplitude of 1e-60 m: the support's work is of order 1e-120 J
    text = "&time dt=1e-5, t_end=1e-4 /\n&support amplitude=1e-60 /\n"
    done = beamstops("run", write(tmp_path, text), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    info = beamstops("info", write(tmp_path, text + "&stops lower=-1e-120, upper=1e-120 /\n", "tiny.nml"),
                     cwd=tmp_path)
    assert info.returncode == 0, info.stderr
    for shown_text in (done.stdout, info.stdout):
        # a mantissa followed by a signed exponent without its e (gfortran's ES of |exponent| > 99)
        assert not re.search(r"\d[-+]\d{3}\b", shown_text), shown_text
    work = re.search(r"support work (\S+),", done.stdout)
    assert work is not None, done.stdout
    shown = {line[:29].strip(): line[29:].split() for line in info.stdout.splitlines()}
    assert float(shown["&support amplitude"][0]) == 1e-60 and float(shown["&stops lower"][0]) == -1e-120
    with h5py.File(tmp_path / "scene.h5") as f:  # the summary's number is the file's, to its 4 digits
        assert 0 < abs(f.attrs["work"]) < 1e-99
        assert float(work.group(1)) == pytest.approx(f.attrs["work"], rel=1e-3)
        assert "amplitude = 1e-60" in f.attrs["scene"].decode() and f.attrs["amplitude"] == 1e-60

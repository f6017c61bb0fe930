"""Outputs of ``plot``, ``plan`` and the studies (beamstops.output_files): no data destroyed, no
half-written file, one line naming the file.

Found by an audit: the studies wrote over any file at their fixed names (an HDF5 output named
compliance.png, a namelist named convergence.md) and through symbolic links; a full disk left a
truncated PNG in place of the old image, and a 0-byte scene that later plans refused; ``plan``
invented /dev/stdin_plan.nml, hung on a FIFO at -o and found an unwritable -o only after its
whole search."""

from __future__ import annotations

import csv
import os
import resource
import stat
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import beamstops
from beamstops import cli, output_files
from beamstops.output_files import IMAGE, WriteError

PNG = b"\x89PNG\r\n\x1a\n"
HDF5 = b"\x89HDF\r\n\x1a\n"
SCENE = beamstops.Scene(law="none", t_end=0.05)
PLAN = ["--qoi", "tip", "--until", "0.01", "--tol", "1e-2", "--quiet"]


def command(*args: str | Path, cwd: Path, stdin: str | None = None,
            preexec_fn: Callable[[], None] | None = None) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    return subprocess.run([sys.executable, "-m", "beamstops", *map(str, args)], cwd=cwd, input=stdin,
                          capture_output=True, text=True, timeout=300, env={**env, "MPLBACKEND": "Agg"},
                          preexec_fn=preexec_fn)


def file_size_limit(size: int) -> Callable[[], None]:
    """RLIMIT_FSIZE in the child: a write past ``size`` bytes fails with EFBIG (Python ignores
    SIGXFSZ), as a full disk fails with ENOSPC."""
    def apply() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (size, resource.RLIM_INFINITY))

    return apply


@pytest.fixture(scope="module")
def run_file(program: str, tmp_path_factory: pytest.TempPathFactory) -> Path:
    where = tmp_path_factory.mktemp("run")
    SCENE.replace(snapshot_every=50, file="keep.h5").to_namelist(where / "scene.nml")
    done = subprocess.run([program, "run", "scene.nml"], cwd=where, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return where / "keep.h5"


# ------------------------------------------------------------------ the helper itself

def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path: Path) -> None:
    old = tmp_path / "old.png"
    old.write_bytes(PNG + b"old")

    def fail(tmp: Path) -> None:
        tmp.write_bytes(PNG + b"half")
        raise OSError(28, "No space left on device")

    with pytest.raises(WriteError) as error:
        output_files.write(old, IMAGE, fail)
    assert str(error.value) == f"cannot write {old}: No space left on device" and error.value.errno == 28
    with pytest.raises(KeyboardInterrupt):
        output_files.write(tmp_path / "new.png", IMAGE, lambda tmp: (_ for _ in ()).throw(KeyboardInterrupt()))
    assert old.read_bytes() == PNG + b"old" and sorted(p.name for p in tmp_path.iterdir()) == ["old.png"]


def test_a_written_file_gets_the_permissions_of_a_new_file(tmp_path: Path) -> None:
    """The temporary file is made as a new file is (0666 less the umask), not 0600 as mkstemp makes it."""
    mask = os.umask(0o022)
    try:
        path = output_files.write_text(tmp_path / "a.png", IMAGE, "<svg/>")
    finally:
        os.umask(mask)
    assert stat.S_IMODE(path.stat().st_mode) == 0o644


def test_check_refuses_links_special_files_and_unwritable_folders(tmp_path: Path) -> None:
    (tmp_path / "image.png").write_bytes(PNG)
    (tmp_path / "link.png").symlink_to(tmp_path / "image.png")
    (tmp_path / "dangling.png").symlink_to(tmp_path / "absent.png")
    os.mkfifo(tmp_path / "fifo.png")
    for name in ("link.png", "dangling.png"):
        with pytest.raises(FileExistsError, match=f"{name}: is a symbolic link; refusing to write an image through it"):
            output_files.check(tmp_path / name, IMAGE)
    with pytest.raises(FileExistsError, match="fifo.png: exists and is not a regular file"):
        output_files.check(tmp_path / "fifo.png", IMAGE)
    with pytest.raises(WriteError, match=r"cannot write .*/absent/x\.png: No such file or directory"):
        output_files.check(tmp_path / "absent" / "x.png", IMAGE)
    with pytest.raises(ValueError, match="an empty file name"):
        output_files.check("", IMAGE)
    assert not (tmp_path / "absent.png").exists() and (tmp_path / "image.png").read_bytes() == PNG
    assert output_files.check(tmp_path / "image.png", IMAGE) == tmp_path / "image.png"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dangling.png", "fifo.png", "image.png", "link.png"]


# ------------------------------------------------------------------ plot

def test_plot_on_a_write_that_fails_keeps_the_old_image(run_file: Path, tmp_path: Path) -> None:
    """A failed write (here the file-size limit, EFBIG; a full disk is ENOSPC) had left a truncated
    PNG in place of the old image, and a 0-byte file at a new name."""
    assert command("plot", run_file, "-o", "old.png", cwd=tmp_path).returncode == 0
    old = (tmp_path / "old.png").read_bytes()
    for name in ("old.png", "new.png", "anim.gif"):
        kind = "animation" if name.endswith("gif") else "all"
        done = command("plot", run_file, "--kind", kind, "-o", name, cwd=tmp_path, preexec_fn=file_size_limit(4096))
        assert done.returncode == 1 and done.stdout == "", done.stderr
        assert done.stderr.strip() == f"beamstops: error: cannot write {name}: File too large"
    assert (tmp_path / "old.png").read_bytes() == old
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old.png"]


def test_plot_refuses_an_empty_output_name(run_file: Path, tmp_path: Path) -> None:
    """`plot -o ''` wrote the default name (run refuses it)."""
    done = command("plot", run_file, "-o", "", cwd=tmp_path)
    assert done.returncode == 2 and "argument -o/--output: '': allowed: an image file name" in done.stderr
    assert list(tmp_path.iterdir()) == [] and not (run_file.parent / "keep_tip.png").exists()


def test_plots_python_arguments_share_the_command_lines_checks(tmp_path: Path) -> None:
    """save(result, f, kind='pdf', transient=-1) drew what --transient -1 refuses; save(None, ...)
    raised AttributeError."""
    result = beamstops.run(SCENE)
    for transient, error, message in ((-1, ValueError, "transient -1: allowed: a time in s >= 0"),
                                      (float("nan"), ValueError, "transient nan: allowed: a time in s >= 0"),
                                      ("0.01", TypeError, "transient '0.01': allowed: a time in s >= 0")):
        with pytest.raises(error, match=message):
            beamstops.plots.save(result, tmp_path / "x.png", kind="pdf", transient=transient)
        with pytest.raises(error, match=message):
            beamstops.plots.figure(result, "psd", transient=transient)
    with pytest.raises(TypeError, match="result: a beamstops.Result .*, not NoneType"):
        beamstops.plots.save(None, tmp_path / "x.png")  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="path: the image file to write .*, not NoneType"):
        beamstops.plots.save(result, None)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="an empty name"):
        beamstops.plots.save(result, "")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("damage, message", [
    (lambda f: f.__delitem__("energy"), "/energy/E: missing, where /tip/t has"),
    (lambda f: f.__delitem__("tip/u"), "/tip/u: missing, where /tip/t has"),
    (lambda f: (f.__delitem__("tip/u"), f.create_dataset("tip/u", data=np.zeros(3))), "/tip/u: 3 records where"),
    (lambda f: (f.__delitem__("tip/v"), f.create_dataset("tip/v", data=np.zeros((3, 3)))), "/tip/v: 2 dimension(s)"),
    (lambda f: (f.__delitem__("tip/u"), f.create_dataset("tip/u", data=np.array([b"a"] * 3))), "/tip/u: not numbers"),
    (lambda f: (f.__delitem__("snapshots/x"), f.create_dataset("snapshots/x", data=np.zeros(3))),
     "/snapshots/x: shape (3,), where the run's 19 elements have 19 + 1 nodes"),
])
def test_plot_of_a_file_missing_its_series_is_one_line_naming_it(run_file: Path, tmp_path: Path,
                                                                  damage: Callable[..., object], message: str) -> None:
    """Identity attributes in place but /energy or /tip/u missing, or /snapshots/x of the wrong size:
    matplotlib's words without the file's name ('x and y must have same first dimension'), a
    traceback for the snapshots."""
    import h5py

    path = tmp_path / "damaged.h5"
    path.write_bytes(run_file.read_bytes())
    with h5py.File(path, "r+") as f:
        damage(f)
    for kind in ("tip", "all"):
        done = command("plot", path, "--kind", kind, "-o", "x.png", cwd=tmp_path)
        assert done.returncode == 1 and "Traceback" not in done.stderr, done.stderr
        err = done.stderr.strip().splitlines()
        assert len(err) == 1 and err[0].startswith(f"beamstops: error: {path}: ") and message in err[0], err
    with pytest.raises(ValueError, match="not the output of `beamstops run`, or damaged"):
        beamstops.load(path)
    assert not (tmp_path / "x.png").exists()


# ------------------------------------------------------------------ plan

def test_plan_checks_its_output_before_searching(tmp_path: Path) -> None:
    """A FIFO at -o hung; a missing folder was told after the whole search, in errno's words; a
    link at -o was written through; a pipe gave the name /dev/stdin_plan.nml."""
    SCENE.to_namelist(tmp_path / "s.nml")
    os.mkfifo(tmp_path / "fifo.nml")
    (tmp_path / "lnk.nml").symlink_to(tmp_path / "target.nml")
    for out, message in (("fifo.nml", "fifo.nml: exists and is not a regular file (a FIFO, a device or a socket)"),
                         ("absent/x.nml", "cannot write absent/x.nml: No such file or directory"),
                         ("lnk.nml", "lnk.nml: is a symbolic link; refusing to write a scene through it")):
        done = command("plan", "s.nml", *PLAN, "-o", out, cwd=tmp_path)
        assert done.returncode == 1 and done.stdout == "", done.stderr  # no table: nothing was searched
        err = done.stderr.strip().splitlines()
        assert len(err) == 1 and err[0].startswith(f"beamstops: error: {message}"), err
    assert not (tmp_path / "target.nml").exists() and not (tmp_path / "absent").exists()
    text = (tmp_path / "s.nml").read_text()
    for source in ("/dev/stdin", "/dev/fd/0"):
        done = command("plan", source, *PLAN, cwd=tmp_path, stdin=text)
        assert done.returncode == 1 and done.stdout == "", done.stderr
        assert done.stderr.strip() == (f"beamstops: error: {source}: a namelist read from a pipe, a device or an open "
                                       "descriptor (/dev/stdin, /dev/fd/N, <(...)) gives no output name; allowed: "
                                       "name the output, -o OUT.nml")
    assert not Path("/dev/stdin_plan.nml").exists() and not Path("/dev/fd/0_plan.nml").exists()
    done = command("plan", "/dev/stdin", *PLAN, "-o", "piped.nml", cwd=tmp_path, stdin=text)
    assert done.returncode == 0, done.stderr
    assert beamstops.Scene.from_namelist(tmp_path / "piped.nml").law == "none"


def test_plan_on_a_write_that_fails_leaves_no_file(tmp_path: Path) -> None:
    """A full disk left a 0-byte p.nml, which later plans refused as not theirs; an empty file at
    -o is written over."""
    SCENE.to_namelist(tmp_path / "s.nml")
    done = command("plan", "s.nml", *PLAN, "-o", "p.nml", cwd=tmp_path, preexec_fn=file_size_limit(256))
    assert done.returncode == 1 and done.stderr.strip().endswith("beamstops: error: cannot write p.nml: File too large")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.nml"]
    (tmp_path / "p.nml").write_bytes(b"")
    assert command("plan", "s.nml", *PLAN, "-o", "p.nml", cwd=tmp_path).returncode == 0
    assert beamstops.Scene.from_namelist(tmp_path / "p.nml").law == "none"


# ------------------------------------------------------------------ studies

#: A study, its options, and one name it writes of each kind (table, CSV, chart).
STUDIES = [
    ("converge", [], ["convergence.md", "dt_none_centered.csv", "h_none.md"]),
    ("converge", ["--qoi", "tip_rms"], ["qoi_convergence.md", "qoi_convergence_tip_rms_dt.csv",
                                        "qoi_convergence_tip_rms.png"]),
    ("work-precision", [], ["work_precision.md", "work_precision.csv", "work_precision.png"]),
    ("work-precision", ["--qoi", "tip_rms"], ["work_precision_statistics.md", "statistics_runs.csv",
                                              "work_precision_tip_rms_dt.png"]),
    ("stability-map", [], ["stability.md", "stability_beta.csv", "stability_map.png"]),
    ("compliance", [], ["compliance.md", "compliance.csv", "compliance.png"]),
    ("contact-laws", [], ["contact_laws.md", "contact_laws_energy.csv", "contact_laws.png"]),
]


@pytest.mark.parametrize("study, options, names", STUDIES)
def test_a_study_refuses_before_running_to_write_over_what_is_not_its_own(
        tmp_path: Path, study: str, options: list[str], names: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    """`cp run.h5 u/compliance.png; echo notes > u/compliance.md; beamstops compliance -o u` exited 0
    with them gone; a link at compliance.png destroyed what it led to."""
    run_h5, notes = HDF5 + b"\0" * 64, b"my notes\n"
    precious = tmp_path / "precious.h5"
    precious.write_bytes(run_h5)
    for name, content in zip(names, (notes, run_h5, notes)):
        folder = tmp_path / f"d_{name}"
        folder.mkdir()
        (folder / name).write_bytes(content)
        (folder / "other.txt").write_bytes(notes)
        assert cli.main([study, *options, "--quick", "--quiet", "-o", str(folder)]) == 1
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith(f"beamstops: error: {folder / name}: exists and "), err
        assert "move it away or choose another -o folder" in err[0] or "name another file" in err[0], err
        assert sorted(p.name for p in folder.iterdir()) == sorted([name, "other.txt"])  # nothing ran
        assert (folder / name).read_bytes() == content
        link = tmp_path / f"l_{name}"
        link.mkdir()
        (link / name).symlink_to(precious)
        assert cli.main([study, *options, "--quick", "--quiet", "-o", str(link)]) == 1
        assert f"{link / name}: is a symbolic link" in capsys.readouterr().err
    assert precious.read_bytes() == run_h5


def test_a_study_checks_every_file_of_both_parts_before_either_runs(tmp_path: Path,
                                                                    capsys: pytest.CaptureFixture[str]) -> None:
    """converge --qoi tip STAT runs the statistics' study, then the pointwise one: the namelist at
    convergence.md was found (and kept) only after the first had run and written its files."""
    (tmp_path / "convergence.md").write_text("&time dt = 1e-5 /\n")
    assert cli.main(["converge", "--qoi", "stop_power", "tip", "--quick", "--quiet", "-o", str(tmp_path)]) == 1
    assert "convergence.md: exists and is not a table the study convergence wrote" in capsys.readouterr().err
    assert [p.name for p in tmp_path.iterdir()] == ["convergence.md"]


def test_a_study_runs_again_over_its_own_outputs_only(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Its own earlier outputs are written over (their Markdown marked, their CSV listed with their
    content's hash); a CSV changed since is not; an empty file is; the CSV stays a plain table."""
    (tmp_path / "compliance.png").write_bytes(b"")
    for _ in range(2):
        assert cli.main(["compliance", "--quick", "--quiet", "-o", str(tmp_path)]) == 0
    capsys.readouterr()
    text = (tmp_path / "compliance.md").read_text(encoding="utf-8")
    assert text.startswith("<!-- beamstops study compliance: rewritten when the study runs again into this folder "
                           "-->\n### Normal compliance")
    table = tmp_path / "compliance.csv"
    with table.open(newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert rows and float(rows[0]["Δt (s)"]) > 0
    loaded = np.genfromtxt(table, delimiter=",", names=True, dtype=None, encoding="utf-8")
    assert loaded.shape == (len(rows),) and "np.float64" not in table.read_text(encoding="utf-8")
    assert (tmp_path / "compliance.png").read_bytes()[:8] == PNG
    table.write_text(table.read_text(encoding="utf-8") + "my row\n", encoding="utf-8")
    changed = table.read_bytes()
    assert cli.main(["compliance", "--quick", "--quiet", "-o", str(tmp_path)]) == 1
    assert "compliance.csv: exists and is not a table the study compliance wrote, unchanged since" in \
        capsys.readouterr().err
    assert table.read_bytes() == changed


def test_a_study_on_a_write_that_fails_leaves_no_half_written_file(tmp_path: Path) -> None:
    done = command("stability-map", "--quick", "--quiet", "-o", "out", cwd=tmp_path, preexec_fn=file_size_limit(1024))
    assert done.returncode == 1, done.stderr
    err = done.stderr.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("beamstops: error: cannot write out/") and \
        err[0].endswith(": File too large"), err
    for path in (tmp_path / "out").iterdir():  # what was written is whole (the tables below the limit), no temporary
        assert ".tmp" not in path.name and path.stat().st_size > 0, path


@pytest.mark.parametrize("study", ["converge", "compliance"])
def test_a_study_refuses_an_empty_output_folder_name(tmp_path: Path, study: str, capsys: pytest.CaptureFixture[str],
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    from beamstops.studies import compliance

    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_:
        cli.main([study, "--quick", "--quiet", "-o", ""], prog="beamstops")
    assert exit_.value.code == 2
    assert f"beamstops {study}: error: argument -o/--output: '': allowed: a folder name" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(ValueError, match="an empty output folder name"):
        compliance.study("", quick=True, quiet=True)

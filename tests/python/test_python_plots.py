"""beamstops.plots and `python -m beamstops plot`: files written without any display."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import beamstops
from beamstops import Scene, plots

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def result() -> beamstops.Result:
    return beamstops.run(Scene(t_end=0.2, snapshot_every=50))


@pytest.fixture(scope="module")
def output(program: str, tmp_path_factory: pytest.TempPathFactory) -> Path:
    where = tmp_path_factory.mktemp("plot")
    Scene(t_end=0.2, snapshot_every=50, file="out.h5").to_namelist(where / "scene.nml")
    done = subprocess.run([program, "run", "scene.nml"], cwd=where, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return where / "out.h5"


def headless() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "MPLBACKEND")}
    return env


@pytest.mark.parametrize("kind", plots.KINDS)
def test_each_kind_is_written_from_python(kind: str, result: beamstops.Result, tmp_path: Path) -> None:
    path = plots.save(result, tmp_path / f"{kind}.png", kind=kind)
    assert path.read_bytes()[:8] == PNG and path.stat().st_size > 5000


def test_plot_functions_draw_on_given_axes(result: beamstops.Result, tmp_path: Path) -> None:
    from matplotlib.figure import Figure

    fig = Figure()
    axes = fig.subplots(1, 5)
    for ax, draw in zip(axes, (plots.plot_tip, plots.plot_shape, plots.plot_energy, plots.plot_phase,
                               plots.plot_reaction)):
        assert draw(result, ax) is ax
    fig.savefig(tmp_path / "grid.svg")
    assert (tmp_path / "grid.svg").stat().st_size > 0
    # the stops are drawn on the tip plot
    assert any(line.get_ydata()[0] == 0.1 for line in axes[0].get_lines()[1:])


def test_shape_without_snapshots_says_so(tmp_path: Path) -> None:
    bare = beamstops.run(Scene(t_end=0.01))
    assert plots.save(bare, tmp_path / "shape.png", kind="shape").stat().st_size > 0
    with pytest.raises(ValueError, match="unknown plot kind"):
        plots.figure(bare, "bode")


@pytest.mark.parametrize("kind", ["tip", "all"])
def test_command_line_plot_needs_no_display(kind: str, output: Path, tmp_path: Path) -> None:
    png = tmp_path / f"cli-{kind}.png"
    done = subprocess.run([sys.executable, "-m", "beamstops", "plot", str(output), "-o", str(png), "--kind", kind],
                          capture_output=True, text=True, timeout=120, env=headless())
    assert done.returncode == 0, done.stderr
    assert png.read_bytes()[:8] == PNG
    # and the default name, next to the file
    done = subprocess.run([sys.executable, "-m", "beamstops", "plot", str(output), "--kind", "energy"],
                          capture_output=True, text=True, timeout=120, env=headless())
    assert done.returncode == 0, done.stderr
    assert (output.parent / "out_energy.png").is_file()


def test_command_line_errors_are_one_line(tmp_path: Path) -> None:
    done = subprocess.run([sys.executable, "-m", "beamstops", "plot", str(tmp_path / "nowhere.h5")],
                          capture_output=True, text=True, timeout=120, env=headless())
    assert done.returncode == 1
    assert done.stderr.startswith("beamstops: error: ") and "Traceback" not in done.stderr
    done = subprocess.run([sys.executable, "-m", "beamstops", "plot", "x.h5", "--kind", "bode"],
                          capture_output=True, text=True, timeout=120, env=headless())
    assert done.returncode == 2


def test_importing_the_package_does_not_import_pyplot() -> None:
    code = "import sys, beamstops, beamstops.plots; print('matplotlib.pyplot' in sys.modules)"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, env=headless())
    assert done.stdout.strip() == "False", done.stderr

"""beamstops.plots and `python -m beamstops plot`: files written without any display.

Every kind is drawn from a real run (in memory and by the program, with snapshots); the kinds
of the shock log and the statistics also from the program's file with /impacts and
/statistics groups added in the engine's layout (tests/python/synthetic.py)."""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

import synthetic
import beamstops
from beamstops import Scene, plots
from beamstops.plotbase import NO_SNAPSHOTS
from beamstops.transforms import frame_indices, stroboscopic, welch

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def result() -> beamstops.Result:
    return beamstops.run(Scene(t_end=1.3, snapshot_every=100))


@pytest.fixture(scope="module")
def output(program: str, tmp_path_factory: pytest.TempPathFactory) -> Path:
    where = tmp_path_factory.mktemp("plot")
    Scene(t_end=1.3, snapshot_every=100, file="out.h5").to_namelist(where / "scene.nml")
    done = subprocess.run([program, "run", "scene.nml"], cwd=where, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return where / "out.h5"


@pytest.fixture(scope="module")
def logged(output: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The program's output with a shock log and statistics added in the engine's layout."""
    path = tmp_path_factory.mktemp("logged") / "logged.h5"
    path.write_bytes(output.read_bytes())
    return synthetic.write(path, synthetic.impacts(60, stops=1), synthetic.statistics(stops=1, bins=24),
                           {"transient": 0.05, "batches": 8, "bins": 24, "rest_time": 1e-3})


@pytest.fixture(scope="module")
def logged_result(logged: Path) -> beamstops.Result:
    return beamstops.load(logged)


def headless() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "MPLBACKEND")}
    return env


#: Still kinds a run has data for without a shock log, stops along the span or statistics.
RUN_KINDS = [k for k in plots.FIGURE_KINDS if k not in ("stops", "impacts")]


@pytest.mark.parametrize("kind", RUN_KINDS)
def test_each_kind_is_written_from_python(kind: str, result: beamstops.Result, tmp_path: Path) -> None:
    path = plots.save(result, tmp_path / f"{kind}.png", kind=kind)
    assert path.read_bytes()[:8] == PNG and path.stat().st_size > 5000


@pytest.mark.parametrize("kind", plots.FIGURE_KINDS)
def test_each_kind_is_drawn_from_a_file_with_shocks_and_statistics(kind: str, logged_result: beamstops.Result,
                                                                   tmp_path: Path) -> None:
    if kind == "stops":
        pytest.skip("no stops along the span in this scene (tests/python/test_python_stops.py)")
    path = plots.save(logged_result, tmp_path / f"{kind}.png", kind=kind)
    assert path.read_bytes()[:8] == PNG and path.stat().st_size > 5000


def test_every_kind_is_known_to_the_command_line() -> None:
    from beamstops.cli import build_parser

    plot = build_parser()._subparsers._group_actions[0].choices["plot"]  # type: ignore[union-attr]
    kind = next(a for a in plot._actions if a.dest == "kind")
    assert tuple(kind.choices) == plots.KINDS
    assert {"impacts", "pdf", "psd", "poincare", "spacetime", "shape", "animation", "all"} <= set(plots.KINDS)


def test_the_command_line_starts_without_matplotlib() -> None:
    """``python -m beamstops`` builds its parser (every subcommand, plot's kinds included) without
    importing matplotlib: it is imported when a plot is drawn, not at every start (it was about a
    second of each ``python -m beamstops sweep ...``)."""
    import subprocess
    import sys

    code = ("import sys; from beamstops.cli import build_parser; build_parser(); "
            "print(sorted(m for m in sys.modules if m.split('.')[0] == 'matplotlib'))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"


def test_spacetime_is_the_shape(result: beamstops.Result) -> None:
    assert plots.plot_spacetime is plots.plot_shape
    a, b = plots.figure(result, "shape"), plots.figure(result, "spacetime")
    assert [ax.get_title() for ax in a.axes] == [ax.get_title() for ax in b.axes]


def test_impacts_histograms_count_the_logged_shocks(logged_result: beamstops.Result) -> None:
    fig = plots.figure(logged_result, "impacts")
    impulses, velocities = fig.axes[:2]
    side = logged_result.impacts["side"]
    kept = logged_result.impacts["truncated"] == 0
    # one step histogram per side, labelled with its count
    labels = [t.get_text() for t in impulses.get_legend().get_texts()]
    assert labels == [f"lower stop ({np.sum(kept & (side == 1))})", f"upper stop ({np.sum(kept & (side == -1))})"]
    labels = [t.get_text() for t in velocities.get_legend().get_texts()]
    assert labels == [f"lower stop ({np.sum(side == 1)})", f"upper stop ({np.sum(side == -1)})"]
    assert "60 shocks, 1 truncated left out" in impulses.get_title()
    assert len(impulses.patches) == 2 and len(velocities.patches) == 2


def test_impacts_histograms_count_in_whole_shocks(logged_result: beamstops.Result) -> None:
    """The y axis counts shocks: its ticks are whole numbers (not 0.25 of a shock on a short run)."""
    few = dataclasses.replace(logged_result, impacts={k: v[:3] for k, v in logged_result.impacts.items()})
    for ax in plots.figure(few, "impacts").axes[:2]:
        ax.figure.canvas.draw()
        ticks = ax.get_yticks()
        assert ticks.size >= 2 and np.all(ticks == np.round(ticks)), ticks


def test_impacts_per_stop_along_the_span(logged: Path, tmp_path: Path) -> None:
    path = tmp_path / "span.h5"
    with h5py.File(path, "w") as f:
        f.attrs["status"] = "complete"
        f.create_dataset("stops/x", data=[0.5, 1.0, 1.5])
        f.create_dataset("stops/node", data=[5.0, 10.0, 15.0])
    synthetic.write(path, synthetic.impacts(90, stops=3, seed=2))
    result = beamstops.load(path)
    fig = plots.figure(result, "impacts")
    labels = [t.get_text() for t in fig.axes[1].get_legend().get_texts()]
    stop = result.impacts["stop"]
    assert labels == [f"stop {k} (x = {x:g} m) ({np.sum(stop == k)})" for k, x in ((1, 0.5), (2, 1), (3, 1.5))]


def test_pdf_from_the_engine_histogram_with_its_intervals(logged_result: beamstops.Result) -> None:
    ax = plots.figure(logged_result, "pdf").axes[0]
    histogram = logged_result.statistics["tip_histogram"]
    edges = logged_result.statistics["tip_histogram_edges"].value
    stairs = next(p for p in ax.patches)
    np.testing.assert_allclose(stairs.get_data().values, histogram.value / np.diff(edges))
    bars = ax.collections[0].get_segments()
    np.testing.assert_allclose([s[1, 1] - s[0, 1] for s in bars], 2 * histogram.half_width / np.diff(edges))
    assert "engine, t ≥ 0.05 s, 8 batches" in ax.get_title()
    # integrates to one, as a PDF does
    assert np.sum(stairs.get_data().values * np.diff(edges)) == pytest.approx(1.0)
    # another transient than the engine's: a histogram of the records after it
    other = plots.figure(logged_result, "pdf", transient=0.1).axes[0]
    assert "records /tip/u, t ≥ 0.1 s" in other.get_title()
    count = int(np.sum(logged_result.t >= 0.1))
    assert f"{count} samples" in other.get_title()


def test_pdf_without_statistics_is_a_histogram_of_the_records(result: beamstops.Result) -> None:
    ax = plots.figure(result, "pdf").axes[0]
    values, edges, _ = next(p for p in ax.patches).get_data()
    assert np.sum(values * np.diff(edges)) == pytest.approx(1.0)
    assert edges[0] == pytest.approx(result.tip_u.min()) and edges[-1] == pytest.approx(result.tip_u.max())


def test_psd_is_welch_on_log_axes(result: beamstops.Result) -> None:
    fig = plots.figure(result, "psd")
    top, bottom = fig.axes[:2]
    assert top.get_xscale() == "log" and top.get_yscale() == "log" and bottom.get_yscale() == "log"
    f, p = welch(result.tip_u, 1.0 / (result.t[1] - result.t[0]))
    line = top.get_lines()[0]
    np.testing.assert_allclose(line.get_xdata(), f[1:][p[1:] > 0])
    np.testing.assert_allclose(line.get_ydata(), p[1:][p[1:] > 0])
    assert "reaction" in bottom.get_title()


def test_welch_matches_scipy_and_parseval() -> None:
    signal = pytest.importorskip("scipy.signal")
    rng = np.random.default_rng(3)
    x = np.sin(0.3 * np.arange(5000)) + rng.normal(size=5000)
    for segment in (None, 256, 301):
        f, p = welch(x, 200.0, segment)
        f2, p2 = signal.welch(x, 200.0, nperseg=2 * (f.size - 1) if segment is None else segment)
        np.testing.assert_allclose(f, f2)
        np.testing.assert_allclose(p, p2, rtol=1e-10, atol=1e-14 * p2.max())
    f, p = welch(rng.normal(size=1 << 14), 100.0, 1024)
    assert np.sum(p) * (f[1] - f[0]) == pytest.approx(1.0, rel=0.05)  # variance 1
    sine = np.sin(2 * np.pi * 12.5 * np.arange(4096) / 100.0)
    f, p = welch(sine, 100.0, 512)
    assert f[np.argmax(p)] == pytest.approx(12.5)


def test_poincare_samples_the_records_nearest_kT(result: beamstops.Result) -> None:
    period = 2 * np.pi / result.attrs["omega"]
    long = beamstops.run(Scene(t_end=4 * period + 1e-3, omega=10.0))
    ax = plots.figure(long, "poincare", transient=1.5 * period).axes[0]
    k, index, offset = stroboscopic(long.t, period, 1.5 * period)
    assert list(k) == [2, 3, 4]
    assert offset <= 0.5 * (long.t[1] - long.t[0]) * (1 + 1e-9)
    expected = np.array([[long.tip_u[np.argmin(np.abs(long.t - j * period))],
                          long.tip_v[np.argmin(np.abs(long.t - j * period))]] for j in k])
    np.testing.assert_allclose(ax.collections[0].get_offsets(), expected)
    with pytest.raises(ValueError, match="no stroboscopic sample"):
        plots.figure(long, "poincare", transient=10 * period)
    still = beamstops.run(Scene(t_end=0.01, omega=0.0))
    with pytest.raises(ValueError, match="no forcing period: omega = 0"):
        plots.figure(still, "poincare")


def test_animation_writes_a_gif_of_at_most_200_frames(tmp_path: Path) -> None:
    from PIL import Image

    many = beamstops.run(Scene(t_end=0.3, snapshot_every=10))  # 601 snapshots
    assert many.snapshot_t.size > 200
    path = plots.save(many, tmp_path / "beam.gif", kind="animation", dpi=40)
    with Image.open(path) as gif:
        assert gif.format == "GIF" and gif.n_frames == 200
    few = beamstops.run(Scene(t_end=0.02, snapshot_every=50))
    path = plots.save(few, tmp_path / "few.gif", kind="animation", dpi=40, frames=10)
    with Image.open(path) as gif:
        assert gif.n_frames == few.snapshot_t.size == 9
    assert list(frame_indices(601, 200)[[0, -1]]) == [0, 600] and frame_indices(601, 200).size == 200


def test_animation_with_stops_along_the_span_marks_the_contacts(tmp_path: Path) -> None:
    from PIL import Image

    from beamstops.animation import _contacts

    span = beamstops.run(Scene(length=1.5, elements=30, amplitude=0.002, omega=40.0, beta=0.25, dt=2e-5, t_end=0.3,
                               nodes=(10, 20, 30), lower=(-0.002, -0.002, -0.004), upper=(0.002, 0.002, 0.004),
                               snapshot_every=100))
    acting = np.array([_contacts(span, i) for i in range(span.snapshot_t.size)])
    assert acting.shape == (span.snapshot_t.size, 3) and acting.any()
    rows = np.searchsorted(span.t, span.snapshot_t)
    np.testing.assert_array_equal(acting, span.stops_reaction[rows] != 0)
    path = plots.save(span, tmp_path / "span.gif", kind="animation", dpi=40, frames=20)
    with Image.open(path) as gif:
        assert gif.n_frames == 20


@pytest.mark.skipif(not __import__("shutil").which("ffmpeg"), reason="ffmpeg is not installed")
def test_animation_writes_mp4_with_ffmpeg(result: beamstops.Result, tmp_path: Path) -> None:
    path = plots.save(result, tmp_path / "beam.mp4", kind="animation", dpi=40, frames=10)
    assert path.stat().st_size > 1000 and path.read_bytes()[4:8] == b"ftyp"


def test_animation_format_errors(result: beamstops.Result, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from matplotlib import animation

    with pytest.raises(ValueError, match=r"written as \.gif or \.mp4, not \.png"):
        plots.save(result, tmp_path / "beam.png", kind="animation")
    monkeypatch.setattr(animation.FFMpegWriter, "isAvailable", classmethod(lambda cls: False))
    with pytest.raises(ValueError, match="MP4 needs ffmpeg, which is not on PATH; write a .gif instead"):
        plots.save(result, tmp_path / "beam.mp4", kind="animation")
    with pytest.raises(ValueError, match="not a still figure"):
        plots.figure(result, "animation")


@pytest.mark.parametrize("kind", ["shape", "spacetime", "animation"])
def test_kinds_without_snapshots_say_how_to_get_them(kind: str, tmp_path: Path) -> None:
    bare = beamstops.run(Scene(t_end=0.01))
    with pytest.raises(ValueError, match=r"^no snapshots: run with &output snapshot_every > 0$"):
        plots.save(bare, tmp_path / ("out.gif" if kind == "animation" else "out.png"), kind=kind)


def test_other_missing_data_messages(result: beamstops.Result, tmp_path: Path) -> None:
    # the scene turned the log off: said so (the message blamed 'a beamstops that did not log shocks')
    with pytest.raises(ValueError, match=r"^no shock log: the run was made with &statistics enabled = \.false\."):
        plots.figure(beamstops.run(Scene(t_end=0.3, enabled=False)), "impacts")
    path = synthetic.write(tmp_path / "quiet.h5", synthetic.impacts(0))
    with pytest.raises(ValueError, match=r"^no shocks: the shock log /impacts is empty"):
        plots.figure(beamstops.load(path), "impacts")
    with pytest.raises(ValueError, match=r"^no stops along the span"):
        plots.figure(result, "stops")
    with pytest.raises(ValueError, match="too few records for a spectrum"):
        plots.figure(result, "psd", transient=float(result.t[-1]))


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


def test_all_draws_what_the_run_has(result: beamstops.Result, logged_result: beamstops.Result,
                                    tmp_path: Path) -> None:
    bare = beamstops.run(Scene(t_end=0.01))
    fig = plots.figure(bare, "all")  # no snapshots: the shape's panel says so
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert any(t.startswith("no snapshots") for t in texts)
    assert plots.save(bare, tmp_path / "bare.png", kind="all").stat().st_size > 0
    titles = [ax.get_title() for ax in plots.figure(logged_result, "all").axes]
    for expected in ("tip displacement PDF (engine", "tip displacement u(L, t)", "contact reaction at the tip",
                     "Poincaré section", "impulse: 60 shocks", "impact velocity: 60 shocks"):
        assert any(t.startswith(expected) for t in titles), (expected, titles)
    unlogged = beamstops.run(Scene(t_end=1.3, enabled=False))
    assert not any(t.startswith("impulse") for t in (ax.get_title() for ax in plots.figure(unlogged, "all").axes))
    info = "\n".join(t.get_text() for ax in plots.figure(logged_result, "all").axes for t in ax.texts)
    assert "shocks logged: 60" in info and "power to the stops: 0.560 ± 0.031 W" in info
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


@pytest.mark.parametrize("kind", ["impacts", "pdf", "psd", "poincare", "spacetime"])
def test_command_line_new_kinds(kind: str, logged: Path, tmp_path: Path) -> None:
    png = tmp_path / f"cli-{kind}.png"
    done = subprocess.run([sys.executable, "-m", "beamstops", "plot", str(logged), "-o", str(png), "--kind", kind,
                           "--transient", "0.05"], capture_output=True, text=True, timeout=120, env=headless())
    assert done.returncode == 0, done.stderr
    assert png.read_bytes()[:8] == PNG


def test_command_line_animation(output: Path, tmp_path: Path) -> None:
    done = subprocess.run([sys.executable, "-m", "beamstops", "plot", str(output), "--kind", "animation",
                           "--frames", "7", "--dpi", "40"], capture_output=True, text=True, timeout=120, env=headless())
    assert done.returncode == 0, done.stderr
    gif = output.parent / "out_animation.gif"
    assert done.stdout.strip() == str(gif)
    from PIL import Image

    with Image.open(gif) as image:
        assert image.n_frames == 7


def test_command_line_missing_data_is_one_line(program: str, tmp_path: Path) -> None:
    Scene(t_end=0.3, enabled=False, file="bare.h5").to_namelist(tmp_path / "bare.nml")
    subprocess.run([program, "run", "bare.nml"], cwd=tmp_path, check=True, capture_output=True, timeout=120)
    output = tmp_path / "bare.h5"
    done = subprocess.run([sys.executable, "-m", "beamstops", "plot", str(output), "--kind", "impacts",
                           "-o", str(tmp_path / "x.png")], capture_output=True, text=True, timeout=120, env=headless())
    assert done.returncode == 1 and done.stderr.count("\n") == 1
    # the message names the file that lacks the data (it said only 'no shock log ...')
    assert done.stderr.startswith(f"beamstops: error: {output}: no shock log") and "Traceback" not in done.stderr
    done = subprocess.run([sys.executable, "-m", "beamstops", "plot", str(output), "--kind", "shape",
                           "-o", str(tmp_path / "y.png")], capture_output=True, text=True, timeout=120, env=headless())
    assert done.returncode == 1 and done.stderr == f"beamstops: error: {output}: {NO_SNAPSHOTS}\n"


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


def plot_command(*args: str | Path, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "beamstops", "plot", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=120, env=headless())


@pytest.mark.parametrize("spelling", ["existing", "existing/", "new/", "."])
def test_command_line_refuses_a_folder_as_output(spelling: str, output: Path, tmp_path: Path) -> None:
    (tmp_path / "existing").mkdir()
    done = plot_command(output, "-o", spelling, cwd=tmp_path)
    assert done.returncode == 1 and done.stdout == ""
    assert done.stderr.strip() == (f"beamstops: error: -o {spelling}: is a folder; name the image file to write, "
                                   f"e.g. -o {Path(spelling) / 'out_tip.png'}")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["existing"]  # nothing written beside it
    assert list((tmp_path / "existing").iterdir()) == []


def test_command_line_prints_the_file_it_wrote(output: Path, tmp_path: Path) -> None:
    done = plot_command(output, "-o", "noext", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "noext.png" and (tmp_path / "noext.png").read_bytes()[:8] == PNG
    assert not (tmp_path / "noext").exists()
    done = plot_command(output, "-o", "figure.pdf", cwd=tmp_path)
    assert done.returncode == 0 and done.stdout.strip() == "figure.pdf"
    assert (tmp_path / "figure.pdf").read_bytes()[:4] == b"%PDF"


def test_save_gives_the_file_written_and_refuses_a_folder(result: beamstops.Result, tmp_path: Path) -> None:
    written = plots.save(result, tmp_path / "noext", kind="energy")
    assert written == tmp_path / "noext.png" and written.read_bytes()[:8] == PNG
    with pytest.raises(IsADirectoryError, match=r"is a folder; name the image file to write"):
        plots.save(result, tmp_path)
    with pytest.raises(IsADirectoryError, match=r"is a folder"):
        plots.save(result, f"{tmp_path}/new/", kind="animation")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["noext.png"]


def test_command_line_names_its_option_for_an_incomplete_run(program: str, tmp_path: Path) -> None:
    Scene(beta=0.0, dt=2e-5, t_end=0.5, allow_unstable=True, record_every=100, file="bad.h5").to_namelist(
        tmp_path / "bad.nml")
    assert subprocess.run([program, "run", "bad.nml"], cwd=tmp_path, capture_output=True, timeout=120).returncode == 3
    done = plot_command("bad.h5", "-o", "bad.png", cwd=tmp_path)
    assert done.returncode == 1 and not (tmp_path / "bad.png").exists()
    err = done.stderr.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("beamstops: error: bad.h5: run diverged: "), err
    assert err[0].endswith("; plot what it holds with --allow-incomplete") and "allow_incomplete" not in err[0]
    done = plot_command("bad.h5", "-o", "bad.png", "--allow-incomplete", cwd=tmp_path)
    assert done.returncode == 0 and done.stdout.strip() == "bad.png", done.stderr
    # from Python, the message names the keyword
    with pytest.raises(beamstops.IncompleteRunError, match=r"pass allow_incomplete=True to read what it holds$"):
        beamstops.load(tmp_path / "bad.h5")


def test_command_line_does_not_flood_stderr_with_font_lookups(output: Path, tmp_path: Path) -> None:
    # a configuration asking for a font family that is nowhere: every text's lookup falls back to
    # DejaVu Sans, which matplotlib logs as a warning each time (as a font cache without cmr10 does)
    config = tmp_path / "mplconfig"
    config.mkdir()
    (config / "matplotlibrc").write_text("font.family: beamstops-absent-font\nmathtext.fontset: cm\n")
    env = {**headless(), "MPLCONFIGDIR": str(config)}
    probe = subprocess.run([sys.executable, "-c", "import matplotlib.font_manager as fm; fm.findfont(fm.FontProperties())"],
                           capture_output=True, text=True, timeout=120, env=env)
    assert "findfont" in probe.stderr  # the situation is there
    done = subprocess.run([sys.executable, "-m", "beamstops", "plot", str(output), "-o", str(tmp_path / "p.png"),
                           "--kind", "psd"], capture_output=True, text=True, timeout=120, env=env)
    assert done.returncode == 0, done.stderr
    assert done.stderr == "" and (tmp_path / "p.png").read_bytes()[:8] == PNG


def test_an_image_never_overwrites_an_hdf5_file(output: Path, tmp_path: Path, result: beamstops.Result) -> None:
    """`plot run.png -o run.png` (an output named like an image) or any other HDF5 file at -o
    (`-o noext` writes noext.png): refused, the file left as it was. The image was written over it."""
    data = output.read_bytes()
    for name in ("run.png", "other.pdf", "noext.png"):
        (tmp_path / name).write_bytes(data)
    for plotted, target, named in (("run.png", "run.png", "run.png"), (str(output), "other.pdf", "other.pdf"),
                                   (str(output), "noext", "noext.png")):
        done = plot_command(plotted, "-o", target, cwd=tmp_path)
        assert done.returncode == 1 and done.stdout == "", done.stderr
        assert done.stderr.strip() == (f"beamstops: error: {named}: exists and is an HDF5 file (a run's output?); "
                                       "refusing to overwrite it with an image; name another file")
    for name in ("run.png", "other.pdf", "noext.png"):
        assert (tmp_path / name).read_bytes() == data
    assert output.read_bytes() == data
    with pytest.raises(FileExistsError, match="exists and is an HDF5 file"):
        plots.save(result, tmp_path / "run.png", kind="energy")
    assert output.read_bytes() == data


@pytest.mark.parametrize("target", ["output", "image"])
def test_an_image_is_never_written_through_a_link(target: str, output: Path, tmp_path: Path,
                                                  result: beamstops.Result) -> None:
    """-o naming a symbolic link, to a run's output or to an image: refused, the link and what it
    leads to left as they were. An image at the link's end was written over through it (the link
    kept), and a link to an HDF5 file refused only for what it led to."""
    where = output if target == "output" else tmp_path / "old.png"
    if target == "image":
        plots.save(result, where, kind="energy")
    data = where.read_bytes()
    for name in ("link.png", "link.gif"):
        (tmp_path / name).symlink_to(where)
    done = plot_command(output, "-o", "link.png", cwd=tmp_path)
    assert done.returncode == 1 and done.stdout == "", done.stderr
    assert done.stderr.strip() == ("beamstops: error: link.png: is a symbolic link; refusing to write an image "
                                   "through it or over it; name the file itself, or remove the link")
    with pytest.raises(FileExistsError, match="is a symbolic link"):
        plots.save(result, tmp_path / "link.gif", kind="animation", frames=2, dpi=20)
    with pytest.raises(FileExistsError, match="is a symbolic link"):
        plots.save(result, tmp_path / "link.png", kind="tip")
    assert where.read_bytes() == data and (tmp_path / "link.png").is_symlink()


def test_an_image_overwrites_only_an_image(output: Path, tmp_path: Path, result: beamstops.Result) -> None:
    """A text, a namelist or a table at -o is refused and left as it was (the plot had replaced
    it); a plot drawn before, of any format, and an empty file are written over."""
    precious = {"notes.png": b"precious notes\n", "scene.pdf": b"&time dt = 1e-5 /\n", "table.svg": b"t,u\n0,1\n"}
    for name, content in precious.items():
        (tmp_path / name).write_bytes(content)
        done = plot_command(str(output), "-o", name, cwd=tmp_path)
        assert done.returncode == 1 and done.stdout == "", done.stderr
        assert done.stderr.strip() == (f"beamstops: error: {name}: exists and is not an image (not PNG, PDF, SVG, "
                                       "PostScript, JPEG, GIF, TIFF, WebP or MP4); refusing to overwrite it with an "
                                       "image; name another file or remove it")
        assert (tmp_path / name).read_bytes() == content
    for name in ("again.png", "again.pdf", "again.svg"):
        assert plot_command(str(output), "-o", name, cwd=tmp_path).returncode == 0
        first = (tmp_path / name).stat().st_mtime_ns
        assert plot_command(str(output), "-o", name, "--kind", "energy", cwd=tmp_path).returncode == 0
        assert (tmp_path / name).stat().st_mtime_ns >= first
    (tmp_path / "empty.png").write_bytes(b"")
    plots.save(result, tmp_path / "empty.png", kind="energy")
    assert (tmp_path / "empty.png").read_bytes()[:8] == PNG


def test_an_image_is_never_written_to_a_fifo(output: Path, tmp_path: Path) -> None:
    """-o naming a FIFO: refused at once (reading its first bytes to tell what it is had hung)."""
    os.mkfifo(tmp_path / "pipe.png")
    done = plot_command(str(output), "-o", "pipe.png", cwd=tmp_path)
    assert done.returncode == 1 and done.stdout == "", done.stderr
    assert done.stderr.strip() == ("beamstops: error: pipe.png: exists and is not a regular file (a FIFO, a device or "
                                   "a socket); refusing to write an image there; name another file")


@pytest.mark.parametrize("dpi", ["0", "-5", "100000", "abc"])
def test_a_resolution_out_of_range_is_refused_by_the_command_line(dpi: str, output: Path, tmp_path: Path) -> None:
    """--dpi 100000 ended in a MemoryError traceback from the renderer; 0 in matplotlib's words."""
    done = plot_command(output, "-o", "x.png", "--dpi", dpi, cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert f"argument --dpi: '{dpi}': allowed: a whole number of dots per inch, 1 ... 2400" in done.stderr
    assert not (tmp_path / "x.png").exists()


def test_an_animation_named_without_extension_gets_gif(output: Path, result: beamstops.Result,
                                                       tmp_path: Path) -> None:
    done = plot_command(output, "--kind", "animation", "-o", "anim", "--frames", "4", "--dpi", "30", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "anim.gif"
    assert (tmp_path / "anim.gif").read_bytes()[:6] == b"GIF89a"
    path = plots.save(result, tmp_path / "beam", kind="animation", dpi=30, frames=4)
    assert path == tmp_path / "beam.gif" and path.read_bytes()[:6] == b"GIF89a"

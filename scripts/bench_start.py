"""The fixed cost of starting `beamstops run`: two builds of the program, the two alternating
(by default one linked against HDF5's shared libraries against the default, static HDF5).

    meson setup build/shared -Dstatic_hdf5=false -Dpython=false -Dtests=false && meson compile -C build/shared
    python scripts/bench_start.py build/shared/beamstops .venv/bin/beamstops [--repeats 20]
    meson setup build/dynlapack -Dstatic_lapack=false -Dpython=false -Dtests=false && meson compile -C build/dynlapack
    python scripts/bench_start.py build/dynlapack/beamstops .venv/bin/beamstops --labels "shared LAPACK,static LAPACK"

Three commands, each timed on both programs (wall, time.perf_counter; least and median of the
repeats; OPENBLAS_NUM_THREADS=1): `--version`; a 100-step run of the paper's scene
(input/paper_fig4.nml, t_end = 1e-4 s); a point of the README's ω sweep (dt = 1e-5 s,
t_end = 0.5 s, every 10th step recorded). Prints a markdown table; asserts nothing."""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


def scene(text: str, folder: Path, name: str, **keys: str) -> Path:
    """input/paper_fig4.nml with `keys` replaced and its output in `folder`."""
    for key, value in keys.items():
        text = re.sub(rf"\b{key}=[^,/ ]+", f"{key}={value}", text)
    text = re.sub(r"file='[^']*'", f"file='{folder / (name + '.h5')}'", text)
    path = folder / f"{name}.nml"
    path.write_text(text)
    return path


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("shared", help="the program built with -Dstatic_hdf5=false (or another option off)")
    parser.add_argument("static", help="the program built by default")
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--labels", default="shared HDF5,static HDF5", help="the two programs' columns")
    args = parser.parse_args()
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    labels = args.labels.split(",")
    if len(labels) != 2:
        parser.error("--labels takes two names separated by a comma")
    programs = {labels[0]: args.shared, labels[1]: args.static}
    base = (REPO / "input" / "paper_fig4.nml").read_text()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        commands = {
            "`--version`": ["--version"],
            "100-step run": ["run", str(scene(base, folder, "short", t_end="1e-4"))],
            "sweep point (50,000 steps)": ["run", str(scene(base, folder, "point", dt="1e-5", t_end="0.5",
                                                            record_every="10"))],
        }
        print("| command | " + " | ".join(f"{p}: least / median ms" for p in programs) + " |")
        print("|---|" + "---|" * len(programs))
        for label, command in commands.items():
            times: dict[str, list[float]] = {p: [] for p in programs}
            for i in range(args.repeats):
                order = list(programs.items()) if i % 2 == 0 else list(reversed(programs.items()))
                for name, program in order:
                    start = time.perf_counter()
                    subprocess.run([program, *command], check=True, env=env, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
                    times[name].append(time.perf_counter() - start)
            cells = [f"{1e3 * min(t):.1f} / {1e3 * statistics.median(t):.1f}" for t in times.values()]
            print(f"| {label} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
